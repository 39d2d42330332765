//! Laser-cut molds of a flat skin (Soter et al. Sec. II-A): each tray a stack of sheets of the
//! chosen stock with registration holes; the sheets' areas, the union's analytic volume and
//! its cavity equal to the pour; kerf compensation (a path offset by half the kerf, cut with
//! that kerf, leaves the nominal sheet); bad values by path.

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
