//! The rules of a flat skin's design ([`validate`]) and its layers' z ranges
//! ([`flat_layers`]): the design-wide sections, each layer's own fields, the stacked
//! thicknesses, the channels and marker grid within the outline, and the laser-cut trays
//! (Soter et al., Sec. II-A; docs/conventions.md, flat skins). The parts are built by
//! [`crate::parts::flat`] and [`crate::build`].

use crate::error::ParamError;
use crate::geometry::ChordTolerance;
use crate::parts::channels::FlatLayer;
use crate::parts::flat_family::FLAT_FAMILIES;
use crate::parts::layer_feature::FlatInput;
use crate::parts::registry::FAMILIES;
use crate::profile::FlatOutline;
use crate::schema::Design;

/// The layers of a flat design, inner (camera side, from the base plane) to outer, with
/// their z ranges; `None` for a design that is not flat or whose thicknesses are not given.
pub fn flat_layers(design: &Design) -> Option<Vec<FlatLayer>> {
    let crate::profile::BodyProfile::Flat { thickness_mm, .. } = design.body else {
        return None;
    };
    let mut outline = design.body.flat_outline()?;
    let given: f64 = design.layers.iter().filter_map(|l| l.thickness_mm).sum();
    let mut z = 0.0;
    let mut out = Vec::with_capacity(design.layers.len());
    for (i, l) in design.layers.iter().enumerate() {
        let t = match (l.thickness_mm, l.solid && i == 0) {
            (Some(t), _) => t,
            (None, true) => thickness_mm - given,
            (None, false) => return None,
        };
        let wraps = l.wrap_mm.filter(|_| i > 0).map(|side_mm| {
            let under = outline.clone();
            outline = under.grown(side_mm);
            crate::parts::channels::Wrap {
                side_mm,
                under,
                outline: outline.clone(),
            }
        });
        out.push(FlatLayer {
            name: l.name.clone(),
            z0_mm: z,
            z1_mm: z + t,
            outline: outline.clone(),
            wraps,
            channels: l.channels.clone(),
            marker_grid: l.marker_grid.clone(),
        });
        z += t;
    }
    Some(out)
}

/// Every rule of a flat design, by path (see [`crate::build::build_kit`]).
pub fn validate(
    design: &Design,
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
        check_layer_stack(design, layers, body_ok, &mut errs);
    }
    check_laser_cut_trays(design, materials, layers.as_deref(), &outline, &mut errs);
    check_flat_families(design, materials, layers.as_deref(), &mut errs);
    let errs = numbers.merge_negative(errs);
    match layers {
        Some(l) if errs.is_empty() => Ok(l),
        _ => Err(crate::ParamErrors(errs)),
    }
}

/// Every flat part family's rules ([`FLAT_FAMILIES`]): its materials, then its own rules (with
/// the skin's layers when they are sound).
fn check_flat_families(
    design: &Design,
    materials: &crate::materials::MaterialsTable,
    layers: Option<&[FlatLayer]>,
    errs: &mut Vec<ParamError>,
) {
    for f in FLAT_FAMILIES {
        for (path, key, kinds) in f.materials(design) {
            match materials.get(key) {
                None => errs.push(ParamError::new(path, key, "unknown material")),
                Some(m) if !kinds.contains(&m.kind) => errs.push(ParamError::new(
                    path,
                    key,
                    format!("is a {:?} material, expected one of {:?}", m.kind, kinds),
                )),
                Some(_) => {}
            }
        }
        f.check(design, layers, errs);
    }
}

/// The design-wide rules of a flat skin after its body: no curved skins' sections (`core`,
/// `backing`, `housing`, the section families), at least one layer, the mold, printer and
/// optics parameters, and `casting.waste_allowance` in [0, 1]; pushed onto `errs` in that
/// order.
fn check_design_sections(design: &Design, errs: &mut Vec<ParamError>) {
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
    crate::parts::molds::check_mold_params(&design.stack_input(), errs);
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
    design: &Design,
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
        for (key, rule) in crate::parts::layer_registry::flat_misplaced(l, i) {
            errs.push(ParamError::new(p(key), "given", rule));
        }
    }
    check_wraps(design, errs);
}

