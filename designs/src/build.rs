//! From a validated design to a [`Kit`]: mold parts per cast layer, every section family's
//! parts (the registry, [`crate::parts::registry::FAMILIES`]), and the pour numbers.

mod flat_kit;

use crate::error::{DesignError, GeometryContext};
use crate::geometry::ChordTolerance;
use crate::kit::Kit;
use crate::materials::{pour, MaterialsTable};
use crate::parts::family::FillingPour;
use crate::parts::layers::SharedFeatureSolids;
use crate::parts::molds::{build_mold, cast_plans, strategy_of, CastPlan};
use crate::parts::registry::{SectionInput, FAMILIES};
use crate::schema::{Design, LayerProcess};
use crate::stack::{validate, Stack};
use crate::timings;
use rayon::prelude::*;
use serde_json::json;

/// Validates `design` and builds every part of its kit at chord tolerance `tol`.
///
/// Mold parts come first (per cast layer, inner to outer), then the families' parts in registry
/// order. Casts are listed in
/// the order they are poured: silicone molds (master strategy) first, then the layers from the
/// inside out.
///
/// # Errors
/// [`DesignError::Params`] with every violated rule, or [`DesignError::Geometry`] if the kernel
/// fails on valid parameters.
pub fn build_kit(design: &Design, tol: ChordTolerance) -> Result<Kit, DesignError> {
    build_kit_bounded(design, tol, u64::MAX)
}

/// Builds layer `i` of `design` (its resolved `stack`) when it is printed or cast without a
/// core ([`crate::parts::molds::build_layer`]), with the families' parts printed with the
/// outermost layer ([`crate::parts::registry::printed_with_skin`]).
///
/// # Errors
/// As [`crate::parts::molds::build_layer`].
pub fn build_layer(
    design: &Design,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> Result<crate::parts::layers::LayerOutput, DesignError> {
    build_layer_sharing(design, stack, i, tol, None)
}

/// [`build_layer`] with the feature compositions of a kit build.
fn build_layer_sharing(
    design: &Design,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
    shared: Option<&SharedFeatureSolids>,
) -> Result<crate::parts::layers::LayerOutput, DesignError> {
    let with_skin = || crate::parts::registry::printed_with_skin(design, stack, tol);
    let si = design.stack_input().sharing(shared);
    crate::parts::molds::build_layer(&si, stack, i, tol, &with_skin)
}

/// Validates `design` as `fabkit validate` does and returns its resolved layer stack: for a
/// curved skin the [`Stack`] ([`crate::stack::validate`]) as JSON, for a flat skin
/// `{"flat_layers": [...]}` ([`crate::stack::flat::validate`]); mm, inner to outer.
///
/// # Errors
/// [`DesignError::Params`] with every violated rule at once (parameter path, value, rule);
/// [`DesignError::Yaml`] if the embedded materials table does not load (a defect).
pub fn validate_design(
    design: &Design,
    tol: ChordTolerance,
) -> Result<serde_json::Value, DesignError> {
    let materials = MaterialsTable::embedded().map_err(DesignError::Yaml)?;
    if design.body.flat_outline().is_some() {
        let layers = crate::stack::flat::validate(design, &materials)?;
        Ok(json!({ "flat_layers": layers }))
    } else {
        let stack = validate(design, &materials, tol)?;
        serde_json::to_value(stack).map_err(|e| DesignError::Yaml(e.to_string()))
    }
}

/// [`build_kit`], refused before anything is built when the kit's estimated triangles pass
/// `max_triangles` ([`crate::estimate::check_work`]; `fabkit export --max-triangles`).
///
/// # Errors
/// As [`build_kit`], and [`DesignError::WorkLimit`] with the estimate, the limit and how to
/// raise it.
pub fn build_kit_bounded(
    design: &Design,
    tol: ChordTolerance,
    max_triangles: u64,
) -> Result<Kit, DesignError> {
    build_kit_scoped(design, tol, max_triangles, AssemblyScope::Whole)
}

/// How much of the assembled sensor a build makes ([`build_kit_scoped`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AssemblyScope {
    /// Every member's exact solid: what an export writes (the assembly 3MF, the section view,
    /// STEP).
    Whole,
    /// What the fit check and the insertion check need, for a kit that is measured and not
    /// written (a metrics-only sweep): a cast layer's member is first a stand-in that holds it
    /// (its featureless shell with the features that grow it,
    /// [`crate::parts::layers::layer_stand_in`]), replaced by the exact layer only when the
    /// stand-in overlaps another member or an insertion path passes it; the same errors as
    /// [`AssemblyScope::Whole`], and the kit's assembly leaves out the stand-ins.
    FitCheck,
}

