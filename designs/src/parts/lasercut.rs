//! Laser-cut molds of a flat skin (Soter et al. Sec. II-A: "the first mold is laser-cut", the
//! second of wood): each casting tray as a stack of sheets, bottom to top
//!
//! - `base`: the tray's floor, the first sheet stock, the tray's rectangle;
//! - `markers` (a marker layer): a sheet as thick as the markers are tall, a hole per marker
//!   (straight through: the markers come out flat-ended, their full height);
//! - `ribs` (a channel layer): a sheet as thick as the channels are tall, the outline cut out
//!   but for the ribs that form the channels' grooves, joined to the wall at the near edge;
//! - `wall`: the rest of the layer's depth, the outline cut out;
//!
//! every sheet with a registration (dowel) hole in each corner of the wall. A level is made of
//! the first stock whose thickness, taken 1 to 8 times, is the level's. The laser's paths are
//! the sheet's outline offset by half the stock's kerf away from the part (out of its outer
//! boundary, into its holes) by `geo`'s buffer (i_overlay), with round joins: cut with that
//! kerf, the path leaves the nominal sheet (inside corners rounded to half the kerf, which no
//! laser avoids). The printable tray is the union of the extruded sheets.
//!
//! Frame: the tray frame, x and y of the flat skin's frame (docs/conventions.md), z = 0 on the
//! base sheet's underside, z up through the stack.

use crate::error::ParamError;
use crate::geometry::{extrude, ChordTolerance, GeometryError, Solid};
use crate::parts::channels::FlatLayer;
use crate::parts::cut_part::{ring_area_mm2, CutPart, Operation, Outline};
use crate::profile::FlatOutline;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Laser-cut molds of a flat skin (Soter et al. Sec. II-A: the molds are laser-cut): the sheet
/// stock and the registration holes that align a stack of sheets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct LaserCutParams {
    /// The sheet stock, in the order fabkit picks from: each level of a tray is made of the
    /// first stock whose thickness, taken 1 to 8 times, equals the level's; the base sheet is
    /// the first stock.
    #[schemars(extend("minItems" = 1))]
    pub stock: Vec<SheetStock>,
    /// Dowel holes through every sheet of a stack, one in each corner of the tray's wall
    /// (when no `plate` is given).
    pub registration: SheetRegistration,
    /// The sheets' own outline and holes, as a published mold gives them (9DTact's 60 x 50 mm
    /// plates with R12 corners, eight 3.1 mm bolt holes, and the sensor's M2 pattern in the
    /// base sheet); without it every sheet is the pocket grown by `mold.wall_thickness_mm`,
    /// square-cornered, with a `registration` hole in each corner.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plate: Option<SheetPlate>,
}
defaults!(LaserCutParams {
    stock: vec![
        SheetStock {
            name: "acrylic_3mm".into(),
            material: "pmma".into(),
            thickness_mm: 3.0,
            kerf_mm: 0.15,
        },
        SheetStock {
            name: "acrylic_2mm".into(),
            material: "pmma".into(),
            thickness_mm: 2.0,
            kerf_mm: 0.12,
        },
        SheetStock {
            name: "acrylic_1_5mm".into(),
            material: "pmma".into(),
            thickness_mm: 1.5,
            kerf_mm: 0.1,
        },
    ],
    registration: SheetRegistration::default(),
    plate: None,
});

/// One sheet material profile: what the sheet is and what the laser takes out of it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SheetStock {
    /// `[a-z0-9_]+`, for file names and the bill of materials.
    #[schemars(extend("pattern" = "^[a-z0-9_]+$", "maxLength" = 64))]
    pub name: String,
    /// Material key in the materials table (designs/materials.yaml).
    pub material: String,
    /// Thickness of the sheet, mm, above 0 and at most 25 (a laser cutter's sheet). Every
    /// level of a tray is 1 to 8 sheets of the first stock whose thickness makes it; the
    /// tray's base sheet is one sheet of the first stock.
    #[schemars(extend("exclusiveMinimum" = 0, "maximum" = 25))]
    pub thickness_mm: f64,
    /// Width of the laser's cut in this sheet, mm: every path is offset by half of it.
    #[schemars(extend("minimum" = 0, "exclusiveMaximum" = 2))]
    pub kerf_mm: f64,
}

