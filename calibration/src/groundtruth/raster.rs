//! Frame casts in triangle order: every triangle is tested against the rays that can pass
//! through it, found by projection, without walking the hierarchy.
//!
//! All rays of a frame start at the camera centre, so "which rays pass through this
//! triangle" is a rasterisation question. The rays are sorted once per camera onto the six
//! faces of a cube around the camera centre: a direction `d` belongs to the face of its
//! dominant axis `w` (largest `|d_w|`), where its gnomonic (central projection) coordinates
//! `u = d_u / |d_w|`, `v = d_v / |d_w|` lie in [-1, 1]. A face keeps a uniform grid of cells
//! over its rays, in rows, so that the rays of a row of cells are one contiguous span.
//!
//! A triangle goes to the face of its centroid's dominant axis. The central projection maps
//! the triangle to the triangle of its projected vertices (lines stay lines), so a ray that
//! passes through the triangle projects inside the bounding box of the three projected
//! vertices, which is all it takes to find every candidate ray. When that box (with a margin)
//! lies inside the face, every such ray belongs to the face. A triangle near a cube edge is
//! projected onto every face whose pyramid it may enter instead; one that reaches behind such
//! a face (only a triangle spanning tens of degrees around the camera) is tested by tiles.
//! Each candidate is decided by the same f32 edge test as the tile traversal in
//! [`super::mesh`] (same arithmetic, same rounding), and a ray keeps its nearest f32 hit, ties
//! going to the lower triangle (in the caster's leaf order). Both casts therefore give the same
//! hits.
//!
//! This pays off when most rays of the frame are cast: every triangle is visited once, in
//! leaf order (neighbours in memory are neighbours in the image), and no triangle or node is
//! fetched once per tile. It does not cull occluded triangles, so it loses when few rays are
//! cast or the mesh covers little of the frame (the protrusions alone, the reachable-pixels
//! frame of [`super::synthetic::BenchScene::protrusion_frame`]);
//! [`super::mesh::MeshCaster::cast_each_in`] says how `CastOrder::Auto` chooses.

#[cfg(target_arch = "x86_64")]
use super::mesh::avx2_fma;
use super::mesh::{cross32, dot32, f32_bound, sub32, MeshCaster, NO_HIT};
use super::rays::PixelRays;

/// Added to a triangle's projected box on each side, tangent units: several times the f32
/// rounding of the projection and of the edge test at this extent (below 1e-4 for
/// micrometre facets 10 mm away), and a small fraction of a cell (cells are about a pixel,
/// 5e-3 here).
const MARGIN: f32 = 3e-4;
/// Rows of rays per row of cells (cells are one ray wide): fewer, fuller spans per triangle.
const CELL_ROWS: f32 = 2.0;
/// Lanes of one span test.
const W: usize = 8;

/// A span test: `(face, slot state, first slot, lanes, edge normals, normal . a, triangle)`.
type SpanFn = fn(&Face, &mut SlotState, usize, usize, &[[f32; 3]; 4], f32, u32);

/// The rays of a frame sorted into the cells of six cube faces, made once per camera and
/// pose ([`PixelRays::raster`]).
#[derive(Debug, Clone)]
pub struct RayRaster {
    /// Number of pixels of the frame.
    pixels: usize,
    /// Index into `faces` of face `2 * axis + (sign < 0)`, or `None` when no ray belongs
    /// there.
    lookup: [Option<usize>; 6],
    faces: Vec<Face>,
}

#[derive(Debug, Clone)]
struct Face {
    u0: f32,
    v0: f32,
    /// Cells per tangent unit across (u) and down (v).
    inv_hu: f32,
    inv_hv: f32,
    nu: usize,
    nv: usize,
    /// First slot of each cell, row by row (`nu * nv + 1` entries).
    start: Vec<u32>,
    /// Directions of the slots (f32, as in the tiles), padded with `W` zeros.
    dx: Vec<f32>,
    dy: Vec<f32>,
    dz: Vec<f32>,
    /// Pixel of each slot.
    pix: Vec<u32>,
}

/// The other two axes of face axis `w`, (u, v).
fn face_axes(w: usize) -> (usize, usize) {
    ((w + 1) % 3, (w + 2) % 3)
}

/// The face code `2 * w + (d_w < 0)` of a direction's dominant axis `w` (the first of equal
/// ones) and its gnomonic coordinates there.
fn face_of(d: [f64; 3]) -> (usize, f64, f64) {
    let m = d.map(f64::abs);
    let w = if m[0] >= m[1] && m[0] >= m[2] {
        0
    } else if m[1] >= m[2] {
        1
    } else {
        2
    };
    let (iu, iv) = face_axes(w);
    (2 * w + (d[w] < 0.0) as usize, d[iu] / m[w], d[iv] / m[w])
}

