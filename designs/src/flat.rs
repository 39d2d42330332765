//! Flat skins: a rounded-rectangle outline with a layer stack through its thickness, internal
//! liquid channels in a layer, and a grid of 3D markers on a face (Soter et al., Sec. II-A:
//! an Ecoflex 00-10 skin of two cast layers, 16 liquid-filled channels in the top layer and a
//! 10 x 10 grid of markers on the bottom layer; flat gels such as GelSight and DIGIT).
//!
//! Frame (docs/conventions.md, flat skins): x across the outline's width, y along its length,
//! z up through the thickness from the base plane z = 0 (the camera's side, under the
//! innermost layer) to the contact face; the outline centred on the z axis. Channels run along
//! +y from the near edge (y = -length / 2), where they open for their tubes, to a closed far
//! end; markers stand on the base plane's face, towards the camera.

use crate::error::ParamError;
use crate::geometry::{cuboid, prism, ChordTolerance, GeometryError, Solid};
use crate::markers::{feature_solid, FeatureShape, Polarity};
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI};

/// The outline of a flat skin: a rectangle `width_mm` (x) by `length_mm` (y) with corners
/// rounded to `corner_radius_mm`, centred on the z axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlatOutline {
    /// Across x, mm, > 0.
    pub width_mm: f64,
    /// Along y (the channels' direction), mm, > 0.
    pub length_mm: f64,
    /// Corner radius, mm, in [0, half the shorter side).
    #[serde(default)]
    pub corner_radius_mm: f64,
}

impl FlatOutline {
    /// Exact area, mm^2: w l - (4 - pi) r^2.
    pub fn area_mm2(&self) -> f64 {
        let r = self.corner_radius_mm;
        self.width_mm * self.length_mm - (4.0 - PI) * r * r
    }

    /// The outline as a convex counter-clockwise polygon, its corner arcs inscribed within
    /// `tol` (vertices on the arcs).
    pub fn polygon(&self, tol: ChordTolerance) -> Vec<[f64; 2]> {
        let (hw, hl, r) = (
            self.width_mm / 2.0,
            self.length_mm / 2.0,
            self.corner_radius_mm,
        );
        if r <= 0.0 {
            return vec![[-hw, -hl], [hw, -hl], [hw, hl], [-hw, hl]];
        }
        let per_quarter = tol.circle_segments(r).div_ceil(4).max(1);
        let mut pts = Vec::with_capacity(4 * (per_quarter + 1));
        // corner centres counter-clockwise from the (+x, -y) corner, each arc's start angle
        for (k, (cx, cy)) in [
            (hw - r, -hl + r),
            (hw - r, hl - r),
            (-hw + r, hl - r),
            (-hw + r, -hl + r),
        ]
        .into_iter()
        .enumerate()
        {
            let a0 = -FRAC_PI_2 + k as f64 * FRAC_PI_2;
            for i in 0..=per_quarter {
                let a = a0 + FRAC_PI_2 * i as f64 / per_quarter as f64;
                let p = [cx + r * a.cos(), cy + r * a.sin()];
                if pts.last() != Some(&p) {
                    pts.push(p);
                }
            }
        }
        pts
    }

    /// Distance from `(x, y)` inside the outline to its edge, mm (negative outside).
    pub fn inset_mm(&self, [x, y]: [f64; 2]) -> f64 {
        let (hw, hl, r) = (
            self.width_mm / 2.0,
            self.length_mm / 2.0,
            self.corner_radius_mm,
        );
        let (dx, dy) = (x.abs() - (hw - r), y.abs() - (hl - r));
        if dx > 0.0 && dy > 0.0 {
            r - dx.hypot(dy)
        } else {
            (hw - x.abs()).min(hl - y.abs())
        }
    }

    /// Every violation under `prefix` (`body.`).
    pub fn errors(&self, prefix: &str) -> Vec<ParamError> {
        let mut errs = Vec::new();
        crate::parts::check_positive(
            prefix,
            &[("width_mm", self.width_mm), ("length_mm", self.length_mm)],
            &mut errs,
        );
        let half = self.width_mm.min(self.length_mm) / 2.0;
        if !(self.corner_radius_mm >= 0.0 && self.corner_radius_mm < half) && errs.is_empty() {
            errs.push(ParamError::new(
                format!("{prefix}corner_radius_mm"),
                self.corner_radius_mm,
                format!("must be 0 or more and below half the shorter side ({half} mm)"),
            ));
        }
        errs
    }
}

