//! UVDtact's shell holder, sensor base, camera holder and diffusion ring (Sec. III-C, Fig. 2):
//! the printed solids against their analytic volumes, one fit broken at a time giving one
//! named interference with its analytic overlap, and one bad value per rule refused by path.

use crate::common::{assert_each_rule_names_its_path, assert_one_interference, RuleCase};
use fabkit_designs::parts::fingertip_base::FingertipBase;
use fabkit_designs::{build_kit, library, ChordTolerance, Design, Kit};
use std::f64::consts::PI;
use std::sync::OnceLock;

fn uvdtact() -> Design {
    library::load("uvdtact").unwrap()
}

/// UVDtact's kit at 0.01 mm, built once for the tests of this module.
fn kit() -> &'static Kit {
    static KIT: OnceLock<Kit> = OnceLock::new();
    KIT.get_or_init(|| build_kit(&uvdtact(), ChordTolerance::new(0.01).unwrap()).unwrap())
}

fn base(d: &mut Design) -> &mut FingertipBase {
    d.fingertip_base.as_mut().unwrap()
}

/// The four printed parts' sizes and volumes, worked by hand from the yaml's numbers (within
/// the cylinders' chords: their walls' area times the 0.01 mm tolerance): the shell's foot is 6.6 mm in radius (the 9 mm skin less its
/// 2.4 mm of layers) and 5 mm long, the holder's bore 6.7 mm, the bolts on an 8.35 mm circle.
///
/// - shell holder: pi (10^2 - 6.7^2) x 5 less three pilots pi 0.5^2 x 3;
/// - sensor base: pi 10^2 x 4.5 less the pocket pi 6.1^2 x 3, the wire holes pi 0.5^2 and
///   pi 0.6^2 through the 1.5 mm floor, three bolt holes pi 0.7^2 x 4.5 with counterbores
///   pi (1.1^2 - 0.7^2) x 1;
/// - camera holder: pi (1.3^2 - 0.85^2) x 3;
/// - diffusion ring: pi (6^2 - 2^2) x 1 less four UV holes pi 0.6^2 x 1.
#[test]
fn printed_parts_have_their_analytic_sizes_and_volumes() {
    let k = kit();
    let got = |name: &str| {
        let p = k.parts.iter().find(|p| p.name == name).expect(name);
        assert_eq!(
            p.print_technology,
            fabkit_designs::PrintTechnology::Sla,
            "{name}"
        );
        let b = p.solid.bounding_box().unwrap();
        ([0, 1, 2].map(|i| b.max[i] - b.min[i]), p.solid.volume())
    };
    let sq = |r: f64| r * r;
    let walls = |rh: &[(f64, f64)]| rh.iter().map(|(r, h)| 2.0 * PI * r * h).sum::<f64>();
    for (name, size, v, area) in [
        (
            "shell_holder",
            [20.0, 20.0, 5.0],
            PI * (sq(10.0) - sq(6.7)) * 5.0 - 3.0 * PI * sq(0.5) * 3.0,
            walls(&[(10.0, 5.0), (6.7, 5.0), (1.5, 3.0)]),
        ),
        (
            "sensor_base",
            [20.0, 20.0, 4.5],
            PI * sq(10.0) * 4.5
                - PI * sq(6.1) * 3.0
                - PI * (sq(0.5) + sq(0.6)) * 1.5
                - 3.0 * PI * (sq(0.7) * 4.5 + (sq(1.1) - sq(0.7)) * 1.0),
            walls(&[
                (10.0, 4.5),
                (6.1, 3.0),
                (1.1, 1.5),
                (3.0 * 0.7, 4.5),
                (3.0 * 1.1, 1.0),
            ]),
        ),
        (
            "camera_holder",
            [2.6, 2.6, 3.0],
            PI * (sq(1.3) - sq(0.85)) * 3.0,
            walls(&[(1.3, 3.0), (0.85, 3.0)]),
        ),
        (
            "diffusion_ring",
            [12.0, 12.0, 1.0],
            PI * (sq(6.0) - sq(2.0)) - 4.0 * PI * sq(0.6),
            walls(&[(6.0, 1.0), (2.0, 1.0), (4.0 * 0.6, 1.0)]),
        ),
    ] {
        let (s, vol) = got(name);
        for i in 0..3 {
            assert!((s[i] - size[i]).abs() < 1e-6, "{name} size {s:?}");
        }
        assert!(
            (vol - v).abs() <= area * 0.01,
            "{name}: {vol} vs {v} (bound {})",
            area * 0.01
        );
    }
}