impl RayRaster {
    /// Sorts every ray with a finite direction onto its face and cell.
    pub fn new(rays: &PixelRays) -> RayRaster {
        let mut reg: [Vec<(f32, f32, u32)>; 6] = Default::default();
        for (p, d) in rays.dirs.iter().enumerate() {
            if d.iter().all(|c| c.is_finite()) && d.iter().any(|&c| c != 0.0) {
                let (code, u, v) = face_of(*d);
                reg[code].push((u as f32, v as f32, p as u32));
            }
        }
        let mut lookup = [None; 6];
        let mut faces = Vec::new();
        for (code, reg) in reg.iter().enumerate() {
            if reg.is_empty() {
                continue;
            }
            let (mut lo, mut hi) = ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]);
            for &(u, v, _) in reg {
                lo = [lo[0].min(u), lo[1].min(v)];
                hi = [hi[0].max(u), hi[1].max(v)];
            }
            // Cells of about one ray each (the rays' mean spacing).
            let area = ((hi[0] - lo[0]) as f64 * (hi[1] - lo[1]) as f64).max(1e-12);
            let h = (area / reg.len() as f64).sqrt().max(1e-6) as f32;
            let (inv_hu, inv_hv) = (1.0 / h, 1.0 / (CELL_ROWS * h));
            let nu = (((hi[0] - lo[0]) * inv_hu).floor() as usize + 1).max(1);
            let nv = (((hi[1] - lo[1]) * inv_hv).floor() as usize + 1).max(1);
            let cell = |u: f32, v: f32| -> usize {
                let cu = (((u - lo[0]) * inv_hu).floor().max(0.0) as usize).min(nu - 1);
                let cv = (((v - lo[1]) * inv_hv).floor().max(0.0) as usize).min(nv - 1);
                cv * nu + cu
            };
            let mut start = vec![0u32; nu * nv + 1];
            for &(u, v, _) in reg {
                start[cell(u, v) + 1] += 1;
            }
            for c in 0..nu * nv {
                start[c + 1] += start[c];
            }
            let n = reg.len();
            let mut fill = start.clone();
            let (mut dx, mut dy, mut dz) = (vec![0.0; n + W], vec![0.0; n + W], vec![0.0; n + W]);
            let mut pix = vec![NO_HIT; n + W];
            // In pixel order within a cell (deterministic).
            for &(u, v, p) in reg {
                let c = cell(u, v);
                let s = fill[c] as usize;
                fill[c] += 1;
                let d = rays.dirs[p as usize];
                (dx[s], dy[s], dz[s]) = (d[0] as f32, d[1] as f32, d[2] as f32);
                pix[s] = p;
            }
            lookup[code] = Some(faces.len());
            faces.push(Face {
                u0: lo[0],
                v0: lo[1],
                inv_hu,
                inv_hv,
                nu,
                nv,
                start,
                dx,
                dy,
                dz,
                pix,
            });
        }
        RayRaster {
            pixels: rays.len(),
            lookup,
            faces,
        }
    }

    /// Number of rays sorted onto the faces (those with a finite direction).
    pub fn registered(&self) -> usize {
        self.faces.iter().map(|f| f.pix.len() - W).sum()
    }
}

/// Per-pixel result of a cast in triangle order.
pub(super) struct RasterState {
    /// Nearest f32 hit where `hit` has one (0 elsewhere).
    pub tmax: Vec<f32>,
    /// Leaf-order triangle of that hit, or [`NO_HIT`].
    pub hit: Vec<u32>,
    /// Triangles left to the tile test (see the module doc).
    pub fallback: Vec<u32>,
}

/// The state of one face's slots during a cast (padded like the slots).
struct SlotState {
    tmax: Vec<f32>,
    hit: Vec<u32>,
}

