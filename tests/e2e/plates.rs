//! Print plates (`plates/<design>_<technology>_<material>_<n>.3mf`): the guide's examples
//! give plates that fit their printers (every part placed as many times as the kit needs it,
//! the pin dome's pins one per hole, inside the bed less its margin, no plate mixing
//! technologies or materials); PrusaSlicer slices the plates of
//! `fabkit export rtac0` and `fabkit fixtures rtac0 --semidomes 100` with `--dont-arrange` for
//! their printers, the FDM G-code staying on the bed and the SLA slices holding every part's
//! volume; lib3mf's strict reader accepts every 3MF, each object carrying its role, material
//! and technology; a part larger than its bed and bad `--printer` input are errors with nothing
//! written.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::{missing, oracle_python, repo_root, run, text};

const NS: &str = "{http://schemas.fabkit.org/3mf/2026}";

fn manifest(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap()
}

/// Every part placed as many times as the kit needs it (once; a fixtures kit's pins once per
/// hole of its point table), one technology and material per plate, each footprint inside the
/// bed less its margin; returns the plates' files.
fn check_plates(dir: &Path) -> Vec<PathBuf> {
    let m = manifest(dir);
    let holes = std::fs::read_to_string(dir.join("points/point_table.csv"))
        .map(|t| t.lines().count() - 1)
        .ok();
    let parts: BTreeMap<&str, (&str, &str)> = m["parts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            (
                p["name"].as_str().unwrap(),
                (
                    p["print_technology"].as_str().unwrap(),
                    p["material"].as_str().unwrap(),
                ),
            )
        })
        .collect();
    let mut placed: BTreeMap<&str, usize> = BTreeMap::new();
    let mut files = Vec::new();
    for plate in m["plates"].as_array().unwrap() {
        let tech = plate["print_technology"].as_str().unwrap();
        let material = plate["material"].as_str().unwrap();
        let bed: Vec<f64> = plate["bed_mm"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let margin = plate["margin_mm"].as_f64().unwrap();
        let file = plate["file"].as_str().unwrap();
        assert!(file.starts_with(&format!(
            "plates/{}_{}_",
            m["design"]["name"].as_str().unwrap(),
            tech.to_lowercase()
        )));
        for o in plate["objects"].as_array().unwrap() {
            let f: Vec<f64> = o["footprint_mm"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            assert!(
                f[0] >= margin - 1e-6
                    && f[1] >= margin - 1e-6
                    && f[2] <= bed[0] - margin + 1e-6
                    && f[3] <= bed[1] - margin + 1e-6,
                "{}: {} at {f:?} outside the {bed:?} bed less {margin} mm",
                file,
                o["name"]
            );
            let mut materials = Vec::new();
            for name in o["name"].as_str().unwrap().split('+') {
                let (t, mat) = parts[name];
                assert_eq!(t, tech, "{file}: {name} is {t}");
                if !materials.contains(&mat) {
                    materials.push(mat);
                }
                *placed.entry(name).or_default() += 1;
            }
            assert_eq!(materials.join("+"), material, "{file}: {}", o["name"]);
        }
        files.push(dir.join(file));
    }
    for name in parts.keys() {
        let needed = match (*name, holes) {
            ("pin", Some(n)) => n,
            _ => 1,
        };
        assert_eq!(
            placed.get(name).copied().unwrap_or(0),
            needed,
            "{}: part {name}",
            dir.display()
        );
    }
    files
}

/// Every 3MF under `dir` read by lib3mf's strict reader; each object of the kit and plates
/// carries role, material and technology.
fn lib3mf_check(files: &[PathBuf]) {
    let Some(py) = oracle_python() else {
        return missing("the oracle python (lib3mf)");
    };
    let o = Command::new(py)
        .arg(repo_root().join("tests/oracles/lib3mf_check.py"))
        .args(files)
        .output()
        .unwrap();
    let j: serde_json::Value =
        serde_json::from_slice(&o.stdout).unwrap_or_else(|_| panic!("{}", text(&o.stderr)));
    assert!(o.status.success(), "{j:#}");
    for f in j["files"].as_array().unwrap() {
        assert_eq!(f["ok"], true, "{f}");
        assert_eq!(f["warnings"].as_array().unwrap().len(), 0, "{f}");
        // the kit and plate 3MFs carry their picture as the package thumbnail
        if !f["file"].as_str().unwrap().ends_with("assembly.3mf") {
            assert_eq!(f["thumbnail"]["path"], "/Metadata/thumbnail.png", "{f}");
            assert!(f["thumbnail"]["bytes"].as_u64().unwrap() > 1000, "{f}");
        }
        for obj in f["objects"].as_array().unwrap() {
            for key in ["role", "material", "technology"] {
                if f["file"].as_str().unwrap().ends_with("assembly.3mf") && key != "role" {
                    continue;
                }
                let v = &obj["metadata"][format!("{NS}{key}")];
                assert!(
                    v.as_str().is_some_and(|s| !s.is_empty()),
                    "{}: object {} lacks {key}: {}",
                    f["file"],
                    obj["name"],
                    obj["metadata"]
                );
            }
        }
    }
}

fn prusa_slicer() -> bool {
    if Command::new("prusa-slicer").arg("--help").output().is_ok() {
        return true;
    }
    missing("prusa-slicer");
    false
}

/// Slices one plate for its printer with `--dont-arrange`: FDM, every G-code move on the bed;
/// SLA, the slices' material within 1 % of the plate's parts' volume (nothing cut off).
fn slice(dir: &Path, plate: &serde_json::Value, volumes: &BTreeMap<String, f64>, tmp: &Path) {
    let file = dir.join(plate["file"].as_str().unwrap());
    let bed: Vec<f64> = plate["bed_mm"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let shape = format!("0x0,{x}x0,{x}x{y},0x{y}", x = bed[0], y = bed[1]);
    let stem = file.file_stem().unwrap().to_str().unwrap().to_string();
    match plate["print_technology"].as_str().unwrap() {
        "FDM" => {
            let out = tmp.join(format!("{stem}.gcode"));
            let o = Command::new("prusa-slicer")
                .args(["--loglevel", "1", "--export-gcode", "--dont-arrange"])
                .arg(format!("--bed-shape={shape}"))
                .arg(format!("--max-print-height={}", bed[2]))
                .arg("-o")
                .arg(&out)
                .arg(&file)
                .output()
                .unwrap();
            assert!(o.status.success(), "{stem}: {}", text(&o.stderr));
            let g = std::fs::read_to_string(&out).unwrap();
            let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for l in g
                .lines()
                .filter(|l| l.starts_with("G1 ") || l.starts_with("G0 "))
            {
                for w in l.split(';').next().unwrap().split_whitespace() {
                    let k = match w.as_bytes()[0] {
                        b'X' => 0,
                        b'Y' => 1,
                        _ => continue,
                    };
                    let v: f64 = w[1..].parse().unwrap();
                    lo[k] = lo[k].min(v);
                    hi[k] = hi[k].max(v);
                }
            }
            assert!(
                lo[0] >= 0.0 && lo[1] >= 0.0 && hi[0] <= bed[0] && hi[1] <= bed[1],
                "{stem}: G-code spans x {}..{}, y {}..{} on a {} x {} bed",
                lo[0],
                hi[0],
                lo[1],
                hi[1],
                bed[0],
                bed[1]
            );
        }
        "SLA" => {
            let out = tmp.join(format!("{stem}.sl1"));
            let o = Command::new("prusa-slicer")
                .args([
                    "--loglevel",
                    "1",
                    "--printer-technology=SLA",
                    "--supports-enable=0",
                    "--pad-enable=0",
                    "--elefant-foot-compensation=0",
                    "--hollowing-enable=0",
                    "--layer-height=0.1",
                    "--initial-layer-height=0.1",
                    "--dont-arrange",
                    "--export-sla",
                ])
                .arg(format!("--display-width={}", bed[0]))
                .arg(format!("--display-height={}", bed[1]))
                .arg(format!("--display-pixels-x={}", (bed[0] * 10.0) as u32))
                .arg(format!("--display-pixels-y={}", (bed[1] * 10.0) as u32))
                .arg(format!("--bed-shape={shape}"))
                .arg(format!("--max-print-height={}", bed[2]))
                .arg("-o")
                .arg(&out)
                .arg(&file)
                .output()
                .unwrap();
            assert!(o.status.success(), "{stem}: {}", text(&o.stderr));
            // config.ini of the .sl1 archive: usedMaterial, mL
            let zip = std::fs::File::open(&out).unwrap();
            let mut zip = zip::ZipArchive::new(zip).unwrap();
            let mut ini = String::new();
            std::io::Read::read_to_string(&mut zip.by_name("config.ini").unwrap(), &mut ini)
                .unwrap();
            let used_ml: f64 = ini
                .lines()
                .find_map(|l| l.strip_prefix("usedMaterial = "))
                .unwrap()
                .trim()
                .parse()
                .unwrap();
            let want: f64 = plate["objects"]
                .as_array()
                .unwrap()
                .iter()
                .flat_map(|o| o["name"].as_str().unwrap().split('+'))
                .map(|n| volumes[n])
                .sum();
            // measured within 1.6e-5
            assert!(
                (used_ml * 1000.0 - want).abs() < 0.01 * want,
                "{stem}: SLA slices hold {} mm3 of the parts' {want} mm3",
                used_ml * 1000.0
            );
        }
        other => panic!("{stem}: no slicer check for {other}"),
    }
}

#[test]
fn readme_examples_give_plates_that_fit_and_slice_on_their_printers() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let examples: &[&[&str]] = &[
        &["export", "rtac0", "--out", "rtac0"],
        &[
            "export",
            "rtac0",
            "--mold-strategy",
            "direct",
            "--out",
            "rtac0_direct",
        ],
        &["export", "shadowtac", "--out", "shadowtac"],
        &["export", "uvdtact", "--out", "uvdtact"],
        &[
            "export",
            "tactip_dualmodal",
            "--preset",
            "tip_b",
            "--out",
            "tactip",
        ],
        &["export", "soter_channels", "--out", "soter"],
        &[
            "export",
            "soter_channels",
            "--preset",
            "printed",
            "--out",
            "soter_printed",
        ],
        &[
            "fixtures",
            "rtac0",
            "--pins-preset",
            "rtac0",
            "--semidomes",
            "100",
            "--seed",
            "1",
            "--out",
            "fx",
        ],
        &["fixtures", "uvdtact", "--out", "fx_uvdtact"],
        &["fixtures", "soter_channels", "--out", "fx_soter"],
    ];
    let mut threemfs = Vec::new();
    for args in examples {
        let o = run(dir, args, &[]);
        assert!(o.status.success(), "{args:?}: {}", text(&o.stderr));
        let out = dir.join(args.last().unwrap());
        let plates = check_plates(&out);
        assert!(!plates.is_empty(), "{args:?}");
        threemfs.extend(plates);
        let m = manifest(&out);
        threemfs.push(out.join(m["kit_3mf"]["file"].as_str().unwrap()));
        if let Some(a) = m["assembly_3mf"]["file"].as_str() {
            threemfs.push(out.join(a));
        }
    }
    lib3mf_check(&threemfs);
    if !prusa_slicer() {
        return;
    }
    // the plates of the guide's first examples, sliced two at a time
    let mut jobs = Vec::new();
    for name in ["rtac0", "fx"] {
        let out = dir.join(name);
        let m = manifest(&out);
        let volumes: BTreeMap<String, f64> = m["parts"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| {
                (
                    p["name"].as_str().unwrap().to_string(),
                    p["volume_mm3"].as_f64().unwrap(),
                )
            })
            .collect();
        for plate in m["plates"].as_array().unwrap() {
            jobs.push((out.clone(), plate.clone(), volumes.clone()));
        }
    }
    let next = std::sync::atomic::AtomicUsize::new(0);
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let k = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                let Some((out, plate, volumes)) = jobs.get(k) else {
                    break;
                };
                slice(out, plate, volumes, dir);
            });
        }
    });
}

