use fabkit_designs::primitives::*;
use fabkit_designs::ChordTolerance;
use std::f64::consts::PI;

fn tol() -> ChordTolerance {
    ChordTolerance::new(0.005).unwrap()
}

/// Each primitive's mesh volume is the analytic volume within (area x tolerance).
#[test]
fn primitive_volumes_match_closed_forms() {
    let r = 1.3;
    let h = 4.0;
    let tilted = unit([0.3, -0.5, 0.8]);
    let cases: Vec<(Primitive, f64, f64)> = vec![
        (
            Primitive::Sphere {
                centre_mm: [1.0, 2.0, 3.0],
                radius_mm: r,
            },
            4.0 / 3.0 * PI * r.powi(3),
            4.0 * PI * r * r,
        ),
        (
            Primitive::Cylinder {
                base_mm: [0.5, 0.0, 0.0],
                top_mm: add([0.5, 0.0, 0.0], scale(tilted, h)),
                radius_mm: r,
            },
            PI * r * r * h,
            2.0 * PI * r * (r + h),
        ),
        (
            Primitive::Cone {
                apex_mm: scale(tilted, h),
                base_mm: [0.0; 3],
                base_radius_mm: r,
            },
            PI * r * r * h / 3.0,
            PI * r * (r + (r * r + h * h).sqrt()),
        ),
        (
            Primitive::Capsule {
                p0_mm: [0.0; 3],
                p1_mm: scale(tilted, h),
                radius_mm: r,
            },
            PI * r * r * h + 4.0 / 3.0 * PI * r.powi(3),
            2.0 * PI * r * h + 4.0 * PI * r * r,
        ),
        (
            Primitive::Box {
                centre_mm: [1.0, 1.0, 1.0],
                axes: [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
                half_extents_mm: [1.0, 2.0, 3.0],
            },
            48.0,
            0.0,
        ),
        (
            Primitive::Prism {
                origin_mm: [0.0, 0.0, 5.0],
                x_axis: [1.0, 0.0, 0.0],
                y_axis: [0.0, 0.0, 1.0],
                // an L shape (not convex), 3 x 3 minus 2 x 2 = 5 mm2
                polygon_mm: vec![
                    [0.0, 0.0],
                    [3.0, 0.0],
                    [3.0, 1.0],
                    [1.0, 1.0],
                    [1.0, 3.0],
                    [0.0, 3.0],
                ],
                height_mm: 2.0,
            },
            10.0,
            0.0,
        ),
    ];
    for (p, v, area) in cases {
        let s = p.solid(tol()).unwrap();
        let got = s.volume();
        assert!(
            got <= v + 1e-9 && v - got <= area * tol().mm() + 1e-9,
            "{p:?}: {got} vs {v}"
        );
        s.mesh().check_closed_manifold().unwrap();
    }
}

#[test]
fn json_round_trip_and_unknown_fields() {
    let g = Geometry {
        frame: "sensor".into(),
        primitives: vec![Primitive::Sphere {
            centre_mm: [0.0, 0.0, 1.0],
            radius_mm: 2.0,
        }],
    };
    let s = serde_json::to_string(&g).unwrap();
    assert!(s.contains("\"type\":\"sphere\""));
    assert_eq!(serde_json::from_str::<Geometry>(&s).unwrap(), g);
    assert!(serde_json::from_str::<Geometry>(
        r#"{"frame":"x","primitives":[{"type":"sphere","centre_mm":[0,0,0],"radius_mm":1,"r":2}]}"#
    )
    .is_err());
}

/// A rigid move keeps the volume and moves a sphere's centre.
#[test]
fn transformed_moves_primitives() {
    let g = Geometry {
        frame: "sensor".into(),
        primitives: vec![Primitive::Capsule {
            p0_mm: [1.0, 0.0, 0.0],
            p1_mm: [1.0, 0.0, 2.0],
            radius_mm: 0.5,
        }],
    };
    let m = fabkit_designs::geometry::rotation_deg(0.0, 0.0, 180.0);
    let t = g.transformed(&m);
    match &t.primitives[0] {
        Primitive::Capsule { p0_mm, .. } => assert!((p0_mm[0] + 1.0).abs() < 1e-12),
        _ => unreachable!(),
    }
    let (a, b) = (
        g.solid(tol()).unwrap().volume(),
        t.solid(tol()).unwrap().volume(),
    );
    assert!((a - b).abs() < 1e-9);
}