/// Registration (dowel) holes through a stack of sheets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct SheetRegistration {
    /// Hole diameter, mm (a dowel pin of this diameter, a sliding fit after the kerf).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
}
defaults!(SheetRegistration { diameter_mm: 3.0 });

/// The outline and holes every sheet of a tray shares, centred on the skin: a rounded
/// rectangle with holes through every sheet (bolts or dowels that clamp and register the
/// stack) and, in the base sheet only, further holes (the sensor's own screw pattern).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SheetPlate {
    /// The plate's size across x and along y, mm: each above the pocket's by at least 2 mm.
    pub size_mm: [f64; 2],
    /// The plate's corner radius, mm, 0 (square) up to half its shorter side.
    #[serde(default)]
    #[schemars(extend("minimum" = 0))]
    pub corner_radius_mm: f64,
    /// Holes through every sheet (bolts or dowel pins through the whole stack).
    pub holes: HolePattern,
    /// Holes through the base sheet only (the sensor's screw pattern), which may lie under the
    /// pocket (the procedure tapes those shut before the pours); none by default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_holes: Option<HolePattern>,
}

/// Round holes of one diameter at given centres.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HolePattern {
    /// The hole's diameter, mm, above 0 (a sliding fit after the kerf).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
    /// The holes' centres (x, y), mm, in the skin's frame (the pocket centred on the origin):
    /// each hole inside the plate and clear of the other holes by 1 mm, and a hole through
    /// every sheet clear of the pocket by 1 mm.
    #[schemars(extend("minItems" = 1))]
    pub xy_mm: Vec<[f64; 2]>,
}

/// The least material left between a plate's hole and the plate's edge, the pocket or
/// another hole, mm.
pub const MIN_LIGAMENT_MM: f64 = 1.0;

impl SheetPlate {
    /// The plate's outline as a rounded rectangle.
    pub fn outline(&self) -> FlatOutline {
        FlatOutline {
            width_mm: self.size_mm[0],
            length_mm: self.size_mm[1],
            corner_radius_mm: self.corner_radius_mm,
        }
    }

