//! Molds for cast layers, one module per strategy (R-Tac0 Sec. III-B1, Fig. 4; UVDtact
//! Sec. III; DIGIT Pinki; Sferrazza et al.):
//!
//! - [`direct`]: a printed block split on the parting plane y = 0 (through the axis), with
//!   hemispherical registration keys, clamp bolt holes and a core holder that closes the open
//!   end, keeps the core concentric and carries the sprue and vents.
//! - [`master`]: a printed master pattern of the cavity and a drafted mold box, to cast a
//!   Mold Star 30 silicone mold, plus the same core holder as casting jig.
//! - [`open`]: a one-piece block open on the base plane, poured to the brim (with the inserts
//!   of the layer's features, [`crate::parts::layer_registry::open_mold_inserts`]).
//! - [`two_piece_open`]: a cavity block and a reservoir top bolted together.
//! - [`boundary`]: outer and inner master patterns for two silicone molds.
//!
//! `direct` and `master` share the cavity ([`frame`]): the offset surface of the layer's
//! outermost sprayed coat (or of the layer itself) plus `cavity_clearance_mm`, opening on the
//! base plane into a disc-shaped plinth recess. The core holder's spigot plugs into that
//! recess (centring it) and leaves a reservoir ring between the spigot and the base plane.
//! Casting is done pole-down, so the reservoir is the high point of the cavity: the sprue and
//! the vents open into it. The strategies' parameters are [`crate::schema::mold`]; their rules
//! are [`checks`]; the laser-cut trays of flat skins are [`crate::parts::lasercut`].

pub mod boundary;
pub mod checks;
pub mod direct;
pub mod frame;
pub mod master;
pub mod open;
pub mod strategy;
pub mod two_piece_open;

use crate::error::{DesignError, GeometryContext, ParamError};
use crate::geometry::ChordTolerance;
use crate::geometry::{revolve, Solid};
use crate::markers::MarkerSurface;
use crate::parts::context::{ResolvedLayer, Stack};
use crate::parts::layers::{self, LayerOutput};
use crate::parts::stack_input::StackInput;
use crate::parts::{Part, PrintTechnology};
use crate::schema::{LayerProcess, MoldStrategy};
use frame::{cavity_profile, core_holder, holder_params, CastMold};
use serde_json::json;
use strategy::{CoreMoldInput, Strategy};

pub use crate::parts::placement::{place_on_bed, place_posed, with_pose};
pub use crate::schema::mold::{
    ClampBolt, CoreHolderParams, MoldParams, OpenBlock, Plinth, RegistrationBoss, RegistrationKey,
    Sprue, TwoPieceOpenParams, Vent,
};
pub use checks::{check_mold_fit, check_mold_params};
pub use frame::{cast_plans, open_cavity_mm, CastPlan, MoldFrame, MoldOutput};
pub(crate) use frame::{material_for, BOX_FLOOR_MM, BOX_FREEBOARD_MM};
pub use master::drafted_box;
pub use two_piece_open::{check_two_piece, TwoPieceFrame};

/// Builds the mold parts of one cast.
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
pub fn build_mold(
    si: &StackInput<'_>,
    stack: &Stack,
    plan: &CastPlan,
    tol: ChordTolerance,
) -> Result<MoldOutput, DesignError> {
    build_mold_parts(si, stack, plan, tol).map_err(|e| {
        e.from_params(&[
            format!("layers[{}]", plan.layer),
            "mold".into(),
            "core".into(),
        ])
    })
}

