//! Residual overlay: the capture image (8-bit RGB PNG) with observed pixels (green circles),
//! reprojected pixels (red crosses), residual vectors scaled by [`RESIDUAL_SCALE`] (yellow) and
//! RANSAC outliers (magenta circles).

use std::io::{BufReader, Cursor};
use std::path::Path;

use crate::report::ExtrinsicsReport;

/// Residual vectors are drawn this many times their length.
pub const RESIDUAL_SCALE: f64 = 10.0;

/// An overlay image that cannot be read or made.
#[derive(Debug, thiserror::Error)]
pub enum OverlayError {
    #[error("{file}: cannot read: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}: not a readable PNG: {message}")]
    Decode { file: String, message: String },
    #[error("{file}: image is {width} x {height} px but the camera file says {cam_width} x {cam_height} px")]
    Size {
        file: String,
        width: u32,
        height: u32,
        cam_width: u32,
        cam_height: u32,
    },
    #[error("cannot encode the overlay PNG: {0}")]
    Encode(String),
}

/// An 8-bit RGB image.
pub struct Rgb8 {
    pub width: u32,
    pub height: u32,
    pub data: Vec<u8>,
}

impl Rgb8 {
    pub(crate) fn put(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as u32) < self.width && (y as u32) < self.height {
            let i = 3 * (y as usize * self.width as usize + x as usize);
            self.data[i..i + 3].copy_from_slice(&c);
        }
    }

    pub(crate) fn line(&mut self, x0: f64, y0: f64, x1: f64, y1: f64, c: [u8; 3]) {
        let n = ((x1 - x0).abs().max((y1 - y0).abs()).ceil() as i64).clamp(1, 10_000);
        for k in 0..=n {
            let t = k as f64 / n as f64;
            self.put(
                (x0 + t * (x1 - x0)).round() as i64,
                (y0 + t * (y1 - y0)).round() as i64,
                c,
            );
        }
    }

    pub(crate) fn circle(&mut self, x: f64, y: f64, r: f64, c: [u8; 3]) {
        let n = (2.0 * std::f64::consts::PI * r).ceil() as i64 * 2;
        for k in 0..n {
            let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            self.put(
                (x + r * a.cos()).round() as i64,
                (y + r * a.sin()).round() as i64,
                c,
            );
        }
    }

    /// Writes `text` ([`fabkit_designs::glyphs`]: digits, `?`, `-`; others blank) with its
    /// top-left corner at (`x`, `y`) px, in a 3 x 5 pixel font scaled `scale` times.
    pub(crate) fn text(&mut self, x: f64, y: f64, text: &str, scale: i64, c: [u8; 3]) {
        fabkit_designs::glyphs::draw_text(
            x.round() as i64,
            y.round() as i64,
            text,
            scale,
            |px, py| self.put(px, py, c),
        );
    }

    /// The image encoded as an 8-bit RGB PNG.
    ///
    /// # Errors
    /// [`OverlayError::Encode`].
    pub fn to_png(&self) -> Result<Vec<u8>, OverlayError> {
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, self.width, self.height);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            // fdeflate's fast mode: an eighth of the default's time for a noisy 640 x 480
            // capture (the whole calibration from images 0.32 s -> 0.04 s), files nearly twice
            // zlib level 6's (450 kB against 240 kB)
            enc.set_compression(png::Compression::Fast);
            let mut w = enc
                .write_header()
                .map_err(|e| OverlayError::Encode(e.to_string()))?;
            w.write_image_data(&self.data)
                .map_err(|e| OverlayError::Encode(e.to_string()))?;
            w.finish()
                .map_err(|e| OverlayError::Encode(e.to_string()))?;
        }
        Ok(out)
    }
}

/// Reads a PNG (any colour type and depth) as 8-bit RGB.
///
/// # Errors
/// [`OverlayError::Io`] or [`OverlayError::Decode`] naming the file.
pub fn read_png_rgb8(path: &Path) -> Result<Rgb8, OverlayError> {
    read_png_rgb8_checked(path, None)
}

/// [`read_png_rgb8`] of an image that must be `expect_px` = (width, height): the size in the
/// PNG header is compared before any pixel is decoded or allocated (a 69-byte PNG can declare
/// 200000 x 200000 px).
///
/// # Errors
/// [`OverlayError::Size`] for another size, else as [`read_png_rgb8`].
pub fn read_png_rgb8_sized(path: &Path, expect_px: (u32, u32)) -> Result<Rgb8, OverlayError> {
    read_png_rgb8_checked(path, Some(expect_px))
}

