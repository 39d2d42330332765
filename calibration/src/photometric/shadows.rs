//! The shadow term's candidate lights ([`ShadowRings`]) and the shadows the protrusions cast
//! from them ([`shadow_map`]).

use super::terms::{
    median, optical_axis, DENT_MARGIN, LIGHT_AZIMUTHS, LIGHT_HEIGHTS, LIGHT_RADIUS, LIGHT_TERMS,
    SHADOW_AZIMUTHS, SHADOW_HEIGHTS, SHADOW_RADII, SHADOW_REACH, SHADOW_TERMS,
};
use crate::groundtruth::exact::ExactPrimitives;
use crate::groundtruth::hits::SurfaceHits;
use crate::groundtruth::rays::PixelRays;
use fabkit_designs::primitives::{cross, dot, sub};
use rayon::prelude::*;

/// The candidate lights of the shadow term: rings about the camera's optical axis, where a
/// sensor's LEDs are not known (a ring of LEDs, or a few, round the camera or the skin's
/// base), at [`SHADOW_HEIGHTS`] and [`SHADOW_RADII`] times the skin's median range `scale_mm`
/// from the camera centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowRings {
    /// The camera centre, sensor frame, mm.
    pub centre_mm: [f64; 3],
    /// The optical axis, sensor frame (unit).
    pub axis: [f64; 3],
    /// The median distance from the camera centre to the reference skin, mm.
    pub scale_mm: f64,
}

impl ShadowRings {
    /// The rings of the camera whose rays are `rays`, seeing the reference skin `reference`.
    pub fn of(rays: &PixelRays, reference: &SurfaceHits) -> ShadowRings {
        let ranges: Vec<f64> = reference
            .t_mm
            .iter()
            .copied()
            .filter(|t| t.is_finite())
            .collect();
        ShadowRings {
            centre_mm: rays.origin_mm,
            axis: optical_axis(rays),
            scale_mm: median(ranges).unwrap_or(1.0),
        }
    }

    /// The candidate point lights of the light term, sensor frame, mm.
    pub(super) fn point_lights(&self) -> [[f64; 3]; LIGHT_TERMS] {
        let (e1, e2) = self.frame();
        std::array::from_fn(|k| {
            let h = LIGHT_HEIGHTS[k / LIGHT_AZIMUTHS] * self.scale_mm;
            let r = LIGHT_RADIUS * self.scale_mm;
            let (sn, cs) = (std::f64::consts::TAU * (k % LIGHT_AZIMUTHS) as f64
                / LIGHT_AZIMUTHS as f64)
                .sin_cos();
            std::array::from_fn(|q| {
                self.centre_mm[q] + h * self.axis[q] + r * (cs * e1[q] + sn * e2[q])
            })
        })
    }

    /// Two unit vectors square to the axis and to each other: the rings' azimuth 0 and 90 deg.
    fn frame(&self) -> ([f64; 3], [f64; 3]) {
        let a = self.axis;
        let helper = if a[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let e1 = cross(a, helper);
        let l1 = dot(e1, e1).sqrt();
        let e1 = e1.map(|x| x / l1);
        (e1, cross(a, e1))
    }

    /// The sampled lights of ring `m` (height major, radius minor), sensor frame, mm: a ring
    /// at [`SHADOW_HEIGHTS`]`[m / 3]` and [`SHADOW_RADII`]`[m % 3]` times `scale_mm`.
    pub fn lights(&self, m: usize) -> [[f64; 3]; SHADOW_AZIMUTHS] {
        let a = self.axis;
        let (e1, e2) = self.frame();
        let h = SHADOW_HEIGHTS[m / SHADOW_RADII.len()] * self.scale_mm;
        let r = SHADOW_RADII[m % SHADOW_RADII.len()] * self.scale_mm;
        std::array::from_fn(|j| {
            let (sn, cs) = (std::f64::consts::TAU * j as f64 / SHADOW_AZIMUTHS as f64).sin_cos();
            std::array::from_fn(|q| self.centre_mm[q] + h * a[q] + r * (cs * e1[q] + sn * e2[q]))
        })
    }
}

/// The shadows the protrusions of a frame cast on its surface from the candidate rings: for
/// each pixel near a protrusion, per ring the share of the ring's light (each sampled light
/// weighted by its incidence cosine over the squared distance) that the protrusions block.
/// Pixels with no shadow are left out (sorted by pixel index).
#[derive(Debug, Clone, PartialEq)]
pub struct ShadowMap {
    pub rings: ShadowRings,
    pub pixels: Vec<ShadowPixel>,
}

/// One shadowed pixel of a [`ShadowMap`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowPixel {
    /// Row-major pixel index.
    pub pixel: u32,
    /// Per candidate ring, the share of its light the protrusions block.
    pub rings: [f64; SHADOW_TERMS],
    /// Bit `k`: candidate point light `k` of the light term is blocked.
    pub blocked: u64,
}

