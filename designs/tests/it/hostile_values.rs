//! Hostile values in every numeric field of every library design (the schema walked as the
//! design serializes): NaN, infinity, a negative and a huge value each give an error naming the
//! field, or a design that validates and builds into closed, consistently oriented 2-manifolds.
//! Never a panic, an abort or a silent success with a broken mesh.

use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::schema::DESIGN_SIGNED_MM;
use fabkit_designs::values::{check_values, number_paths, with_number, MAX_LENGTH_MM};
use fabkit_designs::{build_kit_bounded, library, stack, ChordTolerance, Design, ParamError};

fn listing(errs: &[ParamError]) -> String {
    errs.iter().map(|e| format!("\n  {e}")).collect()
}

const HOSTILE: [f64; 4] = [f64::NAN, f64::INFINITY, -1.0, 1e300];

#[test]
fn every_numeric_field_of_every_library_design_refuses_hostile_values_by_name() {
    let materials = MaterialsTable::embedded().unwrap();
    let tol = ChordTolerance::new(0.05).unwrap();
    let (mut fields, mut refused, mut built) = (0, 0, Vec::new());
    for (name, _) in library::LIBRARY {
        let d = library::load(name).unwrap();
        assert!(check_values(&d, DESIGN_SIGNED_MM).is_empty(), "{name}");
        // presets are paths into the same fields, checked when applied
        let paths = number_paths(&d, &["presets"]).unwrap();
        assert!(paths.len() >= 20, "{name}: {} numeric fields", paths.len());
        fields += paths.len();
        for path in &paths {
            let p = path.to_string();
            // a signed length (a light's position) may be negative
            let signed = DESIGN_SIGNED_MM.iter().any(|k| p.contains(k));
            let is_length =
                (p.ends_with("_mm") || p.contains("_mm[") || p.contains("_mm.")) && !signed;
            for x in HOSTILE {
                let m = with_number(&d, path, x).unwrap();
                let valid = if m.body.flat_outline().is_some() {
                    fabkit_designs::stack::flat::validate(&m, &materials).map(|_| ())
                } else {
                    stack::validate(&m, &materials, tol).map(|_| ())
                };
                match valid {
                    Err(e) => {
                        // NaN, infinity, 1e300 and a negative length are refused by name;
                        // any other refusal names some parameter with its rule
                        if !x.is_finite() || x.abs() > MAX_LENGTH_MM || is_length {
                            assert!(
                                e.0.iter().any(|e| e.path == p),
                                "{name}: {p} = {x}: no error names it:{}",
                                listing(&e.0)
                            );
                        }
                        assert!(e.0.iter().all(|e| !e.path.is_empty() && !e.rule.is_empty()));
                        refused += 1;
                    }
                    Ok(_) => {
                        assert!(
                            x == -1.0 && !is_length,
                            "{name}: {p} = {x} passes validation"
                        );
                        // the optics change no part: they resolve for a render
                        if p.starts_with("optics.") {
                            fabkit_designs::optics::of_design(&m, tol).unwrap_or_else(|e| {
                                panic!("{name}: {p} = {x} validates but its optics fail: {e}")
                            });
                            built.push(format!("{name}: {p} = {x}"));
                            continue;
                        }
                        // a negative that is valid (an angle, a signed offset) builds closed
                        // 2-manifolds or is refused by name
                        match build_kit_bounded(&m, tol, 4_000_000) {
                            Ok(kit) => {
                                for part in &kit.parts {
                                    part.solid
                                        .mesh()
                                        .check_closed_manifold()
                                        .unwrap_or_else(|e| {
                                            panic!("{name}: {p} = {x}: {}: {e}", part.name)
                                        });
                                }
                                built.push(format!("{name}: {p} = {x}"));
                            }
                            Err(e) => panic!("{name}: {p} = {x} validates but fails: {e}"),
                        }
                    }
                }
            }
        }
    }
    eprintln!(
        "{fields} numeric fields, {refused} hostile values refused, {} built:\n{}",
        built.len(),
        built.join("\n")
    );
    assert!(fields >= 100, "{fields}");
}

/// The errors of `validate` for `d` at the default tolerance (empty when valid).
fn errors(d: &Design) -> Vec<ParamError> {
    crate::common::validation_errors(d)
}

/// `d` is refused with an error on `path` whose value prints as `value` and whose rule holds
/// `words`.
#[track_caller]
fn assert_refused(d: &Design, path: &str, value: &str, words: &str) {
    let errs = errors(d);
    assert!(
        errs.iter()
            .any(|e| e.path == path && e.value == value && e.rule.contains(words)),
        "expected `{path} = {value}: ...{words}...`, got:{}",
        listing(&errs)
    );
}

