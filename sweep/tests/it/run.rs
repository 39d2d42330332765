//! Expansion of sweep files: grid, zip and random modes, ids, and the errors reported before
//! anything runs.

use fabkit_designs::library;
use fabkit_sweep::*;
use serde_json::Value;
use std::path::Path;

const SPACING: &str = "layers[0].markers[0].pattern.spacing_mm";
const HEIGHT: &str = "layers[0].markers[0].feature.height_mm";

fn spec(text: &str) -> SweepSpec {
    SweepSpec::parse(text, "sweep.yaml", Path::new("")).unwrap()
}

fn err(text: &str) -> String {
    SweepSpec::parse(text, "sweep.yaml", Path::new(""))
        .unwrap_err()
        .to_string()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

/// The id of the library design (preset `paper_text`: concentric rings by spacing) with the
/// two parameters set directly on the typed design.
fn id_of(spacing: f64, height: f64, tol: f64) -> String {
    let mut d = library::load("shadowtac")
        .unwrap()
        .with_preset("paper_text")
        .unwrap();
    d.layers[0].markers[0].pattern.spacing_mm = Some(spacing);
    d.layers[0].markers[0].feature.height_mm = height;
    variant_id(&d, tol)
}

const GRID: &str = "base: shadowtac
preset: paper_text
vary:
  layers[0].markers[0].pattern.spacing_mm: {range: [1.2, 2.0, 0.2]}
  layers[0].markers[0].feature.height_mm: [0.3, 0.4, 0.5, 0.6]
mode: grid
outputs: [metrics]
";

#[test]
fn grid_is_the_cartesian_product_with_the_first_parameter_slowest() {
    let s = spec(GRID);
    let spacing = [1.2, 1.4, 1.6, 1.8, 2.0];
    let height = [0.3, 0.4, 0.5, 0.6];
    // the range gives the decimals as typed, not 1.2 + 2 x 0.2 = 1.5999999999999999
    let got: Vec<f64> = s.parameters[0].values.iter().map(f).collect();
    assert_eq!(got, spacing);
    let plan = s.plan().unwrap();
    assert_eq!(plan.variants.len(), 20);
    for (k, v) in plan.variants.iter().enumerate() {
        assert_eq!(v.index, k);
        assert_eq!(v.params[0].0, SPACING);
        assert_eq!(v.params[1].0, HEIGHT);
        assert_eq!(f(&v.params[0].1), spacing[k / 4]);
        assert_eq!(f(&v.params[1].1), height[k % 4]);
        // the id is the hash of the resolved design: the same as setting the fields directly
        assert_eq!(v.id, id_of(spacing[k / 4], height[k % 4], 0.01));
        assert_eq!(v.id.len(), ID_HEX_DIGITS);
    }
    let mut ids: Vec<&str> = plan.variants.iter().map(|v| v.id.as_str()).collect();
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), 20);
    // stable: parsing and expanding again gives the same ids and plan hash
    let again = spec(GRID).plan().unwrap();
    assert_eq!(again.variants, plan.variants);
    assert_eq!(again.plan_sha256, plan.plan_sha256);
}

#[test]
fn ids_depend_on_the_design_and_tolerance_only() {
    // the vary keys in the other order: other variant order, same ids per point
    let swapped = spec(
        "base: shadowtac
preset: paper_text
vary:
  layers[0].markers[0].feature.height_mm: [0.3, 0.4, 0.5, 0.6]
  layers[0].markers[0].pattern.spacing_mm: {list: [1.2, 1.4, 1.6, 1.8, 2.0]}
",
    )
    .plan()
    .unwrap();
    let grid = spec(GRID).plan().unwrap();
    let mut a: Vec<String> = grid.variants.iter().map(|v| v.id.clone()).collect();
    let mut b: Vec<String> = swapped.variants.iter().map(|v| v.id.clone()).collect();
    assert_ne!(a, b);
    assert_ne!(grid.plan_sha256, swapped.plan_sha256);
    a.sort();
    b.sort();
    assert_eq!(a, b);
    // another chord tolerance: other ids
    let fine = spec(&format!("{GRID}chord_tolerance_mm: 0.005\n"))
        .plan()
        .unwrap();
    assert_eq!(fine.variants[5].id, id_of(1.4, 0.4, 0.005));
    assert_ne!(fine.variants[5].id, grid.variants[5].id);
}

