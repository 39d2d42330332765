//! The kit of a flat skin (Soter et al. Sec. II-A): a casting tray per layer (printed, or
//! stacked from laser-cut sheets), the pours, the channels' tubes and liquid, the procedure.
//! Its layers' rules and solids are the flat family's ([`crate::parts::flat`]).

use crate::error::{DesignError, GeometryContext as _};
use crate::geometry::ChordTolerance;
use crate::kit::Kit;
use crate::materials::{CastReport, MaterialsTable};
use crate::parts::cut_part::CutPart;
use crate::parts::flat::{
    estimated_triangles, layer_solid_as_cast, tray_solid, ChannelEnds, ChannelSet, FlatLayer,
    FlatOutline,
};
use crate::parts::flat_family::{FlatBuilt, FlatFamilyInput, FLAT_FAMILIES};
use crate::parts::{Member, MemberKind, Part, PrintTechnology, ProcedureAction, ProcedureStep};
use crate::schema::{Design, LaserCutParams};
use crate::stack::flat::validate;

/// Validates a flat design ([`validate`]) and builds its kit at `tol`: one tray per layer
/// (FDM or as `mold.fixture_print_technology` says; Soter et al. laser-cut theirs), the pours
/// in order (the channel layers first, then the marker layer the channel layer is laid onto
/// while it is tacky: Sec. II-A casts the top layer first), the tubes and liquid, the
/// procedure, and the skin's layers as the assembly (for the section view).
///
/// # Errors
/// [`crate::DesignError::Params`] with every violated rule; [`crate::DesignError::WorkLimit`]
/// past `max_triangles`; [`crate::DesignError::Geometry`] on a kernel failure.
pub(crate) fn build_flat_kit(
    design: &Design,
    materials: &MaterialsTable,
    tol: ChordTolerance,
    max_triangles: u64,
) -> Result<Kit, DesignError> {
    let layers = validate(design, materials).map_err(DesignError::Params)?;
    let Some(outline) = design.body.flat_outline() else {
        return Err(DesignError::Yaml("not a flat design".into()));
    };
    let est = estimated_triangles(&layers, design.mold.laser_cut.is_some(), tol)
        + crate::parts::flat_family::estimated_triangles(design, tol);
    if est > max_triangles as f64 {
        return Err(DesignError::WorkLimit(format!(
            "{}: the kit would have about {:.0} triangles at chord tolerance {} mm, more than the limit of {max_triangles} (about 1 KB of memory each; raise it with --max-triangles, up to {}, or coarsen --chord-tolerance-mm)",
            design.name,
            est,
            tol.mm(),
            crate::estimate::MAX_TRIANGLES_LIMIT
        )));
    }
    let m = &design.mold;
    let tech: PrintTechnology = m.fixture_print_technology.into();
    let wall = m.wall_thickness_mm;
    let mut parts = Vec::new();
    let mut assembly = Vec::new();
    let mut volumes = Vec::new();
    let mut cut_parts = Vec::new();
    let laser = design.mold.laser_cut.as_ref();
    // the sheets of every tray round the largest pocket, the outermost layer's
    let outer = layers.last().map_or(&outline, |l| &l.outline);
    let wrapped = layers.iter().any(|l| l.wraps.is_some());
    for (i, l) in layers.iter().enumerate() {
        let tray = TrayInput {
            outer,
            shared_base: wrapped.then(|| layers[0].name.as_str()),
            laser,
            tech,
            wall,
        };
        let (part, mut member, v, sheets) = layer_tray(l, i, &tray, tol)?;
        member.material = design.layers.get(i).map(|d| d.material.clone());
        parts.push(part);
        assembly.push(member);
        volumes.push(v);
        // a wrapped stack's trays share the innermost tray's base sheet: cut once
        for c in sheets {
            if !cut_parts.iter().any(|k: &CutPart| k.name == c.name) {
                cut_parts.push(c);
            }
        }
    }
    // pours: a wrapped stack inner first, each layer over the cured ones; else the channel
    // layers (outer) first, the innermost (marker) layer last
    let order: Vec<usize> = if wrapped {
        (0..layers.len()).collect()
    } else {
        (1..layers.len()).chain(std::iter::once(0)).collect()
    };
    let mut casts = Vec::new();
    for (step, &i) in order.iter().enumerate() {
        let l = &design.layers[i];
        let mat = materials
            .get(&l.material)
            .ok_or_else(|| DesignError::Yaml(format!("unknown material {}", l.material)))?;
        casts.push(
            crate::materials::pour(
                step as u32 + 1,
                &l.name,
                &l.material,
                mat,
                vec![parts[i].name.clone()],
                volumes[i],
                design.casting.waste_allowance,
            )
            .map_err(DesignError::Yaml)?,
        );
    }
    let channel_sets: Vec<(&FlatLayer, &ChannelSet)> = layers
        .iter()
        .filter_map(|l| l.channels.as_ref().map(|c| (l, c)))
        .collect();
    let (mut bought, liquid_ml) = bought_items(&layers, &channel_sets, laser, &cut_parts);
    let mut procedure = procedure(&parts, &casts, &layers, &channel_sets, laser, outer);
    let housed = families(design, &layers, tol)?;
    if !housed.parts.is_empty() || !housed.cut_parts.is_empty() {
        procedure.push(housing_print_step(&housed));
    }
    parts.extend(housed.parts);
    cut_parts.extend(housed.cut_parts);
    for f in FLAT_FAMILIES {
        bought.extend(f.bought_items(design));
        procedure.extend(
            f.assembly_steps(design, &parts)
                .into_iter()
                .map(|t| ProcedureStep::new(ProcedureAction::Assemble, format!("Assemble: {t}"))),
        );
    }
    if !housed.members.is_empty() {
        assembly.extend(housed.members);
        let found = crate::assembly::interferences(&assembly, tol)?;
        if let Some(e) = crate::assembly::fit_errors(design, &found) {
            return Err(e);
        }
    }
    let summary = serde_json::json!({
        "flat": {
            "outline": outline,
            "area_mm2": outline.area_mm2(),
            "layers": layers.iter().map(|l| {
                let mut j = serde_json::json!({"name": l.name, "z0_mm": l.z0_mm, "z1_mm": l.z1_mm});
                if let Some(w) = &l.wraps {
                    j["wraps"] = serde_json::json!(w);
                }
                j
            }).collect::<Vec<_>>(),
            "channels": channel_sets.iter().map(|(l, c)| serde_json::json!({
                "layer": l.name, "count": c.count, "channel_volume_mm3": c.channel_volume_mm3(),
                "liquid_per_channel_ml": c.liquid_per_channel_ml(), "ends": c.ends,
                "centres_x_mm": c.centres_x_mm()})).collect::<Vec<_>>(),
            "markers": layers.iter().filter_map(|l| l.marker_grid.as_ref()).map(|g| g.rows * g.columns).sum::<usize>(),
            "liquid_ml": liquid_ml,
        }
    });
    Ok(Kit {
        design: design.name.clone(),
        parts,
        casts,
        bought_items: bought,
        procedure,
        assembly,
        cut_parts,
        pcb_outlines: Vec::new(),
        machined_parts: Vec::new(),
        summary,
    })
}

