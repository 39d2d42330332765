//! The layer stack: each layer's inner and outer surfaces as signed offsets from the body
//! surface (negative = inward), and the validation of a design.

pub mod flat;

use crate::error::{ParamError, ParamErrors};
use crate::geometry::{revolve, revolve_shell, ChordTolerance, Solid};
use crate::materials::{MaterialKind, MaterialsTable};
pub use crate::parts::context::{ResolvedCore, ResolvedLayer, Stack};
use crate::parts::layer_feature::solid_layer_profile;
use crate::parts::layer_registry::{check_layer_features, seat_of};
use crate::parts::registry::FAMILIES;
use crate::parts::stack_input::StackInput;
use crate::schema::printers::check_printers;
pub use crate::schema::printers::{check_bed, MAX_BED_MM};
pub use crate::schema::DESIGN_SIGNED_MM;
use crate::schema::{Design, LayerProcess};

impl Stack {
    /// The solid of layer `i` without its features: between its inner and outer surfaces,
    /// closed on the base plane (each surface on its own segment count, [`revolve_shell`]), or
    /// for a solid layer under its outer surface less its seat.
    ///
    /// # Errors
    /// Only on a kernel failure.
    pub fn layer_solid(
        &self,
        si: &StackInput<'_>,
        i: usize,
        tol: ChordTolerance,
    ) -> Result<Solid, crate::geometry::GeometryError> {
        Solid::from_mesh(&self.layer_mesh(si, i, tol)?)
    }

    /// The volume of [`Self::layer_solid`], mm^3, from its mesh (without building the solid).
    ///
    /// # Errors
    /// On a profile the revolve refuses.
    pub fn layer_volume_mm3(
        &self,
        si: &StackInput<'_>,
        i: usize,
        tol: ChordTolerance,
    ) -> Result<f64, crate::geometry::GeometryError> {
        Ok(self.layer_mesh(si, i, tol)?.signed_volume())
    }

    /// The closed mesh [`Self::layer_solid`] is built from.
    fn layer_mesh(
        &self,
        si: &StackInput<'_>,
        i: usize,
        tol: ChordTolerance,
    ) -> Result<crate::geometry::Mesh, crate::geometry::GeometryError> {
        let l = &self.layers[i];
        let body = si.ctx.body;
        Ok(if l.solid {
            revolve(
                &solid_layer_profile(body, l.outer_offset_mm, seat_of(si, i).as_ref(), tol.half()),
                tol,
            )?
        } else {
            revolve_shell(
                &body.offset_polyline(l.outer_offset_mm, 0.0, tol.half()),
                &body.offset_polyline(l.inner_offset_mm, 0.0, tol.half()),
                tol,
            )?
        })
    }
}

