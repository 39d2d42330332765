//! Per-pixel rays of a calibrated camera at a pose: the exact bearing of every pixel centre
//! (no undistort approximation), expressed in the sensor frame.

use nalgebra::{Isometry3, Point3, Vector2, Vector3};
use rayon::prelude::*;

use crate::camera::CameraModel;

/// The rays of every pixel of one camera at one pose.
///
/// Pixel `(u, v)` (column, row; (0, 0) is the centre of the top-left pixel, OpenCV) is entry
/// `v * width + u`. Rays start at the camera centre; a pixel that does not unproject (outside
/// the lens's monotonic field) has NaN direction and bearing and never hits anything.
#[derive(Debug, Clone)]
pub struct PixelRays {
    pub width: usize,
    pub height: usize,
    /// `T_cam_sensor`: sensor-frame points (mm) into the camera frame (mm).
    pub t_cam_sensor: Isometry3<f64>,
    /// Camera centre in the sensor frame, mm.
    pub origin_mm: [f64; 3],
    /// Unit ray directions in the sensor frame, (H * W, 3).
    pub dirs: Vec<[f64; 3]>,
    /// Unit bearings in the camera frame, (H * W, 3): `zdepth_mm = range_mm * bearing[2]` for
    /// straight rays.
    pub bearings: Vec<[f64; 3]>,
    /// Rays bent by an optical path ([`PixelRays::through`]): each ray's start in the last
    /// medium (where it crosses the last plane), sensor frame, mm, (H * W, 3); `dirs` are then
    /// the directions there. `None`: every ray starts at the camera centre.
    pub origins: Option<Vec<[f64; 3]>>,
    /// Tiles for mesh casts, made on first use.
    tiles: std::sync::OnceLock<super::mesh::RayTiles>,
    /// Rays sorted by cube face and cell for casts in triangle order, made on first use.
    raster: std::sync::OnceLock<super::raster::RayRaster>,
}

impl PixelRays {
    /// Unprojects every pixel centre of `camera` (Newton iteration to 1e-15; see
    /// [`CameraModel::unproject`]) and turns the bearings into the sensor frame with
    /// `t_cam_sensor`. Rows are computed in parallel; the result does not depend on the
    /// thread count.
    pub fn new(camera: &CameraModel, t_cam_sensor: &Isometry3<f64>) -> PixelRays {
        let i = camera.intrinsics();
        let (w, h) = (i.image_width_px as usize, i.image_height_px as usize);
        let rot_inv = t_cam_sensor.rotation.inverse();
        let centre = t_cam_sensor.inverse() * Point3::origin();
        let rows: Vec<Vec<([f64; 3], [f64; 3])>> = (0..h)
            .into_par_iter()
            .map(|v| {
                (0..w)
                    .map(
                        |u| match camera.unproject(&Vector2::new(u as f64, v as f64)) {
                            Ok(b) => {
                                let d = rot_inv * b;
                                ([d.x, d.y, d.z], [b.x, b.y, b.z])
                            }
                            Err(_) => ([f64::NAN; 3], [f64::NAN; 3]),
                        },
                    )
                    .collect()
            })
            .collect();
        let (dirs, bearings) = rows.into_iter().flatten().unzip();
        PixelRays {
            width: w,
            height: h,
            t_cam_sensor: *t_cam_sensor,
            origin_mm: [centre.x, centre.y, centre.z],
            dirs,
            bearings,
            origins: None,
            tiles: std::sync::OnceLock::new(),
            raster: std::sync::OnceLock::new(),
        }
    }

    /// The rays of [`PixelRays::new`] bent at the interfaces of `layers` by Snell's law
    /// ([`crate::refraction`]): each ray is traced from the camera centre across the planes
    /// and out of the curved faces, and continues from the last in the last medium, where the
    /// skin is; `origins` holds those starts. A ray that runs away from the planes, is
    /// totally internally reflected, or is blocked at a core's open end or seat has NaN
    /// direction and never hits anything. The depth maps of these rays
    /// ([`super::DepthFrame::new`]) give the hit's camera-frame z and its distance from the
    /// camera centre. The mesh casts and the image rasteriser take straight rays only.
    ///
    /// # Errors
    /// A message when the camera centre is not below every plane (the model puts the camera
    /// in air under the layers).
    pub fn through(
        camera: &CameraModel,
        t_cam_sensor: &Isometry3<f64>,
        layers: &crate::refraction::OpticalLayers,
    ) -> Result<PixelRays, String> {
        let mut rays = PixelRays::new(camera, t_cam_sensor);
        if layers.planes_z_mm().is_empty() {
            return Ok(rays);
        }
        let c = Vector3::from(rays.origin_mm);
        if let Some(&low) = layers.planes_z_mm().first() {
            if !(c.z < low) {
                return Err(format!(
                    "the camera centre (z = {:.3} mm, sensor frame) is not below the optical path's lowest plane (z = {low:.3} mm): the camera must look up through the layers from the air under them",
                    c.z
                ));
            }
        }
        let bent: Vec<([f64; 3], [f64; 3])> = rays
            .dirs
            .par_iter()
            .map(|d| {
                let d = Vector3::from(*d);
                match layers.trace_beyond(&c, &d) {
                    Some((o, e)) if d.z > 0.0 => ([o.x, o.y, o.z], [e.x, e.y, e.z]),
                    _ => ([f64::NAN; 3], [f64::NAN; 3]),
                }
            })
            .collect();
        let (origins, dirs) = bent.into_iter().unzip();
        rays.dirs = dirs;
        rays.origins = Some(origins);
        Ok(rays)
    }

    /// Where ray `p` starts, sensor frame, mm: the camera centre, or for bent rays its start in
    /// the last medium.
    #[inline]
    pub fn origin(&self, p: usize) -> [f64; 3] {
        match &self.origins {
            Some(o) => o[p],
            None => self.origin_mm,
        }
    }

    /// The frame's tiles for [`super::mesh::MeshCaster::cast`] (made once, on first use: a
    /// per-camera cost like the unprojection).
    pub fn tiles(&self) -> &super::mesh::RayTiles {
        debug_assert!(self.origins.is_none(), "mesh casts take straight rays only");
        self.tiles.get_or_init(|| super::mesh::RayTiles::new(self))
    }

    /// The frame's rays by cube face and cell for casts in triangle order (made once, on first
    /// use; see [`super::raster`]).
    pub fn raster(&self) -> &super::raster::RayRaster {
        debug_assert!(
            self.origins.is_none(),
            "the rasteriser takes straight rays only"
        );
        self.raster
            .get_or_init(|| super::raster::RayRaster::new(self))
    }

    /// Number of pixels, `width * height`.
    pub fn len(&self) -> usize {
        self.dirs.len()
    }

    /// Whether the frame has no pixel.
    pub fn is_empty(&self) -> bool {
        self.dirs.is_empty()
    }

    /// A sensor-frame point as a camera-frame point, mm.
    pub fn to_camera(&self, p: [f64; 3]) -> [f64; 3] {
        let q = self.t_cam_sensor * Point3::new(p[0], p[1], p[2]);
        [q.x, q.y, q.z]
    }

    /// A sensor-frame direction as a camera-frame direction.
    pub fn dir_to_camera(&self, n: [f64; 3]) -> [f64; 3] {
        let q = self.t_cam_sensor.rotation * Vector3::new(n[0], n[1], n[2]);
        [q.x, q.y, q.z]
    }
}