impl MeshCaster {
    /// Tests every triangle against the rays of `raster` through it, each ray up to its
    /// bound `t_max[p]` (mm; not cast unless above 0).
    pub(super) fn raster_triangles(
        &self,
        raster: &RayRaster,
        o: [f32; 3],
        t_max: &[f64],
    ) -> RasterState {
        let mut slots: Vec<SlotState> = raster
            .faces
            .iter()
            .map(|f| SlotState {
                tmax: f
                    .pix
                    .iter()
                    .map(|&p| {
                        if p == NO_HIT {
                            0.0
                        } else {
                            f32_bound(t_max[p as usize])
                        }
                    })
                    .collect(),
                hit: vec![NO_HIT; f.pix.len()],
            })
            .collect();
        let mut fallback = Vec::new();
        #[cfg(target_arch = "x86_64")]
        let done = if avx2_fma() {
            // SAFETY: the CPU supports the features the function is compiled for.
            unsafe { self.raster_avx2(raster, o, &mut slots, &mut fallback) };
            true
        } else {
            false
        };
        #[cfg(not(target_arch = "x86_64"))]
        let done = false;
        if !done {
            self.raster_any(raster, o, &mut slots, &mut fallback);
        }
        let mut st = RasterState {
            tmax: vec![0.0; raster.pixels],
            hit: vec![NO_HIT; raster.pixels],
            fallback,
        };
        for (f, ss) in raster.faces.iter().zip(&slots) {
            for (s, &p) in f.pix.iter().enumerate() {
                if ss.hit[s] != NO_HIT {
                    st.tmax[p as usize] = ss.tmax[s];
                    st.hit[p as usize] = ss.hit[s];
                }
            }
        }
        st
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn raster_avx2(
        &self,
        raster: &RayRaster,
        o: [f32; 3],
        slots: &mut [SlotState],
        fallback: &mut Vec<u32>,
    ) {
        let table = avx2::FaceTable::new(raster);
        let n = self.triangle_count();
        for (bi, block) in self.tri_blocks().iter().enumerate() {
            // SAFETY: this function runs only where AVX2 and FMA are present.
            let p = unsafe { avx2::setup(block, o, &table) };
            let valid = if 8 * bi + 8 <= n {
                0xff
            } else {
                (1u32 << (n - 8 * bi)) - 1
            };
            let mut lanes = (p.go | p.border) & valid;
            while lanes != 0 {
                let l = lanes.trailing_zeros() as usize;
                lanes &= lanes - 1;
                let k = (8 * bi + l) as u32;
                if p.border & (1 << l) != 0 {
                    let t = &self.tri32()[k as usize];
                    border(
                        raster,
                        slots,
                        fallback,
                        k,
                        t.map(|v| sub32(v, o)),
                        avx2::span_safe,
                    );
                    continue;
                }
                let fi = table.index[p.face[l] as usize];
                let f = &raster.faces[fi];
                let ss = &mut slots[fi];
                let e = [
                    [p.e[0][l], p.e[1][l], p.e[2][l]],
                    [p.e[3][l], p.e[4][l], p.e[5][l]],
                    [p.e[6][l], p.e[7][l], p.e[8][l]],
                    [p.e[9][l], p.e[10][l], p.e[11][l]],
                ];
                let cells = p.cell.map(|c| c[l] as usize);
                scan_cells(f, ss, cells, &e, p.num[l], k, avx2::span_safe);
            }
        }
    }

    fn raster_any(
        &self,
        raster: &RayRaster,
        o: [f32; 3],
        slots: &mut [SlotState],
        fallback: &mut Vec<u32>,
    ) {
        for (k, t) in self.tri32().iter().enumerate() {
            let k = k as u32;
            let [a, b, c] = t.map(|v| sub32(v, o));
            let s = [a[0] + b[0] + c[0], a[1] + b[1] + c[1], a[2] + b[2] + c[2]];
            let w = if s[0].abs() >= s[1].abs() && s[0].abs() >= s[2].abs() {
                0
            } else if s[1].abs() >= s[2].abs() {
                1
            } else {
                2
            };
            let code = 2 * w + (s[w] < 0.0) as usize;
            match project(code, [a, b, c]) {
                Some(bx) if bx.iter().all(|x| x.abs() <= 1.0) => {
                    if let Some(fi) = raster.lookup[code] {
                        let f = &raster.faces[fi];
                        scan(f, &mut slots[fi], bx, &edges([a, b, c]), k, span);
                    }
                }
                _ => border(raster, slots, fallback, k, [a, b, c], span),
            }
        }
    }
}

/// The projected box of a triangle on face `code`, with the margin: `[ulo, uhi, vlo, vhi]`,
/// or `None` when a vertex is not in front of the face (or the box is not finite).
fn project(code: usize, p: [[f32; 3]; 3]) -> Option<[f32; 4]> {
    let (w, sign) = (code / 2, if code & 1 == 0 { 1.0 } else { -1.0 });
    let (iu, iv) = face_axes(w);
    let mut bx = [
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::INFINITY,
        f32::NEG_INFINITY,
    ];
    for q in p {
        let dw = sign * q[w];
        if !(dw > 0.0) {
            return None;
        }
        let iw = 1.0 / dw;
        let (u, v) = (q[iu] * iw, q[iv] * iw);
        // (min and max would skip a NaN.)
        if !(u.is_finite() && v.is_finite()) {
            return None;
        }
        bx = [bx[0].min(u), bx[1].max(u), bx[2].min(v), bx[3].max(v)];
    }
    let bx = [
        bx[0] - MARGIN,
        bx[1] + MARGIN,
        bx[2] - MARGIN,
        bx[3] + MARGIN,
    ];
    bx.iter().all(|x| x.is_finite()).then_some(bx)
}

/// The edge normals a x b, b x c, c x a, the normal (b - a) x (c - a) and normal . a: the
/// tile test's values (same operations).
fn edges([a, b, c]: [[f32; 3]; 3]) -> ([[f32; 3]; 4], f32) {
    let n = cross32(sub32(b, a), sub32(c, a));
    (
        [cross32(a, b), cross32(b, c), cross32(c, a), n],
        dot32(n, a),
    )
}

/// Tests a triangle against the rays of face `f` in the cells of its projected box `bx`
/// (clipped to the face's grid) with `span`.
#[inline(always)]
fn scan(
    f: &Face,
    ss: &mut SlotState,
    bx: [f32; 4],
    (e, num): &([[f32; 3]; 4], f32),
    k: u32,
    span: SpanFn,
) {
    let cu0 = ((bx[0] - f.u0) * f.inv_hu).floor().max(0.0);
    let cu1 = ((bx[1] - f.u0) * f.inv_hu).floor().min((f.nu - 1) as f32);
    let cv0 = ((bx[2] - f.v0) * f.inv_hv).floor().max(0.0);
    let cv1 = ((bx[3] - f.v0) * f.inv_hv).floor().min((f.nv - 1) as f32);
    if !(cu0 <= cu1 && cv0 <= cv1) {
        return;
    }
    let cells = [cu0, cu1, cv0, cv1].map(|c| c as usize);
    scan_cells(f, ss, cells, e, *num, k, span);
}

/// Tests a triangle against the rays of face `f` in cell columns `cells[0]..=cells[1]` of rows
/// `cells[2]..=cells[3]` (within the grid), a span of up to `W` rays at a time.
#[inline(always)]
fn scan_cells(
    f: &Face,
    ss: &mut SlotState,
    [cu0, cu1, cv0, cv1]: [usize; 4],
    e: &[[f32; 3]; 4],
    num: f32,
    k: u32,
    span: SpanFn,
) {
    for cv in cv0..=cv1 {
        let row = cv * f.nu;
        let (s0, s1) = (f.start[row + cu0] as usize, f.start[row + cu1 + 1] as usize);
        let mut s = s0;
        while s < s1 {
            span(f, ss, s, (s1 - s).min(W), e, num, k);
            s += W;
        }
    }
}

/// A triangle whose box leaves its centroid's face (near a cube edge): tested on every face
/// whose pyramid (`|d_u|, |d_v| <= d_w`) it may enter, or left to the tiles (`fallback`) if
/// one of those faces has a vertex behind it.
#[inline(always)]
fn border(
    raster: &RayRaster,
    slots: &mut [SlotState],
    fallback: &mut Vec<u32>,
    k: u32,
    p: [[f32; 3]; 3],
    span: SpanFn,
) {
    let e = edges(p);
    for code in 0..6 {
        let Some(fi) = raster.lookup[code] else {
            continue;
        };
        let (w, sign) = (code / 2, if code & 1 == 0 { 1.0 } else { -1.0 });
        let (iu, iv) = face_axes(w);
        // Outside the pyramid when every vertex is beyond one of its four planes by more than
        // the edge test's rounding (the margin, scaled by the vertex's size).
        let beyond = |su: f32, sv: f32| {
            p.iter().all(|q| {
                let tol = 2.0 * MARGIN * (q[0].abs() + q[1].abs() + q[2].abs());
                sign * q[w] - (su * q[iu] + sv * q[iv]) < -tol
            })
        };
        if beyond(1.0, 0.0) || beyond(-1.0, 0.0) || beyond(0.0, 1.0) || beyond(0.0, -1.0) {
            continue;
        }
        let Some(bx) = project(code, p) else {
            fallback.push(k);
            return;
        };
        scan(&raster.faces[fi], &mut slots[fi], bx, &e, k, span);
    }
}

/// The edge test of one triangle against up to `W` consecutive slots of a face (the
/// arithmetic of the tile rows' test, lane by lane), keeping each slot's nearest hit.
/// Triangles come in increasing order, so a tie replaces only a slot without a hit.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn span(f: &Face, ss: &mut SlotState, s: usize, len: usize, e: &[[f32; 3]; 4], num: f32, k: u32) {
    let [nab, nbc, nca, n] = *e;
    let dx: &[f32; W] = f.dx[s..s + W].try_into().expect("padded");
    let dy: &[f32; W] = f.dy[s..s + W].try_into().expect("padded");
    let dz: &[f32; W] = f.dz[s..s + W].try_into().expect("padded");
    let mut inside = [false; W];
    let mut any = false;
    for i in 0..W {
        let s1 = dz[i].mul_add(nab[2], dy[i].mul_add(nab[1], dx[i] * nab[0]));
        let s2 = dz[i].mul_add(nbc[2], dy[i].mul_add(nbc[1], dx[i] * nbc[0]));
        let s3 = dz[i].mul_add(nca[2], dy[i].mul_add(nca[1], dx[i] * nca[0]));
        let pos = (s1 >= 0.0) & (s2 >= 0.0) & (s3 >= 0.0);
        let neg = (s1 <= 0.0) & (s2 <= 0.0) & (s3 <= 0.0);
        inside[i] = (pos | neg) & (i < len);
        any |= inside[i];
    }
    if !any {
        return;
    }
    let tm: &mut [f32; W] = (&mut ss.tmax[s..s + W]).try_into().expect("padded");
    let hi: &mut [u32; W] = (&mut ss.hit[s..s + W]).try_into().expect("padded");
    for i in 0..W {
        let den = dz[i].mul_add(n[2], dy[i].mul_add(n[1], dx[i] * n[0]));
        let tt = num / den;
        let h = inside[i] & (tt > 0.0) & ((tt < tm[i]) | ((tt == tm[i]) & (hi[i] == NO_HIT)));
        tm[i] = if h { tt } else { tm[i] };
        hi[i] = if h { k } else { hi[i] };
    }
}