/// What closes a channel's liquid circuit (Soter et al. Sec. II-A: "each channel is closed at
/// both ends, this ensures that the liquid always returns back to its initial state"; and
/// "the internal chambers are closed on one end", which is why they are filled in a tank).
/// The channel in the skin is the same either way: closed at its far end, open at the near
/// edge into its tube.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ChannelEnds {
    /// The tube's display end is sealed once filled: the liquid cannot leave the circuit.
    #[default]
    BothClosed,
    /// The display end stays open to the air.
    OneClosed,
}

/// The silicone tube glued into a channel's open end (Sil-Poxy, Soter et al. Sec. II-A).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelTube {
    /// Outer diameter, mm: at least the channel's width and height, so that it seals the
    /// channel's mouth by stretching it.
    pub outer_diameter_mm: f64,
    /// Inner diameter, mm, below the outer.
    pub inner_diameter_mm: f64,
    /// From the skin to the display, mm.
    pub length_mm: f64,
    /// How far it is pushed into the channel, mm, below the channel's length.
    pub insertion_mm: f64,
}

/// Straight channels of rectangular section in one layer, along y, side by side across x at
/// `pitch_mm`, centred on the axis: grooves in the layer's bottom face, closed by the layer
/// under it, open at the near edge for their tubes and closed `length_mm` from it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelSet {
    pub count: usize,
    /// Across x, mm.
    pub width_mm: f64,
    /// Up z from the layer's bottom face, mm.
    pub height_mm: f64,
    /// Centre to centre, mm.
    pub pitch_mm: f64,
    /// From the near edge to the closed far end, mm.
    pub length_mm: f64,
    #[serde(default)]
    pub ends: ChannelEnds,
    /// Least silicone between two channels, over a channel (to the contact face), beyond its
    /// far end and to the outline's side, mm.
    #[serde(default = "default_min_wall")]
    pub min_wall_mm: f64,
    pub tube: ChannelTube,
}

fn default_min_wall() -> f64 {
    0.5
}

impl ChannelSet {
    /// x of each channel's centre line, mm.
    pub fn centres_x_mm(&self) -> Vec<f64> {
        let mid = (self.count as f64 - 1.0) / 2.0;
        (0..self.count)
            .map(|i| (i as f64 - mid) * self.pitch_mm)
            .collect()
    }

    /// The void of one channel, mm^3: width x height x length.
    pub fn channel_volume_mm3(&self) -> f64 {
        self.width_mm * self.height_mm * self.length_mm
    }

    /// The liquid of one channel's circuit, mL: the channel less the tube's inserted end,
    /// plus the tube's bore over its length.
    pub fn liquid_per_channel_ml(&self) -> f64 {
        let t = &self.tube;
        let plug = PI * (t.outer_diameter_mm / 2.0).powi(2) * t.insertion_mm;
        let bore = PI * (t.inner_diameter_mm / 2.0).powi(2) * t.length_mm;
        ((self.channel_volume_mm3() - plug).max(0.0) + bore) / 1000.0
    }