    /// Every rule of the plate against the pocket `pocket` (the skin's outline), by path
    /// under `mold.laser_cut.plate`, pushed onto `errs`.
    pub fn check(&self, pocket: &FlatOutline, errs: &mut Vec<ParamError>) {
        let p = "mold.laser_cut.plate";
        let [w, l] = self.size_mm;
        let fits = [(w, pocket.width_mm, 0), (l, pocket.length_mm, 1)];
        let mut size_ok = true;
        for (size, inner, k) in fits {
            if !(size.is_finite() && size >= inner + 2.0 * MIN_LIGAMENT_MM) {
                size_ok = false;
                errs.push(ParamError::new(
                    format!("{p}.size_mm[{k}]"),
                    size,
                    format!(
                        "must exceed the pocket's {inner} mm by at least {} mm (1 mm of sheet either side)",
                        2.0 * MIN_LIGAMENT_MM
                    ),
                ));
            }
        }
        let r = self.corner_radius_mm;
        if !(r >= 0.0 && r <= w.min(l) / 2.0) {
            errs.push(ParamError::new(
                format!("{p}.corner_radius_mm"),
                r,
                format!(
                    "must be 0 or more and at most half the plate's shorter side ({} mm)",
                    w.min(l) / 2.0
                ),
            ));
            size_ok = false;
        }
        // each hole's path, centre, radius and whether it goes through every sheet
        let mut all: Vec<(String, [f64; 2], f64, bool)> = Vec::new();
        for (key, pattern, through) in [
            ("holes", Some(&self.holes), true),
            ("base_holes", self.base_holes.as_ref(), false),
        ] {
            let Some(h) = pattern else { continue };
            let d = h.diameter_mm;
            if !(d > 0.0 && d.is_finite()) {
                errs.push(ParamError::new(
                    format!("{p}.{key}.diameter_mm"),
                    d,
                    "must be above 0",
                ));
                continue;
            }
            if h.xy_mm.is_empty() {
                errs.push(ParamError::new(
                    format!("{p}.{key}.xy_mm"),
                    "[]",
                    "must list at least one hole",
                ));
            }
            for (i, c) in h.xy_mm.iter().enumerate() {
                all.push((format!("{p}.{key}.xy_mm[{i}]"), *c, d / 2.0, through));
            }
        }
        if !size_ok {
            return;
        }
        let plate = self.outline();
        for (k, (path, c, r, through)) in all.iter().enumerate() {
            let value = format!("[{}, {}]", c[0], c[1]);
            let edge = -plate.signed_distance_mm(*c);
            if !(edge >= r + MIN_LIGAMENT_MM) {
                errs.push(ParamError::new(
                    path.as_str(),
                    &value,
                    format!("a hole of radius {r} mm there leaves less than {MIN_LIGAMENT_MM} mm to the plate's edge"),
                ));
                continue;
            }
            // a base hole may lie under the pocket (the base sheet has none): taped shut for
            // the pours
            let to_pocket = pocket.signed_distance_mm(*c);
            if *through && !(to_pocket >= r + MIN_LIGAMENT_MM) {
                errs.push(ParamError::new(
                    path.as_str(),
                    &value,
                    format!("a hole of radius {r} mm there leaves less than {MIN_LIGAMENT_MM} mm to the pocket (the skin's outline, {} x {} mm)", pocket.width_mm, pocket.length_mm),
                ));
                continue;
            }
            if let Some((other, ..)) = all[..k].iter().find(|(_, o, ro, _)| {
                ((o[0] - c[0]).powi(2) + (o[1] - c[1]).powi(2)).sqrt() < r + ro + MIN_LIGAMENT_MM
            }) {
                errs.push(ParamError::new(
                    path.as_str(),
                    &value,
                    format!("leaves less than {MIN_LIGAMENT_MM} mm to the hole at {other}"),
                ));
            }
        }
    }
}

/// Most sheets of one stock a level may take.
pub const MAX_SHEETS_PER_LEVEL: u32 = 8;

/// A region of the plane: its outer boundary counter-clockwise and its holes clockwise, mm
/// (no closing vertex).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Region {
    pub outer: Vec<[f64; 2]>,
    pub holes: Vec<Vec<[f64; 2]>>,
}

impl Region {
    /// Area, mm^2: the outer boundary less the holes.
    pub fn area_mm2(&self) -> f64 {
        ring_area_mm2(&self.outer).abs()
            - self
                .holes
                .iter()
                .map(|h| ring_area_mm2(h).abs())
                .sum::<f64>()
    }

    /// The boundary rings, outer first.
    pub fn rings(&self) -> Vec<Vec<[f64; 2]>> {
        std::iter::once(self.outer.clone())
            .chain(self.holes.iter().cloned())
            .collect()
    }

    fn to_geo(&self) -> geo::Polygon<f64> {
        let ring = |r: &[[f64; 2]]| {
            geo::LineString::from(r.iter().map(|p| (p[0], p[1])).collect::<Vec<_>>())
        };
        geo::Polygon::new(
            ring(&self.outer),
            self.holes.iter().map(|h| ring(h)).collect(),
        )
    }

    fn from_geo(p: &geo::Polygon<f64>) -> Self {
        // geo closes its rings; drop the closing vertex and orient outer CCW, holes CW
        let ring = |r: &geo::LineString<f64>, ccw: bool| {
            let mut v: Vec<[f64; 2]> = r.0.iter().map(|c| [c.x, c.y]).collect();
            if v.len() > 1 && v.first() == v.last() {
                v.pop();
            }
            if (ring_area_mm2(&v) > 0.0) != ccw {
                v.reverse();
            }
            v
        };
        Self {
            outer: ring(p.exterior(), true),
            holes: p.interiors().iter().map(|h| ring(h, false)).collect(),
        }
    }
}

