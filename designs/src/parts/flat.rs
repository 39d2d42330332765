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
use crate::markers::feature_solid;

use crate::parts::registry::FAMILIES;
pub use crate::profile::FlatOutline;

pub use crate::parts::channels::{ChannelEnds, ChannelSet, ChannelTube, FlatLayer, MarkerGrid};

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
    layer_solid_as_cast(outline, layer, false, tol)
}

/// [`layer_solid`] as the layer's tray casts it: in a laser-cut tray (`laser_cut`) the markers
/// are flat-ended, the straight holes through the marker sheet
/// ([`crate::parts::lasercut::tray_sheets`]) with the same polygon, instead of ending in a
/// hemisphere as a printed tray's holes do.
///
/// # Errors
/// [`GeometryError`] on a kernel failure.
pub fn layer_solid_as_cast(
    outline: &FlatOutline,
    layer: &FlatLayer,
    laser_cut: bool,
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
/// `wall` mm round the outline and `floor` mm under the layer, its cavity the outline's prism
/// as deep as the layer (poured to the brim and scraped level, the poured face the layer's
/// top). For a channel layer, ribs on the floor form the grooves and run into the near wall,
/// so that the channels open at the near edge; for a marker layer, holes in the floor form the
/// markers.
///
/// # Errors
/// [`GeometryError`] on a kernel failure.
pub fn tray_solid(
    outline: &FlatOutline,
    layer: &FlatLayer,
    wall_mm: f64,
    floor_mm: f64,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    let (hw, hl) = (outline.width_mm / 2.0, outline.length_mm / 2.0);
    let depth = layer.z1_mm - layer.z0_mm;
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

/// The layers of a flat design, inner (camera side, from the base plane) to outer, with
/// their z ranges; `None` for a design that is not flat or whose thicknesses are not given.
pub fn flat_layers(design: &crate::schema::Design) -> Option<Vec<FlatLayer>> {
    let crate::profile::BodyProfile::Flat { thickness_mm, .. } = design.body else {
        return None;
    };
    let given: f64 = design.layers.iter().filter_map(|l| l.thickness_mm).sum();
    let mut z = 0.0;
    let mut out = Vec::with_capacity(design.layers.len());
    for (i, l) in design.layers.iter().enumerate() {
        let t = match (l.thickness_mm, l.solid && i == 0) {
            (Some(t), _) => t,
            (None, true) => thickness_mm - given,
            (None, false) => return None,
        };
        out.push(FlatLayer {
            name: l.name.clone(),
            z0_mm: z,
            z1_mm: z + t,
            channels: l.channels.clone(),
            marker_grid: l.marker_grid.clone(),
        });
        z += t;
    }
    Some(out)
}

/// Every rule of a flat design, by path (see [`build_kit`]).
pub fn validate(
    design: &crate::schema::Design,
    materials: &crate::materials::MaterialsTable,
) -> Result<Vec<FlatLayer>, crate::ParamErrors> {
    let numbers = crate::values::check_values(design, crate::schema::DESIGN_SIGNED_MM);
    if !numbers.unusable.is_empty() {
        // a count past any count, said by its field's own rule
        return Err(crate::ParamErrors(crate::values::with_field_count_rules(
            design,
            numbers.unusable,
            |d| {
                validate(d, materials)
                    .err()
                    .map(|e| e.0)
                    .unwrap_or_default()
            },
        )));
    }
    let mut errs = Vec::new();
    if !crate::values::is_file_stem(&design.name) {
        errs.push(ParamError::new(
            "name",
            format!("{:?}", design.name),
            "must be 1 to 64 lowercase letters, digits and _",
        ));
    }
    for (path, value, rule) in design.body.violations() {
        errs.push(ParamError::new(path, value, rule));
    }
    let body_ok = errs.is_empty();
    check_design_sections(design, &mut errs);
    check_layer_fields(design, materials, &mut errs);
    let Some(outline) = design.body.flat_outline() else {
        return Err(crate::ParamErrors(numbers.merge_negative(errs)));
    };
    let layers = if errs.is_empty() {
        flat_layers(design)
    } else {
        None
    };
    if let Some(layers) = &layers {
        check_layer_stack(design, layers, &outline, body_ok, &mut errs);
    }
    check_laser_cut_trays(design, materials, layers.as_deref(), &outline, &mut errs);
    let errs = numbers.merge_negative(errs);
    match layers {
        Some(l) if errs.is_empty() => Ok(l),
        _ => Err(crate::ParamErrors(errs)),
    }
}

/// The design-wide rules of a flat skin after its body: no curved skins' sections (`core`,
/// `backing`, `housing`, the section families), at least one layer, the mold, printer and
/// optics parameters, and `casting.waste_allowance` in [0, 1]; pushed onto `errs` in that
/// order.
fn check_design_sections(design: &crate::schema::Design, errs: &mut Vec<ParamError>) {
    let curved_only = [
        ("core", design.core.is_some()),
        ("backing", design.backing.is_some()),
        ("housing", design.housing.is_some()),
    ]
    .into_iter()
    .chain(FAMILIES.iter().map(|f| (f.path(), f.given(design))));
    for (path, given) in curved_only {
        if given {
            errs.push(ParamError::new(
                path,
                "given",
                "does not apply to a flat skin (body.profile: flat)",
            ));
        }
    }
    if design.layers.is_empty() {
        errs.push(ParamError::new("layers", "[]", "give at least one layer"));
    }
    // the trays' walls and printers, the pours' waste (the curved skins' rules)
    crate::parts::molds::check_mold_params(design, errs);
    crate::schema::printers::check_printers(&design.printers, errs);
    if let Some(o) = &design.optics {
        crate::schema::optics::check(o, errs);
    }
    if !(0.0..=1.0).contains(&design.casting.waste_allowance) {
        errs.push(ParamError::new(
            "casting.waste_allowance",
            design.casting.waste_allowance,
            "must be in [0, 1]",
        ));
    }
}

/// The rules of each layer's own fields (`layers[i].name`, `process`, `material`, `markers`,
/// `outer_radius_mm`, `thickness_mm`, `channels`, `marker_grid`), layer by layer, pushed onto
/// `errs`.
fn check_layer_fields(
    design: &crate::schema::Design,
    materials: &crate::materials::MaterialsTable,
    errs: &mut Vec<ParamError>,
) {
    use crate::materials::MaterialKind;
    use crate::schema::LayerProcess;
    let mut names = std::collections::BTreeSet::new();
    for (i, l) in design.layers.iter().enumerate() {
        let p = |f: &str| format!("layers[{i}].{f}");
        if !crate::values::is_file_stem(&l.name) || !names.insert(l.name.as_str()) {
            errs.push(ParamError::new(
                p("name"),
                format!("{:?}", l.name),
                "must be 1 to 64 lowercase letters, digits and _, and unique",
            ));
        }
        if l.process != LayerProcess::Cast {
            errs.push(ParamError::new(
                p("process"),
                format!("{:?}", l.process).to_lowercase(),
                "a flat skin's layers are cast (each in its tray)",
            ));
        }
        match materials.get(&l.material) {
            Some(m) if m.kind == MaterialKind::Cast => {}
            Some(_) => errs.push(ParamError::new(
                p("material"),
                &l.material,
                "must be a cast material",
            )),
            None => errs.push(ParamError::new(
                p("material"),
                &l.material,
                "unknown material",
            )),
        }
        for (key, rule) in crate::parts::layer_registry::flat_refusals(l) {
            errs.push(ParamError::new(p(key), "given", rule));
        }
        if !l.markers.is_empty() {
            errs.push(ParamError::new(
                p("markers"),
                "given",
                "curved skins' marker patterns do not apply to a flat skin: use marker_grid",
            ));
        }
        if l.outer_radius_mm.is_some() || l.mold_strategy.is_some() || l.brushed_coat.is_some() {
            errs.push(ParamError::new(
                p("outer_radius_mm"),
                "given",
                "outer_radius_mm, mold_strategy and brushed_coat do not apply to a flat skin's layers",
            ));
        }
        match (l.thickness_mm, l.solid) {
            (Some(t), false) if t > 0.0 => {}
            (None, true) if i == 0 => {}
            (t, _) => errs.push(ParamError::new(
                p("thickness_mm"),
                t.map_or("none".to_string(), |t| t.to_string()),
                "give a thickness above 0 (or solid: true on the innermost layer, which fills down to the base plane)",
            )),
        }
        if i == 0 && l.channels.is_some() {
            errs.push(ParamError::new(
                p("channels"),
                "given",
                "the innermost layer cannot hold channels: their grooves are closed by the layer under them",
            ));
        }
        if i != 0 && l.marker_grid.is_some() {
            errs.push(ParamError::new(
                p("marker_grid"),
                "given",
                "markers stand on the innermost layer's bottom face (towards the camera)",
            ));
        }
    }
}

/// The rules of the stacked layers (valid fields): their thicknesses add up to
/// `body.thickness_mm`, and, when the body is valid (`body_ok`), each layer's channels and
/// marker grid fit `outline`; pushed onto `errs`.
fn check_layer_stack(
    design: &crate::schema::Design,
    layers: &[FlatLayer],
    outline: &FlatOutline,
    body_ok: bool,
    errs: &mut Vec<ParamError>,
) {
    if let crate::profile::BodyProfile::Flat { thickness_mm, .. } = &design.body {
        let top = layers.last().map_or(0.0, |l| l.z1_mm);
        if (top - thickness_mm).abs() > 1e-9 || layers.first().is_some_and(|l| l.z1_mm <= 0.0) {
            errs.push(ParamError::new(
                "layers",
                format!("{top} mm in all"),
                format!(
                    "the layers' thicknesses must add up to body.thickness_mm ({thickness_mm} mm)"
                ),
            ));
        }
        for (i, l) in layers.iter().enumerate() {
            if !body_ok {
                break;
            }
            if let Some(c) = &l.channels {
                errs.extend(c.errors(
                    &format!("layers[{i}].channels."),
                    l.z1_mm - l.z0_mm,
                    outline,
                ));
            }
            if let Some(g) = &l.marker_grid {
                errs.extend(g.errors(&format!("layers[{i}].marker_grid."), outline));
            }
        }
    }
}

/// The rules of laser-cut trays (`mold.laser_cut`), checked only when the layers were stacked
/// and nothing else is wrong: the stock and registration, then every tray's sheets; pushed
/// onto `errs`.
fn check_laser_cut_trays(
    design: &crate::schema::Design,
    materials: &crate::materials::MaterialsTable,
    layers: Option<&[FlatLayer]>,
    outline: &FlatOutline,
    errs: &mut Vec<ParamError>,
) {
    // laser-cut trays: the stock and registration, then every tray's sheets
    if let (Some(lc), Some(layers), true) = (&design.mold.laser_cut, layers, errs.is_empty()) {
        let wall = design.mold.wall_thickness_mm;
        let lc_errs = crate::parts::lasercut::check_params(lc, wall, materials);
        if lc_errs.is_empty() {
            let tol =
                ChordTolerance::new(ChordTolerance::DEFAULT_MM).expect("the default is valid");
            for (i, l) in layers.iter().enumerate() {
                if let Err(e) = crate::parts::lasercut::tray_sheets(outline, l, i, wall, lc, tol) {
                    errs.extend(e);
                }
            }
        }
        errs.extend(lc_errs);
    }
}

/// About how many triangles a flat kit has at `tol` (both trays and the layers): the
/// outline's prisms, 12 per channel groove or rib, and per marker a revolved feature of
/// `circle_segments` by a quarter as many profile points (and its seam with the face) in its
/// layer, and in its tray's hole
/// another (printed trays) or a straight hole of 4 triangles a segment (`laser_cut` trays).
pub fn estimated_triangles(
    outline: &FlatOutline,
    layers: &[FlatLayer],
    laser_cut: bool,
    tol: ChordTolerance,
) -> f64 {
    let prism_tris = 4.0 * outline.polygon(tol).len() as f64;
    layers
        .iter()
        .map(|l| {
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
