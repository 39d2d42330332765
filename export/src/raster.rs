//! Raster and point-cloud writers for ground-truth datasets: NPY (float32), NPZ, 16-bit and 8-bit
//! PNG, colour-mapped preview PNG and binary PLY. Every encoder is deterministic (same input,
//! same bytes). Images are row-major, (H, W) or (H, W, C).

use crate::ExportError;

fn encode_err(what: &str) -> impl Fn(png::EncodingError) -> ExportError + '_ {
    move |e| ExportError::Encode {
        what: format!("PNG {what}"),
        reason: e.to_string(),
    }
}

/// Several NPY arrays (e.g. from [`npy_f32`]) as one compressed NPZ file: a zip of
/// `<name>.npy` entries, deflated, fixed timestamps (what `numpy.savez_compressed` writes and
/// `numpy.load` reads as a mapping from `name` to array). `arrays` is (name, NPY bytes), in the
/// order of the entries.
///
/// # Errors
/// [`ExportError::Encode`] if the zip writer fails, or a name is not `[A-Za-z0-9_]+` or
/// repeats.
pub fn npz(arrays: &[(&str, &[u8])]) -> Result<Vec<u8>, ExportError> {
    use std::io::Write as _;
    use zip::ZipWriter;
    let err = |reason: String| ExportError::Encode {
        what: "NPZ".into(),
        reason,
    };
    let mut zip = ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for (k, (name, bytes)) in arrays.iter().enumerate() {
        if name.is_empty()
            || !name.bytes().all(|c| c.is_ascii_alphanumeric() || c == b'_')
            || arrays[..k].iter().any(|(n, _)| n == name)
        {
            return Err(err(format!(
                "array name '{name}' must be [A-Za-z0-9_]+ and unique"
            )));
        }
        let opts = zip_entry_options(bytes.len());
        zip.start_file(format!("{name}.npy"), opts)
            .map_err(|e| err(e.to_string()))?;
        zip.write_all(bytes).map_err(|e| err(e.to_string()))?;
    }
    Ok(zip.finish().map_err(|e| err(e.to_string()))?.into_inner())
}

/// The options of every NPZ entry: deflated at level 4 (as the 3MF packages,
/// [`crate::zip_package`]), a fixed timestamp and Unix mode 0644, so the same bytes go in and
/// come out; ZIP64 when an entry of `len` bytes needs it.
fn zip_entry_options(len: usize) -> zip::write::SimpleFileOptions {
    zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .compression_level(Some(4))
        .last_modified_time(zip::DateTime::default())
        .system(zip::System::Unix)
        .unix_permissions(0o644)
        .large_file(len as u64 >= u64::from(u32::MAX))
}

/// A float32 array as an NPY file (format version 1.0, little endian `<f4`, C order): what
/// `numpy.load` reads. `shape` is e.g. `[H, W]` or `[H, W, 3]`.
///
/// # Panics
/// If `data.len()` is not the product of `shape`.
pub fn npy_f32(shape: &[usize], data: &[f32]) -> Vec<u8> {
    assert_eq!(
        shape.iter().product::<usize>(),
        data.len(),
        "data matches the shape"
    );
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let shape_txt = if dims.len() == 1 {
        format!("({},)", dims[0])
    } else {
        format!("({})", dims.join(", "))
    };
    let mut header = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {shape_txt}, }}");
    // magic (6) + version (2) + header length (2) + header + '\n' is a multiple of 64.
    let total = 10 + header.len() + 1;
    header.push_str(&" ".repeat(total.div_ceil(64) * 64 - total));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + 4 * data.len());
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for v in data {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

fn png_bytes(
    width: usize,
    height: usize,
    color: png::ColorType,
    depth: png::BitDepth,
    data: &[u8],
    text: &[(&str, &str)],
    fast: bool,
) -> Result<Vec<u8>, ExportError> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width as u32, height as u32);
        enc.set_color(color);
        enc.set_depth(depth);
        if fast {
            enc.set_compression(png::Compression::Fast);
        }
        for (k, v) in text {
            enc.add_text_chunk(k.to_string(), v.to_string())
                .map_err(encode_err("text chunk"))?;
        }
        let mut w = enc.write_header().map_err(encode_err("header"))?;
        w.write_image_data(data).map_err(encode_err("image data"))?;
        w.finish().map_err(encode_err("finish"))?;
    }
    Ok(out)
}

