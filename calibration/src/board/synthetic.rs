//! Synthetic board presses for the tests: the reference and the capture of a flat skin with
//! the board ([`super::BoardGrid`]) pressed in, as 8-bit RGB images, with each bump's true
//! centre in the image.
//!
//! What is rendered, per pixel (u, v) and channel c:
//!
//! - the skin's light `L_c(u, v) = skin_rgb_c (1 - (1 - corner_light_c) rho^2)`, `rho` the
//!   distance from the image's centre over its half-diagonal: brighter at the centre, dimmer
//!   at the corners, each channel by its own amount (a tinted, not grey, image);
//! - the capture's imprints: the pixel's ray ([`CameraModel::unproject`]) meets the plane
//!   `z = plane_z_mm` (sensor frame) at (x, y); there the indentation depth of a rigid sphere
//!   of the bump's radius `R` pressed `depth` into the skin is
//!   `d = max(0, depth - (R - sqrt(R^2 - s^2)))`, `s` the distance from the bump's point;
//!   the light is darkened by the fraction `k(rho) d`, `k(rho) = darkening_per_mm (1 - (1 -
//!   corner_contrast) rho^2)`: proportional to the depth and to the light (a shading, not a
//!   stain), a little weaker towards the corners;
//! - dark specks (dust) in the capture only, each a disc darkening the light by a fraction;
//! - the capture's global gain over the reference's (auto exposure, the LEDs' supply);
//! - both images blurred by a Gaussian point-spread function (the skin lies out of focus),
//!   then Gaussian noise per channel from a ChaCha8 stream of the seed, rounded and clamped
//!   to 0..255: the same inputs give the same bytes.
//!
//! The true centre of a bump ([`RenderedBoard::centres_px`]) is the projection of its point
//! `(x, y, plane_z_mm)`: the imprint's deepest point on the plane. Under the lens's distortion
//! and the light's fall-off an imprint's image is not symmetric about it, so the centroid a
//! detector takes sits a little off it, by up to 0.2 px for 9DTact's board seen as 9DTact's
//! camera sees it: [`RenderedBoard::centroids_px`] gives those centroids (noise-free), what
//! a detector that takes centroids can at best reach.
//!
//! What real captures (9DTact's `camera_calibration/{ref,sample}.png`) show that this lacks:
//! the gel's elastic spreading around each bump (the skin pulled in beyond the contact, a
//! faint skirt that joins neighbouring imprints; here each imprint ends at its contact), the
//! shading's lateral asymmetry (light from the LEDs at the rim makes an imprint's outer slope
//! darker than its inner one, moving its shading off the bump's point), LED highlights and
//! their flicker, the bumps' print (unequal heights and radii, so unequal imprints), the
//! board's tilt against the skin (every bump here is pressed to one depth), the skin's
//! texture, a colour noise correlated across channels (a Bayer sensor's demosaicing) and
//! compression artefacts. The imprints' shape on the plane ignores the refraction between the
//! lens and the plane (straight rays, as [`super::solve_board_camera`] models them).
//!
//! Pixels whose ray does not unproject (beyond the distortion's monotonic range) or misses
//! the plane show the skin's light without imprints.

use super::BoardGrid;
use crate::camera::CameraModel;
use crate::imprints::{gaussian_blur, GrayImage};
use nalgebra::{Isometry3, Point3, Vector2};
use rand_chacha::rand_core::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// How a synthetic board press looks: light, imprints' contrast, blur, noise and seed.
#[derive(Debug, Clone, PartialEq)]
pub struct BoardShading {
    /// The skin's RGB at the image's centre in the reference, grey levels (0..255).
    pub skin_rgb: [f32; 3],
    /// Each channel's light at the image's corners over its light at the centre (the light
    /// falls with the square of the distance from the centre), in (0, 1].
    pub corner_light: [f32; 3],
    /// The fraction of the light an imprint takes per mm of indentation depth at the image's
    /// centre, per mm.
    pub darkening_per_mm: f32,
    /// The imprints' contrast at the image's corners over their contrast at the centre, on
    /// top of the light's fall-off, in (0, 1].
    pub corner_contrast: f32,
    /// Sigma of the Gaussian point-spread function, px.
    pub psf_sigma_px: f64,
    /// Sigma of the noise of each channel, independent across channels, grey levels (the
    /// grey the calibration reads, Rec. 709 luma, has 0.75 of it).
    pub noise_sigma: f64,
    /// The capture's light over the reference's.
    pub capture_gain: f32,
    /// Seed of the noise.
    pub seed: u64,
}

