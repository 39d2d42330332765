//! Image formation (calibration/src/groundtruth/shading.rs) against closed forms: the flux a
//! point light sends onto a flat Lambertian floor, a light's cone and shadows, and the camera's
//! response (gain, vignetting, photon and read noise, seeded and thread-count independent).

use fabkit_calibration::groundtruth::shading::{expose, irradiance, radiance, Exposure};

const FRAME0: Exposure = Exposure {
    gain: 1.0,
    frame: 0,
};
use fabkit_designs::optics::{CameraResponse, Light, Reflectance};
use std::f64::consts::PI;

fn down_light(h_mm: f64, cone_deg: f64) -> Light {
    Light {
        position_mm: [0.0, 0.0, h_mm],
        direction: [0.0, 0.0, -1.0],
        cone_half_angle_deg: cone_deg,
        colour_rgb: [1.0, 0.5, 0.25],
        intensity: 100.0,
    }
}

/// A cosine-beam light `h` mm above a floor, facing it, sends `pi I R^2 / (h^2 + R^2)` onto
/// the disc of radius `R` under it (the integral of `I h^2 / (h^2 + r^2)^2` over the disc);
/// summed from the irradiance at 4000 radii it agrees within 0.5 %, per colour channel.
#[test]
fn a_flat_floor_receives_the_analytic_flux_of_a_point_light() {
    let (h, big_r, n) = (10.0, 30.0, 4000);
    let light = down_light(h, 90.0);
    let mut flux = [0.0; 3];
    for k in 0..n {
        let r = (k as f64 + 0.5) * big_r / n as f64;
        let e = irradiance(&light, [r, 0.0, 0.0], [0.0, 0.0, 1.0]);
        for c in 0..3 {
            flux[c] += e[c] * 2.0 * PI * r * big_r / n as f64;
        }
    }
    let want = PI * light.intensity * big_r * big_r / (h * h + big_r * big_r);
    for c in 0..3 {
        let w = want * light.colour_rgb[c];
        // measured 5.3e-8 relative: the midpoint rule's error at 4000 radii, of order (R / n)^2 / h^2
        assert!((flux[c] - w).abs() <= 0.005 * w, "{c}: {} vs {w}", flux[c]);
    }
    // a Lambertian floor (no specular lobe) sends albedo E / pi towards any viewer
    let matte = Reflectance {
        albedo_rgb: [0.8, 0.8, 0.8],
        specular: 0.0,
        roughness: 1.0,
        darkness_per_mm: None,
    };
    let p = [3.0, 4.0, 0.0];
    let e = irradiance(&light, p, [0.0, 0.0, 1.0]);
    for eye in [[0.0, 0.0, 1.0], [0.6, 0.0, 0.8]] {
        let l = radiance(
            p,
            [0.0, 0.0, 1.0],
            eye,
            matte.albedo_rgb,
            &matte,
            &[light.clone()],
            |_| true,
        );
        for c in 0..3 {
            assert!((l[c] - 0.8 * e[c] / PI).abs() < 1e-12 * e[c].max(1.0));
        }
    }
}

/// Outside its 30 deg cone (beyond h tan 30 deg = 5.77 mm from under a light 10 mm up) a light
/// gives nothing; a point facing away gets nothing; a light in shadow adds nothing, and two
/// lights add up.
#[test]
fn cones_shadows_and_two_lights() {
    let narrow = down_light(10.0, 30.0);
    let up = [0.0, 0.0, 1.0];
    assert!(irradiance(&narrow, [5.7, 0.0, 0.0], up)[0] > 0.0);
    assert_eq!(irradiance(&narrow, [5.8, 0.0, 0.0], up), [0.0; 3]);
    assert_eq!(
        irradiance(&narrow, [0.0, 0.0, 0.0], [0.0, 0.0, -1.0]),
        [0.0; 3]
    );

    let s = Reflectance::default();
    let a = down_light(10.0, 90.0);
    let b = Light {
        position_mm: [8.0, 0.0, 6.0],
        direction: [-1.0, 0.0, -1.0],
        ..down_light(10.0, 90.0)
    };
    let p = [1.0, 2.0, 0.0];
    let eye = [0.0, 0.0, 1.0];
    let both = radiance(
        p,
        up,
        eye,
        s.albedo_rgb,
        &s,
        &[a.clone(), b.clone()],
        |_| true,
    );
    let only_a = radiance(p, up, eye, s.albedo_rgb, &s, &[a.clone(), b.clone()], |i| {
        i == 0
    });
    let only_b = radiance(p, up, eye, s.albedo_rgb, &s, &[b], |_| true);
    let a_alone = radiance(p, up, eye, s.albedo_rgb, &s, &[a], |_| true);
    for c in 0..3 {
        assert!((only_a[c] - a_alone[c]).abs() < 1e-15);
        assert!((both[c] - only_a[c] - only_b[c]).abs() < 1e-12);
        assert!(only_b[c] > 0.0);
    }
}

