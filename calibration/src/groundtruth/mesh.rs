//! Rays of a whole camera frame against a triangle mesh: a bounding volume hierarchy (binned
//! SAH) traversed by tiles of pixels that share the camera centre.
//!
//! All rays of a frame start at the camera centre, so a tile of neighbouring pixels is a thin
//! pyramid. Each tile (8 x 8 pixels) computes four planes through the camera centre that
//! bound its rays exactly, and walks the hierarchy once for all its rays: a node is skipped
//! when its box lies outside one of the planes, or farther than the farthest hit found so far.
//! A triangle is tested against all rays of the tile at once (SIMD lanes) with the
//! shared-origin form of the watertight edge test: the ray `d` passes through the triangle
//! `(a, b, c)` (relative to the camera centre) when `d . (a x b)`, `d . (b x c)` and
//! `d . (c x a)` have one sign; two triangles sharing an edge compute that edge's value with
//! opposite signs exactly, so no ray slips between them. The tests run in f32; the distance
//! of the winning triangle is then recomputed in f64 from the exact vertices (error well
//! below 1 nm at sensor scale). A ray keeps its nearest f32 hit, ties going to the lower
//! triangle, so the result does not depend on the order of the tests.
//!
//! Whole frames go the other way round ([`super::raster`]): every triangle once, against the
//! rays through it, found by central projection onto a cube face. Same test, same hits, about
//! twice as fast when most of the frame sees the mesh; the tiles stay faster when it sees
//! little of it ([`CastOrder`]).
//!
//! Why not a crate: see the user guide, docs/src/benchmarks.md, "Ground truth" (the `bvh` and `obvhs`
//! crates measured on the same scene with single-ray traversal).

use fabkit_designs::geometry::Mesh;

use super::rays::PixelRays;
use fabkit_designs::primitives::{cross, dot, scale, sub};

/// No triangle hit.
pub const NO_HIT: u32 = u32::MAX;
const MAX_LEAF: usize = 4;
const BINS: usize = 16;
/// Tile size in pixels.
const TW: usize = 8;
const TH: usize = 8;
const LANES: usize = TW * TH;

#[derive(Debug, Clone, Copy)]
#[repr(C)]
struct Node {
    min: [f32; 3],
    /// Internal: index of the right child (the left child follows the node). Leaf: first
    /// triangle.
    link: u32,
    max: [f32; 3],
    /// Internal: `INTERNAL | split axis`. Leaf: triangle count.
    meta: u32,
}

const INTERNAL: u32 = 0x8000_0000;
/// An unused child slot of a 4-wide node.
const EMPTY: u32 = u32::MAX;

/// A 4-wide node: the boxes of up to four children (structure of arrays) and, per child, a
/// node index (`count == 0`) or a leaf's first triangle and its count.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
struct Node4 {
    lo: [[f32; 4]; 3],
    hi: [[f32; 4]; 3],
    child: [u32; 4],
    count: [u32; 4],
}

/// A triangle mesh prepared for frame casts. Triangles keep their indices in the input mesh.
#[derive(Debug, Clone)]
pub struct MeshCaster {
    nodes: Vec<Node4>,
    /// Vertices in leaf order, f32 (a, b, c).
    tri32: Vec<[[f32; 3]; 3]>,
    /// The same vertices by blocks of eight triangles (a.x, a.y, a.z, b.x, ..., c.z), each
    /// row one coordinate of the eight: the layout of the triangle-order cast.
    blocks: Vec<[[f32; 8]; 9]>,
    /// First vertex and unit normal (from the winding) in leaf order, exact.
    tri64: Vec<([f64; 3], [f64; 3])>,
    /// Input index of each triangle in leaf order.
    index: Vec<u32>,
    /// Bounds of the whole mesh.
    root_lo: [f32; 3],
    root_hi: [f32; 3],
}

/// One ray's nearest hit: pixel index, distance (mm), input triangle index, unit normal (from
/// the winding).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    pub pixel: usize,
    pub t_mm: f64,
    pub triangle: u32,
    pub normal: [f64; 3],
}

/// How a frame cast visits the mesh. Both orders find the same hits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CastOrder {
    /// Triangles when the mesh has no more triangles than there are cast rays in its reach,
    /// tiles otherwise (see [`MeshCaster::cast_each_in`]).
    Auto,
    /// Tiles of 8 x 8 pixels walk the hierarchy nearest first (culls occluded triangles; best
    /// when few rays are cast).
    Tiles,
    /// Every triangle once, against the rays through it ([`super::raster`]; best for whole
    /// frames).
    Triangles,
}

/// The result of a frame cast: per pixel, the distance to the nearest hit (mm; the pixel's
/// `t_max` where nothing was hit), the hit triangle's index in the input mesh ([`NO_HIT`]),
/// and its unit normal (from the triangle's winding: outward for a mesh wound counter-clockwise
/// seen from outside; zero where nothing was hit).
#[derive(Debug, Clone, PartialEq)]
pub struct FrameHits {
    pub t_mm: Vec<f64>,
    pub triangle: Vec<u32>,
    pub normal: Vec<[f64; 3]>,
}

fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) > x {
        f.next_down()
    } else {
        f
    }
}

fn round_up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x {
        f.next_up()
    } else {
        f
    }
}

#[derive(Clone, Copy)]
struct Bounds {
    min: [f64; 3],
    max: [f64; 3],
}