/// A camera holder 3.6 mm across in the PCB's 3.2 mm bore: it overlaps the board by the ring
/// pi (1.8^2 - 1.6^2) over the board's 0.8 mm.
#[test]
fn a_camera_holder_wider_than_the_pcbs_bore_is_a_named_interference() {
    let mut d = uvdtact();
    base(&mut d).camera_holder.outer_diameter_mm = 3.6;
    assert_one_interference(
        &d,
        ("fingertip_base.led_pcb.inner_diameter_mm", "3.2"),
        "`camera_holder` and `led_pcb_envelope`",
        &["fingertip_base.camera_holder.outer_diameter_mm"],
        PI * (1.8f64.powi(2) - 1.6f64.powi(2)) * 0.8,
        0.01,
    );
}

/// LEDs 1.4 mm tall reach 0.2 mm into the diffusion ring (board 0.8 mm on the floor, ring
/// from 2 mm up): the LEDs' ring (3.2 to 4.8 mm) less the four UV holes (0.6 mm) over them.
#[test]
fn leds_taller_than_the_pocket_leaves_them_are_a_named_interference() {
    let mut d = uvdtact();
    base(&mut d).led_pcb.led_height_mm = 1.4;
    assert_one_interference(
        &d,
        ("fingertip_base.pocket_depth_mm", "3.0"),
        "`diffusion_ring` and `leds_envelope`",
        &["fingertip_base.led_pcb.led_height_mm"],
        0.2 * (PI * (4.8f64.powi(2) - 3.2f64.powi(2)) - 4.0 * PI * 0.36),
        0.01,
    );
}

/// A diffusion ring bored 2 mm round the 2.6 mm camera holder: pi (1.3^2 - 1^2) over the
/// ring's 1 mm.
#[test]
fn a_diffusion_ring_tight_on_the_camera_holder_is_a_named_interference() {
    let mut d = uvdtact();
    base(&mut d).diffusion_ring.inner_diameter_mm = 2.0;
    assert_one_interference(
        &d,
        ("fingertip_base.diffusion_ring.inner_diameter_mm", "2.0"),
        "`camera_holder` and `diffusion_ring`",
        &["fingertip_base.camera_holder.outer_diameter_mm"],
        PI * (1.3f64.powi(2) - 1.0),
        0.01,
    );
}

