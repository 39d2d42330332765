//! Image formation for rendered tactile images: the light a surface point sends to the camera
//! under the design's lights ([`fabkit_designs::optics`]), and the camera's response to it
//! (gain, vignetting, photon and read noise, quantisation). Sensor frame, mm.
//!
//! Each light is a point emitter whose intensity falls as the cosine of the angle from its
//! beam's axis and is 0 outside its cone; the irradiance it gives a point `d` mm away is
//! `intensity x cos(off-axis) x cos(incidence) / d^2` per colour channel, times its colour.
//! The surface reflects it with a Lambertian albedo plus a normalised Blinn-Phong lobe (its
//! exponent from the roughness). Markers are albedo on the surface ([`MarkerMap`]); dimples
//! are solids in it that shade and cast shadows ([`DimpleField`]); both move with the surface
//! along their normals. Not modelled: refraction through the clear layers between the camera
//! and the reflective surface, light scattered inside the elastomer, light reflected from one
//! part of the skin onto another, and penumbrae (each light is a point).

use fabkit_designs::optics::{CameraResponse, Light, Reflectance};
use fabkit_designs::primitives::{dot, sub};
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::rand_core::SeedableRng;
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use std::f64::consts::PI;

fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

/// A light with what every pixel needs of it worked out once: its beam's unit axis, its cone's
/// cosine and its coloured intensity.
#[derive(Debug, Clone, Copy)]
struct Prepared {
    position_mm: [f64; 3],
    axis: [f64; 3],
    cos_cone: f64,
    rgb: [f64; 3],
}

impl Prepared {
    fn of(light: &Light) -> Prepared {
        Prepared {
            position_mm: light.position_mm,
            axis: unit(light.direction),
            cos_cone: light.cone_half_angle_deg.to_radians().cos() - 1e-12,
            rgb: light.colour_rgb.map(|c| c * light.intensity),
        }
    }

    /// The irradiance factor at `p_mm` with normal `n` and the unit vector to the light, or
    /// `None` where the point is outside the cone or faces away.
    #[inline]
    fn incident(&self, p_mm: [f64; 3], n: [f64; 3]) -> Option<(f64, [f64; 3])> {
        let to_light = sub(self.position_mm, p_mm);
        let d2 = dot(to_light, to_light);
        if !(d2 > 0.0) {
            return None;
        }
        let inv = 1.0 / d2.sqrt();
        let l = to_light.map(|x| x * inv);
        let cos_incidence = dot(n, l);
        let cos_axis = -dot(self.axis, l);
        if cos_incidence <= 0.0 || cos_axis <= 0.0 || cos_axis < self.cos_cone {
            return None;
        }
        Some((cos_axis * cos_incidence / d2, l))
    }
}

/// The irradiance `light` gives the point `p_mm` whose surface normal (towards the light's
/// side) is `n`, per colour channel, relative units (see [`Light::intensity`]); 0 when the
/// point is outside the light's cone or faces away from it.
pub fn irradiance(light: &Light, p_mm: [f64; 3], n: [f64; 3]) -> [f64; 3] {
    let pl = Prepared::of(light);
    match pl.incident(p_mm, n) {
        Some((e, _)) => pl.rgb.map(|c| c * e),
        None => [0.0; 3],
    }
}

/// The specular lobe's exponent and normalisation of `surface` (normalised Blinn-Phong).
fn lobe_of(surface: &Reflectance) -> (f64, f64) {
    let r = surface.roughness.clamp(1e-3, 1.0);
    let shininess = (2.0 / (r * r) - 2.0).max(0.0);
    (shininess, surface.specular * (shininess + 8.0) / (8.0 * PI))
}

