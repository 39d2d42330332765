//! Image formation for rendered tactile images: the light a surface point sends to the camera
//! under the design's lights ([`fabkit_designs::optics`]), and the camera's response to it
//! (gain, vignetting, photon and read noise, quantisation). Sensor frame, mm.
//!
//! Each light is a point emitter whose intensity falls as the cosine of the angle from its
//! beam's axis and is 0 outside its cone; the irradiance it gives a point `d` mm away is
//! `intensity x cos(off-axis) x cos(incidence) / d^2` per colour channel, times its colour.
//! The surface reflects it with a Lambertian albedo plus a normalised Blinn-Phong lobe (its
//! exponent from the roughness). Not modelled: refraction through the clear layers between
//! the camera and the reflective surface, light scattered inside the elastomer, and light
//! reflected from one part of the skin onto another.

use fabkit_designs::optics::{CameraResponse, Light, Reflectance};
use rand_chacha::rand_core::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use std::f64::consts::PI;

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

/// The irradiance `light` gives the point `p_mm` whose surface normal (towards the light's
/// side) is `n`, per colour channel, relative units (see [`Light::intensity`]); 0 when the
/// point is outside the light's cone or faces away from it.
pub fn irradiance(light: &Light, p_mm: [f64; 3], n: [f64; 3]) -> [f64; 3] {
    let to_light = sub(light.position_mm, p_mm);
    let d2 = dot(to_light, to_light);
    if !(d2 > 0.0) {
        return [0.0; 3];
    }
    let l = unit(to_light);
    let cos_incidence = dot(n, l);
    let cos_axis = -dot(unit(light.direction), l);
    let cone = light.cone_half_angle_deg.to_radians().cos();
    if cos_incidence <= 0.0 || cos_axis <= 0.0 || cos_axis < cone - 1e-12 {
        return [0.0; 3];
    }
    let e = light.intensity * cos_axis * cos_incidence / d2;
    light.colour_rgb.map(|c| c * e)
}

/// The radiance the point `p_mm` (surface normal `n`, towards the camera's side) sends along
/// `to_eye` (unit, from the point to the camera) under `lights`, per colour channel: the
/// diffuse part with `albedo_rgb`, the specular lobe of `surface`. `lit(i)` says whether light
/// `i` reaches the point (false: in its shadow).
pub fn radiance(
    p_mm: [f64; 3],
    n: [f64; 3],
    to_eye: [f64; 3],
    albedo_rgb: [f64; 3],
    surface: &Reflectance,
    lights: &[Light],
    lit: impl Fn(usize) -> bool,
) -> [f64; 3] {
    let r = surface.roughness.clamp(1e-3, 1.0);
    let shininess = (2.0 / (r * r) - 2.0).max(0.0);
    let mut out = [0.0; 3];
    for (i, light) in lights.iter().enumerate() {
        let e = irradiance(light, p_mm, n);
        if e == [0.0; 3] || !lit(i) {
            continue;
        }
        let l = unit(sub(light.position_mm, p_mm));
        let h = unit([l[0] + to_eye[0], l[1] + to_eye[1], l[2] + to_eye[2]]);
        let lobe =
            surface.specular * (shininess + 8.0) / (8.0 * PI) * dot(n, h).max(0.0).powf(shininess);
        for c in 0..3 {
            out[c] += (albedo_rgb[c] / PI + lobe) * e[c];
        }
    }
    out
}

/// The image the camera records of `radiance` (row-major, `width` x `height`, per channel):
/// times `gain` and the vignetting (`1 - vignetting x (r / r_corner)^2` about `principal_px`),
/// as a fraction of full scale, with photon noise (the signal's electrons out of
/// `full_well_electrons`, Gaussian with the Poisson variance; `rand_distr`'s ziggurat) and read
/// noise, clipped and quantised to `bit_depth` bits. NaN radiance (a pixel that sees nothing) records 0 plus
/// noise. The noise of row `v` comes from its own stream of `seed`: the same seed gives the
/// same values whatever the thread count.
pub fn expose(
    radiance: &[[f64; 3]],
    width: usize,
    height: usize,
    principal_px: [f64; 2],
    camera: &CameraResponse,
) -> Vec<[u16; 3]> {
    let full = f64::from((1u32 << camera.bit_depth.min(16)) - 1);
    let corners = [
        [0.0, 0.0],
        [width as f64 - 1.0, 0.0],
        [0.0, height as f64 - 1.0],
        [width as f64 - 1.0, height as f64 - 1.0],
    ];
    let r_corner2 = corners
        .iter()
        .map(|c| (c[0] - principal_px[0]).powi(2) + (c[1] - principal_px[1]).powi(2))
        .fold(0.0f64, f64::max)
        .max(1e-12);
    let fw = camera.full_well_electrons;
    (0..height)
        .into_par_iter()
        .flat_map_iter(|v| {
            let mut rng = ChaCha8Rng::seed_from_u64(camera.seed);
            rng.set_stream(v as u64);
            let mut gauss = move || -> f64 { StandardNormal.sample(&mut rng) };
            (0..width)
                .map(|u| {
                    let r2 =
                        (u as f64 - principal_px[0]).powi(2) + (v as f64 - principal_px[1]).powi(2);
                    let k = camera.gain * (1.0 - camera.vignetting * r2 / r_corner2);
                    let l = radiance[v * width + u];
                    l.map(|x| {
                        let signal = if x.is_finite() { (k * x).max(0.0) } else { 0.0 };
                        let electrons = signal.min(1.0) * fw;
                        let sigma = (electrons + camera.read_noise_electrons.powi(2)).sqrt();
                        let noisy = (electrons + sigma * gauss()) / fw;
                        (noisy.clamp(0.0, 1.0) * full).round() as u16
                    })
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The radiance every pixel of a frame receives (row-major, per channel; NaN where the ray
/// sees no skin): the surface `hits` along `rays` (reference or indented) lit by `optics`'
/// lights, the skin's albedo everywhere (markers are not drawn yet), a light shadowed where the
/// segment from the point to it enters a protrusion of `protrusions`. The reference skin is
/// convex: seen from inside it casts no shadow on itself. Pixels are shaded in parallel, each
/// on its own: the result does not depend on the thread count.
pub fn frame_radiance(
    rays: &super::rays::PixelRays,
    hits: &super::SurfaceHits,
    optics: &fabkit_designs::optics::ResolvedOptics,
    protrusions: Option<&super::exact::ExactPrimitives>,
) -> Vec<[f64; 3]> {
    let o = rays.origin_mm;
    (0..rays.dirs.len())
        .into_par_iter()
        .map(|i| {
            let (t, d) = (hits.t_mm[i], rays.dirs[i]);
            if !t.is_finite() {
                return [f64::NAN; 3];
            }
            let p = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
            // the normal on the camera's side: the elastomer's outward normal reversed
            let n = hits.normal[i].map(|v| -v);
            let lit = |k: usize| {
                let Some(prims) = protrusions else {
                    return true;
                };
                let to_light = sub(optics.lights[k].position_mm, p);
                let dist = dot(to_light, to_light).sqrt();
                let l = unit(to_light);
                let start = [p[0] + 1e-6 * n[0], p[1] + 1e-6 * n[1], p[2] + 1e-6 * n[2]];
                prims.first_crossing(start, l, dist).is_none()
            };
            radiance(
                p,
                n,
                [-d[0], -d[1], -d[2]],
                optics.surface.albedo_rgb,
                &optics.surface,
                &optics.lights,
                lit,
            )
        })
        .collect()
}