impl ShadowMap {
    /// No shadow (the reference, or a frame without protrusions).
    pub fn none(rings: ShadowRings) -> ShadowMap {
        ShadowMap {
            rings,
            pixels: Vec::new(),
        }
    }

    /// The shadow features of pixel `i`, if it is shadowed.
    pub fn at(&self, i: usize) -> Option<&ShadowPixel> {
        self.pixels
            .binary_search_by_key(&(i as u32), |p| p.pixel)
            .ok()
            .map(|k| &self.pixels[k])
    }
}

/// A protrusion's dent in the skin: the primitive, and the sphere (centre, radius, mm) that
/// bounds the contact points it presses.
type Dent = (usize, [f64; 3], f64);

/// The surface point of pixel `i`, sensor frame, mm.
fn surface_point(rays: &PixelRays, hits: &SurfaceHits, i: usize) -> [f64; 3] {
    let (o, t, d) = (rays.origin_mm, hits.t_mm[i], rays.dirs[i]);
    std::array::from_fn(|q| o[q] + t * d[q])
}

/// The dents of `protrusions` in the skin `hits`: only what a protrusion pushes into the skin
/// can shadow it from lights inside. Each primitive's dent is bounded by the contact points in
/// its bounding sphere, grown by [`DENT_MARGIN`] times the rings' scale; a primitive with none
/// does not press the skin.
fn dents(
    rays: &PixelRays,
    hits: &SurfaceHits,
    protrusions: &ExactPrimitives,
    rings: &ShadowRings,
) -> Vec<Dent> {
    let contact: Vec<[f64; 3]> = (0..hits.t_mm.len())
        .filter(|&i| hits.contact[i] && hits.t_mm[i].is_finite())
        .map(|i| surface_point(rays, hits, i))
        .collect();
    (0..protrusions.len())
        .filter_map(|k| {
            let (c, r) = protrusions.bounding_sphere_of(k);
            let inside: Vec<&[f64; 3]> = contact
                .iter()
                .filter(|q| {
                    let v = [q[0] - c[0], q[1] - c[1], q[2] - c[2]];
                    dot(v, v) <= r * r
                })
                .collect();
            if inside.is_empty() {
                return None;
            }
            let n = inside.len() as f64;
            let m: [f64; 3] = std::array::from_fn(|q| inside.iter().map(|p| p[q]).sum::<f64>() / n);
            let rad = inside
                .iter()
                .map(|p| {
                    let v = [p[0] - m[0], p[1] - m[1], p[2] - m[2]];
                    dot(v, v)
                })
                .fold(0.0, f64::max)
                .sqrt();
            Some((k, m, rad + DENT_MARGIN * rings.scale_mm))
        })
        .collect()
}

/// Whether the segment from the skin point `p` (camera-side normal `n`, the segment starting
/// at `start` just off the skin) to the light at `l` is blocked by a protrusion whose dent in
/// `near` it passes through, and the light's weight there (cos / distance^2; 0 behind the
/// surface, never blocked). With `traced` false the segment is known to pass through no dent
/// (a conservative test said so): only the weight is computed.
fn light_seen(
    protrusions: &ExactPrimitives,
    near: &[&Dent],
    (p, n, start): ([f64; 3], [f64; 3], [f64; 3]),
    l: &[f64; 3],
    traced: bool,
) -> (bool, f64) {
    let v = [l[0] - p[0], l[1] - p[1], l[2] - p[2]];
    let dist = dot(v, v).sqrt();
    let u = v.map(|x| x / dist);
    let w = dot(n, u).max(0.0) / (dist * dist);
    if w <= 0.0 {
        return (false, 0.0);
    }
    if !traced {
        return (false, w);
    }
    // only a dent the segment passes through can block it
    let crossed = near.iter().filter_map(|(k, c, r)| {
        let v = [c[0] - p[0], c[1] - p[1], c[2] - p[2]];
        let along = dot(v, u).clamp(0.0, dist);
        let w = [
            v[0] - along * u[0],
            v[1] - along * u[1],
            v[2] - along * u[2],
        ];
        (dot(w, w) <= r * r).then_some(*k)
    });
    let hit = protrusions
        .first_crossing_among(start, u, dist, crossed)
        .is_some();
    (hit, w)
}