#[inline]
fn radiance_prepared(
    p_mm: [f64; 3],
    n: [f64; 3],
    to_eye: [f64; 3],
    albedo_rgb: [f64; 3],
    (shininess, lobe_scale): (f64, f64),
    lights: &[Prepared],
    lit: impl Fn(usize, [f64; 3]) -> bool,
) -> [f64; 3] {
    let diffuse = albedo_rgb.map(|a| a / PI);
    let mut out = [0.0; 3];
    for (i, light) in lights.iter().enumerate() {
        let Some((e, l)) = light.incident(p_mm, n) else {
            continue;
        };
        if !lit(i, l) {
            continue;
        }
        let lobe = if lobe_scale > 0.0 {
            let h = unit([l[0] + to_eye[0], l[1] + to_eye[1], l[2] + to_eye[2]]);
            lobe_scale * dot(n, h).max(0.0).powf(shininess)
        } else {
            0.0
        };
        for c in 0..3 {
            out[c] += (diffuse[c] + lobe) * e * light.rgb[c];
        }
    }
    out
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
    let prepared: Vec<Prepared> = lights.iter().map(Prepared::of).collect();
    radiance_prepared(
        p_mm,
        n,
        to_eye,
        albedo_rgb,
        lobe_of(surface),
        &prepared,
        |i, _| lit(i),
    )
}

/// What differs between the frames of one set: the gain they are all exposed with (a manual
/// exposure, held) and the frame's index, whose noise is its own.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exposure {
    /// Pixel value, as a fraction of full scale, per unit of radiance, > 0.
    pub gain: f64,
    /// The frame's index in its set (0 for the reference): each frame draws its own noise.
    pub frame: u64,
}

/// The fraction of full scale [`auto_gain`] puts the reference image's bright pixels at.
pub const AUTO_EXPOSURE_LEVEL: f64 = 0.8;

/// The gain that puts the 99th percentile of `radiance`'s brightest channel (pixels that see
/// the skin, NaN elsewhere) at [`AUTO_EXPOSURE_LEVEL`] of full scale: the camera's exposure set
/// once on the reference image, as on a real sensor whose exposure is then held. 1 when no
/// pixel has light.
pub fn auto_gain(radiance: &[[f64; 3]]) -> f64 {
    let mut v: Vec<f64> = radiance
        .iter()
        .map(|p| p[0].max(p[1]).max(p[2]))
        .filter(|x| x.is_finite() && *x > 0.0)
        .collect();
    if v.is_empty() {
        return 1.0;
    }
    let k = ((v.len() - 1) as f64 * 0.99).round() as usize;
    let (_, p99, _) = v.select_nth_unstable_by(k, f64::total_cmp);
    AUTO_EXPOSURE_LEVEL / *p99
}

/// SplitMix64's finaliser: a bijection of the 64-bit words that scatters nearby inputs.
fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The seed of row `v` of frame `frame` of a camera seeded with `seed`.
fn row_seed(seed: u64, frame: u64, v: u64) -> u64 {
    mix64(mix64(mix64(seed) ^ frame) ^ v)
}

/// The image the camera records of `radiance` (row-major, `width` x `height`, per channel):
/// times the exposure's gain and the vignetting (`1 - vignetting x (r / r_corner)^2` about
/// `principal_px`), as a fraction of full scale, with photon noise (the signal's electrons out
/// of `full_well_electrons`, Poisson as a Gaussian of the same variance) and read noise (one
/// Gaussian of the summed variance, `rand_distr`'s ziggurat on a PCG-64 stream), clipped and quantised to
/// `bit_depth` bits. NaN radiance (a pixel that sees nothing) records 0 plus noise. The noise
/// of row `v` of frame `exposure.frame` comes from its own stream of `seed`: the same seed
/// gives the same values whatever the thread count, and each frame of a set its own noise.
pub fn expose(
    radiance: &[[f64; 3]],
    width: usize,
    height: usize,
    principal_px: [f64; 2],
    camera: &CameraResponse,
    exposure: Exposure,
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
    let read2 = camera.read_noise_electrons.powi(2);
    let to_counts = full / fw;
    let mut out = vec![[0u16; 3]; width * height];
    if width == 0 {
        return out;
    }
    out.par_chunks_mut(width).enumerate().for_each(|(v, row)| {
        let mut rng = Pcg64Mcg::seed_from_u64(row_seed(camera.seed, exposure.frame, v as u64));
        let dv2 = (v as f64 - principal_px[1]).powi(2);
        let line = &radiance[v * width..(v + 1) * width];
        for (u, (px, l)) in row.iter_mut().zip(line).enumerate() {
            let r2 = (u as f64 - principal_px[0]).powi(2) + dv2;
            let k = exposure.gain * (1.0 - camera.vignetting * r2 / r_corner2);
            for c in 0..3 {
                let x = l[c];
                let signal = if x.is_finite() { (k * x).max(0.0) } else { 0.0 };
                let electrons = signal.min(1.0) * fw;
                let sigma = (electrons + read2).sqrt();
                let g: f64 = StandardNormal.sample(&mut rng);
                // clamped to [0, full]: adding a half and truncating rounds to nearest
                px[c] = (((electrons + sigma * g) * to_counts).clamp(0.0, full) + 0.5) as u16;
            }
        }
    });
    out
}

