//! End-to-end: `fabkit export soter_channels` and `fabkit fixtures soter_channels`, the flat
//! skin of Soter et al. (Sec. II-A): its two casting trays read back by the independent oracle
//! and sliced by PrusaSlicer, its pours against the layers' exact volumes, the filling
//! procedure on the sheet, the trays' laser-cut sheets read back by ezdxf (DXF), as SVG and as
//! STL, and bad channel, grid and sheet values refused by path with nothing written; its
//! indenter grid plate, pin, point table and capture plan.

use crate::common::*;
use serde_json::Value;
use std::f64::consts::PI;

/// The kit: a tray per layer (the channel layer's with 16 ribs, the marker layer's with 100
/// holes), closed and printable; the channel layer poured first, each pour the layer's exact
/// volume (80 x 80 mm less the four 5 mm corners; 3 mm less 16 channels of 1.5 x 1.5 x 70 mm;
/// 2 mm plus 100 markers of 1.5 mm ending in hemispheres, 2 mm long); the liquid per channel
/// on the sheet; the `one_closed` preset leaves the tubes' display ends open.
#[test]
fn soter_channels_kit() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run(
        tmp.path(),
        &["export", "soter_channels", "--out", "out/s"],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let dir = tmp.path().join("out/s");
    let m: Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    let parts = m["parts"].as_array().unwrap();
    let names: Vec<&str> = parts.iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["marker_layer_tray", "channel_layer_tray"]);
    // laser-cut trays (the library default): a registration hole in each corner
    assert!(parts
        .iter()
        .all(|p| p["role"] == "casting_tray" && p["genus"] == 4));
    let area = 80.0 * 80.0 - (4.0 - PI) * 25.0;
    // flat-ended markers: straight through their sheet
    let marker = PI * 0.75f64.powi(2) * 2.0;
    let casts = m["casts"].as_array().unwrap();
    assert_eq!(casts[0]["cast"], "channel_layer");
    assert_eq!(casts[1]["cast"], "marker_layer");
    let ml = |i: usize| casts[i]["cavity_volume_ml"].as_f64().unwrap();
    assert!((ml(0) - (area * 3.0 - 16.0 * 1.5 * 1.5 * 70.0) / 1000.0).abs() < 1e-9);
    assert!((ml(1) - (area * 2.0 + 100.0 * marker) / 1000.0).abs() < 1e-9);
    let per = m["summary"]["flat"]["channels"][0]["liquid_per_channel_ml"]
        .as_f64()
        .unwrap();
    let want = (157.5 - PI * 5.0 + PI * 0.25 * 300.0) / 1000.0;
    assert!((per - want).abs() < 1e-12, "{per}");
    let sheet = std::fs::read_to_string(dir.join("FABRICATION.md")).unwrap();
    assert!(
        sheet.contains(&format!("{want:.3} mL per channel")),
        "{sheet}"
    );
    assert!(sheet.contains("close each tube's display end"), "{sheet}");
    oracle_check(&dir);
    let mut files: Vec<std::path::PathBuf> = parts
        .iter()
        .map(|p| dir.join(p["file"].as_str().unwrap()))
        .collect();
    files.push(dir.join(m["kit_3mf"]["file"].as_str().unwrap()));
    printcheck_all(&files);

    let o = run(
        tmp.path(),
        &[
            "export",
            "soter_channels",
            "--preset",
            "one_closed",
            "--out",
            "out/o",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let sheet = std::fs::read_to_string(tmp.path().join("out/o/FABRICATION.md")).unwrap();
    assert!(
        sheet.contains("the tubes' display ends stay open"),
        "{sheet}"
    );

    // printed trays: no sheets, the markers ending in hemispheres
    let o = run(
        tmp.path(),
        &[
            "export",
            "soter_channels",
            "--preset",
            "printed",
            "--out",
            "out/p",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let m: Value =
        serde_json::from_slice(&std::fs::read(tmp.path().join("out/p/manifest.json")).unwrap())
            .unwrap();
    assert!(m["parts"]
        .as_array()
        .unwrap()
        .iter()
        .all(|p| p["genus"] == 0));
    assert_eq!(m["cut_parts"].as_array().map_or(0, Vec::len), 0);
    let marker = PI * 0.75f64.powi(2) * (2.0 - 0.75) + 2.0 / 3.0 * PI * 0.75f64.powi(3);
    let ml = m["casts"][1]["cavity_volume_ml"].as_f64().unwrap();
    assert!((ml - (area * 2.0 + 100.0 * marker) / 1000.0).abs() < 1e-9);
}

/// Reads every laser-cut sheet of an export with ezdxf (audit), the SVG (its `cut` group's
/// paths) and the sheet's STL: (name, DXF area, SVG area, STL volume, audit errors and fixes,
/// DXF version and units) per sheet, areas as the outer path less the holes, mm^2.
fn read_sheets(dir: &std::path::Path) -> Option<Vec<Value>> {
    let py = oracle_python()?;
    let script = r#"
import sys, json, struct, pathlib, xml.etree.ElementTree as ET
import numpy as np, ezdxf
d = pathlib.Path(sys.argv[1])
m = json.loads((d / "manifest.json").read_text())
def shoelace(p):
    p = np.asarray(p, float)
    return 0.5 * float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))
def region(areas):
    areas = sorted((abs(a) for a in areas), reverse=True)
    return areas[0] - sum(areas[1:])
out = []
for c in m["cut_parts"]:
    doc = ezdxf.readfile(d / c["dxf"])
    a = doc.audit()
    polys = [[(x, y) for x, y, *_ in e.get_points()] for e in doc.modelspace().query('LWPOLYLINE[layer=="cut"]')]
    closed = all(e.closed for e in doc.modelspace().query('LWPOLYLINE'))
    ns = {"s": "http://www.w3.org/2000/svg"}
    def cut_rings(root):
        rings, strokes = [], []
        for g in root.findall("s:g", ns):
            if g.get("id") != "cut":
                continue
            strokes.append(float(g.get("stroke-width")))
            for path in g.findall("s:path", ns):
                toks = path.get("d").replace("Z", "").split()
                rings.append([tuple(float(v) for v in t[1:].split(",")) for t in toks])
        return rings, strokes
    rings, laser_strokes = cut_rings(ET.parse(d / c["svg"]).getroot())
    preview = ET.parse(d / c["preview_svg"]).getroot()
    preview_rings, preview_strokes = cut_rings(preview)
    texts = [t.text for t in preview.iter("{http://www.w3.org/2000/svg}text")]
    raw = (d / c["stl"]).read_bytes()
    n = struct.unpack("<I", raw[80:84])[0]
    tri = np.frombuffer(raw[84:84 + 50 * n], dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))["v"].astype(float)
    vol = float(np.sum(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])))) / 6.0
    out.append({"name": c["name"], "dxf_area": region([shoelace(p) for p in polys]),
                "svg_area": region([shoelace(r) for r in rings]), "stl_volume": vol,
                "preview_area": region([shoelace(r) for r in preview_rings]),
                "laser_strokes": laser_strokes, "preview_strokes": preview_strokes, "texts": texts,
                "errors": len(a.errors), "fixes": len(a.fixes), "closed": closed,
                "version": doc.dxfversion, "units": doc.units, "measurement": doc.header.get("$MEASUREMENT"),
                "rings": len(polys)})
