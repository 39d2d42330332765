//! The ground-truth benchmark scene (issue 6), shared by the tests, the criterion bench and the
//! Open3D comparison: the R-Tac0 skin (hemisphere of 15.0 mm on a 6 mm cylinder, base plane
//! z = -6 mm), the R-Tac0-like Kannala-Brandt camera of [`crate::synthetic::benchmark_camera`]
//! (f = 215 px, 640 x 480, 160 deg field) on the sensor axis 10 mm below the sphere centre
//! looking along +z (`T_cam_sensor = [I | (0, 0, 10) mm]`), and six protrusions of every
//! primitive kind pressed 0.3-0.9 mm into the skin around the dome.

use fabkit_designs::geometry::{ChordTolerance, GeometryError, Mesh};
use fabkit_designs::primitives::{add, cross, scale, unit, Primitive};
use fabkit_designs::profile::BodyProfile;
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

use super::exact::ExactPrimitives;
use super::mesh::{Hit, MeshCaster};
use super::rays::PixelRays;
use super::surface::ReferenceSurface;

/// R-Tac0's reference radius, mm: the outer casting mold's cavity (authors' CAD, measured;
/// `body.radius_mm` of designs/library/rtac0.yaml).
pub const RTAC0_RADIUS_MM: f64 = 15.0;

/// R-Tac0's body profile (designs/library/rtac0.yaml).
pub fn rtac0_body() -> BodyProfile {
    BodyProfile::HemisphereOnCylinder {
        radius_mm: RTAC0_RADIUS_MM,
        cylinder_length_mm: 6.0,
    }
}

/// The benchmark pose: camera on the axis at z = -10 mm (sensor frame) looking along +z.
pub fn benchmark_pose() -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(0.0, 0.0, 10.0),
        UnitQuaternion::identity(),
    )
}

/// The point and outward normal of the R-Tac0 sphere at polar / azimuth angles (deg).
fn surface_point(polar_deg: f64, azimuth_deg: f64) -> ([f64; 3], [f64; 3]) {
    let (p, a) = (polar_deg.to_radians(), azimuth_deg.to_radians());
    let n = [p.sin() * a.cos(), p.sin() * a.sin(), p.cos()];
    (scale(n, RTAC0_RADIUS_MM), n)
}

/// Six protrusions (sensor frame, mm), indentation depths 0.3 to 0.9 mm.
pub fn benchmark_protrusions() -> Vec<Primitive> {
    let at = |polar: f64, az: f64, off: f64| {
        let (c, n) = surface_point(polar, az);
        (add(c, scale(n, off)), n)
    };
    let mut v = Vec::new();
    // A 2.5 mm sphere, 0.8 mm deep, near the pole.
    let (c, _) = at(12.0, 30.0, 2.5 - 0.8);
    v.push(Primitive::Sphere {
        centre_mm: c,
        radius_mm: 2.5,
    });
    // A 1.2 mm cylinder, 0.5 mm deep.
    let (b, n) = at(35.0, 150.0, -0.5);
    v.push(Primitive::Cylinder {
        base_mm: b,
        top_mm: add(b, scale(n, 3.0)),
        radius_mm: 1.2,
    });
    // A cone, apex 0.9 mm deep.
    let (apex, n) = at(40.0, 260.0, -0.9);
    v.push(Primitive::Cone {
        apex_mm: apex,
        base_mm: add(apex, scale(n, 3.0)),
        base_radius_mm: 1.8,
    });
    // A ridge: capsule of radius 0.6 mm, 5 mm long, 0.4 mm deep, along the meridian.
    let (m, n) = at(55.0, 330.0, 0.6 - 0.4);
    let t = unit(cross(n, [0.0, 0.0, 1.0]));
    let t = unit(cross(t, n));
    v.push(Primitive::Capsule {
        p0_mm: add(m, scale(t, -2.5)),
        p1_mm: add(m, scale(t, 2.5)),
        radius_mm: 0.6,
    });
    // A box, 0.3 mm deep.
    let (c, n) = at(50.0, 80.0, 1.0 - 0.3);
    let e1 = unit(cross(n, [0.0, 0.0, 1.0]));
    let e2 = cross(n, e1);
    v.push(Primitive::Box {
        centre_mm: c,
        axes: [e1, e2, n],
        half_extents_mm: [1.5, 0.8, 1.0],
    });
    // A second sphere on the cylinder wall region, 0.6 mm deep.
    let (c, _) = at(75.0, 200.0, 1.5 - 0.6);
    v.push(Primitive::Sphere {
        centre_mm: c,
        radius_mm: 1.5,
    });
    v
}