/// Checks every rule of a design and resolves its stack. Reports every violation at once.
///
/// # Errors
/// [`ParamErrors`] listing each violated rule with its parameter path and value.
pub fn validate(
    design: &Design,
    materials: &MaterialsTable,
    tol: ChordTolerance,
) -> Result<Stack, ParamErrors> {
    // Every number finite and within its unit's magnitude first: the rules below compare and
    // compute with them. Negative lengths are reported with the rules below.
    let mut numbers = crate::values::check_values(design, DESIGN_SIGNED_MM);
    // A non-finite angle of a marker point list is reported by the placement with every other
    // bad point of its list (the list's rule covers it); any other unusable value stops here.
    let (in_points, other): (Vec<_>, Vec<_>) = std::mem::take(&mut numbers.unusable)
        .into_iter()
        .partition(|e| e.path.contains(".pattern.points["));
    if !other.is_empty() {
        // a count past any count, said by its field's own rule
        let other = crate::values::with_field_count_rules(design, other, |d| {
            validate(d, materials, tol)
                .err()
                .map(|e| e.0)
                .unwrap_or_default()
        });
        return Err(ParamErrors(other.into_iter().chain(in_points).collect()));
    }
    let mut errs: Vec<ParamError> = Vec::new();
    let t = tol.mm();
    check_scope(design, &mut errs)?;
    let body_ok = errs.iter().all(|e| !e.path.starts_with("body."));
    let sphere_r = if body_ok {
        design.body.sphere_radius_mm()
    } else {
        None
    };

    check_coats_and_backing(design, &mut errs);
    check_materials(design, materials, &mut errs);

    let layer_specs_ok = check_layer_specs(design, sphere_r, body_ok, &mut errs);
    check_core_and_casting(design, sphere_r, body_ok, &mut errs);
    check_mold_strategies(design, &mut errs);
    check_layer_features(&design.stack_input(), body_ok, &mut errs);

    // Resolve the stack from the inside out, in "radius" units for spheres (r = R + offset).
    let (layers, core, stack_ok) = if body_ok && layer_specs_ok && !design.layers.is_empty() {
        resolve_surfaces(design, sphere_r, t, &mut errs)
    } else {
        (Vec::new(), None, false)
    };

    check_with_stack(design, &layers, core.as_ref(), stack_ok, &mut errs);
    let mut errs = numbers.merge_negative(errs);
    // a non-finite point's row, when the placement did not report it (its layer not placed)
    for e in in_points {
        let row = &e.path[..e.path.rfind('[').unwrap_or(e.path.len())];
        if !errs.iter().any(|x| x.path == row || x.path == e.path) {
            errs.push(e);
        }
    }
    if errs.is_empty() && stack_ok {
        Ok(Stack { core, layers })
    } else {
        Err(ParamErrors(errs))
    }
}

/// The design's name, whether its body is one this validation handles (flat skins have their
/// own, [`crate::stack::flat::validate`]), the body's own rules, and the flat-skin-only keys.
///
/// # Errors
/// The one error of a flat body, alone.
fn check_scope(design: &Design, errs: &mut Vec<ParamError>) -> Result<(), ParamErrors> {
    if !crate::values::is_file_stem(&design.name) {
        errs.push(ParamError::new(
            "name",
            format!("{:?}", design.name),
            "must be 1 to 64 lowercase letters, digits and _",
        ));
    }
    if design.body.flat_outline().is_some() {
        return Err(ParamErrors(vec![ParamError::new(
            "body.profile",
            "flat",
            "this step handles curved skins only (spherical_cap, hemisphere_on_cylinder, half_ellipsoid) for now, as do sweeps; a flat skin is exported, validated, given its fixtures and rendered (fabkit export, validate, fixtures, groundtruth)",
        )]));
    }
    for (path, value, rule) in design.body.violations() {
        errs.push(ParamError::new(path, value, rule));
    }
    if design.mold.laser_cut.is_some() {
        errs.push(ParamError::new(
            "mold.laser_cut",
            "given",
            format!(
                "applies to flat skins only (body.profile: flat; their trays are stacks of sheets); this body is {}",
                design.body.kind()
            ),
        ));
    }
    for f in crate::parts::flat_family::FLAT_FAMILIES {
        if f.given(design) {
            errs.push(ParamError::new(
                f.path(),
                "given",
                format!(
                    "applies to flat skins only (body.profile: flat); this body is {}",
                    design.body.kind()
                ),
            ));
        }
    }
    for (i, l) in design.layers.iter().enumerate() {
        let wrap = l.wrap_mm.map(|_| "wrap_mm");
        for field in crate::parts::layer_registry::flat_only_given(l)
            .into_iter()
            .chain(wrap)
        {
            errs.push(ParamError::new(
                format!("layers[{i}].{field}"),
                "given",
                format!(
                    "applies to flat skins only (body.profile: flat); this body is {}",
                    design.body.kind()
                ),
            ));
        }
    }
    Ok(())
}