/// The [`ShadowMap`] of the surface `hits` (seen along `rays`) under `protrusions`. Pixels
/// are computed in parallel; the map does not depend on the thread count.
pub fn shadow_map(
    rays: &PixelRays,
    hits: &SurfaceHits,
    protrusions: &ExactPrimitives,
    rings: &ShadowRings,
) -> ShadowMap {
    let lights: Vec<[[f64; 3]; SHADOW_AZIMUTHS]> =
        (0..SHADOW_TERMS).map(|m| rings.lights(m)).collect();
    let points = rings.point_lights();
    // the rings of the shadow term, then the point lights' rings (one per height), each as
    // its bounding sphere: centre and radius, mm
    let groups: Vec<([f64; 3], f64)> = lights
        .iter()
        .map(|ring| ring.as_slice())
        .chain(points.chunks(LIGHT_AZIMUTHS))
        .map(|g| {
            let k = g.len() as f64;
            let a: [f64; 3] = std::array::from_fn(|q| g.iter().map(|l| l[q]).sum::<f64>() / k);
            let rad = g
                .iter()
                .map(|l| {
                    let v = [l[0] - a[0], l[1] - a[1], l[2] - a[2]];
                    dot(v, v).sqrt()
                })
                .fold(0.0, f64::max);
            (a, rad * (1.0 + 1e-9) + 1e-9)
        })
        .collect();
    let reach = SHADOW_REACH * rings.scale_mm;
    let point = |i: usize| surface_point(rays, hits, i);
    let dents = dents(rays, hits, protrusions, rings);
    // each thread's buffers for a pixel's near dents, their cones and their primitives'
    // bounding spheres
    let buffers = || (Vec::<&Dent>::new(), Vec::new(), Vec::new());
    let pixels = (0..hits.t_mm.len())
        .into_par_iter()
        .map_init(buffers, |(near, cones, spheres), i| {
            if !hits.t_mm[i].is_finite() {
                return None;
            }
            let p = point(i);
            // the protrusions whose dents are near enough to shadow the point
            near.clear();
            near.extend(dents.iter().filter(|(_, c, r)| {
                let v = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
                dot(v, v).sqrt() <= r + reach
            }));
            if near.is_empty() {
                return None;
            }
            let near: &[&Dent] = near;
            // the camera's side of the surface: the elastomer's outward normal reversed
            let n = hits.normal[i].map(|v| -v);
            let start = [p[0] + 1e-6 * n[0], p[1] + 1e-6 * n[1], p[2] + 1e-6 * n[2]];
            let to = |l: &[f64; 3], traced| light_seen(protrusions, near, (p, n, start), l, traced);
            // The bounding sphere of each near dent's primitive as the exact test meets it
            // (ExactPrimitives::first_crossing_among, from `start`): the offset of `start`
            // from its centre, its radius, and whether `start` is outside it by a margin far
            // above rounding.
            spheres.clear();
            spheres.extend(near.iter().map(|(k, _, _)| {
                let (c, r) = protrusions.bounding_sphere_of(*k);
                let oc = sub(start, c);
                let cc = dot(oc, oc) - r * r;
                (oc, r, cc > 1e-9 * (r * r + 1e-9))
            }));
            let spheres: &[([f64; 3], f64, bool)] = spheres;
            // Only a light whose segment from the point passes within a near dent can be
            // blocked (`to` asks whether it does), and only by that dent's primitive, which
            // the light's ray from `start` must then meet: a superset of those lights without
            // roots or divisions, with margins far above rounding. The line's distance
            // squared |v x q|^2 / |v|^2 from the dent's centre and from the primitive's
            // bounding sphere's; and, with `start` outside that sphere, the sphere not behind
            // `start` (the exact test refuses a ray leaving it: b >= 0 with c >= 0). A ring
            // without such a light casts no shadow here.
            let may_block = |l: &[f64; 3]| -> bool {
                let v = [l[0] - p[0], l[1] - p[1], l[2] - p[2]];
                let vv = dot(v, v);
                near.iter()
                    .zip(spheres)
                    .any(|((_, c, r), (oc, rb, outside))| {
                        let q = [c[0] - p[0], c[1] - p[1], c[2] - p[2]];
                        let x = cross(v, q);
                        if dot(x, x) > (r * r * (1.0 + 1e-6) + 1e-9) * vv {
                            return false;
                        }
                        let b = dot(*oc, v);
                        if *outside && b > 0.0 && b * b >= 1e-12 * dot(*oc, *oc) * vv {
                            return false;
                        }
                        let x = cross(v, *oc);
                        dot(x, x) <= (rb * rb * (1.0 + 1e-6) + 1e-9) * vv
                    })
            };
            // A group of lights (a ring) in a sphere of radius R about a, seen from p within
            // the angle asin(R / |a - p|) of a - p; a line from p within r of a dent's centre
            // c runs within asin(r / |c - p|) of c - p (unless p is in that sphere): the
            // group can be blocked only if the two cones meet, cos(theta) >= cos(alpha +
            // beta), less a margin far above rounding. A test per group and dent before the
            // test per light.
            cones.clear();
            cones.extend(near.iter().map(|(_, c, r)| {
                let q = [c[0] - p[0], c[1] - p[1], c[2] - p[2]];
                let lq = dot(q, q).sqrt();
                if lq <= r * (1.0 + 1e-9) + 1e-9 {
                    return None;
                }
                let sb = r / lq;
                Some((q.map(|x| x / lq), sb, (1.0 - sb * sb).sqrt()))
            }));
            let cones: &[Option<([f64; 3], f64, f64)>] = cones;
            let group_may_block = |g: usize| -> bool {
                let (a, rad) = groups[g];
                let d = [a[0] - p[0], a[1] - p[1], a[2] - p[2]];
                let l = dot(d, d).sqrt();
                if l <= rad {
                    return true;
                }
                let sa = rad / l;
                let ca = (1.0 - sa * sa).sqrt();
                let du = d.map(|x| x / l);
                cones.iter().any(|cone| match cone {
                    None => true,
                    Some((q, sb, cb)) => dot(du, *q) >= ca * cb - sa * sb - 1e-6,
                })
            };
            let mut f = [0.0; SHADOW_TERMS];
            for (m, ring) in lights.iter().enumerate() {
                if !group_may_block(m) {
                    continue;
                }
                // a light whose line passes no near dent's sphere cannot be blocked: its
                // weight only; a ring without one casts no shadow here
                let traced: [bool; SHADOW_AZIMUTHS] = std::array::from_fn(|j| may_block(&ring[j]));
                if !traced.contains(&true) {
                    continue;
                }
                let (mut blocked, mut all) = (0.0, 0.0);
                for (l, &traced) in ring.iter().zip(&traced) {
                    let (hit, w) = to(l, traced);
                    all += w;
                    if hit {
                        blocked += w;
                    }
                }
                if all > 0.0 {
                    f[m] = blocked / all;
                }
            }
            let mut mask = 0u64;
            for (g, ring) in points.chunks(LIGHT_AZIMUTHS).enumerate() {
                if !group_may_block(SHADOW_TERMS + g) {
                    continue;
                }
                for (j, l) in ring.iter().enumerate() {
                    if may_block(l) && to(l, true).0 {
                        mask |= 1 << (g * LIGHT_AZIMUTHS + j);
                    }
                }
            }
            (f.iter().any(|x| *x > 0.0) || mask != 0).then_some(ShadowPixel {
                pixel: i as u32,
                rings: f,
                blocked: mask,
            })
        })
        .flatten()
        .collect();
    ShadowMap {
        rings: *rings,
        pixels,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::groundtruth::surface::ReferenceSurface;
    use crate::groundtruth::synthetic::{benchmark_pose, rtac0_body};
    use crate::groundtruth::{indented_hits, reference_hits};
    use crate::photometric::pin_primitives;
    use crate::synthetic::benchmark_intrinsics;
    use crate::CameraModel;

    /// [`shadow_map`] without its cone tests: every light traced ([`light_seen`]) at every
    /// pixel near a dent. The reference the prefiltered map must equal.
    fn every_light_traced(
        rays: &PixelRays,
        hits: &SurfaceHits,
        protrusions: &ExactPrimitives,
        rings: &ShadowRings,
    ) -> Vec<(u32, [u64; SHADOW_TERMS], u64)> {
        let lights: Vec<[[f64; 3]; SHADOW_AZIMUTHS]> =
            (0..SHADOW_TERMS).map(|m| rings.lights(m)).collect();
        let points = rings.point_lights();
        let reach = SHADOW_REACH * rings.scale_mm;
        let dents = dents(rays, hits, protrusions, rings);
        (0..hits.t_mm.len())
            .filter_map(|i| {
                if !hits.t_mm[i].is_finite() {
                    return None;
                }
                let p = surface_point(rays, hits, i);
                let near: Vec<&Dent> = dents
                    .iter()
                    .filter(|(_, c, r)| {
                        let v = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
                        dot(v, v).sqrt() <= r + reach
                    })
                    .collect();
                if near.is_empty() {
                    return None;
                }
                let n = hits.normal[i].map(|v| -v);
                let start = [p[0] + 1e-6 * n[0], p[1] + 1e-6 * n[1], p[2] + 1e-6 * n[2]];
                let to = |l: &[f64; 3]| light_seen(protrusions, &near, (p, n, start), l, true);
                let mut f = [0.0; SHADOW_TERMS];
                for (m, ring) in lights.iter().enumerate() {
                    let (mut blocked, mut all) = (0.0, 0.0);
                    for l in ring {
                        let (hit, w) = to(l);
                        all += w;
                        if hit {
                            blocked += w;
                        }
                    }
                    if all > 0.0 {
                        f[m] = blocked / all;
                    }
                }
                let mut mask = 0u64;
                for (k, l) in points.iter().enumerate() {
                    if to(l).0 {
                        mask |= 1 << k;
                    }
                }
                (f.iter().any(|x| *x > 0.0) || mask != 0).then_some((
                    i as u32,
                    f.map(f64::to_bits),
                    mask,
                ))
            })
            .collect()
    }

    /// The map's cone tests only skip lights that cannot be blocked: on R-Tac0 through the
    /// benchmark fisheye, pressed by its own five pins (shafts in the skin, deep shadows) in two
    /// turns, the map is the one that traces every light at every pixel near a dent, to the
    /// bit.
    #[test]
    fn the_cone_tests_skip_only_lights_that_cannot_be_blocked() {
        let cam = CameraModel::new(benchmark_intrinsics()).unwrap();
        let rays = PixelRays::new(&cam, &benchmark_pose());
        let surface = ReferenceSurface::of(&rtac0_body()).unwrap();
        let reference = reference_hits(&rays, &surface);
        let rings = ShadowRings::of(&rays, &reference);
        for turn_deg in [0.0, 47.0] {
            let mut solids = Vec::new();
            for p in crate::imprints::synthetic::ring_pins(turn_deg, 1.0) {
                let l = dot(p.centre_mm, p.centre_mm).sqrt();
                let axis = p.centre_mm.map(|x| x / l);
                let tip = axis.map(|x| x * (15.0 - 1.54));
                solids.extend(pin_primitives(tip, axis, 0.8, 0.8, 5.6));
            }
            let prims = ExactPrimitives::new(&solids).unwrap();
            let hits = indented_hits(&rays, &reference, &prims, surface.base_z_mm());
            let map = shadow_map(&rays, &hits, &prims, &rings);
            let got: Vec<(u32, [u64; SHADOW_TERMS], u64)> = map
                .pixels
                .iter()
                .map(|p| (p.pixel, p.rings.map(f64::to_bits), p.blocked))
                .collect();
            let want = every_light_traced(&rays, &hits, &prims, &rings);
            assert!(want.len() > 1000, "{} shadowed pixels", want.len());
            assert!(
                got == want,
                "turned {turn_deg} deg: {} of {} pixels",
                got.len(),
                want.len()
            );
        }
    }
}
