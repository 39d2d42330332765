//! The memory budget of a ground-truth render and the least skin a camera must see: every
//! per-pixel buffer of a run is estimated before any is allocated (`fabkit groundtruth`,
//! `fabkit.DepthRenderer`).

/// Memory the render may take, bytes: 2 GiB. Every per-pixel buffer of a run is estimated
/// ([`render_memory`]) and a camera image whose render would need more is refused before
/// anything is allocated; configurations are rendered as many at a time as fit in it.
pub const MEMORY_BUDGET_BYTES: u64 = 2 << 30;

/// Bytes per pixel that stay allocated while the configurations are rendered: the rays
/// (sensor-frame directions and camera-frame bearings, 48), the reference hits (range, normal,
/// contact, exit: 41) and the reference frame (range, z-depth, point, normal, contact: 65),
/// rounded up; the rays' construction briefly holds them twice (+48), before any frame.
pub const FIXED_BYTES_PER_PIXEL: u64 = 160;

/// Bytes per pixel of one frame being rendered and encoded: its hits (41) and depth frame
/// (65), the differences to the reference (16, twice), the float32 arrays, the 16-bit and
/// preview PNGs, the normals, the PLY points and their encoded bytes (about 130 at the peak),
/// and the PNG and deflate encoders' working copies, rounded up. The image of `--images`
/// (radiance 24, counts 6, its PNG) is made after the frame's depth files are written and
/// dropped, within the same bytes.
pub const FRAME_BYTES_PER_PIXEL: u64 = 320;

/// Bytes besides the per-pixel buffers: the program, thread stacks, the fixtures and the
/// manifest.
pub const BASE_MEMORY_BYTES: u64 = 128 << 20;

/// Largest `--max-pixels`: the largest image whose render, one frame at a time, fits in
/// [`MEMORY_BUDGET_BYTES`] (4194304 = 2048 x 2048; a 2 MP camera, 1920 x 1080, and a
/// 2048 x 1536 one fit).
pub const MAX_PIXELS_LIMIT: u64 = 2048 * 2048;

/// Default bound on the camera image, pixels (`--max-pixels`, `DepthRenderer(max_pixels=)`):
/// the largest, [`MAX_PIXELS_LIMIT`].
pub const DEFAULT_MAX_PIXELS: u64 = MAX_PIXELS_LIMIT;

/// Memory a render of `pixels` pixels takes with `frames_at_once` frames rendered at a time,
/// bytes (an upper bound; see [`FIXED_BYTES_PER_PIXEL`], [`FRAME_BYTES_PER_PIXEL`]).
pub fn render_memory(pixels: u64, frames_at_once: u64) -> u64 {
    pixels
        .saturating_mul(
            FIXED_BYTES_PER_PIXEL
                .saturating_add(FRAME_BYTES_PER_PIXEL.saturating_mul(frames_at_once)),
        )
        .saturating_add(BASE_MEMORY_BYTES)
}

/// How many frames of `pixels` pixels to render at a time: at most `threads`, and as many as
/// fit in [`MEMORY_BUDGET_BYTES`] besides the fixed buffers (at least 1: `--max-pixels`
/// guarantees that one fits).
pub fn frames_at_once(pixels: u64, threads: u64) -> usize {
    let fit = (1..=threads.max(1))
        .take_while(|&k| render_memory(pixels, k) <= MEMORY_BUDGET_BYTES)
        .last()
        .unwrap_or(1);
    fit as usize
}

/// Smallest fraction of the image's pixels that must see the skin: a camera that sees less
/// (focal length, principal point or pose far off) would give a dataset of empty maps.
pub const MIN_SKIN_FRACTION: f64 = 0.01;

/// Pixels of an image of `image_pixels` that must see the skin: [`MIN_SKIN_FRACTION`] of
/// them, rounded up, and at least 1.
pub fn min_skin_pixels(image_pixels: u64) -> u64 {
    (MIN_SKIN_FRACTION * image_pixels as f64).ceil().max(1.0) as u64
}