/// Which layers of `stack` are built how: those `crate::parts::layers` builds (printed layers,
/// and cast ones in the open, two-piece open and boundary strategies), by index, and the pours
/// of `plans` whose molds hold the core (direct and master).
fn layer_builds(stack: &Stack, plans: &[CastPlan]) -> (Vec<usize>, Vec<CastPlan>) {
    let other: Vec<usize> = stack
        .layers
        .iter()
        .filter(|l| {
            l.process == LayerProcess::Printed
                || (l.process == LayerProcess::Cast && !l.mold_strategy.holds_core())
        })
        .map(|l| l.index)
        .collect();
    let held: Vec<_> = plans
        .iter()
        .filter(|p| p.strategy.holds_core())
        .cloned()
        .collect();
    (other, held)
}

/// [`build_kit_bounded`] with the assembly made as `scope` says.
///
/// # Errors
/// As [`build_kit_bounded`].
pub fn build_kit_scoped(
    design: &Design,
    tol: ChordTolerance,
    max_triangles: u64,
    scope: AssemblyScope,
) -> Result<Kit, DesignError> {
    let materials = MaterialsTable::embedded().map_err(DesignError::Yaml)?;
    if design.body.flat_outline().is_some() {
        let _t = timings::stage("build the flat kit (parts, trays, pours)");
        return flat_kit::build_flat_kit(design, &materials, tol, max_triangles);
    }
    let t = timings::stage("check the design (layer stack, rules, work bound)");
    let stack = validate(design, &materials, tol)?;
    if max_triangles < u64::MAX {
        crate::estimate::check_work(design, &stack, tol, max_triangles)?;
    }
    drop(t);
    let t = timings::stage("build the parts, the assembly's layers and the fillings (in parallel)");
    let plans = cast_plans(&design.stack_input(), &stack);
    let mut parts = Vec::new();
    let mut silicone = Vec::new();
    let mut gel = Vec::new();
    // Casts and the families' parts are independent: build them in parallel. Each build is
    // single-threaded and the results are collected in order, so the output does not depend
    // on the thread count.
    let (other, held) = layer_builds(&stack, &plans);
    let at = SectionInput {
        design,
        stack: &stack,
        tol,
    };
    // The assembly's members that come from no part (the cast layers, the core's and backing's
    // envelopes, the families' bought and cut members) and the filling gels' pours build
    // alongside the parts. The layers' marker features are composed once first, for the molds,
    // the printed layers and the assembly's cast layers to share, while the families build.
    let (((molds, others), cast_members), ((sections, family_members), fillings)) = rayon::join(
        || {
            // the layers a mold reads whole and the assembly puts in whole: built once
            let read_twice: Vec<usize> = match scope {
                AssemblyScope::Whole => stack
                    .layers
                    .iter()
                    .filter(|l| {
                        l.process == LayerProcess::Cast
                            && strategy_of(l.mold_strategy).reads_layer_solid()
                    })
                    .map(|l| l.index)
                    .collect(),
                AssemblyScope::FitCheck => Vec::new(),
            };
            let shared = crate::parts::layers::share_feature_solids(
                &design.stack_input(),
                &stack,
                tol,
                &read_twice,
            );
            let shared = Some(&shared);
            rayon::join(
                || {
                    rayon::join(
                        || {
                            held.par_iter()
                                .map(|plan| {
                                    build_mold(
                                        &design.stack_input().sharing(shared),
                                        &stack,
                                        plan,
                                        tol,
                                    )
                                })
                                .collect::<Vec<_>>()
                        },
                        || {
                            other
                                .par_iter()
                                .map(|&i| build_layer_sharing(design, &stack, i, tol, shared))
                                .collect::<Vec<_>>()
                        },
                    )
                },
                || crate::assembly::unprinted_members(design, &stack, tol, scope, shared),
            )
        },
        || {
            let families = || {
                rayon::join(
                    || FAMILIES.par_iter().map(|f| f.build(at)).collect::<Vec<_>>(),
                    || {
                        FAMILIES
                            .par_iter()
                            .map(|f| f.members(at))
                            .collect::<Vec<_>>()
                    },
                )
            };
            let fillings = || {
                let cavity = |i: usize| {
                    let si = design.stack_input();
                    Ok((
                        crate::parts::layers::inner_cavity(&si, &stack, i, tol)?,
                        crate::parts::layers::layer_twin_params(&si, &stack, i, tol),
                    ))
                };
                FAMILIES
                    .iter()
                    .map(|f| f.filling_pour(at, &cavity))
                    .collect::<Vec<_>>()
            };
            rayon::join(families, fillings)
        },
    );
    let unprinted = (cast_members, family_members);
    let layer_markers = gather_layer_outputs(
        &other,
        others,
        &held,
        molds,
        &plans,
        &stack,
        (&mut parts, &mut silicone, &mut gel),
    )?;
    let mut bought = bought_items(design, &stack, &materials);
    let mut summary = json!({
        "body": design.body,
        "base_z_mm": design.body.base_z_mm(),
        "pole_z_mm": design.body.pole_z_mm(0.0),
        "core": stack.core,
        "layers": stack.layers,
        "markers": layer_markers,
    });
    for (f, built) in FAMILIES.iter().zip(sections) {
        let Some(built) = built else { continue };
        let built = built?;
        parts.extend(built.parts);
        for (key, value) in built.summary {
            summary[key] = value;
        }
        bought.extend(f.bought_items(design));
    }

    drop(t);
    let t = timings::stage("pour volumes");
    let (mut casts, step) = layer_pours(design, &stack, &materials, silicone, gel)?;
    let poured = filling_gel_pours(design, &materials, &parts, fillings, (&mut casts, step))?;
    drop(t);
    check_unique_names(&parts)?;
    // The assembled sensor and its fit check: no file is written when parts overlap.
    let assembly = assembled(design, &stack, &parts, unprinted, poured, tol)?;
    let assembly = match scope {
        AssemblyScope::Whole => assembly,
        AssemblyScope::FitCheck => assembly
            .into_iter()
            .filter(|m| m.features.stand_in_for_layer.is_none())
            .collect(),
    };
    let t = timings::stage("procedure and machined parts");
    let bolts = crate::procedure::clamp_bolts(design, &parts);
    bought.extend(crate::procedure::clamp_bolt_items(&bolts));
    let procedure = crate::procedure::procedure(design, &parts, &stack.layers, &casts, &bolts);
    let machined_parts = machined_parts(design, &stack, &parts, tol)?;
    drop(t);
    Ok(Kit {
        design: design.name.clone(),
        parts,
        casts,
        bought_items: bought,
        procedure,
        assembly,
        cut_parts: crate::cut::cut_parts(design),
        pcb_outlines: crate::cut::pcb_outlines(design),
        machined_parts,
        summary,
    })
}