fn flat_field(w: usize, h: usize, value: f64) -> Vec<[f64; 3]> {
    vec![[value; 3]; w * h]
}

/// A flat field at half scale, 16 bit: its mean is half of 65535 within 0.2 % and its spread
/// is the photon and read noise, sqrt(5000 + 5^2) / 10000 of full scale, within 3 %; the same
/// seed gives the same values with one thread or two, another seed other values.
#[test]
fn the_camera_adds_the_noise_of_its_electrons_the_same_for_a_seed() {
    let (w, h) = (256, 256);
    let cam = CameraResponse {
        bit_depth: 16,
        seed: 7,
        ..CameraResponse::default()
    };
    let img = expose(&flat_field(w, h, 0.5), w, h, [127.5, 127.5], &cam, FRAME0);
    let vals: Vec<f64> = img.iter().map(|p| f64::from(p[1])).collect();
    let mean = vals.iter().sum::<f64>() / vals.len() as f64;
    let sd = (vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / vals.len() as f64).sqrt();
    let full = 65535.0;
    // measured 1.0e-5 of half scale (the mean of 65,536 pixels, each with sd 1.4 % of half
    // scale: sd of the mean 5.5e-5)
    assert!(
        (mean - 0.5 * full).abs() < 0.002 * 0.5 * full,
        "mean {mean}"
    );
    let want = (5000.0f64 + 25.0).sqrt() / 10000.0 * full;
    // measured 0.6 % (a sample sd of 65,536 varies by 1 / sqrt(2 x 65,536) = 0.28 %)
    assert!((sd - want).abs() < 0.03 * want, "sd {sd} vs {want}");

    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let a = one.install(|| expose(&flat_field(w, h, 0.5), w, h, [127.5, 127.5], &cam, FRAME0));
    let b = two.install(|| expose(&flat_field(w, h, 0.5), w, h, [127.5, 127.5], &cam, FRAME0));
    assert_eq!(a, b);
    assert_eq!(a, img);
    let other = expose(
        &flat_field(w, h, 0.5),
        w,
        h,
        [127.5, 127.5],
        &CameraResponse { seed: 8, ..cam },
        FRAME0,
    );
    assert_ne!(other, img);
    let next = expose(
        &flat_field(w, h, 0.5),
        w,
        h,
        [127.5, 127.5],
        &cam,
        Exposure {
            gain: 1.0,
            frame: 1,
        },
    );
    assert_ne!(next, img, "each frame of a set has its own noise");
}

/// Without noise, the corners record `1 - vignetting` of the centre; a pixel that sees nothing
/// (NaN) records 0; 8 bits quantise to 255 levels and a bright pixel clips at full scale.
#[test]
fn vignetting_quantisation_and_clipping() {
    let (w, h) = (101, 81);
    let cam = CameraResponse {
        gain: None,
        vignetting: 0.3,
        full_well_electrons: 1e12,
        read_noise_electrons: 0.0,
        bit_depth: 16,
        seed: 1,
    };
    let mut rad = flat_field(w, h, 0.2);
    rad[1] = [f64::NAN; 3];
    rad[w * h - 2] = [10.0; 3];
    let gain2 = Exposure {
        gain: 2.0,
        frame: 0,
    };
    let img = expose(&rad, w, h, [50.0, 40.0], &cam, gain2);
    let full: f64 = 65535.0;
    assert_eq!(f64::from(img[40 * w + 50][0]), (0.4 * full).round());
    assert_eq!(f64::from(img[0][0]), (0.7 * 0.4 * full).round());
    assert_eq!(img[1], [0, 0, 0]);
    assert_eq!(img[w * h - 2], [65535; 3]);
    let eight = expose(
        &rad,
        w,
        h,
        [50.0, 40.0],
        &CameraResponse {
            bit_depth: 8,
            ..cam
        },
        gain2,
    );
    assert_eq!(eight[40 * w + 50][0], 102);
}

