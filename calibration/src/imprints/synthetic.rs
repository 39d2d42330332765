//! Synthetic captures for the tests and benchmarks: the skin rendered through a camera with the
//! ground-truth caster ([`crate::groundtruth`]), each pin's imprint shaded as a darkening
//! proportional to its indentation depth along the pixel's ray, blurred by a Gaussian
//! point-spread function, with vignetting, bright LED reflections near the rim (a little
//! brighter or dimmer in each image) and Gaussian noise; [`Shading::real_capture`] adds what a
//! real R-Tac0 capture shows besides (a saturated LED ring that moves, gain drift, side-lit
//! crescent imprints, specks and a scratch off the pins, JPEG compression).

use super::{gaussian_blur, GrayImage};
use crate::groundtruth::exact::ExactPrimitives;
use crate::groundtruth::rays::PixelRays;
use crate::groundtruth::surface::ReferenceSurface;
use crate::groundtruth::{indented_hits, reference_hits, SurfaceHits};
use crate::CameraModel;
use fabkit_designs::primitives::Primitive;
use nalgebra::Isometry3;
use rand_chacha::rand_core::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// How the images are shaded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shading {
    /// Grey of the skin at the image centre.
    pub skin_grey: f32,
    /// Grey outside the skin.
    pub background_grey: f32,
    /// Darkening per mm of indentation depth along the ray.
    pub grey_per_mm: f32,
    /// Sigma of the point-spread function, px.
    pub psf_sigma_px: f64,
    /// Sigma of the noise, grey levels.
    pub noise_sigma: f64,
    /// Fraction of the grey lost at the image's corners (quadratic in the radius).
    pub vignetting: f32,
    /// LED reflections: count, peak grey above the skin, sigma px, and how much each image's
    /// peak varies (fraction).
    pub leds: usize,
    pub led_grey: f32,
    pub led_sigma_px: f64,
    pub led_flicker: f32,
    /// How far each LED highlight moves between the reference and the capture, px (in a
    /// random direction per highlight).
    pub led_shift_px: f64,
    /// The capture's global gain differs from the reference's by a random factor in
    /// [1 - drift, 1 + drift] (auto exposure, LED supply).
    pub gain_drift: f32,
    /// Side light: the imprint's darkening is `grey_per_mm x (d + side_light_px x l . grad d)`
    /// with `d` the indentation depth (mm), `grad d` its gradient per pixel and `l` the
    /// vector from the image centre to the pixel over the skin's radius in the image (0 at
    /// the centre, 1 at the skin's edge): the LEDs at the rim light each imprint from
    /// outside, so that its outer slope is darker and a thin crescent inside its inner edge
    /// brighter than the skin. To first order the shading is the imprint moved by
    /// `side_light_px x |l|` px towards the image centre; the true centres
    /// ([`Rendered::centres_px`]) stay the centroids of the depth, so that move is error.
    pub side_light_px: f64,
    /// Specks on the skin that only the capture shows (dust, a fibre): this many dark dots of
    /// 1 to 2 px radius, 40 to 80 grey levels deep, each at least 30 px from every pin's
    /// imprint.
    pub specks: usize,
    /// And this many scratches: dark lines 1 px wide, 12 to 20 px long, 30 to 50 grey deep.
    pub scratches: usize,
    /// Both images are stored as 8-bit JPEG of this quality (1 to 100) and read back; `None`:
    /// kept as the floating-point grey levels.
    pub jpeg_quality: Option<u8>,
    /// The skin around each imprint is pulled in too: outside the contact the depth follows
    /// the surface displacement of a Hertz contact, `halo x d (h(s) - h(4))` with `h(s) = (1 /
    /// pi) [(2 - s^2) asin(1 / s) + sqrt(s^2 - 1)]` at `s` contact radii from the imprint's
    /// deepest point on the skin (`d` its deepest depth; Johnson, *Contact Mechanics*,
    /// Sec. 3.4, Eq. 3.42: half the depth at the contact's edge, falling as 1 / s), lowered to
    /// end at 4 radii; 0: the imprint ends at the contact (ASSUMPTION: the rigid sphere's contact radius stands for the Hertz
    /// one; issue 101 models the skin). A faint skirt the detector's spots grow into, and
    /// that joins two imprints near each other.
    pub halo: f64,
    /// Dark LED notches at the skin's rim, in both images: this many slots at the
    /// background's grey, `notch_width_px` wide, from the skin's edge in the image inwards by
    /// `notch_depth_px`, along the azimuths `notch_phase_deg + k 360 / notches` (about the
    /// image centre, from +u towards +v). The reference mask leaves them out, clipping an
    /// imprint beside one.
    pub notches: usize,
    pub notch_phase_deg: f64,
    pub notch_width_px: f64,
    pub notch_depth_px: f64,
}

