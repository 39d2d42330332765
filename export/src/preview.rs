//! Shaded pictures of the printed parts and the print plates: `previews/<part>.png` (two views
//! of one part side by side) and `previews/plate_<plate>.png` (a plate seen from above-front
//! with its bed outline), also the `Metadata/thumbnail.png` of the 3MF files.
//!
//! A small software rasterizer, no GPU: orthographic projection fitted to the scene's
//! bounding box, back faces culled (every written mesh is a closed, outward-oriented
//! 2-manifold), a z-buffer, flat Lambert shading of each triangle's normal by a light fixed
//! relative to the viewer (above-left of the eye, so both views are lit alike), a dark
//! silhouette line around each object, on a light background. Everything is computed in f64
//! in one fixed order per picture, so the same meshes give the same bytes whatever the
//! thread count ([`part_pngs`] renders parts in parallel and keeps their order).
//!
//! Pixel (0, 0) is the top-left pixel; its centre is at (0.5, 0.5) in the rasterizer's
//! continuous coordinates. The pictures are for people; no number is read back from them.

use crate::ExportError;
use fabkit_designs::geometry::Mesh;
use fabkit_designs::primitives::{add, cross, dot, scale, sub, unit};
use rayon::prelude::*;

/// Width and height of one view of a part preview, px; the preview is two views side by side.
pub const PART_VIEW_PX: usize = 320;
/// Width of a part preview, px (two views).
pub const PART_WIDTH_PX: usize = 2 * PART_VIEW_PX;
/// Height of a part preview, px.
pub const PART_HEIGHT_PX: usize = PART_VIEW_PX;
/// Width of a plate picture, px.
pub const PLATE_WIDTH_PX: usize = 640;
/// Height of a plate picture, px.
pub const PLATE_HEIGHT_PX: usize = 480;
/// Background colour, RGB.
pub const BACKGROUND: [u8; 3] = [244, 245, 247];
/// Free border around the fitted scene, px.
const PAD_PX: f64 = 12.0;
/// Elevation of the isometric view, degrees: atan(1 / sqrt(2)).
const ISO_ELEVATION_DEG: f64 = 35.264_389_682_754_654;

/// The direction the viewer looks from: azimuth from the front (-y) towards +x, degrees, and
/// elevation above the xy plane, degrees (in (-90, 90)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewDirection {
    pub azimuth_deg: f64,
    pub elevation_deg: f64,
}

/// The two views of a part preview: isometric from above-front-right (what stands on the bed),
/// and isometric from below-back-left (the underside and the three faces the first view hides:
/// a mold's cavity or a shell's inside opening shows in one of them).
pub const PART_VIEWS: [ViewDirection; 2] = [
    ViewDirection {
        azimuth_deg: 45.0,
        elevation_deg: ISO_ELEVATION_DEG,
    },
    ViewDirection {
        azimuth_deg: 225.0,
        elevation_deg: -ISO_ELEVATION_DEG,
    },
];

/// The view of a plate picture: from above-front, a little to the right.
pub const PLATE_VIEW: ViewDirection = ViewDirection {
    azimuth_deg: 20.0,
    elevation_deg: 50.0,
};

/// Colour of a part in its preview, RGB.
const PART_COLOUR: [u8; 3] = [96, 140, 196];
/// Colours of the objects of a plate, cycled in plate order, RGB.
const PLATE_COLOURS: [[u8; 3]; 6] = [
    [96, 140, 196],
    [214, 132, 64],
    [92, 168, 112],
    [190, 90, 96],
    [150, 116, 190],
    [200, 176, 70],
];
const SILHOUETTE: [u8; 3] = [48, 52, 60];
const BED_FILL: [u8; 3] = [214, 216, 222];
const BED_EDGE: [u8; 3] = [90, 94, 104];
const BED_MARGIN: [u8; 3] = [160, 164, 172];

/// An RGB picture, row-major, 3 bytes a pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    pub width_px: usize,
    pub height_px: usize,
    pub rgb: Vec<u8>,
}

impl Image {
    /// The picture as PNG (8-bit RGB) with `description` in a tEXt chunk.
    ///
    /// # Errors
    /// [`ExportError::Encode`] if the encoder fails.
    pub fn png(&self, description: &str) -> Result<Vec<u8>, ExportError> {
        crate::raster::png_rgb8(
            self.width_px,
            self.height_px,
            &self.rgb,
            &[("Description", description)],
        )
    }
}