/// Every flat part family's parts, members and cut parts ([`FLAT_FAMILIES`]), in order.
///
/// # Errors
/// As [`crate::parts::flat_family::FlatFamily::build`].
fn families(
    design: &Design,
    layers: &[FlatLayer],
    tol: ChordTolerance,
) -> Result<FlatBuilt, DesignError> {
    let mut out = FlatBuilt::default();
    for f in FLAT_FAMILIES {
        if let Some(built) = f.build(design, FlatFamilyInput { layers, tol }) {
            let built = built?;
            out.parts.extend(built.parts);
            out.members.extend(built.members);
            out.cut_parts.extend(built.cut_parts);
        }
    }
    Ok(out)
}

/// The step that prints the families' parts and cuts their cut parts, after the pours.
fn housing_print_step(housed: &FlatBuilt) -> ProcedureStep {
    let printed = housed
        .parts
        .iter()
        .map(|p| format!("{} ({:?}, {})", p.name, p.print_technology, p.material))
        .collect::<Vec<_>>()
        .join(", ");
    let cut = housed
        .cut_parts
        .iter()
        .map(|c| {
            format!(
                "{} (cut/{}.dxf, {} {:.2} mm)",
                c.name, c.name, c.material, c.thickness_mm
            )
        })
        .collect::<Vec<_>>()
        .join(", ");
    let text = match (printed.is_empty(), cut.is_empty()) {
        (false, false) => format!("Print the housing's parts: {printed}; cut {cut}."),
        (false, true) => format!("Print the housing's parts: {printed}."),
        _ => format!("Cut {cut}."),
    };
    ProcedureStep::new(ProcedureAction::Print, text)
}

