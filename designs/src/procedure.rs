//! The fabrication procedure in order, and the clamp bolts the molds need: what the
//! fabrication sheet tells a maker at the bench, derived from the kit's parts and pours.
//!
//! Sources: R-Tac0 Sec. III-B1 (Mold Star molds from printed masters, primed tube press-fitted,
//! release sprayed, black coat sprayed before the next pour); UVDtact Sec. III (outer and inner
//! silicone molds, layers cast inside out on the first inner mold, acrylic shell attached with
//! clear silicone sealant); ShadowTac Sec. III (release sprayed, poured, degassed, cured 24 h,
//! glued to the PMMA plate).

use crate::materials::MaterialKind;
use crate::materials::{cure_text, CastReport};
use crate::parts::context::ResolvedLayer;
use crate::parts::family::AssemblyStep;
use crate::parts::fasteners::bolt_name;
use crate::parts::layer_registry::insert_roles;
use crate::parts::molds::strategy::{DemoldInput, PourInput, Strategy};
use crate::parts::molds::{strategy_of, STRATEGIES};
use crate::parts::registry::FAMILIES;
use crate::parts::{Part, ProcedureAction, ProcedureStep};
use crate::schema::Design;

/// The clamp bolts of one mold: `count` bolts of `name` (e.g. `M3 x 60`) through `grip_mm`.
#[derive(Debug, Clone, PartialEq)]
pub struct ClampBolts {
    /// The layer the mold casts.
    pub layer: String,
    pub count: usize,
    /// Standard size and length, e.g. `M3 x 60`; `None` when no standard bolt fits the hole.
    pub name: Option<String>,
    /// Thickness the bolt clamps (both mold parts), mm.
    pub grip_mm: f64,
    pub clearance_mm: f64,
}

pub use crate::parts::family::FILLING_GEL;
/// The clamp bolts of every bolted mold of the kit, from the parts' parameters, as each mold
/// strategy names them ([`crate::parts::molds::strategy::Strategy::clamp_bolts`]: the direct
/// strategy's halves, 4 bolts across both halves, perpendicular to the parting plane; the
/// two-piece open mold, `two_piece.bolt_count` bolts through both pieces).
pub fn clamp_bolts(design: &Design, parts: &[Part]) -> Vec<ClampBolts> {
    let si = design.stack_input();
    let mut out = Vec::new();
    for p in parts {
        let Some(b) = STRATEGIES.iter().find_map(|s| s.clamp_bolts(&si, p)) else {
            continue;
        };
        let layer = p.params["layer"]
            .as_str()
            .or_else(|| p.params["base"]["layer"].as_str())
            .unwrap_or(&p.name)
            .to_string();
        out.push(ClampBolts {
            layer,
            count: b.count,
            name: bolt_name(b.clearance_mm, b.grip_mm),
            grip_mm: b.grip_mm,
            clearance_mm: b.clearance_mm,
        });
    }
    out
}

/// The bought-items lines of [`clamp_bolts`].
pub fn clamp_bolt_items(bolts: &[ClampBolts]) -> Vec<String> {
    bolts
        .iter()
        .map(|b| {
            format!(
                "{} clamp bolts{} with nuts for the {} mold: {:.1} mm holes, {:.1} mm grip",
                b.count,
                b.name
                    .as_deref()
                    .map(|n| format!(" {n}"))
                    .unwrap_or_default(),
                b.layer,
                b.clearance_mm,
                b.grip_mm
            )
        })
        .collect()
}

fn part<'a>(parts: &'a [Part], name: &str) -> Option<&'a Part> {
    parts.iter().find(|p| p.name == name)
}

fn with_role<'a>(parts: &'a [Part], names: &[String], roles: &[&str]) -> Vec<&'a Part> {
    names
        .iter()
        .filter_map(|n| part(parts, n))
        .filter(|p| roles.contains(&p.role.as_str()))
        .collect()
}

fn step(action: ProcedureAction, text: String) -> ProcedureStep {
    ProcedureStep { action, text }
}