impl Bounds {
    const EMPTY: Bounds = Bounds {
        min: [f64::INFINITY; 3],
        max: [f64::NEG_INFINITY; 3],
    };
    fn grow(&mut self, o: &Bounds) {
        for k in 0..3 {
            self.min[k] = self.min[k].min(o.min[k]);
            self.max[k] = self.max[k].max(o.max[k]);
        }
    }
    fn grow_point(&mut self, p: [f64; 3]) {
        for k in 0..3 {
            self.min[k] = self.min[k].min(p[k]);
            self.max[k] = self.max[k].max(p[k]);
        }
    }
    fn area(&self) -> f64 {
        let e = [
            self.max[0] - self.min[0],
            self.max[1] - self.min[1],
            self.max[2] - self.min[2],
        ];
        if e[0] < 0.0 {
            return 0.0;
        }
        2.0 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0])
    }
}

impl MeshCaster {
    /// Builds the hierarchy (binned SAH, 16 bins, at most 4 triangles per leaf, collapsed to
    /// 4-wide nodes). Deterministic. Degenerate (zero-area) triangles are kept; they are never
    /// hit.
    pub fn new(mesh: &Mesh) -> MeshCaster {
        let tris: Vec<[[f64; 3]; 3]> = mesh
            .triangles
            .iter()
            .map(|t| {
                [
                    mesh.vertices[t[0] as usize],
                    mesh.vertices[t[1] as usize],
                    mesh.vertices[t[2] as usize],
                ]
            })
            .collect();
        let bounds: Vec<Bounds> = tris
            .iter()
            .map(|t| {
                let mut b = Bounds::EMPTY;
                for v in t {
                    b.grow_point(*v);
                }
                b
            })
            .collect();
        let centroids: Vec<[f64; 3]> = bounds
            .iter()
            .map(|b| {
                [
                    0.5 * (b.min[0] + b.max[0]),
                    0.5 * (b.min[1] + b.max[1]),
                    0.5 * (b.min[2] + b.max[2]),
                ]
            })
            .collect();
        let mut order: Vec<u32> = (0..tris.len() as u32).collect();
        let mut bin = Vec::with_capacity(2 * tris.len() / MAX_LEAF + 1);
        let mut nodes = Vec::new();
        let (mut root_lo, mut root_hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        if !tris.is_empty() {
            build(&mut bin, &mut order, 0, &bounds, &centroids);
            root_lo = bin[0].min;
            root_hi = bin[0].max;
            collapse(&bin, 0, &mut nodes);
        }
        let tri32: Vec<[[f32; 3]; 3]> = order
            .iter()
            .map(|&i| tris[i as usize].map(|v| v.map(|c| c as f32)))
            .collect();
        let blocks = tri32
            .chunks(8)
            .map(|ch| {
                let mut b = [[0.0f32; 8]; 9];
                for (l, t) in ch.iter().enumerate() {
                    for (r, row) in b.iter_mut().enumerate() {
                        row[l] = t[r / 3][r % 3];
                    }
                }
                b
            })
            .collect();
        let tri64 = order
            .iter()
            .map(|&i| {
                let t = &tris[i as usize];
                let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
                let l = dot(n, n).sqrt();
                (t[0], if l > 0.0 { scale(n, 1.0 / l) } else { [0.0; 3] })
            })
            .collect();
        MeshCaster {
            nodes,
            tri32,
            blocks,
            tri64,
            index: order,
            root_lo,
            root_hi,
        }
    }

    /// Vertices in leaf order, f32.
    pub(super) fn tri32(&self) -> &[[[f32; 3]; 3]] {
        &self.tri32
    }

    /// [`tri32`](Self::tri32) by blocks of eight.
    pub(super) fn tri_blocks(&self) -> &[[[f32; 8]; 9]] {
        &self.blocks
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.index.len()
    }

    /// Casts every ray of `rays` whose `t_max_mm` is above 0 and finds its nearest hit with
    /// `0 < t < t_max`. Single-threaded; the result depends only on the inputs.
    ///
    /// # Panics
    /// If `t_max_mm.len() != rays.len()`.
    pub fn cast(&self, rays: &PixelRays, t_max_mm: &[f64]) -> FrameHits {
        let mut out = FrameHits {
            t_mm: Vec::new(),
            triangle: Vec::new(),
            normal: Vec::new(),
        };
        self.cast_into(rays, t_max_mm, &mut out);
        out
    }

    /// [`cast`](Self::cast) into reused buffers (resized as needed). `normal` is written only
    /// where a triangle is hit; elsewhere it keeps what it held.
    ///
    /// # Panics
    /// If `t_max_mm.len() != rays.len()`.
    pub fn cast_into(&self, rays: &PixelRays, t_max_mm: &[f64], out: &mut FrameHits) {
        assert_eq!(t_max_mm.len(), rays.len(), "one t_max per ray");
        out.t_mm.clear();
        out.t_mm.extend_from_slice(t_max_mm);
        out.triangle.clear();
        out.triangle.resize(rays.len(), NO_HIT);
        out.normal.resize(rays.len(), [0.0; 3]);
        let mut put = |h: Hit| {
            out.t_mm[h.pixel] = h.t_mm;
            out.triangle[h.pixel] = h.triangle;
            out.normal[h.pixel] = h.normal;
        };
        if !self.nodes.is_empty() && self.triangle_order_pays(rays, t_max_mm) {
            self.cast_raster(rays, t_max_mm, &mut put);
        } else {
            self.cast_each_in(CastOrder::Tiles, rays, t_max_mm, &mut put);
        }
    }

    /// Like [`cast`](Self::cast), but reports only the rays that hit, through `sink`: cheaper
    /// when few rays hit. The order of the reports is deterministic: by tile when the cast
    /// walks tiles, by pixel when it visits triangles ([`CastOrder`]; `Auto` picks one from the
    /// mesh and the rays, see [`cast_each_in`](Self::cast_each_in)).
    ///
    /// # Panics
    /// If `t_max_mm.len() != rays.len()`.
    pub fn cast_each(&self, rays: &PixelRays, t_max_mm: &[f64], sink: &mut dyn FnMut(Hit)) {
        self.cast_each_in(CastOrder::Auto, rays, t_max_mm, sink);
    }

    /// [`cast_each`](Self::cast_each) in a given order. Every order gives the same hits
    /// (distances, triangles and normals, bit for bit); only the order of the reports differs.
    /// `Auto` visits triangles when the mesh has no more triangles than there are cast rays in
    /// the tiles that meet the hierarchy's boxes two levels down, tiles otherwise.
    ///
    /// # Panics
    /// If `t_max_mm.len() != rays.len()`.
    pub fn cast_each_in(
        &self,
        order: CastOrder,
        rays: &PixelRays,
        t_max_mm: &[f64],
        sink: &mut dyn FnMut(Hit),
    ) {
        assert_eq!(t_max_mm.len(), rays.len(), "one t_max per ray");
        if self.nodes.is_empty() {
            return;
        }
        let out = sink;
        let triangles = match order {
            CastOrder::Tiles => false,
            CastOrder::Triangles => true,
            CastOrder::Auto => self.triangle_order_pays(rays, t_max_mm),
        };
        if triangles {
            self.cast_raster(rays, t_max_mm, out);
            return;
        }
        let tiles = rays.tiles();
        #[cfg(target_arch = "x86_64")]
        if avx2_fma() {
            // SAFETY: the CPU supports the features the function is compiled for.
            unsafe { self.cast_tiles_avx2(rays, tiles, t_max_mm, out) };
            return;
        }
        self.cast_tiles(rays, tiles, t_max_mm, out);
    }

    /// Whether the triangle order is the faster one for this cast: when the mesh has no more
    /// triangles than there are cast rays in the tiles that meet the hierarchy's boxes two
    /// levels down (estimated from every fourth tile and four rays per tile). Tiles win when
    /// few rays are cast or the mesh covers little of the frame (they skip the rest);
    /// triangles win on whole frames (docs/src/benchmarks.md, "Ground truth").
    fn triangle_order_pays(&self, rays: &PixelRays, t_max: &[f64]) -> bool {
        // First the cast rays alone (every 64th counted): no walk when they are too few.
        let cast = t_max.iter().step_by(64).filter(|&&t| t > 0.0).count() * 64;
        if self.triangle_count() > cast {
            return false;
        }
        let mut reach = 0usize;
        self.for_reaching_tiles(rays, 2, 4, &mut |tile| {
            let cast = [0, 27, 36, 63]
                .iter()
                .filter(|&&l| tile.pix[l] != NO_HIT && t_max[tile.pix[l] as usize] > 0.0)
                .count();
            reach += cast * LANES;
        });
        self.triangle_count() <= reach
    }

    /// The pixels whose rays can reach the mesh: every active pixel (a finite direction) of the
    /// tiles whose bounding planes meet one of the hierarchy's boxes three levels below the
    /// root (up to 64 boxes, one per protrusion or tighter). Conservative: a ray outside this
    /// set cannot hit the mesh. In tile order; the rest of a frame keeps its reference depth.
    pub fn reachable_pixels(&self, rays: &PixelRays) -> Vec<u32> {
        let mut out = Vec::new();
        self.for_reaching_tiles(rays, 3, 1, &mut |tile| {
            out.extend((0..LANES).filter(|&l| tile.active[l]).map(|l| tile.pix[l]));
        });
        out
    }

    /// Calls `f` on every `stride`-th tile whose bounding planes meet one of the hierarchy's
    /// boxes `depth` levels below the root (or a leaf above them), in tile order.
    fn for_reaching_tiles(
        &self,
        rays: &PixelRays,
        depth: u32,
        stride: usize,
        f: &mut dyn FnMut(&Tile),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let tiles = rays.tiles();
        let o = tiles.origin;
        let mut stack: Vec<(u32, u32)> = Vec::with_capacity(64);
        for tile in tiles.tiles.iter().step_by(stride) {
            let mut reach = !tile.valid;
            if !reach && tile.overlaps(self.root_lo, self.root_hi, o) {
                stack.clear();
                stack.push((0, 1));
                'walk: while let Some((ni, d)) = stack.pop() {
                    let node = &self.nodes[ni as usize];
                    let (ok, _) = tile.test4(node, o, f32::INFINITY);
                    for k in 0..4 {
                        if ok[k] {
                            if node.count[k] > 0 || d >= depth {
                                reach = true;
                                break 'walk;
                            }
                            stack.push((node.child[k], d + 1));
                        }
                    }
                }
            }
            if reach {
                f(tile);
            }
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn cast_tiles_avx2(
        &self,
        rays: &PixelRays,
        tiles: &RayTiles,
        t_max: &[f64],
        out: &mut dyn FnMut(Hit),
    ) {
        self.cast_tiles(rays, tiles, t_max, out)
    }

    #[inline(always)]
    fn cast_tiles(
        &self,
        rays: &PixelRays,
        tiles: &RayTiles,
        t_max: &[f64],
        out: &mut dyn FnMut(Hit),
    ) {
        let o = tiles.origin;
        let mut stack: Vec<(u32, u32, f32)> = Vec::with_capacity(256);
        let mut pkt = Packet {
            tmax: [0.0; LANES],
            hit: [NO_HIT; LANES],
        };
        // Distance from the camera to the mesh's box: tiles whose rays all end before it skip.
        let root_d2 = box_dist2(self.root_lo, self.root_hi, o);
        for tile in &tiles.tiles {
            if !tile.overlaps(self.root_lo, self.root_hi, o) {
                continue;
            }
            let mut any = false;
            for l in 0..LANES {
                let p = tile.pix[l];
                let tm = if p != NO_HIT { t_max[p as usize] } else { 0.0 };
                if tm > 0.0 && tile.active[l] {
                    pkt.tmax[l] = f32_bound(tm);
                    any = true;
                } else {
                    pkt.tmax[l] = 0.0;
                }
                pkt.hit[l] = NO_HIT;
            }
            if !any {
                continue;
            }
            let tm = pkt.max_t() * 1.0001;
            if root_d2 > tm * tm {
                continue;
            }
            self.traverse(&mut pkt, tile, o, &mut stack);
            for l in 0..LANES {
                self.emit(rays, tile.pix[l], pkt.hit[l], t_max, out);
            }
        }
    }

    /// Reports the hit of leaf-order triangle `k` (if any) on pixel `p`, with its distance
    /// recomputed in f64 from the exact vertices, if it lies within `(0, t_max)`.
    #[inline(always)]
    fn emit<F: FnMut(Hit) + ?Sized>(
        &self,
        rays: &PixelRays,
        p: u32,
        k: u32,
        t_max: &[f64],
        out: &mut F,
    ) {
        if k == NO_HIT {
            return;
        }
        let p = p as usize;
        let (a, n) = self.tri64[k as usize];
        let tt = dot(n, sub(a, rays.origin_mm)) / dot(n, rays.dirs[p]);
        if tt > 0.0 && tt < t_max[p] {
            out(Hit {
                pixel: p,
                t_mm: tt,
                triangle: self.index[k as usize],
                normal: n,
            });
        }
    }

    /// The cast in triangle order ([`super::raster`]), reported by pixel. Triangles that the
    /// raster leaves to the tiles are tested here, tile by tile.
    fn cast_raster<F: FnMut(Hit) + ?Sized>(&self, rays: &PixelRays, t_max: &[f64], out: &mut F) {
        let tiles = rays.tiles();
        let o = tiles.origin;
        let mut st = self.raster_triangles(rays.raster(), o, t_max);
        if !st.fallback.is_empty() {
            let mut pkt = Packet {
                tmax: [0.0; LANES],
                hit: [NO_HIT; LANES],
            };
            for tile in &tiles.tiles {
                let live = |l: usize| tile.pix[l] != NO_HIT && tile.active[l];
                for l in 0..LANES {
                    let p = tile.pix[l] as usize;
                    (pkt.tmax[l], pkt.hit[l]) = match live(l) {
                        true if st.hit[p] != NO_HIT => (st.tmax[p], st.hit[p]),
                        true => (f32_bound(t_max[p]), NO_HIT),
                        false => (0.0, NO_HIT),
                    };
                }
                for &k in &st.fallback {
                    self.test_triangle_dispatch(&mut pkt, tile, o, k as usize);
                }
                for l in (0..LANES).filter(|&l| live(l)) {
                    let p = tile.pix[l] as usize;
                    (st.tmax[p], st.hit[p]) = (pkt.tmax[l], pkt.hit[l]);
                }
            }
        }
        for (p, &k) in st.hit.iter().enumerate() {
            if k != NO_HIT {
                self.emit(rays, p as u32, k, t_max, out);
            }
        }
    }

    /// [`test_triangle`](Self::test_triangle) with the CPU's fused multiply-add when it has one
    /// (the same results either way).
    fn test_triangle_dispatch(&self, pkt: &mut Packet, tile: &Tile, o: [f32; 3], k: usize) {
        #[cfg(target_arch = "x86_64")]
        if avx2_fma() {
            // SAFETY: the CPU supports the features the function is compiled for.
            unsafe { self.test_triangle_avx2(pkt, tile, o, k) };
            return;
        }
        self.test_triangle(pkt, tile, o, k);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn test_triangle_avx2(&self, pkt: &mut Packet, tile: &Tile, o: [f32; 3], k: usize) {
        self.test_triangle(pkt, tile, o, k);
    }

    #[inline(always)]
    fn traverse(
        &self,
        pkt: &mut Packet,
        tile: &Tile,
        o: [f32; 3],
        stack: &mut Vec<(u32, u32, f32)>,
    ) {
        let mut tmax = pkt.max_t() * 1.0001;
        let mut tmax2 = tmax * tmax;
        stack.clear();
        stack.push((0, 0, 0.0));
        while let Some((ni, count, d2)) = stack.pop() {
            if d2 > tmax2 {
                continue;
            }
            if count > 0 {
                let mut changed = false;
                for k in ni as usize..(ni + count) as usize {
                    changed |= self.test_triangle(pkt, tile, o, k);
                }
                if changed {
                    tmax = pkt.max_t() * 1.0001;
                    tmax2 = tmax * tmax;
                }
                continue;
            }
            let node = &self.nodes[ni as usize];
            let (ok, dist2) = tile.test4(node, o, tmax2);
            // Push far to near so that the nearest child is visited first (a 4-input sorting
            // network on the distances, far first; culled children sort as infinitely far and
            // are not pushed).
            let mut key = [0.0f32; 4];
            for k in 0..4 {
                key[k] = if ok[k] { dist2[k] } else { f32::INFINITY };
            }
            let mut order = [0usize, 1, 2, 3];
            let mut cs = |i: usize, j: usize| {
                if key[order[i]] < key[order[j]] {
                    order.swap(i, j);
                }
            };
            cs(0, 1);
            cs(2, 3);
            cs(0, 2);
            cs(1, 3);
            cs(1, 2);
            for &k in &order {
                if ok[k] {
                    stack.push((node.child[k], node.count[k], dist2[k]));
                }
            }
        }
    }

    #[inline(always)]
    /// Tests one triangle against the tile's rays; true if a ray's nearest hit changed.
    fn test_triangle(&self, pkt: &mut Packet, tile: &Tile, o: [f32; 3], k: usize) -> bool {
        let t = &self.tri32[k];
        let a = sub32(t[0], o);
        let b = sub32(t[1], o);
        let c = sub32(t[2], o);
        // Rows of the tile the triangle may cover: in the tile's gnomonic coordinates the
        // triangle is a triangle (lines stay lines), so its y range bounds the rows.
        let mut rows = (1u32 << TH) - 1;
        if tile.valid {
            let (fa, fb, fc) = (
                dot32(tile.axis, a),
                dot32(tile.axis, b),
                dot32(tile.axis, c),
            );
            if fa > 0.0 && fb > 0.0 && fc > 0.0 {
                let inv = [1.0 / fa, 1.0 / fb, 1.0 / fc];
                let ya = dot32(tile.e1, a) * inv[0];
                let yb = dot32(tile.e1, b) * inv[1];
                let yc = dot32(tile.e1, c) * inv[2];
                let xa = dot32(tile.e0, a) * inv[0];
                let xb = dot32(tile.e0, b) * inv[1];
                let xc = dot32(tile.e0, c) * inv[2];
                let (ylo, yhi) = (ya.min(yb).min(yc) - MARGIN, ya.max(yb).max(yc) + MARGIN);
                let (xlo, xhi) = (xa.min(xb).min(xc) - MARGIN, xa.max(xb).max(xc) + MARGIN);
                if (xhi < tile.x_range[0]) | (xlo > tile.x_range[1]) {
                    return false;
                }
                rows = 0;
                for r in 0..TH {
                    let over = (tile.row_hi[r] >= ylo) & (tile.row_lo[r] <= yhi);
                    rows |= (over as u32) << r;
                }
                if rows == 0 {
                    return false;
                }
            }
        }
        let nab = cross32(a, b);
        let nbc = cross32(b, c);
        let nca = cross32(c, a);
        let n = cross32(sub32(b, a), sub32(c, a));
        let num = dot32(n, a);
        let kk = k as u32;
        let mut changed = false;
        while rows != 0 {
            let r = rows.trailing_zeros() as usize;
            rows &= rows - 1;
            let base = r * TW;
            let row = |v: &[f32; LANES]| -> [f32; TW] {
                let mut o = [0.0; TW];
                o.copy_from_slice(&v[base..base + TW]);
                o
            };
            let (dx, dy, dz) = (row(&tile.dx), row(&tile.dy), row(&tile.dz));
            let tm: &mut [f32; TW] = (&mut pkt.tmax[base..base + TW]).try_into().expect("row");
            let hi: &mut [u32; TW] = (&mut pkt.hit[base..base + TW]).try_into().expect("row");
            changed |= test_row(&dx, &dy, &dz, tm, hi, [nab, nbc, nca, n], num, kk);
        }
        changed
    }
}

/// The edge test of one triangle against one row of a tile (SIMD lanes).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn test_row(
    dx: &[f32; TW],
    dy: &[f32; TW],
    dz: &[f32; TW],
    tmax: &mut [f32; TW],
    hit: &mut [u32; TW],
    e: [[f32; 3]; 4],
    num: f32,
    k: u32,
) -> bool {
    let [nab, nbc, nca, n] = e;
    // Fused multiply-adds keep the edge values of a shared edge exact negations of each other
    // (fma(a, -b, -c) = -fma(a, b, c)), so the test stays watertight.
    let mut s1 = [0.0f32; TW];
    let mut s2 = [0.0f32; TW];
    let mut s3 = [0.0f32; TW];
    let mut inside = [false; TW];
    let mut any = false;
    for i in 0..TW {
        s1[i] = dz[i].mul_add(nab[2], dy[i].mul_add(nab[1], dx[i] * nab[0]));
        s2[i] = dz[i].mul_add(nbc[2], dy[i].mul_add(nbc[1], dx[i] * nbc[0]));
        s3[i] = dz[i].mul_add(nca[2], dy[i].mul_add(nca[1], dx[i] * nca[0]));
        let pos = (s1[i] >= 0.0) & (s2[i] >= 0.0) & (s3[i] >= 0.0);
        let neg = (s1[i] <= 0.0) & (s2[i] <= 0.0) & (s3[i] <= 0.0);
        inside[i] = pos | neg;
        any |= inside[i];
    }
    if !any {
        return false;
    }
    let mut changed = false;
    for i in 0..TW {
        let den = dz[i].mul_add(n[2], dy[i].mul_add(n[1], dx[i] * n[0]));
        let tt = num / den;
        // Ties go to the lower triangle, so that the result does not depend on the order of
        // the tests (the triangle-order cast of `raster` gives the same hits).
        let h = inside[i] & (tt > 0.0) & ((tt < tmax[i]) | ((tt == tmax[i]) & (k < hit[i])));
        tmax[i] = if h { tt } else { tmax[i] };
        hit[i] = if h { k } else { hit[i] };
        changed |= h;
    }
    changed
}

/// Whether the CPU has AVX2 and FMA (the vector paths; every path gives the same results).
#[cfg(target_arch = "x86_64")]
#[inline]
pub(super) fn avx2_fma() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
}

/// A ray's bound `t_max` (mm) for the f32 tests: slightly beyond it, so that a hit just short
/// of it is decided in f64 afterwards; 0 (not cast) unless `t_max > 0`.
#[inline(always)]
pub(super) fn f32_bound(t_max: f64) -> f32 {
    if t_max > 0.0 {
        (t_max * (1.0 + 1e-5)) as f32
    } else {
        0.0
    }
}

/// Gnomonic-coordinate margin (tangent units) far above the f32 rounding of the tests.
const MARGIN: f32 = 1e-4;

struct Packet {
    tmax: [f32; LANES],
    hit: [u32; LANES],
}

impl Packet {
    #[inline(always)]
    fn max_t(&self) -> f32 {
        let mut m = [0.0f32; TW];
        for r in 0..TH {
            for i in 0..TW {
                m[i] = fmax(m[i], self.tmax[r * TW + i]);
            }
        }
        m.iter().fold(0.0f32, |a, &b| fmax(a, b))
    }
}

/// The rays of every tile of a frame, prepared once per camera and pose: f32 directions,
/// four planes through the camera centre that contain all rays of the tile (normals inwards)
/// and the tile's gnomonic frame (axis `axis`, in-plane `e0`, `e1`) with each row's y range.
#[derive(Debug, Clone)]
pub struct RayTiles {
    origin: [f32; 3],
    tiles: Vec<Tile>,
}

#[derive(Debug, Clone)]
struct Tile {
    pix: [u32; LANES],
    active: [bool; LANES],
    dx: [f32; LANES],
    dy: [f32; LANES],
    dz: [f32; LANES],
    valid: bool,
    planes: [[f32; 3]; 4],
    axis: [f32; 3],
    e0: [f32; 3],
    e1: [f32; 3],
    x_range: [f32; 2],
    row_lo: [f32; TH],
    row_hi: [f32; TH],
}

impl RayTiles {
    /// Splits the frame into tiles of 8 x 8 pixels.
    pub fn new(rays: &PixelRays) -> RayTiles {
        let (w, h) = (rays.width, rays.height);
        let mut tiles = Vec::with_capacity(w.div_ceil(TW) * h.div_ceil(TH));
        for ty in (0..h).step_by(TH) {
            for tx in (0..w).step_by(TW) {
                tiles.push(Tile::new(rays, tx, ty));
            }
        }
        RayTiles {
            origin: rays.origin_mm.map(|c| c as f32),
            tiles,
        }
    }
}

impl Tile {
    fn new(rays: &PixelRays, tx: usize, ty: usize) -> Tile {
        let (w, h) = (rays.width, rays.height);
        let mut t = Tile {
            pix: [NO_HIT; LANES],
            active: [false; LANES],
            dx: [0.0; LANES],
            dy: [0.0; LANES],
            dz: [0.0; LANES],
            valid: false,
            planes: [[0.0; 3]; 4],
            axis: [0.0; 3],
            e0: [0.0; 3],
            e1: [0.0; 3],
            x_range: [f32::NEG_INFINITY, f32::INFINITY],
            row_lo: [f32::NEG_INFINITY; TH],
            row_hi: [f32::INFINITY; TH],
        };
        let mut d64 = [[0.0f64; 3]; LANES];
        let mut s = [0.0f64; 3];
        // Mean directions of the first and last columns give the in-plane x axis.
        let (mut left, mut right) = ([0.0f64; 3], [0.0f64; 3]);
        for j in 0..TH {
            for i in 0..TW {
                let (x, y) = (tx + i, ty + j);
                let l = j * TW + i;
                if x >= w || y >= h {
                    continue;
                }
                let p = y * w + x;
                t.pix[l] = p as u32;
                let d = rays.dirs[p];
                if d.iter().all(|c| c.is_finite()) {
                    t.active[l] = true;
                    d64[l] = d;
                    t.dx[l] = d[0] as f32;
                    t.dy[l] = d[1] as f32;
                    t.dz[l] = d[2] as f32;
                    s = [s[0] + d[0], s[1] + d[1], s[2] + d[2]];
                    let wgt = i as f64 - (TW as f64 - 1.0) / 2.0;
                    if wgt < 0.0 {
                        left = [left[0] + d[0], left[1] + d[1], left[2] + d[2]];
                    } else {
                        right = [right[0] + d[0], right[1] + d[1], right[2] + d[2]];
                    }
                }
            }
        }
        let ls = dot(s, s).sqrt();
        if !(ls > 0.0) {
            return t;
        }
        let a = scale(s, 1.0 / ls);
        let mut ex = sub(right, left);
        ex = sub(ex, scale(a, dot(ex, a)));
        if !(dot(ex, ex) > 1e-24) {
            let helper = if a[0].abs() < 0.6 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 1.0, 0.0]
            };
            ex = cross(helper, a);
        }
        let e0 = normalize(ex);
        let e1 = cross(a, e0);
        let (mut xr, mut yr) = (
            [f64::INFINITY, f64::NEG_INFINITY],
            [[f64::INFINITY, f64::NEG_INFINITY]; TH],
        );
        for l in 0..LANES {
            if !t.active[l] {
                continue;
            }
            let d = d64[l];
            let da = dot(d, a);
            if !(da > 0.5) {
                return t;
            }
            let (x, y) = (dot(d, e0) / da, dot(d, e1) / da);
            xr = [xr[0].min(x), xr[1].max(x)];
            let r = l / TW;
            yr[r] = [yr[r][0].min(y), yr[r][1].max(y)];
        }
        let m = MARGIN as f64;
        let ylo = yr.iter().map(|r| r[0]).fold(f64::INFINITY, f64::min) - m;
        let yhi = yr.iter().map(|r| r[1]).fold(f64::NEG_INFINITY, f64::max) + m;
        let (xlo, xhi) = (xr[0] - m, xr[1] + m);
        let pl = |u: [f64; 3]| normalize(u).map(|c| c as f32);
        t.planes = [
            pl(sub(e0, scale(a, xlo))),
            pl(sub(scale(a, xhi), e0)),
            pl(sub(e1, scale(a, ylo))),
            pl(sub(scale(a, yhi), e1)),
        ];
        t.axis = a.map(|c| c as f32);
        t.e0 = e0.map(|c| c as f32);
        t.e1 = e1.map(|c| c as f32);
        t.x_range = [xlo as f32, xhi as f32];
        for r in 0..TH {
            // Rows without an active ray keep an empty range.
            (t.row_lo[r], t.row_hi[r]) = if yr[r][0] <= yr[r][1] {
                ((yr[r][0] - m) as f32, (yr[r][1] + m) as f32)
            } else {
                (f32::INFINITY, f32::NEG_INFINITY)
            };
        }
        t.valid = true;
        t
    }

    /// Whether a box may hold a hit of the tile (frustum planes only).
    fn overlaps(&self, lo: [f32; 3], hi: [f32; 3], o: [f32; 3]) -> bool {
        if !self.valid {
            return true;
        }
        self.planes.iter().all(|m| {
            let p = [
                if m[0] >= 0.0 { hi[0] } else { lo[0] } - o[0],
                if m[1] >= 0.0 { hi[1] } else { lo[1] } - o[1],
                if m[2] >= 0.0 { hi[2] } else { lo[2] } - o[2],
            ];
            dot32(*m, p) >= -1e-6
        })
    }

    /// The four children of a node: which may hold a hit nearer than sqrt(tmax2), and their
    /// squared distances from the camera centre.
    #[inline(always)]
    fn test4(&self, n: &Node4, o: [f32; 3], tmax2: f32) -> ([bool; 4], [f32; 4]) {
        let mut lo = [[0.0f32; 4]; 3];
        let mut hi = [[0.0f32; 4]; 3];
        let mut d2 = [0.0f32; 4];
        for c in 0..3 {
            for k in 0..4 {
                lo[c][k] = n.lo[c][k] - o[c];
                hi[c][k] = n.hi[c][k] - o[c];
                let e = fmax(lo[c][k], 0.0) + fmax(-hi[c][k], 0.0);
                d2[k] += e * e;
            }
        }
        let mut ok = [true; 4];
        for k in 0..4 {
            ok[k] = d2[k] <= tmax2 && n.lo[0][k] <= n.hi[0][k];
        }
        if self.valid {
            for m in &self.planes {
                let px = if m[0] >= 0.0 { &hi[0] } else { &lo[0] };
                let py = if m[1] >= 0.0 { &hi[1] } else { &lo[1] };
                let pz = if m[2] >= 0.0 { &hi[2] } else { &lo[2] };
                for k in 0..4 {
                    ok[k] &= m[0] * px[k] + m[1] * py[k] + m[2] * pz[k] >= -1e-6;
                }
            }
        }
        (ok, d2)
    }
}