/// The rules of wrapping layers (`layers[i].wrap_mm`): above 0, not on the innermost layer,
/// on every layer from the second up when on one (each is cast over the cured layers under
/// it, inner first), and no channels or marker grid on a wrapping layer nor channels in a
/// wrapped stack (channel layers are cast outer first and laid on, Soter et al. Sec. II-A);
/// pushed onto `errs`.
fn check_wraps(design: &Design, errs: &mut Vec<ParamError>) {
    let wrapped = design.layers.iter().any(|l| l.wrap_mm.is_some());
    if !wrapped {
        return;
    }
    for (i, l) in design.layers.iter().enumerate() {
        let p = |f: &str| format!("layers[{i}].{f}");
        match l.wrap_mm {
            Some(_) if i == 0 => errs.push(ParamError::new(
                p("wrap_mm"),
                l.wrap_mm.unwrap_or_default(),
                "the innermost layer has no layer under it to wrap",
            )),
            Some(w) if !(w > 0.0 && w.is_finite()) => errs.push(ParamError::new(
                p("wrap_mm"),
                w,
                "must be above 0 (the layer's thickness at the sides of the layers it wraps)",
            )),
            None if i > 0 => errs.push(ParamError::new(
                p("wrap_mm"),
                "none",
                "give it: when a layer wraps the layers under it, every layer from the second up does (each is cast over the cured layers under it, inner first)",
            )),
            _ => {}
        }
        if l.channels.is_some() {
            errs.push(ParamError::new(
                p("channels"),
                "given",
                "a stack of wrapping layers (layers[*].wrap_mm) takes no channels: channel layers are cast outer first and laid onto the tacky layer under them (Soter et al. Sec. II-A), wrapping layers inner first over the cured ones",
            ));
        }
        if l.marker_grid.is_some() && i > 0 {
            errs.push(ParamError::new(
                p("marker_grid"),
                "given",
                "a wrapping layer takes no marker grid: its bottom face is the cured layers under it",
            ));
        }
    }
}

/// The rules of the stacked layers (valid fields): their thicknesses add up to
/// `body.thickness_mm`, and, when the body is valid (`body_ok`), each layer's channels and
/// marker grid fit its outline; pushed onto `errs`.
fn check_layer_stack(
    design: &Design,
    layers: &[FlatLayer],
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
            let input = FlatInput {
                index: i,
                thickness_mm: l.z1_mm - l.z0_mm,
                outline: &l.outline,
            };
            crate::parts::layer_registry::check_flat_features(&design.layers[i], input, errs);
        }
    }
}

/// The rules of laser-cut trays (`mold.laser_cut`), checked only when the layers were stacked
/// and nothing else is wrong: the stock and registration, then every tray's sheets; pushed
/// onto `errs`.
fn check_laser_cut_trays(
    design: &Design,
    materials: &crate::materials::MaterialsTable,
    layers: Option<&[FlatLayer]>,
    outline: &FlatOutline,
    errs: &mut Vec<ParamError>,
) {
    // laser-cut trays: the stock and registration, then every tray's sheets
    if let (Some(lc), Some(layers), true) = (&design.mold.laser_cut, layers, errs.is_empty()) {
        let wall = design.mold.wall_thickness_mm;
        // the plate and the sheets round the largest pocket, the outermost layer's
        let outer = layers.last().map_or(outline, |l| &l.outline);
        let lc_errs = crate::parts::lasercut::check_params(lc, outer, wall, materials);
        if lc_errs.is_empty() {
            let tol =
                ChordTolerance::new(ChordTolerance::DEFAULT_MM).expect("the default is valid");
            for (i, l) in layers.iter().enumerate() {
                if let Err(e) = crate::parts::lasercut::tray_sheets(outer, l, i, wall, lc, tol) {
                    errs.extend(e);
                }
            }
        }
        errs.extend(lc_errs);
    }
}