/// One level of a tray's stack: `quantity` identical sheets of `stock`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sheet {
    /// `<layer>_tray_<level>_<role>`: the file stem of its DXF, SVG and STL.
    pub name: String,
    /// `base`, `markers`, `ribs` or `wall`.
    pub role: &'static str,
    /// Index in `mold.laser_cut.stock`, and the stock.
    pub stock_index: usize,
    pub stock: SheetStock,
    pub quantity: u32,
    /// z of the level's underside in the tray frame, mm.
    pub z0_mm: f64,
    /// The nominal sheet (what the laser leaves).
    pub region: Region,
}

impl Sheet {
    /// The level's thickness (all its sheets), mm.
    pub fn level_mm(&self) -> f64 {
        self.quantity as f64 * self.stock.thickness_mm
    }
}

/// A circle of radius `r` about `c` as a polygon of `tol`'s segment count, vertices on the
/// circle (the first at angle 0), counter-clockwise.
pub(crate) fn circle(c: [f64; 2], r: f64, tol: ChordTolerance) -> Vec<[f64; 2]> {
    let n = tol.circle_segments(r).max(8);
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            [c[0] + r * a.cos(), c[1] + r * a.sin()]
        })
        .collect()
}

fn reversed(mut v: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    v.reverse();
    v
}

/// Centres of the registration holes, (x, y) mm: the middle of the wall at each corner.
pub fn registration_xy_mm(outline: &FlatOutline, wall_mm: f64) -> [[f64; 2]; 4] {
    let (x, y) = (
        outline.width_mm / 2.0 + wall_mm / 2.0,
        outline.length_mm / 2.0 + wall_mm / 2.0,
    );
    [[-x, -y], [x, -y], [x, y], [-x, y]]
}

/// Every sheet's outer boundary (counter-clockwise), the holes through every sheet and the
/// holes through the base sheet only (clockwise), from `mold.laser_cut.plate`, else the
/// pocket grown by `wall_mm` with a registration hole in each corner.
#[allow(clippy::type_complexity)]
fn sheet_outline(
    outline: &FlatOutline,
    wall_mm: f64,
    lc: &LaserCutParams,
    tol: ChordTolerance,
) -> (Vec<[f64; 2]>, Vec<Vec<[f64; 2]>>, Vec<Vec<[f64; 2]>>) {
    let holes = |h: &HolePattern| -> Vec<Vec<[f64; 2]>> {
        h.xy_mm
            .iter()
            .map(|&c| reversed(circle(c, h.diameter_mm / 2.0, tol)))
            .collect()
    };
    if let Some(plate) = &lc.plate {
        return (
            plate.outline().polygon(tol),
            holes(&plate.holes),
            plate.base_holes.as_ref().map(holes).unwrap_or_default(),
        );
    }
    let (hw, hl) = (
        outline.width_mm / 2.0 + wall_mm,
        outline.length_mm / 2.0 + wall_mm,
    );
    let rect = vec![[-hw, -hl], [hw, -hl], [hw, hl], [-hw, hl]];
    let reg = holes(&HolePattern {
        diameter_mm: lc.registration.diameter_mm,
        xy_mm: registration_xy_mm(outline, wall_mm).to_vec(),
    });
    (rect, reg, Vec::new())
}

/// The stock a level of `thickness_mm` is made of: the first whose thickness, 1 to
/// [`MAX_SHEETS_PER_LEVEL`] times, equals it (to 1 um); (index, count).
fn stock_for(stock: &[SheetStock], thickness_mm: f64) -> Option<(usize, u32)> {
    stock.iter().enumerate().find_map(|(i, s)| {
        let n = (thickness_mm / s.thickness_mm).round();
        (s.thickness_mm > 0.0
            && (1.0..=MAX_SHEETS_PER_LEVEL as f64).contains(&n)
            && (n * s.thickness_mm - thickness_mm).abs() <= 1e-3)
            .then_some((i, n as u32))
    })
}

