//! The dual-modal TacTip's body and its tip's bayonet fitting (Pestell et al. Sec. III-A,
//! Fig. 1): the bayonet's bands against their analytic volumes, the locked lugs clear of the
//! grooves, the assembled sensor free of interferences, one fit broken at a time giving one
//! named interference with its analytic overlap, and one bad value per rule refused by path.

use crate::common::{assert_each_rule_names_its_path, assert_one_interference, RuleCase};
use fabkit_designs::assembly::{interferences, ExactShape, MemberKind};
use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::parts::bayonet::band;
use fabkit_designs::parts::family::FamilyInput;
use fabkit_designs::parts::shaft_body::tip_bayonet;
use fabkit_designs::{build_kit, library, stack, ChordTolerance, Design, Kit, Solid};
use std::f64::consts::PI;
use std::sync::OnceLock;

fn tol() -> ChordTolerance {
    ChordTolerance::new(0.01).unwrap()
}

fn tactip() -> Design {
    library::load("tactip_dualmodal").unwrap()
}

/// The TacTip's kit at 0.01 mm, built once for the tests of this module.
fn kit() -> &'static Kit {
    static KIT: OnceLock<Kit> = OnceLock::new();
    KIT.get_or_init(|| build_kit(&tactip(), tol()).unwrap())
}

fn rel_close(a: f64, b: f64, rel: f64, what: &str) {
    assert!((a - b).abs() <= rel * b.abs(), "{what}: {a} vs {b}");
}

/// A band's volume is the annular sector's, whatever its ramp (the ramp shears it along z):
/// (r1^2 - r0^2) / 2 x span x height, less the polygon's shortfall (within 0.2 % at 0.01 mm);
/// it is a closed 2-manifold of genus 0 either way.
///
/// The 0.7 rad span is 11 chords of d = 0.064 rad: -d^2 / 6 = -0.067 %, measured flat. The ramp's
/// top and bottom quads are twisted and split on opposite diagonals, which adds
/// (r1 - r0) slope d / (3 (r1 + r0) h) = +-0.029 % per 0.3 mm/rad: measured -0.039 % (slope 0.3)
/// and -0.106 % (slope -0.4), as predicted.
#[test]
fn bayonet_bands_have_the_sectors_volume_ramped_or_flat() {
    let (r0, r1, a0, a1, z0, z1) = (10.0, 12.0, 0.2, 0.9, -3.0, -1.0);
    let exact = (r1 * r1 - r0 * r0) / 2.0 * (a1 - a0) * (z1 - z0);
    for slope in [0.0, 0.3, -0.4] {
        let s = Solid::from_mesh(&band((r0, r1), (a0, a1), (z0, z1), slope, tol())).unwrap();
        let v = s.volume();
        assert!(
            v <= exact * (1.0 + 1e-9) && v >= exact * 0.998,
            "slope {slope}: {v} vs {exact}"
        );
        assert_eq!(s.genus(), 0, "slope {slope}");
        let b = s.bounding_box().unwrap();
        let rise = slope * (a1 - a0);
        rel_close(b.min[2], z0 + rise.min(0.0), 1e-9, "bottom");
        rel_close(b.max[2], z1 + rise.max(0.0), 1e-9, "top");
    }
}