/// The procedure of a kit in order, from its parts (roles, names, parameters), its pours
/// ([`CastReport`], with their coats and treatments) and its clamp bolts. Every kit starts with
/// printing and ends with assembly; each pour brings the steps its mold needs.
pub fn procedure(
    design: &Design,
    parts: &[Part],
    layers: &[ResolvedLayer],
    casts: &[CastReport],
    bolts: &[ClampBolts],
) -> Vec<ProcedureStep> {
    use ProcedureAction as A;
    let mut out = Vec::new();
    if !parts.is_empty() {
        out.push(step(
            A::Print,
            format!(
                "Print every part of the print list with the print settings of this sheet, and \
                 check each one as in \"Checking the prints\"{}.",
                if casts.is_empty() {
                    ""
                } else {
                    " before the first pour"
                }
            ),
        ));
    }
    let mut core_mounted = false;
    let mut on_inner_mold = false;
    for c in casts {
        let n = c.step;
        if c.cast.starts_with("silicone_mold:") {
            mold_star_steps(&mut out, design, parts, c);
            continue;
        }
        if c.cast == FILLING_GEL {
            // poured into the assembled shell: among the assembly steps
            continue;
        }
        let holder = with_role(parts, &c.mold_parts, &["core_holder", "casting_jig"]);
        let halves = with_role(parts, &c.mold_parts, &["mold_half"]);
        let mut piece_roles = vec!["open_mold_piece", "open_mold"];
        piece_roles.extend(insert_roles());
        let pieces = with_role(parts, &c.mold_parts, &piece_roles);
        let bolt = bolts.iter().find(|b| b.layer == c.cast);
        let bolt_text = bolt.map_or_else(String::new, |b| {
            format!(
                " and tighten the {} clamp bolts{}",
                b.count,
                b.name
                    .as_deref()
                    .map(|n| format!(" ({n}, with nuts)"))
                    .unwrap_or_default()
            )
        });

        treatment_steps(&mut out, c, MaterialKind::Primer);
        if let Some(h) = holder.first() {
            if core_mounted {
                out.push(step(
                    A::MoveCore,
                    format!(
                        "Step {n}: take the core with the layers cast so far off the previous \
                         holder and slide it onto the centring pin of `{}`, down to the shoulder.",
                        h.name
                    ),
                ));
            } else {
                out.push(step(
                    A::MountCore,
                    format!(
                        "Step {n}: slide the core's open end onto the centring pin of `{}`, down \
                         to the shoulder.",
                        h.name
                    ),
                ));
            }
            core_mounted = true;
        }
        // the layer's mold strategy: its own, else the design's (resolved in the stack)
        let strategy = layers
            .iter()
            .find(|l| l.name == c.cast)
            .map(|l| strategy_of(l.mold_strategy));
        // the pieces the layer's features set into the mold apart from the mold's own
        let insert_roles = insert_roles();
        let (inserts, pieces): (Vec<&Part>, Vec<&Part>) = pieces
            .iter()
            .partition(|p| insert_roles.contains(&p.role.as_str()));
        let input = PourInput {
            step: n,
            mix: &c.mix_text(),
            holder: holder.first().copied(),
            halves: &halves,
            pieces: &pieces,
            inserts: &inserts,
            bolt_text: &bolt_text,
            mold_parts: &c.mold_parts,
            on_inner_mold,
        };
        if let Some(s) = strategy {
            out.extend(s.seat_steps(input));
        }
        treatment_steps(&mut out, c, MaterialKind::Release);
        for k in &c.coats {
            out.push(step(
                A::SprayCoat,
                format!(
                    "Step {n}: mix the {} coat ({}, {}) and spray it evenly onto the cavity's \
                     surface, about {:.2} mm thick; pour the next mix straight after.",
                    k.layer, k.material_name, k.mix_ratio, k.thickness_mm
                ),
            ));
        }
        // the layer's mold strategy closes its mold and pours it
        if let Some(s) = strategy {
            out.extend(s.pour_steps(input));
        }
        on_inner_mold |= strategy.is_some_and(|s| s.keeps_inner_mold());
        demold_steps(&mut out, design, (layers, casts), c, strategy, core_mounted);
    }
    let filling = casts.iter().find(|c| c.cast == FILLING_GEL);
    out.extend(assembly_steps(design, parts, core_mounted, filling));
    out
}