impl Default for BoardShading {
    /// Like 9DTact's board press (`tests/data/9dtact_sensor1/camera_calibration`, measured
    /// there): a bluish skin of (165, 173, 173) at the centre and about 83 % of it at the
    /// corners, a little less in blue; imprints darkest at about 17 grey levels at the centre
    /// (a 0.6 mm bump pressed 0.5 mm, seen at 19 px per mm), out of focus (sigma 5 px);
    /// the capture 3 % brighter than the reference. The noise, 2 grey levels per channel
    /// (1.5 on the grey the calibration reads), is about twice the real one (0.75 on the
    /// channels' mean, 0.7 to 1.05 per channel, from the difference of the two images on
    /// flat skin over sqrt(2)).
    fn default() -> Self {
        Self {
            skin_rgb: [165.0, 173.0, 173.0],
            corner_light: [0.84, 0.83, 0.82],
            darkening_per_mm: 0.27,
            corner_contrast: 0.85,
            psf_sigma_px: 5.0,
            noise_sigma: 2.0,
            capture_gain: 1.03,
            seed: 0,
        }
    }
}

/// A dark speck on the skin that only the capture shows (dust, a fibre): a disc of
/// `radius_px` about (`u_px`, `v_px`) that takes the fraction `darkening` of the light
/// (blurred by the point-spread function like the rest).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Speck {
    pub u_px: f64,
    pub v_px: f64,
    pub radius_px: f64,
    pub darkening: f32,
}

/// The press: every bump of the grid is a sphere of `bump_radius_mm` pressed `depth_mm` into
/// the skin along -z, but those of `unpressed` (ids of the grid; a broken bump, one off the
/// skin); and the capture's `specks`.
///
/// ASSUMPTION: only the bumps touch the skin (`depth_mm` below the bumps' height over the
/// board's plate).
#[derive(Debug, Clone, PartialEq)]
pub struct BoardPress {
    pub bump_radius_mm: f64,
    pub depth_mm: f64,
    pub unpressed: Vec<String>,
    pub specks: Vec<Speck>,
}

/// A rendered board press.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderedBoard {
    pub width: usize,
    pub height: usize,
    /// The reference (no contact) and the capture (the board pressed in), RGB, row-major,
    /// `(v * width + u) * 3 + c`.
    pub reference_rgb: Vec<u8>,
    pub capture_rgb: Vec<u8>,
    /// Each bump's id and true centre, px (the projection of its point on the plane; `None`
    /// where it does not project), in the grid's order, pressed or not.
    pub centres_px: Vec<(String, Option<[f64; 2]>)>,
    /// Each bump's id and the centroid of its imprint's darkening of the grey in the image
    /// (noise-free; the point-spread function does not move a centroid), px: what a detector
    /// that takes centroids aims at; `None` for a bump that does not press or is not seen.
    /// It lies off [`Self::centres_px`] where the image's scale changes across the imprint
    /// (the distortion enlarges its outer side) and where the light does.
    pub centroids_px: Vec<(String, Option<[f64; 2]>)>,
}

impl RenderedBoard {
    /// The reference as the calibration reads it ([`crate::capture_images::read_gray`]).
    pub fn reference_gray(&self) -> GrayImage {
        gray_of_rgb8(&self.reference_rgb, self.width, self.height)
    }

    /// The capture as the calibration reads it ([`crate::capture_images::read_gray`]).
    pub fn capture_gray(&self) -> GrayImage {
        gray_of_rgb8(&self.capture_rgb, self.width, self.height)
    }

    /// The true centre of the bump `id`, px ([`Self::centres_px`]).
    pub fn centre_of(&self, id: &str) -> Option<[f64; 2]> {
        find_id(&self.centres_px, id)
    }

    /// The centroid of the imprint of the bump `id`, px ([`Self::centroids_px`]).
    pub fn centroid_of(&self, id: &str) -> Option<[f64; 2]> {
        find_id(&self.centroids_px, id)
    }
}

fn find_id(v: &[(String, Option<[f64; 2]>)], id: &str) -> Option<[f64; 2]> {
    v.iter().find(|(i, _)| i == id).and_then(|(_, c)| *c)
}

