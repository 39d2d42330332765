//! End-to-end: `fabkit export` of the marker designs (ShadowTac, UVDtact, the dual-modal
//! TacTip) and their presets, checked by the independent Python oracle (every output
//! directory), by PrusaSlicer through `printcheck --strict` (every STL and 3MF of the three
//! base designs), and against the papers and the geometry through `manifest.json`.
//!
//! A part with role `marker_tips` (the TacTip dots) only prints together with its skin in one
//! multi-material job, so it is not printchecked alone; the kit 3MF that holds its group is.

use crate::common::*;
use fabkit_designs::library;
use serde_json::Value;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

/// Exports library design `design` (with `preset`) into `<dir>/out/<kit>` from `dir`, and
/// returns that directory and its manifest. (The output goes below `out/` so that no folder
/// named like a design shadows the library design in the working directory.)
fn export(dir: &Path, design: &str, preset: Option<&str>) -> (PathBuf, Value) {
    let kit = match preset {
        Some(p) => format!("{design}_{p}"),
        None => design.to_string(),
    };
    let out = dir.join("out").join(&kit);
    let mut args = vec!["export", design, "--out", out.to_str().unwrap()];
    if let Some(p) = preset {
        args.extend(["--preset", p]);
    }
    let o = run(dir, &args, &[]);
    assert!(
        o.status.success(),
        "fabkit {} failed:\n{}",
        args.join(" "),
        text(&o.stderr)
    );
    let m: Value = serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap())
        .expect("manifest.json parses");
    assert_eq!(m["design"]["name"], kit.as_str());
    (out, m)
}

fn parts(m: &Value) -> &Vec<Value> {
    m["parts"].as_array().expect("parts")
}

fn part<'a>(m: &'a Value, name: &str) -> &'a Value {
    parts(m)
        .iter()
        .find(|p| p["name"] == name)
        .unwrap_or_else(|| panic!("no part {name}"))
}

fn markers_summary(m: &Value) -> &Vec<Value> {
    m["summary"]["markers"].as_array().expect("summary.markers")
}

fn cast<'a>(m: &'a Value, name: &str) -> &'a Value {
    m["casts"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["cast"] == name)
        .unwrap_or_else(|| panic!("no cast {name}"))
}

/// The files to printcheck: every part's STL but the `marker_tips`, and the kit 3MF.
fn printable_files(dir: &Path, m: &Value) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = parts(m)
        .iter()
        .filter(|p| p["role"] != "marker_tips")
        .map(|p| dir.join(p["file"].as_str().unwrap()))
        .collect();
    files.push(dir.join(m["kit_3mf"]["file"].as_str().expect("kit_3mf.file")));
    files
}

/// The skin pour of a ShadowTac design: its solid cap less `n` dimples, each its nominal volume
/// less the slab between its tangent plane and the sphere; and the tessellation bound (area of
/// the cavity and the dimple walls x the chord tolerance).
fn shadowtac_skin_pour(design: &fabkit_designs::schema::Design, n: f64, tol: f64) -> (f64, f64) {
    let rho = design.body.sphere_radius_mm().unwrap();
    let &fabkit_designs::profile::BodyProfile::SphericalCap { height_mm, .. } = &design.body else {
        panic!("a spherical cap")
    };
    let f = &design.layers[0].markers[0].feature;
    let r = f.radius_mm();
    let dome = design.body.analytic_solid_volume_mm3(0.0, 0.0);
    let gap = PI * r.powi(4) * (2.0 / rho) / 8.0;
    let area = 2.0 * PI * rho * height_mm
        + n * (2.0 * PI * r * (f.height_mm - r) + 2.0 * PI * r * r + PI * r * r);
    (dome - n * (f.nominal_volume_mm3() - gap), area * tol)
}

