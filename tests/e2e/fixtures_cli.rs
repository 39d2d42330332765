//! `fabkit fixtures` end to end: files, point table, protrusion descriptions, determinism,
//! oracle check and printcheck of every part, and bad parameters.

use crate::common::*;
use std::path::{Path, PathBuf};

fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

fn fixtures(cwd: &Path, out: &str, threads: &str) -> std::process::Output {
    run(
        cwd,
        &[
            "fixtures",
            "rtac0",
            "--pins-preset",
            "rtac0",
            "--semidomes",
            "2",
            "--seed",
            "3",
            "--out",
            out,
        ],
        &[("RAYON_NUM_THREADS", threads)],
    )
}

/// The R-Tac0 fixtures: 29-point table (CSV = JSON), capture plan, protrusion descriptions for
/// both orientations, manifest hashes, the indenters of the R-Tac0 paper only; byte-identical
/// with 1 and 2 threads; every part passes the oracle check and printcheck --strict.
#[test]
fn rtac0_fixtures_export_is_complete_deterministic_and_printable() {
    // Same command line (it is recorded in the files) in two folders, 1 and 2 threads.
    let (t1, t2) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let o = fixtures(t1.path(), "fx", "1");
    assert!(o.status.success(), "{}", text(&o.stderr));
    let o2 = fixtures(t2.path(), "fx", "2");
    assert!(o2.status.success(), "{}", text(&o2.stderr));
    let (a, b) = (t1.path().join("fx"), t2.path().join("fx"));
    let fa = files_under(&a);
    assert_eq!(fa.len(), files_under(&b).len());
    for f in &fa {
        let rel = f.strip_prefix(&a).unwrap();
        assert!(
            std::fs::read(f).unwrap() == std::fs::read(b.join(rel)).unwrap(),
            "{} differs between runs",
            rel.display()
        );
    }

    // Point table: CSV starting with its header row (the notes, frame and provenance are in
    // point_table.json), 29 rows, ids 1..29, the same numbers as the JSON.
    let csv = std::fs::read_to_string(a.join("points/point_table.csv")).unwrap();
    assert!(csv.starts_with("id,ring,"));
    assert!(!csv.contains('#'));
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("id,"))
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 29);
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(a.join("points/point_table.json")).unwrap()).unwrap();
    assert!(json["notes"][1]
        .as_str()
        .unwrap()
        .contains("frame: sensor frame"));
    let pts = json["points"].as_array().unwrap();
    for (r, p) in rows.iter().zip(pts) {
        assert_eq!(r[0] as u64, p["id"].as_u64().unwrap());
        for k in 0..3 {
            assert!((r[2 + k] - p["tip_mm"][k].as_f64().unwrap()).abs() < 1e-8);
        }
        // the tip lies on the axis through the contact point, indentation below it
        let depth = r[11];
        for k in 0..3 {
            assert!((r[5 + k] - depth * r[8 + k] - r[2 + k]).abs() < 1e-8);
        }
    }
    let plan = std::fs::read_to_string(a.join("points/capture_plan.csv")).unwrap();
    assert!(plan.starts_with("capture,id,ring\n"));
    let plan_rows: Vec<Vec<u32>> = plan
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("capture"))
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(plan_rows.len(), 8 * 5);

    // The authors' numbering (authors' CAD and point table): pole id 1; each ring clockwise
    // seen from +z from the hole at +x; the first capture is the authors' 01_02_06_14_22.png.
    let mut expect = vec![(1u32, 0u32, None)];
    for (k, az) in [0.0, 270.0, 180.0, 90.0].iter().enumerate() {
        expect.push((2 + k as u32, 1, Some(*az)));
    }
    for (first, ring) in [(6u32, 2u32), (14, 3), (22, 4)] {
        for k in 0..8u32 {
            expect.push((first + k, ring, Some((360.0 - 45.0 * k as f64) % 360.0)));
        }
    }
    for (r, (id, ring, az)) in rows.iter().zip(&expect) {
        assert_eq!((r[0] as u32, r[1] as u32), (*id, *ring));
        if let Some(az) = az {
            let got = r[6].atan2(r[5]).to_degrees().rem_euclid(360.0);
            let diff = (got - az).rem_euclid(360.0);
            assert!(
                diff.min(360.0 - diff) < 1e-6,
                "id {id}: azimuth {got}, want {az}"
            );
        }
        // Seated tips at R13.46 (authors' CAD, measured: head on the rim of the 2.5 mm
        // counterbore in the R19.1 outer sphere, 5.6 mm from under the head to the tip).
        let tip_r = (r[2] * r[2] + r[3] * r[3] + r[4] * r[4]).sqrt();
        assert!(
            (tip_r - 13.459_053).abs() < 1e-6,
            "id {id}: tip at R{tip_r}"
        );
    }
    let file_name = |capture: u32| {
        let ids: Vec<String> = plan_rows
            .iter()
            .filter(|r| r[0] == capture)
            .map(|r| format!("{:02}", r[1]))
            .collect();
        format!("{}.png", ids.join("_"))
    };
    assert_eq!(file_name(1), "01_02_06_14_22.png");
    assert_eq!(file_name(2), "01_03_07_15_23.png");

    // The exported meshes (authors' CAD, measured): the pin 8.8 mm long with a 3.0 mm head;
    // the dome's two tabs 43 mm across, its outer sphere 38.2 mm across.
    let size = |f: &str| {
        let b = std::fs::read(a.join(f)).unwrap();
        let n = u32::from_le_bytes(b[80..84].try_into().unwrap()) as usize;
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for t in 0..n {
            for v in 0..3 {
                for k in 0..3 {
                    let o = 84 + 50 * t + 12 + 12 * v + 4 * k;
                    let x = f32::from_le_bytes(b[o..o + 4].try_into().unwrap()) as f64;
                    lo[k] = lo[k].min(x);
                    hi[k] = hi[k].max(x);
                }
            }
        }
        [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]]
    };
    let pin = size("parts/pin.stl");
    // lengths along the axis are exact to float32 (1e-4 mm is 100 ulp at 10 to 45 mm); widths
    // across a tessellated circle are short of the diameter by at most twice the chord
    // tolerance (0.01 mm)
    assert!(
        (pin[2] - 8.8).abs() < 1e-4 && (pin[0] - 3.0).abs() < 0.02,
        "pin {pin:?}"
    );
    let dome = size("parts/pin_dome.stl");
    assert!((dome[0] - 43.0).abs() < 1e-4, "dome {dome:?}");
    assert!((dome[1] - 38.2).abs() < 0.02, "dome {dome:?}");

    // Protrusions: orientation 180 is orientation 0 turned about z.
    let idx: serde_json::Value =
        serde_json::from_slice(&std::fs::read(a.join("protrusions/index.json")).unwrap()).unwrap();
    assert_eq!(idx["stitched_pairs"], 4);
    for p in idx["patterns"].as_array().unwrap() {
        let d: serde_json::Value =
            serde_json::from_slice(&std::fs::read(a.join(p["file"].as_str().unwrap())).unwrap())
                .unwrap();
        let g0 = &d["orientations"][0]["geometry"]["primitives"];
        let g180 = &d["orientations"][1]["geometry"]["primitives"];
        assert!(!g0.as_array().unwrap().is_empty());
        for (x, y) in g0.as_array().unwrap().iter().zip(g180.as_array().unwrap()) {
            for (key, v) in x.as_object().unwrap() {
                let is_point = [
                    "centre_mm",
                    "base_mm",
                    "top_mm",
                    "apex_mm",
                    "p0_mm",
                    "p1_mm",
                    "origin_mm",
                ]
                .contains(&key.as_str());
                if is_point {
                    let (p0, p1) = (v.as_array().unwrap(), y[key].as_array().unwrap());
                    assert!((p0[0].as_f64().unwrap() + p1[0].as_f64().unwrap()).abs() < 1e-9);
                    assert!((p0[1].as_f64().unwrap() + p1[1].as_f64().unwrap()).abs() < 1e-9);
                    assert!((p0[2].as_f64().unwrap() - p1[2].as_f64().unwrap()).abs() < 1e-9);
                }
            }
        }
    }

    // The manifest lists every data file with its hash.
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(a.join("manifest.json")).unwrap()).unwrap();
    let data = m["data_files"].as_array().unwrap();
    assert!(data.len() > 3 + 3);
    // Only the indenters of the R-Tac0 paper (the TacTip's 107 mm disc was among them).
    let indenter_parts: Vec<&str> = m["parts"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|p| p["name"].as_str().filter(|n| n.starts_with("indenter_")))
        .collect();
    assert_eq!(indenter_parts, ["indenter_sphere_8mm_rtac0"]);
    let indenter_files: Vec<&str> = data
        .iter()
        .filter_map(|d| d["file"].as_str().filter(|f| f.starts_with("indenters/")))
        .collect();
    assert_eq!(indenter_files.len(), 1, "{indenter_files:?}");
    assert!(
        String::from_utf8_lossy(&o.stdout)
            .contains("indenters: those of the R-Tac0 paper (sphere_8mm_rtac0)"),
        "{}",
        text(&o.stdout)
    );
    for d in data {
        use sha2::Digest;
        let bytes = std::fs::read(a.join(d["file"].as_str().unwrap())).unwrap();
        let sha: String = sha2::Sha256::digest(&bytes)
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        assert_eq!(d["sha256"], sha.as_str());
    }

    oracle_check(&a);
    let meshes: Vec<PathBuf> = fa
        .into_iter()
        .filter(|f| f.extension().is_some_and(|e| e == "stl" || e == "3mf"))
        .filter(|f| !f.starts_with(a.join("plates")))
        .collect();
    // dome, pin and the dome's holder ring; holder, empty half and two halves; the indenter;
    // the 3MF (the plates are sliced in tests/e2e/plates.rs)
    assert_eq!(meshes.len(), 3 + 4 + 1 + 1);
    printcheck_all(&meshes);

    // The other papers' indenters, from their own designs' fixtures, slice too.
    let mut others = Vec::new();
    for (design, n) in [("shadowtac", 3), ("tactip_dualmodal", 4), ("uvdtact", 1)] {
        let out = format!("fx_{design}");
        let o = run(
            t1.path(),
            &["fixtures", design, "--format", "stl", "--out", &out],
            &[],
        );
        assert!(o.status.success(), "{design}: {}", text(&o.stderr));
        let found: Vec<PathBuf> = files_under(&t1.path().join(&out).join("parts"))
            .into_iter()
            .filter(|f| {
                f.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with("indenter_"))
            })
            .collect();
        assert_eq!(found.len(), n, "{design}: {found:?}");
        others.extend(found);
    }
    printcheck_all(&others);
}