fn build_mold_parts(
    si: &StackInput<'_>,
    stack: &Stack,
    plan: &CastPlan,
    tol: ChordTolerance,
) -> Result<MoldOutput, DesignError> {
    let layer = &stack.layers[plan.layer];
    let core = stack.core.as_ref().ok_or_else(|| {
        DesignError::Params(crate::error::ParamErrors(vec![ParamError::new(
            "core",
            "missing",
            "direct and master molds hold a core",
        )]))
    })?;
    let f = MoldFrame::new(si, core, plan.cavity_offset_mm);
    let m = &si.mold;
    let name = &layer.name;
    let fixture_tech: PrintTechnology = m.fixture_print_technology.into();
    let fixture_material = material_for(fixture_tech);

    // The cavity carries the layer's outer features, grown by the coats sprayed into it.
    let features =
        crate::parts::layers::cavity_features(si, stack, plan.layer, plan.cavity_offset_mm, tol);
    let features: Vec<_> = features.iter().collect();
    let with_features = |s: Solid| {
        crate::parts::layers::apply_features(si.shared, s, &features, tol, false).part(name)
    };
    // The cavity, the holder and what is inside the cavity are independent: built side by side.
    let inner = || {
        // The pour fills the cavity, minus what is inside it (core and inner layers), minus
        // the holder. What the pour lands on: the layers under it down to the base plane, and
        // below it the core alone (its bore is closed by the holder's pin, so it counts as
        // solid).
        let mut inner_pl = si
            .ctx
            .body
            .offset_polyline(plan.core_offset_mm, 0.0, tol.half());
        inner_pl.push([f.core_outer_radius_mm, f.base_z_mm]);
        inner_pl.push([f.core_outer_radius_mm, f.core_end_z_mm]);
        inner_pl.push([0.0, f.core_end_z_mm]);
        Solid::from_mesh(&revolve(&inner_pl, tol).part(name)?).part(name)
    };
    let (cavity, (holder, inner)) = rayon::join(
        || {
            with_features(
                Solid::from_mesh(
                    &revolve(
                        &cavity_profile(si, &f, plan.cavity_offset_mm, false, tol),
                        tol,
                    )
                    .part(name)?,
                )
                .part(name)?,
            )
        },
        || rayon::join(|| core_holder(si, &f, tol), inner),
    );
    let (cavity, holder, inner) = (cavity?, holder?, inner?);
    let pour_volume = || -> Result<f64, DesignError> {
        let void = cavity
            .difference(&holder.union(&inner).part(name)?)
            .part(name)?;
        // a coat over features follows them (crate::parts::layers::taken_features)
        let sprayed_volume: f64 = plan
            .sprayed
            .iter()
            .map(|&i| {
                if features.is_empty() {
                    stack.layer_volume_mm3(si, i, tol)
                } else {
                    crate::parts::layers::layer_solid(si, stack, i, tol).map(|s| s.volume())
                }
            })
            .sum::<Result<f64, _>>()
            .part(name)?;
        Ok(void.volume() - sprayed_volume)
    };

    let mut common = json!({
        "layer": name,
        "strategy": plan.strategy,
        "cavity_offset_mm": plan.cavity_offset_mm,
        "core_offset_mm": plan.core_offset_mm,
        "body": si.ctx.body,
        "frame": f,
        "plinth": m.plinth,
    });
    if !features.is_empty() {
        // the features the cavity carries, for the twins (export/python/twins/cq_molds.py)
        common["markers"] = json!(features
            .iter()
            .map(|p| crate::parts::layers::twin_marker_set(p, MarkerSurface::Outer))
            .collect::<Vec<_>>());
    }
    let direct = plan.strategy == MoldStrategy::Direct;
    let holder_name = if direct {
        format!("{name}_core_holder")
    } else {
        format!("{name}_casting_jig")
    };
    let (holder_placed, holder_pose) = place_posed(&holder, &crate::geometry::Affine::identity());
    let holder_part = Part {
        name: holder_name.clone(),
        role: if direct { "core_holder".into() } else { "casting_jig".into() },
        description: format!(
            "Closes the {name} mold, centres the core on its bore and carries the sprue and {} vents",
            m.vent.count
        ),
        material: fixture_material.into(),
        print_technology: fixture_tech,
        solid: holder_placed,
        params: with_pose(holder_params(si, &f), &holder_pose),
        group: None,
    };

    let c = CastMold {
        name,
        f,
        common,
        holder_name,
        holder_part,
    };
    let input = CoreMoldInput {
        si,
        plan,
        cavity: &cavity,
        with_features: &with_features,
        tol,
    };
    // The pour's volume (a boolean of its own) beside the strategy's parts.
    let (pour_volume, mold) = rayon::join(pour_volume, || {
        strategy_of(plan.strategy)
            .core_mold(input, c)
            .expect("cast_plans plans the pours of core-holding strategies only")
    });
    // the errors in the order of a sequential build
    let (pour_volume_mm3, mold) = (pour_volume?, mold?);
    let mut out = MoldOutput {
        parts: mold.parts,
        pour_volume_mm3,
        silicone_pour: mold.silicone_pour,
        pour_parts: mold.pour_parts,
        markers: Vec::new(),
    };
    let placed = crate::parts::layers::place_layer_markers(si, layer, tol);
    out.markers = crate::parts::layers::marker_summary(
        layer,
        &placed,
        crate::parts::layer_markers::feature_technology(si, &si.layers[plan.layer]),
        si,
    );
    let carriers: Vec<String> = out
        .parts
        .iter()
        .filter(|p| matches!(p.role.as_str(), "mold_half" | "master_pattern"))
        .map(|p| p.name.clone())
        .collect();
    crate::parts::layers::set_forming(
        &mut out.markers,
        &carriers,
        &[],
        plan.cavity_offset_mm - layer.outer_offset_mm,
    );
    Ok(out)
}