/// The locked lugs: `lug_count` of them (from the printer profile), each the sector of the
/// lug's width and height from `lug_depth_mm` inside the spigot out to the given radius, and
/// none of them touches the spigot less its grooves (the clearance all round).
#[test]
fn locked_lugs_sit_clear_inside_their_grooves() {
    let d = tactip();
    let sb = d.shaft_body.as_ref().unwrap();
    let b = tip_bayonet(&d.context(), sb);
    assert_eq!(b.lug_count, d.printers.fdm.bayonet.lug_count);
    assert_eq!(b.lug_count, 3);
    let r = b.spigot_radius_mm;
    let outer = r + 0.2;
    let lugs = b.lugs(outer, tol()).unwrap();
    let exact = f64::from(b.lug_count) * (outer * outer - (r - b.lug_depth_mm).powi(2)) / 2.0
        * (b.lug_width_mm / r)
        * b.lug_height_mm;
    let v = lugs.volume();
    // measured -0.071 %: -d^2 / 6 of the lugs' chords (d = 0.065 rad), as for the bands above
    assert!(
        v <= exact * (1.0 + 1e-9) && v >= exact * 0.998,
        "{v} vs {exact}"
    );
    let spigot = fabkit_designs::geometry::cylinder(20.0, r, tol())
        .unwrap()
        .translate([0.0, 0.0, b.spigot_end_z_mm - 20.0]);
    let grooved = spigot.difference(&b.grooves(tol()).unwrap()).unwrap();
    assert!(grooved.volume() < spigot.volume());
    let touching = grooved.intersection(&lugs).unwrap().volume();
    assert!(
        touching < 1e-9,
        "lugs overlap the grooved spigot by {touching} mm3"
    );
    // the entry grooves rise by the ramp over the turn: an arc of 30 deg on the 11.5 mm
    // spigot (6.0214 mm) at tan 2 deg (0.034921), worked by hand
    rel_close(b.rise_mm(), 0.21027, 1e-4, "rise");
}

/// The kit prints the fitting with the skin (same 3MF object) and the ABS body on FDM; the
/// assembly holds them with the window, the LED ring, the camera board and lens and the cast
/// gel, without an interference; the manifest's view fraction is the share of the skin's inner
/// surface the lens sees, between 0 and 1.
#[test]
fn tactip_kit_has_the_body_and_an_assembly_without_interferences() {
    let k = kit();
    let parts: Vec<(&str, &str)> = k
        .parts
        .iter()
        .map(|p| (p.name.as_str(), p.material.as_str()))
        .collect();
    assert_eq!(
        parts,
        [
            ("skin", "tango_black_plus"),
            ("skin_tips", "vero_white"),
            ("tip_fitting", "vero_white"),
            ("shaft_body", "abs"),
            ("robot_mount", "abs"),
        ]
    );
    assert_eq!(k.parts[2].group, k.parts[0].group);
    let names: Vec<(&str, MemberKind)> = k
        .assembly
        .iter()
        .map(|m| (m.name.as_str(), m.kind))
        .collect();
    for want in [
        ("tip_fitting", MemberKind::Printed),
        ("shaft_body", MemberKind::Printed),
        ("robot_mount", MemberKind::Printed),
        ("filling_gel", MemberKind::Cast),
        ("lens_window_envelope", MemberKind::Bought),
        ("led_ring_envelope", MemberKind::Bought),
        ("camera_board_envelope", MemberKind::Bought),
        ("camera_lens_envelope", MemberKind::Bought),
    ] {
        assert!(names.contains(&want), "{want:?} not in {names:?}");
    }
    assert_eq!(interferences(&k.assembly, tol()).unwrap(), vec![]);
    let f = k.summary["camera_view"]["tip_inner_surface_fraction_seen"]
        .as_f64()
        .unwrap();
    assert!(f > 0.0 && f <= 1.0, "{f}");
    // a wider LED ring bore shades less of the tip
    let mut d = tactip();
    d.shaft_body.as_mut().unwrap().led_ring.inner_diameter_mm = 10.0;
    let materials = MaterialsTable::embedded().unwrap();
    let st = stack::validate(&d, &materials, tol()).unwrap();
    let narrow = fabkit_designs::parts::shaft_body::view_fraction(
        d.shaft_body.as_ref().unwrap(),
        FamilyInput {
            ctx: &d.context(),
            stack: &st,
            tol: tol(),
        },
    );
    assert!(narrow < f, "{narrow} vs {f}");
}