/// [`span`] in AVX2 (the same operations lane by lane, so the same results).
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{Face, RayRaster, SlotState, MARGIN, NO_HIT, W};
    use std::arch::x86_64::*;

    /// The cell grids of the six faces by face code `2 * axis + (sign < 0)`, for lane-wise
    /// lookup (lanes 6 and 7 unused).
    pub(super) struct FaceTable {
        u0: [f32; 8],
        v0: [f32; 8],
        inv_hu: [f32; 8],
        inv_hv: [f32; 8],
        umax: [f32; 8],
        vmax: [f32; 8],
        /// All ones where the face has rays.
        present: [u32; 8],
        /// Index into the raster's faces.
        pub index: [usize; 8],
    }

    impl FaceTable {
        pub fn new(r: &RayRaster) -> FaceTable {
            let mut t = FaceTable {
                u0: [0.0; 8],
                v0: [0.0; 8],
                inv_hu: [0.0; 8],
                inv_hv: [0.0; 8],
                umax: [0.0; 8],
                vmax: [0.0; 8],
                present: [0; 8],
                index: [0; 8],
            };
            for (code, fi) in r.lookup.iter().enumerate() {
                if let Some(fi) = *fi {
                    let f = &r.faces[fi];
                    t.u0[code] = f.u0;
                    t.v0[code] = f.v0;
                    t.inv_hu[code] = f.inv_hu;
                    t.inv_hv[code] = f.inv_hv;
                    t.umax[code] = (f.nu - 1) as f32;
                    t.vmax[code] = (f.nv - 1) as f32;
                    t.present[code] = u32::MAX;
                    t.index[code] = fi;
                }
            }
            t
        }
    }

    /// Eight triangles made ready for their spans (lane `l` is triangle `8 * block + l`).
    pub(super) struct Prep {
        /// Edge normals a x b, b x c, c x a and the normal (b - a) x (c - a), by coordinate.
        pub e: [[f32; 8]; 12],
        /// normal . a
        pub num: [f32; 8],
        /// First and last cell column, first and last cell row.
        pub cell: [[i32; 8]; 4],
        /// Face code.
        pub face: [i32; 8],
        /// Lanes with cells to scan.
        pub go: u32,
        /// Lanes whose box leaves the face (see `border`).
        pub border: u32,
    }

    /// The per-triangle work of the scalar cast for eight triangles at once. The edge normals
    /// and `num` use the scalar code's operations in its order (no fused operations), so they
    /// are bit-identical to the tile test's.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn setup(block: &[[f32; 8]; 9], o: [f32; 3], t: &FaceTable) -> Prep {
        let ld = |r: usize, oc: f32| {
            _mm256_sub_ps(_mm256_loadu_ps(block[r].as_ptr()), _mm256_set1_ps(oc))
        };
        let a = [ld(0, o[0]), ld(1, o[1]), ld(2, o[2])];
        let b = [ld(3, o[0]), ld(4, o[1]), ld(5, o[2])];
        let c = [ld(6, o[0]), ld(7, o[1]), ld(8, o[2])];
        let abs = |x: __m256| _mm256_andnot_ps(_mm256_set1_ps(-0.0), x);
        let sum = [0, 1, 2].map(|i| _mm256_add_ps(_mm256_add_ps(a[i], b[i]), c[i]));
        let m = sum.map(abs);
        let w0 = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GE_OQ>(m[0], m[1]),
            _mm256_cmp_ps::<_CMP_GE_OQ>(m[0], m[2]),
        );
        let w1 = _mm256_andnot_ps(w0, _mm256_cmp_ps::<_CMP_GE_OQ>(m[1], m[2]));
        // Axis w0 -> x, w1 -> y, else z; (u, v) follow as (w + 1, w + 2) mod 3.
        let sel =
            |x: __m256, y: __m256, z: __m256| _mm256_blendv_ps(_mm256_blendv_ps(z, y, w1), x, w0);
        let z = _mm256_setzero_ps();
        let neg = _mm256_cmp_ps::<_CMP_LT_OQ>(sel(sum[0], sum[1], sum[2]), z);
        let flip = _mm256_and_ps(neg, _mm256_set1_ps(-0.0));
        let proj = |p: &[__m256; 3]| {
            let w = _mm256_xor_ps(sel(p[0], p[1], p[2]), flip);
            let u = sel(p[1], p[2], p[0]);
            let v = sel(p[2], p[0], p[1]);
            let iw = _mm256_div_ps(_mm256_set1_ps(1.0), w);
            (w, _mm256_mul_ps(u, iw), _mm256_mul_ps(v, iw))
        };
        let (wa, ua, va) = proj(&a);
        let (wb, ub, vb) = proj(&b);
        let (wc, uc, vc) = proj(&c);
        let front = _mm256_and_ps(
            _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_GT_OQ>(wa, z),
                _mm256_cmp_ps::<_CMP_GT_OQ>(wb, z),
            ),
            _mm256_cmp_ps::<_CMP_GT_OQ>(wc, z),
        );
        let lim = _mm256_set1_ps(1.0 - MARGIN);
        let mut ok = front;
        for x in [ua, ub, uc, va, vb, vc] {
            ok = _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_LE_OQ>(abs(x), lim));
        }
        let mg = _mm256_set1_ps(MARGIN);
        let ulo = _mm256_sub_ps(_mm256_min_ps(_mm256_min_ps(ua, ub), uc), mg);
        let uhi = _mm256_add_ps(_mm256_max_ps(_mm256_max_ps(ua, ub), uc), mg);
        let vlo = _mm256_sub_ps(_mm256_min_ps(_mm256_min_ps(va, vb), vc), mg);
        let vhi = _mm256_add_ps(_mm256_max_ps(_mm256_max_ps(va, vb), vc), mg);
        let axis = _mm256_castps_si256(_mm256_blendv_ps(
            _mm256_blendv_ps(
                _mm256_castsi256_ps(_mm256_set1_epi32(2)),
                _mm256_castsi256_ps(_mm256_set1_epi32(1)),
                w1,
            ),
            _mm256_castsi256_ps(_mm256_setzero_si256()),
            w0,
        ));
        let code = _mm256_sub_epi32(_mm256_slli_epi32::<1>(axis), _mm256_castps_si256(neg));
        let pick = |v: &[f32; 8]| _mm256_permutevar8x32_ps(_mm256_loadu_ps(v.as_ptr()), code);
        let present = _mm256_permutevar8x32_ps(
            _mm256_castsi256_ps(_mm256_loadu_si256(t.present.as_ptr() as *const __m256i)),
            code,
        );
        let (u0, v0) = (pick(&t.u0), pick(&t.v0));
        let (ihu, ihv) = (pick(&t.inv_hu), pick(&t.inv_hv));
        let fl = |x: __m256| _mm256_round_ps::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(x);
        let cu0 = _mm256_max_ps(fl(_mm256_mul_ps(_mm256_sub_ps(ulo, u0), ihu)), z);
        let cu1 = _mm256_min_ps(
            fl(_mm256_mul_ps(_mm256_sub_ps(uhi, u0), ihu)),
            pick(&t.umax),
        );
        let cv0 = _mm256_max_ps(fl(_mm256_mul_ps(_mm256_sub_ps(vlo, v0), ihv)), z);
        let cv1 = _mm256_min_ps(
            fl(_mm256_mul_ps(_mm256_sub_ps(vhi, v0), ihv)),
            pick(&t.vmax),
        );
        let cells = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_LE_OQ>(cu0, cu1),
            _mm256_cmp_ps::<_CMP_LE_OQ>(cv0, cv1),
        );
        let go = _mm256_and_ps(_mm256_and_ps(ok, present), cells);
        let cross = |p: &[__m256; 3], q: &[__m256; 3]| {
            [
                _mm256_sub_ps(_mm256_mul_ps(p[1], q[2]), _mm256_mul_ps(p[2], q[1])),
                _mm256_sub_ps(_mm256_mul_ps(p[2], q[0]), _mm256_mul_ps(p[0], q[2])),
                _mm256_sub_ps(_mm256_mul_ps(p[0], q[1]), _mm256_mul_ps(p[1], q[0])),
            ]
        };
        let ba = [0, 1, 2].map(|i| _mm256_sub_ps(b[i], a[i]));
        let ca = [0, 1, 2].map(|i| _mm256_sub_ps(c[i], a[i]));
        let n = cross(&ba, &ca);
        let num = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(n[0], a[0]), _mm256_mul_ps(n[1], a[1])),
            _mm256_mul_ps(n[2], a[2]),
        );
        let mut p = Prep {
            e: [[0.0; 8]; 12],
            num: [0.0; 8],
            cell: [[0; 8]; 4],
            face: [0; 8],
            go: _mm256_movemask_ps(go) as u32,
            border: _mm256_movemask_ps(_mm256_xor_ps(
                ok,
                _mm256_castsi256_ps(_mm256_set1_epi32(-1)),
            )) as u32,
        };
        for (r, v) in cross(&a, &b)
            .into_iter()
            .chain(cross(&b, &c))
            .chain(cross(&c, &a))
            .chain(n)
            .enumerate()
        {
            _mm256_storeu_ps(p.e[r].as_mut_ptr(), v);
        }
        _mm256_storeu_ps(p.num.as_mut_ptr(), num);
        for (r, v) in [cu0, cu1, cv0, cv1].into_iter().enumerate() {
            _mm256_storeu_si256(
                p.cell[r].as_mut_ptr() as *mut __m256i,
                _mm256_cvttps_epi32(v),
            );
        }
        _mm256_storeu_si256(p.face.as_mut_ptr() as *mut __m256i, code);
        p
    }

    /// [`span`] as a plain `fn` pointer for the AVX2 loop's [`super::scan_cells`].
    pub(super) fn span_safe(
        f: &Face,
        ss: &mut SlotState,
        s: usize,
        len: usize,
        e: &[[f32; 3]; 4],
        num: f32,
        k: u32,
    ) {
        // SAFETY: called only from the AVX2 loop, which runs where AVX2 and FMA are present.
        unsafe { span(f, ss, s, len, e, num, k) }
    }

    #[inline]
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn span(
        f: &Face,
        ss: &mut SlotState,
        s: usize,
        len: usize,
        e: &[[f32; 3]; 4],
        num: f32,
        k: u32,
    ) {
        assert!(s + W <= f.dx.len() && s + W <= ss.tmax.len());
        let dx = _mm256_loadu_ps(f.dx.as_ptr().add(s));
        let dy = _mm256_loadu_ps(f.dy.as_ptr().add(s));
        let dz = _mm256_loadu_ps(f.dz.as_ptr().add(s));
        let dot = |n: &[f32; 3]| {
            _mm256_fmadd_ps(
                dz,
                _mm256_set1_ps(n[2]),
                _mm256_fmadd_ps(
                    dy,
                    _mm256_set1_ps(n[1]),
                    _mm256_mul_ps(dx, _mm256_set1_ps(n[0])),
                ),
            )
        };
        let (s1, s2, s3) = (dot(&e[0]), dot(&e[1]), dot(&e[2]));
        let z = _mm256_setzero_ps();
        let pos = _mm256_and_ps(
            _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_GE_OQ>(s1, z),
                _mm256_cmp_ps::<_CMP_GE_OQ>(s2, z),
            ),
            _mm256_cmp_ps::<_CMP_GE_OQ>(s3, z),
        );
        let neg = _mm256_and_ps(
            _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_LE_OQ>(s1, z),
                _mm256_cmp_ps::<_CMP_LE_OQ>(s2, z),
            ),
            _mm256_cmp_ps::<_CMP_LE_OQ>(s3, z),
        );
        let lane = _mm256_castsi256_ps(_mm256_cmpgt_epi32(
            _mm256_set1_epi32(len as i32),
            _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
        ));
        let inside = _mm256_and_ps(_mm256_or_ps(pos, neg), lane);
        if _mm256_movemask_ps(inside) == 0 {
            return;
        }
        let tt = _mm256_div_ps(_mm256_set1_ps(num), dot(&e[3]));
        let tp = ss.tmax.as_mut_ptr().add(s);
        let hp = ss.hit.as_mut_ptr().add(s) as *mut __m256i;
        let tm = _mm256_loadu_ps(tp);
        let hi = _mm256_loadu_si256(hp);
        let none = _mm256_castsi256_ps(_mm256_cmpeq_epi32(hi, _mm256_set1_epi32(NO_HIT as i32)));
        let nearer = _mm256_or_ps(
            _mm256_cmp_ps::<_CMP_LT_OQ>(tt, tm),
            _mm256_and_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(tt, tm), none),
        );
        let h = _mm256_and_ps(
            _mm256_and_ps(inside, _mm256_cmp_ps::<_CMP_GT_OQ>(tt, z)),
            nearer,
        );
        _mm256_storeu_ps(tp, _mm256_blendv_ps(tm, tt, h));
        let kk = _mm256_set1_epi32(k as i32);
        _mm256_storeu_si256(hp, _mm256_blendv_epi8(hi, kk, _mm256_castps_si256(h)));
    }
}