/// Reads an NPY file of float32 (`<f4`, C order, format version 1.0 to 3.0) as its shape and
/// values: the files [`npy_f32`] writes, and numpy's `np.save` of a `float32` array.
///
/// # Errors
/// A message saying what is wrong: not NPY, another dtype, Fortran order, a shape that does
/// not parse or does not match the data's length.
pub fn read_npy_f32(bytes: &[u8]) -> Result<(Vec<usize>, Vec<f32>), String> {
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err("not an NPY file (bad magic)".into());
    }
    let (header_len, start): (usize, usize) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        v => return Err(format!("NPY format version {v} is not read")),
    };
    let end = start
        .checked_add(header_len)
        .filter(|e| *e <= bytes.len())
        .ok_or("the NPY header runs past the file")?;
    let header =
        std::str::from_utf8(&bytes[start..end]).map_err(|_| "the NPY header is not text")?;
    let field = |key: &str| -> Option<&str> {
        let i = header.find(&format!("'{key}'"))? + key.len() + 2;
        let rest = header[i..].trim_start().strip_prefix(':')?.trim_start();
        Some(rest)
    };
    let descr = field("descr").ok_or("the NPY header has no descr")?;
    if !descr.starts_with("'<f4'") {
        return Err(format!(
            "dtype {}: only little-endian float32 ('<f4') is read",
            descr.split(',').next().unwrap_or("")
        ));
    }
    if !field("fortran_order").is_some_and(|f| f.starts_with("False")) {
        return Err("only C-order arrays (fortran_order False) are read".into());
    }
    let shape_txt = field("shape").ok_or("the NPY header has no shape")?;
    let close = shape_txt.find(')').ok_or("the NPY shape does not parse")?;
    let shape: Vec<usize> = shape_txt[1..close]
        .split(',')
        .map(str::trim)
        .filter(|t| !t.is_empty())
        .map(|t| {
            t.parse::<usize>()
                .map_err(|_| format!("the NPY shape {} does not parse", &shape_txt[..=close]))
        })
        .collect::<Result<_, _>>()?;
    let n = shape
        .iter()
        .try_fold(1usize, |a, d| a.checked_mul(*d))
        .ok_or("the NPY shape is too large")?;
    let data = &bytes[end..];
    if data.len() != 4 * n {
        return Err(format!(
            "the NPY data holds {} bytes, the shape {:?} needs {}",
            data.len(),
            shape,
            4 * n
        ));
    }
    Ok((
        shape,
        data.chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect(),
    ))
}

/// A 16-bit greyscale PNG (`text`: tEXt chunks, e.g. the units and scale).
///
/// # Errors
/// [`ExportError::Encode`] if the encoder fails.
///
/// # Panics
/// If `data.len() != width * height`.
pub fn png_gray16(
    width: usize,
    height: usize,
    data: &[u16],
    text: &[(&str, &str)],
) -> Result<Vec<u8>, ExportError> {
    assert_eq!(data.len(), width * height);
    let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_be_bytes()).collect();
    png_bytes(
        width,
        height,
        png::ColorType::Grayscale,
        png::BitDepth::Sixteen,
        &bytes,
        text,
        false,
    )
}

/// An 8-bit greyscale PNG.
///
/// # Errors
/// [`ExportError::Encode`] if the encoder fails.
///
/// # Panics
/// If `data.len() != width * height`.
pub fn png_gray8(
    width: usize,
    height: usize,
    data: &[u8],
    text: &[(&str, &str)],
) -> Result<Vec<u8>, ExportError> {
    assert_eq!(data.len(), width * height);
    png_bytes(
        width,
        height,
        png::ColorType::Grayscale,
        png::BitDepth::Eight,
        data,
        text,
        false,
    )
}

