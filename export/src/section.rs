//! `section.png`: the assembled sensor cut by the plane y = 0 through its axis, each member
//! filled in its own colour, x to the right and z up (sensor frame, docs/conventions.md). The
//! picture a maker checks first: the layer stack on the core, the housing and the parts in it.
//!
//! Each member's mesh is cut by the plane into segments, and each pixel row is filled between
//! successive crossings of the segments with the row's centre line (even-odd rule; a closed
//! mesh cuts into closed outlines). Members are drawn in assembly order on white.

use fabkit_designs::assembly::MemberKind;
use fabkit_designs::Mesh;
use serde::{Deserialize, Serialize};

/// Pixels per millimetre of the picture, unless the sensor is too large for
/// [`MAX_SIDE_PX`].
pub const PX_PER_MM: f64 = 20.0;
/// Largest width or height of the picture, px.
pub const MAX_SIDE_PX: f64 = 2000.0;
/// White space around the section, mm.
const MARGIN_MM: f64 = 2.0;
/// The band under the section that holds the scale bar, mm, and the bar's thickness, mm.
const BAR_BAND_MM: f64 = 3.0;
const BAR_THICKNESS_MM: f64 = 0.6;

/// Where the picture lies and what each colour is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SectionView {
    /// `section.png`, relative to the export directory.
    pub file: String,
    pub sha256: String,
    pub width_px: usize,
    pub height_px: usize,
    pub px_per_mm: f64,
    /// Sensor-frame (x, z) of the top-left corner of the top-left pixel, mm.
    pub origin_xz_mm: [f64; 2],
    /// One entry per member drawn, in drawing order.
    pub legend: Vec<SectionLegend>,
    /// The length of the black scale bar in the band under the section (its left end at the
    /// picture's margin), mm.
    #[serde(default)]
    pub scale_bar_mm: f64,
}

/// A member's colour in the picture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SectionLegend {
    pub name: String,
    pub kind: MemberKind,
    /// `#rrggbb`.
    pub colour: String,
    /// Area of the member's section, mm^2, from its outline (not from the pixels).
    pub area_mm2: f64,
}

/// Colours by kind, cycled within a kind: printed parts in greys, cast layers in distinct hues,
/// bought envelopes in pale tones.
fn colour(kind: MemberKind, index: usize) -> [u8; 3] {
    const PRINTED: [[u8; 3]; 3] = [[70, 70, 70], [110, 110, 110], [150, 150, 150]];
    const CAST: [[u8; 3]; 6] = [
        [110, 170, 230],
        [240, 200, 90],
        [200, 60, 60],
        [90, 180, 120],
        [170, 110, 200],
        [240, 140, 60],
    ];
    const BOUGHT: [[u8; 3]; 4] = [
        [170, 230, 230],
        [200, 240, 170],
        [250, 200, 220],
        [220, 220, 250],
    ];
    match kind {
        MemberKind::Printed => PRINTED[index % PRINTED.len()],
        MemberKind::Cast => CAST[index % CAST.len()],
        MemberKind::Bought => BOUGHT[index % BOUGHT.len()],
    }
}

/// The segments where the plane y = 0 cuts `mesh`, as ((x0, z0), (x1, z1)). A vertex on the
/// plane counts as on its positive side, so that every crossing is counted once.
pub fn cut_y0(mesh: &Mesh) -> Vec<[[f64; 2]; 2]> {
    let mut out = Vec::new();
    for t in &mesh.triangles {
        let p = t.map(|i| mesh.vertices[i as usize]);
        let side = p.map(|v| v[1] >= 0.0);
        if side[0] == side[1] && side[1] == side[2] {
            continue;
        }
        let mut hits = Vec::with_capacity(2);
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            if side[a] != side[b] {
                let (pa, pb) = (p[a], p[b]);
                let s = pa[1] / (pa[1] - pb[1]);
                hits.push([pa[0] + s * (pb[0] - pa[0]), pa[2] + s * (pb[2] - pa[2])]);
            }
        }
        if let [a, b] = hits[..] {
            // orient along e_y x n (n the outward normal): the outlines of a closed,
            // consistently oriented mesh then all turn the same way, holes the other way
            let (u, w) = (sub(p[1], p[0]), sub(p[2], p[0]));
            let n = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            let along = (b[0] - a[0]) * n[2] - (b[1] - a[1]) * n[0];
            out.push(if along >= 0.0 { [a, b] } else { [b, a] });
        }
    }
    out
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Area enclosed by cut segments, mm^2: the shoelace sum over the segments, which
/// [`cut_y0`] orients so that outlines turn one way and holes the other.
fn enclosed_area(segments: &[[[f64; 2]; 2]]) -> f64 {
    0.5 * segments
        .iter()
        .map(|[a, b]| a[0] * b[1] - b[0] * a[1])
        .sum::<f64>()
        .abs()
}

