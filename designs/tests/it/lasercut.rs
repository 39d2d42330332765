//! Laser-cut molds of a flat skin (Soter et al. Sec. II-A): each tray a stack of sheets of the
//! chosen stock with registration holes; the sheets' areas, the union's analytic volume and
//! its cavity equal to the pour; kerf compensation (a path offset by half the kerf, cut with
//! that kerf, leaves the nominal sheet); bad values by path.

use crate::common::refused_paths;
use fabkit_designs::cut::Operation;
use fabkit_designs::lasercut::{cut_path, cut_result, tray_sheets, tray_union};
use fabkit_designs::{library, ChordTolerance, Design, DesignError};
use std::f64::consts::PI;

fn tol() -> ChordTolerance {
    ChordTolerance::new(0.01).unwrap()
}

fn soter() -> Design {
    library::load("soter_channels").unwrap()
}

/// The outline's area (80 x 80 mm, corner radius 5 mm) and the rectangle round it (6 mm wall).
const OUTLINE_MM2: f64 = 6400.0 - (4.0 - PI) * 25.0;
const RECT_MM2: f64 = 92.0 * 92.0;

/// The sheets of each tray, bottom to top: the stock each level takes and its place in the
/// stack; every sheet's area the rectangle less its holes (4 registration holes of 3 mm, the
/// outline, 16 ribs of 1.5 x 70 mm left standing, 100 marker holes of 1.5 mm) within its
/// chords; a cut part per sheet, its paths on `cut`.
#[test]
fn soter_trays_are_stacks_of_sheets_of_the_right_stock_and_area() {
    let d = soter();
    let k = fabkit_designs::build_kit(&d, tol()).unwrap();
    let layers = fabkit_designs::stack::flat::flat_layers(&d).unwrap();
    let outline = d.body.flat_outline().unwrap();
    let lc = d.mold.laser_cut.as_ref().unwrap();
    let reg = 4.0 * PI * 1.5 * 1.5;
    let want = [
        (
            0usize,
            vec![
                (
                    "marker_layer_tray_1_base",
                    "acrylic_3mm",
                    1u32,
                    0.0,
                    RECT_MM2 - reg,
                ),
                (
                    "marker_layer_tray_2_markers",
                    "acrylic_2mm",
                    1,
                    3.0,
                    RECT_MM2 - reg - 100.0 * PI * 0.75 * 0.75,
                ),
                (
                    "marker_layer_tray_3_wall",
                    "acrylic_2mm",
                    1,
                    5.0,
                    RECT_MM2 - reg - OUTLINE_MM2,
                ),
            ],
        ),
        (
            1,
            vec![
                (
                    "channel_layer_tray_1_base",
                    "acrylic_3mm",
                    1,
                    0.0,
                    RECT_MM2 - reg,
                ),
                (
                    "channel_layer_tray_2_ribs",
                    "acrylic_1_5mm",
                    1,
                    3.0,
                    RECT_MM2 - reg - OUTLINE_MM2 + 16.0 * 1.5 * 70.0,
                ),
                (
                    "channel_layer_tray_3_wall",
                    "acrylic_1_5mm",
                    1,
                    4.5,
                    RECT_MM2 - reg - OUTLINE_MM2,
                ),
            ],
        ),
    ];
    for (li, sheets) in want {
        let got = tray_sheets(&outline, &layers[li], li, 6.0, lc, tol()).unwrap();
        assert_eq!(got.len(), sheets.len());
        for (s, (name, stock, n, z0, area)) in got.iter().zip(sheets) {
            assert_eq!(
                (s.name.as_str(), s.stock.name.as_str(), s.quantity),
                (name, stock, n)
            );
            assert!((s.z0_mm - z0).abs() < 1e-12, "{name}: z0 {}", s.z0_mm);
            let a = s.region.area_mm2();
            // polygons inscribed in the arcs and circles: off the exact area by at most the
            // boundary's length (under 2000 mm) times the chord tolerance
            let bound = 2000.0 * 0.01;
            assert!((a - area).abs() <= bound, "{name}: {a} vs {area}");
            let c = k.cut_parts.iter().find(|c| c.name == name).unwrap();
            assert_eq!(c.outlines.len(), 1 + s.region.holes.len());
            assert!(c.outlines.iter().all(|(op, _)| *op == Operation::Cut));
            assert!((c.nominal_area_mm2() - a).abs() < 1e-9 * a);
            assert_eq!((c.kerf_mm, c.quantity), (s.stock.kerf_mm, 1));
        }
    }
    assert_eq!(k.cut_parts.len(), 6);
}

