//! Flat skins (Soter et al. Sec. II-A): the rounded-rectangle outline against its exact area,
//! the channel layer and the bonded skin against their analytic volumes, genus and shells,
//! the liquid per channel, and one bad value per rule refused by its path.

use fabkit_designs::flat::{
    layer_solid, ChannelEnds, ChannelSet, ChannelTube, FlatLayer, FlatOutline, MarkerGrid,
};
use fabkit_designs::markers::{FeatureShape, Polarity};
use fabkit_designs::ChordTolerance;
use std::f64::consts::PI;

fn tol() -> ChordTolerance {
    ChordTolerance::new(0.01).unwrap()
}

fn outline() -> FlatOutline {
    FlatOutline {
        width_mm: 80.0,
        length_mm: 80.0,
        corner_radius_mm: 5.0,
    }
}

fn channels() -> ChannelSet {
    ChannelSet {
        count: 16,
        width_mm: 1.5,
        height_mm: 1.5,
        pitch_mm: 4.0,
        length_mm: 70.0,
        ends: ChannelEnds::BothClosed,
        min_wall_mm: 0.5,
        tube: ChannelTube {
            outer_diameter_mm: 2.0,
            inner_diameter_mm: 1.0,
            length_mm: 300.0,
            insertion_mm: 5.0,
        },
    }
}

fn grid() -> MarkerGrid {
    MarkerGrid {
        rows: 10,
        columns: 10,
        pitch_mm: 6.5,
        feature: FeatureShape::new(1.5, 2.0, Polarity::Raised),
        edge_margin_mm: 1.0,
    }
}

/// The marker layer (0 to 2 mm, grid below) and the channel layer (2 to 5 mm, channels).
fn layers() -> (FlatLayer, FlatLayer) {
    (
        FlatLayer {
            name: "markers".into(),
            z0_mm: 0.0,
            z1_mm: 2.0,
            outline: outline(),
            wraps: None,
            channels: None,
            marker_grid: Some(grid()),
        },
        FlatLayer {
            name: "channels".into(),
            z0_mm: 2.0,
            z1_mm: 5.0,
            outline: outline(),
            wraps: None,
            channels: Some(channels()),
            marker_grid: None,
        },
    )
}

fn polygon_area(p: &[[f64; 2]]) -> f64 {
    (0..p.len())
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        / 2.0
}

/// The polygon lies within the chord tolerance inside the exact outline: its area is short of
/// w l - (4 - pi) r^2 by at most the perimeter times the tolerance, and every vertex is on the
/// edge (inset 0).
#[test]
fn outline_polygon_is_the_rounded_rectangle() {
    let o = outline();
    let p = o.polygon(tol());
    let exact = 80.0 * 80.0 - (4.0 - PI) * 25.0;
    assert!((o.area_mm2() - exact).abs() < 1e-9);
    let a = polygon_area(&p);
    let perimeter = 2.0 * (80.0 + 80.0) - 8.0 * 5.0 + 2.0 * PI * 5.0;
    assert!(
        a <= exact && exact - a <= perimeter * 0.01,
        "{a} vs {exact}"
    );
    assert!(p.iter().all(|&q| o.inset_mm(q).abs() < 1e-9));
    assert!((o.inset_mm([0.0, 0.0]) - 40.0).abs() < 1e-12);
    // on the corner's diagonal, r (1 - 1/sqrt 2) inside the bounding box's corner
    let c = 40.0 - 5.0 + 5.0 / 2f64.sqrt();
    assert!(o.inset_mm([c, c]).abs() < 1e-9);
}

/// The channel layer is its prism less 16 grooves 1.5 x 1.5 x 70 mm (exact boxes): its volume
/// is the polygon's area times 3 mm less 16 x 157.5 mm^3 to rounding; one shell, genus 0 (the
/// grooves are open on the bottom face and at the near edge).
#[test]
fn channel_layer_is_the_prism_less_its_grooves() {
    let (_, top) = layers();
    let s = layer_solid(&top, tol()).unwrap();
    let want = polygon_area(&outline().polygon(tol())) * 3.0 - 16.0 * 1.5 * 1.5 * 70.0;
    assert!(
        (s.volume() - want).abs() < 1e-6 * want,
        "{} vs {want}",
        s.volume()
    );
    assert_eq!((s.shell_count(), s.genus()), (1, 0));
    let b = s.bounding_box().unwrap();
    assert!((b.min[2] - 2.0).abs() < 1e-12 && (b.max[2] - 5.0).abs() < 1e-12);
}