/// Parts are named uniquely by construction; checked anyway, the manifest relies on it.
///
/// # Errors
/// [`DesignError::Geometry`] on `kit` for a name used twice.
fn check_unique_names(parts: &[crate::Part]) -> Result<(), DesignError> {
    let mut names: Vec<&str> = parts.iter().map(|p| p.name.as_str()).collect();
    names.sort_unstable();
    if names.windows(2).any(|w| w[0] == w[1]) {
        return Err(crate::geometry::GeometryError::InvalidPrimitive(
            "duplicate part names".into(),
        ))
        .part("kit");
    }
    Ok(())
}

/// The assembly's members that come from no part, as the parts' build gives them: the cast
/// layers with the core's and backing's envelopes, and each family's members.
type UnprintedMembers = (
    Result<Vec<crate::parts::Member>, DesignError>,
    Vec<Result<Vec<crate::parts::Member>, DesignError>>,
);

/// A silicone mold's pour: what, volume (mm^3), the parts that hold it.
type SiliconePour = (String, f64, Vec<String>);
/// A layer's pour: layer index, what, material key, volume (mm^3), the parts that hold it, the
/// sprayed layers on its mold.
type GelPour = (usize, String, String, f64, Vec<String>, Vec<usize>);

/// The outputs of the layers built by `crate::parts::layers` (`other`, by layer index) and of the
/// held molds (`held`, by cast plan), in that order: their parts, silicone pours and gel pours
/// appended to `into`; the layers' marker summaries.
///
/// # Errors
/// The first build error among them.
#[allow(clippy::type_complexity)]
fn gather_layer_outputs(
    other: &[usize],
    others: Vec<Result<crate::parts::layers::LayerOutput, DesignError>>,
    held: &[crate::parts::molds::CastPlan],
    molds: Vec<Result<crate::parts::molds::MoldOutput, DesignError>>,
    plans: &[crate::parts::molds::CastPlan],
    stack: &Stack,
    (parts, silicone, gel): (
        &mut Vec<crate::Part>,
        &mut Vec<SiliconePour>,
        &mut Vec<GelPour>,
    ),
) -> Result<Vec<serde_json::Value>, DesignError> {
    let mut layer_markers = Vec::new();
    for (&i, out) in other.iter().zip(others) {
        let out = out?;
        for (what, material, v, holders) in out.pours {
            if material == "mold_star_30" {
                silicone.push((what, v, holders));
            } else {
                let sprayed = plans
                    .iter()
                    .find(|p| p.layer == i)
                    .map(|p| p.sprayed.clone())
                    .unwrap_or_default();
                gel.push((i, what, material, v, holders, sprayed));
            }
        }
        layer_markers.extend(out.markers);
        parts.extend(out.parts);
    }
    for (plan, out) in held.iter().zip(molds) {
        let out = out?;
        let layer = &stack.layers[plan.layer];
        if let Some((v, holders)) = out.silicone_pour {
            silicone.push((format!("silicone_mold:{}", layer.name), v, holders));
        }
        gel.push((
            plan.layer,
            layer.name.clone(),
            layer.material.clone(),
            out.pour_volume_mm3,
            out.pour_parts,
            plan.sprayed.clone(),
        ));
        layer_markers.extend(out.markers);
        parts.extend(out.parts);
    }
    // inner to outer, whatever built each layer
    let at = |m: &serde_json::Value| {
        stack
            .layers
            .iter()
            .position(|l| m["layer"].as_str() == Some(l.name.as_str()))
    };
    layer_markers.sort_by_key(at);
    // a pattern that no part carries would be cast without its features
    if let Some(m) = layer_markers
        .iter()
        .find(|m| m["formed_by"].as_array().is_none_or(|a| a.is_empty()))
    {
        return Err(DesignError::Yaml(format!(
            "the markers on {} ({}) are carried by no part of the kit",
            m["layer"], m["surface"]
        )));
    }
    Ok(layer_markers)
}