    /// Every violation under `prefix` (`layers[1].channels.`), for channels in a layer
    /// `layer_thickness_mm` thick inside `outline`.
    pub fn errors(
        &self,
        prefix: &str,
        layer_thickness_mm: f64,
        outline: &FlatOutline,
    ) -> Vec<ParamError> {
        let mut errs = Vec::new();
        let p = |f: &str| format!("{prefix}{f}");
        if self.count == 0 {
            errs.push(ParamError::new(p("count"), 0, "must be 1 or more"));
        }
        crate::parts::check_positive(
            prefix,
            &[
                ("width_mm", self.width_mm),
                ("height_mm", self.height_mm),
                ("pitch_mm", self.pitch_mm),
                ("length_mm", self.length_mm),
                ("min_wall_mm", self.min_wall_mm),
                ("tube.outer_diameter_mm", self.tube.outer_diameter_mm),
                ("tube.inner_diameter_mm", self.tube.inner_diameter_mm),
                ("tube.length_mm", self.tube.length_mm),
                ("tube.insertion_mm", self.tube.insertion_mm),
            ],
            &mut errs,
        );
        if !errs.is_empty() {
            return errs;
        }
        let w = self.min_wall_mm;
        if self.count > 1 && self.width_mm + w > self.pitch_mm {
            errs.push(ParamError::new(
                p("width_mm"),
                self.width_mm,
                format!(
                    "channels {} mm wide at a {} mm pitch leave less than min_wall_mm ({w} mm) between them: the width must be at most the pitch less the wall",
                    self.width_mm, self.pitch_mm
                ),
            ));
        }
        if self.height_mm + w > layer_thickness_mm {
            errs.push(ParamError::new(
                p("height_mm"),
                self.height_mm,
                format!(
                    "the channel breaks through the skin's face: its layer is {layer_thickness_mm} mm thick, so a channel may be at most {:.3} mm high under a min_wall_mm ({w} mm) roof",
                    layer_thickness_mm - w
                ),
            ));
        }
        if self.length_mm + w > outline.length_mm {
            errs.push(ParamError::new(
                p("length_mm"),
                self.length_mm,
                format!(
                    "the far end must stay min_wall_mm ({w} mm) inside the {} mm outline",
                    outline.length_mm
                ),
            ));
        }
        // the mouths open on the near edge's straight part, min_wall_mm from its corners
        let span = (self.count as f64 - 1.0) * self.pitch_mm / 2.0 + self.width_mm / 2.0;
        let straight = outline.width_mm / 2.0 - outline.corner_radius_mm - w;
        if span > straight {
            errs.push(ParamError::new(
                p("count"),
                self.count,
                format!(
                    "{} channels at a {} mm pitch span {:.3} mm across: more than the near edge's straight part less min_wall_mm ({:.3} mm)",
                    self.count,
                    self.pitch_mm,
                    2.0 * span,
                    2.0 * straight
                ),
            ));
        }
        let t = &self.tube;
        if t.inner_diameter_mm >= t.outer_diameter_mm {
            errs.push(ParamError::new(
                p("tube.inner_diameter_mm"),
                t.inner_diameter_mm,
                format!(
                    "must be below the outer diameter ({} mm)",
                    t.outer_diameter_mm
                ),
            ));
        }
        let mouth = self.width_mm.max(self.height_mm);
        if t.outer_diameter_mm < mouth {
            errs.push(ParamError::new(
                p("tube.outer_diameter_mm"),
                t.outer_diameter_mm,
                format!("must be at least the channel's width and height ({mouth} mm), to seal its mouth"),
            ));
        }
        if self.count > 1 && t.outer_diameter_mm >= self.pitch_mm {
            errs.push(ParamError::new(
                p("tube.outer_diameter_mm"),
                t.outer_diameter_mm,
                format!(
                    "must be below the pitch ({} mm): neighbouring tubes side by side",
                    self.pitch_mm
                ),
            ));
        }
        if t.insertion_mm >= self.length_mm {
            errs.push(ParamError::new(
                p("tube.insertion_mm"),
                t.insertion_mm,
                format!("must be below the channel's length ({} mm)", self.length_mm),
            ));
        }
        errs
    }
}

/// Markers on a grid, `rows` along y by `columns` along x at `pitch_mm`, centred on the axis,
/// standing on a layer's bottom face towards the camera (Soter et al. Sec. II-A: a 10 x 10
/// grid of 3D markers whose ends are painted white).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MarkerGrid {
    pub rows: usize,
    pub columns: usize,
    pub pitch_mm: f64,
    /// A cylinder ending in a hemisphere (`polarity: raised`: it stands out of the face).
    pub feature: FeatureShape,
    /// Least distance from a marker's side to the outline's edge, mm.
    #[serde(default = "default_edge_margin")]
    pub edge_margin_mm: f64,
}

fn default_edge_margin() -> f64 {
    1.0
}

impl MarkerGrid {
    /// (x, y) of each marker's axis, row by row from -y, mm.
    pub fn positions_mm(&self) -> Vec<[f64; 2]> {
        let (mr, mc) = (
            (self.rows as f64 - 1.0) / 2.0,
            (self.columns as f64 - 1.0) / 2.0,
        );
        (0..self.rows)
            .flat_map(|r| {
                (0..self.columns).map(move |c| {
                    [
                        (c as f64 - mc) * self.pitch_mm,
                        (r as f64 - mr) * self.pitch_mm,
                    ]
                })
            })
            .collect()
    }