/// An object placed on a plate as by its 3MF build item: its meshes (the volumes, in part
/// coordinates), turned 90 deg about z (counter-clockwise from above) when `turned`, then
/// translated by `translation_mm`; `name` labels it in the plate picture's legend.
#[derive(Debug, Clone)]
pub struct PlacedObject<'a> {
    pub name: &'a str,
    pub meshes: Vec<&'a Mesh>,
    pub turned: bool,
    pub translation_mm: [f64; 3],
}

impl PlacedObject<'_> {
    fn place(&self, p: [f64; 3]) -> [f64; 3] {
        let t = self.translation_mm;
        let (x, y) = if self.turned {
            (-p[1], p[0])
        } else {
            (p[0], p[1])
        };
        [x + t[0], y + t[1], p[2] + t[2]]
    }
}

/// A printer's bed drawn under a plate: the plate from (0, 0) to `size_xy_mm` at z = 0, its
/// edge, and the margin kept clear inside it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BedOutline {
    pub size_xy_mm: [f64; 2],
    pub margin_mm: f64,
}

/// Orthographic camera fitted to a box, mapping into a viewport of the picture.
#[derive(Debug, Clone, Copy)]
struct Camera {
    right: [f64; 3],
    up: [f64; 3],
    /// Unit vector from the scene towards the viewer.
    toward: [f64; 3],
    light: [f64; 3],
    px_per_mm: f64,
    /// Scene (right, up) coordinates of the viewport's centre, mm.
    centre_mm: [f64; 2],
    /// Viewport: left column, width, height, px.
    x0_px: usize,
    width_px: usize,
    height_px: usize,
}

impl Camera {
    /// The camera looking from `dir` whose viewport (`x0_px`, width, height) holds every point
    /// of `points` with [`PAD_PX`] to spare.
    fn fitted(
        dir: ViewDirection,
        points: &[[f64; 3]],
        x0_px: usize,
        width_px: usize,
        height_px: usize,
    ) -> Self {
        let (az, el) = (dir.azimuth_deg.to_radians(), dir.elevation_deg.to_radians());
        let toward = [el.cos() * az.sin(), -el.cos() * az.cos(), el.sin()];
        let right = unit(cross([0.0, 0.0, 1.0], toward));
        let up = cross(toward, right);
        let light = unit(add(
            add(scale(right, -0.4), scale(up, 0.35)),
            scale(toward, 0.85),
        ));
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in points {
            let q = [dot(*p, right), dot(*p, up)];
            for k in 0..2 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        if !lo[0].is_finite() {
            (lo, hi) = ([0.0; 2], [1.0; 2]);
        }
        let extent = [(hi[0] - lo[0]).max(1e-9), (hi[1] - lo[1]).max(1e-9)];
        let px_per_mm = ((width_px as f64 - 2.0 * PAD_PX) / extent[0])
            .min((height_px as f64 - 2.0 * PAD_PX) / extent[1])
            .max(1e-9);
        Self {
            right,
            up,
            toward,
            light,
            px_per_mm,
            centre_mm: [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])],
            x0_px,
            width_px,
            height_px,
        }
    }

    /// Picture coordinates (x right, y down, px) and depth towards the viewer (mm) of `p`.
    fn project(&self, p: [f64; 3]) -> [f64; 3] {
        let r = dot(p, self.right) - self.centre_mm[0];
        let u = dot(p, self.up) - self.centre_mm[1];
        [
            self.x0_px as f64 + 0.5 * self.width_px as f64 + r * self.px_per_mm,
            0.5 * self.height_px as f64 - u * self.px_per_mm,
            dot(p, self.toward),
        ]
    }
}

/// A picture being drawn: colours, depth and the object id of every pixel (0 background,
/// 1 bed, 2, 3, ... objects).
struct Canvas {
    image: Image,
    depth: Vec<f64>,
    ids: Vec<u16>,
}

impl Canvas {
    fn new(width_px: usize, height_px: usize) -> Self {
        let n = width_px * height_px;
        Self {
            image: Image {
                width_px,
                height_px,
                rgb: BACKGROUND.repeat(n),
            },
            depth: vec![f64::NEG_INFINITY; n],
            ids: vec![0; n],
        }
    }