/// The values that once passed: a ShadowTac backing of NaN, infinite, negative, zero or 1e300
/// mm (which reached the fabrication sheet), an infinite core, and marker polar limits that are
/// NaN, negative, beyond the surface or crossed (a bad minimum was reported as a maximum).
#[test]
fn values_that_once_passed_are_refused_by_name() {
    let shadowtac = library::load("shadowtac").unwrap();
    for (x, value, words) in [
        (f64::NAN, "NaN", "must be a finite number"),
        (f64::INFINITY, "inf", "must be a finite number"),
        (-3.0, "-3", "must be above 0"),
        (0.0, "0", "must be above 0"),
        (1e300, "1e300", "at most 1000 mm"),
    ] {
        let mut d = shadowtac.clone();
        d.backing.as_mut().unwrap().thickness_mm = x;
        assert_refused(&d, "backing.thickness_mm", value, words);
        let mut d = shadowtac.clone();
        d.backing.as_mut().unwrap().diameter_mm = x;
        assert_refused(&d, "backing.diameter_mm", value, words);
    }

    let rtac0 = library::load("rtac0").unwrap();
    let mut d = rtac0.clone();
    d.core.as_mut().unwrap().wall_thickness_mm = f64::INFINITY;
    assert_refused(
        &d,
        "core.wall_thickness_mm",
        "inf",
        "must be a finite number",
    );
    let mut d = rtac0.clone();
    d.core.as_mut().unwrap().length_mm = f64::INFINITY;
    assert_refused(&d, "core.length_mm", "inf", "must be a finite number");

    // the dual-modal TacTip's pattern has max_polar_deg 85 on a hemisphere on a cylinder
    let tactip = library::load("tactip_dualmodal").unwrap();
    let pat = "layers[0].markers[0].pattern";
    let with = |max: Option<f64>, min: Option<f64>| {
        let mut d = tactip.clone();
        let p = &mut d.layers[0].markers[0].pattern;
        p.max_polar_deg = max;
        p.min_polar_deg = min;
        d
    };
    assert!(errors(&with(Some(85.0), None)).is_empty());
    for (max, min, field, value, words) in [
        (
            Some(f64::NAN),
            None,
            "max_polar_deg",
            "NaN",
            "must be a finite number",
        ),
        (
            Some(720.0),
            None,
            "max_polar_deg",
            "720",
            "from -360 to 360 deg",
        ),
        (
            Some(-1.0),
            None,
            "max_polar_deg",
            "-1",
            "above 0 and at most 180 deg",
        ),
        (
            Some(0.0),
            None,
            "max_polar_deg",
            "0",
            "above 0 and at most 180 deg",
        ),
        (
            Some(200.0),
            None,
            "max_polar_deg",
            "200",
            "above 0 and at most 180 deg",
        ),
        (
            Some(85.0),
            Some(-5.0),
            "min_polar_deg",
            "-5",
            "from 0 to below 180 deg",
        ),
        (
            Some(40.0),
            Some(60.0),
            "min_polar_deg",
            "60",
            "must be below max_polar_deg (40 deg)",
        ),
        (
            None,
            Some(179.0),
            "min_polar_deg",
            "179",
            "leaves no room for markers",
        ),
    ] {
        assert_refused(&with(max, min), &format!("{pat}.{field}"), value, words);
    }
    // beyond the polar range of the surface (a hemisphere on a cylinder ends below 90 deg)
    let errs = errors(&with(Some(170.0), None));
    assert!(
        errs.iter().any(|e| e.path == format!("{pat}.max_polar_deg")
            && e.value == "170"
            && e.rule.contains("must be at most the surface's polar range")),
        "{}",
        listing(&errs)
    );
}

/// Inward features once crossed the axis (30 mm: a mesh error naming no parameter at export) or
/// passed at 1e20 mm (the exported negative lost its feature holes): each is refused by name,
/// with the deepest reach the body allows.
#[test]
fn inward_features_end_before_the_centre_of_curvature() {
    // the dual-modal TacTip's pins point inward from the skin's inner surface (R12.5)
    let tactip = library::load("tactip_dualmodal").unwrap();
    let path = "layers[0].markers[0].feature.height_mm";
    for (h, value, words) in [
        (
            30.0,
            "30",
            "must be below 12.500 mm: the features point inward from the inner surface",
        ),
        (12.5, "12.5", "must be below 12.500 mm"),
        (1e20, "1e20", "at most 1000 mm"),
    ] {
        let mut d = tactip.clone();
        d.layers[0].markers[0].feature.height_mm = h;
        assert_refused(&d, path, value, words);
    }
    let mut d = tactip.clone();
    d.layers[0].markers[0].feature.height_mm = 6.0;
    assert!(
        errors(&d).iter().all(|e| e.path != path),
        "{}",
        listing(&errors(&d))
    );
}