/// What every tray of a flat kit shares: the outermost layer's outline (the laser-cut sheets
/// are cut round it), the innermost layer's name when the trays share its base sheet (a
/// wrapped stack), `mold.laser_cut`, the trays' print technology and wall, mm.
struct TrayInput<'a> {
    outer: &'a FlatOutline,
    shared_base: Option<&'a str>,
    laser: Option<&'a LaserCutParams>,
    tech: PrintTechnology,
    wall: f64,
}

/// Layer `i`'s casting tray (printed, or the union of its laser-cut sheets) with the cast
/// layer as its member of the assembly, the layer's exact volume (mm^3) and the tray's sheets
/// as cut parts.
///
/// # Errors
/// [`DesignError`] naming the tray or the layer if a sheet or the kernel fails.
fn layer_tray(
    l: &FlatLayer,
    i: usize,
    input: &TrayInput<'_>,
    tol: ChordTolerance,
) -> Result<(Part, Member, f64, Vec<CutPart>), DesignError> {
    let TrayInput {
        outer,
        shared_base,
        laser,
        tech,
        wall,
    } = *input;
    let mut cut_parts = Vec::new();
    let name = format!("{}_tray", l.name);
    // a laser-cut tray: its sheets, their union the printable tray; the layer's bottom face
    // on the base sheet (and the marker sheet)
    let (tray, floor, sheets) = match laser {
        Some(lc) => {
            let mut sheets = crate::parts::lasercut::tray_sheets(outer, l, i, wall, lc, tol)
                .map_err(|e| DesignError::Params(crate::ParamErrors(e)))?;
            for s in &mut sheets {
                let what = match shared_base {
                    Some(first) if s.role == "base" => {
                        // one base sheet under every tray: the layers stay on it between pours
                        s.name = format!("{first}_tray_1_base");
                        format!("every tray's base (the cured layers stay on it for the next pour), sheet {}", s.name)
                    }
                    _ => format!("{} tray, sheet {}: {}", l.name, s.name, s.role),
                };
                cut_parts.push(
                    crate::parts::lasercut::cut_part(s, &what, lc.plate.as_ref(), tol)
                        .map_err(DesignError::Yaml)?,
                );
            }
            let floor = sheets
                .iter()
                .filter(|s| s.role == "base" || s.role == "markers")
                .map(|s| s.level_mm())
                .sum::<f64>();
            (
                crate::parts::lasercut::tray_union(&sheets).part(&name)?,
                floor,
                Some(sheets),
            )
        }
        None => {
            let floor = wall + l.marker_grid.as_ref().map_or(0.0, |g| g.feature.height_mm);
            (tray_solid(l, wall, floor, tol).part(&name)?, floor, None)
        }
    };
    let skin = layer_solid_as_cast(l, laser.is_some(), tol).part(&l.name)?;
    let t = l.z1_mm - l.z0_mm;
    let depth = l.pocket_depth_mm();
    // the cast layer's own volume, exact (flat-ended markers in a laser-cut tray: its holes
    // go straight through their sheet)
    let v = l.volume_mm3(laser.is_some());
    let what = match (&l.channels, &l.marker_grid) {
        (Some(c), _) => format!(", {} ribs forming the channels' grooves", c.count),
        (_, Some(g)) => format!(", {} x {} holes forming the markers", g.rows, g.columns),
        _ => String::new(),
    };
    let made = match (&sheets, shared_base.filter(|_| l.wraps.is_some())) {
        (Some(s), Some(first)) => format!(
            "; the union of its {} laser-cut sheets (cut/{first}_tray_1_base, every tray's base, and cut/{name}_*), or print it",
            s.iter().map(|s| s.quantity).sum::<u32>(),
        ),
        (Some(s), None) => format!(
            "; the union of its {} laser-cut sheets (cut/{}_*), or print it",
            s.iter().map(|s| s.quantity).sum::<u32>(),
            name
        ),
        (None, _) => String::new(),
    };
    let over = match &l.wraps {
        Some(w) => format!(
            ", round the cured layers under it: {:.2} mm over their top, {:.2} mm at their sides",
            t, w.side_mm
        ),
        None => String::new(),
    };
    let mut part = Part {
        name: name.clone(),
        role: "casting_tray".into(),
        description: format!(
            "Open tray of layer {} ({depth:.2} mm deep{what}{over}); pour to the brim and scrape level{made}",
            l.name
        ),
        material: crate::parts::molds::material_for(tech).into(),
        print_technology: tech,
        solid: tray,
        params: serde_json::json!({
            "layer": l.name, "layer_index": i, "outline": l.outline, "depth_mm": depth,
            "z0_mm": l.bottom_mm(), "wall_mm": wall, "floor_mm": floor,
            "channels": l.channels, "marker_grid": l.marker_grid,
            "laser_cut": sheets.as_ref().map(|sh| serde_json::json!({
                "sheets": sh.iter().map(|s| serde_json::json!({"name": s.name, "role": s.role, "stock": s.stock,
                    "quantity": s.quantity, "z0_mm": s.z0_mm, "level_mm": s.level_mm(), "area_mm2": s.region.area_mm2()})).collect::<Vec<_>>(),
                "registration_xy_mm": crate::parts::lasercut::registration_xy_mm(outer, wall),
                "registration_diameter_mm": laser.map(|lc| lc.registration.diameter_mm),
                "markers": "flat-ended, straight through their sheet",
            })),
            // the layer's lowest face on the tray's floor (print z = floor)
            "T_print_sensor": [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, floor - l.bottom_mm()]],
        }),
        group: None,
    };
    // a plate's outline and holes (mold.laser_cut.plate) for the tray's twin
    if let (Some(plate), Some(lc)) = (
        laser.and_then(|lc| lc.plate.as_ref()),
        part.params.get_mut("laser_cut"),
    ) {
        lc["plate"] = serde_json::json!(plate);
    }
    // the sheets of a wrapped stack's inner trays are cut round the outermost pocket
    if let (true, Some(lc)) = (outer != &l.outline, part.params.get_mut("laser_cut")) {
        lc["sheets_round"] = serde_json::json!(outer);
    }
    let member = Member {
        name: l.name.clone(),
        kind: MemberKind::Cast,
        description: format!("{} layer, {t:.2} mm", l.name),
        solid: skin,
        fix: vec![format!("layers[{i}]")],
        nested_by_stack: true,
        features: Default::default(),
        exact: None,
        material: None,
    };
    Ok((part, member, v, cut_parts))
}