/// Bonded (the marker layer's top face closes the grooves), the skin is one shell of genus 0
/// whose channels are tunnels open only at the near edge: its volume is the 5 mm prism, plus
/// 100 markers (1.5 mm cylinders of 1.25 mm ending in hemispheres, within their chords), less
/// the 16 channels' 2520 mm^3 of void.
#[test]
fn bonded_skin_holds_the_channels_as_tunnels() {
    let (bottom, top) = layers();
    let a = layer_solid(&bottom, tol()).unwrap();
    let b = layer_solid(&top, tol()).unwrap();
    let skin = a.union(&b).unwrap();
    assert_eq!((skin.shell_count(), skin.genus()), (1, 0));
    let area = polygon_area(&outline().polygon(tol()));
    let marker = grid().feature.nominal_volume_mm3();
    let void = 16.0 * channels().channel_volume_mm3();
    assert!((void - 2520.0).abs() < 1e-9);
    let want = area * 5.0 + 100.0 * marker - void;
    let bound = skin.surface_area() * 0.01;
    assert!(
        (skin.volume() - want).abs() <= bound,
        "{} vs {want} (bound {bound})",
        skin.volume()
    );
    // the markers hang 2 mm below the base plane
    let bb = skin.bounding_box().unwrap();
    assert!((bb.min[2] + 2.0).abs() < 1e-9, "{:?}", bb);
}

/// Liquid per channel: the channel's 157.5 mm^3 less the tube's inserted 5 mm (pi 1^2 x 5),
/// plus the tube's bore over 300 mm (pi 0.5^2 x 300), in mL.
#[test]
fn liquid_per_channel_is_channel_less_plug_plus_bore() {
    let want = (157.5 - PI * 5.0 + PI * 0.25 * 300.0) / 1000.0;
    assert!((channels().liquid_per_channel_ml() - want).abs() < 1e-12);
}

/// A bad value: the field's path under its prefix, and how to set it.
type Case<T> = (&'static str, fn(&mut T));

/// Each bad value is refused by its own path with its value and rule; the baseline passes.
#[test]
fn bad_flat_values_are_refused_by_path() {
    let o = outline();
    assert!(o.errors("body.").is_empty());
    assert!(channels().errors("layers[1].channels.", 3.0, &o).is_empty());
    assert!(grid().errors("layers[0].marker_grid.", &o).is_empty());
    let ch_cases: &[Case<ChannelSet>] = &[
        ("width_mm", |c| c.width_mm = 3.8), // wider than the pitch less the wall
        ("height_mm", |c| c.height_mm = 2.8), // breaks through the face of a 3 mm layer
        ("length_mm", |c| c.length_mm = 79.8),
        ("count", |c| c.count = 19), // 19 x 4 mm spans more than the straight edge
        ("count", |c| c.count = 0),
        ("tube.outer_diameter_mm", |c| c.tube.outer_diameter_mm = 1.2),
        ("tube.outer_diameter_mm", |c| c.tube.outer_diameter_mm = 4.0),
        ("tube.inner_diameter_mm", |c| c.tube.inner_diameter_mm = 2.0),
        ("tube.insertion_mm", |c| c.tube.insertion_mm = 70.0),
        ("min_wall_mm", |c| c.min_wall_mm = -1.0),
        ("pitch_mm", |c| c.pitch_mm = f64::NAN),
    ];
    for (path, mutate) in ch_cases {
        let mut c = channels();
        mutate(&mut c);
        let e = c.errors("layers[1].channels.", 3.0, &o);
        let want = format!("layers[1].channels.{path}");
        assert!(
            e.iter()
                .any(|x| x.path == want && !x.rule.is_empty() && !x.value.is_empty()),
            "{path}: {e:?}"
        );
    }
    let grid_cases: &[Case<MarkerGrid>] = &[
        ("pitch_mm", |g| g.pitch_mm = 8.5), // 58.5 mm + markers beyond the 80 mm outline less margins
        ("feature.diameter_mm", |g| g.feature.diameter_mm = 6.5),
        ("feature.height_mm", |g| g.feature.height_mm = 0.5),
        ("feature.polarity", |g| {
            g.feature.polarity = Some(Polarity::Recessed)
        }),
        ("rows", |g| g.rows = 0),
        ("edge_margin_mm", |g| g.edge_margin_mm = -0.1),
    ];
    for (path, mutate) in grid_cases {
        let mut g = grid();
        mutate(&mut g);
        let e = g.errors("layers[0].marker_grid.", &o);
        let want = format!("layers[0].marker_grid.{path}");
        assert!(e.iter().any(|x| x.path == want), "{path}: {e:?}");
    }
    for (path, o) in [
        (
            "corner_radius_mm",
            FlatOutline {
                corner_radius_mm: 40.0,
                ..outline()
            },
        ),
        (
            "width_mm",
            FlatOutline {
                width_mm: 0.0,
                ..outline()
            },
        ),
    ] {
        let e = o.errors("body.");
        assert!(
            e.iter().any(|x| x.path == format!("body.{path}")),
            "{path}: {e:?}"
        );
    }
    // the corner's rounding alone: at 8.4 mm the outermost markers' sides are 1.45 mm from
    // the straight edges but 0.29 mm from the 5 mm corner arc
    let mut g = grid();
    g.pitch_mm = 8.4;
    let e = g.errors("g.", &o);
    assert!(
        e.len() == 1 && e[0].rule.contains("0.290 mm from the edge"),
        "{e:?}"
    );
    g.pitch_mm = 8.2;
    assert!(g.errors("g.", &o).is_empty());
}

/// The test design: an 80 x 80 x 5 mm skin (r 5 mm corners), a 2 mm marker layer with the
/// 10 x 10 grid and a 3 mm channel layer with the 16 channels above (the values above).
const FLAT_YAML: &str = include_str!("data/flat_channels.yaml");

fn flat_design() -> fabkit_designs::Design {
    fabkit_designs::Design::from_yaml(FLAT_YAML, "flat_channels.yaml").unwrap()
}

/// Its kit: a tray per layer, each a closed solid of the analytic volume (a 4 mm walled box
/// less the cavity; the channel tray plus its 16 ribs inside the cavity, the marker tray less
/// its 100 holes within their chords), the channel layer poured first, each pour the layer's
/// exact volume (the outline's area, less the grooves, plus the markers), and the liquid per
/// channel in the summary.
#[test]
fn flat_kit_has_its_trays_and_pours() {
    let k = fabkit_designs::build_kit(&flat_design(), tol()).unwrap();
    let names: Vec<&str> = k.parts.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["marker_layer_tray", "channel_layer_tray"]);
    let area_poly = polygon_area(&outline().polygon(tol()));
    let block = |h: f64| 88.0 * 88.0 * h;
    let ch = &k.parts[1].solid;
    let want = block(4.0 + 3.0) - area_poly * 3.0 + 16.0 * 1.5 * 1.5 * 70.0;
    assert!(
        (ch.volume() - want).abs() < 1e-6 * want,
        "{} vs {want}",
        ch.volume()
    );
    assert_eq!((ch.shell_count(), ch.genus()), (1, 0));
    let mk = &k.parts[0].solid;
    let hole = grid().feature.nominal_volume_mm3();
    let want = block(4.0 + 2.0 + 2.0) - area_poly * 2.0 - 100.0 * hole;
    let bound = mk.surface_area() * 0.01;
    assert!(
        (mk.volume() - want).abs() <= bound,
        "{} vs {want}",
        mk.volume()
    );
    assert_eq!(mk.shell_count(), 1);
    let area = outline().area_mm2();
    let casts: Vec<(&str, f64)> = k
        .casts
        .iter()
        .map(|c| (c.cast.as_str(), c.cavity_volume_ml))
        .collect();
    assert_eq!(casts[0].0, "channel_layer");
    assert_eq!(casts[1].0, "marker_layer");
    assert!((casts[0].1 - (area * 3.0 - 16.0 * 157.5) / 1000.0).abs() < 1e-12);
    assert!((casts[1].1 - (area * 2.0 + 100.0 * hole) / 1000.0).abs() < 1e-12);
    let per = k.summary["flat"]["channels"][0]["liquid_per_channel_ml"]
        .as_f64()
        .unwrap();
    assert!((per - channels().liquid_per_channel_ml()).abs() < 1e-15);
    assert_eq!(k.summary["flat"]["markers"], 100);
    assert_eq!(k.assembly.len(), 2);
}

