//! The worked example of a section family (`parts/spacer.rs`, docs/src/development.md "Adding
//! a part family"): registered by one line, it is validated, built, fit-checked in the
//! assembly, listed in the bought items and the procedure, and refused on a flat skin, with no
//! code of its own outside its module.
//!
//! The design: UVDtact's skin on its acrylic shell (its fingertip base taken off) standing on
//! a PLA spacer ring 20 mm across, bored 14 mm, 5 mm high. The skin's rim at the base plane is
//! 9 mm in radius and the shell's foot 6.6 mm (the 9 mm skin less its 2.4 mm of layers).

use crate::common::{assert_each_rule_names_its_path, RuleCase};
use fabkit_designs::parts::spacer::SpacerParams;
use fabkit_designs::parts::MemberKind;
use fabkit_designs::{build_kit, library, ChordTolerance, Design, PrintTechnology};
use std::f64::consts::PI;

fn on_spacer() -> Design {
    let mut d = library::load("uvdtact").unwrap();
    d.fingertip_base = None;
    d.spacer = Some(SpacerParams {
        material: "pla".into(),
        outer_diameter_mm: 20.0,
        inner_diameter_mm: 14.0,
        height_mm: 5.0,
    });
    d
}

/// The ring is printed (FDM) at its analytic size and volume, pi (10^2 - 7^2) x 5, within its
/// walls' area times the 0.01 mm chord tolerance; it stands in the assembled sensor from
/// 5 mm below the base plane up to it, a printed member named by its own parameters; its glue
/// is bought and its step is in the procedure.
#[test]
fn the_example_family_builds_and_appears_in_the_assembly_and_the_procedure() {
    let tol = ChordTolerance::new(0.01).unwrap();
    let d = on_spacer();
    let k = build_kit(&d, tol).unwrap();
    let p = k.parts.iter().find(|p| p.name == "spacer").expect("part");
    assert_eq!(p.role, "spacer");
    assert_eq!(p.print_technology, PrintTechnology::Fdm);
    let b = p.solid.bounding_box().unwrap();
    let size = [0, 1, 2].map(|i| b.max[i] - b.min[i]);
    for (got, want) in size.iter().zip([20.0, 20.0, 5.0]) {
        assert!((got - want).abs() < 1e-6, "size {size:?}");
    }
    let v = PI * (10.0f64.powi(2) - 7.0f64.powi(2)) * 5.0;
    let walls = 2.0 * PI * (10.0 + 7.0) * 5.0;
    assert!(
        (p.solid.volume() - v).abs() <= walls * 0.01,
        "{} vs {v}",
        p.solid.volume()
    );

    let m = k
        .assembly
        .iter()
        .find(|m| m.name == "spacer")
        .expect("member");
    assert_eq!(m.kind, MemberKind::Printed);
    assert_eq!(
        m.fix,
        ["spacer.inner_diameter_mm", "spacer.outer_diameter_mm"]
    );
    let zb = d.body.base_z_mm();
    let mb = m.solid.bounding_box().unwrap();
    assert!((mb.max[2] - zb).abs() < 1e-6 && (mb.min[2] - (zb - 5.0)).abs() < 1e-6);
    assert!(mb.max[0] > 10.0 - 1e-6 && mb.max[0] < 10.0 + 1e-6);

    assert!(k
        .bought_items
        .iter()
        .any(|b| b.contains("spacer's top face")));
    assert!(k.procedure.iter().any(|s| s
        .text
        .starts_with("Assemble: Glue the skin's rim onto the top face of `spacer`")));
    let envelope = &k.summary["envelope_mm"];
    assert_eq!(envelope[0].as_f64(), Some(20.0));
    let pole = d.body.pole_z_mm(0.0);
    assert!((envelope[2].as_f64().unwrap() - (pole - (zb - 5.0))).abs() < 1e-9);
}

/// Each rule of the family refuses one bad value by its path: a ring narrower than the skin's
/// 18 mm rim, a bore leaving less than the FDM printer's 0.8 mm wall (above 18.4 mm), a bore
/// not clearing the shell's 13.2 mm foot, no height, a material that is not printed.
#[test]
fn the_example_familys_rules_name_their_paths() {
    fn spacer(d: &mut Design) -> &mut SpacerParams {
        d.spacer.as_mut().unwrap()
    }
    let cases: &[RuleCase] = &[
        ("spacer.outer_diameter_mm", |d| {
            spacer(d).outer_diameter_mm = 17.0
        }),
        ("spacer.inner_diameter_mm", |d| {
            spacer(d).inner_diameter_mm = 18.6
        }),
        ("spacer.inner_diameter_mm", |d| {
            spacer(d).inner_diameter_mm = 13.0
        }),
        ("spacer.height_mm", |d| spacer(d).height_mm = 0.0),
        ("spacer.material", |d| {
            spacer(d).material = "sylgard_184".into()
        }),
    ];
    assert_each_rule_names_its_path(on_spacer, cases);
}

/// A flat skin has no base plane rim to rest on a ring: the family is refused there by its
/// path, as every section family is.
#[test]
fn the_example_family_is_refused_on_a_flat_skin() {
    let mut d = library::load("soter_channels").unwrap();
    d.spacer = on_spacer().spacer;
    let e = fabkit_designs::stack::flat::validate(
        &d,
        &fabkit_designs::materials::MaterialsTable::embedded().unwrap(),
    )
    .unwrap_err();
    assert!(
        e.0.iter()
            .any(|x| x.path == "spacer" && x.rule.contains("flat skin")),
        "{e}"
    );
}
