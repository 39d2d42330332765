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

    /// Writes `text` (digits, `?` and `-`; other characters as blanks) with its top-left corner
    /// at (`x`, `y`) px, in a 3 x 5 pixel font scaled `scale` times.
    pub(crate) fn text(&mut self, x: f64, y: f64, text: &str, scale: i64, c: [u8; 3]) {
        for (k, ch) in text.chars().enumerate() {
            let rows = glyph(ch);
            for (r, bits) in rows.iter().enumerate() {
                for col in 0..3 {
                    if bits & (0b100 >> col) == 0 {
                        continue;
                    }
                    for dy in 0..scale {
                        for dx in 0..scale {
                            self.put(
                                x.round() as i64 + (4 * k as i64 + col) * scale + dx,
                                y.round() as i64 + r as i64 * scale + dy,
                                c,
                            );
                        }
                    }
                }
            }
        }
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

/// Rows (top first, 3 bits each, high bit left) of a 3 x 5 pixel glyph.
fn glyph(c: char) -> [u8; 5] {
    match c {
        '0' => [0b111, 0b101, 0b101, 0b101, 0b111],
        '1' => [0b010, 0b110, 0b010, 0b010, 0b111],
        '2' => [0b111, 0b001, 0b111, 0b100, 0b111],
        '3' => [0b111, 0b001, 0b111, 0b001, 0b111],
        '4' => [0b101, 0b101, 0b111, 0b001, 0b001],
        '5' => [0b111, 0b100, 0b111, 0b001, 0b111],
        '6' => [0b111, 0b100, 0b111, 0b101, 0b111],
        '7' => [0b111, 0b001, 0b010, 0b010, 0b010],
        '8' => [0b111, 0b101, 0b111, 0b101, 0b111],
        '9' => [0b111, 0b101, 0b111, 0b001, 0b111],
        '?' => [0b111, 0b001, 0b011, 0b000, 0b010],
        '-' => [0b000, 0b000, 0b111, 0b000, 0b000],
        _ => [0; 5],
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