/// The filling gel carries its exact shape (STEP export builds its B-rep from it): the skin
/// layer's inside round its pins and tips, from the same twin parameters as the printed skin
/// (offsets, body, markers), and the lip's opening, whose bottom is the gel's lowest point and
/// whose top reaches into the cavity (the skin's base plane); a gel whose solid is that union
/// (its volume above the bare opening disc).
#[test]
fn the_filling_gel_carries_its_exact_shape() {
    let k = kit();
    let gel = k.assembly.iter().find(|m| m.name == "filling_gel").unwrap();
    let skin = k.parts.iter().find(|p| p.name == "skin").unwrap();
    let Some(ExactShape::InnerCavity {
        params,
        opening_radius_mm: r,
        opening_z0_mm: z0,
        opening_z1_mm: z1,
    }) = &gel.exact
    else {
        panic!("filling gel's exact shape: {:?}", gel.exact);
    };
    for key in [
        "layer",
        "body",
        "inner_offset_mm",
        "outer_offset_mm",
        "markers",
    ] {
        assert_eq!(params[key], skin.params[key], "{key}");
    }
    let bb = gel.solid.bounding_box().unwrap();
    assert!((bb.min[2] - z0).abs() < 1e-9, "{} vs {z0}", bb.min[2]);
    let base_z = tactip().body.base_z_mm();
    assert!(
        *z0 < base_z && *z1 > base_z && *z1 - base_z < 0.02,
        "{z0} {z1} {base_z}"
    );
    assert!(*r > 0.0 && bb.max[0] > *r);
    assert!(gel.solid.volume() > PI * r * r * (z1 - z0));
}

/// The LED ring's seat bored 0.3 mm under the ring's diameter: one error naming the seat's
/// diameter with its value, both parts and the overlap, the ring of 18 / 17.7 mm over the
/// ring's thickness and its LEDs' height (2.6 mm); no kit.
#[test]
fn a_seat_too_small_for_the_led_ring_is_a_named_interference() {
    let mut d = tactip();
    d.shaft_body.as_mut().unwrap().led_ring.seat_diameter_mm = Some(17.7);
    assert_one_interference(
        &d,
        ("shaft_body.led_ring.seat_diameter_mm", "17.7"),
        "`shaft_body` and `led_ring_envelope`",
        &[],
        PI * (9.0f64.powi(2) - 8.85f64.powi(2)) * 2.6,
        0.02,
    );
}

/// A lug 1 mm wider than designed with its groove's width pinned (3.4 mm): each of the three
/// lugs reaches 0.3 mm past the locking groove's closed end, into the spigot between the
/// groove's floor (lug depth 0.8 mm) and the spigot's surface (11.5 mm), over the lug's
/// 1.5 mm height. One error naming the groove's width, both parts and the overlap; no kit.
#[test]
fn a_lug_too_wide_for_its_groove_is_a_named_interference() {
    let mut d = tactip();
    let b = &mut d.shaft_body.as_mut().unwrap().bayonet;
    b.groove_width_mm = Some(b.lug_width_mm + 0.4);
    b.lug_width_mm += 1.0;
    let r: f64 = 11.5;
    assert_one_interference(
        &d,
        ("shaft_body.bayonet.groove_width_mm", "3.4"),
        "`tip_fitting` and `shaft_body`",
        // the error names the lug's width too
        &["shaft_body.bayonet.lug_width_mm"],
        3.0 * (0.3 / r) * (r * r - (r - 0.8f64).powi(2)) / 2.0 * 1.5,
        0.03,
    );
}