fn read_png_rgb8_checked(path: &Path, expect_px: Option<(u32, u32)>) -> Result<Rgb8, OverlayError> {
    let file = path.display().to_string();
    let bytes = crate::read_binary(path).map_err(|source| OverlayError::Io {
        file: file.clone(),
        source,
    })?;
    let dec_err = |e: png::DecodingError| OverlayError::Decode {
        file: file.clone(),
        message: e.to_string(),
    };
    let mut dec = png::Decoder::new(BufReader::new(Cursor::new(bytes)));
    dec.set_transformations(png::Transformations::normalize_to_color8());
    let mut reader = dec.read_info().map_err(dec_err)?;
    if let Some((cam_width, cam_height)) = expect_px {
        let (width, height) = (reader.info().width, reader.info().height);
        if (width, height) != (cam_width, cam_height) {
            return Err(OverlayError::Size {
                file,
                width,
                height,
                cam_width,
                cam_height,
            });
        }
    }
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| OverlayError::Decode {
            file: file.clone(),
            message: "image too large".into(),
        })?;
    let mut buf = vec![0u8; size];
    let info = reader.next_frame(&mut buf).map_err(dec_err)?;
    let (w, h) = (info.width, info.height);
    let channels = match info.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => 3,
    };
    let mut data = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h as usize {
        let row = &buf[y * info.line_size..];
        for x in 0..w as usize {
            let px = &row[x * channels..x * channels + channels];
            match channels {
                1 | 2 => data.extend_from_slice(&[px[0], px[0], px[0]]),
                _ => data.extend_from_slice(&px[..3]),
            }
        }
    }
    Ok(Rgb8 {
        width: w,
        height: h,
        data,
    })
}

/// Draws the report's points on `img` and encodes it as PNG bytes.
///
/// # Errors
/// [`OverlayError::Encode`].
pub fn render_overlay(mut img: Rgb8, report: &ExtrinsicsReport) -> Result<Vec<u8>, OverlayError> {
    const GREEN: [u8; 3] = [0, 220, 0];
    const RED: [u8; 3] = [255, 40, 40];
    const YELLOW: [u8; 3] = [255, 220, 0];
    const MAGENTA: [u8; 3] = [255, 0, 255];
    for p in &report.residuals.points {
        let [u, v] = p.observed_px;
        img.circle(u, v, 4.0, if p.inlier { GREEN } else { MAGENTA });
        if !p.inlier {
            img.circle(u, v, 6.0, MAGENTA);
        }
        if let Some([ru, rv]) = p.reprojected_px {
            img.line(ru - 3.0, rv, ru + 3.0, rv, RED);
            img.line(ru, rv - 3.0, ru, rv + 3.0, RED);
            img.line(
                u,
                v,
                u + RESIDUAL_SCALE * (ru - u),
                v + RESIDUAL_SCALE * (rv - v),
                YELLOW,
            );
        }
    }
    img.to_png()
}

/// `residuals.png`: a histogram of the inliers' reprojection errors (20 bins from 0 to the
/// largest, px; bar heights the counts), the axis labelled with the bins' edges in px and the
/// tallest bar's count. 480 x 260 px.
///
/// # Errors
/// [`OverlayError::Encode`].
pub fn render_residual_histogram(report: &ExtrinsicsReport) -> Result<Vec<u8>, OverlayError> {
    const W: u32 = 480;
    const H: u32 = 260;
    const BINS: usize = 20;
    let (left, right, top, bottom) = (40.0, 460.0, 30.0, 220.0);
    let mut img = Rgb8 {
        width: W,
        height: H,
        data: vec![255; (3 * W * H) as usize],
    };
    let errors: Vec<f64> = report
        .residuals
        .points
        .iter()
        .filter(|p| p.inlier)
        .filter_map(|p| p.reprojection_error_px)
        .collect();
    let max = errors.iter().copied().fold(0.0f64, f64::max).max(1e-3);
    let mut counts = [0usize; BINS];
    for e in &errors {
        counts[((e / max * BINS as f64) as usize).min(BINS - 1)] += 1;
    }
    let tallest = counts.iter().copied().max().unwrap_or(0).max(1);
    let bar_w = (right - left) / BINS as f64;
    for (k, &n) in counts.iter().enumerate() {
        let h = (bottom - top) * n as f64 / tallest as f64;
        let x0 = left + k as f64 * bar_w;
        for x in (x0 + 1.0) as i64..(x0 + bar_w - 1.0) as i64 {
            for y in (bottom - h) as i64..bottom as i64 {
                img.put(x, y, [60, 110, 200]);
            }
        }
    }
    const BLACK: [u8; 3] = [0, 0, 0];
    img.line(left, bottom, right, bottom, BLACK);
    img.line(left, top, left, bottom, BLACK);
    img.text(left - 4.0, bottom + 8.0, "0", 2, BLACK);
    img.text(right - 60.0, bottom + 8.0, &format!("{max:.3}px"), 2, BLACK);
    img.text(
        left + 0.5 * (right - left) - 30.0,
        bottom + 8.0,
        &format!("{:.3}", 0.5 * max),
        2,
        BLACK,
    );
    img.text(left + 6.0, top - 20.0, &tallest.to_string(), 2, BLACK);
    img.to_png()
}

/// Encodes an 8-bit grey image (row-major, `width * height` bytes) as PNG, e.g. for synthetic
/// captures in tests.
///
/// # Errors
/// [`OverlayError::Encode`].
pub fn encode_gray8(width: u32, height: u32, data: &[u8]) -> Result<Vec<u8>, OverlayError> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc
            .write_header()
            .map_err(|e| OverlayError::Encode(e.to_string()))?;
        w.write_image_data(data)
            .map_err(|e| OverlayError::Encode(e.to_string()))?;
        w.finish()
            .map_err(|e| OverlayError::Encode(e.to_string()))?;
    }
    Ok(out)
}