/// An 8-bit RGB PNG; `rgb` holds `width * height * 3` bytes.
///
/// # Errors
/// [`ExportError::Encode`] if the encoder fails.
///
/// # Panics
/// If `rgb.len() != 3 * width * height`.
pub fn png_rgb8(
    width: usize,
    height: usize,
    rgb: &[u8],
    text: &[(&str, &str)],
) -> Result<Vec<u8>, ExportError> {
    rgb8(width, height, rgb, text, false)
}

/// [`png_rgb8`] deflated by the PNG encoder's fast mode (`png::Compression::Fast`): the same
/// pixels in about a third of the encoding time, a larger file (the photometric fit's 30
/// re-rendered 640 x 480 captures: 5.8 MB at the default level, 6.7 MB fast).
///
/// # Errors
/// As [`png_rgb8`].
///
/// # Panics
/// As [`png_rgb8`].
pub fn png_rgb8_fast(
    width: usize,
    height: usize,
    rgb: &[u8],
    text: &[(&str, &str)],
) -> Result<Vec<u8>, ExportError> {
    rgb8(width, height, rgb, text, true)
}

/// [`png_rgb8`], fast or at the default level.
fn rgb8(
    width: usize,
    height: usize,
    rgb: &[u8],
    text: &[(&str, &str)],
    fast: bool,
) -> Result<Vec<u8>, ExportError> {
    assert_eq!(rgb.len(), 3 * width * height);
    png_bytes(
        width,
        height,
        png::ColorType::Rgb,
        png::BitDepth::Eight,
        rgb,
        text,
        fast,
    )
}

/// A 16-bit RGB PNG; `rgb` holds `width * height` pixels (big-endian in the file, as PNG
/// stores them).
///
/// # Errors
/// [`ExportError::Encode`] if the encoder fails.
///
/// # Panics
/// If `rgb.len() != width * height`.
pub fn png_rgb16(
    width: usize,
    height: usize,
    rgb: &[[u16; 3]],
    text: &[(&str, &str)],
) -> Result<Vec<u8>, ExportError> {
    rgb16(width, height, rgb, text, false)
}

/// [`png_rgb16`] deflated by the PNG encoder's fast mode, as [`png_rgb8_fast`].
///
/// # Errors
/// As [`png_rgb16`].
///
/// # Panics
/// As [`png_rgb16`].
pub fn png_rgb16_fast(
    width: usize,
    height: usize,
    rgb: &[[u16; 3]],
    text: &[(&str, &str)],
) -> Result<Vec<u8>, ExportError> {
    rgb16(width, height, rgb, text, true)
}

/// [`png_rgb16`], fast or at the default level.
fn rgb16(
    width: usize,
    height: usize,
    rgb: &[[u16; 3]],
    text: &[(&str, &str)],
    fast: bool,
) -> Result<Vec<u8>, ExportError> {
    assert_eq!(rgb.len(), width * height);
    let bytes: Vec<u8> = rgb
        .iter()
        .flat_map(|p| p.iter().flat_map(|c| c.to_be_bytes()))
        .collect();
    png_bytes(
        width,
        height,
        png::ColorType::Rgb,
        png::BitDepth::Sixteen,
        &bytes,
        text,
        fast,
    )
}

/// How a quantity is stored in a 16-bit PNG: `value = (count - offset_counts) * scale`,
/// count 0 = no value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Png16Encoding {
    /// Units per count (for depth: 0.001 mm, one micrometre).
    pub scale: f64,
    pub offset_counts: u16,
}

impl Png16Encoding {
    /// Counts of `values` (NaN -> 0); values that do not fit in 1..=65535 become 0 too. Returns
    /// the counts and the number of finite values that did not fit.
    pub fn encode(&self, values: &[f64]) -> (Vec<u16>, usize) {
        let mut clipped = 0;
        let counts = values
            .iter()
            .map(|v| {
                if !v.is_finite() {
                    return 0;
                }
                let c = (v / self.scale).round() + self.offset_counts as f64;
                if (1.0..=65535.0).contains(&c) {
                    c as u16
                } else {
                    clipped += 1;
                    0
                }
            })
            .collect();
        (counts, clipped)
    }
}