impl Default for Shading {
    fn default() -> Self {
        Self {
            skin_grey: 160.0,
            background_grey: 12.0,
            grey_per_mm: 120.0,
            psf_sigma_px: 1.2,
            noise_sigma: 2.0,
            vignetting: 0.35,
            leds: 6,
            led_grey: 90.0,
            led_sigma_px: 3.0,
            led_flicker: 0.3,
            led_shift_px: 0.0,
            gain_drift: 0.0,
            side_light_px: 0.0,
            specks: 0,
            scratches: 0,
            jpeg_quality: None,
            halo: 0.0,
            notches: 0,
            notch_phase_deg: 0.0,
            notch_width_px: 0.0,
            notch_depth_px: 0.0,
        }
    }
}

impl Shading {
    /// What a real R-Tac0 capture adds to [`Shading::default`]: a ring of 12 LED
    /// highlights saturated at 255 (steep edges around flat tops, dark skin between them)
    /// that each move by 1.5 px between the reference and the capture, and a global gain
    /// that drifts by up to 5 %.
    pub fn real_rim() -> Self {
        Self {
            leds: 12,
            led_grey: 300.0,
            led_sigma_px: 8.0,
            led_flicker: 0.1,
            led_shift_px: 1.5,
            gain_drift: 0.05,
            ..Self::default()
        }
    }
}

impl Shading {
    /// [`Shading::real_rim`] and the rest of what a real capture shows: imprints side-lit by
    /// the rim's LEDs (moved up to 0.1 px towards the image centre, a faint bright crescent on
    /// their inner edge), three specks and a scratch off the pins, JPEG at quality 90. It still
    /// lacks the skin's texture, the sensor's rolling shutter and lens flare.
    pub fn real_capture() -> Self {
        Self {
            side_light_px: 0.1,
            specks: 3,
            scratches: 1,
            jpeg_quality: Some(90),
            ..Self::real_rim()
        }
    }
}

/// A pin of a capture: a sphere of `radius_mm` about `centre_mm` (sensor frame), pressing
/// the skin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pin {
    pub centre_mm: [f64; 3],
    pub radius_mm: f64,
}

/// One pin per ring of an R-Tac0-like dome (polar 0, 18, 34, 50 and 64 deg, azimuths 0, 30,
/// 150, 250 and 330 deg turned by `turn_deg`), each a ball of 1.5 mm radius pressed
/// `depth_mm` into the R = 15 mm skin along its normal: the test and benchmark captures.
pub fn ring_pins(turn_deg: f64, depth_mm: f64) -> Vec<Pin> {
    ring_pins_pressed(turn_deg, [depth_mm; 5])
}

/// [`ring_pins`] with each ring's own depth, mm (from the pole outwards): a pin that barely
/// marks the skin is one pressed a fraction of a millimetre.
pub fn ring_pins_pressed(turn_deg: f64, depths_mm: [f64; 5]) -> Vec<Pin> {
    [
        (0.0, 0.0),
        (18.0, 30.0),
        (34.0, 150.0),
        (50.0, 250.0),
        (64.0, 330.0),
    ]
    .iter()
    .zip(depths_mm)
    .map(|(&(polar, az), depth_mm): (&(f64, f64), f64)| {
        let (p, a) = (polar.to_radians(), (az + turn_deg).to_radians());
        let c = 15.0 + 1.5 - depth_mm;
        Pin {
            centre_mm: [c * p.sin() * a.cos(), c * p.sin() * a.sin(), c * p.cos()],
            radius_mm: 1.5,
        }
    })
    .collect()
}