/// The bought items of a flat kit: the channels' tubes, adhesive and liquid, the dowels and
/// sheet stock of laser-cut trays, the markers' paint; with the liquid's volume, mL.
fn bought_items(
    layers: &[FlatLayer],
    channel_sets: &[(&FlatLayer, &ChannelSet)],
    laser: Option<&LaserCutParams>,
    cut_parts: &[CutPart],
) -> (Vec<String>, f64) {
    let mut bought = Vec::new();
    let mut liquid_ml = 0.0;
    let wrapped = layers.iter().any(|l| l.wraps.is_some());
    for (l, c) in channel_sets {
        let t = &c.tube;
        liquid_ml += c.count as f64 * c.liquid_per_channel_ml();
        bought.push(format!(
            "{} x silicone tube {:.1} mm OD, {:.1} mm ID, {:.0} mm long (one per channel of layer {}, from the skin to the display)",
            c.count, t.outer_diameter_mm, t.inner_diameter_mm, t.length_mm, l.name
        ));
    }
    if !channel_sets.is_empty() {
        bought.push(
            "Smooth-On Sil-Poxy silicone adhesive (glues the tubes into the channels' mouths)"
                .into(),
        );
        bought.push(format!(
            "Coloured liquid (water with food dye), {:.1} mL in the channels and tubes, and a tank deep enough to submerge the skin and tubes in it",
            liquid_ml
        ));
    }
    if let Some(lc) = laser {
        let pins = match &lc.plate {
            None => format!(
                "{} x steel dowel pin {} mm diameter",
                4 * layers.len(),
                lc.registration.diameter_mm
            ),
            Some(p) => format!(
                "{} x bolt (with nut) or dowel pin for the plates' {} mm holes",
                // a wrapped stack's trays are stacked on one base sheet, one at a time
                p.holes.xy_mm.len() * if wrapped { 1 } else { layers.len() },
                p.holes.diameter_mm
            ),
        };
        bought.push(format!(
            "{pins}, as long as the thickest tray's stack (registration of each tray's sheets); {}",
            {
                let mut used: Vec<String> = Vec::new();
                for c in cut_parts {
                    let s = format!("{} mm {}", c.thickness_mm, c.material);
                    if !used.contains(&s) {
                        used.push(s);
                    }
                }
                format!("sheet stock: {}", used.join(", "))
            }
        ));
    }
    if layers.iter().any(|l| l.marker_grid.is_some()) {
        bought.push("White silicone paint (Silc Pig white in a little uncured Ecoflex) for the markers' ends".into());
    }
    (bought, liquid_ml)
}

