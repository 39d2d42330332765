//! The assembled sensor and its fit check: members in the sensor frame with their analytic
//! volumes, designed contacts that are not interferences, and one fit broken at a time giving
//! one named interference with its analytic overlap.

use fabkit_designs::assembly::{fit_errors, interferences, ExactShape, Member, MemberKind};
use fabkit_designs::{build_kit, ChordTolerance, Kit};
use std::f64::consts::PI;
use std::sync::OnceLock;

fn tol() -> ChordTolerance {
    ChordTolerance::new(0.01).unwrap()
}

/// R-Tac0's kit at 0.01 mm, built once for the tests of this module.
fn rtac0() -> &'static Kit {
    static KIT: OnceLock<Kit> = OnceLock::new();
    KIT.get_or_init(|| build_kit(&fabkit_designs::library::load("rtac0").unwrap(), tol()).unwrap())
}

fn member<'a>(members: &'a [Member], name: &str) -> &'a Member {
    members
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("no member {name}"))
}

fn rel_close(a: f64, b: f64, rel: f64, what: &str) {
    assert!((a - b).abs() <= rel * b.abs(), "{what}: {a} vs {b}");
}

/// Every part of the sensor in the sensor frame: the printed shell turned back from its print
/// pose (the collar's top face on the base plane z = -6 mm, 30 mm across), the cast layers and
/// the bought envelopes with their analytic volumes (hemisphere of radius r on a 6 mm cylinder
/// down to the base plane; the tube continues 3 mm below it).
#[test]
fn rtac0_members_are_in_the_sensor_frame_with_their_volumes() {
    let a = &rtac0().assembly;
    let names: Vec<(&str, MemberKind)> = a.iter().map(|m| (m.name.as_str(), m.kind)).collect();
    assert_eq!(
        names,
        [
            ("shell_collar", MemberKind::Printed),
            ("shell_tube", MemberKind::Printed),
            ("shell_base", MemberKind::Printed),
            ("transparent_gel", MemberKind::Cast),
            ("translucent_gel", MemberKind::Cast),
            ("black_coating", MemberKind::Cast),
            ("core_envelope", MemberKind::Bought),
            ("filling_gel", MemberKind::Cast),
            ("led_pcb_envelope", MemberKind::Bought),
            ("camera_board_envelope", MemberKind::Bought),
            ("diffuser_envelope", MemberKind::Bought),
        ]
    );
    // the collar from the base plane down to the diffuser (3 mm), the 2 mm diffuser disc, then
    // the tube
    let collar = member(a, "shell_collar").solid.bounding_box().unwrap();
    assert!(
        (collar.max[2] - -6.0).abs() < 1e-9 && (collar.min[2] - -9.0).abs() < 1e-9,
        "{collar:?}"
    );
    let tube = member(a, "shell_tube").solid.bounding_box().unwrap();
    assert!((tube.max[2] - -11.0).abs() < 1e-9, "{tube:?}");
    assert!((tube.max[0] - 15.0).abs() < 1e-6 && (tube.min[0] + 15.0).abs() < 1e-6);
    let printed = rtac0()
        .parts
        .iter()
        .find(|p| p.name == "shell_tube")
        .unwrap();
    rel_close(
        member(a, "shell_tube").solid.volume(),
        printed.solid.volume(),
        1e-9,
        "tube",
    );
    let shell = |ri: f64, ro: f64, below: f64| {
        2.0 / 3.0 * PI * (ro.powi(3) - ri.powi(3)) + PI * (ro * ro - ri * ri) * (6.0 + below)
    };
    for (name, v, ri) in [
        ("transparent_gel", shell(10.0, 13.5, 0.0), 10.0),
        ("translucent_gel", shell(13.5, 14.9, 0.0), 13.5),
        ("black_coating", shell(14.9, 15.0, 0.0), 14.9),
        ("core_envelope", shell(9.0, 10.0, 3.0), 9.0),
    ] {
        // Both surfaces of a shell are inscribed at the chord tolerance d = 0.01 mm: each loses
        // about d x its area, so the shell changes by about d (A_outer - A_inner), some
        // 2 d / r_inner of its volume for the hemisphere and less for the cylinder; allowed
        // twice that again (the triangles' sagittas spread about d): 4 d / r_inner, 0.27 % for
        // the coat (issue 96 asked 1 %; measured 0.04 to 0.07 % for the four)
        rel_close(member(a, name).solid.volume(), v, 4.0 * 0.01 / ri, name);
    }
    // the camera board: 15 mm square, 3 mm of board and components, on the base's spigot
    let board = member(a, "camera_board_envelope").solid.volume();
    rel_close(board, 15.0 * 15.0 * 3.0, 1e-9, "camera board");
    // rings of 3 mm (collar: 30 mm across, bored to the core's 20 mm + 2 x 0.2 mm) and of 2 mm
    // (the diffuser disc, 30 mm with its 19.6 mm opening, authors' CAD, measured); the
    // inscribed bore's polygon adds at most 2 x 0.01 / 4.8 of the collar's volume, and the
    // same 2 d / (ro - ri) bounds the filling gel and the diffuser (measured -0.040 %, -0.053 %
    // and -0.037 %: the outer circles' polygons lose more than the bores' give back)
    let ring = |ro: f64, ri: f64, h: f64| PI * (ro * ro - ri * ri) * h;
    rel_close(
        member(a, "shell_collar").solid.volume(),
        ring(15.0, 10.2, 3.0),
        2.0 * 0.01 / 4.8,
        "collar",
    );
    // the filling gel (R-Tac0 Sec. III-B1, `fills: core`): the core's inside (radius 9 mm,
    // hemisphere on 6 + 3 mm of cylinder) down to the tube's mouth at z = -9 mm
    let gel = member(a, "filling_gel");
    rel_close(
        gel.solid.volume(),
        shell(0.0, 9.0, 3.0),
        2.0 * 0.01 / 9.0,
        "filling gel",
    );
    assert!((gel.solid.bounding_box().unwrap().min[2] - -9.0).abs() < 1e-9);
    rel_close(
        member(a, "diffuser_envelope").solid.volume(),
        ring(15.0, 9.8, 2.0),
        2.0 * 0.01 / 5.2,
        "diffuser",
    );
}