/// ShadowTac (Sec. IV-A; authors' CAD, measured): the two-piece SLA mold (cavity block with
/// 469 pins, top piece with the pour reservoir and 20 bolts) casts 469 dimples, which only SLA
/// prints; the skin pour is the cap less the dimples. The preset `paper_text` (the paper's
/// 35 x 8 mm cap, dimples concentric at 1.4 mm) casts in one open mold.
#[test]
fn shadowtac_kits() {
    let tmp = tempfile::tempdir().unwrap();
    let (dir, m) = export(tmp.path(), "shadowtac", None);
    let pieces: Vec<&Value> = parts(&m)
        .iter()
        .filter(|p| p["role"] == "open_mold_piece")
        .collect();
    assert_eq!(pieces.len(), 2, "{:?}", parts(&m));
    for (p, genus) in pieces.iter().zip([20, 21]) {
        assert_eq!(p["print_technology"], "SLA");
        // one handle per bolt hole; the top piece's bore adds one
        assert_eq!(p["genus"], genus, "{}", p["name"]);
    }
    let mk = markers_summary(&m);
    assert_eq!(mk.len(), 1);
    assert_eq!(mk[0]["count"], 469, "{}", mk[0]);
    assert_eq!(mk[0]["needs_sla_or_finer"], true, "{}", mk[0]);
    assert_eq!(mk[0]["printable_with"], serde_json::json!(["SLA"]));
    assert!(mk[0]["min_spacing_mm"].as_f64().unwrap() >= 0.45 + 0.4);

    let design = library::load("shadowtac").unwrap();
    let tol = m["chord_tolerance_mm"].as_f64().unwrap();
    let (expected, bound) = shadowtac_skin_pour(&design, 469.0, tol);
    let pour = cast(&m, "skin")["cavity_volume_ml"].as_f64().unwrap() * 1000.0;
    assert!(
        (pour - expected).abs() <= bound,
        "skin pour {pour} mm^3, expected {expected} within {bound}"
    );
    assert!(
        m["bought_items"]
            .to_string()
            .contains("Backing (PMMA (acrylic) sheet or machined part)"),
        "{}",
        m["bought_items"]
    );
    oracle_check(&dir);
    // the casing and the gripper base (Sec. IV-B: "two filament-printed components")
    for name in ["casing", "gripper_base"] {
        let p = part(&m, name);
        assert_eq!(p["print_technology"], "FDM", "{name}");
        assert_eq!(p["material"], "pla", "{name}");
        assert_eq!(p["genus"], if name == "casing" { 4 } else { 9 }, "{name}");
    }
    // the envelope: the base's 82.6 mm square, from its bottom to the skin's pole (10 mm of
    // the base under the casing's 24.5 mm, the 3 mm plate, the 8.358 mm skin)
    let env = &m["summary"]["envelope_mm"];
    let h = 10.0 + 24.5 + 3.0 + (22.5 - 200f64.sqrt());
    assert!(
        env[0] == 82.6 && env[1] == 82.6 && (env[2].as_f64().unwrap() - h).abs() < 1e-9,
        "{env}"
    );
    // the camera sees the skin's rim through the window (ShadowTac: 14.95 < 15.5 mm)
    let view = &m["summary"]["camera_view"];
    let cross = view["rim_crossing_radius_mm"].as_f64().unwrap();
    assert!(
        (cross - 14.945).abs() < 1e-3 && cross < view["window_radius_mm"].as_f64().unwrap(),
        "{view}"
    );
    // the two mold pieces, the casing, the base and the kit's 3MF
    let files = printable_files(&dir, &m);
    assert_eq!(files.len(), 5);

    let (pdir, pm) = export(tmp.path(), "shadowtac", Some("paper_text"));
    let molds: Vec<&Value> = parts(&pm)
        .iter()
        .filter(|p| p["role"] == "open_mold")
        .collect();
    assert_eq!(molds.len(), 1, "{:?}", parts(&pm));
    assert_eq!(molds[0]["genus"], 0);
    let mk = markers_summary(&pm);
    assert_eq!(mk[0]["pattern"]["layout"], "concentric");
    let n = mk[0]["count"].as_u64().unwrap() as f64;
    let design = design.with_preset("paper_text").unwrap();
    let (expected, bound) = shadowtac_skin_pour(&design, n, tol);
    let pour = cast(&pm, "skin")["cavity_volume_ml"].as_f64().unwrap() * 1000.0;
    assert!(
        (pour - expected).abs() <= bound,
        "paper_text skin pour {pour} mm^3, expected {expected} within {bound}"
    );
    oracle_check(&pdir);

    printcheck_all(&files);
}