/// The fraction of an imprint's deepest depth above which its core lies
/// ([`Rendered::centres_px`]), as the detector's default `DetectParams::core_fraction`.
pub const CORE_FRACTION: f64 = 0.5;

/// Where [`Shading::halo`] ends, in contact radii.
const HALO_RADII: f64 = 4.0;

/// Hertz's surface displacement outside the contact over the indentation depth at `s > 1`
/// contact radii from its centre (Johnson, *Contact Mechanics*, Eq. 3.42b): 1/2 at `s = 1`.
fn hertz(s: f64) -> f64 {
    ((2.0 - s * s) * (1.0 / s).asin() + (s * s - 1.0).sqrt()) / std::f64::consts::PI
}

/// A rendered capture and its reference.
#[derive(Debug, Clone)]
pub struct Rendered {
    pub reference: GrayImage,
    pub capture: GrayImage,
    /// Each pin's true centre, px: the centroid of its noise-free imprint's core as the lens
    /// images it (its depth along the rays blurred by the PSF, above [`CORE_FRACTION`] of its
    /// deepest: the part nearest the tip, as the detector takes it,
    /// `DetectParams::core_fraction`), in the order given; `None` for a pin the camera does
    /// not see press.
    pub centres_px: Vec<Option<[f64; 2]>>,
}

