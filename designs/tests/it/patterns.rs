//! Concentric patterns given by a polar step, per-ring azimuth offsets (TacTipGenerator's pin
//! layout), and the printers a pattern prints on, from the rules that validate it.
//!
//! Validation tests follow STYLE.md: a valid baseline passes, one mutation yields exactly one
//! error naming its parameter path, value and rule, several mutations yield all their errors.
//! (A file of its own, apart from `markers.rs`, so that these tests and the property tests of
//! the marker solids evolve independently.)

use fabkit_designs::geometry::ChordTolerance;
use fabkit_designs::library;
use fabkit_designs::markers::{
    self, AlternateOffset, Layout, Marker, Pattern, RingAzimuthOffset, Surface,
};
use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::profile::BodyProfile;
use fabkit_designs::schema::Technology;
use fabkit_designs::stack::validate;
use fabkit_designs::{Design, ParamError};
use std::f64::consts::PI;

fn errors(d: &Design) -> Vec<ParamError> {
    let materials = MaterialsTable::embedded().expect("embedded materials table");
    match validate(d, &materials, ChordTolerance::default()) {
        Ok(_) => vec![],
        Err(e) => e.0,
    }
}

fn listing(errs: &[ParamError]) -> String {
    errs.iter().map(|e| format!("\n  {e}")).collect()
}

