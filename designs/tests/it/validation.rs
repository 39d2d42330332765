//! Validation tests (STYLE.md, "Tests" and "Errors"): the library design `rtac0` is a valid
//! baseline that builds; one mutation yields exactly one error naming its parameter path, value
//! and rule; several mutations yield all their errors at once; YAML errors point at
//! file:line:column; a `ParamError` prints as `path = value: rule`.
//!

use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::stack::validate;
use fabkit_designs::{build_kit, ChordTolerance, Design, DesignError, ParamError};

const ORIGIN: &str = "x.yaml";

fn text() -> &'static str {
    fabkit_designs::library::yaml("rtac0").expect("rtac0 is in the library")
}

fn baseline() -> Design {
    Design::from_yaml(text(), ORIGIN).expect("rtac0 parses")
}

/// Every error `validate` reports at tolerance `tol` (empty when the design is valid).
fn errors_at(d: &Design, tol: ChordTolerance) -> Vec<ParamError> {
    let materials = MaterialsTable::embedded().expect("embedded materials table");
    match validate(d, &materials, tol) {
        Ok(_) => Vec::new(),
        Err(e) => e.0,
    }
}

fn errors(d: &Design) -> Vec<ParamError> {
    errors_at(d, ChordTolerance::default())
}

fn listing(errs: &[ParamError]) -> String {
    errs.iter().map(|e| format!("\n  {e}")).collect()
}

/// What one expected error looks like: its path, its value as printed, and words its rule
/// must contain.
struct Expect {
    path: &'static str,
    value: &'static str,
    rule: &'static [&'static str],
}

fn matches(e: &ParamError, x: &Expect) -> bool {
    e.path == x.path && e.value == x.value && x.rule.iter().all(|w| e.rule.contains(w))
}

/// `errs` is exactly the expected errors, in any order.
fn assert_exactly(errs: &[ParamError], expected: &[&Expect]) {
    assert_eq!(
        errs.len(),
        expected.len(),
        "expected {} error(s), got:{}",
        expected.len(),
        listing(errs)
    );
    for x in expected {
        assert!(
            errs.iter().any(|e| matches(e, x)),
            "no error `{} = {}: ...{:?}...` among:{}",
            x.path,
            x.value,
            x.rule,
            listing(errs)
        );
    }
}

fn housing(d: &mut Design) -> &mut fabkit_designs::schema::HousingParams {
    d.housing.as_mut().expect("rtac0 has a housing")
}

/// The baseline with the square split shell (preset `square_split`).
fn square_split() -> Design {
    baseline()
        .with_preset("square_split")
        .expect("rtac0 has the preset square_split")
}

// ---------------------------------------------------------------------------------------------
// The baseline.

#[test]
fn baseline_validates_and_builds() {
    let d = baseline();
    let materials = MaterialsTable::embedded().unwrap();
    let stack = validate(&d, &materials, ChordTolerance::default())
        .unwrap_or_else(|e| panic!("rtac0 does not validate: {e}"));
    // The stack the YAML describes: core 20 mm (offset 10 - 15.0), layers to 13.5, 14.9, 15.0
    // (the reference surface is the outer mold's cavity, R15.000, authors' CAD, measured; the
    // 0.1 mm sprayed coat lies inside it).
    assert_eq!(stack.layers.len(), 3);
    let outer: Vec<f64> = stack
        .layers
        .iter()
        .map(|l| 15.0 + l.outer_offset_mm)
        .collect();
    for (got, want) in outer.iter().zip([13.5, 14.9, 15.0]) {
        assert!((got - want).abs() < 1e-9, "outer radii {outer:?}");
    }
    assert!((stack.core.as_ref().unwrap().outer_offset_mm - (10.0 - 15.0)).abs() < 1e-9);
    assert!(stack
        .layers
        .iter()
        .all(|l| l.thickness_mm >= ChordTolerance::DEFAULT_MM));

    let kit = build_kit(&d, ChordTolerance::default())
        .unwrap_or_else(|e| panic!("rtac0 does not build: {e}"));
    assert_eq!(kit.design, "rtac0");
    assert!(!kit.parts.is_empty());
    for p in &kit.parts {
        p.solid
            .mesh()
            .check_closed_manifold()
            .unwrap_or_else(|e| panic!("part {}: {e}", p.name));
        assert!(p.solid.volume() > 0.0, "part {} is empty", p.name);
    }
}

// ---------------------------------------------------------------------------------------------
// One mutation, one error.