/// Bad fixture parameters: an error naming the parameter and the rule, exit 2, nothing written;
/// a YAML mistake names file:line:col.
#[test]
fn bad_fixture_parameters_name_the_parameter_and_write_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        ("pin_dome:\n  rings:\n    - {polar_angle_deg: 20, count: 16}\n", "pin_dome.rings[0].count"),
        ("pin_dome:\n  clearance_mm: -1\n", "pin_dome.clearance_mm"),
        // once aborted on a 32 GB allocation
        (
            "pin_dome:\n  rings:\n    - {polar_angle_deg: 20, count: 4000000000}\n",
            "pin_dome.rings[0].count = 4000000000: must be at most 1000 holes on one ring (checked at 1000000, the most any count may be)",
        ),
        (
            "pin_dome:\n  rings:\n    - {polar_angle_deg: 20, count: 1000000}\n",
            "pin_dome.rings[0].count = 1000000: must be at most 1000 holes on one ring",
        ),
        (
            "pin_dome:\n  pin:\n    length_mm: 2.0\n",
            "pin_dome.pin.length_mm = 2: the seated tip stops 1.100 mm above the surface: the pins would not reach it (seated with the head on the counterbore's floor, ",
        ),
        ("semidomes:\n  patterns:\n    - name: edge\n      protrusions:\n        - {polar_angle_deg: 40, azimuth_deg: 88, indentation_depth_mm: 1, shape: {type: sphere, radius_mm: 2}}\n", "semidomes.patterns[0].protrusions[0].azimuth_deg"),
        (
            "pin_dome:\n  wall_thicknes_mm: 2\n",
            "params.yaml:2:3: unknown field `wall_thicknes_mm`, expected one of",
        ),
        // the nearest valid key, as in a design file
        (
            "pin_dome:\n  wall_thicknes_mm: 2\n",
            "; did you mean `wall_thickness_mm`?",
        ),
        (
            "pin_dome:\n  hole_numbering: {direction: clockwise, start_azimuth_deg: 10}\n",
            "pin_dome.hole_numbering.start_azimuth_deg = 10: must be the azimuth of a hole in every ring",
        ),
        (
            "pin_dome:\n  clearance_mm: 1.5\n  inner_radius_mm: 16.65\n  outer_radius_mm: 19.1\n",
            "pin_dome.clearance_mm = 1.5: give the shell either by",
        ),
        (
            "pin_dome:\n  orientation_mark: {azimuth_range_deg: [65, 66], polar_range_deg: [5.6, 86.5], depth_mm: 3}\n",
            "pin_dome.orientation_mark.depth_mm = 3",
        ),
        (
            "pin_dome:\n  base_tabs: {span_mm: 43, width_mm: 6, height_mm: 4, azimuth_deg: 0}\n",
            "pin_dome.keyed_dowels = true",
        ),
        (
            "pin_dome:\n  holder_ring: {outer_diameter_mm: 42.3, floor_thickness_mm: 1, clearance_mm: 0.2}\n",
            "pin_dome.holder_ring = given: needs pin_dome.base_tabs",
        ),
        (
            "pin_dome:\n  keyed_dowels: false\n  base_tabs: {span_mm: 43, width_mm: 6, height_mm: 4, azimuth_deg: 0}\n  holder_ring: {outer_diameter_mm: 39, floor_thickness_mm: 1, clearance_mm: 0.2}\n",
            "pin_dome.holder_ring.outer_diameter_mm = 39: leaves 0.40 mm of upstand",
        ),
    ];
    for (yaml, expect) in cases {
        let f = tmp.path().join("params.yaml");
        std::fs::write(&f, yaml).unwrap();
        let o = run(
            tmp.path(),
            &[
                "fixtures",
                "rtac0",
                "--params",
                "params.yaml",
                "--out",
                "never",
            ],
            &[],
        );
        assert_eq!(o.status.code(), Some(2), "{yaml}");
        let err = text(&o.stderr);
        assert!(err.contains(expect), "{yaml}: {err}");
        assert!(!tmp.path().join("never").exists());
    }
    // The semi-dome count is bounded before any pattern is generated (--semidomes 4294967295
    // once aborted; 1000 took 4 GB).
    for (n, rule) in [
        (
            "101",
            "with 0 listed patterns makes 101 semi-domes, more than the 100",
        ),
        (
            "4294967295",
            "with 0 listed patterns makes 1000000 semi-domes, more than the 100",
        ),
    ] {
        let o = run(
            tmp.path(),
            &["fixtures", "rtac0", "--semidomes", n, "--out", "never"],
            &[],
        );
        assert_eq!(o.status.code(), Some(2), "{n}");
        let err = text(&o.stderr);
        assert!(
            err.contains(&format!("semidomes.generate = {n}: {rule}")),
            "{n}: {err}"
        );
        assert!(!tmp.path().join("never").exists());
    }
}