/// The outer skin surface of `body` (offset 0, from the pole to the base plane) as an open
/// triangle mesh within `tol`: half of it for the profile (`BodyProfile::offset_polyline`),
/// half for the circumference (the segment count of `fabkit_designs::geometry::revolve`); every vertex on
/// the true surface, triangles wound counter-clockwise seen from outside.
pub fn skin_mesh(body: &BodyProfile, tol: ChordTolerance) -> Mesh {
    let pl = body.offset_polyline(0.0, 0.0, tol.half());
    let mut pts = pl.points;
    pts.dedup();
    let r_max = pts.iter().map(|p| p[0]).fold(0.0, f64::max);
    let n = tol.half().circle_segments(r_max);
    let mut vertices = Vec::new();
    let mut first = Vec::new();
    for p in &pts {
        first.push(vertices.len() as u32);
        if p[0] == 0.0 {
            vertices.push([0.0, 0.0, p[1]]);
        } else {
            for j in 0..n {
                let (s, c) = (2.0 * std::f64::consts::PI * j as f64 / n as f64).sin_cos();
                vertices.push([p[0] * c, p[0] * s, p[1]]);
            }
        }
    }
    let idx = |k: usize, j: usize| -> u32 {
        if pts[k][0] == 0.0 {
            first[k]
        } else {
            first[k] + (j % n) as u32
        }
    };
    let mut triangles = Vec::new();
    for k in 0..pts.len() - 1 {
        let (a_axis, b_axis) = (pts[k][0] == 0.0, pts[k + 1][0] == 0.0);
        for j in 0..n {
            // Profile runs from the pole down: ring k is above ring k + 1.
            let (p0, p1, q0, q1) = (idx(k, j), idx(k, j + 1), idx(k + 1, j), idx(k + 1, j + 1));
            if a_axis {
                triangles.push([p0, q0, q1]);
            } else if b_axis {
                triangles.push([p0, q0, p1]);
            } else {
                triangles.push([p0, q0, q1]);
                triangles.push([p0, q1, p1]);
            }
        }
    }
    Mesh {
        vertices,
        triangles,
    }
}

/// The protrusion primitives as one mesh (each primitive closed, outward winding, not joined).
///
/// # Errors
/// A kernel failure or an invalid primitive.
pub fn primitives_mesh(prims: &[Primitive], tol: ChordTolerance) -> Result<Mesh, GeometryError> {
    let mut m = Mesh {
        vertices: Vec::new(),
        triangles: Vec::new(),
    };
    for p in prims {
        let q = p.solid(tol)?.mesh();
        let base = m.vertices.len() as u32;
        m.vertices.extend(q.vertices);
        m.triangles
            .extend(q.triangles.iter().map(|t| t.map(|i| i + base)));
    }
    Ok(m)
}

/// Everything of the benchmark scene.
pub struct BenchScene {
    pub rays: PixelRays,
    pub surface: ReferenceSurface,
    pub primitives: Vec<Primitive>,
    pub exact: ExactPrimitives,
    /// The skin surface (open at the base plane), within the chord tolerance.
    pub body_mesh: Mesh,
    pub protrusion_mesh: Mesh,
    pub chord_tolerance_mm: f64,
}

impl BenchScene {
    /// The scene at chord tolerance `tol_mm` (0.00085 mm gives about 200k triangles).
    ///
    /// # Panics
    /// On an invalid tolerance (benchmark code).
    pub fn new(tol_mm: f64) -> BenchScene {
        let tol = ChordTolerance::new(tol_mm).expect("valid tolerance");
        let body = rtac0_body();
        let primitives = benchmark_protrusions();
        BenchScene {
            rays: PixelRays::new(&crate::synthetic::benchmark_camera(), &benchmark_pose()),
            surface: ReferenceSurface::of(&body).expect("R-Tac0's body is curved"),
            exact: ExactPrimitives::new(&primitives).expect("valid primitives"),
            body_mesh: skin_mesh(&body, tol),
            protrusion_mesh: primitives_mesh(&primitives, tol).expect("protrusion mesh"),
            primitives,
            chord_tolerance_mm: tol_mm,
        }
    }

    /// Body and protrusions in one mesh (body triangles first).
    pub fn combined_mesh(&self) -> Mesh {
        let mut m = self.body_mesh.clone();
        let base = m.vertices.len() as u32;
        m.vertices
            .extend(self.protrusion_mesh.vertices.iter().copied());
        m.triangles.extend(
            self.protrusion_mesh
                .triangles
                .iter()
                .map(|t| t.map(|i| i + base)),
        );
        m
    }

    /// Casters for the combined mesh and the protrusions alone.
    pub fn casters(&self) -> (MeshCaster, MeshCaster) {
        (
            MeshCaster::new(&self.combined_mesh()),
            MeshCaster::new(&self.protrusion_mesh),
        )
    }
}