fn box_dist2(lo: [f32; 3], hi: [f32; 3], o: [f32; 3]) -> f32 {
    let mut d2 = 0.0;
    for c in 0..3 {
        let e = (lo[c] - o[c]).max(0.0) + (o[c] - hi[c]).max(0.0);
        d2 += e * e;
    }
    d2
}

/// Collapses the binary hierarchy under `b` into 4-wide nodes; returns the new node's index.
fn collapse(bin: &[Node], b: usize, out: &mut Vec<Node4>) -> u32 {
    let me = out.len();
    out.push(Node4 {
        lo: [[f32::INFINITY; 4]; 3],
        hi: [[f32::NEG_INFINITY; 4]; 3],
        child: [EMPTY; 4],
        count: [0; 4],
    });
    let node = &bin[b];
    if node.meta & INTERNAL == 0 {
        // A leaf as the root: one child.
        let n4 = &mut out[me];
        for c in 0..3 {
            n4.lo[c][0] = node.min[c];
            n4.hi[c][0] = node.max[c];
        }
        n4.child[0] = node.link;
        n4.count[0] = node.meta;
        return me as u32;
    }
    // Open the largest internal child until there are four.
    let mut kids = vec![b + 1, node.link as usize];
    while kids.len() < 4 {
        let area = |i: usize| {
            let n = &bin[i];
            let e = [
                n.max[0] - n.min[0],
                n.max[1] - n.min[1],
                n.max[2] - n.min[2],
            ];
            e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
        };
        let pick = kids
            .iter()
            .enumerate()
            .filter(|(_, &i)| bin[i].meta & INTERNAL != 0)
            .max_by(|a, b| area(*a.1).total_cmp(&area(*b.1)))
            .map(|(k, _)| k);
        let Some(k) = pick else { break };
        let i = kids.remove(k);
        kids.insert(k, bin[i].link as usize);
        kids.insert(k, i + 1);
    }
    for (slot, &i) in kids.iter().enumerate() {
        let n = bin[i];
        let (child, count) = if n.meta & INTERNAL == 0 {
            (n.link, n.meta)
        } else {
            (collapse(bin, i, out), 0)
        };
        let n4 = &mut out[me];
        for c in 0..3 {
            n4.lo[c][slot] = n.min[c];
            n4.hi[c][slot] = n.max[c];
        }
        n4.child[slot] = child;
        n4.count[slot] = count;
    }
    me as u32
}