/// How far inward (mm) a marker's centre is followed to the indented surface: past any
/// indentation a protrusion makes.
const MARKER_FOLLOW_MM: f64 = 50.0;

/// The point `c` of the reference surface (outward normal `n`) on the frame's surface: moved
/// along its normal to where that line enters a protrusion of `protrusions` that holds it
/// (normal displacement), else `c`.
fn follow(
    c: [f64; 3],
    n: [f64; 3],
    protrusions: Option<&super::exact::ExactPrimitives>,
) -> [f64; 3] {
    let Some(prims) = protrusions.filter(|p| p.contains(c)) else {
        return c;
    };
    let start: [f64; 3] = std::array::from_fn(|k| c[k] - MARKER_FOLLOW_MM * n[k]);
    match prims.first_crossing(start, n, MARKER_FOLLOW_MM) {
        Some(hit) => std::array::from_fn(|k| start[k] + hit.t_mm * n[k]),
        None => c,
    }
}

/// Balls (centre, radius) hashed by the cells of a uniform grid they touch: what
/// [`MarkerMap`] and [`DimpleField`] look their features up in.
#[derive(Debug, Clone)]
struct SphereGrid {
    cell_mm: f64,
    cells: rustc_hash::FxHashMap<[i64; 3], Vec<u32>>,
}

impl SphereGrid {
    fn new(cell_mm: f64) -> SphereGrid {
        SphereGrid {
            cell_mm,
            cells: rustc_hash::FxHashMap::default(),
        }
    }

    /// Lists `k` in every cell that the ball about `c` of radius `r` (mm) touches.
    fn insert(&mut self, k: u32, c: [f64; 3], r: f64) {
        let lo = c.map(|x| ((x - r) / self.cell_mm).floor() as i64);
        let hi = c.map(|x| ((x + r) / self.cell_mm).floor() as i64);
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    self.cells.entry([x, y, z]).or_default().push(k);
                }
            }
        }
    }

    /// The cell holding `p_mm`.
    #[inline]
    fn key(&self, p_mm: [f64; 3]) -> [i64; 3] {
        p_mm.map(|x| (x / self.cell_mm).floor() as i64)
    }

    /// The balls listed in the cell `key`.
    #[inline]
    fn at(&self, key: [i64; 3]) -> &[u32] {
        self.cells.get(&key).map_or(&[], Vec::as_slice)
    }
}

/// The cosine below which a ray's window near the surface stops growing: a ray within 3 deg
/// of the surface is searched for dimples over 1 / 0.05 = 20 times their reach.
const GRAZING_COS: f64 = 0.05;

/// The dimples of one frame as solids: each a capsule (its cylinder and hemispherical end, the
/// cylinder continued out past the surface), its base moved with the surface as a marker is
/// ([`MarkerMap`]), its axis along its reference normal. Looked up along a ray by the cells of
/// a hashed grid the ray passes (sampled at half a cell; each capsule listed in every cell its
/// bounding sphere, grown by a quarter cell, touches).
#[derive(Debug, Clone)]
pub struct DimpleField {
    solids: super::exact::ExactPrimitives,
    grid: SphereGrid,
    /// How far from the surface a dimple reaches, mm: height plus a diameter.
    reach_mm: f64,
}