/// A named mutation of the baseline and the one error it must cause.
type Mutation = (&'static str, fn(&mut Design), Expect);

/// The single mutations of the baseline that each break exactly one rule, with that error.
fn single_mutations() -> Vec<Mutation> {
    vec![
        (
            "translucent layer thinner than the chord tolerance",
            |d| d.layers[1].outer_radius_mm = Some(13.505),
            Expect {
                path: "layers[1].outer_radius_mm",
                value: "13.505",
                rule: &["translucent_gel", "0.0050 mm thick", "below the chord tolerance 0.01 mm"],
            },
        ),
        (
            "vent below the fixture printer's minimum hole",
            |d| d.mold.vent.diameter_mm = 0.3,
            Expect {
                path: "mold.vent.diameter_mm",
                value: "0.3",
                rule: &["minimum hole 1 mm", "printer profile 'fdm'"],
            },
        ),
        (
            "draft angle of 12 degrees",
            |d| d.mold.draft_angle_deg = 12.0,
            Expect {
                path: "mold.draft_angle_deg",
                value: "12",
                rule: &["must be in [0, 10)"],
            },
        ),
        (
            "unknown layer material",
            |d| d.layers[0].material = "unobtainium".into(),
            Expect {
                path: "layers[0].material",
                value: "unobtainium",
                rule: &["unknown material", "sylgard_184"],
            },
        ),
        (
            "printing filament as a cast layer",
            |d| d.layers[1].material = "pla".into(),
            Expect {
                path: "layers[1].material",
                value: "pla",
                rule: &["Print material", "Cast"],
            },
        ),
        (
            "unknown housing material",
            |d| housing(d).material = "unobtainium".into(),
            Expect {
                path: "housing.material",
                value: "unobtainium",
                rule: &["unknown material"],
            },
        ),
        (
            "seats tighter than the nozzle allows",
            |d| housing(d).fit_clearance_mm = 0.1,
            Expect {
                path: "housing.fit_clearance_mm",
                value: "0.1",
                rule: &["at least half the nozzle width 0.4 mm", "printer profile 'fdm' (0.2 mm)"],
            },
        ),
        (
            "printing filament as the filling gel",
            |d| housing(d).filling_gel.as_mut().unwrap().material = "pla".into(),
            Expect {
                path: "housing.filling_gel.material",
                value: "pla",
                rule: &["is a Print material", "expected one of [Cast]"],
            },
        ),
        (
            "negative core wall",
            |d| d.core.as_mut().unwrap().wall_thickness_mm = -1.0,
            Expect {
                path: "core.wall_thickness_mm",
                value: "-1",
                rule: &["must be above 0"],
            },
        ),
        (
            "camera board wider than the tube's camera bay allows",
            |d| housing(d).camera.board_width_mm = 29.0,
            Expect {
                path: "housing.camera.board_width_mm",
                value: "29",
                rule: &["does not fit the camera bay", "bay_diameter_mm = 22.4"],
            },
        ),
        (
            "lens view angle of 180 deg",
            |d| housing(d).camera.view_angle_deg = Some(180.0),
            Expect {
                path: "housing.camera.view_angle_deg",
                value: "180",
                rule: &["must be in (0, 180)"],
            },
        ),
        (
            "diffuser wider than the shell",
            |d| housing(d).diffuser.outer_diameter_mm = 30.5,
            Expect {
                path: "housing.diffuser.outer_diameter_mm",
                value: "30.5",
                rule: &["must not exceed the shell's diameter", "outer_width_mm = 30", "between the tube and the collar"],
            },
        ),
        (
            // The translucent layer above the coating: the coating is then below the layer
            // under it (a single error, as when lowering the coating; see
            // `coating_below_the_layer_under_it_yields_one_error`).
            "translucent layer above the coating",
            |d| d.layers[1].outer_radius_mm = Some(15.2),
            Expect {
                path: "layers[2].outer_radius_mm",
                value: "15",
                rule: &["must be above the outer radius of layer 'translucent_gel' under it (15.200 mm)"],
            },
        ),
        (
            "a release agent as the core's primer",
            |d| d.core.as_mut().unwrap().primer = Some("ease_release_200".into()),
            Expect {
                path: "core.primer",
                value: "ease_release_200",
                rule: &["is a Release material, expected one of [Primer]"],
            },
        ),
        (
            "an unknown mold release",
            |d| d.casting.mold_release = Some("soap".into()),
            Expect {
                path: "casting.mold_release",
                value: "soap",
                rule: &["unknown material; known:", "ease_release_200"],
            },
        ),
        (
            "a printer bed of no width",
            |d| {
                d.printers.fdm.bed = Some(fabkit_designs::schema::Bed {
                    name: "flat".into(),
                    size_mm: [0.0, 200.0, 200.0],
                    margin_mm: 5.0,
                })
            },
            Expect {
                path: "printers.fdm.bed.size_mm[0]",
                value: "0",
                rule: &["must be above 0 and at most 10000 mm"],
            },
        ),
        (
            "a printer bed all margin",
            |d| {
                d.printers.sla.bed = Some(fabkit_designs::schema::Bed {
                    name: "small".into(),
                    size_mm: [100.0, 150.0, 100.0],
                    margin_mm: 50.0,
                })
            },
            Expect {
                path: "printers.sla.bed.margin_mm",
                value: "50",
                rule: &["must leave room on the plate", "100 mm"],
            },
        ),
        (
            "a printer named with spaces",
            |d| {
                d.printers.polyjet.bed = Some(fabkit_designs::schema::Bed {
                    name: "My Printer".into(),
                    size_mm: [200.0, 200.0, 200.0],
                    margin_mm: 5.0,
                })
            },
            Expect {
                path: "printers.polyjet.bed.name",
                value: "'My Printer'",
                rule: &["a-z, 0-9 and _"],
            },
        ),
        (
            "waste allowance above 1",
            |d| d.casting.waste_allowance = 1.5,
            Expect {
                path: "casting.waste_allowance",
                value: "1.5",
                rule: &["must be in [0, 1]"],
            },
        ),
    ]
}

#[test]
fn each_single_mutation_yields_exactly_its_one_error() {
    for (what, mutate, expect) in single_mutations() {
        let mut d = baseline();
        mutate(&mut d);
        let errs = errors(&d);
        assert!(
            errs.len() == 1 && matches(&errs[0], &expect),
            "{what}: expected only `{} = {}: ...{:?}...`, got:{}",
            expect.path,
            expect.value,
            expect.rule,
            listing(&errs)
        );
    }
}

/// The same layer is fine at the default 0.01 mm tolerance and too thin at a coarse one: the
/// rule uses the tolerance passed in, not a global.
#[test]
fn a_layer_thinner_than_a_coarse_tolerance_is_named() {
    let d = baseline();
    assert_exactly(&errors_at(&d, ChordTolerance::new(0.099).unwrap()), &[]);
    let errs = errors_at(&d, ChordTolerance::new(0.2).unwrap());
    assert_exactly(
        &errs,
        &[&Expect {
            path: "layers[2].outer_radius_mm",
            value: "15",
            rule: &["black_coating", "below the chord tolerance 0.2 mm"],
        }],
    );
}

#[test]
fn draft_angle_bounds_are_half_open() {
    for (deg, ok) in [(0.0, true), (9.99, true), (10.0, false), (-0.1, false)] {
        let mut d = baseline();
        d.mold.draft_angle_deg = deg;
        let errs = errors(&d);
        if ok {
            assert_exactly(&errs, &[]);
        } else {
            assert!(
                errs.len() == 1 && errs[0].path == "mold.draft_angle_deg",
                "draft {deg}:{}",
                listing(&errs)
            );
        }
    }
}

/// A mutation written into the YAML text gives the same error as the same mutation in Rust.
#[test]
fn a_mutation_in_the_yaml_text_is_reported_like_one_in_rust() {
    let t = text().replacen("draft_angle_deg: 2.0", "draft_angle_deg: 12", 1);
    assert_ne!(t, text());
    let d = Design::from_yaml(&t, ORIGIN).unwrap();
    let errs = errors(&d);
    assert_eq!(errs.len(), 1, "{}", listing(&errs));
    assert_eq!(
        errs[0].to_string(),
        "mold.draft_angle_deg = 12: must be in [0, 10)"
    );
}

/// The LED PCB seat at 29.5 mm breaks two independent rules at once: it leaves a 0.05 mm wall
/// and it covers the camera board's mounting holes (on a 20 mm square, at 14.14 mm from the
/// axis). Every LED PCB wide enough to thin the wall below 0.8 mm (over 28 mm) also covers the
/// holes (over 24.7 mm), so no value of this one parameter gives the wall error alone.
#[test]
fn led_pcb_too_wide_thins_the_wall_and_covers_the_mount_holes() {
    let mut d = square_split();
    housing(&mut d).led_pcb.outer_diameter_mm = 29.5;
    assert_exactly(
        &errors(&d),
        &[
            &Expect {
                path: "housing.led_pcb.outer_diameter_mm",
                value: "29.5",
                rule: &[
                    "0.05 mm of wall",
                    "around the LED PCB seat",
                    "printer profile 'fdm'",
                ],
            },
            &Expect {
                path: "housing.camera.mount_hole_spacing_mm",
                value: "20",
                rule: &["under the LED PCB seat"],
            },
        ],
    );
}

/// The core-larger-than-cavity rule is named on the innermost layer with the radii.
#[test]
fn core_larger_than_its_cavity_is_named() {
    let mut d = baseline();
    d.core.as_mut().unwrap().outer_diameter_mm = Some(28.0);
    let errs = errors(&d);
    let want = Expect {
        path: "layers[0].outer_radius_mm",
        value: "13.5",
        rule: &[
            "the core (outer radius 14.000 mm) is larger than the cavity of layer 'transparent_gel' (outer radius 13.500 mm)",
        ],
    };
    assert!(errs.iter().any(|e| matches(e, &want)), "{}", listing(&errs));
}

#[test]
fn core_larger_than_its_cavity_yields_one_error() {
    let mut d = baseline();
    d.core.as_mut().unwrap().outer_diameter_mm = Some(28.0);
    assert_exactly(
        &errors(&d),
        &[&Expect {
            path: "layers[0].outer_radius_mm",
            value: "13.5",
            rule: &["larger than the cavity"],
        }],
    );
}

#[test]
fn coating_below_the_layer_under_it_is_named() {
    let mut d = baseline();
    d.layers[2].outer_radius_mm = Some(14.8);
    let errs = errors(&d);
    let want = Expect {
        path: "layers[2].outer_radius_mm",
        value: "14.8",
        rule: &["must be above the outer radius of layer 'translucent_gel' under it (14.900 mm)"],
    };
    assert!(errs.iter().any(|e| matches(e, &want)), "{}", listing(&errs));
}

#[test]
fn coating_below_the_layer_under_it_yields_one_error() {
    let mut d = baseline();
    d.layers[2].outer_radius_mm = Some(14.8);
    assert_exactly(
        &errors(&d),
        &[&Expect {
            path: "layers[2].outer_radius_mm",
            value: "14.8",
            rule: &["must be above the outer radius of layer 'translucent_gel' under it"],
        }],
    );
}

/// A NaN radius (`outer_radius_mm: .nan` in YAML) passes every comparison in the stack
/// check (`th < t` is false for NaN), so validation accepts it and the kernel rejects it later
/// as a "fabkit defect" instead of a named parameter error.
#[test]
fn a_nan_layer_radius_is_a_named_error() {
    let t = with_line(
        30,
        "    outer_radius_mm: 14.9",
        &["    outer_radius_mm: .nan"],
    );
    let d = Design::from_yaml(&t, ORIGIN).expect("`.nan` is a YAML float");
    assert!(d.layers[1].outer_radius_mm.unwrap().is_nan());
    let errs = errors(&d);
    assert!(
        errs.iter().any(|e| e.path == "layers[1].outer_radius_mm"),
        "no error names layers[1].outer_radius_mm:{}",
        listing(&errs)
    );
}

// ---------------------------------------------------------------------------------------------
// Several mutations, every error at once.

#[test]
fn two_mutations_yield_both_errors() {
    let mut d = baseline();
    d.mold.vent.diameter_mm = 0.3;
    d.mold.draft_angle_deg = 12.0;
    d.layers[1].outer_radius_mm = Some(13.505);
    housing(&mut d).camera.board_width_mm = 29.0;
    let singles = single_mutations();
    let find = |path: &str| &singles.iter().find(|(_, _, x)| x.path == path).unwrap().2;
    assert_exactly(
        &errors(&d),
        &[
            find("mold.vent.diameter_mm"),
            find("mold.draft_angle_deg"),
            find("layers[1].outer_radius_mm"),
            find("housing.camera.board_width_mm"),
        ],
    );
}

#[test]
fn every_pair_of_single_mutations_yields_both_errors() {
    let singles = single_mutations();
    for (i, (what_a, mutate_a, expect_a)) in singles.iter().enumerate() {
        for (what_b, mutate_b, expect_b) in &singles[i + 1..] {
            // two mutations of layers[1].outer_radius_mm overwrite each other
            let radius = |p: &str| p.ends_with(".outer_radius_mm");
            if radius(expect_a.path) && radius(expect_b.path) {
                continue;
            }
            let mut d = baseline();
            mutate_a(&mut d);
            mutate_b(&mut d);
            let errs = errors(&d);
            assert!(
                errs.len() == 2
                    && errs.iter().any(|e| matches(e, expect_a))
                    && errs.iter().any(|e| matches(e, expect_b)),
                "{what_a} + {what_b}: got{}",
                listing(&errs)
            );
        }
    }
}

#[test]
fn an_unknown_layer_material_does_not_hide_stack_errors() {
    let mut d = baseline();
    d.layers[0].material = "unobtainium".into();
    d.layers[1].outer_radius_mm = Some(13.505);
    let singles = single_mutations();
    let find = |path: &str| &singles.iter().find(|(_, _, x)| x.path == path).unwrap().2;
    assert_exactly(
        &errors(&d),
        &[
            find("layers[0].material"),
            find("layers[1].outer_radius_mm"),
        ],
    );
}

#[test]
fn an_unknown_housing_material_does_not_hide_housing_errors() {
    let mut d = baseline();
    housing(&mut d).material = "unobtainium".into();
    housing(&mut d).camera.board_width_mm = 29.0;
    let singles = single_mutations();
    let find = |path: &str| &singles.iter().find(|(_, _, x)| x.path == path).unwrap().2;
    assert_exactly(
        &errors(&d),
        &[
            find("housing.material"),
            find("housing.camera.board_width_mm"),
        ],
    );
}

// ---------------------------------------------------------------------------------------------
// YAML errors carry file:line:column.

/// The text with `line` (1-based) replaced by `new` (several lines, or none, allowed).
fn with_line(line: usize, old: &str, new: &[&str]) -> String {
    let mut lines: Vec<&str> = text().lines().collect();
    assert!(
        lines[line - 1].starts_with(old),
        "line {line} of rtac0.yaml is {:?}, expected it to start with {old:?}",
        lines[line - 1]
    );
    lines.splice(line - 1..line, new.iter().copied());
    lines.join("\n") + "\n"
}

/// (line, column, message) of a YAML error for `text`, asserting the `x.yaml:L:C: ` form.
fn yaml_error(text: &str) -> (usize, usize, String) {
    let msg = match Design::from_yaml(text, ORIGIN) {
        Err(DesignError::Yaml(msg)) => msg,
        Err(e) => panic!("expected a YAML error, got {e:?}"),
        Ok(_) => panic!("expected a YAML error, the text parsed"),
    };
    let rest = msg
        .strip_prefix("x.yaml:")
        .unwrap_or_else(|| panic!("{msg:?} does not start with the file name"));
    let mut it = rest.splitn(3, ':');
    let line = it.next().and_then(|s| s.parse().ok());
    let col = it.next().and_then(|s| s.parse().ok());
    match (line, col, it.next()) {
        (Some(l), Some(c), Some(m)) if m.starts_with(' ') => (l, c, m.to_string()),
        _ => panic!("{msg:?} is not `x.yaml:LINE:COLUMN: message`"),
    }
}

/// A mistyped key or value names the nearest valid one ("did you mean"), and only when one is
/// near (within a third of its length in edits).
#[test]
fn a_mistyped_key_or_value_names_the_nearest_valid_one() {
    let t = with_line(37, "  strategy: master", &["  strategi: master"]);
    let (line, col, msg) = yaml_error(&t);
    assert_eq!((line, col), (37, 3), "{msg}");
    assert!(
        msg.contains("unknown field `strategi`") && msg.contains("; did you mean `strategy`?"),
        "{msg}"
    );
    // a value of an enumeration
    let t = with_line(37, "  strategy: master", &["  strategy: mastr"]);
    let (_, _, msg) = yaml_error(&t);
    assert!(msg.contains("did you mean `master`?"), "{msg}");
    // nothing near: no guess
    let t = with_line(37, "  strategy: master", &["  colour: red"]);
    let (_, _, msg) = yaml_error(&t);
    assert!(
        msg.contains("unknown field `colour`") && !msg.contains("did you mean"),
        "{msg}"
    );
}

/// `body: {profil: ...}` names `profile` at the key's file:line:column; letter case is ignored
/// (`Profile`); two edits are near even in a short name (`drct`); a far-off key gets no guess.
#[test]
fn a_mistyped_body_key_names_the_nearest_one() {
    let near = [
        ("  profil: hemisphere_on_cylinder", "profil"),
        ("  Profile: hemisphere_on_cylinder", "Profile"),
        ("  PROFLIE: hemisphere_on_cylinder", "PROFLIE"),
        ("  proifle: hemisphere_on_cylinder", "proifle"),
    ];
    for (new, typed) in near {
        let t = with_line(11, "  profile: hemisphere_on_cylinder", &[new]);
        let (line, col, msg) = yaml_error(&t);
        assert_eq!((line, col), (11, 3), "{msg}");
        assert!(
            msg.contains(&format!("unknown field `{typed}`, expected one of profile"))
                && msg.ends_with("; did you mean `profile`?"),
            "{msg}"
        );
    }
    // the flow form of the example, on one line
    let t = with_line(
        10,
        "body:",
        &["body: {profil: hemisphere_on_cylinder, radius_mm: 15.0, cylinder_length_mm: 6.0}"],
    );
    let t = t.replacen("  profile: hemisphere_on_cylinder\n", "", 1);
    let t = t.replacen("  radius_mm: 15.0", "#", 1);
    let t = t.replacen("  cylinder_length_mm: 6.0", "#", 1);
    let (line, col, msg) = yaml_error(&t);
    assert_eq!(line, 10, "{msg}");
    assert!(col > 6, "{msg}");
    assert!(msg.ends_with("; did you mean `profile`?"), "{msg}");
    // a short name two edits away (a third of its length would allow one)
    let t = with_line(37, "  strategy: master", &["  strategy: drct"]);
    let (_, _, msg) = yaml_error(&t);
    assert!(
        msg.contains("; did you mean `direct`? (at mold.strategy)"),
        "{msg}"
    );
    // a key far from every body key: no guess
    let t = with_line(
        11,
        "  profile: hemisphere_on_cylinder",
        &["  outline: hemisphere"],
    );
    let (line, _, msg) = yaml_error(&t);
    assert_eq!(line, 11, "{msg}");
    assert!(
        msg.contains("unknown field `outline`") && !msg.contains("did you mean"),
        "{msg}"
    );
}

#[test]
fn unknown_key_points_at_its_line() {
    // line 16 is `  description: ...` under `core:`; the new key takes its place
    let t = with_line(
        16,
        "  description:",
        &["  colour: red", text().lines().nth(15).unwrap()],
    );
    let (line, col, msg) = yaml_error(&t);
    assert_eq!((line, col), (16, 3), "{msg}");
    assert!(msg.contains("unknown field `colour`"), "{msg}");

    // a key in a layer (a sequence item) and one in a nested mold section
    let t = with_line(
        25,
        "    process: cast",
        &["    process: cast", "    colour: red"],
    );
    let (line, col, msg) = yaml_error(&t);
    assert_eq!((line, col), (26, 5), "{msg}");
    assert!(msg.contains("colour"), "{msg}");
    let t = with_line(
        39,
        "  draft_angle_deg:",
        &["  draft_angle_deg: 2.0", "  draft_angel_deg: 2.0"],
    );
    let (line, col, msg) = yaml_error(&t);
    assert_eq!((line, col), (40, 3), "{msg}");
    assert!(msg.contains("draft_angel_deg"), "{msg}");
}

#[test]
fn wrong_type_points_at_the_value() {
    // `  wall_thickness_mm: big`: the value starts in column 22
    let t = with_line(
        19,
        "  wall_thickness_mm: 1.0",
        &["  wall_thickness_mm: big"],
    );
    let (line, col, msg) = yaml_error(&t);
    assert_eq!((line, col), (19, 22), "{msg}");
    // and names the parameter path of the value
    assert!(msg.ends_with(" (at core.wall_thickness_mm)"), "{msg}");
    // `    outer_radius_mm: big` in a layer: column 22 as well
    let t = with_line(
        30,
        "    outer_radius_mm: 14.9",
        &["    outer_radius_mm: big"],
    );
    let (line, col, msg) = yaml_error(&t);
    assert_eq!((line, col), (30, 22), "{msg}");
    assert!(msg.ends_with(" (at layers[1].outer_radius_mm)"), "{msg}");
    // an unknown enum variant
    let t = with_line(25, "    process: cast", &["    process: poured"]);
    let (line, col, msg) = yaml_error(&t);
    assert_eq!(line, 25, "{msg}");
    assert!((5..=14).contains(&col), "{msg}");
    assert!(msg.contains("poured"), "{msg}");
}

#[test]
fn missing_field_points_into_its_mapping() {
    // remove `material:` (line 28) of layers[1], whose mapping then spans lines 27-29
    let t = with_line(28, "    material: ecoflex_00_30", &[]);
    let (line, col, msg) = yaml_error(&t);
    assert!((27..=29).contains(&line), "{msg}");
    assert!((3..=5).contains(&col), "{msg}");
    assert!(msg.contains("missing field `material`"), "{msg}");
}

#[test]
fn syntax_error_points_at_its_line() {
    // a tab-indented key under `core:`
    let t = with_line(17, "  material:", &["\tmaterial: borosilicate_glass"]);
    let (line, _col, msg) = yaml_error(&t);
    assert_eq!(line, 17, "{msg}");
}

#[test]
fn errors_inside_body_point_at_their_line() {
    // unknown key right under `body:` (new line 11)
    let t = with_line(
        11,
        "  profile:",
        &["  colour: red", "  profile: hemisphere_on_cylinder"],
    );
    let (line, col, msg) = yaml_error(&t);
    assert_eq!((line, col), (11, 3), "{msg}");
    assert!(msg.contains("unknown field `colour`"), "{msg}");
    // wrong type: `  radius_mm: big`, the value starts in column 14
    let t = with_line(12, "  radius_mm: 15.0", &["  radius_mm: big"]);
    let (line, col, msg) = yaml_error(&t);
    assert_eq!((line, col), (12, 14), "{msg}");
    // an unknown profile: the value starts in column 12
    let t = with_line(11, "  profile:", &["  profile: cone"]);
    let (line, col, msg) = yaml_error(&t);
    assert_eq!((line, col), (11, 12), "{msg}");
    assert!(msg.contains("cone"), "{msg}");
    // a key of another profile, and a missing one: inside the body mapping (lines 11-13)
    let t = with_line(13, "  cylinder_length_mm:", &["  height_mm: 6.0"]);
    let (line, _, msg) = yaml_error(&t);
    assert!((11..=13).contains(&line), "{msg}");
    assert!(
        msg.contains("body.height_mm") && msg.contains("body.cylinder_length_mm"),
        "{msg}"
    );
}

// ---------------------------------------------------------------------------------------------
// Display.

#[test]
fn param_error_displays_as_path_value_rule() {
    let e = ParamError::new("mold.draft_angle_deg", 12.0, "must be below 10");
    assert_eq!(e.to_string(), "mold.draft_angle_deg = 12: must be below 10");
    let e = ParamError::new("layers[1].material", "unobtainium", "unknown material");
    assert_eq!(
        e.to_string(),
        "layers[1].material = unobtainium: unknown material"
    );

    // and so does every error validate reports
    let mut d = baseline();
    d.layers[1].outer_radius_mm = Some(13.505);
    d.mold.vent.diameter_mm = 0.3;
    let errs = errors(&d);
    assert_eq!(errs.len(), 2);
    for e in &errs {
        assert_eq!(
            e.to_string(),
            format!("{} = {}: {}", e.path, e.value, e.rule)
        );
    }
    assert!(errs.iter().any(|e| e.to_string()
        == "layers[1].outer_radius_mm = 13.505: leaves layer 'translucent_gel' 0.0050 mm thick, below the chord tolerance 0.01 mm"));
    assert!(errs.iter().any(|e| e.to_string()
        == "mold.vent.diameter_mm = 0.3: below the minimum hole 1 mm of printer profile 'fdm'"));
    // the collection lists them all, one a line
    let all = fabkit_designs::ParamErrors(errs.clone()).to_string();
    assert!(all.starts_with("2 invalid design parameter(s):"), "{all}");
    for e in &errs {
        assert!(all.contains(&format!("\n  {e}")), "{all}");
    }
}

// ---------------------------------------------------------------------------------------------
// The shell arrangements.

/// The square split shell keeps its own rules on the camera bay's and the diffuser seat's walls.
#[test]
fn square_split_camera_board_wider_than_the_shell_allows() {
    let mut d = square_split();
    housing(&mut d).diffuser.outer_diameter_mm = 29.5;
    assert_exactly(
        &errors(&d),
        &[&Expect {
            path: "housing.diffuser.outer_diameter_mm",
            value: "29.5",
            rule: &[
                "0.05 mm of wall",
                "around the diffuser seat",
                "minimum wall 0.8 mm",
            ],
        }],
    );
    let mut d = square_split();
    housing(&mut d).camera.board_width_mm = 29.0;
    assert_exactly(
        &errors(&d),
        &[&Expect {
            path: "housing.camera.board_width_mm",
            value: "29",
            rule: &[
                "0.30 mm of wall",
                "beside the camera bay",
                "printer profile 'fdm'",
            ],
        }],
    );
}

/// `style: round_tube` without its `round_tube` block is a named error, not a panic.
#[test]
fn round_tube_without_its_parameters_is_named() {
    let mut d = baseline();
    housing(&mut d).round_tube = None;
    assert_exactly(
        &errors(&d),
        &[&Expect {
            path: "housing.round_tube",
            value: "missing",
            rule: &["required with housing.style = round_tube"],
        }],
    );
}

/// A bay wider than the LED PCB seat leaves no ledge under the PCB and too thin a wall for the
/// base screws' pilots (both named on the bay diameter), and moves the screws out so far that
/// their heads pass the outline. A short tube brings the screw pilots up beside the light
/// chamber; a light chamber
/// narrower than the LED PCB's seat does not let the PCB in from the top; a diffuser opening as
/// wide as the core lets the core through; a non-positive spigot is named on its own.
#[test]
fn round_tube_rules_name_their_parameters() {
    let mut d = baseline();
    housing(&mut d).round_tube.as_mut().unwrap().bay_diameter_mm = 26.0;
    assert_exactly(
        &errors(&d),
        &[
            &Expect {
                path: "housing.round_tube.bay_diameter_mm",
                value: "26",
                rule: &["ledge of -1.30 mm under the LED PCB"],
            },
            &Expect {
                path: "housing.round_tube.bay_diameter_mm",
                value: "26",
                rule: &["leaves 2.00 mm of tube wall", "need 3.20 mm"],
            },
            // The screws move out with the wall's middle, and their heads pass the outline.
            &Expect {
                path: "housing.joint_screw.head_diameter_mm",
                value: "3.8",
                rule: &["at radius 14.00 mm", "past the tube's outer diameter 30 mm"],
            },
        ],
    );
    let mut d = baseline();
    housing(&mut d).round_tube.as_mut().unwrap().height_mm = 19.0;
    // A short tube: the base's screw pilots, 5 mm up from the tube's bottom, reach beside the
    // light chamber (whether the camera board still fits under the LED PCB is the fit check's).
    assert_exactly(
        &errors(&d),
        &[&Expect {
            path: "housing.joint_screw.pilot_depth_mm",
            value: "5",
            rule: &["reaches 2.60 mm above the LED PCB's underside"],
        }],
    );
    // A tube too short for any camera bay.
    let mut d = baseline();
    housing(&mut d).round_tube.as_mut().unwrap().height_mm = 18.0;
    assert!(
        errors(&d)
            .iter()
            .any(|e| e.path == "housing.round_tube.height_mm"
                && e.rule.contains(
                    "leaves no camera bay between the base's spigot and the LED PCB (-0.60 mm)"
                )),
        "{}",
        listing(&errors(&d))
    );
    // The LED PCB goes in from the tube's top, down the light chamber.
    let mut d = baseline();
    housing(&mut d).light_chamber_diameter_mm = 23.0;
    assert_exactly(
        &errors(&d),
        &[&Expect {
            path: "housing.light_chamber_diameter_mm",
            value: "23",
            rule: &[
                "must pass the LED PCB",
                "outer_diameter_mm = 23",
                "fit clearance 0.2 mm",
            ],
        }],
    );
    // A pilot that reaches up beside the light chamber needs its wall there too.
    let mut d = baseline();
    housing(&mut d).joint_screw.pilot_depth_mm = 6.0;
    assert_exactly(
        &errors(&d),
        &[&Expect {
            path: "housing.joint_screw.pilot_depth_mm",
            value: "6",
            rule: &[
                "reaches 0.95 mm above the LED PCB's underside",
                "0.60 mm of wall is left to the light chamber",
                "minimum wall 0.8 mm",
            ],
        }],
    );
    // The core's rim rests on the diffuser's inner edge.
    let mut d = baseline();
    housing(&mut d).diffuser.inner_diameter_mm = 20.0;
    assert_exactly(
        &errors(&d),
        &[&Expect {
            path: "housing.diffuser.inner_diameter_mm",
            value: "20",
            rule: &[
                "below the core's outer diameter (20.00 mm)",
                "rests on the diffuser",
            ],
        }],
    );
    let mut d = baseline();
    housing(&mut d)
        .round_tube
        .as_mut()
        .unwrap()
        .base_spigot_height_mm = -1.0;
    assert_exactly(
        &errors(&d),
        &[&Expect {
            path: "housing.round_tube.base_spigot_height_mm",
            value: "-1",
            rule: &["must be above 0"],
        }],
    );
}

/// More vents than fit on the core holder's vent circle (10,000 once ran a minute of booleans
/// into a mesh error naming no parameter) is one named error, found before any vent is built.
/// (A rule of the mold's fit: checked once the layer stack is valid, so it is not among the
/// single mutations that combine with stack errors.)
#[test]
fn more_vents_than_fit_yield_one_error() {
    for (count, value) in [(22, "22"), (10_000, "10000"), (1_000_000, "1000000")] {
        let mut d = baseline();
        d.mold.vent.count = count;
        assert_exactly(
            &errors(&d),
            &[&Expect {
                path: "mold.vent.count",
                value,
                rule: &["at most 21 vents fit beside the sprue", "min_wall_mm (1.5)"],
            }],
        );
    }
    // past any count: refused as a number, before the rule
    let mut d = baseline();
    d.mold.vent.count = u32::MAX;
    assert_exactly(
        &errors(&d),
        &[&Expect {
            path: "mold.vent.count",
            value: "4294967295",
            rule: &[
                "vents fit beside the sprue",
                "(checked at 1000000, the most any count may be)",
            ],
        }],
    );
    let mut d = baseline();
    d.mold.vent.count = 21;
    assert_exactly(&errors(&d), &[]);
}

/// DIGIT Pinki's recess and open block: each broken rule is one error naming its path, value
/// and rule, and the library design itself is valid.
#[test]
fn pinki_recess_and_open_block_rules_name_their_parameters() {
    let pinki = || {
        Design::from_yaml(
            fabkit_designs::library::yaml("digit_pinki").unwrap(),
            ORIGIN,
        )
        .unwrap()
    };
    assert_exactly(&errors(&pinki()), &[]);
    let cases: Vec<(Box<dyn Fn(&mut Design)>, Expect)> = vec![
        (
            Box::new(|d| d.layers[0].recess.as_mut().unwrap().cap_radius_mm = 3.0),
            Expect {
                path: "layers[0].recess.cap_radius_mm",
                value: "3",
                rule: &["must exceed", "meets the wall above the base plane"],
            },
        ),
        (
            Box::new(|d| d.layers[0].recess.as_mut().unwrap().fillet_radius_mm = 3.5),
            Expect {
                path: "layers[0].recess.fillet_radius_mm",
                value: "3.5",
                rule: &["too large"],
            },
        ),
        (
            Box::new(|d| d.layers[0].recess.as_mut().unwrap().draft_angle_deg = 45.0),
            Expect {
                path: "layers[0].recess.draft_angle_deg",
                value: "45",
                rule: &["[0, 45)"],
            },
        ),
        (
            Box::new(|d| {
                let r = d.layers[0].recess.as_mut().unwrap();
                (r.depth_mm, r.cap_radius_mm) = (15.6, 9.0);
            }),
            Expect {
                path: "layers[0].recess.depth_mm",
                value: "15.6",
                rule: &["below the skin's height"],
            },
        ),
        (
            // a nearly flat roof 15.5 mm up pokes out of the R7.5 tip
            Box::new(|d| {
                let r = d.layers[0].recess.as_mut().unwrap();
                (r.depth_mm, r.cap_radius_mm) = (15.5, 20.0);
            }),
            Expect {
                path: "layers[0].recess",
                value: "given",
                rule: &["breaks through the skin's outer surface"],
            },
        ),
        (
            Box::new(|d| d.mold.open_block.as_mut().unwrap().width_mm = 15.0),
            Expect {
                path: "mold.open_block.width_mm",
                value: "15",
                rule: &["min_wall_mm each side"],
            },
        ),
        (
            Box::new(|d| d.mold.open_block.as_mut().unwrap().height_mm = 15.6),
            Expect {
                path: "mold.open_block.height_mm",
                value: "15.6",
                rule: &["cavity's height"],
            },
        ),
        (
            Box::new(|d| {
                d.mold.strategy = fabkit_designs::schema::MoldStrategy::TwoPieceOpen;
                d.mold.open_block = None;
            }),
            Expect {
                path: "layers[0].recess",
                value: "given",
                rule: &["open mold strategy"],
            },
        ),
    ];
    for (mutate, want) in cases {
        let mut d = pinki();
        mutate(&mut d);
        assert_exactly(&errors(&d), &[&want]);
    }
    // a mutation in the YAML text is reported like one in Rust
    let t = fabkit_designs::library::yaml("digit_pinki")
        .unwrap()
        .replacen("draft_angle_deg: 2.0", "draft_angle_deg: -1.0", 1);
    let d = Design::from_yaml(&t, ORIGIN).unwrap();
    let errs = errors(&d);
    assert_eq!(errs.len(), 1, "{}", listing(&errs));
    assert_eq!(
        errs[0].to_string(),
        "layers[0].recess.draft_angle_deg = -1: must be in [0, 45)"
    );
}

/// The least wall of DIGIT Pinki is its open block's 1.4 mm beyond the pole (17.0 mm block,
/// 15.6 mm gel), not `mold.wall_thickness_mm`; a seat 14 mm across at its mouth (no fillet)
/// leaves 0.5 mm of skin beside the mouth, inside the R7.5 cylinder: the least.
#[test]
fn pinki_min_wall_is_the_open_blocks_or_the_skin_over_its_seat() {
    use fabkit_designs::variant::{evaluate, Outcome};
    let materials = MaterialsTable::embedded().unwrap();
    let tol = ChordTolerance::default();
    let least = |d: &Design| match evaluate(d, &materials, tol) {
        Outcome::Ok { metrics, .. } => (metrics.min_wall_mm.unwrap(), metrics.min_wall_at.unwrap()),
        _ => panic!("digit_pinki does not build"),
    };
    let mut d = Design::from_yaml(
        fabkit_designs::library::yaml("digit_pinki").unwrap(),
        ORIGIN,
    )
    .unwrap();
    let (w, at) = least(&d);
    assert!((w - 1.4).abs() < 1e-9, "{w} at {at}");
    assert!(at.starts_with("mold.open_block.height_mm"), "{at}");
    let r = d.layers[0].recess.as_mut().unwrap();
    (r.base_diameter_mm, r.cap_radius_mm, r.fillet_radius_mm) = (14.0, 9.5, 0.0);
    let (w, at) = least(&d);
    assert!((w - 0.5).abs() < 1e-9, "{w} at {at}");
    assert!(at.starts_with("layers[0].recess: the skin between"), "{at}");
}

/// The lens's front must sit in the air under the gel's free surface (z = -9, the core's open
/// end, which the resolved core places): 17 mm over the spigot's top (z = -25.65) is above it;
/// 16.6 mm, 0.05 mm under it, passes. A lens under a broken stack is checked once the stack is
/// sound.
#[test]
fn lens_above_the_gel_surface_is_named() {
    let mut d = baseline();
    housing(&mut d).camera.lens_height_mm = Some(17.0);
    assert_exactly(
        &errors(&d),
        &[&Expect {
            path: "housing.camera.lens_height_mm",
            value: "17",
            rule: &[
                "lens's front at z = -8.65 mm",
                "not below the filling gel's free surface (z = -9.00 mm)",
            ],
        }],
    );
    housing(&mut d).camera.lens_height_mm = Some(16.6);
    assert_exactly(&errors(&d), &[]);
    housing(&mut d).camera.lens_height_mm = Some(-1.0);
    assert_exactly(
        &errors(&d),
        &[&Expect {
            path: "housing.camera.lens_height_mm",
            value: "-1",
            rule: &["must be above 0"],
        }],
    );
}

/// Every mold strategy the schema publishes (`MoldStrategy`'s values) has exactly one line in
/// `molds::STRATEGIES`, which the build and the cast check look a layer's strategy up in: a
/// strategy added to the schema but not listed would panic there.
#[test]
fn every_strategy_is_listed() {
    use fabkit_designs::molds::{strategy_of, STRATEGIES};
    let schema = fabkit_designs::schema::design_json_schema();
    let names: Vec<String> = schema["$defs"]["MoldStrategy"]["oneOf"]
        .as_array()
        .expect("MoldStrategy is a oneOf of constants")
        .iter()
        .map(|v| v["const"].as_str().expect("a constant").to_owned())
        .collect();
    assert_eq!(names.len(), 5, "{names:?}");
    assert_eq!(STRATEGIES.len(), names.len());
    for n in &names {
        let kind: fabkit_designs::schema::MoldStrategy =
            serde_json::from_value(serde_json::json!(n)).unwrap();
        assert_eq!(strategy_of(kind).kind(), kind, "{n}");
        assert_eq!(
            STRATEGIES.iter().filter(|s| s.kind() == kind).count(),
            1,
            "{n}"
        );
    }
}