print(json.dumps(out))
"#;
    Some(python_json(&py, script, &[dir.as_os_str()]))
}

/// Runs the Python `script` with `args` and parses the JSON list it prints; a failure fails the
/// test with its stderr.
fn python_json(py: &std::path::Path, script: &str, args: &[&std::ffi::OsStr]) -> Vec<Value> {
    let o = std::process::Command::new(py)
        .arg("-c")
        .arg(script)
        .args(args)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// The laser-cut trays' sheets (Soter et al. Sec. II-A: laser-cut molds): each sheet's DXF
/// passes ezdxf's audit with nothing to fix (R2000 or later, mm and metric, closed polylines on
/// `cut`);
/// its DXF area equals its SVG area and the manifest's; its STL is one sheet, whose section
/// (volume / thickness) is the nominal sheet's area; the paths enclose more than the sheet (the
/// kerf taken outside it). With every kerf 0, the DXF and SVG areas equal the STL's section
/// area within 1e-6. Every sheet's STL is closed and printable.
#[test]
fn soter_laser_cut_sheets_read_back() {
    let tmp = tempfile::tempdir().unwrap();
    let yaml =
        std::fs::read_to_string(repo_root().join("designs/library/soter_channels.yaml")).unwrap();
    let zero = yaml
        .replace("kerf_mm: 0.15", "kerf_mm: 0.0")
        .replace("kerf_mm: 0.12", "kerf_mm: 0.0")
        .replace("kerf_mm: 0.10", "kerf_mm: 0.0");
    assert_eq!(zero.matches("kerf_mm: 0.0").count(), 3);
    write_design(
        &tmp.path().join("zero_kerf.yaml"),
        &zero,
        SchemaVerdict::Accepts,
    );
    for (design, out) in [("soter_channels", "out/k"), ("zero_kerf.yaml", "out/z")] {
        let o = run(tmp.path(), &["export", design, "--out", out], &[]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        let dir = tmp.path().join(out);
        let m: Value =
            serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
        let cut = m["cut_parts"].as_array().unwrap();
        let names: Vec<&str> = cut.iter().map(|c| c["name"].as_str().unwrap()).collect();
        assert_eq!(
            names,
            [
                "marker_layer_tray_1_base",
                "marker_layer_tray_2_markers",
                "marker_layer_tray_3_wall",
                "channel_layer_tray_1_base",
                "channel_layer_tray_2_ribs",
                "channel_layer_tray_3_wall"
            ]
        );
        let stls: Vec<std::path::PathBuf> = cut
            .iter()
            .map(|c| dir.join(c["stl"].as_str().unwrap()))
            .collect();
        printcheck_all(&stls);
        let Some(read) = read_sheets(&dir) else {
            return missing("the oracle python (ezdxf, numpy)");
        };
        for (c, r) in cut.iter().zip(&read) {
            let name = c["name"].as_str().unwrap();
            assert!(r["version"].as_str().unwrap() >= "AC1015", "{r}");
            assert_eq!(r["units"], 4, "{r}"); // $INSUNITS: millimetres
            assert_eq!(r["measurement"], 1, "{r}"); // $MEASUREMENT: metric, agreeing
            assert_eq!(
                (r["errors"].as_u64(), r["fixes"].as_u64()),
                (Some(0), Some(0)),
                "{r}"
            );
            assert_eq!(r["closed"], true, "{r}");
            let f = |k: &str| r[k].as_f64().unwrap();
            let (dxf, svg) = (f("dxf_area"), f("svg_area"));
            let section = f("stl_volume") / c["thickness_mm"].as_f64().unwrap();
            let nominal = c["nominal_area_mm2"].as_f64().unwrap();
            assert!(
                (dxf - svg).abs() <= 1e-9 * dxf,
                "{name}: DXF {dxf} vs SVG {svg}"
            );
            // issue 102: the laser's SVG keeps its hairline; its preview draws the same paths
            // in strokes a browser shows, labelled with the part's name
            assert_eq!(r["laser_strokes"], serde_json::json!([0.01]), "{r}");
            assert_eq!(r["preview_strokes"], serde_json::json!([0.25]), "{r}");
            assert!((f("preview_area") - svg).abs() <= 1e-9 * svg, "{r}");
            assert!(
                r["texts"][0].as_str().is_some_and(|t| t.contains(name)),
                "{r}"
            );
            assert!(
                (dxf - c["area_mm2"].as_f64().unwrap()).abs() <= 1e-9 * dxf,
                "{name}: DXF {dxf} vs manifest {}",
                c["area_mm2"]
            );
            // float32 STL vertices: the section within 1e-6
            assert!(
                (section - nominal).abs() <= 1e-6 * nominal,
                "{name}: STL section {section} vs {nominal}"
            );
            if out == "out/z" {
                assert!(
                    (dxf - section).abs() <= 1e-6 * dxf,
                    "{name}: DXF {dxf} vs STL section {section}"
                );
            } else {
                assert!(
                    dxf > nominal,
                    "{name}: the path encloses the kerf: {dxf} vs {nominal}"
                );
            }
        }
        let sheet = std::fs::read_to_string(dir.join("FABRICATION.md")).unwrap();
        assert!(sheet.contains("Laser-cut the trays' sheets"), "{sheet}");
    }
}

/// Channels wider than their pitch allows, channels that break through the skin's face, a
/// marker grid that does not fit the outline, a kerf wider than a slot, registration holes
/// too wide for the wall and a sheet no stock makes are refused by path (exit 2), nothing
/// written.
#[test]
fn bad_flat_values_write_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let yaml =
        std::fs::read_to_string(repo_root().join("designs/library/soter_channels.yaml")).unwrap();
    for (from, to, expect) in [
        (
            "      width_mm: 1.5 ",
            "      width_mm: 3.8 ",
            "layers[1].channels.width_mm = 3.8: channels 3.8 mm wide at a 4 mm pitch leave less than min_wall_mm",
        ),
        (
            "      height_mm: 1.5 ",
            "      height_mm: 2.8 ",
            "layers[1].channels.height_mm = 2.8: the channel breaks through the skin's face",
        ),
        (
            "      pitch_mm: 6.5 ",
            "      pitch_mm: 8.5 ",
            "layers[0].marker_grid.pitch_mm = 8.5: a 10 x 10 grid at this pitch does not fit the 80 x 80 mm outline",
        ),
        // laser-cut sheets: a kerf wider than the 1.5 mm marker holes, registration holes
        // too wide for the 6 mm wall, no stock for the 1.5 mm rib sheet
        (
            "thickness_mm: 2.0, kerf_mm: 0.12}",
            "thickness_mm: 2.0, kerf_mm: 1.6}",
            "mold.laser_cut.stock[1].kerf_mm = 1.6: is wider than a slot of sheet marker_layer_tray_2_markers",
        ),
        (
            "registration: {diameter_mm: 3.0}",
            "registration: {diameter_mm: 4.5}",
            "mold.laser_cut.registration.diameter_mm = 4.5: must be above 0 and leave 1 mm of the 6 mm wall",
        ),
        (
            "      - {name: acrylic_1_5mm, material: pmma, thickness_mm: 1.5, kerf_mm: 0.10}\n",
            "",
            "layers[1].channels.height_mm = 1.5: the ribs sheets of channel_layer's tray must be made of mold.laser_cut.stock",
        ),
    ] {
        assert!(yaml.contains(from), "{from}");
        let bad = yaml.replacen(from, to, 1);
        // each a rule between parameters (the pitch, the wall, the sheets): the schema accepts it
        write_design(&tmp.path().join("bad.yaml"), &bad, SchemaVerdict::Accepts);
        let o = run(tmp.path(), &["export", "bad.yaml", "--out", "out/bad"], &[]);
        assert_eq!(o.status.code(), Some(2), "{to}");
        let err = text(&o.stderr);
        assert!(err.contains(expect), "{expect}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(!tmp.path().join("out").exists());
    }
}

/// `fabkit fixtures soter_channels`: the indenter grid plate and its pin, closed and
/// printable, and the point table (49 holes on the 10 mm grid, their contact points on the
/// face 5 mm up and the tips 1 mm under it) with the capture plan covering every pin once,
/// read back as CSV by pandas.
#[test]
fn soter_channels_grid_plate() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run(
        tmp.path(),
        &["fixtures", "soter_channels", "--out", "fx"],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("grid plate: 49 holes in 13 captures"),
        "{}",
        text(&o.stdout)
    );
    let dir = tmp.path().join("fx");
    oracle_check(&dir);
    printcheck_all(&[dir.join("parts/grid_plate.stl"), dir.join("parts/pin.stl")]);
    let Some(py) = oracle_python() else {
        return missing("the oracle python (pandas)");
    };
    let script = r##"
import sys, json
import pandas as pd
t = pd.read_csv(sys.argv[1] + "/points/point_table.csv", comment="#")
c = pd.read_csv(sys.argv[1] + "/points/capture_plan.csv")
print(json.dumps({"n": len(t), "contact_z": sorted(set(t.contact_z_mm)), "tip_z": sorted(set(t.tip_z_mm)),
    "xs": sorted(set(t.contact_x_mm)), "ids": sorted(c.id.tolist()), "captures": int(c.capture.max())}))
"##;
    let o = std::process::Command::new(py)
        .arg("-c")
        .arg(script)
        .arg(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["n"], 49, "{v}");
    assert_eq!(v["contact_z"], serde_json::json!([5.0]), "{v}");
    assert_eq!(v["tip_z"], serde_json::json!([4.0]), "{v}");
    assert_eq!(
        v["xs"],
        serde_json::json!([-30.0, -20.0, -10.0, 0.0, 10.0, 20.0, 30.0]),
        "{v}"
    );
    assert_eq!(
        v["ids"],
        serde_json::json!((1..=49).collect::<Vec<_>>()),
        "{v}"
    );
    assert_eq!(v["captures"], 13, "{v}");
}

/// Reads each exported sheet's DXF and the published DXF it reproduces with ezdxf, flattens
/// both (ezdxf's paths: lines, arcs, circles, polylines; within 0.0005 mm), samples their
/// boundaries every 0.005 mm and returns per pair (exported name, the exported DXF's polylines,
/// the symmetric Hausdorff distance between the two drawings, mm; audit errors).
fn compare_to_published(dir: &std::path::Path, pairs: &[(&str, &str)]) -> Option<Vec<Value>> {
    let py = oracle_python()?;
    let script = r#"
import sys, json, pathlib
import numpy as np, ezdxf
from ezdxf import path as ezpath
from scipy.spatial import cKDTree
d, published = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
def samples(doc):
    pts = []
    for e in doc.modelspace():
        if e.dxftype() not in ("LINE", "ARC", "CIRCLE", "LWPOLYLINE", "POLYLINE"):
            continue
        v = np.array([(p.x, p.y) for p in ezpath.make_path(e).flattening(0.0005)], float)
        for a, b in zip(v[:-1], v[1:]):
            n = max(1, int(np.ceil(np.hypot(*(b - a)) / 0.005)))
            t = np.linspace(0.0, 1.0, n + 1)[:, None]
            pts.append(a + t * (b - a))
    return np.vstack(pts)
out = []
for name, ref in json.loads(sys.argv[3]):
    mine = ezdxf.readfile(d / "cut" / f"{name}.dxf")
    theirs = ezdxf.readfile(published / ref)
    a, b = samples(mine), samples(theirs)
    h = max(cKDTree(b).query(a)[0].max(), cKDTree(a).query(b)[0].max())
    out.append({"name": name, "hausdorff_mm": float(h), "errors": len(mine.audit().errors),
                "polylines": len(mine.modelspace().query("LWPOLYLINE"))})
print(json.dumps(out))
"#;
    let published = repo_root().join("tests/data/9dtact_published_cad");
    let pairs = serde_json::to_string(pairs).unwrap();
    Some(python_json(
        &py,
        script,
        &[dir.as_os_str(), published.as_os_str(), pairs.as_ref()],
    ))
}

/// 9DTact's gel stack in its published laser-cut molds (the library design `ninedtact`: the
/// translucent gel, the black gel wrapping it 0.8 mm round its sides, the published plates,
/// kerf 0): `fabkit export ninedtact` writes the three published sheets (and the housing's
/// window), each DXF within 0.01 mm of the published one as ezdxf reads
/// both (outline, pocket and holes; at a 0.001 mm chord tolerance), each sheet's STL passes
/// `printcheck --strict`, and the pours are the published molds' gel volumes within 1 %
/// (translucent 1657.2 mm3, black 433.6 mm3).
#[test]
fn ninedtact_sheets_are_the_published_ones() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run(
        tmp.path(),
        &[
            "export",
            "ninedtact",
            "--out",
            "out",
            "--chord-tolerance-mm",
            "0.001",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let dir = tmp.path().join("out");
    let m: Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    let cut = m["cut_parts"].as_array().unwrap();
    let names: Vec<&str> = cut.iter().map(|c| c["name"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        [
            "translucent_gel_tray_1_base",
            "translucent_gel_tray_2_wall",
            "black_gel_tray_2_wall",
            "window"
        ]
    );
    for (cast, published) in [("translucent_gel", 1657.2), ("black_gel", 433.6)] {
        let c = m["casts"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["cast"] == cast)
            .unwrap();
        let mm3 = c["cavity_volume_ml"].as_f64().unwrap() * 1000.0;
        assert!(
            (mm3 / published - 1.0).abs() < 0.01,
            "{cast}: {mm3} mm3 against the published {published}"
        );
    }
    let stls: Vec<std::path::PathBuf> = cut
        .iter()
        .filter(|c| c["name"] != "window")
        .map(|c| dir.join(c["stl"].as_str().unwrap()))
        .collect();
    // FDM and SLA: the 2.8 mm sheet is sliced into 56 layers of 0.05 mm, its top stored as
    // the f32 not below 2.8 (Mesh::rounded_to_f32)
    printcheck_all(&stls);
    let pairs = [
        (
            "translucent_gel_tray_1_base",
            "mold_base_thickness_3.0mm.DXF",
        ),
        ("translucent_gel_tray_2_wall", "mold_1_thickness_2.5mm.DXF"),
        ("black_gel_tray_2_wall", "mold_2_thickness_2.8mm.DXF"),
    ];
    let Some(read) = compare_to_published(&dir, &pairs) else {
        return missing("the oracle python (ezdxf, numpy, scipy)");
    };
    for (r, rings) in read.iter().zip([13, 10, 10]) {
        assert_eq!(r["errors"], 0, "{r}");
        assert_eq!(r["polylines"], rings, "{r}");
        let h = r["hausdorff_mm"].as_f64().unwrap();
        assert!(h < 0.01, "{r}");
    }
}

/// 9DTact's housing (the library design `ninedtact`: the published numbers, read off the STEP
/// files): `fabkit export ninedtact` writes the shell, the base and the isolation ring, each
/// within 0.02 mm of the published STEP (two-sided, sampled every 0.1 mm, measured by OCCT and
/// libigl in tests/oracles/published_step.py; the issue asks 0.05 mm of the outer form, and the
/// whole part holds) and of its volume within 0.1 %; each STL passes `printcheck --strict`. The
/// window is cut to the chamber less its clearance, as thick as the chamber above the collar.
#[test]
fn ninedtact_housing_is_the_published_shell_base_and_ring() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run(tmp.path(), &["export", "ninedtact", "--out", "out"], &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let dir = tmp.path().join("out");
    let m: Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    let window = m["cut_parts"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == "window")
        .expect("the window's drawing");
    assert!((window["thickness_mm"].as_f64().unwrap() - 10.4).abs() < 1e-9);
    // sensor frame -> each file's frame: the shell's y runs down from the skin's face, the
    // base's up from its bottom face (22.5 mm below the skin's face), the ring's up from the
    // plate's underside (13.2 mm below it)
    let parts = [
        (
            "flat_shell",
            "sensor_shell.STEP",
            "[[1,0,0,0],[0,0,-1,0],[0,1,0,0]]",
        ),
        (
            "flat_base",
            "sensor_base.STEP",
            "[[-1,0,0,0],[0,0,1,22.5],[0,1,0,0]]",
        ),
        (
            "isolation_ring",
            "isolation_ring.STEP",
            "[[1,0,0,0],[0,0,1,13.2],[0,-1,0,0]]",
        ),
    ];
    let stls: Vec<std::path::PathBuf> = parts
        .iter()
        .map(|(name, _, _)| dir.join(format!("parts/{name}.stl")))
        .collect();
    printcheck_all(&stls);
    let Some(py) = cadquery_python() else {
        eprintln!("SKIPPED: 9DTact's housing against its STEP files (set FABKIT_CADQUERY_PYTHON; .ci/run does)");
        return;
    };
    for (name, step, t_step) in parts {
        let p = m["parts"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == name)
            .unwrap();
        let o = std::process::Command::new(&py)
            .arg(repo_root().join("tests/oracles/published_step.py"))
            .arg(
                repo_root()
                    .join("tests/data/9dtact_published_cad")
                    .join(step),
            )
            .arg(dir.join(format!("parts/{name}.stl")))
            .arg(p["params"]["T_print_sensor"].to_string())
            .arg(t_step)
            .output()
            .unwrap();
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        let r: Value = serde_json::from_slice(&o.stdout).unwrap();
        let h = r["hausdorff_mm"].as_f64().unwrap();
        assert!(h < 0.02, "{name} against {step}: {r}");
        let (ours, theirs) = (
            r["our_volume_mm3"].as_f64().unwrap(),
            r["published_volume_mm3"].as_f64().unwrap(),
        );
        assert!((ours / theirs - 1.0).abs() < 1e-3, "{name}: {r}");
    }
}