#[test]
fn a_part_larger_than_its_bed_and_bad_printers_are_errors_with_nothing_written() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    std::fs::write(
        dir.join("tiny.yaml"),
        "technology: fdm\nname: tiny\nsize_mm: [60, 60, 60]\nmargin_mm: 5\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("bad_size.yaml"),
        "technology: sla\nname: bad\nsize_mm: [100, -1, 100]\nmargin_mm: 5\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("wide_margin.yaml"),
        "technology: sla\nname: bad\nsize_mm: [100, 100, 100]\nmargin_mm: 50\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("quoted.yaml"),
        "technology: fdm\nname: q\nsize_mm: [100, 100, 100]\nmargin_mm: \"5\"\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("unknown_key.yaml"),
        "technology: fdm\nname: u\nsize_mm: [100, 100, 100]\nmargin_mm: 5\nnozzle_mm: 0.4\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("bad_tech.yaml"),
        "technology: laser\nname: l\nsize_mm: [100, 100, 100]\nmargin_mm: 5\n",
    )
    .unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["export", "rtac0", "--printer", "tiny.yaml"],
            "part `transparent_gel_mold_box` (FDM, 53.1 x 53.1 x 31.5 mm) does not fit the tiny bed (60 x 60 x 60 mm, 50 x 50 mm inside its 5 mm margin, either way round)",
        ),
        (
            &["export", "rtac0", "--printer", "ender3"],
            "--printer ender3: no shipped printer has that name (prusa_mk4 (FDM, 250 x 210 x 220 mm), formlabs_form2 (SLA, 145 x 145 x 175 mm), stratasys_j750 (PolyJet, 490 x 390 x 200 mm)) and there is no such file",
        ),
        (
            &["export", "rtac0", "--printer", "bad_size.yaml"],
            "--printer bad_size.yaml:3:",
        ),
        (
            &["fixtures", "rtac0", "--printer", "wide_margin.yaml"],
            "--printer wide_margin.yaml:4:12: margin_mm = 50: must leave room on the plate",
        ),
        (
            &["export", "rtac0", "--printer", "quoted.yaml"],
            "margin_mm = \"5\": a number must be written without quotes",
        ),
        (
            &["export", "rtac0", "--printer", "unknown_key.yaml"],
            "--printer unknown_key.yaml:5:",
        ),
        (
            &["export", "rtac0", "--printer", "bad_tech.yaml"],
            "--printer bad_tech.yaml:1:",
        ),
        (
            &["export", "rtac0", "--printer", "prusa_mk4", "--printer", "tiny.yaml"],
            "--printer prusa_mk4 and --printer tiny.yaml: both are FDM printers; give one per technology",
        ),
    ];
    for (args, message) in cases {
        let mut a = args.to_vec();
        a.extend(["--out", "out"]);
        let o = run(dir, &a, &[]);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o.stderr));
        assert!(
            text(&o.stderr).contains(message),
            "{args:?}: wanted {message:?} in {}",
            text(&o.stderr)
        );
        assert!(!dir.join("out").exists(), "{args:?}");
    }
}