/// Renders the section of `members` (name, kind, mesh in the sensor frame) and returns the
/// RGB pixels with the picture's placement and legend (`file` and `sha256` left empty).
pub fn render(members: &[(&str, MemberKind, &Mesh)]) -> (Vec<u8>, SectionView) {
    let cuts: Vec<Vec<[[f64; 2]; 2]>> = members.iter().map(|(_, _, m)| cut_y0(m)).collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for seg in cuts.iter().flatten() {
        for p in seg {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    if !lo[0].is_finite() {
        (lo, hi) = ([0.0; 2], [1.0; 2]);
    }
    let (lo, hi) = (lo.map(|v| v - MARGIN_MM), hi.map(|v| v + MARGIN_MM));
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let px_per_mm = PX_PER_MM.min(MAX_SIDE_PX / extent);
    let width = ((hi[0] - lo[0]) * px_per_mm).ceil() as usize;
    let section_height = ((hi[1] - lo[1]) * px_per_mm).ceil() as usize;
    let height = section_height + (BAR_BAND_MM * px_per_mm).ceil() as usize;
    let mut rgb = vec![255u8; 3 * width * height];
    let mut counters = [0usize; 3];
    let mut legend = Vec::with_capacity(members.len());
    for ((name, kind, _), segments) in members.iter().zip(&cuts) {
        let k = match kind {
            MemberKind::Printed => 0,
            MemberKind::Cast => 1,
            MemberKind::Bought => 2,
        };
        let c = colour(*kind, counters[k]);
        counters[k] += 1;
        let mut xs: Vec<f64> = Vec::new();
        for row in 0..section_height {
            // z of the row's centre line (row 0 at the top)
            let z = hi[1] - (row as f64 + 0.5) / px_per_mm;
            xs.clear();
            for [a, b] in segments {
                let (z0, z1) = (a[1].min(b[1]), a[1].max(b[1]));
                if z0 <= z && z < z1 {
                    xs.push(a[0] + (z - a[1]) / (b[1] - a[1]) * (b[0] - a[0]));
                }
            }
            xs.sort_by(f64::total_cmp);
            for pair in xs.chunks_exact(2) {
                // columns whose centres lie between the two crossings
                let c0 = ((pair[0] - lo[0]) * px_per_mm - 0.5).ceil().max(0.0) as usize;
                let c1 = ((pair[1] - lo[0]) * px_per_mm - 0.5).floor();
                if c1 < 0.0 {
                    continue;
                }
                let c1 = (c1 as usize).min(width.saturating_sub(1));
                for col in c0..=c1 {
                    let i = 3 * (row * width + col);
                    rgb[i..i + 3].copy_from_slice(&c);
                }
            }
        }
        legend.push(SectionLegend {
            name: (*name).to_string(),
            kind: *kind,
            colour: format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]),
            area_mm2: enclosed_area(segments),
        });
    }
    // the scale bar: 10 mm (5 mm under a narrow section), black, in the band under it
    let scale_bar_mm = if hi[0] - lo[0] >= 10.0 + 2.0 * MARGIN_MM {
        10.0
    } else {
        5.0
    };
    let bar_row0 = section_height + ((BAR_BAND_MM - BAR_THICKNESS_MM) / 2.0 * px_per_mm) as usize;
    let bar_rows = (BAR_THICKNESS_MM * px_per_mm).round().max(1.0) as usize;
    let col0 = (MARGIN_MM * px_per_mm).round() as usize;
    let cols = (scale_bar_mm * px_per_mm).round() as usize;
    for row in bar_row0..(bar_row0 + bar_rows).min(height) {
        for col in col0..(col0 + cols).min(width) {
            let i = 3 * (row * width + col);
            rgb[i..i + 3].copy_from_slice(&[0, 0, 0]);
        }
    }
    let view = SectionView {
        file: String::new(),
        sha256: String::new(),
        width_px: width,
        height_px: height,
        px_per_mm,
        origin_xz_mm: [lo[0], hi[1]],
        legend,
        scale_bar_mm,
    };
    (rgb, view)
}