/// Bad values of a flat design are refused by path, with nothing built; flat-only keys on a
/// curved design and curved-only sections on a flat one too.
#[test]
fn bad_flat_designs_are_refused_by_path() {
    let cases = [
        (
            "      width_mm: 1.5",
            "      width_mm: 3.8",
            "layers[1].channels.width_mm",
        ),
        (
            "      height_mm: 1.5",
            "      height_mm: 2.8",
            "layers[1].channels.height_mm",
        ),
        (
            "      pitch_mm: 6.5",
            "      pitch_mm: 8.5",
            "layers[0].marker_grid.pitch_mm",
        ),
        ("    thickness_mm: 3.0", "    thickness_mm: 2.5", "layers"),
        (
            "  corner_radius_mm: 5.0",
            "  corner_radius_mm: 45.0",
            "body.corner_radius_mm",
        ),
        (
            "    material: ecoflex_00_10\n    process: cast\n    thickness_mm: 3.0",
            "    material: pla_black\n    process: cast\n    thickness_mm: 3.0",
            "layers[1].material",
        ),
        (
            "layers:\n",
            "core: {material: pmma, wall_thickness_mm: 1.0, length_mm: 5.0}\nlayers:\n",
            "core",
        ),
    ];
    for (from, to, path) in cases {
        assert!(FLAT_YAML.contains(from), "{from}");
        let d =
            fabkit_designs::Design::from_yaml(&FLAT_YAML.replacen(from, to, 1), "x.yaml").unwrap();
        match fabkit_designs::build_kit(&d, tol()) {
            Err(fabkit_designs::DesignError::Params(e)) => {
                assert!(e.0.iter().any(|x| x.path == path), "{path}: {e}")
            }
            other => panic!("{path}: {:?}", other.map(|k| k.parts.len())),
        }
    }
    // channels on a curved skin
    let mut d = fabkit_designs::library::load("uvdtact").unwrap();
    d.layers[1].channels = Some(channels());
    match fabkit_designs::build_kit(&d, ChordTolerance::new(0.05).unwrap()) {
        Err(fabkit_designs::DesignError::Params(e)) => {
            assert!(e.0.iter().any(|x| x.path == "layers[1].channels"), "{e}")
        }
        other => panic!("{:?}", other.map(|k| k.parts.len())),
    }
}
