//! Insertion paths (R-Tac0's round shell): the LED PCB goes down the tube's light chamber and
//! the core down the collar; a ledge in the way is one named error with its analytic overlap.

use fabkit_designs::geometry::cylinder;
use fabkit_designs::insertion::{blocked, errors, paths};
use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::{build_kit, library, stack, ChordTolerance};
use std::f64::consts::PI;

fn tol() -> ChordTolerance {
    ChordTolerance::new(0.01).unwrap()
}

/// R-Tac0's parts go in: the PCB's 23 mm disc down the 23.4 mm chamber, the 20 mm core down
/// the 20.4 mm collar. A 1 mm ledge of 20 mm bore left in the chamber (the shell before it was
/// split) blocks the PCB: the ring between the ledge's bore and the PCB's edge, 1 mm high.
#[test]
fn the_pcb_and_the_core_go_in_from_the_top_and_a_ledge_blocks_the_pcb() {
    let d = library::load("rtac0").unwrap();
    let kit = build_kit(&d, tol()).unwrap();
    let s = stack::validate(&d, &MaterialsTable::embedded().unwrap(), tol()).unwrap();
    let lv = fabkit_designs::parts::housing::levels(
        &d.context(),
        d.housing.as_ref().unwrap(),
        s.core.as_ref().unwrap(),
    );
    let p = paths(&d, &s, tol()).unwrap();
    let names: Vec<(&str, &str)> = p
        .iter()
        .map(|p| (p.member.as_str(), p.through.as_str()))
        .collect();
    assert_eq!(
        names,
        [
            ("led_pcb_envelope", "shell_tube"),
            ("core_envelope", "shell_collar")
        ]
    );
    assert_eq!(blocked(&kit.assembly, &p, tol()).unwrap(), vec![]);

    let mut members = kit.assembly.clone();
    let tube = members.iter_mut().find(|m| m.name == "shell_tube").unwrap();
    let ledge = cylinder(1.0, 11.8, tol())
        .unwrap()
        .difference(
            &cylinder(3.0, 10.0, tol())
                .unwrap()
                .translate([0.0, 0.0, -1.0]),
        )
        .unwrap()
        .translate([0.0, 0.0, lv.chamber_z_mm + 2.0]);
    tube.solid = tube.solid.union(&ledge).unwrap();
    let found = blocked(&members, &p, tol()).unwrap();
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(
        (found[0].a.as_str(), found[0].b.as_str()),
        ("led_pcb_envelope", "shell_tube")
    );
    let want = PI * (11.5f64.powi(2) - 10.0f64.powi(2));
    // measured -0.030 %, as predicted: the PCB's R11.5 polygon (sagitta 0.01 / sqrt 2) is short
    // of its circle by r^2 (pi - n/2 sin(2 pi / n)), about (4/3) pi r s, the ledge's R10 bore's
    // polygon gives most of it back
    assert!(
        (found[0].volume_mm3 - want).abs() < 0.01 * want,
        "{} vs {want}",
        found[0].volume_mm3
    );
    let e = errors(&d, &found).unwrap().to_string();
    assert!(
        e.contains("housing.light_chamber_diameter_mm = 23.4")
            && e.contains("`led_pcb_envelope` cannot go in from the top")
            && e.contains(&format!("`shell_tube` by {:.3} mm³", found[0].volume_mm3)),
        "{e}"
    );
}