use fabkit_calibration::groundtruth::exact::ExactPrimitives;
use fabkit_calibration::groundtruth::rays::PixelRays;
use fabkit_calibration::groundtruth::shading::frame_radiance;
use fabkit_calibration::groundtruth::surface::ReferenceSurface;
use fabkit_calibration::groundtruth::synthetic::{benchmark_pose, rtac0_body};
use fabkit_calibration::groundtruth::{indented_hits, reference_hits};
use fabkit_calibration::synthetic::benchmark_intrinsics;
use fabkit_calibration::CameraModel;
use fabkit_designs::optics::ResolvedOptics;
use fabkit_designs::primitives::Primitive;

pub(crate) fn optics_with(lights: Vec<Light>) -> ResolvedOptics {
    ResolvedOptics {
        light_sources: vec!["test".into(); lights.len()],
        lights,
        surface: Reflectance {
            albedo_rgb: [0.7, 0.7, 0.7],
            specular: 0.0,
            roughness: 1.0,
            darkness_per_mm: None,
        },
        marker_albedo_rgb: [0.9; 3],
        camera: CameraResponse::default(),
        markers: Vec::new(),
        marker_sources: Vec::new(),
        dimples: Vec::new(),
        dimple_sources: Vec::new(),
    }
}

/// R-Tac0's skin (a 15 mm hemisphere on a cylinder) seen by the 160 deg benchmark camera, a
/// 4 mm sphere tip pressed 2 mm into it near the pole.
fn pressed() -> (PixelRays, ExactPrimitives, [f64; 3], f64) {
    let cam = CameraModel::new(benchmark_intrinsics()).unwrap();
    let rays = PixelRays::new(&cam, &benchmark_pose());
    let (c, r) = ([2.0, -1.0, 15.0], 4.0);
    let prims = ExactPrimitives::new(&[Primitive::Sphere {
        centre_mm: c,
        radius_mm: r,
    }])
    .unwrap();
    (rays, prims, c, r)
}

/// A distant light straight under the skin (1 km down, facing up; irradiance 1 where it
/// faces the light): on the sphere tip's imprint every pixel's radiance is
/// `albedo / pi x cos`, the cosine between the tip's own normal at the point (from its centre,
/// not from the caster) and the light, within 0.1 %.
#[test]
fn a_sphere_tip_imprint_under_a_distant_light_has_the_analytic_shading() {
    let (rays, prims, c, r) = pressed();
    let surface = ReferenceSurface::of(&rtac0_body()).unwrap();
    let reference = reference_hits(&rays, &surface);
    let hits = indented_hits(&rays, &reference, &prims, surface.base_z_mm());
    let far = 1e6;
    let light = Light {
        position_mm: [0.0, 0.0, -far],
        direction: [0.0, 0.0, 1.0],
        cone_half_angle_deg: 90.0,
        colour_rgb: [1.0, 1.0, 1.0],
        intensity: far * far,
    };
    let rad = frame_radiance(&rays, None, &hits, &optics_with(vec![light]), Some(&prims));
    let mut checked = 0;
    for i in 0..rays.dirs.len() {
        if !hits.contact[i] {
            continue;
        }
        let (t, d, o) = (hits.t_mm[i], rays.dirs[i], rays.origin_mm);
        let p = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
        // the tip's outward normal, facing the camera; the light comes from -z
        let cos = ((c[2] - p[2]) / r).max(0.0);
        let want = 0.7 / PI * cos;
        // measured up to 4.9e-5 relative (the radiance's rounding in the cosine's sampling)
        assert!(
            (rad[i][0] - want).abs() <= 1e-3 * want.max(1e-3),
            "pixel {i}: {} vs {want}",
            rad[i][0]
        );
        checked += 1;
    }
    // measured 3,715
    assert!(checked > 500, "{checked} imprint pixels");
}