    fn set(&mut self, i: usize, c: [u8; 3]) {
        self.image.rgb[3 * i..3 * i + 3].copy_from_slice(&c);
    }

    /// Fills the triangle `p` (scene points, counter-clockwise seen from outside) with the
    /// z-buffer, Lambert-shaded in `colour` (or flat when `shaded` is false); back faces are
    /// skipped.
    fn triangle(&mut self, cam: &Camera, p: [[f64; 3]; 3], colour: [u8; 3], shaded: bool, id: u16) {
        let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
        let facing = dot(n, cam.toward);
        if facing <= 0.0 {
            return;
        }
        let c = if shaded {
            let len = dot(n, n).sqrt();
            let lambert = (dot(n, cam.light) / len).max(0.0);
            let k = 0.3 + 0.7 * lambert;
            colour.map(|v| (f64::from(v) * k).round().clamp(0.0, 255.0) as u8)
        } else {
            colour
        };
        let [a, b, d] = p.map(|q| cam.project(q));
        // front faces turn clockwise on the picture (its y points down): area < 0
        let area = edge(a, b, d);
        if area == 0.0 || !area.is_finite() {
            return;
        }
        let x_lo = cam.x0_px as f64;
        let x_hi = (cam.x0_px + cam.width_px) as f64 - 1.0;
        let y_hi = cam.height_px.min(self.image.height_px) as f64 - 1.0;
        let min_x = (a[0].min(b[0]).min(d[0]) - 0.5).ceil().max(x_lo);
        let max_x = (a[0].max(b[0]).max(d[0]) - 0.5).floor().min(x_hi);
        let min_y = (a[1].min(b[1]).min(d[1]) - 0.5).ceil().max(0.0);
        let max_y = (a[1].max(b[1]).max(d[1]) - 0.5).floor().min(y_hi);
        if min_x > max_x || min_y > max_y {
            return;
        }
        let w = self.image.width_px;
        for row in min_y as usize..=max_y as usize {
            let y = row as f64 + 0.5;
            for col in min_x as usize..=max_x as usize {
                let q = [col as f64 + 0.5, y, 0.0];
                let (wa, wb, wd) = (
                    edge(b, d, q) / area,
                    edge(d, a, q) / area,
                    edge(a, b, q) / area,
                );
                if wa < 0.0 || wb < 0.0 || wd < 0.0 {
                    continue;
                }
                let z = wa * a[2] + wb * b[2] + wd * d[2];
                let i = row * w + col;
                if z > self.depth[i] {
                    self.depth[i] = z;
                    self.ids[i] = id;
                    self.set(i, c);
                }
            }
        }
    }

    /// Every triangle of `mesh`, each point moved by `place`.
    fn mesh(
        &mut self,
        cam: &Camera,
        mesh: &Mesh,
        place: impl Fn([f64; 3]) -> [f64; 3],
        colour: [u8; 3],
        id: u16,
    ) {
        let placed: Vec<[f64; 3]> = mesh.vertices.iter().map(|&v| place(v)).collect();
        for t in &mesh.triangles {
            let p = t.map(|i| placed[i as usize]);
            self.triangle(cam, p, colour, true, id);
        }
    }