/// `errs` holds exactly one error, at `path` with `value`, whose rule contains every word.
fn assert_one(what: &str, errs: &[ParamError], path: &str, value: &str, words: &[&str]) {
    assert!(
        errs.len() == 1
            && errs[0].path == path
            && errs[0].value == value
            && words.iter().all(|w| errs[0].rule.contains(w)),
        "{what}: expected only `{path} = {value}: ...{words:?}...`, got:{}",
        listing(errs)
    );
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

// ---------------------------------------------------------------------------------------------
// Rings by polar step: the ShadowTac authors' mold.

/// The ShadowTac authors' mold cavity: a sphere of radius 22.500 mm cut to a rim of
/// 35.000 mm diameter, 8.358 mm deep (authors' CAD, measured).
fn shadowtac_cad_cap() -> BodyProfile {
    BodyProfile::SphericalCap {
        base_diameter_mm: 35.0,
        height_mm: 22.5 - (22.5f64 * 22.5 - 17.5 * 17.5).sqrt(),
    }
}

/// The authors' dimple rings (authors' CAD, measured): 12 rings of 6k, 3.9474 deg apart in
/// polar angle.
const SHADOWTAC_STEP_DEG: f64 = 3.9474;

fn concentric_6k_by_step(rings: u32, step_deg: f64) -> Pattern {
    Pattern {
        layout: Layout::Concentric6k,
        rings: Some(rings),
        pitch_arc_mm: None,
        spacing_mm: None,
        count: None,
        points: None,
        csv_file: None,
        center_marker: true,
        max_polar_deg: None,
        min_polar_deg: None,
        polar_step_deg: Some(step_deg),
        ring_azimuth_offset: None,
    }
}

/// Ring k of a 6k pattern by polar step lies at polar angle k x step: on the authors' cavity
/// (R22.5) every one of the 469 dimples lands where the sphere's parametrisation puts it,
/// ring 12 at 47.37 deg (authors' CAD, measured), within 1e-6 mm (the issue asks 0.01 mm).
#[test]
fn shadowtac_rings_by_polar_step_land_on_the_authors_positions() {
    let surface = Surface::new(&shadowtac_cad_cap(), 0.0);
    // rim margin of the SLA mold: dimple diameter 0.45 + minimum wall 0.4
    let m = markers::place(
        &surface,
        &concentric_6k_by_step(12, SHADOWTAC_STEP_DEG),
        0.85,
    )
    .unwrap_or_else(|e| panic!("{e:?}"));
    assert_eq!(m.len(), 469);
    let mut worst: f64 = 0.0;
    for k in 0..=12u32 {
        let ring: Vec<&Marker> = m.iter().filter(|x| x.ring == k).collect();
        let n = if k == 0 { 1 } else { 6 * k as usize };
        assert_eq!(ring.len(), n, "ring {k}");
        let polar = (k as f64 * SHADOWTAC_STEP_DEG).to_radians();
        for (j, x) in ring.iter().enumerate() {
            let az = 2.0 * PI * j as f64 / n as f64;
            let want = [
                22.5 * polar.sin() * az.cos(),
                22.5 * polar.sin() * az.sin(),
                22.5 * polar.cos(),
            ];
            worst = worst.max(dist(x.position_mm, want));
        }
    }
    assert!(worst < 1e-6, "largest deviation {worst} mm");
    let outer = m.iter().filter(|x| x.ring == 12).map(|x| x.polar_deg);
    for p in outer {
        assert!((p - 47.37).abs() < 0.005, "outer ring at {p} deg");
    }
}

/// `concentric` by polar step: ring k at k x step until the region ends, round(circumference /
/// spacing) markers on each.
#[test]
fn concentric_by_polar_step_keeps_the_spacing_within_rings() {
    let surface = Surface::new(&shadowtac_cad_cap(), 0.0);
    let mut p = concentric_6k_by_step(0, 4.0);
    p.layout = Layout::Concentric;
    p.rings = None;
    p.spacing_mm = Some(1.4);
    let m = markers::place(&surface, &p, 0.85).unwrap_or_else(|e| panic!("{e:?}"));
    // the region ends 0.85 mm of arc inside the rim at asin(17.5 / 22.5): 48.893 deg, so 12
    // rings (48 deg)
    let polar_max = (17.5f64 / 22.5).asin().to_degrees() - (0.85f64 / 22.5).to_degrees();
    let rings = (polar_max / 4.0).floor() as u32;
    assert_eq!(rings, 12);
    let mut expected = 1;
    for k in 1..=rings {
        let r = 22.5 * (4.0 * k as f64).to_radians().sin();
        let n = (2.0 * PI * r / 1.4).round() as usize;
        let ring: Vec<&Marker> = m.iter().filter(|x| x.ring == k).collect();
        assert_eq!(ring.len(), n, "ring {k}");
        for x in ring {
            assert!((x.polar_deg - 4.0 * k as f64).abs() < 1e-9, "{x:?}");
        }
        expected += n;
    }
    assert_eq!(m.len(), expected);
}

/// The `published_469` ShadowTac design on the authors' cavity, rings by polar step.
fn shadowtac_by_step() -> Design {
    let mut d = library::load("shadowtac")
        .unwrap()
        .with_preset("published_469")
        .unwrap();
    d.body = shadowtac_cad_cap();
    let p = &mut d.layers[0].markers[0].pattern;
    p.pitch_arc_mm = None;
    p.polar_step_deg = Some(SHADOWTAC_STEP_DEG);
    d
}

const PATTERN: &str = "layers[0].markers[0].pattern";

#[test]
fn polar_step_errors_name_the_path_the_value_and_the_rule() {
    let d = shadowtac_by_step();
    assert!(errors(&d).is_empty(), "{}", listing(&errors(&d)));

    type Mutation = (
        &'static str,
        fn(&mut Pattern),
        &'static str,
        &'static str,
        &'static [&'static str],
    );
    let cases: Vec<Mutation> = vec![
        (
            "a step that puts ring 12 past the rim",
            |p| p.polar_step_deg = Some(4.2),
            "polar_step_deg",
            "4.2",
            &[
                "ring 12",
                "12 x 4.2 = 50.4000 deg",
                "beyond the patterned region",
                "up to 48.89",
                "rim at 51.058 deg less a margin of 0.850 mm",
            ],
        ),
        (
            "a step that puts ring 12 past max_polar_deg",
            |p| p.max_polar_deg = Some(45.0),
            "polar_step_deg",
            "3.9474",
            &[
                "ring 12",
                "47.3688 deg",
                "up to 45.0000 deg: max_polar_deg 45",
            ],
        ),
        (
            "a negative step",
            |p| p.polar_step_deg = Some(-1.0),
            "polar_step_deg",
            "-1",
            &["must be a finite angle above 0"],
        ),
        (
            "a NaN step",
            |p| p.polar_step_deg = Some(f64::NAN),
            "polar_step_deg",
            "NaN",
            &["must be a finite number"],
        ),
        (
            "an infinite step",
            |p| p.polar_step_deg = Some(f64::INFINITY),
            "polar_step_deg",
            "inf",
            &["must be a finite number"],
        ),
        (
            "both a pitch and a step",
            |p| p.pitch_arc_mm = Some(1.53),
            "polar_step_deg",
            "3.9474",
            &[
                "exactly one of pitch_arc_mm and polar_step_deg",
                "pitch_arc_mm is 1.53",
            ],
        ),
        (
            "neither a pitch nor a step",
            |p| p.polar_step_deg = None,
            "pitch_arc_mm",
            "missing",
            &["exactly one of pitch_arc_mm and polar_step_deg"],
        ),
        (
            "a spacing, which concentric_6k does not use",
            |p| p.spacing_mm = Some(1.4),
            "spacing_mm",
            "1.4",
            &["has no effect on concentric_6k", "use layout concentric"],
        ),
        (
            "a step on a hex grid",
            |p| {
                p.layout = Layout::HexGrid;
                p.rings = None;
                p.spacing_mm = Some(1.4);
            },
            "polar_step_deg",
            "3.9474",
            &["has no effect on layout hex_grid: it applies only to the concentric layouts"],
        ),
    ];
    for (what, mutate, field, value, words) in cases {
        let mut d = shadowtac_by_step();
        mutate(&mut d.layers[0].markers[0].pattern);
        assert_one(
            what,
            &errors(&d),
            &format!("{PATTERN}.{field}"),
            value,
            words,
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Per-ring azimuth offsets: TacTipGenerator's layout.

/// TacTipGenerator's pin positions (C. J. Ford, github.com/chrisjford/TacTipGenerator,
/// skinGenerator.py), computed here from its formula: `pointsCalculator(n, x1, r)` puts a pin
/// at the pole (0, 0, r) and, for rings i = 1..n and k = 1..i, one at
/// (x0 sin(k alpha), x0 cos(k alpha), r cos(i theta)) with alpha = 2 pi / 6i,
/// x0 = r sin(i theta), theta = asin(x1 / r); a circular pattern then repeats every pin six
/// times about z, 60 deg apart (the pole pin onto itself, so it is one pin).
fn tactipgenerator_points(n: u32, theta: f64, r: f64) -> Vec<[f64; 3]> {
    let mut pts = vec![[0.0, 0.0, r]];
    for i in 1..=n {
        let alpha = 2.0 * PI / (6 * i) as f64;
        let x0 = r * (i as f64 * theta).sin();
        let z = r * (i as f64 * theta).cos();
        for k in 1..=i {
            let (x, y) = (x0 * (k as f64 * alpha).sin(), x0 * (k as f64 * alpha).cos());
            for q in 0..6 {
                let (s, c) = (q as f64 * PI / 3.0).sin_cos();
                pts.push([c * x - s * y, s * x + c * y, z]);
            }
        }
    }
    pts
}

/// The generator's defaults (skinGenerator.py `run`): r = 10.2 mm tip, t = 1 mm skin, pins on
/// the inner surface (radius r - t), n = 8 rings, x1 = 1.5 mm.
const GEN_R_MM: f64 = 10.2;
const GEN_T_MM: f64 = 1.0;
const GEN_X1_MM: f64 = 1.5;

fn gen_theta() -> f64 {
    (GEN_X1_MM / (GEN_R_MM - GEN_T_MM)).asin()
}

/// How many of `want` have a point of `got` within `tol_mm`, each point of `got` used once.
fn coinciding(want: &[[f64; 3]], got: &[[f64; 3]], tol_mm: f64) -> usize {
    let mut used = vec![false; got.len()];
    let mut n = 0;
    for w in want {
        if let Some(j) = (0..got.len()).find(|&j| !used[j] && dist(*w, got[j]) < tol_mm) {
            used[j] = true;
            n += 1;
        }
    }
    n
}

fn tactipgenerator_pattern(offset: Option<RingAzimuthOffset>) -> Pattern {
    let mut p = concentric_6k_by_step(8, gen_theta().to_degrees());
    p.ring_azimuth_offset = offset;
    p
}

/// fabkit's `concentric_6k` with `polar_step_deg` = asin(1.5 / 9.2) = 9.3836 deg and
/// `ring_azimuth_offset: {alternate: half_step}` on the generator's own skin (inner surface of
/// a 10.2 mm hemisphere, 1 mm skin) puts its 217 pins on the generator's 217 positions; without
/// the offset only the centre and the even rings coincide (1 + 12 + 24 + 36 + 48 = 121).
#[test]
fn tactipgenerator_default_layout_is_reproduced_pin_for_pin() {
    assert!((gen_theta().to_degrees() - 9.3836).abs() < 5e-5);
    let body = BodyProfile::HemisphereOnCylinder {
        radius_mm: GEN_R_MM,
        cylinder_length_mm: 4.0,
    };
    let surface = Surface::new(&body, -GEN_T_MM);
    let want = tactipgenerator_points(8, gen_theta(), GEN_R_MM - GEN_T_MM);
    assert_eq!(want.len(), 217);
    let place = |p: &Pattern| -> Vec<[f64; 3]> {
        markers::place(&surface, p, 1.0)
            .unwrap_or_else(|e| panic!("{e:?}"))
            .iter()
            .map(|m| m.position_mm)
            .collect()
    };
    let got = place(&tactipgenerator_pattern(Some(
        RingAzimuthOffset::Alternate(AlternateOffset::HalfStep),
    )));
    assert_eq!(got.len(), 217);
    assert_eq!(coinciding(&want, &got, 1e-6), 217);
    let plain = place(&tactipgenerator_pattern(None));
    assert_eq!(plain.len(), 217);
    assert_eq!(coinciding(&want, &plain, 1e-6), 121);
}

/// The library preset `tactip_dualmodal` / `tactipgenerator_217` validates, and its 217 pins
/// sit at the generator's angles on this design's inner surface (R12.5).
#[test]
fn tactipgenerator_preset_places_the_generators_217_pins() {
    let tol = ChordTolerance::default();
    let d = library::load("tactip_dualmodal")
        .unwrap()
        .with_preset("tactipgenerator_217")
        .unwrap_or_else(|e| panic!("{e}"));
    let materials = MaterialsTable::embedded().unwrap();
    let stack = validate(&d, &materials, tol).unwrap_or_else(|e| panic!("{e}"));
    let pms = fabkit_designs::layers::place_layer_markers(&d.stack_input(), &stack.layers[0], tol);
    let got: Vec<[f64; 3]> = pms[0].markers.iter().map(|m| m.position_mm).collect();
    let want = tactipgenerator_points(8, gen_theta(), 12.5);
    assert_eq!(got.len(), 217);
    // the preset's step is written to 6 decimals of a degree: 1e-5 mm at ring 8
    assert_eq!(coinciding(&want, &got, 1e-5), 217);
}

/// `per_ring_deg` turns ring k by its own entry; the offset applies to `concentric` too.
#[test]
fn per_ring_offsets_turn_each_ring() {
    let surface = Surface::new(&shadowtac_cad_cap(), 0.0);
    let offsets = [
        5.0, -10.0, 0.0, 7.5, 100.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0,
    ];
    let mut p = concentric_6k_by_step(12, SHADOWTAC_STEP_DEG);
    p.ring_azimuth_offset = Some(RingAzimuthOffset::PerRingDeg(offsets.to_vec()));
    let m = markers::place(&surface, &p, 0.85).unwrap_or_else(|e| panic!("{e:?}"));
    for k in 1..=12u32 {
        let ring: Vec<&Marker> = m.iter().filter(|x| x.ring == k).collect();
        for (j, x) in ring.iter().enumerate() {
            let want = offsets[k as usize - 1] + 360.0 * j as f64 / (6 * k) as f64;
            assert!((x.azimuth_deg - want).abs() < 1e-9, "ring {k}: {x:?}");
        }
    }
    // concentric: as many entries as rings placed (12 at a 4 deg step, see above)
    p.layout = Layout::Concentric;
    p.rings = None;
    p.spacing_mm = Some(1.4);
    p.polar_step_deg = Some(4.0);
    let m = markers::place(&surface, &p, 0.85).unwrap_or_else(|e| panic!("{e:?}"));
    let first = m.iter().find(|x| x.ring == 5).unwrap();
    assert!((first.azimuth_deg - 100.0).abs() < 1e-9, "{first:?}");
    p.ring_azimuth_offset = Some(RingAzimuthOffset::PerRingDeg(vec![1.0; 11]));
    let e = markers::place(&surface, &p, 0.85).unwrap_err();
    assert_eq!(e.0, "ring_azimuth_offset.per_ring_deg");
    assert_eq!(e.1, "11 entries");
    assert!(e.2.contains("the pattern has 12 rings"), "{e:?}");
}

#[test]
fn ring_azimuth_offset_errors_name_the_path_the_value_and_the_rule() {
    type Mutation = (
        &'static str,
        fn(&mut Pattern),
        &'static str,
        &'static str,
        &'static [&'static str],
    );
    let cases: Vec<Mutation> = vec![
        (
            "a per-ring list shorter than the rings",
            |p| p.ring_azimuth_offset = Some(RingAzimuthOffset::PerRingDeg(vec![0.0; 3])),
            "ring_azimuth_offset.per_ring_deg",
            "3 entries",
            &["one entry per ring (rings is 12)"],
        ),
        (
            "a NaN per-ring offset",
            |p| {
                let mut v = vec![0.0; 12];
                v[2] = f64::NAN;
                p.ring_azimuth_offset = Some(RingAzimuthOffset::PerRingDeg(v));
            },
            "ring_azimuth_offset.per_ring_deg[2]",
            "NaN",
            &["must be a finite number"],
        ),
        (
            "an offset on a golden spiral",
            |p| {
                p.layout = Layout::GoldenSpiral;
                p.polar_step_deg = None;
                p.count = Some(200);
                p.ring_azimuth_offset =
                    Some(RingAzimuthOffset::Alternate(AlternateOffset::HalfStep));
            },
            "ring_azimuth_offset",
            "Alternate(HalfStep)",
            &["has no effect on layout golden_spiral: it applies only to the concentric layouts"],
        ),
    ];
    for (what, mutate, field, value, words) in cases {
        let mut d = shadowtac_by_step();
        mutate(&mut d.layers[0].markers[0].pattern);
        assert_one(
            what,
            &errors(&d),
            &format!("{PATTERN}.{field}"),
            value,
            words,
        );
    }
    // two violations at once: both reported
    let mut d = shadowtac_by_step();
    let p = &mut d.layers[0].markers[0].pattern;
    p.polar_step_deg = Some(-2.0);
    p.ring_azimuth_offset = Some(RingAzimuthOffset::PerRingDeg(vec![0.0; 3]));
    let errs = errors(&d);
    assert_eq!(errs.len(), 2, "{}", listing(&errs));
    assert!(errs
        .iter()
        .any(|e| e.path == format!("{PATTERN}.polar_step_deg")));
    assert!(errs
        .iter()
        .any(|e| e.path == format!("{PATTERN}.ring_azimuth_offset.per_ring_deg")));
    // values no rule can compute with are reported first, every one of them, alone
    let p = &mut d.layers[0].markers[0].pattern;
    p.ring_azimuth_offset = Some(RingAzimuthOffset::PerRingDeg(vec![f64::INFINITY; 12]));
    let errs = errors(&d);
    assert_eq!(errs.len(), 12, "{}", listing(&errs));
    assert!(errs.iter().all(|e| e.rule == "must be a finite number"));
}

/// The YAML spelling of the offsets, and an unknown one rejected by the schema.
#[test]
fn ring_azimuth_offset_yaml() {
    let text = library::yaml("tactip_dualmodal").unwrap();
    for (yaml, want) in [
        (
            "{alternate: half_step}",
            RingAzimuthOffset::Alternate(AlternateOffset::HalfStep),
        ),
        (
            "{per_ring_deg: [1.5, -3]}",
            RingAzimuthOffset::PerRingDeg(vec![1.5, -3.0]),
        ),
    ] {
        let t = text.replace(
            "          max_polar_deg: 85.0",
            &format!("          max_polar_deg: 85.0\n          ring_azimuth_offset: {yaml}"),
        );
        let d = Design::from_yaml(&t, "x.yaml").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            d.layers[0].markers[0].pattern.ring_azimuth_offset,
            Some(want)
        );
    }
    let t = text.replace(
        "          max_polar_deg: 85.0",
        "          max_polar_deg: 85.0\n          ring_azimuth_offset: {alternate: third_step}",
    );
    let e = Design::from_yaml(&t, "x.yaml").unwrap_err().to_string();
    assert!(e.contains("x.yaml:") && e.contains("third_step"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// printable_with comes from the rules that validate.

/// TacTipGenerator's own skin (R10.2 tip, 1 mm skin, 0.6 mm pins on its 217 layout): ring 8's
/// 48 pins are 1.164 mm apart on the R9.2 inner surface (chord 2 x 9.2 sin(75.07 deg)
/// sin(3.75 deg) = 1.163 mm), a 0.564 mm wall between 0.6 mm pins,
/// above SLA's 0.4 mm minimum wall and below PolyJet's 0.6 mm. Printed on SLA it validates and
/// lists only SLA (FDM's 0.8 mm minimum feature rejects the pins too); printed on PolyJet,
/// validation names the wall.
#[test]
fn printable_with_follows_the_validation_rules() {
    let tol = ChordTolerance::default();
    let mut d = library::load("tactip_dualmodal")
        .unwrap()
        .with_preset("tactipgenerator_217")
        .unwrap();
    d.shaft_body = None;
    d.body = BodyProfile::HemisphereOnCylinder {
        radius_mm: GEN_R_MM,
        cylinder_length_mm: 4.0,
    };
    d.layers[0].markers[0].tip_material = None;
    d.layers[0].print_technology = Some(Technology::Sla);
    let materials = MaterialsTable::embedded().unwrap();
    let stack = validate(&d, &materials, tol).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        fabkit_designs::layers::printable_with(&d.stack_input(), &stack.layers[0], 0),
        [Technology::Sla]
    );
    let out = fabkit_designs::build::build_layer(&d, &stack, 0, tol).unwrap();
    assert_eq!(out.markers[0]["printable_with"], serde_json::json!(["SLA"]));
    assert_eq!(out.markers[0]["needs_sla_or_finer"], true);

    d.layers[0].print_technology = Some(Technology::Polyjet);
    assert_one(
        "the same skin printed on PolyJet",
        &errors(&d),
        PATTERN,
        "concentric_6k",
        &[
            "1.164 mm apart",
            "leave too thin a wall (wall 0.564 mm, minimum 0.6 mm of printer profile 'polyjet')",
        ],
    );
}

/// On every library design and preset, for every marker pattern and every technology:
/// `printable_with` lists the technology exactly when the design, with its features made by
/// that technology (a printed layer's `print_technology`, a cast layer's mold cavity printer),
/// validates without an error on the pattern.
#[test]
fn printable_with_and_validation_agree_on_every_library_design() {
    use fabkit_designs::schema::LayerProcess;
    let tol = ChordTolerance::default();
    let materials = MaterialsTable::embedded().unwrap();
    let mut checked = 0;
    // curved designs: a flat skin's marker grid has no pattern rules
    for d in crate::common::library_designs_and_presets()
        .into_iter()
        .filter(|d| d.body.flat_outline().is_none())
    {
        let stack = validate(&d, &materials, tol).unwrap();
        for l in &stack.layers {
            for j in 0..d.layers[l.index].markers.len() {
                let listed = fabkit_designs::layers::printable_with(&d.stack_input(), l, j);
                let own = format!("layers[{}].markers[{j}]", l.index);
                let shared = format!("layers[{}].markers", l.index);
                for tech in [Technology::Fdm, Technology::Sla, Technology::Polyjet] {
                    let mut m = d.clone();
                    match m.layers[l.index].process {
                        LayerProcess::Printed => m.layers[l.index].print_technology = Some(tech),
                        _ => m.mold.cavity_print_technology = tech,
                    }
                    let pattern_errors: Vec<ParamError> = match validate(&m, &materials, tol) {
                        Ok(_) => Vec::new(),
                        Err(e) => {
                            e.0.into_iter()
                                .filter(|e| {
                                    e.path == own
                                        || e.path.starts_with(&format!("{own}."))
                                        || e.path == shared
                                })
                                .collect()
                        }
                    };
                    assert_eq!(
                        listed.contains(&tech),
                        pattern_errors.is_empty(),
                        "{} {own} on {tech:?}: printable_with {listed:?}, validation:{}",
                        d.name,
                        listing(&pattern_errors)
                    );
                    checked += 1;
                }
            }
        }
    }
    assert!(checked >= 30, "{checked}");
}