fn build(
    nodes: &mut Vec<Node>,
    order: &mut [u32],
    first: usize,
    bounds: &[Bounds],
    cent: &[[f64; 3]],
) -> usize {
    let me = nodes.len();
    let mut bb = Bounds::EMPTY;
    let mut cb = Bounds::EMPTY;
    for &i in order.iter() {
        bb.grow(&bounds[i as usize]);
        cb.grow_point(cent[i as usize]);
    }
    nodes.push(Node {
        min: bb.min.map(round_down),
        link: first as u32,
        max: bb.max.map(round_up),
        meta: order.len() as u32,
    });
    let n = order.len();
    if n <= 2 {
        return me;
    }
    // Binned SAH over the axis of largest centroid extent.
    let ext = [
        cb.max[0] - cb.min[0],
        cb.max[1] - cb.min[1],
        cb.max[2] - cb.min[2],
    ];
    let axis = if ext[0] >= ext[1] && ext[0] >= ext[2] {
        0
    } else if ext[1] >= ext[2] {
        1
    } else {
        2
    };
    let mut split = None;
    if ext[axis] > 0.0 {
        let scale_b = BINS as f64 / ext[axis];
        let bin_of = |i: u32| -> usize {
            (((cent[i as usize][axis] - cb.min[axis]) * scale_b) as usize).min(BINS - 1)
        };
        let mut bin_b = [Bounds::EMPTY; BINS];
        let mut bin_n = [0usize; BINS];
        for &i in order.iter() {
            let b = bin_of(i);
            bin_b[b].grow(&bounds[i as usize]);
            bin_n[b] += 1;
        }
        let mut right_area = [0.0; BINS];
        let mut right_n = [0usize; BINS];
        let (mut acc, mut cnt) = (Bounds::EMPTY, 0);
        for b in (1..BINS).rev() {
            acc.grow(&bin_b[b]);
            cnt += bin_n[b];
            right_area[b] = acc.area();
            right_n[b] = cnt;
        }
        let (mut acc, mut cnt) = (Bounds::EMPTY, 0);
        let mut best = (f64::INFINITY, 0);
        for b in 1..BINS {
            acc.grow(&bin_b[b - 1]);
            cnt += bin_n[b - 1];
            if cnt == 0 || right_n[b] == 0 {
                continue;
            }
            let cost = acc.area() * cnt as f64 + right_area[b] * right_n[b] as f64;
            if cost < best.0 {
                best = (cost, b);
            }
        }
        let leaf_cost = bb.area() * n as f64;
        // Traversal costs about one triangle test per child.
        if best.0.is_finite() && (n > MAX_LEAF || best.0 + bb.area() < leaf_cost) {
            let b = best.1;
            let mut l = 0;
            for k in 0..n {
                if bin_of(order[k]) < b {
                    order.swap(k, l);
                    l += 1;
                }
            }
            split = Some(l);
        }
    }
    let mid = match split {
        Some(l) => l,
        None if n > MAX_LEAF => {
            // All centroids in one bin: split by index (stable).
            n / 2
        }
        None => return me,
    };
    nodes[me].meta = INTERNAL | axis as u32;
    let (lo, hi) = order.split_at_mut(mid);
    build(nodes, lo, first, bounds, cent);
    let r = build(nodes, hi, first + mid, bounds, cent);
    nodes[me].link = r as u32;
    me
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}
/// max without NaN handling (vectorises; the operands are never NaN).
#[inline(always)]
fn fmax(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

#[inline(always)]
pub(super) fn sub32(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline(always)]
pub(super) fn dot32(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline(always)]
pub(super) fn cross32(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