/// The summary says in words how the pins sit, for either seat (it printed the Rust names
/// `CounterboreFloor` and `Rim`): no CamelCase word and neither variant name in what
/// `fabkit fixtures` prints.
#[test]
fn the_fixtures_summary_is_in_words_not_rust_names() {
    let tmp = tempfile::tempdir().unwrap();
    for (preset, seat) in [
        (
            Some("default"),
            "seated with the head on the counterbore's floor,",
        ),
        (None, "seated with the head on the rim of its hole,"),
    ] {
        let out = format!("fx_{}", preset.unwrap_or("paper"));
        let mut args = vec!["fixtures", "rtac0", "--semidomes", "1", "--out", &out];
        args.extend(preset.map(|p| ["--pins-preset", p]).into_iter().flatten());
        let o = run(tmp.path(), &args, &[]);
        assert!(o.status.success(), "{preset:?}: {}", text(&o.stderr));
        let said = text(&o.stdout);
        assert!(said.contains(seat), "{preset:?}: {said}");
        let rust_names: Vec<&str> = said
            .split(|c: char| !c.is_ascii_alphanumeric())
            .filter(|w| is_camel_case(w) || ["Rim", "CounterboreFloor"].contains(w))
            .collect();
        assert!(
            rust_names.is_empty(),
            "{preset:?}: {rust_names:?} in {said}"
        );
    }
    assert!(is_camel_case("CounterboreFloor") && !is_camel_case("FDM") && !is_camel_case("Tac0"));
}