/// The pours of the silicone molds, then of the layers inner to outer, numbered from 1, with
/// each layer's treatments and sprayed coats; the next step's number.
///
/// # Errors
/// [`DesignError::Yaml`] for a material missing from `materials`.
fn layer_pours(
    design: &Design,
    stack: &Stack,
    materials: &MaterialsTable,
    silicone: Vec<SiliconePour>,
    mut gel: Vec<GelPour>,
) -> Result<(Vec<crate::materials::CastReport>, u32), DesignError> {
    let mut casts = Vec::new();
    let waste = design.casting.waste_allowance;
    let mut step = 1;
    let mold_star = materials
        .get("mold_star_30")
        .ok_or_else(|| DesignError::Yaml("materials table lacks mold_star_30".into()))?;
    for (what, v, holders) in silicone {
        casts.push(
            pour(step, &what, "mold_star_30", mold_star, holders, v, waste)
                .map_err(DesignError::Yaml)?,
        );
        step += 1;
    }
    gel.sort_by_key(|g| g.0);
    let mut primed = false;
    let mut inner_released = false;
    for (_, layer, material_key, v, holders, sprayed) in gel {
        let m = materials
            .get(&material_key)
            .ok_or_else(|| DesignError::Yaml(format!("unknown material {material_key}")))?;
        let mut r =
            pour(step, &layer, &material_key, m, holders, v, waste).map_err(DesignError::Yaml)?;
        r.layer_volume_ml = stack
            .layers
            .iter()
            .find(|l| l.name == layer)
            .map(|l| layer_volume_mm3(design, l) / 1000.0);
        // the note the layer's mold strategy starts a pour with (boundary: UVDtact Sec. III)
        let poured = stack.layers.iter().find(|l| l.name == layer);
        if let Some(note) = poured.and_then(|l| strategy_of(l.mold_strategy).pour_note()) {
            r.notes = format!("{note} {}", r.notes);
        }
        r.treatments = treatments(
            design,
            stack,
            materials,
            &layer,
            &sprayed,
            &r.mold_parts,
            (&mut primed, &mut inner_released),
        );
        for s in sprayed {
            let sl = &stack.layers[s];
            if let Some(cm) = materials.get(&sl.material) {
                if let Ok(c) = crate::materials::coat(
                    &sl.name,
                    &sl.material,
                    cm,
                    sl.thickness_mm,
                    layer_volume_mm3(design, sl),
                ) {
                    r.coats.push(c);
                }
            }
            let (product, sm) = materials
                .get(&sl.material)
                .map(|m| (m.name.clone(), m.notes.clone()))
                .unwrap_or_else(|| (sl.material.clone(), String::new()));
            r.notes = format!(
                "First spray the {} layer ({product}, {:.2} mm) onto the inner surface of the mold: {sm} Then: {}",
                sl.name, sl.thickness_mm, r.notes
            );
        }
        casts.push(r);
        step += 1;
    }
    Ok((casts, step))
}

