//! The marker grid of a flat skin's innermost layer (`layers[0].marker_grid`; Soter et al.,
//! Sec. II-A: a 10 x 10 grid of 3D markers on the bottom layer, their ends painted white): its
//! parameters and rules, in the flat-skin frame of [`crate::parts::flat`]
//! (docs/conventions.md, flat skins), and its place among the layer features
//! ([`MarkerGridFeature`]).

use crate::error::ParamError;
use crate::markers::{FeatureShape, Polarity};
use crate::parts::layer_feature::{FlatInput, LayerFeature, LayerInput};
use crate::profile::FlatOutline;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Markers on a grid, `rows` along y by `columns` along x at `pitch_mm`, centred on the axis,
/// standing on a layer's bottom face towards the camera (Soter et al. Sec. II-A: a 10 x 10
/// grid of 3D markers whose ends are painted white).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MarkerGrid {
    /// Number of rows, stacked along y, at least 1 (Soter et al. Sec. II-A: a 10 x 10 grid).
    #[schemars(extend("minimum" = 1))]
    pub rows: usize,
    /// Number of columns, side by side along x, at least 1 (Soter et al. Sec. II-A: a 10 x 10
    /// grid).
    #[schemars(extend("minimum" = 1))]
    pub columns: usize,
    /// Centre-to-centre distance between neighbouring markers along x and along y, mm, > 0:
    /// above the markers' diameter (with more than one row or column), and the outermost
    /// markers must keep `edge_margin_mm` inside the outline.
    #[schemars(extend("exclusiveMinimum" = 0))]
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
        // bounded before positions_mm allocates one position per marker
        let max = crate::markers::MAX_MARKERS_PER_PATTERN;
        if self.rows.checked_mul(self.columns).is_none_or(|n| n > max) {
            let (f, n) = if self.rows >= self.columns {
                ("rows", self.rows)
            } else {
                ("columns", self.columns)
            };
            errs.push(ParamError::new(
                p(f),
                n,
                format!(
                    "a {} x {} grid has more than the {max} markers one grid may have",
                    self.rows, self.columns
                ),
            ));
        }
        crate::parts::check_above_zero(prefix, self, &[], &mut errs);
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

/// The marker grid as a layer feature: flat skins only, on the innermost layer, its markers
/// within the outline.
pub struct MarkerGridFeature;

impl LayerFeature for MarkerGridFeature {
    type Params = MarkerGrid;
    const KEY: &'static str = "marker_grid";
    const FLAT_ONLY: bool = true;

    /// Curved skins refuse it ([`LayerFeature::FLAT_ONLY`]): no rules of its own there.
    fn check(_g: &MarkerGrid, _input: LayerInput<'_>, _errs: &mut Vec<ParamError>) {}

    fn flat_place_rule(index: usize) -> Option<&'static str> {
        (index != 0)
            .then_some("markers stand on the innermost layer's bottom face (towards the camera)")
    }

    fn check_flat(g: &MarkerGrid, input: FlatInput<'_>, errs: &mut Vec<ParamError>) {
        errs.extend(g.errors(&input.prefix(Self::KEY), input.outline));
    }
}