/// A concentric spacing of 1e-300 mm made a ring's marker count (a float cast to usize) past
/// `usize::MAX`, and the placement allocated until it was killed: the count is compared with
/// the cap before the cast, whatever rule runs first.
#[test]
fn a_vanishing_concentric_spacing_is_refused_before_placing() {
    use fabkit_designs::markers::{place, Layout, Pattern, MAX_MARKERS_PER_PATTERN};
    let d = library::load("shadowtac").unwrap();
    let s = fabkit_designs::markers::Surface::new(&d.body, 0.0);
    for spacing in [1e-20, 1e-100, 1e-300, 5e-324] {
        let p = Pattern {
            layout: Layout::Concentric,
            spacing_mm: Some(spacing),
            ..d.layers[0].markers[0].pattern.clone()
        };
        let (field, _, rule) = place(&s, &p, 0.5).unwrap_err();
        assert_eq!(field, "spacing_mm", "{spacing}: {rule}");
        assert!(
            rule.contains(&format!("more than {MAX_MARKERS_PER_PATTERN} markers")),
            "{spacing}: {rule}"
        );
    }
}

/// Counts that once allocated before their rule: 2e8 clamp bolts (a position per bolt), a flat
/// marker grid of 1e8 columns or 2^63 rows (rows x columns positions), 2^31 LEDs on a ring
/// PCB (which reached the shopping list). Past 1e6 a count is refused as a number; up to it,
/// by its own rule, which computes before it allocates.
#[test]
fn counts_that_once_allocated_or_passed_are_refused_by_name() {
    let mut d = library::load("shadowtac").unwrap();
    d.mold.two_piece.bolt_count = 200_000_000;
    assert_refused(
        &d,
        "mold.two_piece.bolt_count",
        "200000000",
        "bolts 0.000 mm apart on the flange",
    );
    d.mold.two_piece.bolt_count = 1_000_000;
    assert_refused(&d, "mold.two_piece.bolt_count", "1000000", "bolts");

    let soter = library::load("soter_channels").unwrap();
    let i = soter
        .layers
        .iter()
        .position(|l| l.marker_grid.is_some())
        .unwrap();
    for (rows, columns, path, value, rule) in [
        (
            1,
            100_000_000,
            "columns",
            "100000000",
            "more than the 100000 markers",
        ),
        (
            1 << 31,
            10,
            "rows",
            "2147483648",
            "more than the 100000 markers",
        ),
        (
            1 << 63,
            10,
            "rows",
            "9223372036854775808",
            "more than the 100000 markers",
        ),
        (1000, 1000, "rows", "1000", "more than the 100000 markers"),
        (
            1,
            1_000_000,
            "columns",
            "1000000",
            "more than the 100000 markers",
        ),
        (
            1_000_000,
            1_000_000,
            "rows",
            "1000000",
            "more than the 100000 markers",
        ),
    ] {
        let mut d = soter.clone();
        let g = d.layers[i].marker_grid.as_mut().unwrap();
        g.rows = rows;
        g.columns = columns;
        let errs = fabkit_designs::stack::flat::validate(&d, &MaterialsTable::embedded().unwrap())
            .err()
            .map(|e| e.0)
            .unwrap_or_default();
        let path = format!("layers[{i}].marker_grid.{path}");
        assert!(
            errs.iter()
                .any(|e| e.path == path && e.value == value && e.rule.contains(rule)),
            "{path}:{}",
            listing(&errs)
        );
    }

    let mut d = library::load("rtac0").unwrap();
    d.housing.as_mut().unwrap().led_pcb.led_count = 1 << 31;
    assert_refused(
        &d,
        "housing.led_pcb.led_count",
        "2147483648",
        "at most 59 LEDs fit around the ring",
    );
    d.housing.as_mut().unwrap().led_pcb.led_count = 1_000_000;
    assert_refused(
        &d,
        "housing.led_pcb.led_count",
        "1000000",
        "LEDs fit around the ring",
    );
    // the published eight fit; one per millimetre of the mid-line is the most
    let ring = &library::load("rtac0").unwrap().housing.unwrap().led_pcb;
    let fit = (std::f64::consts::PI * (ring.outer_diameter_mm + ring.inner_diameter_mm) / 2.0)
        .floor() as u32;
    d.housing.as_mut().unwrap().led_pcb.led_count = fit;
    assert!(errors(&d).is_empty(), "{}", listing(&errors(&d)));
    d.housing.as_mut().unwrap().led_pcb.led_count = fit + 1;
    assert_refused(
        &d,
        "housing.led_pcb.led_count",
        &(fit + 1).to_string(),
        "fit",
    );
    let mut d = library::load("tactip_dualmodal").unwrap();
    d.shaft_body.as_mut().unwrap().led_ring.led_count = 100_000;
    assert_refused(
        &d,
        "shaft_body.led_ring.led_count",
        "100000",
        "LEDs fit around the ring",
    );
}

