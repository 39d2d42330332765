//! A flat skin's layer ([`FlatLayer`]) and the liquid channels in it (Soter et al., Sec. II-A:
//! 16 liquid-filled channels in the top layer): their parameters (`layers[i].channels`), rules
//! and sizes, in the flat-skin frame of [`crate::parts::flat`] (docs/conventions.md, flat
//! skins), and their place among the layer features ([`ChannelsFeature`]). The marker grid on
//! the bottom layer is [`crate::parts::marker_grid`].

use crate::error::ParamError;
use crate::parts::layer_feature::{FlatInput, LayerFeature, LayerInput};
pub use crate::parts::marker_grid::MarkerGrid;
use crate::profile::FlatOutline;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// One layer of a flat skin: its outline's prism from `z0_mm` up to `z1_mm` (and, when it
/// wraps the layers under it, down their sides to the base plane), with its channels and
/// marker grid.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlatLayer {
    pub name: String,
    pub z0_mm: f64,
    pub z1_mm: f64,
    /// The layer's own outline: the body's, grown by the wraps of this layer and those under it.
    #[serde(skip)]
    pub outline: FlatOutline,
    /// What the layer wraps (`layers[i].wrap_mm`); none for a layer that lies on the top of the
    /// one under it only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wraps: Option<Wrap>,
    pub channels: Option<ChannelSet>,
    pub marker_grid: Option<MarkerGrid>,
}

/// How a flat layer wraps the layers under it: over their top and down their sides to the
/// base plane, `side_mm` thick at the sides.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Wrap {
    /// The thickness at the sides, mm (`layers[i].wrap_mm`).
    pub side_mm: f64,
    /// The outline of the layers it wraps, mm.
    pub under: FlatOutline,
    /// Its own outline: `under` grown by `side_mm`.
    pub outline: FlatOutline,
}

impl FlatLayer {
    /// z of the layer's lowest face, mm: the base plane for a wrapping layer, else `z0_mm`.
    pub fn bottom_mm(&self) -> f64 {
        if self.wraps.is_some() {
            0.0
        } else {
            self.z0_mm
        }
    }

    /// The depth of the pocket the layer is cast in, mm: from its lowest face to its top.
    pub fn pocket_depth_mm(&self) -> f64 {
        self.z1_mm - self.bottom_mm()
    }

    /// The layer's volume, mm^3, exact for its outline: its prism, less the layers it wraps,
    /// less its channels' grooves, plus its markers beyond the face (`flat_ended`: straight
    /// holes through a laser-cut sheet, else the marker's own feature).
    pub fn volume_mm3(&self, flat_ended: bool) -> f64 {
        let prism = self.outline.area_mm2() * self.pocket_depth_mm()
            - self
                .wraps
                .as_ref()
                .map_or(0.0, |w| w.under.area_mm2() * self.z0_mm);
        let grooves = self
            .channels
            .as_ref()
            .map_or(0.0, |c| c.count as f64 * c.channel_volume_mm3());
        let markers = self.marker_grid.as_ref().map_or(0.0, |g| {
            let one = if flat_ended {
                PI * (g.feature.diameter_mm / 2.0).powi(2) * g.feature.height_mm
            } else {
                g.feature.nominal_volume_mm3()
            };
            (g.rows * g.columns) as f64 * one
        });
        prism - grooves + markers
    }
}

/// What closes a channel's liquid circuit (Soter et al. Sec. II-A: "each channel is closed at
/// both ends, this ensures that the liquid always returns back to its initial state"; and
/// "the internal chambers are closed on one end", which is why they are filled in a tank).
/// The channel in the skin is the same either way: closed at its far end, open at the near
/// edge into its tube.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema, Default)]
#[serde(rename_all = "snake_case")]
pub enum ChannelEnds {
    /// The tube's display end is sealed once filled: the liquid cannot leave the circuit.
    #[default]
    BothClosed,
    /// The display end stays open to the air.
    OneClosed,
}

/// The silicone tube glued into a channel's open end (Sil-Poxy, Soter et al. Sec. II-A).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ChannelTube {
    /// Outer diameter, mm: at least the channel's width and height, so that it seals the
    /// channel's mouth by stretching it.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_diameter_mm: f64,
    /// Inner diameter, mm, below the outer.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub inner_diameter_mm: f64,
    /// From the skin to the display, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub length_mm: f64,
    /// How far it is pushed into the channel, mm, below the channel's length.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub insertion_mm: f64,
}

/// Straight channels of rectangular section in one layer, along y, side by side across x at
/// `pitch_mm`, centred on the axis: grooves in the layer's bottom face, closed by the layer
/// under it, open at the near edge for their tubes and closed `length_mm` from it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ChannelSet {
    /// Number of channels, at least 1 (Soter et al. Sec. II-A: 16); their mouths together
    /// must fit on the near edge's straight part less `min_wall_mm` at each corner.
    #[schemars(extend("minimum" = 1))]
    pub count: usize,
    /// Across x, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub width_mm: f64,
    /// Up z from the layer's bottom face, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub height_mm: f64,
    /// Centre to centre, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub pitch_mm: f64,
    /// From the near edge to the closed far end, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub length_mm: f64,
    #[serde(default)]
    pub ends: ChannelEnds,
    /// Least silicone between two channels, over a channel (to the contact face), beyond its
    /// far end and to the outline's side, mm.
    #[serde(default = "default_min_wall")]
    #[schemars(extend("exclusiveMinimum" = 0))]
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
        crate::parts::check_above_zero(prefix, self, &[], &mut errs);
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

/// The channels as a layer feature: flat skins only, in a layer with one under it to close
/// their grooves, each groove within the layer and the outline.
pub struct ChannelsFeature;

impl LayerFeature for ChannelsFeature {
    type Params = ChannelSet;
    const KEY: &'static str = "channels";
    const FLAT_ONLY: bool = true;

    /// Curved skins refuse them ([`LayerFeature::FLAT_ONLY`]): no rules of their own there.
    fn check(_c: &ChannelSet, _input: LayerInput<'_>, _errs: &mut Vec<ParamError>) {}

    fn flat_place_rule(index: usize) -> Option<&'static str> {
        (index == 0).then_some(
            "the innermost layer cannot hold channels: their grooves are closed by the layer under them",
        )
    }

    fn check_flat(c: &ChannelSet, input: FlatInput<'_>, errs: &mut Vec<ParamError>) {
        errs.extend(c.errors(&input.prefix(Self::KEY), input.thickness_mm, input.outline));
    }
}