/// A light beside the tip, inside the skin: the skin's pixels it leaves dark are exactly those
/// whose segment to the light passes through the tip (a closed-form segment-sphere test),
/// bar pixels whose segment grazes the tip within 1 um.
#[test]
fn the_tip_shadows_the_skin_where_its_sphere_blocks_the_light() {
    let (rays, prims, c, r) = pressed();
    let surface = ReferenceSurface::of(&rtac0_body()).unwrap();
    let reference = reference_hits(&rays, &surface);
    let hits = indented_hits(&rays, &reference, &prims, surface.base_z_mm());
    let light = Light {
        position_mm: [-9.0, 4.0, 6.0],
        direction: [1.0, -0.4, 1.0],
        cone_half_angle_deg: 90.0,
        colour_rgb: [1.0, 1.0, 1.0],
        intensity: 100.0,
    };
    let rad = frame_radiance(
        &rays,
        None,
        &hits,
        &optics_with(vec![light.clone()]),
        Some(&prims),
    );
    let unshadowed = frame_radiance(&rays, None, &hits, &optics_with(vec![light.clone()]), None);
    let (mut shadowed, mut graze) = (0, 0);
    for i in 0..rays.dirs.len() {
        if !hits.t_mm[i].is_finite() || hits.contact[i] || !(unshadowed[i][0] > 0.0) {
            continue;
        }
        let (t, d, o) = (hits.t_mm[i], rays.dirs[i], rays.origin_mm);
        let p = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
        // the segment p -> light against the sphere |x - c| = r
        let s: Vec<f64> = (0..3).map(|k| light.position_mm[k] - p[k]).collect();
        let len = s.iter().map(|x| x * x).sum::<f64>().sqrt();
        let u: Vec<f64> = s.iter().map(|x| x / len).collect();
        let m: Vec<f64> = (0..3).map(|k| p[k] - c[k]).collect();
        let b = (0..3).map(|k| m[k] * u[k]).sum::<f64>();
        let cc = m.iter().map(|x| x * x).sum::<f64>() - r * r;
        let disc = b * b - cc;
        let t_hit = -b - disc.max(0.0).sqrt();
        let blocked = disc > 0.0 && t_hit > 0.0 && t_hit < len;
        let near_graze = disc.abs() < 2.0 * r * 1e-3;
        let dark = rad[i][0] == 0.0;
        if dark != blocked {
            assert!(near_graze, "pixel {i}: dark {dark}, blocked {blocked}");
            graze += 1;
        }
        shadowed += usize::from(dark);
    }
    // measured 1,082 shadowed and 0 grazing
    assert!(shadowed > 100, "{shadowed} shadowed pixels");
    assert!(graze < 10, "{graze} grazing pixels");
}