/// Builds the parts of a cast layer whose strategy casts without a core
/// ([`Strategy::build_layer`]: `open`, `two_piece_open`, `boundary`), or of a printed layer
/// (with the families' parts printed with it when it is the outermost, `with_skin`;
/// [`crate::build::build_layer`] gives them).
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails, naming the parameters (`layers[i]`, and
/// `mold` for a cast layer).
pub fn build_layer(
    si: &StackInput<'_>,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
    with_skin: layers::WithSkin<'_>,
) -> Result<LayerOutput, DesignError> {
    layers::with_layer_build(si, stack, i, tol, with_skin, |b| {
        if b.l.process == LayerProcess::Printed {
            return layers::build_printed_layer(b);
        }
        strategy_of(b.l.mold_strategy)
            .build_layer(b)
            .expect("direct and master molds are built by molds::build_mold")
    })
    .map_err(|e| e.from_params(&layers::layer_params(si, i)))
}

/// Every mold strategy, one line each: the build and the cast check find a layer's strategy
/// here ([`strategy_of`]); the validation and the thinnest-wall metric ask each in this order.
pub static STRATEGIES: &[&dyn Strategy] = &[
    &direct::Direct,
    &master::Master,
    &two_piece_open::TwoPieceOpen,
    &open::Open,
    &boundary::Boundary,
];

/// The strategy of kind `kind` in [`STRATEGIES`].
///
/// # Panics
/// When `kind` has no line in [`STRATEGIES`] (a strategy added to the schema but not listed;
/// `every_strategy_is_listed` in designs/tests/it/validation.rs checks that none is).
pub fn strategy_of(kind: MoldStrategy) -> &'static dyn Strategy {
    *STRATEGIES
        .iter()
        .find(|s| s.kind() == kind)
        .expect("every mold strategy is listed in STRATEGIES")
}

/// The cast layers of `layers` whose (resolved) mold strategy is `kind`, inner to outer;
/// printed layers are cast in none.
pub fn cast_in(layers: &[ResolvedLayer], kind: MoldStrategy) -> Vec<&ResolvedLayer> {
    layers
        .iter()
        .filter(|l| l.process == LayerProcess::Cast && l.mold_strategy == kind)
        .collect()
}