#[cfg(test)]
mod tests {
    use super::super::mesh::{CastOrder, Hit, MeshCaster};
    use super::super::synthetic::BenchScene;
    use super::*;
    use fabkit_designs::geometry::Mesh;

    /// The hits of a cast, by pixel (the triangle order reports them by pixel, the tiles by
    /// tile).
    fn hits(c: &MeshCaster, order: CastOrder, rays: &PixelRays, t_max: &[f64]) -> Vec<Hit> {
        let mut v = Vec::new();
        c.cast_each_in(order, rays, t_max, &mut |h| v.push(h));
        if order == CastOrder::Triangles {
            assert!(v.windows(2).all(|w| w[0].pixel < w[1].pixel));
        }
        v.sort_by_key(|h| h.pixel);
        v
    }

    /// The triangle-order cast finds exactly the hits of the tile traversal (distances,
    /// triangles, normals, order), with and without per-ray bounds, and its vector and scalar
    /// triangle loops agree slot for slot.
    #[test]
    fn triangle_order_equals_tile_order() {
        let scene = BenchScene::new(0.004);
        let rays = &scene.rays;
        let (all, prot) = scene.casters();
        let inf = vec![f64::INFINITY; rays.len()];
        let a = hits(&all, CastOrder::Triangles, rays, &inf);
        let b = hits(&all, CastOrder::Tiles, rays, &inf);
        // measured 0.73 of the rays
        assert!(a.len() > rays.len() / 2, "{} hits", a.len());
        assert_eq!(a, b);
        // Bounds: the skin's distance along every other ray, none on the rest.
        let skin: Vec<f64> = {
            let mut t = vec![0.0; rays.len()];
            for h in &hits(
                &MeshCaster::new(&scene.body_mesh),
                CastOrder::Auto,
                rays,
                &inf,
            ) {
                t[h.pixel] = if h.pixel % 2 == 0 { h.t_mm } else { 0.0 };
            }
            t
        };
        let a = hits(&prot, CastOrder::Triangles, rays, &skin);
        let b = hits(&prot, CastOrder::Tiles, rays, &skin);
        assert!(!a.is_empty());
        assert_eq!(a, b);
        assert!(a.iter().all(|h| h.pixel % 2 == 0 && h.t_mm < skin[h.pixel]));

        let raster = rays.raster();
        // The 160 deg fisheye sees five cube faces, so triangles near the cube's edges (tested
        // on several faces) are part of the comparison.
        assert_eq!(raster.faces.len(), 5);
        assert!(
            raster.registered() >= rays.len() - rays.dirs.iter().filter(|d| d[0].is_nan()).count()
        );
        let o = rays.origin_mm.map(|c| c as f32);
        let fresh = |r: &RayRaster| -> Vec<SlotState> {
            r.faces
                .iter()
                .map(|f| SlotState {
                    tmax: f
                        .pix
                        .iter()
                        .map(|&p| if p == NO_HIT { 0.0 } else { f32::INFINITY })
                        .collect(),
                    hit: vec![NO_HIT; f.pix.len()],
                })
                .collect()
        };
        let (mut s1, mut s2) = (fresh(raster), fresh(raster));
        let (mut f1, mut f2) = (Vec::new(), Vec::new());
        all.raster_any(raster, o, &mut s1, &mut f1);
        #[cfg(target_arch = "x86_64")]
        if avx2_fma() {
            // SAFETY: checked above.
            unsafe { all.raster_avx2(raster, o, &mut s2, &mut f2) };
            assert_eq!(f1, f2);
            for (x, y) in s1.iter().zip(&s2) {
                assert_eq!(x.hit, y.hit);
                assert_eq!(x.tmax, y.tmax);
            }
        }
    }