impl DimpleField {
    /// The field of `dimples` on the surface indented by `protrusions` (none: the reference);
    /// `None` without dimples.
    pub fn new(
        dimples: &[fabkit_designs::optics::Dimple],
        protrusions: Option<&super::exact::ExactPrimitives>,
    ) -> Option<DimpleField> {
        use fabkit_designs::primitives::Primitive;
        if dimples.is_empty() {
            return None;
        }
        let prims: Vec<Primitive> = dimples
            .iter()
            .map(|m| {
                let (n, r) = (m.normal, m.radius_mm);
                let b = follow(m.base_mm, n, protrusions);
                let deep = (m.height_mm - r).max(0.0);
                Primitive::Capsule {
                    p0_mm: std::array::from_fn(|k| b[k] + r * n[k]),
                    p1_mm: std::array::from_fn(|k| b[k] - deep * n[k]),
                    radius_mm: r,
                }
            })
            .collect();
        let solids = super::exact::ExactPrimitives::new(&prims).ok()?;
        let r_max = dimples.iter().map(|m| m.radius_mm).fold(0.0f64, f64::max);
        let h_max = dimples.iter().map(|m| m.height_mm).fold(0.0f64, f64::max);
        let mut grid = SphereGrid::new((2.0 * r_max).max(0.05));
        for k in 0..solids.len() {
            let (c, r) = solids.bounding_sphere_of(k);
            grid.insert(k as u32, c, r + 0.25 * grid.cell_mm);
        }
        Some(DimpleField {
            solids,
            grid,
            reach_mm: h_max + 2.0 * r_max,
        })
    }

    /// The first crossing of a dimple along `o + t d` (d unit) with `t0 <= t < t1`, the
    /// normal pointing out of the capsule.
    pub fn first_crossing(
        &self,
        o: [f64; 3],
        d: [f64; 3],
        t0: f64,
        t1: f64,
    ) -> Option<super::exact::Crossing> {
        if !(t1 > t0) {
            return None;
        }
        let step = 0.5 * self.grid.cell_mm;
        let n = ((t1 - t0) / step).ceil() as usize;
        let mut found: Vec<u32> = Vec::new();
        let mut last: Option<[i64; 3]> = None;
        for j in 0..=n {
            let t = (t0 + j as f64 * step).min(t1);
            let key = self.grid.key(std::array::from_fn(|k| o[k] + t * d[k]));
            if last == Some(key) {
                continue;
            }
            last = Some(key);
            found.extend_from_slice(self.grid.at(key));
        }
        if found.is_empty() {
            return None;
        }
        found.sort_unstable();
        found.dedup();
        let start: [f64; 3] = std::array::from_fn(|k| o[k] + t0 * d[k]);
        self.solids
            .first_crossing_among(start, d, t1 - t0, found.iter().map(|&k| k as usize))
            .map(|c| super::exact::Crossing {
                t_mm: c.t_mm + t0,
                ..c
            })
    }

    /// The window of a ray near the surface whose normal is `n` (unit, either side): how far
    /// before the surface (or from it, towards a light) a dimple can be met, mm.
    #[inline]
    fn window_mm(&self, d: [f64; 3], n: [f64; 3]) -> f64 {
        self.reach_mm / dot(d, n).abs().max(GRAZING_COS)
    }
}

/// The markers of one frame, moved with its surface: a spot whose centre a protrusion pushes
/// in moves along its normal to where that line enters the protrusion (normal displacement
/// only: the skin's stretch along the surface is not modelled), keeping its radius. Looked up
/// by a hashed grid of cells at least a marker's diameter wide.
#[derive(Debug, Clone)]
pub struct MarkerMap {
    grid: SphereGrid,
    centres: Vec<[f64; 3]>,
    r2: Vec<f64>,
}

impl MarkerMap {
    /// The spots of `spots` on the surface indented by `protrusions` (none: the reference).
    pub fn new(
        spots: &[fabkit_designs::optics::MarkerSpot],
        protrusions: Option<&super::exact::ExactPrimitives>,
    ) -> MarkerMap {
        let r_max = spots.iter().map(|m| m.radius_mm).fold(0.0f64, f64::max);
        let mut grid = SphereGrid::new((2.0 * r_max).max(1e-3));
        let centres: Vec<[f64; 3]> = spots
            .iter()
            .map(|m| follow(m.centre_mm, m.normal, protrusions))
            .collect();
        for (i, (c, m)) in centres.iter().zip(spots).enumerate() {
            grid.insert(i as u32, *c, m.radius_mm);
        }
        MarkerMap {
            grid,
            r2: spots.iter().map(|m| m.radius_mm * m.radius_mm).collect(),
            centres,
        }
    }