/// Every rule on `mold.laser_cut` alone, by path: stock names, materials, thicknesses and
/// kerfs, and the plate against the pocket (the skin's outline `pocket`), or else the
/// registration holes against the tray's wall.
pub fn check_params(
    lc: &LaserCutParams,
    pocket: &FlatOutline,
    wall_mm: f64,
    materials: &crate::materials::MaterialsTable,
) -> Vec<ParamError> {
    let mut errs = Vec::new();
    if lc.stock.is_empty() {
        errs.push(ParamError::new(
            "mold.laser_cut.stock",
            "[]",
            "must list at least one sheet stock",
        ));
    }
    let mut names = std::collections::BTreeSet::new();
    for (i, s) in lc.stock.iter().enumerate() {
        let p = format!("mold.laser_cut.stock[{i}]");
        let good_name = crate::values::is_file_stem(&s.name);
        if !good_name || !names.insert(s.name.clone()) {
            errs.push(ParamError::new(
                format!("{p}.name"),
                &s.name,
                "must be [a-z0-9_]+, at most 64 characters, and unique",
            ));
        }
        if materials.get(&s.material).is_none() {
            errs.push(ParamError::new(
                format!("{p}.material"),
                &s.material,
                "must be a key of the materials table (designs/materials.yaml), e.g. pmma or plywood",
            ));
        }
        if !(s.thickness_mm > 0.0 && s.thickness_mm <= 25.0) {
            errs.push(ParamError::new(
                format!("{p}.thickness_mm"),
                s.thickness_mm,
                "must be above 0 and at most 25 mm (a laser cutter's sheet)",
            ));
        }
        if !(s.kerf_mm >= 0.0 && s.kerf_mm < 2.0) {
            errs.push(ParamError::new(
                format!("{p}.kerf_mm"),
                s.kerf_mm,
                "must be 0 or more and below 2 mm (a laser's cut is a few tenths of a mm wide)",
            ));
        }
    }
    let d = lc.registration.diameter_mm;
    if let Some(plate) = &lc.plate {
        plate.check(pocket, &mut errs);
        // unused under a plate's own holes, but a number the schema bounds is always held to it
        if !(d > 0.0 && d.is_finite()) {
            errs.push(ParamError::new(
                "mold.laser_cut.registration.diameter_mm",
                d,
                "must be above 0",
            ));
        }
    } else if !(d > 0.0 && d <= wall_mm - 2.0) {
        errs.push(ParamError::new(
            "mold.laser_cut.registration.diameter_mm",
            d,
            format!(
                "must be above 0 and leave 1 mm of the {wall_mm} mm wall (mold.wall_thickness_mm) either side: at most {} mm",
                wall_mm - 2.0
            ),
        ));
    }
    errs
}