/// Uniform in [0, 1).
fn unit(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

fn led_image(
    w: usize,
    h: usize,
    base: &[f32],
    leds: &[[f64; 2]],
    s: &Shading,
    rng: &mut ChaCha8Rng,
) -> Vec<f32> {
    let mut img = base.to_vec();
    for c in leds {
        let k = 1.0 + s.led_flicker * (2.0 * unit(rng) as f32 - 1.0);
        let r = (4.0 * s.led_sigma_px).ceil() as i64;
        for dv in -r..=r {
            for du in -r..=r {
                let (u, v) = (c[0].round() as i64 + du, c[1].round() as i64 + dv);
                if u < 0 || v < 0 || u >= w as i64 || v >= h as i64 {
                    continue;
                }
                let d2 = (u as f64 - c[0]).powi(2) + (v as f64 - c[1]).powi(2);
                img[v as usize * w + u as usize] +=
                    k * s.led_grey * (-d2 / (2.0 * s.led_sigma_px * s.led_sigma_px)).exp() as f32;
            }
        }
    }
    img
}

fn noisy(img: Vec<f32>, sigma: f64, rng: &mut ChaCha8Rng) -> Vec<f32> {
    img.into_iter()
        .map(|g| {
            // Box-Muller
            let (a, b): (f64, f64) = (unit(rng).max(1e-300), unit(rng));
            let n = (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos();
            (g as f64 + sigma * n).clamp(0.0, 255.0) as f32
        })
        .collect()
}

/// `img` (grey levels 0..255) stored as an 8-bit JPEG of `quality` and read back.
fn jpeg(img: &[f32], w: usize, h: usize, quality: u8) -> Vec<f32> {
    let bytes: Vec<u8> = img
        .iter()
        .map(|g| g.round().clamp(0.0, 255.0) as u8)
        .collect();
    let mut out = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, quality.clamp(1, 100))
        .encode(&bytes, w as u32, h as u32, image::ExtendedColorType::L8)
        .expect("a grey image of the camera's size encodes");
    image::load_from_memory_with_format(&out, image::ImageFormat::Jpeg)
        .expect("the JPEG just written decodes")
        .into_luma8()
        .into_raw()
        .into_iter()
        .map(f32::from)
        .collect()
}

/// Renders the reference and the capture of `pins` seen by `camera` at `t_cam_sensor`
/// (seeded noise and flicker).
pub fn render(
    camera: &CameraModel,
    t_cam_sensor: &Isometry3<f64>,
    surface: &ReferenceSurface,
    pins: &[Pin],
    s: &Shading,
    seed: u64,
) -> Rendered {
    render_through(camera, t_cam_sensor, None, surface, pins, s, seed)
}

/// [`render`] with the camera's rays bent at the interfaces of `layers`
/// ([`PixelRays::through`]): a pin dome seen through a filling gel's surface. The imprints'
/// true centroids are those of the bent rays.
///
/// # Panics
/// When the camera centre is not under every plane of `layers` (a test scene's error).
pub fn render_through(
    camera: &CameraModel,
    t_cam_sensor: &Isometry3<f64>,
    layers: Option<&crate::refraction::OpticalLayers>,
    surface: &ReferenceSurface,
    pins: &[Pin],
    s: &Shading,
    seed: u64,
) -> Rendered {
    let rays = match layers {
        None => PixelRays::new(camera, t_cam_sensor),
        Some(l) => PixelRays::through(camera, t_cam_sensor, l)
            .expect("the scene's camera is under the layers"),
    };
    let (w, h) = (rays.width, rays.height);
    let refh = reference_hits(&rays, surface);
    let (cx, cy) = (0.5 * (w as f64 - 1.0), 0.5 * (h as f64 - 1.0));
    let mut scene = Scene {
        rays: &rays,
        refh: &refh,
        s,
        w,
        h,
        cx,
        cy,
        rmax: cx.hypot(cy),
        skin_r: 0.0,
    };
    let mut base = scene.skin_base();
    // LED reflections on a circle at 90 % of the skin's extent in the image; where a core's
    // open end bounds the view (the layers have shells), on that edge: the lit diffuser ring
    // beside the tube's mouth mirrored in the gel's free surface
    let at_edge = layers.is_some_and(|l| !l.shells().is_empty());
    let leds = scene.led_centres(at_edge);
    // dark notches at the rim: the skin's edge in the image along each notch's azimuth
    if s.notches > 0 && s.notch_width_px > 0.0 && s.notch_depth_px > 0.0 {
        for k in 0..s.notches {
            scene.cut_notch(k, &mut base);
        }
    }
    // each pin's imprint: the depth it pushes the skin in along each ray
    let mut dent = vec![0f32; w * h];
    let mut centres = Vec::with_capacity(pins.len());
    for pin in pins {
        let own = scene.pin_depth(pin, surface);
        for (x, o) in dent.iter_mut().zip(&own) {
            *x += o;
        }
        centres.push(scene.imprint_centre(own));
    }
    let shade = scene.side_lit(&dent);
    let marks = scene.marks(seed, &centres);
    let (reference, capture) = scene.photographs(&base, &shade, &marks, &leds, seed);
    Rendered {
        reference: GrayImage {
            width: w,
            height: h,
            data: reference,
        },
        capture: GrayImage {
            width: w,
            height: h,
            data: capture,
        },
        centres_px: centres,
    }
}

/// [`render_through`]'s scene: the camera's rays, the reference skin they meet, the shading,
/// the image's size (`w` x `h` px), its centre (`cx`, `cy`) and half-diagonal `rmax`, px, and
/// the skin's radius in the image about the centre (`skin_r`, px; set by [`Self::skin_base`]).
struct Scene<'a> {
    rays: &'a PixelRays,
    refh: &'a SurfaceHits,
    s: &'a Shading,
    w: usize,
    h: usize,
    cx: f64,
    cy: f64,
    rmax: f64,
    skin_r: f64,
}