#[test]
fn zip_takes_the_lists_in_step() {
    let s = spec(
        "base: shadowtac
preset: paper_text
vary:
  layers[0].markers[0].pattern.spacing_mm: [1.4, 1.6, 1.8]
  layers[0].markers[0].feature.height_mm: {range: [0.3, 0.5, 0.1]}
mode: zip
",
    );
    let plan = s.plan().unwrap();
    assert_eq!(plan.variants.len(), 3);
    for (k, (sp, h)) in [(1.4, 0.3), (1.6, 0.4), (1.8, 0.5)].into_iter().enumerate() {
        let v = &plan.variants[k];
        assert_eq!((f(&v.params[0].1), f(&v.params[1].1)), (sp, h));
        assert_eq!(v.id, id_of(sp, h, 0.01));
    }
    let grid = spec(GRID).plan().unwrap();
    // (1.4, 0.3) is grid point 4 (second spacing, first height)
    assert_eq!(plan.variants[0].id, grid.variants[4].id);
}

/// Issue 95: in a zip a value may repeat in one list while the rows differ (it was refused as
/// "the value 3.0 is listed twice"); only a repeated row, the same variant twice, is refused.
#[test]
fn a_zip_refuses_repeated_rows_only() {
    let plan = spec(
        "base: shadowtac
preset: paper_text
vary:
  layers[0].markers[0].pattern.spacing_mm: [1.4, 1.4, 1.6]
  layers[0].markers[0].feature.height_mm: [0.3, 0.4, 0.4]
mode: zip
",
    )
    .plan()
    .unwrap();
    assert_eq!(plan.variants.len(), 3);
    let e = err("base: shadowtac
preset: paper_text
vary:
  layers[0].markers[0].pattern.spacing_mm: [1.4, 1.6, 1.4]
  layers[0].markers[0].feature.height_mm: [0.3, 0.4, 0.3]
mode: zip
");
    assert!(
        e.contains("mode zip: rows 0 and 2 of the lists are the same variant"),
        "{e}"
    );
}

#[test]
fn random_draws_distinct_grid_points_reproducibly() {
    let random = |seed: u64, count: u64| {
        spec(&format!(
            "{}mode: random\nseed: {seed}\ncount: {count}\n",
            GRID.replace("mode: grid\n", "")
        ))
        .plan()
        .unwrap()
    };
    let grid = spec(GRID).plan().unwrap();
    let a = random(7, 6);
    assert_eq!(a.variants.len(), 6);
    let mut last = None;
    for (k, v) in a.variants.iter().enumerate() {
        assert_eq!(v.index, k);
        // a grid point, with the grid point's id, listed in grid order, no repeats
        let g = grid
            .variants
            .iter()
            .find(|g| g.params == v.params)
            .expect("a grid point");
        assert_eq!(g.id, v.id);
        assert!(last.is_none_or(|l| l < g.index));
        last = Some(g.index);
    }
    assert_eq!(random(7, 6).variants, a.variants);
    assert_ne!(random(8, 6).variants, a.variants);
    // the whole grid when count is its size
    let all = random(3, 20);
    assert_eq!(all.variants, grid.variants);
    let e = SweepSpec::parse(
        &format!(
            "{}mode: random\ncount: 21\n",
            GRID.replace("mode: grid\n", "")
        ),
        "sweep.yaml",
        Path::new(""),
    )
    .unwrap()
    .plan()
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("count = 21: more than the 20 combinations"),
        "{e}"
    );
}

/// The issue's example file, with its short paths, plans the 5 x 4 grid on the full paths.
#[test]
fn the_issues_example_with_short_paths_plans_its_grid() {
    let sweep = SweepSpec::parse(
        "base: designs/library/shadowtac.yaml
preset: paper_text
vary:
  markers.spacing_mm: {range: [1.2, 2.0, 0.2]}
  markers.feature.height_mm: [0.3, 0.4, 0.5, 0.6]
mode: grid
outputs: [metrics]
",
        "sweep.yaml",
        Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap(),
    )
    .unwrap();
    let plan = sweep.plan().unwrap();
    assert_eq!(plan.variants.len(), 20);
    let names: Vec<&str> = sweep.parameters.iter().map(|p| p.path.as_str()).collect();
    assert_eq!(names, [SPACING, HEIGHT]);
}