/// UVDtact (Sec. III): boundary molds for three layers (six Mold Star pours, then the three
/// layers inside out); slots and protrusions of 85 (or 43) markers; the two mixed layers
/// together fill the shell between offsets -2.4 and -0.4 mm.
#[test]
fn uvdtact_kits() {
    let tmp = tempfile::tempdir().unwrap();
    let design = library::load("uvdtact").unwrap();
    let (dir, m) = export(tmp.path(), "uvdtact", None);
    let casts: Vec<&str> = m["casts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["cast"].as_str().unwrap())
        .collect();
    assert_eq!(casts.len(), 9, "{casts:?}");
    assert!(
        casts[..6].iter().all(|c| c.starts_with("silicone_mold:")),
        "{casts:?}"
    );
    assert_eq!(casts[6..], ["inner_mixed", "outer_mixed", "black_gel"]);
    for c in &casts[..6] {
        assert_eq!(cast(&m, c)["material"], "mold_star_30");
    }
    let count = |role: &str| parts(&m).iter().filter(|p| p["role"] == role).count();
    assert_eq!(
        (
            count("master_pattern"),
            count("mold_box"),
            count("negative_mold")
        ),
        (3, 3, 3)
    );
    // the fingertip's base (Sec. III-C: "the camera holder, shell holder, and sensor base are
    // fabricated using an SLA 3D printer"; the white SLA diffusion ring)
    for role in [
        "shell_holder",
        "sensor_base",
        "camera_holder",
        "diffusion_ring",
    ] {
        assert_eq!(count(role), 1, "{role}");
    }
    assert_eq!(part(&m, "diffusion_ring")["material"], "sla_white_resin");
    for p in parts(&m) {
        let want = if p["role"] == "mold_box" {
            "FDM"
        } else {
            "SLA"
        };
        assert_eq!(p["print_technology"], want, "{}", p["name"]);
    }
    let tol = m["chord_tolerance_mm"].as_f64().unwrap();
    let (v_out, v_in) = (
        design.body.analytic_solid_volume_mm3(-0.4, 0.0),
        design.body.analytic_solid_volume_mm3(-2.4, 0.0),
    );
    // curved areas of the two offset surfaces, within a few per cent (bounded by the
    // circumscribing cylinder plus disc areas)
    let shell_area = 2.0 * (PI * 9.0 * 9.0 + 2.0 * PI * 9.0 * 24.0);
    let (dir43, m43) = export(tmp.path(), "uvdtact", Some("markers_43"));
    for (mk_dir, mm, n) in [(&dir, &m, 85), (&dir43, &m43, 43)] {
        let mk = markers_summary(mm);
        assert_eq!(mk.len(), 2);
        for x in mk {
            assert_eq!(x["count"], n, "{x}");
        }
        assert_eq!(mk[0]["surface"], "outer");
        assert_eq!(mk[0]["feature"]["polarity"], "recessed");
        assert_eq!(mk[1]["surface"], "inner");
        assert_eq!(mk[1]["feature"]["polarity"], "raised");
        let mixed = (cast(mm, "inner_mixed")["cavity_volume_ml"]
            .as_f64()
            .unwrap()
            + cast(mm, "outer_mixed")["cavity_volume_ml"]
                .as_f64()
                .unwrap())
            * 1000.0;
        assert!(
            (mixed - (v_out - v_in)).abs() <= shell_area * tol,
            "{}: the two mixed layers hold {mixed} mm^3, the shell {}",
            mm["design"]["name"],
            v_out - v_in
        );
        oracle_check(mk_dir);
    }
    printcheck_all(&printable_files(&dir, &m));
    lighting_pcb_outline_passes_ezdxf(&dir, &m);
    acrylic_shell_drawing_reads_back(&dir, &m);
}

/// UVDtact's acrylic shell (Sec. III: CNC machined, vapour polished, 2 mm wall), made to
/// order: `machined/acrylic_shell.svg` parses as XML with its size in mm; each dimension of
/// the manifest is written once with an arrowed dimension line of its value times the
/// drawing's scale; the hatched section's two halves, revolved (Pappus), hold the volume of
/// `machined/acrylic_shell.stl` (read with numpy) less the revolution's chords (under 0.5 %);
/// and the STL's own volume is the manifest's.
fn acrylic_shell_drawing_reads_back(dir: &Path, m: &Value) {
    let shell = &m["machined_parts"][0];
    assert_eq!(shell["name"], "acrylic_shell");
    assert_eq!(shell["material"], "pmma");
    let labels: Vec<&str> = shell["dimensions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["label"].as_str().unwrap())
        .collect();
    assert_eq!(
        labels,
        ["26.60", "Ø13.20", "Ø9.20", "24.60", "2.00", "5.00"],
        "{shell}"
    );
    let Some(py) = oracle_python() else {
        return missing("the oracle python (numpy)");
    };
    let script = r#"
import sys, json, math, re
import xml.etree.ElementTree as ET
import numpy as np
ns = {"s": "http://www.w3.org/2000/svg"}
root = ET.parse(sys.argv[1]).getroot()
texts = ["".join(t.itertext()).strip() for t in root.iter("{http://www.w3.org/2000/svg}text")]
scale = float(re.search(r"scale (\d+):1", " ".join(texts)).group(1))
dims = root.find(".//s:g[@id='dimensions']", ns)
lines = [math.hypot(float(l.get("x2")) - float(l.get("x1")), float(l.get("y2")) - float(l.get("y1"))) / scale
         for l in dims.findall("s:line", ns) if l.get("marker-start")]
labels = ["".join(t.itertext()).strip() for t in dims.findall("s:text", ns)]
vols = []
for poly in root.find(".//s:g[@id='section']", ns).findall("s:polygon", ns):
    p = np.array([[float(v) for v in xy.split(",")] for xy in poly.get("points").split()]) / scale
    x, z = np.abs(p[:, 0]), -p[:, 1]
    x1, z1 = np.roll(x, -1), np.roll(z, -1)
    cross = x * z1 - x1 * z
    area = cross.sum() / 2.0
    cx = ((x + x1) * cross).sum() / (6.0 * area)
    vols.append(abs(2.0 * math.pi * cx * area))
data = open(sys.argv[2], "rb").read()
n = int.from_bytes(data[80:84], "little")
tri = np.frombuffer(data[84:84 + 50 * n], dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))["v"].astype(float)
stl = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0
print(json.dumps({"width": root.get("width"), "height": root.get("height"), "lines": lines,
                  "labels": labels, "section_volumes": vols, "stl_volume": stl}))
"#;
    let o = std::process::Command::new(py)
        .arg("-c")
        .arg(script)
        .arg(dir.join(shell["drawing"].as_str().unwrap()))
        .arg(dir.join(shell["file"].as_str().unwrap()))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    for k in ["width", "height"] {
        assert!(v[k].as_str().unwrap().ends_with("mm"), "{v}");
    }
    let got: Vec<&str> = v["labels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l.as_str().unwrap())
        .collect();
    assert_eq!(got, labels, "{v}");
    for (d, line) in shell["dimensions"]
        .as_array()
        .unwrap()
        .iter()
        .zip(v["lines"].as_array().unwrap())
    {
        let (want, got) = (d["value_mm"].as_f64().unwrap(), line.as_f64().unwrap());
        // measured 0 (the drawing writes the value's own digits)
        assert!((want - got).abs() < 2e-3, "{d}: drawn {got} mm");
    }
    let vol = shell["volume_mm3"].as_f64().unwrap();
    let stl = v["stl_volume"].as_f64().unwrap();
    // the STL's float32 vertices move each by 6e-8 relative: the volume by about 1e-7
    assert!((stl - vol).abs() < 1e-6 * vol, "{stl} vs {vol}");
    for s in v["section_volumes"].as_array().unwrap() {
        let s = s.as_f64().unwrap();
        assert!(s >= vol && s < 1.005 * vol, "section {s} vs {vol}");
    }
}

/// UVDtact's lighting PCB outline (Sec. III-C: 4 white and 4 UV LEDs alternating every
/// 45 deg): `pcb/lighting_pcb.dxf` passes ezdxf's audit with nothing to fix (R2000 or later,
/// mm); on `cut` the 12 mm board less its 3.2 mm bore, on `engrave` the 8 LED places on the
/// 8 mm circle, 45 deg apart from +x.
fn lighting_pcb_outline_passes_ezdxf(dir: &Path, m: &Value) {
    let pcb = &m["pcb_outlines"][0];
    assert_eq!(pcb["name"], "lighting_pcb");
    let area = PI * (6.0f64.powi(2) - 1.6f64.powi(2));
    assert!(
        (pcb["area_mm2"].as_f64().unwrap() - area).abs() < 1e-9,
        "{pcb}"
    );
    let Some(py) = oracle_python() else {
        return missing("the oracle python (ezdxf)");
    };
    let script = r#"
import sys, json, math, ezdxf
doc = ezdxf.readfile(sys.argv[1])
a = doc.audit()
msp = doc.modelspace()
cut = sorted((e.dxf.radius for e in msp.query('CIRCLE[layer=="cut"]')), reverse=True)
leds = [e.dxf.center for e in msp.query('CIRCLE[layer=="engrave"]')]
print(json.dumps({
    "version": doc.dxfversion, "units": doc.units, "errors": len(a.errors), "fixes": len(a.fixes),
    "area": math.pi * cut[0] ** 2 - sum(math.pi * r ** 2 for r in cut[1:]),
    "led_radii": [math.hypot(c.x, c.y) for c in leds],
    "led_deg": sorted(round(math.degrees(math.atan2(c.y, c.x)) % 360.0, 9) for c in leds),
}))
"#;
    let o = std::process::Command::new(py)
        .arg("-c")
        .arg(script)
        .arg(dir.join(pcb["dxf"].as_str().unwrap()))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["version"].as_str().unwrap() >= "AC1015", "{v}");
    assert_eq!(v["units"], 4, "{v}"); // millimetres
    assert_eq!(
        (v["errors"].as_u64(), v["fixes"].as_u64()),
        (Some(0), Some(0)),
        "{v}"
    );
    assert!((v["area"].as_f64().unwrap() - area).abs() < 1e-9, "{v}");
    let radii = v["led_radii"].as_array().unwrap();
    assert_eq!(radii.len(), 8, "{v}");
    assert!(
        radii
            .iter()
            .all(|r| (r.as_f64().unwrap() - 4.0).abs() < 1e-9),
        "{v}"
    );
    for (k, a) in v["led_deg"].as_array().unwrap().iter().enumerate() {
        let a = a.as_f64().unwrap();
        let d = (a - 45.0 * k as f64).abs();
        assert!(d < 1e-6 || (360.0 - d).abs() < 1e-6, "{v}");
    }
}

/// The dual-modal TacTip (Pestell et al. Sec. III-A, III-D): a PolyJet skin with pins, white
/// pin tips and the bayonet fitting, printed together as one multi-material group, and the ABS
/// body on FDM; layouts A to D.
#[test]
fn tactip_kits() {
    let tmp = tempfile::tempdir().unwrap();
    let mut base = None;
    for (preset, spacing, diameter) in [
        (None, 3.0, 1.0),
        (Some("tip_b"), 4.0, 1.0),
        (Some("tip_c"), 4.5, 1.0),
        (Some("tip_d"), 4.5, 1.7),
    ] {
        let (dir, m) = export(tmp.path(), "tactip_dualmodal", preset);
        let name = m["design"]["name"].as_str().unwrap().to_string();
        let (skin, tips) = (part(&m, "skin"), part(&m, "skin_tips"));
        assert_eq!(skin["role"], "printed_skin", "{name}");
        assert_eq!(tips["role"], "marker_tips", "{name}");
        assert!(skin["group"].is_string(), "{name}: group {}", skin["group"]);
        assert_eq!(skin["group"], tips["group"], "{name}");
        for p in [skin, tips] {
            assert_eq!(p["print_technology"], "PolyJet", "{name}");
        }
        assert_eq!(skin["material"], "tango_black_plus");
        assert_eq!(tips["material"], "vero_white");
        let mk = markers_summary(&m);
        assert_eq!(mk.len(), 1);
        assert_eq!(mk[0]["pattern"]["spacing_mm"], spacing, "{name}");
        assert_eq!(mk[0]["feature"]["diameter_mm"], diameter, "{name}");
        // each tip is a hemisphere of the pin's radius
        let n = mk[0]["count"].as_f64().unwrap();
        let r: f64 = diameter / 2.0;
        let v_tips = n * 2.0 / 3.0 * PI * r.powi(3);
        let tol = m["chord_tolerance_mm"].as_f64().unwrap();
        let v = tips["volume_mm3"].as_f64().unwrap();
        assert!(
            (v - v_tips).abs() <= n * 3.0 * PI * r * r * tol,
            "{name}: tips {v} mm^3 vs {n} hemispheres {v_tips}"
        );
        // the group is one 3MF object with a volume per part
        let objects = m["kit_3mf"]["objects"].as_array().unwrap();
        let grouped: Vec<&Value> = objects
            .iter()
            .filter(|o| o["group"] == skin["group"])
            .collect();
        assert_eq!(grouped.len(), 1, "{name}: {objects:?}");
        let volumes: Vec<&Value> = grouped[0]["volumes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| &v["part"])
            .collect();
        // the bayonet fitting (Vero White) prints with them, a third volume of the object
        assert_eq!(volumes, ["skin", "skin_tips", "tip_fitting"], "{name}");
        let (fitting, body) = (part(&m, "tip_fitting"), part(&m, "shaft_body"));
        assert_eq!(fitting["group"], skin["group"], "{name}");
        assert_eq!(fitting["print_technology"], "PolyJet", "{name}");
        assert_eq!(fitting["material"], "vero_white", "{name}");
        assert_eq!(body["print_technology"], "FDM", "{name}");
        assert_eq!(body["material"], "abs", "{name}");
        oracle_check(&dir);
        if preset.is_none() {
            base = Some((dir, m));
        }
    }
    let (dir, m) = base.unwrap();
    let files = printable_files(&dir, &m);
    assert!(!files.iter().any(|f| f.ends_with("parts/skin_tips.stl")));
    // skin, fitting, body, robot mount and the kit's 3MF
    assert_eq!(files.len(), 5);
    printcheck_all(&files);
    // The tips alone are 107 separate islands that only a layered multi-material process (PolyJet,
    // like SLA: no FDM bed adhesion, no empty-layer rule) prints, beside the skin: checked with the
    // resin slicer only.
    let tips = dir.join(part(&m, "skin_tips")["file"].as_str().unwrap());
    printcheck_all_with(&[tips], &["--no-fdm"]);
}

/// The tutorial's design (R-Tac0 with 127 dimples on the translucent gel, under the sprayed
/// coat), exported with its `master` molds and with `--mold-strategy direct`: the parts that
/// form the dimples are named in the manifest and the command's summary, the oracle reads every
/// output back, and every part and the kit 3MF pass `printcheck --strict`.
#[test]
fn tutorial_markers_under_the_coat_kits() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let o = run(dir, &["show", "rtac0", "--out", "my_sensor.yaml"], &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let yaml = std::fs::read_to_string(dir.join("my_sensor.yaml")).unwrap().replace(
        "  - name: translucent_gel\n",
        "  - name: translucent_gel\n    markers:\n      - surface: outer\n        feature: {diameter_mm: 0.6, height_mm: 0.4, on_skin: dimple}\n        pattern: {layout: concentric_6k, rings: 6, polar_step_deg: 6.0}\n",
    );
    std::fs::write(dir.join("my_sensor.yaml"), yaml).unwrap();
    let mut files = Vec::new();
    for (strategy, carriers) in [
        ("master", vec!["translucent_gel_master_pattern"]),
        (
            "direct",
            vec!["translucent_gel_mold_half_a", "translucent_gel_mold_half_b"],
        ),
    ] {
        let out = dir.join("out").join(strategy);
        let o = run(
            dir,
            &[
                "export",
                "my_sensor.yaml",
                "--mold-strategy",
                strategy,
                "--out",
                out.to_str().unwrap(),
            ],
            &[],
        );
        assert!(o.status.success(), "{}", text(&o.stderr));
        let stdout = text(&o.stdout);
        assert!(
            stdout.contains(&format!(
                "formed by {}: 127 dimple formers, 0.400 mm (under 0.100 mm of coat)",
                carriers.join(", ")
            )),
            "{stdout}"
        );
        let m: Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap())
                .unwrap();
        let sets = markers_summary(&m);
        assert_eq!(sets.len(), 1);
        assert_eq!(sets[0]["count"], 127);
        assert_eq!(sets[0]["formed_by"], serde_json::json!(carriers));
        for c in &carriers {
            part(&m, c);
        }
        oracle_check(&out);
        files.extend(printable_files(&out, &m));
    }
    printcheck_all(&files);
}