    /// Every violation under `prefix` (`layers[0].marker_grid.`).
    pub fn errors(&self, prefix: &str, outline: &FlatOutline) -> Vec<ParamError> {
        let mut errs = Vec::new();
        let p = |f: &str| format!("{prefix}{f}");
        for (f, n) in [("rows", self.rows), ("columns", self.columns)] {
            if n == 0 {
                errs.push(ParamError::new(p(f), 0, "must be 1 or more"));
            }
        }
        crate::parts::check_positive(
            prefix,
            &[
                ("pitch_mm", self.pitch_mm),
                ("feature.diameter_mm", self.feature.diameter_mm),
                ("feature.height_mm", self.feature.height_mm),
            ],
            &mut errs,
        );
        if !(self.edge_margin_mm >= 0.0 && self.edge_margin_mm.is_finite()) {
            errs.push(ParamError::new(
                p("edge_margin_mm"),
                self.edge_margin_mm,
                "must be 0 or more",
            ));
        }
        if !errs.is_empty() {
            return errs;
        }
        let r = self.feature.radius_mm();
        if self.feature.height_mm < r {
            errs.push(ParamError::new(
                p("feature.height_mm"),
                self.feature.height_mm,
                format!("must be at least the radius ({r} mm): the marker ends in a hemisphere"),
            ));
        }
        if self.feature.side() != Polarity::Raised {
            errs.push(ParamError::new(
                p("feature.polarity"),
                "recessed",
                "grid markers stand out of the face (raised)",
            ));
        }
        if self.feature.diameter_mm >= self.pitch_mm && self.rows.max(self.columns) > 1 {
            errs.push(ParamError::new(
                p("feature.diameter_mm"),
                self.feature.diameter_mm,
                format!(
                    "must be below the pitch ({} mm): markers would merge",
                    self.pitch_mm
                ),
            ));
        }
        let worst = self
            .positions_mm()
            .into_iter()
            .map(|q| outline.inset_mm(q))
            .fold(f64::INFINITY, f64::min);
        if worst - r < self.edge_margin_mm {
            errs.push(ParamError::new(
                p("pitch_mm"),
                self.pitch_mm,
                format!(
                    "a {} x {} grid at this pitch does not fit the {} x {} mm outline: its outermost marker's side is {:.3} mm from the edge, edge_margin_mm is {}",
                    self.rows,
                    self.columns,
                    outline.width_mm,
                    outline.length_mm,
                    worst - r,
                    self.edge_margin_mm
                ),
            ));
        }
        errs
    }
}

/// One layer of a flat skin: from `z0_mm` up to `z1_mm`, with its channels and marker grid.
#[derive(Debug, Clone, PartialEq)]
pub struct FlatLayer {
    pub name: String,
    pub z0_mm: f64,
    pub z1_mm: f64,
    pub channels: Option<ChannelSet>,
    pub marker_grid: Option<MarkerGrid>,
}

/// The solid of one layer (validated parameters): the outline's prism from `z0_mm` to `z1_mm`,
/// less its channels' grooves (open on the bottom face and at the near edge), with its
/// markers standing below the bottom face (rooted `embed` into it so that they fuse).
///
/// # Errors
/// [`GeometryError`] on a kernel failure.
pub fn layer_solid(
    outline: &FlatOutline,
    layer: &FlatLayer,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    let mut s = prism(&outline.polygon(tol), layer.z0_mm, layer.z1_mm)?;
    if let Some(ch) = &layer.channels {
        let y_near = -outline.length_mm / 2.0;
        let grooves = ch
            .centres_x_mm()
            .into_iter()
            .map(|x| {
                cuboid(
                    [x - ch.width_mm / 2.0, y_near - 1.0, layer.z0_mm - 1.0],
                    [
                        x + ch.width_mm / 2.0,
                        y_near + ch.length_mm,
                        layer.z0_mm + ch.height_mm,
                    ],
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
        s = s.difference(&Solid::compose(&grooves))?;
    }
    if let Some(g) = &layer.marker_grid {
        let embed = 2.0 * tol.mm() + 0.02;
        let markers = g
            .positions_mm()
            .into_iter()
            .map(|[x, y]| {
                feature_solid(
                    &g.feature,
                    [x, y, layer.z0_mm],
                    [0.0, 0.0, -1.0],
                    embed,
                    tol,
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
        s = s.union(&Solid::compose(&markers))?;
    }
    Ok(s)
}
