//! PNG writers: the fast-deflated images hold the same pixels as the default ones.

use fabkit_export::raster::{png_rgb16, png_rgb16_fast, png_rgb8, png_rgb8_fast};

/// The decoded bytes of a PNG (16-bit samples big-endian, as PNG stores them).
fn decoded(png_bytes: &[u8]) -> Vec<u8> {
    let mut reader = png::Decoder::new(std::io::Cursor::new(png_bytes))
        .read_info()
        .unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    buf
}

#[test]
fn the_fast_pngs_hold_the_default_ones_pixels() {
    let (w, h) = (64, 48);
    // a noisy image with smooth parts, as a rendered capture is
    let value = |k: usize| ((k as f64 * 0.01).sin() * 90.0 + 120.0 + (k * 7919 % 13) as f64) as u16;
    let rgb8: Vec<u8> = (0..3 * w * h).map(|k| value(k) as u8).collect();
    let rgb16: Vec<[u16; 3]> = (0..w * h)
        .map(|i| std::array::from_fn(|c| value(3 * i + c) * 251))
        .collect();
    let (slow8, fast8) = (
        png_rgb8(w, h, &rgb8, &[]).unwrap(),
        png_rgb8_fast(w, h, &rgb8, &[]).unwrap(),
    );
    assert_ne!(slow8, fast8, "the fast mode deflates otherwise");
    assert_eq!(decoded(&fast8), rgb8);
    assert_eq!(decoded(&slow8), rgb8);
    let (slow16, fast16) = (
        png_rgb16(w, h, &rgb16, &[]).unwrap(),
        png_rgb16_fast(w, h, &rgb16, &[]).unwrap(),
    );
    assert_ne!(slow16, fast16, "the fast mode deflates otherwise");
    let be: Vec<u8> = rgb16
        .iter()
        .flatten()
        .flat_map(|v| v.to_be_bytes())
        .collect();
    assert_eq!(decoded(&fast16), be);
    assert_eq!(decoded(&slow16), be);
}