    /// Triangles that cannot be projected onto one face (a quad around the camera, half of it
    /// behind the camera's face) are tested by tiles and still hit exactly like the traversal.
    #[test]
    fn wide_triangles_fall_back_to_tiles() {
        let scene = BenchScene::new(0.02);
        let rays = &scene.rays;
        let o = rays.origin_mm;
        // A plane 3 mm beyond the camera along the mean ray, as two huge triangles.
        let mut m = [0.0; 3];
        for d in rays.dirs.iter().filter(|d| d[0].is_finite()) {
            m = [m[0] + d[0], m[1] + d[1], m[2] + d[2]];
        }
        let l = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
        let ax = m.map(|c| c / l);
        let helper = if ax[0].abs() < 0.6 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let cr = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let e0 = cr(helper, ax);
        let e1 = cr(ax, e0);
        let r = 1000.0;
        let p =
            |s: f64, t: f64| [0, 1, 2].map(|i| o[i] + 3.0 * ax[i] + r * (s * e0[i] + t * e1[i]));
        let quad = Mesh {
            vertices: vec![p(-1.0, -1.0), p(1.0, -1.0), p(1.0, 1.0), p(-1.0, 1.0)],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        };
        let c = MeshCaster::new(&quad);
        let raster = rays.raster();
        let st = c.raster_triangles(
            raster,
            o.map(|v| v as f32),
            &vec![f64::INFINITY; rays.len()],
        );
        assert_eq!(st.fallback, vec![0, 1]);
        let inf = vec![f64::INFINITY; rays.len()];
        let a = hits(&c, CastOrder::Triangles, rays, &inf);
        let b = hits(&c, CastOrder::Tiles, rays, &inf);
        // measured 0.91 of the rays
        assert!(a.len() > rays.len() / 4, "{} hits", a.len());
        assert_eq!(a, b);
    }
}