/// One bad value per rule of the body and the printer's bayonet profile: validation names the
/// parameter's path (among any others the value breaks) with its value and a rule.
#[test]
fn each_rule_of_the_body_names_its_parameter() {
    let cases: &[RuleCase] = &[
        ("printers.fdm.bayonet.lug_count", |d| {
            d.printers.fdm.bayonet.lug_count = 1
        }),
        ("printers.fdm.bayonet.lug_count", |d| {
            d.printers.fdm.bayonet.lug_count = 9
        }),
        ("printers.fdm.bayonet.ramp_deg", |d| {
            d.printers.fdm.bayonet.ramp_deg = 20.0
        }),
        ("printers.fdm.bayonet.ramp_deg", |d| {
            d.printers.fdm.bayonet.ramp_deg = -1.0
        }),
        ("printers.fdm.bayonet.clearance_mm", |d| {
            d.printers.fdm.bayonet.clearance_mm = 0.05
        }),
        ("shaft_body.bayonet.lock_angle_deg", |d| {
            sb(d).bayonet.lock_angle_deg = 95.0
        }),
        ("shaft_body.bayonet.lock_angle_deg", |d| {
            d.printers.fdm.bayonet.lug_count = 8;
            sb(d).bayonet.lock_angle_deg = 45.0;
        }),
        ("shaft_body.camera.view_angle_deg", |d| {
            sb(d).camera.view_angle_deg = 180.0
        }),
        ("shaft_body.fit_clearance_mm", |d| {
            sb(d).fit_clearance_mm = 0.05
        }),
        ("shaft_body.bayonet.lug_depth_mm", |d| {
            sb(d).bayonet.lug_depth_mm = 2.5
        }),
        ("shaft_body.bayonet.groove_width_mm", |d| {
            sb(d).bayonet.groove_width_mm = Some(0.0)
        }),
        ("shaft_body.led_ring.inner_diameter_mm", |d| {
            sb(d).led_ring.inner_diameter_mm = 19.0
        }),
        ("shaft_body.wall_thickness_mm", |d| {
            sb(d).wall_thickness_mm = 0.5
        }),
        ("shaft_body.base.outer_diameter_mm", |d| {
            sb(d).base.outer_diameter_mm = 40.0
        }),
        ("shaft_body.camera.mount_hole_spacing_mm", |d| {
            sb(d).camera.mount_hole_spacing_mm = 30.0
        }),
        ("shaft_body.camera.mount_pilot_depth_mm", |d| {
            sb(d).camera.mount_pilot_depth_mm = 40.0
        }),
        ("shaft_body.camera.lens_height_mm", |d| {
            sb(d).camera.lens_height_mm = 40.0
        }),
        ("shaft_body.shaft_diameter_mm", |d| {
            sb(d).shaft_diameter_mm = 30.0
        }),
        ("shaft_body.lens_window.diameter_mm", |d| {
            sb(d).lens_window.diameter_mm = 28.0
        }),
        ("shaft_body.tip_fitting.lip_width_mm", |d| {
            sb(d).tip_fitting.lip_width_mm = 12.0
        }),
        ("shaft_body.led_ring.seat_diameter_mm", |d| {
            sb(d).led_ring.seat_diameter_mm = Some(f64::NAN)
        }),
        ("shaft_body.robot_mount.bolt_count", |d| {
            mount(d).bolt_count = 1
        }),
        ("shaft_body.robot_mount.bolt_head_diameter_mm", |d| {
            mount(d).bolt_head_diameter_mm = 5.0
        }),
        ("shaft_body.robot_mount.plate_thickness_mm", |d| {
            mount(d).plate_thickness_mm = 8.0
        }),
        ("shaft_body.robot_mount.bolt_circle_diameter_mm", |d| {
            mount(d).bolt_circle_diameter_mm = 50.0
        }),
        ("shaft_body.robot_mount.cup_height_mm", |d| {
            mount(d).cup_height_mm = 3.0
        }),
        ("shaft_body.robot_mount.cup_wall_mm", |d| {
            mount(d).cup_wall_mm = 0.5
        }),
        ("shaft_body.filling_gel.fills", |d| {
            sb(d).filling_gel.as_mut().unwrap().fills = Some(fabkit_designs::schema::GelFill::Core)
        }),
        // the grooves over a 80 deg turn run into the cable window
        ("shaft_body.robot_mount.bayonet.lock_angle_deg", |d| {
            mount(d).bayonet.lock_angle_deg = 80.0
        }),
    ];
    assert_each_rule_names_its_path(tactip, cases);
}

fn mount(d: &mut Design) -> &mut fabkit_designs::parts::robot_mount::RobotMount {
    sb(d).robot_mount.as_mut().unwrap()
}