/// Whether a base hole of the plate (`mold.laser_cut.plate.base_holes`) opens into the cavity
/// (the skin's `outline`), where the pour would run into it.
fn base_holes_under_pocket(lc: &LaserCutParams, outline: &FlatOutline) -> bool {
    lc.plate
        .as_ref()
        .and_then(|p| p.base_holes.as_ref())
        .is_some_and(|b| {
            b.xy_mm
                .iter()
                .any(|&c| outline.signed_distance_mm(c) < b.diameter_mm / 2.0)
        })
}

/// The procedure of a flat kit: make the trays, pour and demold each layer in order (the last
/// one closing the channels), fit and fill the channels' tubes.
fn procedure(
    parts: &[Part],
    casts: &[CastReport],
    layers: &[FlatLayer],
    channel_sets: &[(&FlatLayer, &ChannelSet)],
    laser: Option<&LaserCutParams>,
    outline: &FlatOutline,
) -> Vec<ProcedureStep> {
    let step = |action, text: String| ProcedureStep { action, text };
    let wrapped = layers.iter().any(|l| l.wraps.is_some());
    let trays = parts
        .iter()
        .map(|p| p.name.as_str())
        .collect::<Vec<_>>()
        .join(", ");
    let mut procedure = vec![match laser {
        Some(lc) => step(
            ProcedureAction::Print,
            format!(
                "Laser-cut the trays' sheets (cut/*.dxf or cut/*.svg: each sheet's paths already offset for its stock's kerf; the quantity of each is in its description), or print the trays ({trays}) instead. {} on {}, {} and seal the cavity's inside edges with a thin bead of silicone{}; check that the tray is flat and its cavity clean.",
                match parts.first().filter(|_| wrapped) {
                    Some(first) => format!(
                        "Stack the base sheet and the wall sheets of {} (the first pour's tray)",
                        first.name
                    ),
                    None => "Stack each tray's sheets in order (base at the bottom)".to_string(),
                },
                match &lc.plate {
                    None => format!(
                        "four {} mm dowel pins through the registration holes",
                        lc.registration.diameter_mm
                    ),
                    Some(p) => format!(
                        "bolts or dowel pins through the {} {} mm holes of the plates",
                        p.holes.xy_mm.len(),
                        p.holes.diameter_mm
                    ),
                },
                if wrapped {
                    "clamp them without bonding (the layers are cast one over another on the one base sheet: each tray's wall sheets come off it for the next)"
                } else {
                    "bond them (acrylic cement for acrylic, wood glue for plywood)"
                },
                if base_holes_under_pocket(lc, outline) {
                    "; tape the base sheet's holes under the cavity shut on its top face, so that no silicone runs into them and the cast face stays flat"
                } else {
                    ""
                }
            ),
        ),
        None => step(
            ProcedureAction::Print,
            format!("Print the trays ({trays}); check that each is flat and its cavity clean."),
        ),
    }];
    if wrapped {
        procedure.extend(wrapped_pours(casts, layers, laser.is_some()));
        return procedure;
    }
    for c in casts {
        let l = layers.iter().find(|l| l.name == c.cast);
        let last = c.step as usize == casts.len() && casts.len() > 1;
        procedure.push(step(
            ProcedureAction::Pour,
            format!(
                "Pour {} ({:.2} mL, {:.2} g mixed) into {}: degas the mix in a vacuum chamber, pour to the brim and scrape level{}.",
                c.cast,
                c.cavity_volume_ml,
                c.total_mass_g,
                c.mold_parts.join(", "),
                if last {
                    "; when it has gelled until tacky (about half its pot life), lay the cured layers on it, grooves down, square to the tray's walls with the channels' mouths over the near wall, and weigh them down evenly: the tacky layer closes the grooves into channels"
                } else {
                    ""
                }
            ),
        ));
        let markers = l.and_then(|l| l.marker_grid.as_ref());
        procedure.push(step(
            ProcedureAction::Demold,
            format!(
                "Cure and take {} out of its tray{}.",
                c.cast,
                if markers.is_some() {
                    "; paint the markers' ends white"
                } else {
                    ""
                }
            ),
        ));
    }
    for (l, c) in channel_sets {
        let t = &c.tube;
        procedure.push(step(
            ProcedureAction::Assemble,
            format!(
                "Push a tube {:.1} mm into each of the {} channels' mouths of {} at the near edge and glue it with Sil-Poxy; lead the tubes to the display.",
                t.insertion_mm, c.count, l.name
            ),
        ));
        procedure.push(step(
            ProcedureAction::Assemble,
            format!(
                "Fill the channels: submerge the skin and the tubes in the tank of coloured liquid and squeeze each channel until no more air leaves it (a channel closed at its far end cannot be filled by a syringe; Soter et al. Sec. II-A): {:.3} mL per channel and its tube{}.",
                c.liquid_per_channel_ml(),
                match c.ends {
                    ChannelEnds::BothClosed => "; close each tube's display end while still under the liquid, so that the liquid always returns to its place",
                    ChannelEnds::OneClosed => "; the tubes' display ends stay open",
                }
            ),
        ));
    }
    procedure
}