/// The brushed coats' purpose and components, and the backing plate's size.
fn check_coats_and_backing(design: &Design, errs: &mut Vec<ParamError>) {
    // Brushed coats name what they are and what goes into them.
    for (i, l) in design.layers.iter().enumerate() {
        if let Some(coat) = &l.brushed_coat {
            if coat.purpose.trim().is_empty() {
                errs.push(ParamError::new(
                    format!("layers[{i}].brushed_coat.purpose"),
                    "\"\"",
                    "must say what the coat is for",
                ));
            }
            if coat.components.is_empty() || coat.components.iter().any(|c| c.trim().is_empty()) {
                errs.push(ParamError::new(
                    format!("layers[{i}].brushed_coat.components"),
                    format!("{:?}", coat.components),
                    "must name at least one product, none of them empty",
                ));
            }
        }
    }

    // The bought backing plate (its sheet gives its size).
    if let Some(b) = &design.backing {
        for (path, v) in [
            ("backing.diameter_mm", b.diameter_mm),
            ("backing.thickness_mm", b.thickness_mm),
        ] {
            if !(v > 0.0) {
                errs.push(ParamError::new(path, v, "must be above 0"));
            }
        }
        // the skin is glued onto the plate by its base: the plate must carry its whole rim
        let rim_mm = 2.0 * design.body.rim_radius_mm(0.0);
        if b.diameter_mm > 0.0 && b.diameter_mm < rim_mm {
            errs.push(ParamError::new(
                "backing.diameter_mm",
                b.diameter_mm,
                format!("must carry the skin's rim: at least its diameter at the base plane ({rim_mm:.3} mm)"),
            ));
        }
    }
}