#[test]
fn unknown_paths_are_reported_with_the_nearest_and_the_line() {
    // a misspelt short form: no path fits it; the hint gives the full one
    let e = err("base: shadowtac
preset: paper_text
vary:
  layers[0].markers[0].pattern.spacing_mm: [1.4]
  markers.feature.height: [0.3, 0.4]
");
    assert!(
        e.starts_with("sweep.yaml:5:3: vary: 'markers.feature.height' is not a parameter path of design 'shadowtac_paper_text'; nearest: layers[0].markers[0].feature.height_mm"),
        "{e}"
    );
    let e = err("base: shadowtac\nvary:\n  layers[1].thickness_mm: [1]\n");
    assert!(
        e.starts_with("sweep.yaml:3:3: vary: 'layers[1].thickness_mm'"),
        "{e}"
    );
    assert!(e.contains("nearest: "), "{e}");
}

#[test]
fn values_of_the_wrong_type_are_reported_with_the_line() {
    let e = err("base: shadowtac
vary:
  layers[0].markers[0].pattern.rings:
    [3, 4.5]
");
    assert_eq!(
        e,
        "sweep.yaml:4:5: vary.layers[0].markers[0].pattern.rings = 4.5: invalid type: floating point `4.5`, expected u32"
    );
    let e = err("base: shadowtac\nvary:\n  mold.wall_thickness_mm: [3, thick]\n");
    assert!(
        e.starts_with(
            "sweep.yaml:3:27: vary.mold.wall_thickness_mm = \"thick\": invalid type: string"
        ),
        "{e}"
    );
}

#[test]
fn malformed_sweeps_are_refused_before_anything_runs() {
    let cases = [
        (
            "base: shadowtac\nvary:\n  mold.wall_thickness_mm: [3, 4]\n  mold.draft_angle_deg: [1, 2, 3]\nmode: zip\n",
            "sweep.yaml:4:3: mode zip takes the lists in step",
        ),
        (
            "base: shadowtac\nvary:\n  mold.wall_thickness_mm: {range: [4, 3, 1]}\n",
            "sweep.yaml:3:27: vary.mold.wall_thickness_mm: range [4, 3, 1]: needs step > 0",
        ),
        (
            "base: shadowtac\nvary:\n  mold.wall_thickness_mm: [3, 3]\n",
            "the value 3 is listed twice",
        ),
        (
            "base: shadowtac\nvary:\n  mold.wall_thickness_mm: [3]\nmode: random\n",
            "sweep.yaml:4:7: mode random needs `count`",
        ),
        (
            "base: shadowtac\nvary:\n  mold.wall_thickness_mm: [3]\ncount: 2\n",
            "sweep.yaml:4:8: `count` only applies to mode random",
        ),
        (
            "base: shadowtac\nvary:\n  mold.wall_thickness_mm: [3]\noutputs: [files]\n",
            "outputs must include metrics",
        ),
        (
            "base: nosuchdesign\nvary:\n  mold.wall_thickness_mm: [3]\n",
            "sweep.yaml:1:7: base design: no library design named 'nosuchdesign'",
        ),
        (
            "base: shadowtac\nvray:\n  mold.wall_thickness_mm: [3]\n",
            "sweep.yaml:2:1: unknown field `vray`, expected one of base, preset, chord_tolerance_mm, vary, mode, seed, count, outputs; did you mean `vary`?",
        ),
        (
            "base: shadowtac\nvary:\n  layers[0].markers[0].pattern.csv_file: [a.csv]\n",
            "sweep.yaml:3:3: vary.layers[0].markers[0].pattern.csv_file: marker CSV files are read once",
        ),
        // An integer range whose next value overflows i64 (it once looped forever): one value,
        // which a u32 parameter then refuses.
        (
            "base: shadowtac\nvary:\n  layers[0].markers[0].pattern.rings: {range: [9223372036854775806, 9223372036854775807, 10]}\n",
            "vary.layers[0].markers[0].pattern.rings = 9223372036854775806",
        ),
        (
            "base: shadowtac\nvary:\n  layers[0].markers[0].pattern.rings: {range: [-9223372036854775808, 9223372036854775807, 1]}\n",
            "has 18446744073709551616 values, more than 1000000",
        ),
    ];
    for (text, want) in cases {
        let e = err(text);
        assert!(e.contains(want), "{text}\n-> {e}\nwanted {want}");
    }
}

#[test]
fn integer_ranges_stay_integers_and_files_outputs_parse() {
    let s = spec(
        "base: shadowtac
preset: published_469
vary:
  layers[0].markers[0].pattern.rings: {range: [8, 12, 2]}
outputs: [metrics, files]
",
    );
    assert_eq!(
        s.parameters[0].values,
        vec![Value::from(8), Value::from(10), Value::from(12)]
    );
    assert!(s.files.stl && s.files.threemf);
    let plan = s.plan().unwrap();
    let mut d = library::load("shadowtac")
        .unwrap()
        .with_preset("published_469")
        .unwrap();
    d.layers[0].markers[0].pattern.rings = Some(10);
    assert_eq!(plan.variants[1].id, variant_id(&d, 0.01));
}

#[test]
fn shards_split_every_nth_variant() {
    let s: Shard = "1/3".parse().unwrap();
    let picked: Vec<usize> = (0..10).filter(|&i| s.contains(i)).collect();
    assert_eq!(picked, [1, 4, 7]);
    for bad in ["3/3", "1", "a/2", "0/0"] {
        assert!(bad.parse::<Shard>().is_err(), "{bad}");
    }
}

/// A parameter given by its full and by its short path is refused (one of its value lists was
/// dropped), naming both places in the file.
#[test]
fn a_parameter_given_twice_is_refused() {
    let e = err(
        "base: shadowtac\nvary:\n  layers[0].markers[0].feature.height_mm: [0.4, 0.5]\n  markers.feature.height_mm: [0.3]\n",
    );
    assert!(
        e.contains("sweep.yaml:4:3: vary: 'markers.feature.height_mm' names layers[0].markers[0].feature.height_mm, which is varied already (at sweep.yaml:3:3)"),
        "{e}"
    );
}

/// A swept parameter that the design ignores is refused before anything runs: ShadowTac's
/// pattern is concentric_6k, on which `spacing_mm` has no effect (every variant was the same).
#[test]
fn a_parameter_the_design_ignores_is_refused() {
    let e = err("base: shadowtac\nvary:\n  layers[0].markers[0].pattern.spacing_mm: [1.2, 1.4]\n");
    assert!(
        e.contains("sweep.yaml:3:3: vary.layers[0].markers[0].pattern.spacing_mm: has no effect on concentric_6k")
            && e.contains("every variant would be the same design"),
        "{e}"
    );
    // under the preset that lays the pattern out by spacing, it is swept
    let s = spec(
        "base: shadowtac\npreset: paper_text\nvary:\n  layers[0].markers[0].pattern.spacing_mm: [1.2, 1.4]\n",
    );
    assert_eq!(s.plan().unwrap().variants.len(), 2);
}

/// The user guide's sweep example (docs/src/guide/sweeps.md) parses, and every parameter it varies changes the design the
/// variants build: its variants' marker counts differ with the spacing.
#[test]
fn the_guide_sweep_example_varies_effective_parameters() {
    let readme = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/src/guide/sweeps.md"),
    )
    .unwrap();
    let start = readme
        .find("# dimples.yaml\n")
        .expect("the guide's sweep example");
    let end = start + readme[start..].find("```").unwrap();
    let s = spec(&readme[start..end]);
    let plan = s.plan().unwrap();
    let materials = fabkit_designs::materials::MaterialsTable::embedded().unwrap();
    let spacing = "layers[0].markers[0].pattern.spacing_mm";
    let mut counts = std::collections::BTreeMap::new();
    for v in &plan.variants {
        let d = s.resolve(&v.params).unwrap();
        let st = fabkit_designs::stack::validate(&d, &materials, s.chord_tolerance).unwrap();
        let n = fabkit_designs::estimate::estimate(&d, &st, s.chord_tolerance).markers;
        let at = v
            .params
            .iter()
            .find(|(p, _)| p == spacing)
            .unwrap()
            .1
            .to_string();
        counts.insert(at, n);
    }
    assert!(counts.len() >= 3, "{counts:?}");
    let distinct: std::collections::BTreeSet<_> = counts.values().collect();
    assert_eq!(distinct.len(), counts.len(), "{counts:?}");
}

/// Any swept parameter whose values all build the same kit is refused, with the reason when it
/// is a known switch: the round tube under the square housing, the mold of a printed skin, the
/// draft of a master-strategy mold box on a two-piece mold, the top piece of a two-piece mold
/// on an open one. Where the design uses it, or under a swept switch that turns it on, the
/// parameter is accepted.
#[test]
fn a_parameter_no_value_of_which_changes_the_kit_is_refused() {
    let e =
        err("base: rtac0\npreset: square_split\nvary:\n  housing.round_tube.height_mm: [24, 26]\n");
    assert!(
        e.starts_with("sweep.yaml:4:3: vary.housing.round_tube.height_mm: has no effect on design 'rtac0_square_split' (it applies only with housing.style: round_tube): the values 24, 26 give the same parts"),
        "{e}"
    );
    assert!(e.contains("every variant would be the same design"), "{e}");
    let e = err("base: tactip_dualmodal\nvary:\n  mold.wall_thickness_mm: [3, 4, 5]\n");
    assert!(
        e.contains("sweep.yaml:3:3: vary.mold.wall_thickness_mm: has no effect on design 'tactip_dualmodal' (no layer is cast, so no mold is built): the values 3, 4, 5"),
        "{e}"
    );
    let e = err("base: shadowtac\nvary:\n  mold.draft_angle_deg: [1, 3]\n");
    assert!(
        e.contains("sweep.yaml:3:3: vary.mold.draft_angle_deg: has no effect on design 'shadowtac': the values 1, 3"),
        "{e}"
    );
    // the same parameters where the design uses them
    // (each variant builds, so the probes did not accept them for want of a result)
    let s = spec("base: rtac0\nvary:\n  housing.round_tube.height_mm: [24, 26]\n");
    let v = volumes(&s);
    // measured 625 mm^3 (2 mm more of the tube's wall); a parameter the kit ignored gives 0
    assert!((v[0] - v[1]).abs() > 1.0, "{v:?}");
    let s = spec(
        "base: shadowtac\npreset: open_mold\nvary:\n  mold.strategy: [open, two_piece_open]\n  mold.two_piece.reservoir_height_mm: [14, 16]\n",
    );
    let v = volumes(&s);
    assert_eq!(v.len(), 4);
    // measured: 0 for the open mold, 8877 mm^3 for 2 mm more of reservoir
    assert!(
        (v[0] - v[1]).abs() < 1e-9 && (v[2] - v[3]).abs() > 1.0,
        "{v:?}"
    );
    let e = err("base: shadowtac\npreset: open_mold\nvary:\n  mold.two_piece.reservoir_height_mm: [14, 16]\n");
    assert!(
        e.contains("sweep.yaml:4:3: vary.mold.two_piece.reservoir_height_mm: has no effect on design 'shadowtac_open_mold' (it applies only to layers cast with mold strategy two_piece_open)"),
        "{e}"
    );
}

/// The total part volume of each variant of `s`, mm^3, built at 0.05 mm; panics unless every
/// variant builds.
fn volumes(s: &SweepSpec) -> Vec<f64> {
    let materials = fabkit_designs::materials::MaterialsTable::embedded().unwrap();
    let tol = fabkit_designs::ChordTolerance::new(0.05).unwrap();
    s.plan()
        .unwrap()
        .variants
        .iter()
        .map(
            |v| match evaluate(&s.resolve(&v.params).unwrap(), &materials, tol) {
                Outcome::Ok { metrics, .. } => metrics.parts.iter().map(|p| p.volume_mm3).sum(),
                other => panic!("{:?}: {other:?}", v.params),
            },
        )
        .collect()
}