/// A colour-mapped preview (d3's Turbo map, `colorous`): `lo` maps to the dark blue end, `hi`
/// to the dark red end; NaN is black. Returns RGB bytes.
pub fn preview_rgb(values: &[f64], lo: f64, hi: f64) -> Vec<u8> {
    let span = if hi > lo { hi - lo } else { 1.0 };
    let mut out = Vec::with_capacity(3 * values.len());
    for v in values {
        if v.is_finite() {
            let c = colorous::TURBO.eval_continuous((v - lo) / span);
            out.extend_from_slice(&[c.r, c.g, c.b]);
        } else {
            out.extend_from_slice(&[0, 0, 0]);
        }
    }
    out
}

/// Width of the colour-bar panel [`with_colour_bar`] adds, px.
pub const COLOUR_BAR_PANEL_PX: usize = 100;

/// `rgb` (`width` x `height`, from [`preview_rgb`] of `lo`..`hi` mm) with a white panel of
/// [`COLOUR_BAR_PANEL_PX`] at its right: the Turbo scale as a bar, `hi` at the top and `lo` at
/// the bottom, each labelled in mm (and the middle). Returns the new width and the RGB bytes.
pub fn with_colour_bar(
    width: usize,
    height: usize,
    rgb: &[u8],
    lo: f64,
    hi: f64,
) -> (usize, Vec<u8>) {
    let w2 = width + COLOUR_BAR_PANEL_PX;
    let mut out = vec![255u8; 3 * w2 * height];
    for y in 0..height {
        out[3 * y * w2..3 * y * w2 + 3 * width]
            .copy_from_slice(&rgb[3 * y * width..3 * (y + 1) * width]);
    }
    let (top, bottom) = (
        10usize.min(height / 4),
        height.saturating_sub(10.min(height / 4)),
    );
    let x0 = width + 8;
    let mut put = |x: i64, y: i64, c: [u8; 3]| {
        if x >= 0 && y >= 0 && (x as usize) < w2 && (y as usize) < height {
            let i = 3 * (y as usize * w2 + x as usize);
            out[i..i + 3].copy_from_slice(&c);
        }
    };
    for y in top..bottom {
        let t = if bottom - 1 > top {
            (bottom - 1 - y) as f64 / (bottom - 1 - top) as f64
        } else {
            0.5
        };
        let c = colorous::TURBO.eval_continuous(t);
        for x in x0..x0 + 14 {
            put(x as i64, y as i64, [c.r, c.g, c.b]);
        }
    }
    let label = |v: f64| format!("{v:.2}mm");
    let tx = (x0 + 18) as i64;
    for (v, y) in [
        (hi, top as i64),
        (0.5 * (lo + hi), ((top + bottom) / 2) as i64 - 5),
        (lo, bottom as i64 - 10),
    ] {
        fabkit_designs::glyphs::draw_text(tx, y, &label(v), 2, |x, y| put(x, y, [0, 0, 0]));
    }
    (w2, out)
}

/// Unit vectors as RGB (`(n + 1) / 2 * 255`), NaN black: the usual normal-map preview.
pub fn normals_rgb(normals: &[[f64; 3]]) -> Vec<u8> {
    let mut out = Vec::with_capacity(3 * normals.len());
    for n in normals {
        if n.iter().all(|c| c.is_finite()) {
            out.extend(
                n.iter()
                    .map(|c| ((c + 1.0) * 127.5).round().clamp(0.0, 255.0) as u8),
            );
        } else {
            out.extend_from_slice(&[0, 0, 0]);
        }
    }
    out
}

/// One point of a PLY point cloud.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlyPoint {
    pub xyz: [f32; 3],
    pub normal: [f32; 3],
    /// Pixel column and row (written as PLY `int`, see [`ply_points`]).
    pub u: u16,
    pub v: u16,
    /// 1 on a protrusion (contact), else 0.
    pub contact: u8,
}

