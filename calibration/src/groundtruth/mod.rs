//! Ground-truth depth for depth training: the reference (undeformed) surface and the surface
//! indented by each protrusion semi-dome, rendered through the calibrated camera with the exact
//! per-pixel ray of the camera model (no undistort approximation).
//!
//! Source: R-Tac0 paper (`shared/papers/rtac0-rounded-monochrome-vbts.txt`), Sec. IV-B and
//! Fig. 6: semi-domes with known protrusions pressed onto the sensor give depth maps "derived
//! using the known camera parameters and the protrusions geometry"; Eq. (2)-(3): the network
//! learns the differential depth (indented minus reference) per pixel, and the complete depth
//! is the reference surface depth plus that difference.
//!
//! Geometry: the reference surface is the outer skin surface (body profile at offset 0),
//! intersected in closed form ([`surface`]); the indented surface is the skin pushed in by the
//! protrusions, the boundary of (sensor body minus protrusion solids): along a ray, the nearer
//! of the reference exit and the first entry into a protrusion ([`exact`] in closed form, or
//! [`mesh`] for triangle meshes). Frames and units: `docs/conventions.md`.

pub mod budget;
pub mod dataset;
pub mod exact;
pub mod files;
pub mod hits;
pub mod inputs;
pub mod mesh;
pub mod pins;
pub mod press;
pub mod press_skin;
pub mod raster;
pub mod rays;
pub mod shading;
pub mod surface;
pub mod synthetic;

use exact::ExactPrimitives;
pub use hits::SurfaceHits;
use rays::PixelRays;
use surface::ReferenceSurface;

/// What the camera sees of a design's skin: its reference surface and the camera's per-pixel
/// rays in the sensor frame, with the camera centre checked to be inside the sensor body.
#[derive(Debug, Clone)]
pub struct Scene {
    pub surface: ReferenceSurface,
    pub rays: PixelRays,
}

impl Scene {
    /// The scene of `design` seen through `camera` at the pose `t_cam_sensor` (sensor frame ->
    /// camera frame, mm). `pose_name` names where the pose came from in errors (the
    /// extrinsics file).
    ///
    /// # Errors
    /// A message naming the body profile when it has no reference surface, or naming
    /// `pose_name`, the camera centre and the body when the centre is outside the sensor body
    /// (the camera must look at the skin from inside).
    pub fn new(
        design: &fabkit_designs::Design,
        camera: &crate::CameraModel,
        t_cam_sensor: &nalgebra::Isometry3<f64>,
        pose_name: &str,
    ) -> Result<Scene, String> {
        Scene::through(design, camera, t_cam_sensor, pose_name, None)
    }

    /// [`Scene::new`] with the rays bent at the interfaces of `layers`
    /// ([`PixelRays::through`]); `None`: straight rays.
    ///
    /// # Errors
    /// As [`Scene::new`], and when the camera centre is not under every plane of `layers`.
    pub fn through(
        design: &fabkit_designs::Design,
        camera: &crate::CameraModel,
        t_cam_sensor: &nalgebra::Isometry3<f64>,
        pose_name: &str,
        layers: Option<&crate::refraction::OpticalLayers>,
    ) -> Result<Scene, String> {
        let surface = ReferenceSurface::of_design(design).ok_or_else(|| {
            format!(
                "body.profile = {}: no reference surface for this profile",
                design.body.kind()
            )
        })?;
        let rays = match layers {
            None => PixelRays::new(camera, t_cam_sensor),
            Some(l) => PixelRays::through(camera, t_cam_sensor, l)
                .map_err(|e| format!("{pose_name}: {e}"))?,
        };
        let c = rays.origin_mm;
        if !surface.contains(c, 0.0) {
            let body = match surface {
                ReferenceSurface::Flat {
                    half_width_mm,
                    half_length_mm,
                    top_z_mm,
                    ..
                } => format!(
                    "the {} x {} mm skin's contact face z = {top_z_mm} mm and its edges, continued below the base plane",
                    2.0 * half_width_mm,
                    2.0 * half_length_mm,
                ),
                _ => format!(
                    "skin surface, continued below the base plane z = {} mm at radius {:.3} mm",
                    surface.base_z_mm(),
                    surface.rim_radius_mm()
                ),
            };
            return Err(format!(
                "{pose_name}: the camera centre [{:.3}, {:.3}, {:.3}] mm (sensor frame) is outside the sensor body of {} ({body}): the camera must look at the skin from inside (hint: check that T_cam_sensor maps sensor-frame points into the camera frame)",
                c[0], c[1], c[2], design.name
            ));
        }
        Ok(Scene { surface, rays })
    }

    /// Checks that the camera centre is inside none of the protrusions of `configurations`.
    ///
    /// # Errors
    /// A message naming `pose_name` and the first configuration (pattern and orientation)
    /// whose protrusion holds the camera centre.
    pub fn check_outside(
        &self,
        configurations: &[inputs::Configuration],
        pose_name: &str,
    ) -> Result<(), String> {
        let c = self.rays.origin_mm;
        match configurations.iter().find(|k| k.primitives.contains(c)) {
            Some(cfg) if !cfg.pins.is_empty() => Err(format!(
                "{pose_name}: the camera centre is inside a pin of capture {}",
                cfg.name
            )),
            Some(cfg) => Err(format!(
                "{pose_name}: the camera centre is inside a protrusion of {} at {} deg",
                cfg.pattern, cfg.orientation_deg
            )),
            None => Ok(()),
        }
    }
}