/// Every material key of the design exists in `materials` and is of a kind its use allows.
fn check_materials(design: &Design, materials: &MaterialsTable, errs: &mut Vec<ParamError>) {
    // Materials exist and fit their use.
    let mut check_material =
        |path: String, key: &str, kinds: &[MaterialKind]| match materials.get(key) {
            None => errs.push(ParamError::new(
                path,
                key,
                format!(
                    "unknown material; known: {}",
                    materials
                        .materials
                        .keys()
                        .cloned()
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )),
            Some(m) if !kinds.contains(&m.kind) => errs.push(ParamError::new(
                path,
                key,
                format!("is a {:?} material, expected one of {:?}", m.kind, kinds),
            )),
            Some(_) => {}
        };
    if let Some(c) = &design.core {
        check_material(
            "core.material".into(),
            &c.material,
            &[MaterialKind::Bought, MaterialKind::Print],
        );
        if let Some(p) = &c.primer {
            check_material("core.primer".into(), p, &[MaterialKind::Primer]);
        }
    }
    if let Some(r) = &design.casting.mold_release {
        check_material("casting.mold_release".into(), r, &[MaterialKind::Release]);
    }
    if let Some(b) = &design.backing {
        check_material(
            "backing.material".into(),
            &b.material,
            &[MaterialKind::Bought, MaterialKind::Print],
        );
    }
    for (i, l) in design.layers.iter().enumerate() {
        let kinds: &[MaterialKind] = match l.process {
            LayerProcess::Cast => &[MaterialKind::Cast],
            LayerProcess::Sprayed => &[MaterialKind::Coating, MaterialKind::Cast],
            LayerProcess::Printed => &[MaterialKind::Print],
        };
        check_material(format!("layers[{i}].material"), &l.material, kinds);
        for (j, m) in l.markers.iter().enumerate() {
            if let Some(tm) = &m.tip_material {
                check_material(
                    format!("layers[{i}].markers[{j}].tip_material"),
                    tm,
                    &[MaterialKind::Print],
                );
            }
        }
    }
    for f in FAMILIES {
        for (path, key, kinds) in f.materials(design) {
            check_material(path, key, kinds);
        }
    }
}

/// The layers' names, solidity and thickness-or-radius; whether they all hold (the stack can
/// then be resolved).
fn check_layer_specs(
    design: &Design,
    sphere_r: Option<f64>,
    body_ok: bool,
    errs: &mut Vec<ParamError>,
) -> bool {
    if design.layers.is_empty() {
        errs.push(ParamError::new(
            "layers",
            "[]",
            "at least one layer is required",
        ));
    }
    let mut names = std::collections::BTreeSet::new();
    let errors_before_layer_specs = errs.len();
    for (i, l) in design.layers.iter().enumerate() {
        if !crate::values::is_file_stem(&l.name) {
            errs.push(ParamError::new(
                format!("layers[{i}].name"),
                format!("{:?}", l.name),
                "must be 1 to 64 lowercase letters, digits and _",
            ));
        } else if !names.insert(l.name.clone()) {
            errs.push(ParamError::new(
                format!("layers[{i}].name"),
                &l.name,
                "is used by another layer",
            ));
        }
        if l.solid {
            if i != 0 || design.core.is_some() {
                errs.push(ParamError::new(
                    format!("layers[{i}].solid"),
                    true,
                    "only the innermost layer of a design without core can be solid",
                ));
            }
            if l.thickness_mm.is_some() || l.outer_radius_mm.is_some() {
                errs.push(ParamError::new(
                    format!("layers[{i}]"),
                    &l.name,
                    "a solid layer fills the body: give neither thickness_mm nor outer_radius_mm",
                ));
            }
        } else {
            match (l.thickness_mm, l.outer_radius_mm) {
                (Some(_), Some(_)) | (None, None) => errs.push(ParamError::new(
                    format!("layers[{i}]"),
                    &l.name,
                    "give exactly one of thickness_mm and outer_radius_mm",
                )),
                (None, Some(_)) if sphere_r.is_none() && body_ok => errs.push(ParamError::new(
                    format!("layers[{i}].outer_radius_mm"),
                    l.outer_radius_mm.unwrap_or_default(),
                    format!(
                        "radii only describe spherical profiles; the {} needs thickness_mm",
                        design.body.kind()
                    ),
                )),
                _ => {}
            }
        }
        for (what, v) in [
            ("thickness_mm", l.thickness_mm),
            ("outer_radius_mm", l.outer_radius_mm),
        ] {
            if v.is_some_and(|v| !v.is_finite()) {
                errs.push(ParamError::new(
                    format!("layers[{i}].{what}"),
                    v.unwrap_or_default(),
                    "must be a finite number",
                ));
            }
        }
    }
    errs.len() == errors_before_layer_specs
}

/// The layers' processes (one cast or printed, the innermost not sprayed), the core's own
/// fields and the pour's waste allowance.
fn check_core_and_casting(
    design: &Design,
    sphere_r: Option<f64>,
    body_ok: bool,
    errs: &mut Vec<ParamError>,
) {
    if !design.layers.is_empty()
        && design
            .layers
            .iter()
            .all(|l| l.process == LayerProcess::Sprayed)
    {
        errs.push(ParamError::new(
            "layers",
            design.layers.len(),
            "at least one layer must be cast or printed",
        ));
    }
    if design
        .layers
        .first()
        .is_some_and(|l| l.process == LayerProcess::Sprayed)
    {
        errs.push(ParamError::new(
            "layers[0].process",
            "sprayed",
            "the innermost layer must be cast or printed: a sprayed layer coats the mold of the cast layer under it",
        ));
    }
    if let Some(c) = &design.core {
        if c.outer_diameter_mm.is_some() && sphere_r.is_none() && body_ok {
            errs.push(ParamError::new(
                "core.outer_diameter_mm",
                c.outer_diameter_mm.unwrap_or_default(),
                format!(
                    "a diameter only describes spherical profiles; remove it for the {}",
                    design.body.kind()
                ),
            ));
        }
        if !(c.wall_thickness_mm > 0.0) {
            errs.push(ParamError::new(
                "core.wall_thickness_mm",
                c.wall_thickness_mm,
                "must be above 0",
            ));
        }
        if let Some(m) = &c.machining {
            check_machining(m, errs);
        }
    }
    if !(0.0..=1.0).contains(&design.casting.waste_allowance) {
        errs.push(ParamError::new(
            "casting.waste_allowance",
            design.casting.waste_allowance,
            "must be in [0, 1]",
        ));
    }
}

/// Mold strategies that need a rigid core (a holder grips it) or a solid layer.
fn check_mold_strategies(design: &Design, errs: &mut Vec<ParamError>) {
    for (i, l) in design.layers.iter().enumerate() {
        if l.process != LayerProcess::Cast {
            continue;
        }
        let strategy = l.strategy_or(design.mold.strategy);
        let path = if l.mold_strategy.is_some() {
            format!("layers[{i}].mold_strategy")
        } else {
            "mold.strategy".to_string()
        };
        let needs_core = strategy.holds_core();
        if needs_core && (design.core.is_none() || l.solid) {
            errs.push(ParamError::new(
                path.clone(),
                format!("{strategy:?}").to_lowercase(),
                format!(
                    "layer '{}' has no core to hold; use open (solid skins) or boundary",
                    l.name
                ),
            ));
        }
        // A coat is sprayed into the cavity before the pour: only the direct and master molds
        // have their cavity the coat's thickness beyond the layer.
        if !needs_core
            && design
                .layers
                .get(i + 1)
                .is_some_and(|n| n.process == LayerProcess::Sprayed)
        {
            errs.push(ParamError::new(
                format!("layers[{}].process", i + 1),
                "sprayed",
                format!(
                    "a coat is sprayed into the mold of the layer under it, but the {} strategy of layer '{}' forms that layer's outer surface itself and leaves no room for the coat; cast '{}' with mold_strategy: direct or master (their cavity lies the coat's thickness beyond it), or cast the coat as a layer of its own",
                    format!("{strategy:?}").to_lowercase(),
                    l.name,
                    l.name
                ),
            ));
        }
        if crate::parts::molds::strategy_of(strategy).solid_only() && !l.solid {
            errs.push(ParamError::new(
                path,
                serde_json::to_value(strategy)
                    .ok()
                    .and_then(|v| v.as_str().map(str::to_owned))
                    .unwrap_or_default(),
                format!(
                    "an open mold casts a solid skin; layer '{}' is not solid (use boundary)",
                    l.name
                ),
            ));
        }
    }
}

/// The layers' and the core's surfaces, resolved from the inside out in "radius" units for
/// spheres (r = R + offset), with the errors of a stack that does not close; whether it does.
fn resolve_surfaces(
    design: &Design,
    sphere_r: Option<f64>,
    t: f64,
    errs: &mut Vec<ParamError>,
) -> (Vec<ResolvedLayer>, Option<ResolvedCore>, bool) {
    let mut layers = Vec::new();
    let mut core = None;
    let mut stack_ok = false;
    let solid_first = design.layers[0].solid;
    let shells = if solid_first {
        &design.layers[1..]
    } else {
        &design.layers[..]
    };
    let total_t: Option<f64> = shells.iter().map(|l| l.thickness_mm).sum();
    let core_od = design.core.as_ref().and_then(|c| c.outer_diameter_mm);
    // Offset of the innermost shell layer's inner surface.
    let start = match (sphere_r, core_od) {
        (_, Some(od)) if !(od > 0.0 && od.is_finite()) => {
            errs.push(ParamError::new(
                "core.outer_diameter_mm",
                od,
                "must be above 0",
            ));
            None
        }
        (Some(r), Some(od)) => Some(od / 2.0 - r),
        _ => total_t.map(|s| -s),
    };
    match start {
        None if core_od.is_some() => {}
        None => errs.push(ParamError::new(
            if design.core.is_some() { "core.outer_diameter_mm" } else { "layers" },
            "missing",
            "layers given by outer_radius_mm are measured from the core: give core.outer_diameter_mm (or thickness_mm for every layer)",
        )),
        Some(start) => {
            let r_body = sphere_r.unwrap_or(0.0);
            let mut below = start;
            let mut below_name = if design.core.is_some() { "the core".to_string() } else { "the inner surface".to_string() };
            let errors_before_stack = errs.len();
            if solid_first {
                let l = &design.layers[0];
                if !design.body.offset_is_valid(start) {
                    errs.push(ParamError::new(
                        "layers[1].thickness_mm",
                        -start,
                        "the layers above the solid layer leave no room for it",
                    ));
                }
                layers.push(ResolvedLayer {
                    index: 0,
                    name: l.name.clone(),
                    material: l.material.clone(),
                    process: l.process,
                    inner_offset_mm: f64::NEG_INFINITY,
                    outer_offset_mm: start,
                    thickness_mm: design.body.pole_z_mm(start) - design.body.base_z_mm(),
                    mold_strategy: l.strategy_or(design.mold.strategy),
                    solid: true,
                });
                below_name = format!("layer '{}'", l.name);
            }
            for (i, l) in design.layers.iter().enumerate().skip(usize::from(solid_first)) {
                let (out, path, value) = match (l.thickness_mm, l.outer_radius_mm) {
                    (Some(th), _) => (below + th, format!("layers[{i}].thickness_mm"), th),
                    (_, Some(ro)) => (ro - r_body, format!("layers[{i}].outer_radius_mm"), ro),
                    _ => unreachable!("checked above"),
                };
                let th = out - below;
                if !(th >= t) {
                    let rule = if i == 0 && l.outer_radius_mm.is_some() && th < 0.0 {
                        format!(
                            "the core (outer radius {:.3} mm) is larger than the cavity of layer '{}' (outer radius {:.3} mm)",
                            r_body + below,
                            l.name,
                            r_body + out
                        )
                    } else if l.outer_radius_mm.is_some() && th < 0.0 {
                        format!("must be above the outer radius of {below_name} under it ({:.3} mm)", r_body + below)
                    } else {
                        format!("leaves layer '{}' {:.4} mm thick, below the chord tolerance {} mm", l.name, th, t)
                    };
                    errs.push(ParamError::new(path, value, rule));
                }
                layers.push(ResolvedLayer {
                    index: i,
                    name: l.name.clone(),
                    material: l.material.clone(),
                    process: l.process,
                    inner_offset_mm: below,
                    outer_offset_mm: out,
                    thickness_mm: th,
                    mold_strategy: l.strategy_or(design.mold.strategy),
                    solid: false,
                });
                below = out;
                below_name = format!("layer '{}'", l.name);
            }
            // A layer error already explains a stack that misses the body surface.
            stack_ok = errs.len() == errors_before_stack;
            if stack_ok && below.abs() > 1e-9 {
                stack_ok = false;
                let last = design.layers.len() - 1;
                errs.push(ParamError::new(
                    if sphere_r.is_some() { "body.radius_mm" } else { "layers" },
                    format!("{}", r_body),
                    format!(
                        "the outermost layer '{}' ends {:+.4} mm from the body surface; its outer surface must be the body surface{}",
                        design.layers[last].name,
                        below,
                        if core_od.is_some() { " (check core.outer_diameter_mm and the layer radii)" } else { "" }
                    ),
                ));
            }
            // Every shell surface must be a valid offset (no fold at high curvature).
            if stack_ok {
                for l in &layers {
                    if !l.solid && !design.body.offset_is_valid(l.inner_offset_mm) {
                        stack_ok = false;
                        errs.push(ParamError::new(
                            format!("layers[{}]", l.index),
                            &l.name,
                            format!(
                                "its inner surface lies {:.3} mm inside the body surface, beyond what the {} allows (smallest radius of curvature {:.3} mm): the offset surface would fold",
                                -l.inner_offset_mm,
                                design.body.kind(),
                                design.body.min_curvature_radius_mm()
                            ),
                        ));
                    }
                }
            }
            if let (Some(c), true) = (&design.core, stack_ok) {
                core = Some(resolve_core(design, c, start, sphere_r, errs));
            }
        }
    }
    (layers, core, stack_ok)
}

/// The checks that use the resolved stack: the molds', the printers', the markers', the
/// every section family's rules (those that need no stack when it is not sound), and the first
/// held mold's fit on the core.
fn check_with_stack(
    design: &Design,
    layers: &[ResolvedLayer],
    core: Option<&ResolvedCore>,
    stack_ok: bool,
    errs: &mut Vec<ParamError>,
) {
    crate::parts::molds::check_mold_params(&design.stack_input(), errs);
    check_printers(&design.printers, errs);
    if stack_ok {
        crate::parts::layers::check_markers(&design.stack_input(), layers, errs);
    }
    // each strategy's own mold parameters against the layers cast in it
    for s in crate::parts::molds::STRATEGIES {
        let cast = crate::parts::molds::cast_in(layers, s.kind());
        s.check_layers(&design.stack_input(), stack_ok.then_some(&cast[..]), errs);
    }
    // Checks that use the core only make sense once the stack itself is sound.
    let sound_core = core.filter(|_| stack_ok);
    // the families' rules with the sound stack, or those that need none
    let st = stack_ok.then(|| Stack {
        core: core.cloned(),
        layers: layers.to_vec(),
    });
    for f in FAMILIES {
        f.check(design, st.as_ref(), errs);
    }
    if let Some(o) = &design.optics {
        crate::schema::optics::check(o, errs);
    }
    if let (Some(c), true) = (sound_core, errs.is_empty()) {
        if let Some(first) = layers
            .iter()
            .find(|l| l.process == LayerProcess::Cast && l.mold_strategy.holds_core())
        {
            crate::parts::molds::check_mold_fit(
                &design.stack_input(),
                c,
                first.outer_offset_mm,
                errs,
            );
        }
    }
}

/// The drawing's fields of a core made to order (the bore is checked with the core's surfaces).
fn check_machining(m: &crate::schema::CoreMachining, errs: &mut Vec<ParamError>) {
    let name_ok = crate::values::is_file_stem(&m.part_name);
    if !name_ok {
        errs.push(ParamError::new(
            "core.machining.part_name",
            m.part_name.as_str(),
            "must be [a-z0-9_]+, at most 64 characters (it names the drawing and the STEP file)",
        ));
    }
    if m.finish.trim().is_empty() {
        errs.push(ParamError::new(
            "core.machining.finish",
            m.finish.as_str(),
            "must name the surface finish the shop is asked for",
        ));
    }
    if !(m.general_tolerance_mm > 0.0 && m.general_tolerance_mm.is_finite()) {
        errs.push(ParamError::new(
            "core.machining.general_tolerance_mm",
            m.general_tolerance_mm,
            "must be above 0",
        ));
    }
}

/// The core's surfaces and the checks on its length. Its inner surface is only needed (and
/// only checked) when a mold holds the core by its bore.
fn resolve_core(
    design: &Design,
    c: &crate::schema::Core,
    core_out: f64,
    sphere_r: Option<f64>,
    errs: &mut Vec<ParamError>,
) -> ResolvedCore {
    let core_in = core_out - c.wall_thickness_mm;
    let pole_z = design.body.pole_z_mm(core_out);
    let below_base = c.length_mm - (pole_z - design.body.base_z_mm());
    let held = design.layers.iter().any(|l| {
        l.process == LayerProcess::Cast && l.strategy_or(design.mold.strategy).holds_core()
    });
    if !(c.length_mm > 0.0) || below_base < 0.0 {
        errs.push(ParamError::new(
            "core.length_mm",
            c.length_mm,
            format!(
                "the core must reach the base plane: at least {:.3} mm from its pole",
                pole_z - design.body.base_z_mm()
            ),
        ));
    }
    if c.machining.is_some()
        && c.wall_thickness_mm > 0.0
        && design
            .body
            .shell_inner_surface(core_out, c.wall_thickness_mm)
            .is_none()
    {
        errs.push(ParamError::new(
            "core.wall_thickness_mm",
            c.wall_thickness_mm,
            format!(
                "a core made to order needs a bore: the wall must be below its rim radius ({:.3} mm) and its height above the base plane ({:.3} mm)",
                design.body.rim_radius_mm(core_out),
                pole_z - design.body.base_z_mm()
            ),
        ));
    }
    if held && c.wall_thickness_mm > 0.0 && !design.body.offset_is_valid(core_in) {
        errs.push(ParamError::new(
            "core.wall_thickness_mm",
            c.wall_thickness_mm,
            format!(
                "the core inner surface lies {:.3} mm inside the body surface, beyond what the {} allows (smallest radius of curvature {:.3} mm): the offset surface would fold",
                -core_in,
                design.body.kind(),
                design.body.min_curvature_radius_mm()
            ),
        ));
    }
    ResolvedCore {
        inner_offset_mm: core_in,
        outer_offset_mm: core_out,
        below_base_mm: below_base.max(0.0),
        outer_radius_mm: sphere_r.map(|r| r + core_out),
        inner_radius_mm: sphere_r.map(|r| r + core_in),
    }
}