/// A binary little-endian PLY point cloud with per-point normal, pixel and contact flag;
/// `comments` go into the header (one line each, no newlines).
///
/// Properties: `float` x, y, z, nx, ny, nz; `int` u, v (pixel column, row); `uchar` contact.
/// u and v are `int`, not `ushort`: Open3D's tensor reader (`open3d.t.io.read_point_cloud`)
/// skips `char`, `short`, `ushort`, `uint` (and their `int8`/`int16`/`uint32` spellings) and
/// keeps `uchar`, `int`, `float`, `double` (and `uint8`/`uint16`/`int32`/`float32`/`float64`),
/// found by experiment with open3d 0.19; `int` is the classic PLY name every reader knows.
pub fn ply_points(points: &[PlyPoint], comments: &[String]) -> Vec<u8> {
    let mut h = String::from("ply\nformat binary_little_endian 1.0\n");
    for c in comments {
        h.push_str(&format!("comment {}\n", c.replace(['\n', '\r'], " ")));
    }
    h.push_str(&format!(
        "element vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty int u\nproperty int v\nproperty uchar contact\nend_header\n",
        points.len()
    ));
    let mut out = h.into_bytes();
    out.reserve(points.len() * 33);
    for p in points {
        for c in p.xyz.iter().chain(&p.normal) {
            out.extend_from_slice(&c.to_le_bytes());
        }
        out.extend_from_slice(&i32::from(p.u).to_le_bytes());
        out.extend_from_slice(&i32::from(p.v).to_le_bytes());
        out.push(p.contact);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn npy_header_is_padded_to_64_bytes_and_holds_the_shape() {
        let b = npy_f32(&[2, 3], &[0.0, 1.0, 2.0, 3.0, 4.0, 5.5]);
        let hlen = u16::from_le_bytes([b[8], b[9]]) as usize;
        assert_eq!((10 + hlen) % 64, 0);
        let h = std::str::from_utf8(&b[10..10 + hlen]).unwrap();
        assert!(h.contains("'shape': (2, 3)") && h.ends_with('\n'));
        assert_eq!(&b[10 + hlen + 20..], &5.5f32.to_le_bytes());
    }

    #[test]
    fn npy_files_read_back_and_bad_ones_are_refused() {
        let data = [0.0, 1.5, f32::NAN, -3.25, 7.0, 8.0];
        let (shape, back) = read_npy_f32(&npy_f32(&[1, 2, 3], &data)).unwrap();
        assert_eq!(shape, [1, 2, 3]);
        assert_eq!(back[1], 1.5);
        assert!(back[2].is_nan());
        assert_eq!(back[5], 8.0);
        let (shape, _) = read_npy_f32(&npy_f32(&[6], &data)).unwrap();
        assert_eq!(shape, [6]);
        let mut short = npy_f32(&[2, 3], &data);
        short.pop();
        assert!(read_npy_f32(&short).unwrap_err().contains("needs 24"));
        let f8 = npy_f32(&[2, 3], &data).to_vec();
        let text = String::from_utf8_lossy(&f8[10..74]).replace("<f4", "<f8");
        let mut bad = f8[..10].to_vec();
        bad.extend_from_slice(text.as_bytes());
        bad.extend_from_slice(&f8[74..]);
        assert!(read_npy_f32(&bad).unwrap_err().contains("float32"));
        assert!(read_npy_f32(b"not an npy file").is_err());
    }

    #[test]
    fn png16_encoding_rounds_and_marks_missing_and_clipped() {
        let e = Png16Encoding {
            scale: 0.001,
            offset_counts: 0,
        };
        let (c, clipped) = e.encode(&[12.3456, f64::NAN, -1.0, 70.0]);
        assert_eq!(c, vec![12346, 0, 0, 0]);
        assert_eq!(clipped, 2);
        let d = Png16Encoding {
            scale: 0.001,
            offset_counts: 32768,
        };
        assert_eq!(d.encode(&[-0.25]).0, vec![32518]);
    }
}