fn sb(d: &mut Design) -> &mut fabkit_designs::parts::shaft_body::ShaftBodyParams {
    d.shaft_body.as_mut().unwrap()
}

/// A mount lug 1 mm wider than designed with its groove's width pinned: the three lugs on the
/// base's foot reach 0.3 mm past their locking grooves' closed ends into the cup's wall, from
/// the bore (23.2 mm) out to the lug's depth (0.8 mm), over its 1.5 mm height: one error
/// naming the mount's groove width, both parts and the overlap; no kit.
#[test]
fn a_mount_lug_too_wide_for_its_groove_is_a_named_interference() {
    let mut d = tactip();
    let b = &mut mount(&mut d).bayonet;
    b.groove_width_mm = Some(b.lug_width_mm + 0.4);
    b.lug_width_mm += 1.0;
    let r: f64 = 23.2;
    assert_one_interference(
        &d,
        ("shaft_body.robot_mount.bayonet.groove_width_mm", "4.4"),
        "`shaft_body` and `robot_mount`",
        &[],
        3.0 * (0.3 / r) * ((r + 0.8f64).powi(2) - r * r) / 2.0 * 1.5,
        0.03,
    );
}

/// The turn that locks: the tip's lugs go in counter-clockwise (seen from +z), the body's
/// into the mount clockwise, so that twisting a tip off does not loosen the body. Turned back
/// by the lock angle along their own direction and raised by the ramp's rise, the lugs sit in
/// the entry grooves, clear of the grooved part; turned the other way they cut into it.
#[test]
fn each_bayonet_unlocks_only_back_along_its_own_turn() {
    let d = tactip();
    let sb = d.shaft_body.as_ref().unwrap();
    let m = sb.robot_mount.as_ref().unwrap();
    let tip = tip_bayonet(&d.context(), sb);
    let base = fabkit_designs::parts::robot_mount::mount_bayonet(&d.context(), sb, m);
    assert!(!tip.clockwise && base.clockwise && base.outward && !tip.outward);
    let rot = |s: &Solid, deg: f64, dz: f64| {
        let (sn, cs) = deg.to_radians().sin_cos();
        s.transform(&fabkit_designs::geometry::transform::with_translation(
            &nalgebra::Matrix3::new(cs, -sn, 0.0, sn, cs, 0.0, 0.0, 0.0, 1.0),
            [0.0, 0.0, dz],
        ))
    };
    for b in [&tip, &base] {
        let r = b.spigot_radius_mm;
        // the grooved part: a tube round the grooved surface, from under the lugs up to the
        // open end
        let (r0, r1) = if b.outward {
            (r, r + 3.0)
        } else {
            (r - 3.0, r)
        };
        let z0 = b.lug_z_mm - b.lug_height_mm - 1.0;
        let h = b.spigot_end_z_mm - z0;
        let tube = fabkit_designs::geometry::cylinder(h, r1, tol())
            .unwrap()
            .difference(
                &fabkit_designs::geometry::cylinder(h + 2.0, r0, tol())
                    .unwrap()
                    .translate([0.0, 0.0, -1.0]),
            )
            .unwrap()
            .translate([0.0, 0.0, z0]);
        let grooved = tube.difference(&b.grooves(tol()).unwrap()).unwrap();
        let attach = if b.outward { r - 0.5 } else { r + 0.5 };
        let lugs = b.lugs(attach, tol()).unwrap();
        let back = if b.clockwise { 1.0 } else { -1.0 } * b.lock_angle_deg;
        let clear = grooved
            .intersection(&rot(&lugs, back, b.rise_mm()))
            .unwrap()
            .volume();
        let wrong = grooved
            .intersection(&rot(&lugs, -back, b.rise_mm()))
            .unwrap()
            .volume();
        // measured: clear 0, wrong 10.4 and 14.7 mm^3 (the lugs cut into the grooved wall)
        assert!(
            clear < 1e-6 && wrong > 0.1,
            "outward {}: {clear} / {wrong}",
            b.outward
        );
    }
}