/// A word with a capital after a lowercase letter (`CounterboreFloor`): a Rust type or variant
/// name, not an abbreviation (`FDM`) or a word of a sentence.
fn is_camel_case(w: &str) -> bool {
    w.as_bytes()
        .windows(2)
        .any(|p| p[0].is_ascii_lowercase() && p[1].is_ascii_uppercase())
}

/// The output folder is checked before anything is built, as `fabkit export` checks it:
/// `--out /` and a folder of the user's own files are refused first, even for fixtures the
/// triangle bound would refuse (`fixtures --out /` built for seconds before refusing it).
#[test]
fn fixtures_and_export_refuse_an_unusable_out_folder_before_building() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::create_dir(tmp.path().join("mine")).unwrap();
    std::fs::write(tmp.path().join("mine/notes.txt"), "mine").unwrap();
    for (out, want) in [
        ("/", "output directory /: has no final directory name"),
        (
            "mine",
            "output directory mine is not a folder fabkit wrote: `notes.txt`",
        ),
    ] {
        // refused by the triangle bound were the folder checked later
        let fixtures = [
            "fixtures",
            "--semidomes",
            "100",
            "--chord-tolerance-mm",
            "0.001",
            "--out",
            out,
        ];
        let export = [
            "export",
            "shadowtac",
            "--max-triangles",
            "100000",
            "--out",
            out,
        ];
        for args in [&fixtures[..], &export[..]] {
            let o = run(tmp.path(), args, &[]);
            assert_eq!(o.status.code(), Some(2), "{args:?}");
            let e = text(&o.stderr);
            assert!(
                e.contains(want) && !e.contains("triangles"),
                "{args:?}: {e}"
            );
        }
    }
    assert_eq!(
        std::fs::read_to_string(tmp.path().join("mine/notes.txt")).unwrap(),
        "mine"
    );
}