/// The filling gels' pours, step `step` of `casts`: each family's `fillings` as the parts'
/// build gave them ([`crate::parts::family::Family::filling_pour`]: the housing's, poured into
/// the assembled shell, or the shaft body's, poured into the tip); the members they bring to
/// the assembly.
///
/// # Errors
/// [`DesignError`] naming the filling gel if the kernel failed or its material is unknown.
fn filling_gel_pours(
    design: &Design,
    materials: &MaterialsTable,
    parts: &[crate::Part],
    fillings: Vec<Result<Option<FillingPour<'_>>, DesignError>>,
    (casts, step): (&mut Vec<crate::materials::CastReport>, u32),
) -> Result<Vec<crate::parts::Member>, DesignError> {
    let waste = design.casting.waste_allowance;
    let mut members = Vec::new();
    for pour in fillings {
        let Some(pour) = pour? else {
            continue;
        };
        casts.push(filling_gel_cast(
            materials,
            pour.gel,
            (step, waste),
            holders(parts, pour.holder_roles),
            pour.volume_mm3,
            pour.how,
        )?);
        members.extend(pour.member);
    }
    Ok(members)
}

/// The members of the assembled sensor (the parts in the sensor frame, then `unprinted`: the
/// cast layers with the core's and backing's envelopes and every family's bought and cut members,
/// then the poured gels' members), checked for interferences and for the paths each member goes
/// in by.
///
/// # Errors
/// [`DesignError`] naming the members that overlap or block each other's way in, or a kernel
/// failure.
fn assembled(
    design: &Design,
    stack: &Stack,
    parts: &[crate::Part],
    unprinted: UnprintedMembers,
    poured: Vec<crate::parts::Member>,
    tol: ChordTolerance,
) -> Result<Vec<crate::parts::Member>, DesignError> {
    let t = timings::stage("assembly members");
    let (own, families) = unprinted;
    let mut assembly = crate::assembly::printed_members(parts);
    assembly.extend(own?);
    for members in families {
        assembly.extend(members?);
    }
    assembly.extend(poured);
    drop(t);
    let t = timings::stage("fit check (interferences)");
    let stand_in = |assembly: &[crate::parts::Member], name: &str| {
        assembly
            .iter()
            .any(|m| m.name == name && m.features.stand_in_for_layer.is_some())
    };
    // A stand-in holds its layer: the layer's overlap with another member is within the
    // stand-in's, its volume at most the stand-in's (its mean thickness may be more), so any
    // overlap of a stand-in over the volume threshold, however thin, asks for the exact layer.
    let any_stand_in = assembly
        .iter()
        .any(|m| m.features.stand_in_for_layer.is_some());
    let mut found = if any_stand_in {
        crate::assembly::overlaps(&assembly, 0.0)?
    } else {
        crate::assembly::interferences(&assembly, tol)?
    };
    if found
        .iter()
        .any(|f| stand_in(&assembly, &f.a) || stand_in(&assembly, &f.b))
    {
        assembly = crate::assembly::with_exact_layers(assembly, design, stack, tol)?;
        found = crate::assembly::interferences(&assembly, tol)?;
    } else {
        found.retain(|f| f.thickness_mm > tol.mm());
    }
    if let Some(e) = crate::assembly::fit_errors(design, &found) {
        return Err(e);
    }
    drop(t);
    let _t = timings::stage("insertion check");
    let paths = crate::insertion::paths(design, stack, tol)?;
    if paths.iter().any(|p| stand_in(&assembly, &p.through)) {
        assembly = crate::assembly::with_exact_layers(assembly, design, stack, tol)?;
    }
    let blocked = crate::insertion::blocked(&assembly, &paths, tol)?;
    if let Some(e) = crate::insertion::errors(design, &blocked) {
        return Err(e);
    }
    Ok(assembly)
}