/// Reusable buffers of [`BenchScene::protrusion_frame`] (one per thread).
#[derive(Debug, Default)]
pub struct FrameScratch {
    t_max_mm: Vec<f64>,
    dirs: Vec<[f64; 3]>,
    t_exit_mm: Vec<f64>,
    t_skin_mm: Vec<f64>,
}

impl BenchScene {
    /// One frame of the fast path of issue 6 ("the reference surface intersected analytically
    /// and only rays that can reach a protrusion's bounds cast against triangles"): the pixels
    /// whose rays can reach the protrusions' boxes ([`MeshCaster::reachable_pixels`] of
    /// `prot`), the skin intersected in closed form for those rays, and those rays cast against
    /// the protrusion triangles up to their skin exit. Every other pixel keeps the reference
    /// depth, which depends on the camera alone and is rendered once. `hits` receives the
    /// protrusion hits in tile order; returns the number of rays cast.
    pub fn protrusion_frame(
        &self,
        prot: &MeshCaster,
        s: &mut FrameScratch,
        hits: &mut Vec<Hit>,
    ) -> usize {
        let rays = &self.rays;
        s.t_max_mm.resize(rays.len(), 0.0);
        let px = prot.reachable_pixels(rays);
        s.dirs.clear();
        s.dirs.extend(px.iter().map(|&p| rays.dirs[p as usize]));
        s.t_exit_mm.resize(px.len(), 0.0);
        s.t_skin_mm.resize(px.len(), 0.0);
        self.surface.exit_all(
            rays.origin_mm,
            &s.dirs,
            &mut s.t_exit_mm,
            &mut s.t_skin_mm,
            None,
        );
        for (&p, &t) in px.iter().zip(&s.t_exit_mm) {
            s.t_max_mm[p as usize] = if t.is_finite() { t } else { 0.0 };
        }
        hits.clear();
        prot.cast_each(rays, &s.t_max_mm, &mut |h| hits.push(h));
        for &p in &px {
            s.t_max_mm[p as usize] = 0.0;
        }
        px.len()
    }

    /// The same frame with the skin intersected for every pixel and every ray handed to the
    /// cast (which skips the tiles that miss the protrusions' box): the per-frame cost when
    /// the reference is not kept. Fills `t_max_mm` (the skin exits, 0 where none).
    pub fn protrusion_frame_all_rays(
        &self,
        prot: &MeshCaster,
        s: &mut FrameScratch,
        hits: &mut Vec<Hit>,
    ) {
        let rays = &self.rays;
        let n = rays.len();
        s.t_max_mm.resize(n, 0.0);
        s.t_skin_mm.resize(n, 0.0);
        self.surface.exit_all(
            rays.origin_mm,
            &rays.dirs,
            &mut s.t_max_mm,
            &mut s.t_skin_mm,
            None,
        );
        for t in s.t_max_mm.iter_mut() {
            if !t.is_finite() {
                *t = 0.0;
            }
        }
        hits.clear();
        prot.cast_each(rays, &s.t_max_mm, &mut |h| hits.push(h));
        s.t_max_mm.iter_mut().for_each(|t| *t = 0.0);
    }
}

/// CPU time consumed by the calling thread, seconds (Linux `CLOCK_THREAD_CPUTIME_ID`; wall
/// time elsewhere). Benchmarks report CPU time because the machine is shared.
pub fn thread_cpu_time_s() -> f64 {
    #[cfg(target_os = "linux")]
    {
        #[repr(C)]
        struct Timespec {
            tv_sec: i64,
            tv_nsec: i64,
        }
        extern "C" {
            fn clock_gettime(clk: i32, tp: *mut Timespec) -> i32;
        }
        const CLOCK_THREAD_CPUTIME_ID: i32 = 3;
        let mut ts = Timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: clock_gettime writes one timespec into the valid pointer.
        if unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut ts) } == 0 {
            return ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9;
        }
    }
    use std::sync::OnceLock;
    static START: OnceLock<std::time::Instant> = OnceLock::new();
    START
        .get_or_init(std::time::Instant::now)
        .elapsed()
        .as_secs_f64()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reachable-pixel cull loses no hit: both frames report the same hits, and the cull
    /// keeps fewer rays than the frame has.
    #[test]
    fn protrusion_frame_equals_the_all_rays_frame() {
        let scene = BenchScene::new(0.004);
        let prot = MeshCaster::new(&scene.protrusion_mesh);
        let mut s = FrameScratch::default();
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let cast = scene.protrusion_frame(&prot, &mut s, &mut a);
        scene.protrusion_frame_all_rays(&prot, &mut s, &mut b);
        assert!(!b.is_empty());
        assert_eq!(a, b);
        assert!(cast < scene.rays.len(), "{cast} of {}", scene.rays.len());
        assert!(s.t_max_mm.iter().all(|&t| t == 0.0));
    }
}