/// `fills: chamber` pours the gel on through the diffuser's opening (9.8 mm, 2 mm) and the
/// light chamber (11.7 mm, 10 mm down to the LED PCB's face at z = -21 mm).
#[test]
fn a_gel_that_fills_the_chamber_reaches_the_led_pcb() {
    let text = fabkit_designs::library::LIBRARY
        .iter()
        .find(|(n, _)| *n == "rtac0")
        .unwrap()
        .1
        .replace("fills: core ", "fills: chamber ")
        // the lens's front under the gel's surface at the PCB's face (z = -21): 4 mm over the
        // spigot's top (z = -25.65)
        .replace("lens_height_mm: 8.25 ", "lens_height_mm: 4.0 ");
    let design = fabkit_designs::Design::from_yaml(&text, "rtac0.yaml").unwrap();
    let kit = build_kit(&design, ChordTolerance::new(0.05).unwrap()).unwrap();
    let gel = member(&kit.assembly, "filling_gel");
    let shell = |r: f64, below: f64| 2.0 / 3.0 * PI * r.powi(3) + PI * r * r * (6.0 + below);
    let disc = |r: f64, h: f64| PI * r * r * h;
    rel_close(
        gel.solid.volume(),
        shell(9.0, 3.0) + disc(9.8, 2.0) + disc(11.7, 10.0),
        2.0 * 0.05 / 9.0,
        "filling gel",
    );
    assert!((gel.solid.bounding_box().unwrap().min[2] - -21.0).abs() < 1e-9);
}