/// The core made to order, if the design gives its machining, checked against the kit's part
/// names (it names the drawing and the STEP file).
///
/// # Errors
/// [`DesignError::Params`] for a name another part has; a kernel failure.
fn machined_parts(
    design: &Design,
    stack: &Stack,
    parts: &[crate::Part],
    tol: ChordTolerance,
) -> Result<Vec<crate::parts::core_shell::MachinedPart>, DesignError> {
    let machined_parts = match (&stack.core, &design.core) {
        (Some(c), Some(spec)) => {
            crate::parts::core_shell::machined_part(&design.context(), c, spec, tol)?
                .into_iter()
                .collect()
        }
        _ => Vec::new(),
    };
    if let Some(m) = machined_parts
        .iter()
        .find(|m| parts.iter().any(|p| p.name == m.name))
    {
        return Err(DesignError::Params(crate::ParamErrors(vec![
            crate::ParamError::new(
                "core.machining.part_name",
                m.name.as_str(),
                "must differ from every part of the kit (it names the drawing and the STEP file)",
            ),
        ])));
    }
    Ok(machined_parts)
}

/// The primer and release agent applied before the pour of `layer` (with the `sprayed` layers
/// coated into its mold first), held by `mold_parts`: the core's primer before the first
/// layer cast on the core (`primed` records it), and the release agent on the cavity (the
/// outermost of the layer and its coats) and, for the boundary strategy, on the inner silicone
/// mold (the layer's inner surface) of the first such pour only: the later layers are cast
/// onto the layers before them (UVDtact Sec. III), which they must bond to. Areas from the
/// exact profile.
fn treatments(
    design: &Design,
    stack: &Stack,
    materials: &MaterialsTable,
    layer: &str,
    sprayed: &[usize],
    mold_parts: &[String],
    (primed, inner_released): (&mut bool, &mut bool),
) -> Vec<crate::kit::TreatmentReport> {
    let Some(l) = stack.layers.iter().find(|l| l.name == layer) else {
        return Vec::new();
    };
    let report = |key: &str, surface: String, area_mm2: f64| {
        let m = materials.get(key)?;
        let area_cm2 = area_mm2 / 100.0;
        Some(crate::kit::TreatmentReport {
            material: key.to_string(),
            material_name: m.name.clone(),
            kind: m.kind,
            surface,
            area_cm2,
            amount_ml: area_cm2 * m.applied_ml_per_cm2.unwrap_or(0.0),
        })
    };
    let mut out = Vec::new();
    let on_core = mold_parts
        .iter()
        .any(|p| p.ends_with("_core_holder") || p.ends_with("_casting_jig"));
    if let (Some(core), true, false) = (&design.core, on_core, *primed) {
        *primed = true;
        if let Some(p) = &core.primer {
            out.extend(report(
                p,
                "the core's outer surface".into(),
                design.body.surface_area_mm2(l.inner_offset_mm),
            ));
        }
    }
    if let Some(rel) = &design.casting.mold_release {
        let cavity = sprayed
            .iter()
            .map(|&i| stack.layers[i].outer_offset_mm)
            .fold(l.outer_offset_mm, f64::max);
        out.extend(report(
            rel,
            format!("the cavity of the {layer} mold"),
            design.body.surface_area_mm2(cavity),
        ));
        if let Some(r) = crate::parts::layer_registry::seat_of(&design.stack_input(), l.index) {
            out.extend(report(
                rel,
                format!("the insert that forms the seat under {layer}"),
                r.surface_area_mm2(),
            ));
        }
        if mold_parts.iter().any(|p| p.ends_with(":inner")) && !l.solid && !*inner_released {
            // later layers are cast onto the layers before them, which they must bond to
            *inner_released = true;
            out.extend(report(
                rel,
                format!("the inner silicone mold of {layer}"),
                design.body.surface_area_mm2(l.inner_offset_mm),
            ));
        }
    }
    out
}