/// The printable tray is the union of the sheets: a closed solid whose volume is the
/// rectangle's stack less the cavity and the registration holes (the ribs standing in it), and
/// whose cavity (the stack's block less the tray and the holes) is the pour of its layer.
#[test]
fn each_tray_is_the_union_of_its_sheets_and_holds_its_pour() {
    let d = soter();
    let k = fabkit_designs::build_kit(&d, tol()).unwrap();
    let layers = fabkit_designs::stack::flat::flat_layers(&d).unwrap();
    let outline = d.body.flat_outline().unwrap();
    let lc = d.mold.laser_cut.as_ref().unwrap();
    for (li, l) in layers.iter().enumerate() {
        let sheets = tray_sheets(&outline, l, li, 6.0, lc, tol()).unwrap();
        let union = tray_union(&sheets).unwrap();
        let tray = &k
            .parts
            .iter()
            .find(|p| p.name == format!("{}_tray", l.name))
            .unwrap()
            .solid;
        assert_eq!((tray.shell_count(), tray.genus()), (1, 4), "{}", l.name);
        assert!((tray.volume() - union.volume()).abs() < 1e-9 * union.volume());
        let height: f64 = sheets.iter().map(|s| s.level_mm()).sum();
        // the registration holes as built (polygons): the base sheet's area is the rectangle
        // less them
        let reg = RECT_MM2 - sheets[0].region.area_mm2();
        let cavity = (RECT_MM2 - reg) * height - tray.volume();
        let cast = k.casts.iter().find(|c| c.cast == l.name).unwrap();
        let pour = cast.cavity_volume_ml * 1000.0;
        let bound = tray.surface_area() * 0.01;
        assert!(
            (cavity - pour).abs() <= bound,
            "{}: cavity {cavity} vs pour {pour} mm3 (bound {bound})",
            l.name
        );
    }
    // the marker layer's pour: flat-ended markers, straight through their sheet
    let mk = k.casts.iter().find(|c| c.cast == "marker_layer").unwrap();
    let want = OUTLINE_MM2 * 2.0 + 100.0 * PI * 0.75 * 0.75 * 2.0;
    assert!((mk.cavity_volume_ml * 1000.0 - want).abs() < 1e-9 * want);
}

/// Kerf compensation on the 2D geometry: every sheet's path is its outline offset by half the
/// kerf (out of the sheet, into its holes); cut with that kerf it leaves the nominal sheet, but
/// for the inside corners the kerf rounds (at most (1 - pi / 4) (kerf / 2)^2 each).
#[test]
fn a_path_offset_by_half_the_kerf_cuts_the_nominal_sheet() {
    let d = soter();
    let layers = fabkit_designs::stack::flat::flat_layers(&d).unwrap();
    let outline = d.body.flat_outline().unwrap();
    let mut lc = d.mold.laser_cut.clone().unwrap();
    for kerf in [0.1, 0.3] {
        for s in &mut lc.stock {
            s.kerf_mm = kerf;
        }
        for (li, l) in layers.iter().enumerate() {
            for s in tray_sheets(&outline, l, li, 6.0, &lc, tol()).unwrap() {
                let nominal = s.region.area_mm2();
                let path = cut_path(&s.region, kerf, tol()).unwrap();
                assert_eq!(path.holes.len(), s.region.holes.len());
                // the path encloses more than the sheet by about half the kerf times the
                // boundary's length (outer out, holes in)
                assert!(path.area_mm2() > nominal, "{}", s.name);
                let cut = cut_result(&path, kerf);
                assert_eq!(cut.len(), 1, "{}", s.name);
                let got = cut[0].area_mm2();
                let corners: usize = s.region.holes.iter().map(|h| h.len()).sum();
                let allowance = corners as f64 * (1.0 - PI / 4.0) * (kerf / 2.0).powi(2);
                assert!(
                    got >= nominal - 1e-6 * nominal && got - nominal <= allowance + 1e-6 * nominal,
                    "{} at kerf {kerf}: cut {got} vs nominal {nominal} (allowance {allowance})",
                    s.name
                );
            }
        }
    }
}

