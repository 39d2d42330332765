//! Single-thread rays per CPU-second of the `obvhs` and `bvh` crates on fabkit's ground-truth
//! benchmark scene, for the ray caster's choice (docs/src/benchmarks.md). Not part of the workspace or CI.
//!
//! FABKIT_GT_KEEP=1 scripts/bench-groundtruth     # prints "scene files kept in DIR"
//! cargo run --release --manifest-path tests/bvh_eval/Cargo.toml -- DIR
//!
//! `bvh`'s `Ray::intersects_triangle` culls back faces, so it misses the skin seen from inside;
//! its time is traversal plus that test (a fair lower bound of what a correct test would cost).
use bvh::aabb::{Aabb, Bounded};
use bvh::bounding_hierarchy::BHShape;
use glam::{vec3a, Vec3A};
use nalgebra::{Point3, Vector3};
use obvhs::{cwbvh::builder::build_cwbvh_from_tris, ray::{Ray, RayHit}, triangle::Triangle, BvhBuildParams};
use std::time::Duration;

fn cpu() -> f64 {
    #[repr(C)] struct Ts { s: i64, n: i64 }
    extern "C" { fn clock_gettime(c: i32, t: *mut Ts) -> i32; }
    let mut t = Ts { s: 0, n: 0 };
    unsafe { clock_gettime(3, &mut t) };
    t.s as f64 + t.n as f64 * 1e-9
}
fn npy(p: &str) -> Vec<f32> {
    let b = std::fs::read(p).unwrap();
    let h = u16::from_le_bytes([b[8], b[9]]) as usize;
    b[10 + h..].chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
}
struct Tri { a: Point3<f32>, b: Point3<f32>, c: Point3<f32>, node: usize }
impl Bounded<f32, 3> for Tri {
    fn aabb(&self) -> Aabb<f32, 3> { Aabb::empty().grow(&self.a).grow(&self.b).grow(&self.c) }
}
impl BHShape<f32, 3> for Tri {
    fn set_bh_node_index(&mut self, i: usize) { self.node = i; }
    fn bh_node_index(&self) -> usize { self.node }
}
fn main() {
    let d = std::env::args().nth(1).unwrap();
    let v = npy(&format!("{d}/vertices.npy"));
    let t = npy(&format!("{d}/triangles.npy"));
    let r = npy(&format!("{d}/rays.npy"));
    let vert = |i: f32| { let i = i as usize * 3; [v[i], v[i + 1], v[i + 2]] };
    let tris: Vec<[[f32; 3]; 3]> = t.chunks_exact(3).map(|c| [vert(c[0]), vert(c[1]), vert(c[2])]).collect();
    let rays: Vec<[f32; 6]> = r.chunks_exact(6).map(|c| [c[0], c[1], c[2], c[3], c[4], c[5]]).collect();
    let n = rays.len();
    println!("{} triangles, {n} rays", tris.len());
    // obvhs
    let otris: Vec<Triangle> = tris.iter().map(|t| Triangle { v0: vec3a(t[0][0], t[0][1], t[0][2]), v1: vec3a(t[1][0], t[1][1], t[1][2]), v2: vec3a(t[2][0], t[2][1], t[2][2]) }).collect();
    for (name, params) in [("medium_build", BvhBuildParams::medium_build()), ("slow_build", BvhBuildParams::slow_build())] {
        let c0 = cpu();
        let bvh = build_cwbvh_from_tris(&otris, params, &mut Duration::default());
        let build = cpu() - c0;
        let mut best = f64::INFINITY;
        let mut hits = 0;
        for _ in 0..5 {
            let c0 = cpu();
            hits = 0;
            for q in &rays {
                if q[3] == 0.0 && q[4] == 0.0 && q[5] == 0.0 { continue; }
                let ray = Ray::new_inf(vec3a(q[0], q[1], q[2]), Vec3A::new(q[3], q[4], q[5]));
                let mut hit = RayHit::none();
                if bvh.ray_traverse(ray, &mut hit, |ray, id| otris[bvh.primitive_indices[id] as usize].intersect(ray)) { hits += 1; }
            }
            best = best.min(cpu() - c0);
        }
        println!("obvhs 0.4 CWBVH ({name}, build {:.0} ms): {:.1} ms, {:.2} M rays/CPU-s, {hits} hits", build * 1e3, best * 1e3, n as f64 / best / 1e6);
    }
    // bvh
    let mut btris: Vec<Tri> = tris.iter().map(|t| Tri { a: Point3::from(t[0]), b: Point3::from(t[1]), c: Point3::from(t[2]), node: 0 }).collect();
    let c0 = cpu();
    let bvh = bvh::bvh::Bvh::build(&mut btris);
    let build = cpu() - c0;
    let mut best = f64::INFINITY;
    let mut hits = 0;
    for _ in 0..3 {
        let c0 = cpu();
        hits = 0;
        for q in &rays {
            if q[3] == 0.0 && q[4] == 0.0 && q[5] == 0.0 { continue; }
            let ray = bvh::ray::Ray::new(Point3::new(q[0], q[1], q[2]), Vector3::new(q[3], q[4], q[5]));
            let mut t_best = f32::INFINITY;
            for s in bvh.traverse_iterator(&ray, &btris) {
                let i = ray.intersects_triangle(&s.a, &s.b, &s.c);
                if i.distance < t_best { t_best = i.distance; }
            }
            if t_best.is_finite() { hits += 1; }
        }
        best = best.min(cpu() - c0);
    }
    println!("bvh 0.13 (SAH, build {:.0} ms, all candidates tested): {:.1} ms, {:.2} M rays/CPU-s, {hits} hits", build * 1e3, best * 1e3, n as f64 / best / 1e6);
}
