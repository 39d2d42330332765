use fabkit_designs::geometry::*;
use std::f64::consts::PI;

#[test]
fn circle_segments_honour_tolerance() {
    for &(r, tol) in &[(15.0, 0.01), (1.0, 0.001), (100.0, 0.05), (0.5, 0.01)] {
        let t = ChordTolerance::new(tol).unwrap();
        let n = t.circle_segments(r);
        let d = tol / 2f64.sqrt();
        assert_eq!(n % 4, 0);
        assert!(r * (1.0 - (PI / n as f64).cos()) <= d * (1.0 + 1e-12));
        // and not wastefully many: n - 4 segments would break the tolerance (or hit the floor of 8)
        if n > 8 {
            assert!(r * (1.0 - (PI / (n - 4) as f64).cos()) > d);
        }
    }
}

#[test]
fn bad_tolerance_is_rejected() {
    assert!(ChordTolerance::new(0.0).is_err());
    assert!(ChordTolerance::new(-1.0).is_err());
    assert!(ChordTolerance::new(f64::NAN).is_err());
    // The floor: finer tolerances only cost time and memory (the mesh grows as 1 / tol).
    assert!(ChordTolerance::new(ChordTolerance::MIN_MM).is_ok());
    let e = ChordTolerance::new(1e-9).unwrap_err();
    assert!(
        e.contains("= 0.000000001 mm: must be at least 0.001 mm"),
        "{e}"
    );
    assert!(ChordTolerance::new(0.000999).is_err());
}

#[test]
fn sphere_volume_within_chord_bound() {
    let tol = ChordTolerance::new(0.01).unwrap();
    let s = sphere(5.0, tol).unwrap();
    let exact = 4.0 / 3.0 * PI * 125.0;
    let bound = 4.0 * PI * 25.0 * tol.mm();
    assert!(
        s.volume() <= exact && exact - s.volume() <= bound,
        "{}",
        s.volume()
    );
    assert_eq!(s.genus(), 0);
}

#[test]
fn cylinder_cone_box_volumes() {
    let tol = ChordTolerance::new(0.01).unwrap();
    let c = cylinder(10.0, 3.0, tol).unwrap();
    let exact = PI * 9.0 * 10.0;
    assert!(exact - c.volume() >= 0.0 && exact - c.volume() <= 2.0 * PI * 3.0 * 10.0 * 0.01);
    let k = cone(6.0, 2.0, 0.0, tol).unwrap();
    let exact = PI * 4.0 * 6.0 / 3.0;
    assert!((exact - k.volume()).abs() <= 0.01 * 2.0 * PI * 2.0 * 7.0);
    let b = cuboid([0.0, 0.0, 0.0], [1.0, 2.0, 3.0]).unwrap();
    assert!((b.volume() - 6.0).abs() < 1e-12);
}

#[test]
fn difference_of_box_and_cylinder_is_a_ring() {
    let tol = ChordTolerance::new(0.01).unwrap();
    let b = cuboid([-5.0, -5.0, 0.0], [5.0, 5.0, 2.0]).unwrap();
    let c = cylinder(4.0, 2.0, tol).unwrap().translate([0.0, 0.0, -1.0]);
    let r = b.difference(&c).unwrap();
    assert_eq!(r.genus(), 1);
    // the removed polygonal prism is smaller than the cylinder by at most perimeter x tol x height
    let exact = 200.0 - PI * 4.0 * 2.0;
    assert!(r.volume() >= exact && r.volume() - exact <= 2.0 * PI * 2.0 * 0.01 * 2.0);
}