/// Bad laser-cut values are refused by path before anything is built: a kerf wider than the
/// marker holes, no stock for the 1.5 mm rib sheet, registration holes too wide for the wall,
/// an unknown sheet material, a negative kerf, no stock, a sheet thicker than a laser cuts, a
/// repeated stock name; and laser_cut on a curved skin.
#[test]
fn bad_laser_cut_values_are_refused_by_path() {
    type Case = (&'static str, fn(&mut Design));
    let cases: &[Case] = &[
        ("mold.laser_cut.stock[1].kerf_mm", |d| {
            d.mold.laser_cut.as_mut().unwrap().stock[1].kerf_mm = 1.6
        }),
        ("layers[1].channels.height_mm", |d| {
            d.mold.laser_cut.as_mut().unwrap().stock.truncate(1)
        }),
        ("mold.laser_cut.registration.diameter_mm", |d| {
            d.mold.laser_cut.as_mut().unwrap().registration.diameter_mm = 4.5
        }),
        ("mold.laser_cut.stock[0].material", |d| {
            d.mold.laser_cut.as_mut().unwrap().stock[0].material = "balsa".into()
        }),
        ("mold.laser_cut.stock[2].kerf_mm", |d| {
            d.mold.laser_cut.as_mut().unwrap().stock[2].kerf_mm = -0.1
        }),
        ("mold.laser_cut.stock", |d| {
            d.mold.laser_cut.as_mut().unwrap().stock.clear()
        }),
        ("mold.laser_cut.stock[0].thickness_mm", |d| {
            d.mold.laser_cut.as_mut().unwrap().stock[0].thickness_mm = 30.0
        }),
        ("mold.laser_cut.stock[2].name", |d| {
            d.mold.laser_cut.as_mut().unwrap().stock[2].name = "acrylic_3mm".into()
        }),
    ];
    for (path, mutate) in cases {
        let mut d = soter();
        mutate(&mut d);
        match fabkit_designs::build_kit(&d, tol()) {
            Err(DesignError::Params(e)) => {
                assert!(e.0.iter().any(|x| x.path == *path), "{path}: {e}")
            }
            other => panic!("{path}: {:?}", other.map(|k| k.parts.len())),
        }
    }
    let mut d = library::load("rtac0").unwrap();
    d.mold.laser_cut = Some(Default::default());
    match fabkit_designs::build_kit(&d, ChordTolerance::new(0.05).unwrap()) {
        Err(DesignError::Params(e)) => {
            assert!(e.0.iter().any(|x| x.path == "mold.laser_cut"), "{e}")
        }
        other => panic!("{:?}", other.map(|k| k.parts.len())),
    }
}

/// The published sheets' geometry (9DTact, `9DTact_Design/fabrication/*.DXF`): every line,
/// arc and circle of the file's entities.
enum Drawn {
    Line([f64; 2], [f64; 2]),
    /// Centre, radius, start and end angle (degrees, counter-clockwise).
    Arc([f64; 2], f64, f64, f64),
}

fn published(file: &str) -> Vec<Drawn> {
    use dxf::entities::EntityType;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data/9dtact_published_cad")
        .join(file);
    let drawing = dxf::Drawing::load_file(&path).unwrap();
    drawing
        .entities()
        .filter_map(|e| match &e.specific {
            EntityType::Line(l) => Some(Drawn::Line([l.p1.x, l.p1.y], [l.p2.x, l.p2.y])),
            EntityType::Arc(a) => Some(Drawn::Arc(
                [a.center.x, a.center.y],
                a.radius,
                a.start_angle,
                a.end_angle,
            )),
            EntityType::Circle(c) => {
                Some(Drawn::Arc([c.center.x, c.center.y], c.radius, 0.0, 360.0))
            }
            _ => None,
        })
        .collect()
}

fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}

impl Drawn {
    fn distance(&self, p: [f64; 2]) -> f64 {
        match *self {
            Drawn::Line(a, b) => segment_distance(p, a, b),
            Drawn::Arc(c, r, a0, a1) => {
                let at = (p[1] - c[1])
                    .atan2(p[0] - c[0])
                    .to_degrees()
                    .rem_euclid(360.0);
                let span = (a1 - a0).rem_euclid(360.0);
                let span = if span == 0.0 { 360.0 } else { span };
                if (at - a0).rem_euclid(360.0) <= span {
                    ((p[0] - c[0]).hypot(p[1] - c[1]) - r).abs()
                } else {
                    let end = |a: f64| {
                        [
                            c[0] + r * a.to_radians().cos(),
                            c[1] + r * a.to_radians().sin(),
                        ]
                    };
                    let (e0, e1) = (end(a0), end(a1));
                    (p[0] - e0[0])
                        .hypot(p[1] - e0[1])
                        .min((p[0] - e1[0]).hypot(p[1] - e1[1]))
                }
            }
        }
    }