impl Scene<'_> {
    /// The unpressed image before the PSF: the skin's grey with vignetting, the background's
    /// elsewhere; sets `skin_r`.
    fn skin_base(&mut self) -> Vec<f32> {
        let (w, h, s) = (self.w, self.h, self.s);
        let (cx, cy, rmax) = (self.cx, self.cy, self.rmax);
        let mut base = vec![s.background_grey; w * h];
        let mut skin_r: f64 = 0.0;
        for p in 0..w * h {
            if self.refh.t_mm[p].is_finite() {
                let r = ((p % w) as f64 - cx).hypot((p / w) as f64 - cy) / rmax;
                base[p] = s.skin_grey * (1.0 - s.vignetting * (r * r) as f32);
                skin_r = skin_r.max(r * rmax);
            }
        }
        self.skin_r = skin_r;
        base
    }

    /// The LED reflections' centres, px: evenly on a circle at 90 % of the skin's radius in
    /// the image (`at_edge`: at 100 %), at most the image's half-height.
    fn led_centres(&self, at_edge: bool) -> Vec<[f64; 2]> {
        let (s, cx, cy, skin_r) = (self.s, self.cx, self.cy, self.skin_r);
        (0..s.leds)
            .map(|k| {
                let a = std::f64::consts::TAU * (k as f64 + 0.5) / s.leds as f64;
                let r = if at_edge { 1.0 } else { 0.9 } * skin_r.min(cy);
                [cx + r * a.cos(), cy + r * a.sin()]
            })
            .collect()
    }

    /// Notch `k` ([`Shading::notches`]) cut into `base` at the background's grey: from the
    /// skin's last pixel along its azimuth inwards.
    fn cut_notch(&self, k: usize, base: &mut [f32]) {
        let (w, h, s) = (self.w, self.h, self.s);
        let (cx, cy, rmax) = (self.cx, self.cy, self.rmax);
        let a = (s.notch_phase_deg + 360.0 * k as f64 / s.notches as f64).to_radians();
        let (du, dv) = (a.cos(), a.sin());
        // the last skin pixel along the azimuth
        let mut edge: f64 = 0.0;
        let mut r = 0.0;
        while r < rmax {
            let (u, v) = ((cx + r * du).round(), (cy + r * dv).round());
            if u < 0.0 || v < 0.0 || u > (w - 1) as f64 || v > (h - 1) as f64 {
                break;
            }
            if self.refh.t_mm[v as usize * w + u as usize].is_finite() {
                edge = r;
            }
            r += 0.5;
        }
        for (p, b) in base.iter_mut().enumerate() {
            let (x, y) = ((p % w) as f64 - cx, (p / w) as f64 - cy);
            let (along, across) = (x * du + y * dv, -x * dv + y * du);
            if along >= edge - s.notch_depth_px && across.abs() <= 0.5 * s.notch_width_px {
                *b = s.background_grey;
            }
        }
    }

    /// The point where pixel `p`'s ray meets the reference skin, sensor frame, mm.
    fn hit_point(&self, p: usize) -> nalgebra::Vector3<f64> {
        let (o, d, t) = (self.rays.origin(p), self.rays.dirs[p], self.refh.t_mm[p]);
        nalgebra::Vector3::new(o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2])
    }

    /// The depth `pin` pushes the skin in along each pixel's ray, mm (0 where it does not),
    /// with its halo ([`Shading::halo`]) outside the contact.
    fn pin_depth(&self, pin: &Pin, surface: &ReferenceSurface) -> Vec<f32> {
        let (w, h, s, refh) = (self.w, self.h, self.s, self.refh);
        let prim = ExactPrimitives::new(&[Primitive::Sphere {
            centre_mm: pin.centre_mm,
            radius_mm: pin.radius_mm,
        }])
        .expect("a sphere of positive radius");
        let hits = indented_hits(self.rays, refh, &prim, surface.base_z_mm());
        let depth = |p: usize| {
            (hits.contact[p] && refh.t_mm[p].is_finite()).then(|| refh.t_mm[p] - hits.t_mm[p])
        };
        let mut own = vec![0f32; w * h];
        let mut deepest_at: Option<(usize, f64)> = None;
        for p in 0..w * h {
            if let Some(d) = depth(p) {
                own[p] = d as f32;
                if deepest_at.is_none_or(|(_, e)| d > e) {
                    deepest_at = Some((p, d));
                }
            }
        }
        // the halo: Hertz's surface displacement outside the contact (Johnson Eq. 3.42)
        if let (true, Some((q, d))) = (s.halo > 0.0, deepest_at) {
            let c = self.hit_point(q);
            let a = (0..w * h)
                .filter(|&p| own[p] > 0.0)
                .map(|p| (self.hit_point(p) - c).norm())
                .fold(0.0, f64::max);
            if a > 0.0 {
                for p in 0..w * h {
                    if own[p] > 0.0 || !refh.t_mm[p].is_finite() {
                        continue;
                    }
                    let r = (self.hit_point(p) - c).norm() / a;
                    if r > 1.0 && r < HALO_RADII {
                        own[p] = (s.halo * d * (hertz(r) - hertz(HALO_RADII))) as f32;
                    }
                }
            }
        }
        own
    }

    /// The true centre of the imprint of depth `own` ([`Rendered::centres_px`]): the centroid
    /// of its core as the lens images it (blurred by the PSF, noise-free), its depth above
    /// [`CORE_FRACTION`] of its deepest; `None` for no imprint.
    fn imprint_centre(&self, own: Vec<f32>) -> Option<[f64; 2]> {
        let w = self.w;
        let seen = gaussian_blur(
            &GrayImage {
                width: w,
                height: self.h,
                data: own,
            },
            self.s.psf_sigma_px,
        )
        .data;
        let deepest = seen.iter().fold(0f32, |a, &b| a.max(b)) as f64;
        let (mut sw, mut su, mut sv) = (0f64, 0f64, 0f64);
        for (p, &d) in seen.iter().enumerate() {
            let x = (f64::from(d) - CORE_FRACTION * deepest).max(0.0);
            sw += x;
            su += x * (p % w) as f64;
            sv += x * (p / w) as f64;
        }
        (deepest > 0.0 && sw > 0.0).then(|| [su / sw, sv / sw])
    }

    /// The shading of the imprints' depth `dent`, side-lit from the rim
    /// ([`Shading::side_light_px`]); `dent` itself without side light.
    fn side_lit(&self, dent: &[f32]) -> Vec<f32> {
        let (w, h, s, skin_r) = (self.w, self.h, self.s, self.skin_r);
        let (cx, cy) = (self.cx, self.cy);
        if s.side_light_px > 0.0 && skin_r > 0.0 {
            (0..w * h)
                .map(|p| {
                    let (u, v) = (p % w, p / w);
                    let (l, r) = (u.saturating_sub(1), (u + 1).min(w - 1));
                    let (t, b) = (v.saturating_sub(1), (v + 1).min(h - 1));
                    let gu = f64::from(dent[v * w + r] - dent[v * w + l]) / (r - l) as f64;
                    let gv = f64::from(dent[b * w + u] - dent[t * w + u]) / (b - t) as f64;
                    let (lu, lv) = ((u as f64 - cx) / skin_r, (v as f64 - cy) / skin_r);
                    dent[p] + (s.side_light_px * (lu * gu + lv * gv)) as f32
                })
                .collect()
        } else {
            dent.to_vec()
        }
    }

    /// The darkening of the specks and scratches ([`Shading::specks`], [`Shading::scratches`])
    /// on the skin, away from the imprints' `centres`, from their own random stream (the other
    /// draws stay as without them).
    fn marks(&self, seed: u64, centres: &[Option<[f64; 2]>]) -> Vec<f32> {
        let (w, h, s, refh) = (self.w, self.h, self.s, self.refh);
        let (cx, cy, skin_r) = (self.cx, self.cy, self.skin_r);
        let mut marks = vec![0f32; w * h];
        if s.specks + s.scratches == 0 {
            return marks;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x005b_ecc5);
        let clear = |u: f64, v: f64| {
            let p = v.round() as usize * w + u.round() as usize;
            refh.t_mm[p].is_finite()
                && (u - cx).hypot(v - cy) < 0.8 * skin_r
                && centres
                    .iter()
                    .flatten()
                    .all(|c: &[f64; 2]| (c[0] - u).hypot(c[1] - v) >= 30.0)
        };
        let mut placed = 0;
        for _ in 0..10_000 {
            if placed == s.specks + s.scratches {
                break;
            }
            let (u, v) = (
                unit(&mut rng) * (w - 1) as f64,
                unit(&mut rng) * (h - 1) as f64,
            );
            if !clear(u, v) {
                continue;
            }
            if placed < s.specks {
                self.speck(&mut marks, u, v, &mut rng);
            } else {
                self.scratch(&mut marks, u, v, &mut rng);
            }
            placed += 1;
        }
        marks
    }

    /// A speck at (`u`, `v`) px added to `marks`: a dot of 1 to 2 px radius, 40 to 80 grey
    /// levels deep (drawn from `rng`).
    fn speck(&self, marks: &mut [f32], u: f64, v: f64, rng: &mut ChaCha8Rng) {
        let (w, h) = (self.w, self.h);
        let radius = 1.0 + unit(rng);
        let grey = (40.0 + 40.0 * unit(rng)) as f32;
        let r = radius.ceil() as i64 + 1;
        for dv in -r..=r {
            for du in -r..=r {
                let (uu, vv) = (u.round() as i64 + du, v.round() as i64 + dv);
                if uu < 0 || vv < 0 || uu >= w as i64 || vv >= h as i64 {
                    continue;
                }
                if (uu as f64 - u).hypot(vv as f64 - v) <= radius {
                    marks[vv as usize * w + uu as usize] += grey;
                }
            }
        }
    }

    /// A scratch about (`u`, `v`) px added to `marks`: a line 1 px wide, 12 to 20 px long, 30
    /// to 50 grey levels deep, in a random direction (drawn from `rng`).
    fn scratch(&self, marks: &mut [f32], u: f64, v: f64, rng: &mut ChaCha8Rng) {
        let (w, h) = (self.w, self.h);
        let len = 12.0 + 8.0 * unit(rng);
        let a = std::f64::consts::TAU * unit(rng);
        let grey = (30.0 + 20.0 * unit(rng)) as f32;
        let steps = (2.0 * len).ceil() as usize;
        let mut last = usize::MAX;
        for i in 0..=steps {
            let t = len * (i as f64 / steps as f64 - 0.5);
            let (uu, vv) = (u + t * a.cos(), v + t * a.sin());
            if uu < 0.0 || vv < 0.0 || uu > (w - 1) as f64 || vv > (h - 1) as f64 {
                continue;
            }
            let p = vv.round() as usize * w + uu.round() as usize;
            if p != last {
                marks[p] += grey;
                last = p;
            }
        }
    }

    /// The reference and the capture as the camera records them: `base` (minus the imprints'
    /// `shade` and the `marks` for the capture) blurred by the PSF, the LED reflections at
    /// `leds` (moved in the capture), the capture's gain drift, noise and JPEG, drawn from the
    /// stream of `seed`.
    fn photographs(
        &self,
        base: &[f32],
        shade: &[f32],
        marks: &[f32],
        leds: &[[f64; 2]],
        seed: u64,
    ) -> (Vec<f32>, Vec<f32>) {
        let (w, h, s) = (self.w, self.h, self.s);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let blur = |img: Vec<f32>| {
            gaussian_blur(
                &GrayImage {
                    width: w,
                    height: h,
                    data: img,
                },
                s.psf_sigma_px,
            )
            .data
        };
        let reference = led_image(w, h, &blur(base.to_vec()), leds, s, &mut rng);
        let pressed: Vec<f32> = base
            .iter()
            .zip(shade)
            .zip(marks)
            .map(|((b, d), m)| b - s.grey_per_mm * d - m)
            .collect();
        // the highlights move, the gain drifts (no draws when neither does: the same images)
        let moved: Vec<[f64; 2]> = if s.led_shift_px > 0.0 {
            leds.iter()
                .map(|c| {
                    let a = std::f64::consts::TAU * unit(&mut rng);
                    [
                        c[0] + s.led_shift_px * a.cos(),
                        c[1] + s.led_shift_px * a.sin(),
                    ]
                })
                .collect()
        } else {
            leds.to_vec()
        };
        let gain = if s.gain_drift > 0.0 {
            1.0 + s.gain_drift * (2.0 * unit(&mut rng) as f32 - 1.0)
        } else {
            1.0
        };
        let capture: Vec<f32> = led_image(w, h, &blur(pressed), &moved, s, &mut rng)
            .into_iter()
            .map(|g| gain * g)
            .collect();
        let reference = noisy(reference, s.noise_sigma, &mut rng);
        let capture = noisy(capture, s.noise_sigma, &mut rng);
        match s.jpeg_quality {
            Some(q) => (jpeg(&reference, w, h, q), jpeg(&capture, w, h, q)),
            None => (reference, capture),
        }
    }
}