/// Tiny positive lengths (1e-300 to 1e-12 mm) of housing, casing and core dimensions passed
/// validation and failed in the kernel with a message naming a part but not the parameter.
#[test]
fn tiny_lengths_are_refused_by_name_before_the_kernel() {
    type Set = fn(&mut Design, f64);
    let cases: [(&str, Set); 4] = [
        ("housing.camera.bay_height_mm", |d, x| {
            d.housing.as_mut().unwrap().camera.bay_height_mm = x
        }),
        ("housing.joint_screw.clearance_diameter_mm", |d, x| {
            d.housing
                .as_mut()
                .unwrap()
                .joint_screw
                .clearance_diameter_mm = x
        }),
        ("core.wall_thickness_mm", |d, x| {
            d.core.as_mut().unwrap().wall_thickness_mm = x
        }),
        ("casing.leds.width_mm", |d, x| {
            d.casing.as_mut().unwrap().leds.width_mm = x
        }),
    ];
    for (path, set) in cases {
        let name = if path.starts_with("casing") {
            "shadowtac"
        } else {
            "rtac0"
        };
        for (x, shown) in [(1e-300, "1e-300"), (1e-12, "1e-12"), (5e-4, "0.0005")] {
            let mut d = library::load(name).unwrap();
            set(&mut d, x);
            assert_refused(
                &d,
                path,
                shown,
                "must be 0 or a length of at least 0.001 mm",
            );
        }
    }
}

/// A 300-character layer name passed validation and failed export with "File name too long".
#[test]
fn names_that_become_file_names_are_bounded() {
    let mut d = library::load("rtac0").unwrap();
    d.layers[0].name = "a".repeat(300);
    let errs = errors(&d);
    assert!(
        errs.iter()
            .any(|e| e.path == "layers[0].name" && e.rule.contains("1 to 64")),
        "{}",
        listing(&errs)
    );
    d.layers[0].name = "a".repeat(64);
    assert!(errors(&d).is_empty(), "{}", listing(&errors(&d)));
}

/// Extreme values printed as 300-digit decimals in error messages.
#[test]
fn extreme_values_print_in_scientific_notation() {
    let e = ParamError::new("a_mm", 1e300, format!("must be below {}", 1e-300));
    assert_eq!(e.to_string(), "a_mm = 1e300: must be below 1e-300");
    // integers up to 2^64 keep their digits, ordinary decimals are untouched
    let e = ParamError::new("count", u64::MAX, "must be at most 0.125 of 12345678.5");
    assert_eq!(
        e.to_string(),
        "count = 18446744073709551615: must be at most 0.125 of 12345678.5"
    );
}

/// A preset value of the wrong type or range was reported as `presets.<name>: invalid value`,
/// without its parameter path or its place in the file.
#[test]
fn preset_values_are_reported_like_direct_ones() {
    // the first `rings: null` is paper_text's
    let text = library::yaml("shadowtac").unwrap().replacen(
        "    layers[0].markers[0].pattern.rings: null\n",
        "    layers[0].markers[0].pattern.rings: 9223372036854775808\n",
        1,
    );
    let line = text
        .lines()
        .position(|l| l.contains("rings: 9223372036854775808"))
        .unwrap()
        + 1;
    let d = Design::from_yaml(&text, "shadowtac.yaml").unwrap();
    let e = d
        .with_preset_in("paper_text", &text, "shadowtac.yaml")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(&format!("shadowtac.yaml:{line}:41: presets.paper_text: layers[0].markers[0].pattern.rings = 9223372036854775808: ")),
        "{e}"
    );
}