/// Markers as albedo, moving with the skin: spots on R-Tac0's sphere (radius 15 mm about the
/// origin) round the pressed tip. A spot the tip pushes in moves along its normal to where that
/// line meets the tip's sphere (a quadratic solved here); the pixels drawn with the markers'
/// albedo are exactly the surface points within a spot's radius of its moved centre, and there
/// the radiance is that of the skin times 0.9 / 0.7 (the albedos).
#[test]
fn markers_move_along_their_normals_and_carry_their_albedo() {
    use fabkit_calibration::groundtruth::shading::MarkerMap;
    use fabkit_designs::optics::MarkerSpot;
    let (rays, prims, c, r) = pressed();
    let surface = ReferenceSurface::of(&rtac0_body()).unwrap();
    let reference = reference_hits(&rays, &surface);
    let hits = indented_hits(&rays, &reference, &prims, surface.base_z_mm());
    let spots: Vec<MarkerSpot> = (0..12)
        .flat_map(|k| {
            [4.0f64, 9.0, 16.0].map(|polar| {
                let (p, a) = (polar.to_radians(), (30.0 * f64::from(k)).to_radians());
                let n = [p.sin() * a.cos(), p.sin() * a.sin(), p.cos()];
                MarkerSpot {
                    centre_mm: n.map(|x| 15.0 * x),
                    normal: n,
                    radius_mm: 0.6,
                }
            })
        })
        .collect();
    let map = MarkerMap::new(&spots, Some(&prims));
    let mut moved = 0;
    for (s, got) in spots.iter().zip(map.centres_mm()) {
        let (m, n) = (s.centre_mm, s.normal);
        let inside = (0..3).map(|k| (m[k] - c[k]).powi(2)).sum::<f64>() < r * r;
        let want = if inside {
            // m - t n on the sphere |x - c| = r, the root on the camera's side (t > 0)
            let d: Vec<f64> = (0..3).map(|k| m[k] - c[k]).collect();
            let b = (0..3).map(|k| d[k] * n[k]).sum::<f64>();
            let cc = d.iter().map(|x| x * x).sum::<f64>() - r * r;
            let t = b + (b * b - cc).sqrt();
            moved += 1;
            std::array::from_fn(|k| m[k] - t * n[k])
        } else {
            m
        };
        for k in 0..3 {
            assert!((got[k] - want[k]).abs() < 1e-9, "{got:?} vs {want:?}");
        }
    }
    // measured 25
    assert!(moved >= 10, "{moved} spots pushed in");

    let light = Light {
        position_mm: [0.0, 0.0, -1e6],
        direction: [0.0, 0.0, 1.0],
        cone_half_angle_deg: 90.0,
        colour_rgb: [1.0, 1.0, 1.0],
        intensity: 1e12,
    };
    let plain = optics_with(vec![light]);
    let marked = ResolvedOptics {
        markers: spots.clone(),
        ..plain.clone()
    };
    let a = frame_radiance(&rays, None, &hits, &plain, Some(&prims));
    let b = frame_radiance(&rays, None, &hits, &marked, Some(&prims));
    let (mut on_marker, mut on_pushed) = (0, 0);
    for i in 0..rays.dirs.len() {
        let t = hits.t_mm[i];
        if !t.is_finite() {
            continue;
        }
        let (o, d) = (rays.origin_mm, rays.dirs[i]);
        let p: [f64; 3] = std::array::from_fn(|k| o[k] + t * d[k]);
        let within = map
            .centres_mm()
            .iter()
            .any(|q| (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>() <= 0.36);
        if within {
            on_marker += 1;
            on_pushed += usize::from(hits.contact[i]);
            assert!(
                (b[i][0] - a[i][0] * 0.9 / 0.7).abs() <= 1e-12 * a[i][0].max(1.0),
                "pixel {i}"
            );
        } else {
            assert_eq!(a[i], b[i], "pixel {i} off the markers");
        }
    }
    // measured 2,372
    assert!(on_marker > 500, "{on_marker} marker pixels");
    assert!(on_pushed > 50, "{on_pushed} marker pixels on the imprint");
}

/// A darkness-mapping skin (`optics.surface.darkness_per_mm`, DTact / R-Tac0 Sec. II): on
/// R-Tac0's sphere pressed by the tip, every pressed pixel returns what its unpressed point
/// returned (the reference frame's radiance at that pixel, markers included) times
/// `1 - k x sink`, the sink measured along the sphere's own normal at the unpressed point
/// (x / 15 mm, not the renderer's normals); a light beside the tip that shadows a plain skin's
/// pixels shadows none of this skin's; off the imprint (without markers, which move round the
/// tip) the two frames agree.
#[test]
fn a_darkness_skin_returns_its_unpressed_light_dimmed_by_the_sink() {
    use fabkit_designs::optics::MarkerSpot;
    let (rays, prims, _, _) = pressed();
    let surface = ReferenceSurface::of(&rtac0_body()).unwrap();
    let reference = reference_hits(&rays, &surface);
    let hits = indented_hits(&rays, &reference, &prims, surface.base_z_mm());
    // the shadow test's light: it leaves a plain skin's pixels round the tip dark
    let light = Light {
        position_mm: [-9.0, 4.0, 6.0],
        direction: [1.0, -0.4, 1.0],
        cone_half_angle_deg: 90.0,
        colour_rgb: [1.0, 1.0, 1.0],
        intensity: 100.0,
    };
    let k = 0.22;
    let mut optics = optics_with(vec![light]);
    optics.surface.darkness_per_mm = Some(k);
    // markers on the unpressed skin round the pole, some under the tip
    optics.markers = (0..12)
        .flat_map(|a| {
            [3.0f64, 8.0, 13.0].map(|polar| {
                let (p, a) = (polar.to_radians(), (30.0 * f64::from(a)).to_radians());
                let n = [p.sin() * a.cos(), p.sin() * a.sin(), p.cos()];
                MarkerSpot {
                    centre_mm: n.map(|x| 15.0 * x),
                    normal: n,
                    radius_mm: 0.8,
                }
            })
        })
        .collect();
    let unpressed = frame_radiance(&rays, None, &reference, &optics, None);
    let dark = frame_radiance(&rays, Some(&reference), &hits, &optics, Some(&prims));
    let plain = {
        let mut o = optics.clone();
        o.surface.darkness_per_mm = None;
        frame_radiance(&rays, Some(&reference), &hits, &o, Some(&prims))
    };
    let bare = {
        let mut o = optics.clone();
        o.markers.clear();
        frame_radiance(&rays, None, &reference, &o, None)
    };
    let dark_bare = {
        let mut o = optics.clone();
        o.markers.clear();
        frame_radiance(&rays, Some(&reference), &hits, &o, Some(&prims))
    };
    let (mut pressed_px, mut deep, mut on_markers, mut plain_shadowed) = (0, 0, 0, 0);
    for i in 0..rays.dirs.len() {
        if !hits.t_mm[i].is_finite() {
            continue;
        }
        if !hits.contact[i] {
            // (markers the tip pushed in move with the skin round it: compared without them)
            assert_eq!(dark_bare[i], bare[i], "pixel {i} off the imprint");
            continue;
        }
        let (o, d) = (rays.origin_mm, rays.dirs[i]);
        let (t0, t) = (reference.t_mm[i], hits.t_mm[i]);
        let p0: [f64; 3] = std::array::from_fn(|j| o[j] + t0 * d[j]);
        let p: [f64; 3] = std::array::from_fn(|j| o[j] + t * d[j]);
        let sink: f64 = (0..3).map(|j| (p0[j] - p[j]) * p0[j] / 15.0).sum();
        let want = unpressed[i][0] * (1.0 - k * sink);
        assert!(
            (dark[i][0] - want).abs() <= 1e-9 * want.max(1e-9),
            "pixel {i}: {} vs {want} (sink {sink} mm)",
            dark[i][0]
        );
        pressed_px += 1;
        deep += usize::from(sink > 1.0);
        // the unpressed point's albedo is the markers' (0.9 of 0.7's light)
        on_markers += usize::from(
            unpressed[i][0] > 0.0
                && (unpressed[i][0] - bare[i][0] * 0.9 / 0.7).abs() <= 1e-12 * bare[i][0],
        );
        plain_shadowed += usize::from(plain[i][0] == 0.0 && unpressed[i][0] > 0.0);
        assert!(
            unpressed[i][0] == 0.0 || dark[i][0] > 0.0,
            "pixel {i} shadowed"
        );
    }
    // measured 3,715 pressed, 3,440 sunk over 1 mm, 2,280 on markers, 978 a plain skin shadows
    assert!(pressed_px > 3000, "{pressed_px} pressed pixels");
    assert!(deep > 2000, "{deep} pixels sunk over 1 mm");
    assert!(on_markers > 1000, "{on_markers} pressed pixels on markers");
    assert!(
        plain_shadowed > 500,
        "{plain_shadowed} pressed pixels a plain skin shadows"
    );
}

/// A dimple under a grazing light casts a shadow of the analytic length: a flat skin's face
/// (z = 5 mm) seen from 10 mm below by a pinhole camera (f = 1000 px, 0.01 mm a pixel on the
/// face), one ShadowTac dimple (0.45 mm wide, 0.5 mm high: a hemisphere of radius r on a
/// cylinder, its centre a = 0.275 mm from the face) standing towards the camera, a distant
/// light at 20 deg above the face from +x. Along the row through the dimple the face is dark
/// from the dimple to x = x_b - (r + a cos(20 deg)) / sin(20 deg), where the line to the light
/// grazes the hemisphere: the farthest dark pixel is within one pixel of it.
#[test]
fn a_dimple_under_a_grazing_light_casts_a_shadow_of_the_analytic_length() {
    use fabkit_calibration::camera::{Distortion, Intrinsics};
    use fabkit_designs::optics::Dimple;
    use nalgebra::{Isometry3, Translation3, UnitQuaternion};
    let (w, h, f) = (401u32, 41u32, 1000.0);
    let cam = CameraModel::new(Intrinsics {
        image_width_px: w,
        image_height_px: h,
        fx_px: f,
        fy_px: f,
        cx_px: 200.0,
        cy_px: 20.0,
        distortion: Distortion::PlumbBob([0.0; 5]),
    })
    .unwrap();
    let pose = Isometry3::from_parts(Translation3::new(0.0, 0.0, 5.0), UnitQuaternion::identity());
    let rays = PixelRays::new(&cam, &pose);
    let surface = ReferenceSurface::Flat {
        half_width_mm: 10.0,
        half_length_mm: 10.0,
        corner_radius_mm: 1.0,
        top_z_mm: 5.0,
    };
    let hits = reference_hits(&rays, &surface);
    let (xb, r, height) = (0.8, 0.225, 0.5);
    let alpha = 20f64.to_radians();
    let far = 1e6;
    let to_light = [alpha.cos(), 0.0, -alpha.sin()];
    let light = Light {
        position_mm: [xb + far * to_light[0], 0.0, 5.0 + far * to_light[2]],
        direction: to_light.map(|x| -x),
        cone_half_angle_deg: 90.0,
        colour_rgb: [1.0, 1.0, 1.0],
        intensity: far * far,
    };
    let optics = ResolvedOptics {
        dimples: vec![Dimple {
            base_mm: [xb, 0.0, 5.0],
            normal: [0.0, 0.0, 1.0],
            radius_mm: r,
            height_mm: height,
        }],
        ..optics_with(vec![light])
    };
    let rad = frame_radiance(&rays, None, &hits, &optics, None);
    let a = height - r;
    let tip = xb - (r + a * alpha.cos()) / alpha.sin();
    let row = (h / 2) as usize * w as usize;
    let (o, mut farthest, mut dark) = (rays.origin_mm, f64::INFINITY, 0);
    for u in 0..w as usize {
        let i = row + u;
        let (t, d) = (hits.t_mm[i], rays.dirs[i]);
        let x = o[0] + t * d[0];
        // the face's pixels beside the dimple (not those that see it)
        if (x - xb).abs() <= r + 0.02 {
            continue;
        }
        if rad[i][0] == 0.0 {
            dark += 1;
            farthest = farthest.min(x);
        } else {
            assert!(rad[i][0] > 0.0, "pixel {u}");
        }
    }
    let pixel_mm = 10.0 / f;
    // measured 117
    assert!(dark > 50, "{dark} dark pixels");
    assert!(
        farthest >= tip - 1e-9 && farthest - tip <= pixel_mm,
        "the shadow ends at x = {farthest} mm, the analytic tip is {tip} mm"
    );
    // the dark pixels are those between the dimple and the tip
    let lit_between = (0..w as usize)
        .map(|u| row + u)
        .filter(|&i| {
            let x = o[0] + hits.t_mm[i] * rays.dirs[i][0];
            x > tip + pixel_mm && x < xb - r - 0.02 && rad[i][0] > 0.0
        })
        .count();
    assert_eq!(lit_between, 0);
}