    /// A one-pixel line from `p0` to `p1` drawn on the background and the bed only (what is
    /// drawn there later covers it).
    fn line(&mut self, cam: &Camera, p0: [f64; 3], p1: [f64; 3], colour: [u8; 3]) {
        let (a, b) = (cam.project(p0), cam.project(p1));
        let steps = ((b[0] - a[0]).abs().max((b[1] - a[1]).abs()) * 2.0).ceil() as usize + 1;
        let (w, h) = (self.image.width_px as f64, self.image.height_px as f64);
        for s in 0..=steps {
            let t = s as f64 / steps as f64;
            let (x, y) = (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
            if x >= 0.0 && y >= 0.0 && x < w && y < h {
                let i = y as usize * self.image.width_px + x as usize;
                if self.ids[i] <= 1 {
                    self.set(i, colour);
                }
            }
        }
    }

    /// Darkens every object pixel (id >= 2) next to a pixel of another id: the objects'
    /// outlines.
    fn silhouettes(&mut self) {
        let (w, h) = (self.image.width_px, self.image.height_px);
        let mut edge_px = Vec::new();
        for row in 0..h {
            for col in 0..w {
                let i = row * w + col;
                let id = self.ids[i];
                if id < 2 {
                    continue;
                }
                let differs = (col > 0 && self.ids[i - 1] != id)
                    || (col + 1 < w && self.ids[i + 1] != id)
                    || (row > 0 && self.ids[i - w] != id)
                    || (row + 1 < h && self.ids[i + w] != id);
                if differs {
                    edge_px.push(i);
                }
            }
        }
        for i in edge_px {
            self.set(i, SILHOUETTE);
        }
    }
}

/// The eight corners of the box of `points`.
fn box_corners(points: impl Iterator<Item = [f64; 3]>) -> Vec<[f64; 3]> {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if !lo[0].is_finite() {
        return Vec::new();
    }
    let mut out = Vec::with_capacity(8);
    for k in 0..8 {
        out.push([
            if k & 1 == 0 { lo[0] } else { hi[0] },
            if k & 2 == 0 { lo[1] } else { hi[1] },
            if k & 4 == 0 { lo[2] } else { hi[2] },
        ]);
    }
    out
}

/// The preview of one part: [`PART_VIEWS`] side by side, each fitted to the part's bounding
/// box, [`PART_WIDTH_PX`] x [`PART_HEIGHT_PX`] px.
pub fn render_part(mesh: &Mesh) -> Image {
    let corners = box_corners(mesh.vertices.iter().copied());
    let mut canvas = Canvas::new(PART_WIDTH_PX, PART_HEIGHT_PX);
    for (k, dir) in PART_VIEWS.iter().enumerate() {
        let cam = Camera::fitted(
            *dir,
            &corners,
            k * PART_VIEW_PX,
            PART_VIEW_PX,
            PART_HEIGHT_PX,
        );
        canvas.mesh(&cam, mesh, |p| p, PART_COLOUR, 2);
    }
    canvas.silhouettes();
    canvas.image
}

/// The PNG previews of `parts` (name, mesh), in the given order, rendered in parallel.
///
/// # Errors
/// [`ExportError::Encode`] if the PNG encoder fails.
pub fn part_pngs(parts: &[(&str, &Mesh)]) -> Result<Vec<Vec<u8>>, ExportError> {
    parts
        .par_iter()
        .map(|(name, mesh)| {
            render_part(mesh).png(&format!(
                "fabkit preview of part {name}: isometric from above-front-right (left) and from below-back-left (right), print orientation"
            ))
        })
        .collect()
}

/// A plate picture ([`PLATE_WIDTH_PX`] x [`PLATE_HEIGHT_PX`] px): `objects` as placed by their
/// build items, each in its own colour, seen from [`PLATE_VIEW`], on the bed when `bed` is
/// given (its plate, edge and margin line, and a legend in the top-left corner naming the
/// objects and the bed's size, [`legend_lines`]).
pub fn render_plate(objects: &[PlacedObject<'_>], bed: Option<BedOutline>) -> Image {
    draw_plate(objects, bed).0.image
}

/// [`render_plate`] with the canvas (for its object ids) and camera.
fn draw_plate(objects: &[PlacedObject<'_>], bed: Option<BedOutline>) -> (Canvas, Camera) {
    let placed = objects.iter().flat_map(|o| {
        o.meshes
            .iter()
            .flat_map(move |m| m.vertices.iter().map(move |&v| o.place(v)))
    });
    let mut points = box_corners(placed);
    let bed_corners = bed.map(|b| {
        let [x, y] = b.size_xy_mm;
        [[0.0, 0.0, 0.0], [x, 0.0, 0.0], [x, y, 0.0], [0.0, y, 0.0]]
    });
    if let Some(c) = &bed_corners {
        let top = points.iter().map(|p| p[2]).fold(0.0_f64, f64::max);
        points.extend(c);
        points.extend(c.iter().map(|p| [p[0], p[1], top]));
    }
    let cam = Camera::fitted(PLATE_VIEW, &points, 0, PLATE_WIDTH_PX, PLATE_HEIGHT_PX);
    let mut canvas = Canvas::new(PLATE_WIDTH_PX, PLATE_HEIGHT_PX);
    if let (Some(b), Some(c)) = (bed, bed_corners) {
        canvas.triangle(&cam, [c[0], c[1], c[2]], BED_FILL, false, 1);
        canvas.triangle(&cam, [c[0], c[2], c[3]], BED_FILL, false, 1);
        let [x, y] = b.size_xy_mm;
        let m = b.margin_mm;
        let inner = [
            [m, m, 0.0],
            [x - m, m, 0.0],
            [x - m, y - m, 0.0],
            [m, y - m, 0.0],
        ];
        for k in 0..4 {
            canvas.line(&cam, inner[k], inner[(k + 1) % 4], BED_MARGIN);
        }
        for k in 0..4 {
            canvas.line(&cam, c[k], c[(k + 1) % 4], BED_EDGE);
        }
    }
    let colours = object_colours(objects);
    for (k, o) in objects.iter().enumerate() {
        let id = u16::try_from(k + 2).unwrap_or(u16::MAX);
        let colour = colours[k];
        for m in &o.meshes {
            canvas.mesh(&cam, m, |p| o.place(p), colour, id);
        }
    }
    canvas.silhouettes();
    // a plate's picture names its parts and its bed (the kit's picture, on no bed, does not)
    if bed.is_some() {
        legend(&mut canvas, objects, bed);
    }
    (canvas, cam)
}

/// Each object's colour: that of its name, in the order names first appear (the copies of a
/// part alike, one part's colour per row of the legend).
fn object_colours(objects: &[PlacedObject<'_>]) -> Vec<[u8; 3]> {
    let mut names: Vec<&str> = Vec::new();
    objects
        .iter()
        .map(|o| {
            let k = names.iter().position(|n| *n == o.name).unwrap_or_else(|| {
                names.push(o.name);
                names.len() - 1
            });
            PLATE_COLOURS[k % PLATE_COLOURS.len()]
        })
        .collect()
}

/// The colour of the legend's text.
const LABEL: [u8; 3] = [40, 44, 52];
/// Font pixels per legend glyph pixel ([`fabkit_designs::glyphs`]: 3 x 5).
const LABEL_SCALE: i64 = 2;
/// The legend's first row's top-left corner and its rows' pitch, px.
const LEGEND_AT_PX: i64 = 6;
const LEGEND_ROW_PX: i64 = 7 * LABEL_SCALE;

/// The lines of a plate picture's legend: one per object name, in order of first appearance,
/// with its objects' colour ([`object_colours`]) and the name in capitals with its count when the plate
/// holds several (`PIN x29`); then the bed's size (`BED 250 x 210 mm`, no colour).
fn legend_lines(
    objects: &[PlacedObject<'_>],
    bed: Option<BedOutline>,
) -> Vec<(Option<[u8; 3]>, String)> {
    let mut rows: Vec<(&str, usize, [u8; 3])> = Vec::new();
    for (o, colour) in objects.iter().zip(object_colours(objects)) {
        match rows.iter_mut().find(|r| r.0 == o.name) {
            Some(r) => r.1 += 1,
            None => rows.push((o.name, 1, colour)),
        }
    }
    let mut lines: Vec<(Option<[u8; 3]>, String)> = rows
        .into_iter()
        .map(|(name, n, colour)| {
            let name = name.to_uppercase();
            (
                Some(colour),
                if n > 1 { format!("{name} x{n}") } else { name },
            )
        })
        .collect();
    if let Some(b) = bed {
        lines.push((
            None,
            format!("BED {} x {} mm", b.size_xy_mm[0], b.size_xy_mm[1]),
        ));
    }
    lines
}

/// Draws the legend ([`legend_lines`]) over the picture's top-left corner, each line on a box
/// of the background's colour: a swatch of the object's colour, then its text.
fn legend(canvas: &mut Canvas, objects: &[PlacedObject<'_>], bed: Option<BedOutline>) {
    let (w, h) = (canvas.image.width_px as i64, canvas.image.height_px as i64);
    let fill = |canvas: &mut Canvas, x0: i64, y0: i64, x1: i64, y1: i64, c: [u8; 3]| {
        for y in y0.max(0)..y1.min(h) {
            for x in x0.max(0)..x1.min(w) {
                canvas.set((y * w + x) as usize, c);
            }
        }
    };
    let glyph_px = 5 * LABEL_SCALE;
    for (r, (swatch, text)) in legend_lines(objects, bed).iter().enumerate() {
        let y = LEGEND_AT_PX + r as i64 * LEGEND_ROW_PX;
        if y + glyph_px > h {
            break;
        }
        let text_x = LEGEND_AT_PX + glyph_px + 2 * LABEL_SCALE;
        let text_w = 4 * LABEL_SCALE * text.chars().count() as i64;
        fill(
            canvas,
            LEGEND_AT_PX - 2,
            y - 2,
            text_x + text_w + 2,
            y + glyph_px + 2,
            BACKGROUND,
        );
        if let Some(c) = swatch {
            fill(
                canvas,
                LEGEND_AT_PX,
                y,
                LEGEND_AT_PX + glyph_px,
                y + glyph_px,
                *c,
            );
        }
        fabkit_designs::glyphs::draw_text(text_x, y, text, LABEL_SCALE, |x, y| {
            if (0..w).contains(&x) && (0..h).contains(&y) {
                canvas.set((y * w + x) as usize, LABEL);
            }
        });
    }
}

/// Twice the signed area of the picture-plane triangle (a, b, c) (x and y only).
fn edge(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

#[cfg(test)]
mod tests {
    use super::*;
    use fabkit_designs::geometry::cuboid;

    fn cube(lo: [f64; 3], side: f64) -> Mesh {
        cuboid(lo, [lo[0] + side, lo[1] + side, lo[2] + side])
            .unwrap()
            .mesh()
    }

    fn covered(img: &Image, x0: usize, x1: usize) -> usize {
        let mut n = 0;
        for row in 0..img.height_px {
            for col in x0..x1 {
                let i = 3 * (row * img.width_px + col);
                if img.rgb[i..i + 3] != BACKGROUND {
                    n += 1;
                }
            }
        }
        n
    }

    #[test]
    fn cube_preview_covers_its_projected_hexagon_in_each_view() {
        let side = 10.0;
        let img = render_part(&cube([3.0, -2.0, 0.0], side));
        assert_eq!((img.width_px, img.height_px), (640, 320));
        for (k, dir) in PART_VIEWS.iter().enumerate() {
            // a box seen along d covers side^2 (|d_x| + |d_y| + |d_z|); the fit scales the
            // wider of its extents along right and up to the viewport less the padding
            let cam = Camera::fitted(*dir, &[[0.0; 3]], 0, PART_VIEW_PX, PART_HEIGHT_PX);
            let sum_abs = |v: [f64; 3]| v.iter().map(|c| c.abs()).sum::<f64>();
            let usable = PART_VIEW_PX as f64 - 2.0 * PAD_PX;
            let px_per_mm =
                (usable / (side * sum_abs(cam.right))).min(usable / (side * sum_abs(cam.up)));
            let expected = side * side * sum_abs(cam.toward) * px_per_mm * px_per_mm;
            let n = covered(&img, k * PART_VIEW_PX, (k + 1) * PART_VIEW_PX) as f64;
            assert!(
                (n - expected).abs() < 0.02 * expected,
                "view {k}: {n} px, expected {expected}"
            );
            // three faces in three shades (plus the silhouette)
            let mut shades: Vec<[u8; 3]> = Vec::new();
            for row in 0..PART_HEIGHT_PX {
                for col in k * PART_VIEW_PX..(k + 1) * PART_VIEW_PX {
                    let i = 3 * (row * img.width_px + col);
                    let c = [img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]];
                    if c != BACKGROUND && !shades.contains(&c) {
                        shades.push(c);
                    }
                }
            }
            assert_eq!(shades.len(), 4, "view {k}: {shades:?}");
        }
    }

    #[test]
    fn previews_are_the_same_bytes_whatever_the_thread_count() {
        let meshes = [cube([0.0; 3], 5.0), cube([1.0, 2.0, 0.0], 20.0)];
        let parts: Vec<(&str, &Mesh)> = vec![("a", &meshes[0]), ("b", &meshes[1])];
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| part_pngs(&parts).unwrap())
        };
        let one = run(1);
        assert_eq!(one, run(2));
        assert_eq!(one, run(2));
        assert_eq!(one.len(), 2);
        assert_eq!(&one[0][1..4], b"PNG");
        // same mesh, same picture, wherever the part lies
        let moved = cube([40.0, 40.0, 0.0], 5.0);
        assert_eq!(render_part(&moved), render_part(&meshes[0]));
    }

    #[test]
    fn plate_picture_shows_each_object_inside_the_bed_outline() {
        let (a, b) = (cube([0.0; 3], 10.0), cube([0.0; 3], 6.0));
        let objects = [
            PlacedObject {
                name: "a",
                meshes: vec![&a],
                turned: false,
                translation_mm: [10.0, 10.0, 0.0],
            },
            PlacedObject {
                name: "b",
                meshes: vec![&b],
                turned: true,
                translation_mm: [80.0, 60.0, 0.0],
            },
        ];
        let bed = BedOutline {
            size_xy_mm: [100.0, 80.0],
            margin_mm: 5.0,
        };
        let (canvas, cam) = draw_plate(&objects, Some(bed));
        assert_eq!(
            (canvas.image.width_px, canvas.image.height_px),
            (PLATE_WIDTH_PX, PLATE_HEIGHT_PX)
        );
        let quad = [[0.0, 0.0], [100.0, 0.0], [100.0, 80.0], [0.0, 80.0]]
            .map(|[x, y]| cam.project([x, y, 0.0]));
        let inside =
            |x: f64, y: f64| (0..4).all(|k| edge(quad[k], quad[(k + 1) % 4], [x, y, 0.0]) <= 0.0);
        let w = canvas.image.width_px;
        let mut seen = [0usize; 4];
        for (i, &id) in canvas.ids.iter().enumerate() {
            seen[usize::from(id)] += 1;
            if id >= 2 {
                let (x, y) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
                assert!(
                    inside(x, y),
                    "object {id} at pixel ({x}, {y}) outside the bed"
                );
            }
        }
        // the bed and both objects show; the larger object covers more
        assert!(seen[1] > 10 * seen[2], "{seen:?}");
        assert!(seen[2] > seen[3] && seen[3] > 50, "{seen:?}");
        // the bed's edge is drawn in its colour
        let edge_px = canvas
            .image
            .rgb
            .chunks_exact(3)
            .filter(|c| *c == BED_EDGE)
            .count();
        assert!(edge_px > 500, "{edge_px}");
        // without a bed: the objects only
        let bare = render_plate(&objects, None);
        assert!(!bare.rgb.chunks_exact(3).any(|c| c == BED_FILL));
    }

    /// The plate picture's legend: a row per part name (copies counted, one colour each), then
    /// the bed's size; each row's swatch in its objects' colour and its text drawn.
    #[test]
    fn plate_picture_names_its_parts_and_bed() {
        let (a, b) = (cube([0.0; 3], 10.0), cube([0.0; 3], 6.0));
        let at = |name, m, x| PlacedObject {
            name,
            meshes: vec![m],
            turned: false,
            translation_mm: [x, 40.0, 0.0],
        };
        let objects = [
            at("pin", &a, 20.0),
            at("dome", &b, 40.0),
            at("pin", &a, 60.0),
        ];
        let bed = BedOutline {
            size_xy_mm: [145.0, 140.5],
            margin_mm: 5.0,
        };
        let lines = legend_lines(&objects, Some(bed));
        assert_eq!(
            lines,
            vec![
                (Some(PLATE_COLOURS[0]), "PIN x2".to_string()),
                (Some(PLATE_COLOURS[1]), "DOME".to_string()),
                (None, "BED 145 x 140.5 mm".to_string()),
            ]
        );
        let (canvas, _) = draw_plate(&objects, Some(bed));
        let w = canvas.image.width_px;
        let px = |x: i64, y: i64| {
            let i = 3 * (y as usize * w + x as usize);
            [
                canvas.image.rgb[i],
                canvas.image.rgb[i + 1],
                canvas.image.rgb[i + 2],
            ]
        };
        for (r, (swatch, text)) in lines.iter().enumerate() {
            let y = LEGEND_AT_PX + r as i64 * LEGEND_ROW_PX;
            if let Some(c) = swatch {
                assert_eq!(px(LEGEND_AT_PX + 2, y + 2), *c, "row {r}");
            }
            let x0 = LEGEND_AT_PX + 7 * LABEL_SCALE;
            let x1 = x0 + 4 * LABEL_SCALE * text.chars().count() as i64;
            let inked = (x0..x1)
                .flat_map(|x| (y..y + 5 * LABEL_SCALE).map(move |y| (x, y)))
                .filter(|&(x, y)| px(x, y) == LABEL)
                .count();
            assert!(inked > 8 * text.len(), "row {r}: {inked} px of text");
        }
        // both pins drawn in the pins' colour
        assert_eq!(
            object_colours(&objects),
            [PLATE_COLOURS[0], PLATE_COLOURS[1], PLATE_COLOURS[0]]
        );
    }
}