/// Issue 95: a design with 90,000 listed marker points (under the 100,000 one pattern may
/// have) was refused by the parser as "budget breached: Nodes { nodes: 250001 }". The YAML
/// node budget follows the design limits: 90,000 points parse; past the budget the error
/// says the limit and the hint in words.
#[test]
fn the_yaml_budget_follows_the_design_limits_and_speaks_in_words() {
    use fabkit_designs::yaml::MAX_YAML_NODES;
    let base = fabkit_designs::library::yaml("shadowtac").unwrap();
    let layout = "layout: concentric_6k";
    assert!(base.contains(layout));
    let listed = |n: usize| {
        let pts: Vec<String> = (0..n)
            .map(|i| {
                format!(
                    "[{:.3}, {:.2}]",
                    5.0 + (i % 400) as f64 * 0.1,
                    (i / 400) as f64
                )
            })
            .collect();
        base.replacen(
            layout,
            &format!("layout: list\n          points: [{}]", pts.join(", ")),
            1,
        )
        .replacen("rings: 12 ", "", 1)
        .replacen("polar_step_deg: 3.9474 ", "", 1)
    };
    let d = Design::from_yaml(&listed(90_000), "big.yaml").unwrap();
    let points = d.layers[0].markers[0].pattern.points.as_ref().unwrap();
    assert_eq!(points.len(), 90_000);
    // past the budget: a point is three nodes
    let e = Design::from_yaml(&listed(MAX_YAML_NODES / 3 + 1), "huge.yaml")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("huge.yaml:")
            && e.contains(&format!("more than {MAX_YAML_NODES} YAML values"))
            && e.contains("csv_file")
            && !e.contains("budget breached"),
        "{}",
        &e[..e.len().min(400)]
    );
}

/// Issue 95: every count past 1,000,000 was refused as "must be a count from -1000000 to
/// 1000000", whatever the field's own range. Each count is now said by its field's rule (run
/// at 1,000,000, where its work is bounded), or, for a count this design does not read, the
/// range of any unsigned count.
#[test]
fn a_count_past_any_count_is_said_by_its_fields_own_rule() {
    use fabkit_designs::values::{with_integer, NumberPath};
    let checked = "(checked at 1000000, the most any count may be)";
    for (name, path, words) in [
        (
            "rtac0",
            "mold.vent.count",
            "at most 21 vents fit beside the sprue",
        ),
        (
            "rtac0",
            "housing.led_pcb.led_count",
            "at most 59 LEDs fit around the ring",
        ),
        ("shadowtac", "casing.leds.count", "must be 1 to 8"),
        ("uvdtact", "fingertip_base.bolts.count", "must be 2 to 6"),
        ("uvdtact", "optics.camera.bit_depth", "must be 8 or 16"),
        (
            "tactip_dualmodal",
            "shaft_body.robot_mount.bolt_count",
            "must be 2 to 8",
        ),
        (
            "tactip_dualmodal",
            "printers.fdm.bayonet.lug_count",
            "must be 2 to 8",
        ),
        (
            "rtac0",
            "mold.two_piece.bolt_count",
            "must be a count from 0 to 1000000",
        ),
    ] {
        let d = library::load(name).unwrap();
        let d = with_integer(&d, &NumberPath::parse(path).unwrap(), u64::from(u32::MAX)).unwrap();
        let errs = errors(&d);
        let e = errs
            .iter()
            .find(|e| e.path == path)
            .unwrap_or_else(|| panic!("{name} {path}:{}", listing(&errs)));
        assert_eq!(e.value, "4294967295");
        assert!(e.rule.starts_with(words), "{name}: {e}");
        assert_eq!(
            e.rule.ends_with(checked),
            !words.starts_with("must be a count"),
            "{e}"
        );
        assert!(!e.rule.contains("-1000000"), "{e}");
    }
    // a flat skin's own rules
    let soter = library::load("soter_channels").unwrap();
    let materials = MaterialsTable::embedded().unwrap();
    let d = with_integer(
        &soter,
        &NumberPath::parse("layers[1].channels.count").unwrap(),
        u64::from(u32::MAX),
    )
    .unwrap();
    let errs = fabkit_designs::stack::flat::validate(&d, &materials)
        .unwrap_err()
        .0;
    assert!(
        errs.iter()
            .any(|e| e.path == "layers[1].channels.count" && e.rule.ends_with(checked)),
        "{}",
        listing(&errs)
    );
}