    /// Points along it at most `step` mm apart.
    fn samples(&self, step: f64) -> Vec<[f64; 2]> {
        match *self {
            Drawn::Line(a, b) => {
                let n = ((a[0] - b[0]).hypot(a[1] - b[1]) / step).ceil().max(1.0) as usize;
                (0..=n)
                    .map(|i| {
                        let t = i as f64 / n as f64;
                        [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
                    })
                    .collect()
            }
            Drawn::Arc(c, r, a0, a1) => {
                let span = (a1 - a0).rem_euclid(360.0);
                let span = if span == 0.0 { 360.0 } else { span };
                let n = (span.to_radians() * r / step).ceil().max(1.0) as usize;
                (0..=n)
                    .map(|i| {
                        let a = (a0 + span * i as f64 / n as f64).to_radians();
                        [c[0] + r * a.cos(), c[1] + r * a.sin()]
                    })
                    .collect()
            }
        }
    }
}

/// The two-sided distance between a sheet's rings and the published drawing, mm: every
/// vertex and edge midpoint of the rings to the drawing, and every point along the drawing
/// (0.01 mm apart) to the rings.
fn hausdorff_to_published(rings: &[Vec<[f64; 2]>], drawn: &[Drawn]) -> f64 {
    let to_drawn = |p: [f64; 2]| {
        drawn
            .iter()
            .map(|d| d.distance(p))
            .fold(f64::INFINITY, f64::min)
    };
    let mut worst: f64 = 0.0;
    for r in rings {
        for (i, &a) in r.iter().enumerate() {
            let b = r[(i + 1) % r.len()];
            worst = worst
                .max(to_drawn(a))
                .max(to_drawn([(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0]));
        }
    }
    for d in drawn {
        for p in d.samples(0.01) {
            let near = rings
                .iter()
                .flat_map(|r| {
                    (0..r.len()).map(move |i| segment_distance(p, r[i], r[(i + 1) % r.len()]))
                })
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(near);
        }
    }
    worst
}

/// 9DTact's translucent gel in its published mold (`mold.laser_cut.plate`: 60 x 50 mm plates
/// with R12 corners, eight 3.1 mm holes, the base's four 2.1 mm holes on the sensor's M2
/// pattern; a 2.5 mm sheet round the 29.5 x 22.5 mm R1 pocket): the base sheet and the wall
/// sheet are the published mold_base and mold_1 within 0.01 mm (arcs within a 0.001 mm chord
/// tolerance), ring for ring, and the procedure tapes the base holes under the pocket shut.
#[test]
fn a_plate_as_published_gives_the_published_sheets() {
    let d = Design::from_yaml(
        include_str!("data/ninedtact_plate.yaml"),
        "ninedtact_plate.yaml",
    )
    .unwrap();
    let fine = ChordTolerance::new(0.001).unwrap();
    let k = fabkit_designs::build_kit(&d, fine).unwrap();
    let sheet = |name: &str| {
        k.cut_parts
            .iter()
            .find(|c| c.name == name)
            .unwrap_or_else(|| panic!("no sheet {name}"))
    };
    for (name, file, rings) in [
        (
            "translucent_gel_tray_1_base",
            "mold_base_thickness_3.0mm.DXF",
            13,
        ),
        (
            "translucent_gel_tray_2_wall",
            "mold_1_thickness_2.5mm.DXF",
            10,
        ),
        ("black_gel_tray_2_wall", "mold_2_thickness_2.8mm.DXF", 10),
    ] {
        let c = sheet(name);
        let nominal = c.nominal_rings_mm.as_ref().unwrap();
        assert_eq!(nominal.len(), rings, "{name}: outer boundary and holes");
        let h = hausdorff_to_published(nominal, &published(file));
        assert!(h < 0.01, "{name} is {h} mm from {file}");
    }
    assert_eq!(sheet("translucent_gel_tray_1_base").thickness_mm, 3.0);
    assert_eq!(sheet("translucent_gel_tray_2_wall").thickness_mm, 2.5);
    assert_eq!(sheet("black_gel_tray_2_wall").thickness_mm, 2.8);
    // one base sheet under both trays: the three published sheets and no more
    assert_eq!(k.cut_parts.len(), 3, "{:?}", names(&k));
    let make = &k.procedure[0].text;
    assert!(
        make.contains("the 8 3.1 mm holes") && make.contains("tape the base sheet's holes"),
        "{make}"
    );
}

/// The names of a kit's cut parts.
fn names(k: &fabkit_designs::Kit) -> Vec<&str> {
    k.cut_parts.iter().map(|c| c.name.as_str()).collect()
}

/// 9DTact's gels as published: the translucent gel cast in mold_1's 2.5 mm pocket, then the
/// black gel poured over it in mold_2's 2.8 mm pocket, 0.8 mm round its sides
/// (`layers[1].wrap_mm`). The gels' volumes are the published molds': translucent
/// 662.89 mm2 x 2.5 mm = 1657.2 mm3, black 746.73 mm2 x 2.8 mm - 1657.2 = 433.6 mm3 (the
/// pockets' areas from the DXFs), within 1 % as poured and as the assembly's solids; each layer
/// is what its molds cast (the black gel's inner faces formed by the cured translucent gel),
/// poured inner first.
#[test]
fn a_wrapped_gel_is_cast_over_the_cured_one_as_published() {
    let d = Design::from_yaml(
        include_str!("data/ninedtact_plate.yaml"),
        "ninedtact_plate.yaml",
    )
    .unwrap();
    let k = fabkit_designs::build_kit(&d, tol()).unwrap();
    for (step, (layer, published)) in [("translucent_gel", 1657.2), ("black_gel", 433.6)]
        .into_iter()
        .enumerate()
    {
        let c = &k.casts[step];
        assert_eq!(c.cast, layer, "pour {} is {}", step + 1, c.cast);
        let poured = c.layer_volume_ml.unwrap_or(c.cavity_volume_ml) * 1000.0;
        assert!(
            (poured / published - 1.0).abs() < 0.01,
            "{layer}: poured {poured} mm3, published {published}"
        );
        let shown = k
            .assembly
            .iter()
            .find(|m| m.name == layer)
            .unwrap()
            .solid
            .volume();
        assert!(
            (shown / published - 1.0).abs() < 0.01,
            "{layer}: the assembly's {shown} mm3, published {published}"
        );
    }
    let checks = fabkit_designs::cast_check::check_casts(&d, &k, tol()).unwrap();
    for c in &checks {
        assert!(c.holds(), "{c:?}");
    }
    assert_eq!(checks[1].formed_by, ["black_gel_tray", "translucent_gel"]);
    let pour = k
        .procedure
        .iter()
        .find(|s| s.text.starts_with("Pour black_gel"))
        .unwrap();
    assert!(
        pour.text.contains("round the cured layers"),
        "{}",
        pour.text
    );
    // in printed trays: the same gels, each what its tray and the cured layers cast, the black
    // gel's tray as deep as the stack, the cured gel set on its floor
    let mut printed = d.clone();
    printed.mold.laser_cut = None;
    let k = fabkit_designs::build_kit(&printed, tol()).unwrap();
    assert!(k.cut_parts.is_empty());
    for (c, published) in k.casts.iter().zip([1657.2, 433.6]) {
        let mm3 = c.cavity_volume_ml * 1000.0;
        assert!((mm3 / published - 1.0).abs() < 0.01, "{}: {mm3}", c.cast);
    }
    for c in fabkit_designs::cast_check::check_casts(&printed, &k, tol()).unwrap() {
        assert!(c.holds(), "{c:?}");
    }
    let tray = k.parts.iter().find(|p| p.name == "black_gel_tray").unwrap();
    assert!((tray.params["depth_mm"].as_f64().unwrap() - 2.8).abs() < 1e-9);
    assert!(k
        .procedure
        .iter()
        .any(|s| s.text.contains("set the cured layers on its floor")));
}

/// A plate's rules by path: a plate no larger than the pocket, a corner radius past half its
/// side, a hole through every sheet in the pocket, one past the plate's edge, two holes that
/// overlap; a base hole may lie under the pocket.
#[test]
fn a_plates_bad_values_are_refused_by_path() {
    let base = Design::from_yaml(
        include_str!("data/ninedtact_plate.yaml"),
        "ninedtact_plate.yaml",
    )
    .unwrap();
    let cases: [(&str, fn(&mut fabkit_designs::lasercut::SheetPlate)); 5] = [
        ("mold.laser_cut.plate.size_mm[0]", |p| p.size_mm[0] = 30.0),
        ("mold.laser_cut.plate.corner_radius_mm", |p| {
            p.corner_radius_mm = 26.0
        }),
        ("mold.laser_cut.plate.holes.xy_mm[0]", |p| {
            p.holes.xy_mm[0] = [0.0, 5.0]
        }),
        ("mold.laser_cut.plate.holes.xy_mm[1]", |p| {
            p.holes.xy_mm[1] = [-29.5, 0.0]
        }),
        ("mold.laser_cut.plate.holes.xy_mm[7]", |p| {
            p.holes.xy_mm[7] = [27.0, -6.0]
        }),
    ];
    for (path, edit) in cases {
        let mut d = base.clone();
        edit(d.mold.laser_cut.as_mut().unwrap().plate.as_mut().unwrap());
        match fabkit_designs::build_kit(&d, tol()) {
            Err(DesignError::Params(e)) => {
                let paths: Vec<&str> = e.0.iter().map(|x| x.path.as_str()).collect();
                assert!(paths.contains(&path), "{path}: {e}");
            }
            other => panic!("{path}: {:?}", other.map(|k| k.design)),
        }
    }
}

/// A level left over by a difference of thicknesses that no stock makes is said to the
/// micrometre: a 3.1 mm channel layer less 2.4 mm channels is a 0.7 mm wall level
/// (0.7000000000000002 in floating point).
#[test]
fn a_level_no_stock_makes_is_said_to_the_micrometre() {
    let mut d = soter();
    if let fabkit_designs::profile::BodyProfile::Flat { thickness_mm, .. } = &mut d.body {
        *thickness_mm = 5.1;
    }
    let l = &mut d.layers[1];
    l.thickness_mm = Some(3.1);
    let ch = l.channels.as_mut().unwrap();
    ch.height_mm = 2.4;
    ch.tube.outer_diameter_mm = 2.5;
    assert_ne!(3.1 - 2.4, 0.7);
    match fabkit_designs::build_kit(&d, tol()) {
        Err(DesignError::Params(e)) => {
            let wall = e.0.iter().find(|x| x.path == "layers[1].thickness_mm");
            let wall = wall.unwrap_or_else(|| panic!("{e}"));
            assert_eq!(wall.value, "0.7", "{e}");
            assert!(wall.rule.contains("makes 0.7 mm"), "{e}");
        }
        other => panic!("{:?}", other.map(|k| k.parts.len())),
    }
}

/// Wrapping layers' rules by path: not on the innermost layer, above 0, on every layer from
/// the second up once on one, no channels in a wrapped stack, no marker grid on a wrapping
/// layer, and not on a curved skin.
#[test]
fn a_wraps_bad_values_are_refused_by_path() {
    let base = Design::from_yaml(
        include_str!("data/ninedtact_plate.yaml"),
        "ninedtact_plate.yaml",
    )
    .unwrap();
    let mut d = base.clone();
    d.layers[0].wrap_mm = Some(0.5);
    assert!(refused_paths(&d, "a wrapped innermost layer").contains(&"layers[0].wrap_mm".into()));
    for bad in [0.0, -0.5, f64::INFINITY] {
        let mut d = base.clone();
        d.layers[1].wrap_mm = Some(bad);
        let paths = refused_paths(&d, "a wrap not above 0");
        assert!(
            paths.contains(&"layers[1].wrap_mm".into()),
            "{bad}: {paths:?}"
        );
    }
    // a third layer that does not wrap
    let mut d = base.clone();
    let mut third = d.layers[1].clone();
    third.name = "coat".into();
    third.wrap_mm = None;
    d.layers.push(third);
    if let fabkit_designs::profile::BodyProfile::Flat { thickness_mm, .. } = &mut d.body {
        *thickness_mm = 3.1;
    }
    assert!(refused_paths(&d, "a third layer unwrapped").contains(&"layers[2].wrap_mm".into()));
    // Soter's channel layer made to wrap its marker layer
    let mut d = soter();
    d.layers[1].wrap_mm = Some(1.0);
    let paths = refused_paths(&d, "a wrapping channel layer");
    assert!(paths.contains(&"layers[1].channels".into()), "{paths:?}");
    let mut d = library::load("rtac0").unwrap();
    d.layers[1].wrap_mm = Some(1.0);
    let paths = refused_paths(&d, "a curved skin's wrap");
    assert!(paths.contains(&"layers[1].wrap_mm".into()), "{paths:?}");
}