/// A level of a stack before its stock is chosen: its role, thickness, the path of the
/// parameter that sets the thickness, and its holes besides the registration holes.
type Level = (&'static str, f64, String, Vec<Vec<[f64; 2]>>);

/// The sheets of the tray of `layer` (index `li`) of a flat skin whose largest pocket (its
/// outermost layer's outline) is `outline`, bottom to top, with checked `mold.laser_cut`
/// parameters ([`check_params`]): the sheets' outer boundary round `outline`, the cavity the
/// layer's own outline as deep as its pocket ([`FlatLayer::pocket_depth_mm`]).
///
/// # Errors
/// The violated rules, by path: a level no stock makes (the channels' or markers' height, the
/// layer's thickness), and a sheet whose cut-out closes when its path is offset by half its
/// stock's kerf (a slot narrower than the kerf).
pub fn tray_sheets(
    outline: &FlatOutline,
    layer: &FlatLayer,
    li: usize,
    wall_mm: f64,
    lc: &LaserCutParams,
    tol: ChordTolerance,
) -> Result<Vec<Sheet>, Vec<ParamError>> {
    let (rect, reg, base_holes) = sheet_outline(outline, wall_mm, lc, tol);
    let outline = &layer.outline;
    let cavity = reversed(outline.polygon(tol));
    let depth = layer.pocket_depth_mm();
    let name = &layer.name;
    let mut levels: Vec<Level> = Vec::new();
    levels.push((
        "base",
        lc.stock.first().map_or(0.0, |s| s.thickness_mm),
        "mold.laser_cut.stock[0].thickness_mm".into(),
        base_holes,
    ));
    let mut wall_depth = depth;
    if let Some(g) = &layer.marker_grid {
        let r = g.feature.diameter_mm / 2.0;
        levels.push((
            "markers",
            g.feature.height_mm,
            format!("layers[{li}].marker_grid.feature.height_mm"),
            g.positions_mm()
                .into_iter()
                .map(|c| reversed(circle(c, r, tol)))
                .collect(),
        ));
    }
    if let Some(ch) = &layer.channels {
        // the cavity less the ribs, which join the wall at the near edge (y = -length / 2):
        // the outline's polygon with a notch per rib in its near edge (the polygon's closing
        // edge, from its last vertex to its first, along +x), on the outline's own vertices
        let y_near = -outline.length_mm / 2.0;
        let mut open = outline.polygon(tol);
        let mut xs = ch.centres_x_mm();
        xs.sort_by(f64::total_cmp);
        for x in xs {
            let (x0, x1) = (x - ch.width_mm / 2.0, x + ch.width_mm / 2.0);
            let y1 = y_near + ch.length_mm;
            open.extend([[x0, y_near], [x0, y1], [x1, y1], [x1, y_near]]);
        }
        levels.push((
            "ribs",
            ch.height_mm,
            format!("layers[{li}].channels.height_mm"),
            vec![reversed(open)],
        ));
        wall_depth -= ch.height_mm;
    }
    // a channel layer may be all channel height (no wall sheet); validation keeps every
    // layer's thickness above 0
    if wall_depth > 1e-9 {
        levels.push((
            "wall",
            wall_depth,
            format!("layers[{li}].thickness_mm"),
            vec![cavity],
        ));
    }
    let mut errs = Vec::new();
    let mut sheets = Vec::new();
    let mut z = 0.0;
    for (k, (role, t, path, holes)) in levels.into_iter().enumerate() {
        let Some((si, n)) = stock_for(&lc.stock, t) else {
            // a level is a difference of thicknesses: say it to the micrometre
            let t = (t * 1e6).round() / 1e6;
            errs.push(ParamError::new(
                path,
                t,
                format!(
                    "the {role} sheets of {name}'s tray must be made of mold.laser_cut.stock: no stock ({}) makes {t} mm in 1 to {MAX_SHEETS_PER_LEVEL} sheets",
                    lc.stock
                        .iter()
                        .map(|s| format!("{} mm", s.thickness_mm))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
            continue;
        };
        let mut all_holes = reg.clone();
        all_holes.extend(holes);
        let sheet = Sheet {
            name: format!("{name}_tray_{}_{role}", k + 1),
            role,
            stock_index: si,
            stock: lc.stock[si].clone(),
            quantity: n,
            z0_mm: z,
            region: Region {
                outer: rect.clone(),
                holes: all_holes,
            },
        };
        if cut_path(&sheet.region, sheet.stock.kerf_mm, tol).is_none() {
            errs.push(ParamError::new(
                format!("mold.laser_cut.stock[{si}].kerf_mm"),
                sheet.stock.kerf_mm,
                format!(
                    "is wider than a slot of sheet {}: a cut-out closes when the laser's path is offset by half the kerf",
                    sheet.name
                ),
            ));
        }
        z += sheet.level_mm();
        sheets.push(sheet);
    }
    if errs.is_empty() {
        Ok(sheets)
    } else {
        Err(errs)
    }
}

/// The laser's path round `region` for a kerf of `kerf_mm`: the region offset by half the
/// kerf (round joins within `tol`); `None` when the offset changes its topology (a hole closes
/// or splits, the region splits): a slot narrower than the kerf.
pub fn cut_path(region: &Region, kerf_mm: f64, tol: ChordTolerance) -> Option<Region> {
    use geo::algorithm::buffer::{Buffer, BufferStyle, LineJoin};
    if kerf_mm == 0.0 {
        return Some(region.clone());
    }
    let r = kerf_mm / 2.0;
    // the largest step of a round join whose chords stay within the chord tolerance
    let step = if tol.mm() < r {
        (2.0 * (1.0 - tol.mm() / r).acos()).min(0.5)
    } else {
        0.5
    };
    let out = region
        .to_geo()
        .buffer_with_style(BufferStyle::new(r).line_join(LineJoin::Round(step)));
    match out.0.as_slice() {
        [p] if p.interiors().len() == region.holes.len() => Some(Region::from_geo(p)),
        _ => None,
    }
}

/// What the laser leaves of a path cut with a kerf of `kerf_mm` (the path offset back by half
/// the kerf; inside corners come out rounded to half the kerf): for checking kerf compensation.
pub fn cut_result(path: &Region, kerf_mm: f64) -> Vec<Region> {
    use geo::algorithm::buffer::{Buffer, BufferStyle, LineJoin};
    if kerf_mm == 0.0 {
        return vec![path.clone()];
    }
    path.to_geo()
        .buffer_with_style(BufferStyle::new(-kerf_mm / 2.0).line_join(LineJoin::Round(0.05)))
        .0
        .iter()
        .map(Region::from_geo)
        .collect()
}

/// One sheet of a level as a solid, tray frame (from its underside at z = 0).
///
/// # Errors
/// [`GeometryError`] on a kernel failure.
pub fn sheet_solid(sheet: &Sheet) -> Result<Solid, GeometryError> {
    extrude(&sheet.region.rings(), 0.0, sheet.stock.thickness_mm)
}

/// The printable tray: the union of every sheet extruded and stacked, tray frame.
///
/// # Errors
/// [`GeometryError`] on a kernel failure.
pub fn tray_union(sheets: &[Sheet]) -> Result<Solid, GeometryError> {
    let mut solids = Vec::new();
    for s in sheets {
        let one = sheet_solid(s)?;
        for k in 0..s.quantity {
            solids.push(one.translate([0.0, 0.0, s.z0_mm + k as f64 * s.stock.thickness_mm]));
        }
    }
    Solid::union_all(&solids)
}

/// The sheet as a part to cut: its kerf-compensated paths on `cut` ([`cut_path`]).
///
/// # Errors
/// The sheet's name when its path cannot be offset (checked by [`tray_sheets`] before).
pub fn cut_part(
    sheet: &Sheet,
    what: &str,
    plate: Option<&SheetPlate>,
    tol: ChordTolerance,
) -> Result<CutPart, String> {
    let holes_words = match plate {
        None => "a registration hole in each corner".to_string(),
        Some(p) => {
            let base = p
                .base_holes
                .as_ref()
                .filter(|_| sheet.role == "base")
                .map(|b| {
                    format!(
                        " and {} {} mm holes of the sensor's screws",
                        b.xy_mm.len(),
                        b.diameter_mm
                    )
                })
                .unwrap_or_default();
            format!(
                "the {} {} mm holes through the stack{base}",
                p.holes.xy_mm.len(),
                p.holes.diameter_mm
            )
        }
    };
    let path = cut_path(&sheet.region, sheet.stock.kerf_mm, tol)
        .ok_or_else(|| format!("{}: the kerf closes a cut-out", sheet.name))?;
    let polygon = |r: &Vec<[f64; 2]>| {
        (
            Operation::Cut,
            Outline::Polygon {
                points_mm: r.clone(),
            },
        )
    };
    Ok(CutPart {
        name: sheet.name.clone(),
        description: format!(
            "{what}: {} sheet{} of {} ({} mm), {:.2} to {:.2} mm of the stack; paths offset {:.3} mm for a {:.2} mm kerf; {}",
            sheet.quantity,
            if sheet.quantity == 1 { "" } else { "s" },
            sheet.stock.name,
            sheet.stock.thickness_mm,
            sheet.z0_mm,
            sheet.z0_mm + sheet.level_mm(),
            sheet.stock.kerf_mm / 2.0,
            sheet.stock.kerf_mm,
            holes_words,
        ),
        material: sheet.stock.material.clone(),
        thickness_mm: sheet.stock.thickness_mm,
        outlines: std::iter::once(&path.outer)
            .chain(&path.holes)
            .map(polygon)
            .collect(),
        kerf_mm: sheet.stock.kerf_mm,
        quantity: sheet.quantity,
        nominal_rings_mm: Some(sheet.region.rings()),
    })
}