/// Parts that are designed to touch (the skin's base on the shell's top face, the tube's rim
/// on the diffuser, the board on the base's spigot) are not interferences, however their
/// tessellations cross; layers without markers and the core are nested by the stack and not
/// intersected. (UVDtact's layers, whose slots and protrusions interlock, are intersected in
/// every build of its kit.)
/// Each non-printed member carries the exact shape STEP export builds it from, and that shape
/// is the member: envelopes' analytic volumes and boxes match the solids within the chord
/// bound, revolved profiles are closed (r, z) polygons with r >= 0 spanning the solid's z
/// range, layers carry their offsets; printed members carry none (their parts' params do).
#[test]
fn rtac0_members_carry_their_exact_shapes() {
    for m in &rtac0().assembly {
        let bb = m.solid.bounding_box().unwrap();
        let bound = m.solid.surface_area() * tol().mm();
        let exact_volume = match (&m.kind, &m.exact) {
            (MemberKind::Printed, None) => continue,
            (
                _,
                Some(ExactShape::Cylinder {
                    radius_mm,
                    z0_mm,
                    z1_mm,
                }),
            ) => PI * radius_mm * radius_mm * (z1_mm - z0_mm),
            (
                _,
                Some(ExactShape::Ring {
                    outer_radius_mm: ro,
                    inner_radius_mm: ri,
                    z0_mm,
                    z1_mm,
                }),
            ) => PI * (ro * ro - ri * ri) * (z1_mm - z0_mm),
            (_, Some(ExactShape::Box { min_mm, max_mm })) => {
                (0..3).map(|k| max_mm[k] - min_mm[k]).product()
            }
            (_, Some(ExactShape::Revolved { profile_rz_mm })) => {
                assert!(profile_rz_mm.len() >= 3 && profile_rz_mm.iter().all(|p| p[0] >= 0.0));
                let (zlo, zhi) = profile_rz_mm
                    .iter()
                    .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p[1]), b.max(p[1])));
                assert!(
                    (zlo - bb.min[2]).abs() < 1e-9 && (zhi - bb.max[2]).abs() < 1e-9,
                    "{}",
                    m.name
                );
                // Pappus: the volume of revolution of the polygon (shoelace centroid)
                let n = profile_rz_mm.len();
                let mut v = 0.0;
                for i in 0..n {
                    let (p, q) = (profile_rz_mm[i], profile_rz_mm[(i + 1) % n]);
                    v += (p[0] * q[1] - q[0] * p[1]) * (p[0] + q[0]);
                }
                (PI * v / 3.0).abs()
            }
            (_, Some(ExactShape::Layer { params })) => {
                assert_eq!(params["layer"], m.name.as_str());
                assert!(params["outer_offset_mm"].is_f64());
                continue;
            }
            (kind, exact) => panic!("{}: {kind:?} with {exact:?}", m.name),
        };
        assert!(
            (exact_volume - m.solid.volume()).abs() <= bound,
            "{}: exact {exact_volume} mm3, solid {} mm3, bound {bound}",
            m.name,
            m.solid.volume()
        );
    }
}

#[test]
fn designed_contacts_are_not_interferences() {
    assert_eq!(interferences(&rtac0().assembly, tol()).unwrap(), vec![]);
}