    /// Whether the surface point `p_mm` lies on a marker.
    #[inline]
    pub fn covers(&self, p_mm: [f64; 3]) -> bool {
        if self.centres.is_empty() {
            return false;
        }
        self.grid.at(self.grid.key(p_mm)).iter().any(|&i| {
            let d = sub(p_mm, self.centres[i as usize]);
            dot(d, d) <= self.r2[i as usize]
        })
    }

    /// The markers' centres on this frame's surface, sensor frame, mm.
    pub fn centres_mm(&self) -> &[[f64; 3]] {
        &self.centres
    }
}

/// The radiance every pixel of a frame receives (row-major, per channel; NaN where the ray
/// sees no skin): the surface `hits` along `rays` (reference or indented) lit by `optics`'
/// lights, with the markers' albedo on the points within a marker of its centre (moved with the
/// surface, [`MarkerMap`]) and the skin's elsewhere, a light shadowed where the segment from
/// the point to it enters a protrusion of `protrusions` or a dimple. The dimples of `optics`
/// ([`DimpleField`]) are part of the surface seen: a ray that meets one before the skin sees
/// the dimple (the depth maps' `hits` do not hold them). The reference skin is convex: seen
/// from inside it casts no shadow on itself.
///
/// A darkness-mapping skin (`optics.surface.darkness_per_mm`, [`darkness`]) is lit as its
/// light scatters within its translucent layer: no protrusion casts a shadow on it, and where
/// it is pressed (`hits.contact`) it returns what its unpressed point (`reference`, at the
/// same pixel, with its markers and dimples unmoved; none given: as any skin) returned, dimmed
/// by how far it sank along that point's normal. Pixels are shaded in parallel, each on its
/// own: the result does not depend on the thread count.
pub fn frame_radiance(
    rays: &super::rays::PixelRays,
    reference: Option<&super::SurfaceHits>,
    hits: &super::SurfaceHits,
    optics: &fabkit_designs::optics::ResolvedOptics,
    protrusions: Option<&super::exact::ExactPrimitives>,
) -> Vec<[f64; 3]> {
    let darkness_per_mm = optics.surface.darkness_per_mm;
    let lights: Vec<Prepared> = optics.lights.iter().map(Prepared::of).collect();
    let lobe = lobe_of(&optics.surface);
    let pressed = Seen {
        markers: MarkerMap::new(&optics.markers, protrusions),
        dimples: DimpleField::new(&optics.dimples, protrusions),
        // a darkness-mapping skin's light is scattered within its translucent layer: a
        // protrusion pressing it casts no shadow
        shadows: protrusions.filter(|_| darkness_per_mm.is_none()),
    };
    // the unpressed skin a darkness-mapping skin's pressed points return the light of
    let unpressed = darkness_per_mm.zip(reference).map(|(k, r)| {
        let seen = Seen {
            markers: MarkerMap::new(&optics.markers, None),
            dimples: DimpleField::new(&optics.dimples, None),
            shadows: None,
        };
        (k, r, seen)
    });
    let shade = |seen: &Seen, o: [f64; 3], d: [f64; 3], t_skin: f64, n_out: [f64; 3]| {
        // the normal on the camera's side: the elastomer's outward normal reversed
        let n_skin = n_out.map(|v| -v);
        // a dimple stands towards the camera: met first, it is the surface seen
        let (t, n) = match seen.dimples.as_ref().and_then(|f| {
            let w = f.window_mm(d, n_skin);
            f.first_crossing(o, d, (t_skin - w).max(0.0), t_skin)
        }) {
            Some(c) => (c.t_mm, c.normal),
            None => (t_skin, n_skin),
        };
        let p = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
        let lit = |k: usize, l: [f64; 3]| {
            let to_light = sub(lights[k].position_mm, p);
            let dist = dot(to_light, to_light).sqrt();
            let start = [p[0] + 1e-6 * n[0], p[1] + 1e-6 * n[1], p[2] + 1e-6 * n[2]];
            if let Some(prims) = seen.shadows {
                if prims.first_crossing(start, l, dist).is_some() {
                    return false;
                }
            }
            match &seen.dimples {
                Some(f) => f
                    .first_crossing(start, l, 0.0, dist.min(f.window_mm(l, n_skin)))
                    .is_none(),
                None => true,
            }
        };
        let albedo = if seen.markers.covers(p) {
            optics.marker_albedo_rgb
        } else {
            optics.surface.albedo_rgb
        };
        radiance_prepared(p, n, [-d[0], -d[1], -d[2]], albedo, lobe, &lights, lit)
    };
    (0..rays.dirs.len())
        .into_par_iter()
        .map(|i| {
            // a ray bent by an optical path starts in the last medium (`PixelRays::through`)
            let (t_skin, d, o) = (hits.t_mm[i], rays.dirs[i], rays.origin(i));
            if !t_skin.is_finite() {
                return [f64::NAN; 3];
            }
            // a darkness-mapping skin pressed here: the light the unpressed point returned,
            // dimmed by how far it sank along its normal
            if let Some((k, r, seen)) = &unpressed {
                if hits.contact[i] && r.t_mm[i].is_finite() {
                    let (t0, n_out) = (r.t_mm[i], r.normal[i]);
                    let sink = (t0 - t_skin) * dot(d, n_out);
                    return shade(seen, o, d, t0, n_out).map(|v| v * darkness(*k, sink));
                }
            }
            shade(&pressed, o, d, t_skin, hits.normal[i])
        })
        .collect()
}