/// The pours of a wrapped stack, inner first (9DTact's process: the translucent gel in the
/// 2.5 mm sheet's pocket, then the black gel in the 2.8 mm sheet's pocket over it): each layer
/// on the base sheet (`laser_cut`) or in its tray's floor, the next tray put round the cured
/// layers, the last taken out with the skin.
fn wrapped_pours(
    casts: &[CastReport],
    layers: &[FlatLayer],
    laser_cut: bool,
) -> Vec<ProcedureStep> {
    let mut steps = Vec::new();
    for (k, c) in casts.iter().enumerate() {
        let Some(l) = layers.iter().find(|l| l.name == c.cast) else {
            continue;
        };
        let tray = c.mold_parts.join(", ");
        let into = match &l.wraps {
            None => format!("into {tray}"),
            Some(w) if laser_cut => format!(
                "into {tray}: stack its wall sheets on the base sheet round the cured layers (bolts or pins through the plates' holes; the pocket {:.2} mm clear of them all round), then pour over them",
                w.side_mm
            ),
            Some(w) => format!(
                "into {tray}: set the cured layers on its floor, centred ({:.2} mm clear of its walls all round), then pour over them",
                w.side_mm
            ),
        };
        steps.push(ProcedureStep {
            action: ProcedureAction::Pour,
            text: format!(
                "Pour {} ({:.2} mL, {:.2} g mixed) {into}: degas the mix in a vacuum chamber, pour to the brim and scrape level.",
                c.cast, c.cavity_volume_ml, c.total_mass_g
            ),
        });
        let next = casts.get(k + 1).map(|n| n.cast.as_str());
        steps.push(ProcedureStep {
            action: ProcedureAction::Demold,
            text: match next {
                Some(n) if laser_cut => format!(
                    "Cure {}; lift its tray's wall sheets off and leave it on the base sheet for {n}.",
                    c.cast
                ),
                Some(n) => format!(
                    "Cure {} and take it out of its tray for {n}.",
                    c.cast
                ),
                None => format!(
                    "Cure {} and take the skin (every layer, bonded) out of its tray{}.",
                    c.cast,
                    if layers.iter().any(|l| l.marker_grid.is_some()) {
                        "; paint the markers' ends white"
                    } else {
                        ""
                    }
                ),
            },
        });
    }
    steps
}
