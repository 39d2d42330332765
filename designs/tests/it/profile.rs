use fabkit_designs::geometry::profile2d::max_deviation;
use fabkit_designs::profile::*;
use fabkit_designs::ChordTolerance;

#[test]
fn ellipse_offset_is_at_constant_distance() {
    let p = BodyProfile::HalfEllipsoid {
        diameter_mm: 18.0,
        height_mm: 24.0,
    };
    for &d in &[-2.0, -0.5, 0.7] {
        for i in 0..=50 {
            let t = i as f64 / 50.0;
            let q = p.offset_point(d, t);
            // distance from q to the base ellipse, by dense search
            let mut best = f64::INFINITY;
            for k in 0..=20000 {
                let s = p.offset_point(0.0, k as f64 / 20000.0);
                best = best.min(((q[0] - s[0]).powi(2) + (q[1] - s[1]).powi(2)).sqrt());
            }
            // q's foot t = i / 50 is itself a sample (k = 400 i), so the search finds it: measured
            // 1.8e-15 mm at most; an offset off the normal would find a nearer sample
            assert!((best - d.abs()).abs() < 1e-9, "d={d} t={t} dist={best}");
        }
    }
}

#[test]
fn tessellation_honours_the_profile_tolerance() {
    let tol = ChordTolerance::new(0.01).unwrap();
    for p in [
        BodyProfile::HalfEllipsoid {
            diameter_mm: 18.0,
            height_mm: 24.0,
        },
        BodyProfile::SphericalCap {
            base_diameter_mm: 35.0,
            height_mm: 8.0,
        },
        BodyProfile::HemisphereOnCylinder {
            radius_mm: 15.0,
            cylinder_length_mm: 6.0,
        },
    ] {
        let d = -1.0;
        let pl = p.offset_polyline(d, 0.0, tol);
        let dev = max_deviation(&pl, &|t| p.offset_point(d, t), 0.0, 1.0, 4000);
        assert!(dev <= tol.mm() * 1.0001, "{} deviates {dev}", p.kind());
    }
}

#[test]
fn cap_geometry() {
    let p = BodyProfile::SphericalCap {
        base_diameter_mm: 35.0,
        height_mm: 8.0,
    };
    assert!((p.pole_z_mm(0.0) - p.base_z_mm() - 8.0).abs() < 1e-12);
    assert!((p.rim_radius_mm(0.0) - 17.5).abs() < 1e-12);
    assert!(p.offset_is_valid(-2.0));
    assert!(!p.offset_is_valid(-9.0));
}

/// The authors' ShadowTac cavity (authors' CAD, measured): a sphere of R22.500 cut to a
/// rim of 35.000 mm is 8.358 mm deep.
#[test]
fn cap_by_sphere_radius_and_rim() {
    let y = "profile: spherical_cap\nsphere_radius_mm: 22.5\nrim_diameter_mm: 35.0\n";
    let p: BodyProfile = serde_saphyr::from_str(y).unwrap();
    assert!((p.sphere_radius_mm().unwrap() - 22.5).abs() < 1e-12);
    assert!((p.rim_radius_mm(0.0) - 17.5).abs() < 1e-12);
    let depth = p.pole_z_mm(0.0) - p.base_z_mm();
    assert!((depth - 8.358).abs() < 5e-4, "{depth}");
    assert!((depth - (22.5 - 200f64.sqrt())).abs() < 1e-12);
    for (bad, words) in [
        (
            "profile: spherical_cap\nsphere_radius_mm: 22.5\nrim_diameter_mm: 35.0\nheight_mm: 8.0\n",
            "not both forms",
        ),
        (
            "profile: spherical_cap\nsphere_radius_mm: 17.0\nrim_diameter_mm: 35.0\n",
            "body.rim_diameter_mm = 35: must not exceed",
        ),
        (
            "profile: spherical_cap\nsphere_radius_mm: 22.5\n",
            "body.rim_diameter_mm is required",
        ),
        (
            "profile: spherical_cap\nsphere_radius_mm: -1\nrim_diameter_mm: 35.0\n",
            "body.sphere_radius_mm = -1: must be above 0",
        ),
    ] {
        let e = serde_saphyr::from_str::<BodyProfile>(bad).unwrap_err();
        assert!(e.to_string().contains(words), "{bad}: {e}");
    }
}

#[test]
fn ellipsoid_offset_beyond_curvature_is_invalid() {
    let p = BodyProfile::HalfEllipsoid {
        diameter_mm: 18.0,
        height_mm: 24.0,
    };
    assert!((p.min_curvature_radius_mm() - 81.0 / 24.0).abs() < 1e-12);
    assert!(p.offset_is_valid(-3.0));
    assert!(!p.offset_is_valid(-3.5));
}
