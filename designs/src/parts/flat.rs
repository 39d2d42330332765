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

use crate::geometry::{cuboid, prism, ChordTolerance, GeometryError, Solid};
use crate::markers::feature_solid;

pub use crate::profile::FlatOutline;

pub use crate::parts::channels::{
    ChannelEnds, ChannelSet, ChannelTube, FlatLayer, MarkerGrid, Wrap,
};

/// The solid of one layer (validated parameters): its outline's prism from `z0_mm` to
/// `z1_mm` (from the base plane, less the layers under it, when it wraps them), less its
/// channels' grooves (open on the bottom face and at the near edge), with its markers standing
/// below the bottom face (rooted `embed` into it so that they fuse).
///
/// # Errors
/// [`GeometryError`] on a kernel failure.
pub fn layer_solid(layer: &FlatLayer, tol: ChordTolerance) -> Result<Solid, GeometryError> {
    layer_solid_as_cast(layer, false, tol)
}

/// [`layer_solid`] as the layer's tray casts it: in a laser-cut tray (`laser_cut`) the markers
/// are flat-ended, the straight holes through the marker sheet
/// ([`crate::parts::lasercut::tray_sheets`]) with the same polygon, instead of ending in a
/// hemisphere as a printed tray's holes do.
///
/// # Errors
/// [`GeometryError`] on a kernel failure.
pub fn layer_solid_as_cast(
    layer: &FlatLayer,
    laser_cut: bool,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    let outline = &layer.outline;
    let mut s = prism(&outline.polygon(tol), layer.bottom_mm(), layer.z1_mm)?;
    if let Some(w) = &layer.wraps {
        // the layers it wraps: their outline's prism from below the base plane to their top
        s = s.difference(&prism(&w.under.polygon(tol), -1.0, layer.z0_mm)?)?;
    }
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
                if laser_cut {
                    let r = g.feature.diameter_mm / 2.0;
                    prism(
                        &crate::parts::lasercut::circle([x, y], r, tol),
                        layer.z0_mm - g.feature.height_mm,
                        layer.z0_mm + embed,
                    )
                } else {
                    feature_solid(
                        &g.feature,
                        [x, y, layer.z0_mm],
                        [0.0, 0.0, -1.0],
                        embed,
                        tol,
                    )
                }
            })
            .collect::<Result<Vec<_>, _>>()?;
        s = s.union(&Solid::compose(&markers))?;
    }
    Ok(s)
}

/// The tray a flat layer is cast in (print orientation: floor on the plate, z up): a box
/// `wall` mm round the layer's outline and `floor` mm under the layer, its cavity the
/// outline's prism as deep as the layer's pocket (a wrapping layer's from the base plane, the
/// cured layers it wraps set on the floor; poured to the brim and scraped level, the poured
/// face the layer's top). For a channel layer, ribs on the floor form the grooves and run into the near wall,
/// so that the channels open at the near edge; for a marker layer, holes in the floor form the
/// markers.
///
/// # Errors
/// [`GeometryError`] on a kernel failure.
pub fn tray_solid(
    layer: &FlatLayer,
    wall_mm: f64,
    floor_mm: f64,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    let outline = &layer.outline;
    let (hw, hl) = (outline.width_mm / 2.0, outline.length_mm / 2.0);
    let depth = layer.pocket_depth_mm();
    let block = cuboid(
        [-hw - wall_mm, -hl - wall_mm, 0.0],
        [hw + wall_mm, hl + wall_mm, floor_mm + depth],
    )?;
    let cavity = prism(&outline.polygon(tol), floor_mm, floor_mm + depth + 1.0)?;
    let mut tray = block.difference(&cavity)?;
    if let Some(ch) = &layer.channels {
        let ribs = ch
            .centres_x_mm()
            .into_iter()
            .map(|x| {
                cuboid(
                    [x - ch.width_mm / 2.0, -hl - wall_mm / 2.0, floor_mm - 0.5],
                    [
                        x + ch.width_mm / 2.0,
                        -hl + ch.length_mm,
                        floor_mm + ch.height_mm,
                    ],
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
        tray = tray.union(&Solid::compose(&ribs))?;
    }
    if let Some(g) = &layer.marker_grid {
        let holes = g
            .positions_mm()
            .into_iter()
            .map(|[x, y]| feature_solid(&g.feature, [x, y, floor_mm], [0.0, 0.0, -1.0], 1.0, tol))
            .collect::<Result<Vec<_>, _>>()?;
        tray = tray.difference(&Solid::compose(&holes))?;
    }
    Ok(tray)
}

/// About how many triangles a flat kit has at `tol` (both trays and the layers): the
/// outline's prisms, 12 per channel groove or rib, and per marker a revolved feature of
/// `circle_segments` by a quarter as many profile points (and its seam with the face) in its
/// layer, and in its tray's hole
/// another (printed trays) or a straight hole of 4 triangles a segment (`laser_cut` trays).
pub fn estimated_triangles(layers: &[FlatLayer], laser_cut: bool, tol: ChordTolerance) -> f64 {
    layers
        .iter()
        .map(|l| {
            // a wrapping layer: its prism and, inside it, the prism it wraps
            let wrapped = if l.wraps.is_some() { 2.0 } else { 1.0 };
            let prism_tris = wrapped * 4.0 * l.outline.polygon(tol).len() as f64;
            let ch = l
                .channels
                .as_ref()
                .map_or(0.0, |c| 2.0 * 24.0 * c.count as f64);
            let mk = l.marker_grid.as_ref().map_or(0.0, |g| {
                let n = tol.circle_segments(g.feature.radius_mm()) as f64;
                let revolved = 4.0 * n * (n / 4.0 + 3.0);
                // a laser-cut tray's straight holes cast flat-ended markers (layer_solid_as_cast)
                let one = if laser_cut { 4.0 * n } else { revolved };
                (g.rows * g.columns) as f64 * 2.0 * one
            });
            3.0 * prism_tris + ch + mk
        })
        .sum()
}