/// The steps of pour `c` after it is poured: cure and demold in the words of its layer's mold
/// strategy ([`crate::parts::molds::strategy::Strategy::demold_text`]: a boundary-cast layer
/// stays on its inner silicone mold for the next pour), then its brushed coat, if any.
fn demold_steps(
    out: &mut Vec<ProcedureStep>,
    design: &Design,
    (layers, casts): (&[ResolvedLayer], &[CastReport]),
    c: &CastReport,
    strategy: Option<&dyn Strategy>,
    core_mounted: bool,
) {
    use ProcedureAction as A;
    let n = c.step;
    let kind_of = |name: &str| {
        layers
            .iter()
            .find(|l| l.name == name)
            .map(|l| l.mold_strategy)
    };
    let kind = kind_of(&c.cast);
    let cure = cure_text(&c.notes);
    let custom = strategy.and_then(|s| {
        s.demold_text(DemoldInput {
            step: n,
            cure: &cure,
            layer: &c.cast,
            poured_again: casts
                .iter()
                .any(|d| d.step > c.step && kind.is_some() && kind_of(&d.cast) == kind),
        })
    });
    let what = if core_mounted {
        format!("the core with `{}`", c.cast)
    } else {
        format!("`{}`", c.cast)
    };
    let text = custom.unwrap_or_else(|| {
        format!("Step {n}: let it cure ({cure}), open the mold and take {what} out.")
    });
    out.push(step(A::Demold, text));
    let coat = design
        .layers
        .iter()
        .find(|l| l.name == c.cast)
        .and_then(|l| l.brushed_coat.as_ref());
    if let Some(coat) = coat {
        out.push(step(
            A::BrushCoat,
            format!(
                "Step {n}: brush a thin {} onto `{}`: {}, mixed.{}",
                coat.purpose,
                c.cast,
                coat.components.join(", "),
                if coat.notes.is_empty() {
                    String::new()
                } else {
                    format!(" {}", coat.notes)
                }
            ),
        ));
    }
}

/// The primer (`PrimeCore`, wiped) or release agent (`SprayRelease`, sprayed) steps of a pour.
fn treatment_steps(out: &mut Vec<ProcedureStep>, c: &CastReport, kind: MaterialKind) {
    let (action, verb) = match kind {
        MaterialKind::Primer => (ProcedureAction::PrimeCore, "wipe"),
        _ => (ProcedureAction::SprayRelease, "spray"),
    };
    for t in c.treatments.iter().filter(|t| t.kind == kind) {
        out.push(step(
            action,
            format!(
                "Step {}: {verb} {} onto {} ({:.1} cm², about {:.2} mL) and let it dry.",
                c.step, t.material_name, t.surface, t.area_cm2, t.amount_ml
            ),
        ));
    }
}