/// One fit broken at a time gives one interference naming both parts, with the overlap's
/// analytic volume, and an error naming a parameter that sizes them, its value and the rule.
#[test]
fn each_broken_fit_is_one_named_interference() {
    let base = &rtac0().assembly;
    let moved = |name: &str, dz: f64| -> Vec<Member> {
        base.iter()
            .map(|m| {
                let mut m = m.clone();
                if m.name == name {
                    m.solid = m.solid.translate([0.0, 0.0, dz]);
                }
                m
            })
            .collect()
    };
    // the board 1 mm up into the LED PCB: the board's square less the PCB's 7.5 mm bore, over
    // the 0.95 mm the board now reaches past the PCB's underside (0.05 mm gap)
    let board_into_pcb = (225.0 - PI * 7.5 * 7.5) * 0.95;
    // the collar 0.5 mm down into the diffuser disc (15 / 9.8 mm radii): the collar's ring
    // (10.2 to 15 mm) over the disc
    let collar_into_diffuser = PI * (15.0f64.powi(2) - 10.2f64.powi(2)) * 0.5;
    for (name, dz, other, v) in [
        (
            "camera_board_envelope",
            1.0,
            "led_pcb_envelope",
            board_into_pcb,
        ),
        (
            "shell_collar",
            -0.5,
            "diffuser_envelope",
            collar_into_diffuser,
        ),
    ] {
        let found = interferences(&moved(name, dz), tol()).unwrap();
        let pairs: Vec<(&str, &str)> = found.iter().map(|f| (f.a.as_str(), f.b.as_str())).collect();
        let one = found.iter().find(|f| f.a == name || f.b == name);
        assert!(
            found.len() == 1 && one.is_some_and(|f| f.a == other || f.b == other),
            "{name}: {pairs:?}"
        );
        // Each circle's polygon (segments at sagitta s = 0.01 / sqrt 2) is short of it by
        // r^2 (pi - n/2 sin(2 pi / n)), about (4/3) pi r s: the PCB's R7.5 bore by 0.20 mm^2 on
        // the 48.3 mm^2 overlap, +0.42 %; the collar's R15 loses 0.43 and its R10.2 bore gives
        // 0.28 mm^2 back on 380 mm^2, -0.04 %. Measured +0.417 % and -0.040 % (as predicted);
        // a wrong overlap (the wrong part, or its height) is off by tens of %.
        rel_close(found[0].volume_mm3, v, 0.01, name);
        let e = fit_errors(&fabkit_designs::library::load("rtac0").unwrap(), &found)
            .unwrap()
            .to_string();
        assert!(
            e.contains(&format!(
                "`{}` and `{}` overlap by {:.3} mm³",
                found[0].a, found[0].b, found[0].volume_mm3
            )) && e.contains("change housing."),
            "{e}"
        );
    }
}