/// What a frame's rays see on the skin besides its surface: the markers and dimples where the
/// skin put them, and the protrusions that shadow it.
struct Seen<'a> {
    markers: MarkerMap,
    dimples: Option<DimpleField>,
    shadows: Option<&'a super::exact::ExactPrimitives>,
}

/// The brightness left to a darkness-mapping skin ([`frame_radiance`]) that sank `sink_mm`
/// along its normal, losing `per_mm` of its unpressed brightness per mm: `1 - per_mm x sink`,
/// within [0, 1] (a point raised above its unpressed place is not brightened: the law is
/// measured on sinks). The law is linear: on 9DTact's real ball press (tests/data/9dtact_sensor1,
/// MIT; `calibration/src/flat_response.rs`) the darkening is within a few grey levels of linear
/// in the seen face's sink up to 1.5 mm, 0.22 of the unpressed grey per mm.
pub fn darkness(per_mm: f64, sink_mm: f64) -> f64 {
    (1.0 - per_mm * sink_mm.max(0.0)).clamp(0.0, 1.0)
}

/// How the frames of one ground-truth set are imaged: the optics, the principal point the
/// vignetting is centred on, and the gain every frame is exposed with.
#[derive(Debug, Clone)]
pub struct Imaging {
    pub optics: fabkit_designs::optics::ResolvedOptics,
    /// The camera's principal point (cx, cy), px.
    pub principal_px: [f64; 2],
    /// The gain of every frame: `optics.camera.gain`, or [`auto_gain`] of the reference.
    pub gain: f64,
    /// The gain was set on the reference image ([`auto_gain`]), not given.
    pub auto_exposed: bool,
}

impl Imaging {
    /// The imaging of the frames seen along `rays`, whose reference surface is `reference`
    /// (for the exposure when `optics` gives no gain).
    pub fn new(
        optics: fabkit_designs::optics::ResolvedOptics,
        principal_px: [f64; 2],
        rays: &super::rays::PixelRays,
        reference: &super::SurfaceHits,
    ) -> Imaging {
        let (gain, auto_exposed) = match optics.camera.gain {
            Some(g) => (g, false),
            None => (
                auto_gain(&frame_radiance(rays, None, reference, &optics, None)),
                true,
            ),
        };
        Imaging {
            optics,
            principal_px,
            gain,
            auto_exposed,
        }
    }

    /// The image of frame `frame` (0: the reference) whose surface is `hits` (the unpressed
    /// surface `reference`), shadowed by `protrusions`: row-major `width x height` RGB values
    /// of `optics.camera.bit_depth` bits.
    pub fn image(
        &self,
        rays: &super::rays::PixelRays,
        reference: &super::SurfaceHits,
        hits: &super::SurfaceHits,
        protrusions: Option<&super::exact::ExactPrimitives>,
        frame: u64,
    ) -> Vec<[u16; 3]> {
        let radiance = frame_radiance(rays, Some(reference), hits, &self.optics, protrusions);
        expose(
            &radiance,
            rays.width,
            rays.height,
            self.principal_px,
            &self.optics.camera,
            Exposure {
                gain: self.gain,
                frame,
            },
        )
    }
}