/// The Mold Star steps of a `silicone_mold:` pour: seating the master (or levelling the
/// negative), pouring to the fill height, demolding.
fn mold_star_steps(out: &mut Vec<ProcedureStep>, design: &Design, parts: &[Part], c: &CastReport) {
    use ProcedureAction as A;
    let n = c.step;
    let mix = c.mix_text();
    let master = with_role(parts, &c.mold_parts, &["master_pattern"]);
    let boxes = with_role(parts, &c.mold_parts, &["mold_box"]);
    let negative = with_role(parts, &c.mold_parts, &["negative_mold"]);
    if let (Some(m), Some(b)) = (master.first(), boxes.first()) {
        out.push(step(
            A::SeatMaster,
            format!(
                "Step {n}: seat `{}` in `{}`: its locating pin in the socket of the box floor, \
                 the plinth flat on the floor.",
                m.name, b.name
            ),
        ));
        let height = b
            .solid
            .bounding_box()
            .map(|bb| bb.max[2] - bb.min[2])
            .unwrap_or(0.0);
        let fill =
            height - crate::parts::molds::BOX_FLOOR_MM - crate::parts::molds::BOX_FREEBOARD_MM;
        out.push(step(
            A::FillMoldStar,
            format!(
                "Step {n}: mix {mix}, and pour it in a thin stream beside the master, not onto \
                 it, up to {fill:.1} mm above the box floor: {:.1} mm over the master's top, \
                 {:.1} mm below the rim.",
                design.mold.silicone_wall_mm,
                crate::parts::molds::BOX_FREEBOARD_MM
            ),
        ));
        out.push(step(
            A::DemoldSiliconeMold,
            format!(
                "Step {n}: let it cure ({}), push the silicone out of `{}` and peel it off `{}`: \
                 its cavity is the {}.",
                cure_text(&c.notes),
                b.name,
                m.name,
                mold_of(&c.cast)
            ),
        ));
    } else if let Some(neg) = negative.first() {
        out.push(step(
            A::SeatMaster,
            format!(
                "Step {n}: stand `{}` level on a flat surface, cavity up.",
                neg.name
            ),
        ));
        out.push(step(
            A::FillMoldStar,
            format!(
                "Step {n}: mix {mix} and pour it into `{}` up to the brim.",
                neg.name
            ),
        ));
        out.push(step(
            A::DemoldSiliconeMold,
            format!(
                "Step {n}: let it cure ({}) and pull the silicone out of `{}`.",
                cure_text(&c.notes),
                neg.name
            ),
        ));
    }
}

/// `silicone_mold:x` -> `mold of x`, `silicone_mold:x:outer` -> `outer mold of x`.
fn mold_of(cast: &str) -> String {
    let rest = cast.trim_start_matches("silicone_mold:");
    match rest.rsplit_once(':') {
        Some((layer, side)) => format!("{side} mold of {layer}"),
        None => format!("mold of {rest}"),
    }
}

/// The assembly steps in order, each with its screws or glue: the contact module's own
/// bonding (core into the skin, skin onto its backing; UVDtact Sec. III, ShadowTac Sec. IV-A),
/// then every family's steps in registry order ([`crate::parts::family::Family::assembly_steps`]),
/// the filling gel's pour where its family puts it.
fn assembly_steps(
    design: &Design,
    parts: &[Part],
    cast_on_core: bool,
    filling: Option<&CastReport>,
) -> Vec<ProcedureStep> {
    let mut out: Vec<String> = Vec::new();
    let mut filled = None;
    let cast = design
        .layers
        .iter()
        .any(|l| l.process == crate::schema::LayerProcess::Cast);
    if design.core.is_some() && !cast_on_core && cast {
        out.push(
            "Bond the core (see Bought items) into the skin's inner surface with clear \
             silicone sealant (UVDtact Sec. III)."
                .into(),
        );
    }
    if design.backing.is_some() {
        out.push(
            "Glue the skin's base to the backing plate with Smooth-On Sil-Poxy (ShadowTac \
             Sec. IV-A)."
                .into(),
        );
    }
    for f in FAMILIES {
        for s in f.assembly_steps(design, parts, filling) {
            match s {
                AssemblyStep::Text(t) => out.push(t),
                AssemblyStep::Step(s) => filled = Some((out.len(), s)),
            }
        }
    }
    if out.is_empty() && filled.is_none() {
        out.push(if parts.iter().any(|p| p.role == "printed_skin") {
            "Nothing to put together: the printed skin comes off the printer with its marker \
             tips in place."
                .into()
        } else {
            "Put the printed parts and the bought items together.".into()
        });
    }
    let mut steps: Vec<ProcedureStep> = out
        .into_iter()
        .map(|t| step(ProcedureAction::Assemble, format!("Assemble: {t}")))
        .collect();
    // the filling gel's pour goes in after the assembly step it follows
    if let Some((at, s)) = filled {
        steps.insert(at, s);
    }
    steps
}