/// One bad value per rule of the fingertip's base: validation names the parameter's path
/// (among any others the value breaks) with its value and a rule, and no kit is built.
#[test]
fn each_rule_of_the_fingertip_base_names_its_parameter() {
    let cases: &[RuleCase] = &[
        ("fingertip_base.material", |d| {
            base(d).material = "pmma".into()
        }),
        ("fingertip_base.diffusion_ring.material", |d| {
            base(d).diffusion_ring.material = "nosuch".into()
        }),
        ("fingertip_base.outer_diameter_mm", |d| {
            base(d).outer_diameter_mm = -20.0
        }),
        ("fingertip_base.camera.view_angle_deg", |d| {
            base(d).camera.view_angle_deg = 180.0
        }),
        ("fingertip_base.bolts.count", |d| base(d).bolts.count = 1),
        ("fingertip_base.fit_clearance_mm", |d| {
            base(d).fit_clearance_mm = 0.01
        }),
        ("fingertip_base", |d| d.core = None),
        ("fingertip_base.bolts.pilot_depth_mm", |d| {
            base(d).bolts.pilot_depth_mm = 4.8
        }),
        ("fingertip_base.outer_diameter_mm", |d| {
            base(d).outer_diameter_mm = 18.0
        }),
        ("fingertip_base.led_pcb.outer_diameter_mm", |d| {
            base(d).led_pcb.outer_diameter_mm = 14.0
        }),
        ("fingertip_base.bolts.clearance_diameter_mm", |d| {
            base(d).bolts.clearance_diameter_mm = 0.9
        }),
        ("fingertip_base.bolts.head_depth_mm", |d| {
            base(d).bolts.head_depth_mm = 4.3
        }),
        ("fingertip_base.floor_thickness_mm", |d| {
            base(d).floor_thickness_mm = 0.2
        }),
        ("fingertip_base.led_pcb.led_circle_diameter_mm", |d| {
            base(d).led_pcb.led_circle_diameter_mm = 11.0
        }),
        ("fingertip_base.led_pcb.wire_hole_diameter_mm", |d| {
            base(d).led_pcb.wire_hole_diameter_mm = 4.0
        }),
        ("fingertip_base.diffusion_ring.uv_hole_diameter_mm", |d| {
            base(d).diffusion_ring.uv_hole_diameter_mm = 3.5
        }),
        ("fingertip_base.diffusion_ring.thickness_mm", |d| {
            base(d).diffusion_ring.thickness_mm = 3.0
        }),
        ("fingertip_base.camera_holder.outer_diameter_mm", |d| {
            base(d).camera_holder.outer_diameter_mm = 2.0
        }),
        ("fingertip_base.camera.length_mm", |d| {
            base(d).camera.length_mm = 3.5
        }),
        ("fingertip_base.camera.wire_hole_diameter_mm", |d| {
            base(d).camera.wire_hole_diameter_mm = 2.0
        }),
        ("fingertip_base.led_pcb.thickness_mm", |d| {
            base(d).led_pcb.thickness_mm = f64::NAN
        }),
    ];
    assert_each_rule_names_its_path(uvdtact, cases);
}

/// The preset `no_markers` (Sec. V-B: the inner and outer mixed elastomers cast at once with
/// red UV ink): one 2 mm mixed layer without markers, then the black gel, on the same shell and
/// base. Its mixed pour is the shell between the offsets -0.4 and -2.4 mm, the two marked
/// layers' volume together (within the chord tolerance over both surfaces).
#[test]
fn the_no_marker_variant_casts_both_mixed_layers_at_once() {
    let d = uvdtact().with_preset("no_markers").unwrap();
    let tol = ChordTolerance::new(0.01).unwrap();
    let k = build_kit(&d, tol).unwrap();
    let casts: Vec<&str> = k.casts.iter().map(|c| c.cast.as_str()).collect();
    assert_eq!(
        casts[casts.len() - 2..],
        ["mixed", "black_gel"],
        "{casts:?}"
    );
    assert!(k.summary["markers"].as_array().unwrap().is_empty());
    for role in [
        "shell_holder",
        "sensor_base",
        "camera_holder",
        "diffusion_ring",
    ] {
        assert!(k.parts.iter().any(|p| p.role == role), "{role}");
    }
    let mixed = k.casts.iter().find(|c| c.cast == "mixed").unwrap();
    let want =
        d.body.analytic_solid_volume_mm3(-0.4, 0.0) - d.body.analytic_solid_volume_mm3(-2.4, 0.0);
    let area = 2.0 * (PI * 81.0 + 2.0 * PI * 9.0 * 24.0);
    let got = mixed.cavity_volume_ml * 1000.0;
    assert!((got - want).abs() <= area * tol.mm(), "{got} vs {want}");
}