/// A camera board taller than the room between the base and the LED PCB (3.5 mm where 3.05 mm
/// are left) is not a validation rule but the fit check's: one error naming the board's height
/// with its value, both parts and the overlap (the board's square less the PCB's 7.5 mm bore,
/// over the 0.45 mm it reaches past the PCB's underside; the bore's polygon lies inside its
/// circle, so the overlap is up to 1 % more), and no kit.
#[test]
fn a_camera_board_too_tall_for_its_bay_is_a_named_fit_error() {
    let mut d = fabkit_designs::library::load("rtac0").unwrap();
    d.housing.as_mut().unwrap().camera.bay_height_mm = 3.5;
    let e = match build_kit(&d, tol()) {
        Err(fabkit_designs::DesignError::Params(e)) => e,
        other => panic!("{:?}", other.map(|k| k.design)),
    };
    assert_eq!(e.0.len(), 1, "{e}");
    let want = (225.0 - PI * 7.5 * 7.5) * 0.45;
    let got: f64 = e.0[0]
        .rule
        .split("overlap by ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap();
    // The bore's polygon adds 0.20 mm^2 to the 48.3 mm^2 (+0.42 %, as in
    // `each_broken_fit_is_one_named_interference`): measured +0.417 %; 0.999 allows the
    // message's 3 decimals (5e-4 of 21.7 mm^3), the overlap cannot be less.
    assert!(
        e.0[0].path == "housing.camera.bay_height_mm"
            && e.0[0].value == "3.5"
            && e.0[0]
                .rule
                .contains("`led_pcb_envelope` and `camera_board_envelope` overlap by")
            && got >= want * 0.999
            && got <= want * 1.01,
        "{e} (analytic {want})"
    );
}

/// UVDtact's two mixed layers interlock: the outer layer's 85 protrusions fill the inner
/// layer's 85 slots (Sec. III). The fit check intersects nested layers only inside the features
/// that grow them, and skips protrusions that the neighbour cuts as the very same slots: no
/// interference. Protrusions 0.3 mm longer than the slots reach into the inner layer: one
/// interference of the two layers, its volume the whole layers' intersection (to 0.1 %: the
/// booleans meet in another order) and about 85 x pi x 0.5^2 x 0.3 mm^3 (the cylinders' extra
/// length), its error naming both layers.
#[test]
fn interlocking_layers_are_checked_inside_their_features() {
    use fabkit_designs::{library, materials::MaterialsTable, stack};
    let materials = MaterialsTable::embedded().unwrap();
    let layers = |d: &fabkit_designs::Design| -> Vec<Member> {
        let st = stack::validate(d, &materials, tol()).unwrap();
        fabkit_designs::assembly::members(d, &st, &[], tol())
            .unwrap()
            .into_iter()
            .filter(|m| m.kind == MemberKind::Cast)
            .collect()
    };
    let d = library::load("uvdtact").unwrap();
    let fits = layers(&d);
    assert_eq!(fits.len(), 3);
    assert!(fits.iter().all(|m| m.nested_by_stack));
    assert_eq!(interferences(&fits, tol()).unwrap(), vec![]);

    let mut long = d.clone();
    long.layers[1].markers[0].feature.height_mm = 1.3;
    let members = layers(&long);
    let found = interferences(&members, tol()).unwrap();
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(
        (found[0].a.as_str(), found[0].b.as_str()),
        ("inner_mixed", "outer_mixed")
    );
    let whole = member(&members, "inner_mixed")
        .solid
        .intersection(&member(&members, "outer_mixed").solid)
        .unwrap()
        .volume();
    // measured 6.3e-5 (the same solids met in another order)
    rel_close(
        found[0].volume_mm3,
        whole,
        1e-3,
        "overlap inside the features",
    );
    // measured -0.83 %: the features are revolved at half the tolerance, the R0.5 circles as
    // 28-gons, 1 - 28/(2 pi) sin(2 pi/28) = 0.84 % short of them (a length 0.1 mm off would
    // be 33 % off)
    rel_close(
        found[0].volume_mm3,
        85.0 * PI * 0.25 * 0.3,
        0.02,
        "85 cylinders 0.3 mm long",
    );
    let e = fit_errors(&long, &found).unwrap().to_string();
    assert!(e.contains("change layers[1] or layers[0]"), "{e}");
}

/// A kit built only to be measured ([`AssemblyScope::FitCheck`], a metrics-only sweep) stands
/// cast layers in by their featureless shells with their growing features, and builds a layer
/// exactly only where its stand-in overlaps: R-Tac0 gives the same parts (the same written
/// meshes) and the whole assembly but its cast layers; UVDtact with protrusions longer than
/// their slots gives the whole build's very error.
#[test]
fn a_fit_check_build_gives_the_whole_builds_parts_and_errors() {
    use fabkit_designs::build::{build_kit_scoped, AssemblyScope};
    let d = fabkit_designs::library::load("rtac0").unwrap();
    let whole = rtac0();
    let fit = build_kit_scoped(&d, tol(), u64::MAX, AssemblyScope::FitCheck).unwrap();
    assert_eq!(fit.parts.len(), whole.parts.len());
    for (a, b) in fit.parts.iter().zip(&whole.parts) {
        assert_eq!(a.name, b.name);
        assert!(a.written_mesh() == b.written_mesh(), "{}", a.name);
    }
    let names = |k: &[Member]| -> Vec<String> { k.iter().map(|m| m.name.clone()).collect() };
    let not_layers: Vec<Member> = whole
        .assembly
        .iter()
        .filter(|m| !d.layers.iter().any(|l| l.name == m.name))
        .cloned()
        .collect();
    assert!(not_layers.len() < whole.assembly.len());
    assert_eq!(names(&fit.assembly), names(&not_layers));

    let mut long = fabkit_designs::library::load("uvdtact").unwrap();
    long.layers[1].markers[0].feature.height_mm = 1.3;
    let err = |scope| {
        build_kit_scoped(&long, tol(), u64::MAX, scope)
            .expect_err("the protrusions overlap the inner layer")
            .to_string()
    };
    let e = err(AssemblyScope::FitCheck);
    assert!(
        e.contains("`inner_mixed` and `outer_mixed` overlap by"),
        "{e}"
    );
    assert_eq!(e, err(AssemblyScope::Whole));
}