/// The reference (undeformed) surface along every ray, in closed form.
pub fn reference_hits(rays: &PixelRays, surface: &ReferenceSurface) -> SurfaceHits {
    let n = rays.len();
    let mut h = SurfaceHits {
        t_mm: vec![f64::NAN; n],
        normal: vec![[f64::NAN; 3]; n],
        contact: vec![false; n],
        t_exit_mm: vec![f64::NAN; n],
    };
    if rays.origins.is_some() {
        for p in 0..n {
            if let Some(e) = surface.exit(rays.origin(p), rays.dirs[p]) {
                h.t_exit_mm[p] = e.t_mm;
                if e.on_skin {
                    h.t_mm[p] = e.t_mm;
                    h.normal[p] = e.normal;
                }
            }
        }
        return h;
    }
    surface.exit_all(
        rays.origin_mm,
        &rays.dirs,
        &mut h.t_exit_mm,
        &mut h.t_mm,
        Some(&mut h.normal),
    );
    h
}

/// The indented surface: the reference pushed in by the exact protrusion primitives.
pub fn indented_hits(
    rays: &PixelRays,
    reference: &SurfaceHits,
    protrusions: &ExactPrimitives,
    base_z_mm: f64,
) -> SurfaceHits {
    let mut h = reference.clone();
    for (p, d) in rays.dirs.iter().enumerate() {
        let o = rays.origin(p);
        let tmax = reference.t_exit_mm[p];
        if !(tmax > 0.0) {
            continue;
        }
        if let Some(c) = protrusions.first_crossing(o, *d, tmax) {
            let z = o[2] + c.t_mm * d[2];
            if z >= base_z_mm {
                h.t_mm[p] = c.t_mm;
                h.normal[p] = c.normal.map(|v| -v);
                h.contact[p] = true;
            }
        }
    }
    h
}

/// Camera-frame depth maps of one rendered surface (row-major, H * W).
#[derive(Debug, Clone, PartialEq)]
pub struct DepthFrame {
    pub width: usize,
    pub height: usize,
    /// Distance from the camera centre to the surface along the ray, mm (for rays bent by an
    /// optical path, [`PixelRays::through`], the straight distance from the camera centre to
    /// the hit); NaN where the ray misses.
    pub range_mm: Vec<f64>,
    /// z of the hit in the camera frame, mm; NaN where the ray misses.
    pub zdepth_mm: Vec<f64>,
    /// Hit point in the camera frame, mm.
    pub point_cam_mm: Vec<[f64; 3]>,
    /// Unit normal out of the elastomer, camera frame.
    pub normal_cam: Vec<[f64; 3]>,
    /// The hit is on a protrusion.
    pub contact: Vec<bool>,
}

impl DepthFrame {
    /// The camera-frame maps of `hits`.
    pub fn new(rays: &PixelRays, hits: &SurfaceHits) -> DepthFrame {
        let n = rays.len();
        let mut f = DepthFrame {
            width: rays.width,
            height: rays.height,
            range_mm: hits.t_mm.clone(),
            zdepth_mm: vec![f64::NAN; n],
            point_cam_mm: vec![[f64::NAN; 3]; n],
            normal_cam: vec![[f64::NAN; 3]; n],
            contact: hits.contact.clone(),
        };
        for p in 0..n {
            let t = hits.t_mm[p];
            if !t.is_finite() {
                continue;
            }
            if rays.origins.is_some() {
                // bent rays: the hit from the ray's start in the last medium, in the camera
                // frame; the range is its distance from the camera centre
                let (o, d) = (rays.origin(p), rays.dirs[p]);
                let q = rays.to_camera([o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]]);
                f.range_mm[p] = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
                f.zdepth_mm[p] = q[2];
                f.point_cam_mm[p] = q;
            } else {
                let b = rays.bearings[p];
                f.zdepth_mm[p] = t * b[2];
                f.point_cam_mm[p] = [t * b[0], t * b[1], t * b[2]];
            }
            f.normal_cam[p] = rays.dir_to_camera(hits.normal[p]);
        }
        f
    }

    /// The contact mask of an indented frame: the pixels where a protrusion pushes the skin in
    /// (the surface seen is a protrusion) and the ray meets the `reference` surface.
    pub fn contact_mask(&self, reference: &DepthFrame) -> Vec<bool> {
        self.contact
            .iter()
            .zip(&reference.range_mm)
            .map(|(c, r)| *c && r.is_finite())
            .collect()
    }

    /// `self - reference` for range and z-depth (indented minus reference, Eq. (2)-(3) of the
    /// R-Tac0 paper), mm: negative where the skin is pushed towards the camera, 0 elsewhere,
    /// NaN where either misses.
    pub fn delta(&self, reference: &DepthFrame) -> (Vec<f64>, Vec<f64>) {
        let d = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x - y).collect();
        (
            d(&self.range_mm, &reference.range_mm),
            d(&self.zdepth_mm, &reference.zdepth_mm),
        )
    }
}

/// Left and right half masks: the split plane x = 0 of the sensor frame projected into the
/// image. A pixel whose ray hits the reference surface at x >= 0 is in the right mask (the +x
/// half, where orientation 0 puts the pattern), at x < 0 in the left mask; a miss is in
/// neither.
pub fn half_masks(rays: &PixelRays, reference: &SurfaceHits) -> (Vec<bool>, Vec<bool>) {
    let mut left = vec![false; rays.len()];
    let mut right = vec![false; rays.len()];
    for p in 0..rays.len() {
        let t = reference.t_mm[p];
        if t.is_finite() {
            let x = rays.origin(p)[0] + t * rays.dirs[p][0];
            if x >= 0.0 {
                right[p] = true;
            } else {
                left[p] = true;
            }
        }
    }
    (left, right)
}