/// The names of the parts of `roles`.
fn holders(parts: &[crate::Part], roles: &[&str]) -> Vec<String> {
    parts
        .iter()
        .filter(|p| roles.contains(&p.role.as_str()))
        .map(|p| p.name.clone())
        .collect()
}

/// The filling gel's cast: `volume_mm3` of `gel`'s material poured as cast `step` (with the
/// kit's waste allowance) into `holders`, `how` before the material's own notes.
///
/// # Errors
/// [`DesignError::Yaml`] for a material that is unknown or has no mix ratio.
fn filling_gel_cast(
    materials: &MaterialsTable,
    gel: &crate::schema::FillingGel,
    (step, waste): (u32, f64),
    holders: Vec<String>,
    volume_mm3: f64,
    how: &str,
) -> Result<crate::kit::CastReport, DesignError> {
    let m = materials
        .get(&gel.material)
        .ok_or_else(|| DesignError::Yaml(format!("unknown material {}", gel.material)))?;
    let mut r = pour(
        step,
        crate::procedure::FILLING_GEL,
        &gel.material,
        m,
        holders,
        volume_mm3,
        waste,
    )
    .map_err(DesignError::Yaml)?;
    r.notes = format!("{how} {}", r.notes);
    Ok(r)
}

/// `text` with its first letter upper-case.
fn capitalized(text: &str) -> String {
    let mut c = text.chars();
    c.next()
        .map_or_else(String::new, |f| f.to_uppercase().chain(c).collect())
}

fn bought_items(design: &Design, stack: &Stack, materials: &MaterialsTable) -> Vec<String> {
    let product = |key: &str| {
        materials
            .get(key)
            .map_or_else(|| key.to_string(), |m| m.name.clone())
    };
    let mut v = Vec::new();
    if let (Some(c), Some(spec)) = (&stack.core, &design.core) {
        v.push(match (c.outer_radius_mm, c.inner_radius_mm) {
            (Some(ro), Some(ri)) => format!(
                "Core ({}): {}, outer diameter {:.2} mm, wall {:.2} mm (inner diameter {:.2} mm), cut to {:.2} mm from the pole",
                product(&spec.material), spec.description, 2.0 * ro, ro - ri, 2.0 * ri, spec.length_mm
            ),
            _ => format!(
                "Core ({}): {}, wall {:.2} mm at the pole and the rim, {:.2} mm long from the pole{}",
                product(&spec.material), spec.description, spec.wall_thickness_mm, spec.length_mm,
                spec.machining.as_ref().map_or(String::new(), |m| format!(
                    "; made to order by its drawing machined/{}.svg (see Machined parts)",
                    m.part_name
                ))
            ),
        });
    }
    if let Some(b) = &design.backing {
        v.push(format!(
            "Backing ({}): {}, {:.1} mm diameter, {:.1} mm thick; glue the skin's base to it",
            product(&b.material),
            b.description,
            b.diameter_mm,
            b.thickness_mm
        ));
    }
    for l in &design.layers {
        if let Some(coat) = &l.brushed_coat {
            v.push(format!(
                "{} brushed onto `{}`: {}",
                capitalized(&coat.purpose),
                l.name,
                coat.components.join(", ")
            ));
        }
    }
    for l in &stack.layers {
        if l.process == crate::schema::LayerProcess::Sprayed {
            v.push(format!(
                "Coating {} ({}), about {:.2} mm, sprayed into the mold",
                l.name,
                product(&l.material),
                l.thickness_mm
            ));
        }
    }
    v
}

/// Volume of `layer` alone, mm^3: the solid under its outer surface down to the base plane,
/// less the solid under its inner surface (for a solid layer, its recess if it has one), from
/// the exact profile ([`crate::profile::BodyProfile::analytic_solid_volume_mm3`],
/// [`crate::parts::seat::Seat::volume_mm3`]); marker features not counted.
pub fn layer_volume_mm3(design: &Design, layer: &crate::stack::ResolvedLayer) -> f64 {
    let body = &design.body;
    let outer = body.analytic_solid_volume_mm3(layer.outer_offset_mm, 0.0);
    if layer.solid {
        outer
            - crate::parts::layer_registry::seat_of(&design.stack_input(), layer.index)
                .map_or(0.0, |r| r.volume_mm3())
    } else {
        outer - body.analytic_solid_volume_mm3(layer.inner_offset_mm, 0.0)
    }
}