/// `rgb` (8-bit RGB, `width` x `height`) as [`crate::capture_images::read_gray`] reads an
/// 8-bit colour image: the image crate's luma (Rec. 709 weights, 0.2126 R + 0.7152 G +
/// 0.0722 B, at 16 bits) over 257, grey levels 0..255.
fn gray_of_rgb8(rgb: &[u8], width: usize, height: usize) -> GrayImage {
    let img = image::RgbImage::from_raw(width as u32, height as u32, rgb.to_vec())
        .expect("a rendered image holds width x height RGB pixels");
    let luma = image::DynamicImage::ImageRgb8(img).into_luma16();
    GrayImage {
        width,
        height,
        data: luma.as_raw().iter().map(|&g| g as f32 / 257.0).collect(),
    }
}

/// Uniform in [0, 1).
fn unit(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// A standard normal draw (Box-Muller).
fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let (a, b) = (unit(rng).max(1e-300), unit(rng));
    (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
}

/// The indentation depth of a rigid sphere of radius `r` pressed `depth` into a flat skin at
/// `s` from its axis, mm (0 outside the contact, of radius `sqrt(2 r depth - depth^2)`).
fn sphere_depth(r: f64, depth: f64, s: f64) -> f64 {
    if s >= r {
        return 0.0;
    }
    (depth - (r - (r * r - s * s).sqrt())).max(0.0)
}

/// Rec. 709 luma weights of R, G and B: the grey the calibration reads
/// ([`crate::capture_images::read_gray`], through the image crate).
const LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// Renders the reference and the capture of the board `grid` pressed as `press` says, seen by
/// `camera` at `t_cam_sensor` (sensor-frame mm into the camera frame), shaded as `shading`
/// says. The image's size is the camera's.
pub fn render_board(
    camera: &CameraModel,
    t_cam_sensor: &Isometry3<f64>,
    grid: &BoardGrid,
    press: &BoardPress,
    shading: &BoardShading,
) -> RenderedBoard {
    let intr = camera.intrinsics();
    let (w, h) = (intr.image_width_px as usize, intr.image_height_px as usize);
    let (cu, cv) = (0.5 * (w as f64 - 1.0), 0.5 * (h as f64 - 1.0));
    let half_diagonal2 = (cu * cu + cv * cv).max(1e-18);
    let rho2 =
        |p: usize| (((p % w) as f64 - cu).powi(2) + ((p / w) as f64 - cv).powi(2)) / half_diagonal2;
    let light = |c: usize, p: usize| {
        shading.skin_rgb[c] * (1.0 - (1.0 - shading.corner_light[c]) * rho2(p) as f32)
    };
    let (depth, owner) = indentation_depths(camera, t_cam_sensor, grid, press);
    // the fraction of the light the capture keeps, before the blur, and each imprint's
    // darkening of the grey summed over its pixels (weight, u, v)
    let mut kept = vec![1f32; w * h];
    let mut sums = vec![[0f64; 3]; grid.points.len()];
    for p in 0..w * h {
        let contrast =
            shading.darkening_per_mm * (1.0 - (1.0 - shading.corner_contrast) * rho2(p) as f32);
        let taken = (contrast * depth[p]).min(1.0);
        kept[p] = 1.0 - taken;
        if let Some(i) = owner[p] {
            let grey: f32 = (0..3).map(|c| LUMA[c] * light(c, p)).sum();
            let x = f64::from(grey * taken);
            sums[i][0] += x;
            sums[i][1] += x * (p % w) as f64;
            sums[i][2] += x * (p / w) as f64;
        }
    }
    for s in &press.specks {
        let r = s.radius_px.ceil() as i64 + 1;
        let (u0, v0) = (s.u_px.round() as i64, s.v_px.round() as i64);
        for v in (v0 - r).max(0)..=(v0 + r).min(h as i64 - 1) {
            for u in (u0 - r).max(0)..=(u0 + r).min(w as i64 - 1) {
                if (u as f64 - s.u_px).hypot(v as f64 - s.v_px) <= s.radius_px {
                    kept[v as usize * w + u as usize] *= 1.0 - s.darkening;
                }
            }
        }
    }
    let blur = |data: Vec<f32>| {
        gaussian_blur(
            &GrayImage {
                width: w,
                height: h,
                data,
            },
            shading.psf_sigma_px,
        )
        .data
    };
    let mut rng = ChaCha8Rng::seed_from_u64(shading.seed);
    let (mut reference_rgb, mut capture_rgb) = (vec![0u8; w * h * 3], vec![0u8; w * h * 3]);
    for c in 0..3 {
        let lit: Vec<f32> = (0..w * h).map(|p| light(c, p)).collect();
        let pressed: Vec<f32> = lit
            .iter()
            .zip(&kept)
            .map(|(l, k)| shading.capture_gain * l * k)
            .collect();
        for (img, out) in [(lit, &mut reference_rgb), (pressed, &mut capture_rgb)] {
            for (p, g) in blur(img).into_iter().enumerate() {
                let noisy = f64::from(g) + shading.noise_sigma * normal(&mut rng);
                out[p * 3 + c] = noisy.round().clamp(0.0, 255.0) as u8;
            }
        }
    }
    let centres_px = grid
        .points
        .iter()
        .map(|g| {
            let at = camera
                .project(&(t_cam_sensor * Point3::from(g.point_mm)).coords)
                .map(|q: Vector2<f64>| [q.x, q.y]);
            (g.id.clone(), at)
        })
        .collect();
    let centroids_px = grid
        .points
        .iter()
        .zip(&sums)
        .map(|(g, s)| {
            (
                g.id.clone(),
                (s[0] > 0.0).then(|| [s[1] / s[0], s[2] / s[0]]),
            )
        })
        .collect();
    RenderedBoard {
        width: w,
        height: h,
        reference_rgb,
        capture_rgb,
        centres_px,
        centroids_px,
    }
}

/// The indentation depth of the pressed bumps where each pixel's ray meets the plane
/// `z = grid.plane_z_mm`, mm, and the index (in `grid.points`) of the bump that presses there,
/// row-major (depth 0 and no bump off every contact, and where the ray does not unproject or
/// misses the plane). Where two contacts overlap the deeper counts (the board is rigid).
fn indentation_depths(
    camera: &CameraModel,
    t_cam_sensor: &Isometry3<f64>,
    grid: &BoardGrid,
    press: &BoardPress,
) -> (Vec<f32>, Vec<Option<usize>>) {
    let intr = camera.intrinsics();
    let (w, h) = (intr.image_width_px as usize, intr.image_height_px as usize);
    let (cols, rows) = (grid.columns as usize, grid.rows as usize);
    // the pressed bumps (index, x, y) by grid place
    let mut bump: Vec<Option<(usize, f64, f64)>> = vec![None; rows * cols];
    for (i, g) in grid.points.iter().enumerate() {
        if !press.unpressed.contains(&g.id) {
            bump[g.row as usize * cols + g.column as usize] = Some((i, g.point_mm.x, g.point_mm.y));
        }
    }
    let first = grid
        .at(0, 0)
        .map_or((0.0, 0.0), |g| (g.point_mm.x, g.point_mm.y));
    let pitch = grid.pitch_mm;
    // how many places either side a contact can reach
    let reach = (press.bump_radius_mm / pitch).ceil() as i64;
    let sensor_cam = t_cam_sensor.inverse();
    let (mut depth, mut owner) = (vec![0f32; w * h], vec![None; w * h]);
    for v in 0..h {
        for u in 0..w {
            let px = Vector2::new(u as f64, v as f64);
            let Some(p) = super::pixel_on_plane(camera, &sensor_cam, grid.plane_z_mm, px) else {
                continue;
            };
            let (x, y) = (p.x, p.y);
            let (c0, r0) = (
                ((x - first.0) / pitch).round() as i64,
                ((y - first.1) / pitch).round() as i64,
            );
            let mut deepest = (0f64, None);
            for r in (r0 - reach).max(0)..=(r0 + reach).min(rows as i64 - 1) {
                for c in (c0 - reach).max(0)..=(c0 + reach).min(cols as i64 - 1) {
                    if let Some((i, bx, by)) = bump[r as usize * cols + c as usize] {
                        let s = (x - bx).hypot(y - by);
                        let z = sphere_depth(press.bump_radius_mm, press.depth_mm, s);
                        if z > deepest.0 {
                            deepest = (z, Some(i));
                        }
                    }
                }
            }
            depth[v * w + u] = deepest.0 as f32;
            owner[v * w + u] = deepest.1;
        }
    }
    (depth, owner)
}
