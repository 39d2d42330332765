//! The layers as the molds cast them, checked against the layers the assembly shows: what is
//! designed is what gets cast.
//!
//! For each cast layer of a built kit, [`cast_layer`] rebuilds, from the kit's printed mold
//! parts alone (taken back from their print poses into the sensor frame with their
//! `T_print_sensor`), the solid the closed mold leaves for the pour above the base plane:
//!
//! * `master` and the outer boundary of `boundary`: the master pattern is the cavity's positive
//!   (the Mold Star mold is cast around it), so the pour fills the pattern's shape;
//! * `boundary`: less the inner silicone core, the positive of the inner negative's cup;
//! * `direct`, `open`, `two_piece_open`: the space the closed pieces (halves and core holder,
//!   open mold and seat insert, cavity block and reservoir top) leave;
//!
//! each within an envelope just beyond the cavity (its offset surface plus the tallest
//! feature, closed on the base plane) that keeps the bolt holes, keys and the outside out;
//! and for the layers cast onto the stack (`direct`, `master`), less what is already in the
//! mold: the core's envelope, the layers cast before and the coats sprayed into it, as the
//! assembly shows them.
//!
//! [`check_casts`] compares that solid with the layer's member of the assembly: the volume of
//! their symmetric difference, bounded by twice the chord tolerance times the layer's surface
//! area (each mesh lies within the chord tolerance of the true surfaces), and the number of
//! features each carries (the pieces where it differs from the layer's featureless shell).
//! Printed layers and sprayed coats are formed by no mold of their own (a coat follows the
//! cavity it is sprayed into, [`crate::parts::layers::taken_features`]). A flat skin's layers
//! are each cast alone in a tray: the space the tray leaves up to its brim.

use crate::error::{DesignError, GeometryContext};
use crate::geometry::{cuboid, ChordTolerance, Solid};
use crate::kit::Kit;
use crate::markers::MarkerSurface;
use crate::parts::layers;
use crate::parts::molds::strategy::CastPieces;
use crate::parts::molds::strategy_of;
use crate::schema::{Design, LayerProcess};
use crate::stack::Stack;

/// One cast layer, as the molds cast it and as the assembly shows it.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CastCheck {
    pub layer: String,
    /// How the layer is cast: its mold strategy (`master`, `direct`, `boundary`, `open`,
    /// `two_piece_open`), or `tray` / `laser_cut_tray` for a flat skin's layer.
    pub strategy: String,
    /// The printed parts whose closed cavity (or positive) forms the layer.
    pub formed_by: Vec<String>,
    /// Volume of the solid the molds cast, above the base plane, mm^3.
    pub cast_volume_mm3: f64,
    /// Volume of the layer's member in the assembly, mm^3.
    pub assembly_volume_mm3: f64,
    /// Volume of the symmetric difference of the two, mm^3.
    pub symmetric_difference_mm3: f64,
    /// The bound on it: 2 x chord tolerance x the layer's surface area in the assembly, mm^3.
    pub bound_mm3: f64,
    /// The pieces of the symmetric difference thicker than twice the chord tolerance (mean
    /// thickness 2 x volume / area): where both meshes are within the chord tolerance of the
    /// same surface they differ by slivers at most that thick, so each such piece is a shape
    /// the molds cast and the assembly does not show, or the other way round.
    pub thick_pieces: usize,
    /// The designed features the cast layer carries (its own and those it takes from the layer
    /// it is cast onto), each found by a probe inside it (a cube halfway along its axis that
    /// the layer must hold whole, or leave empty, where the featureless shell does the other).
    pub cast_features: usize,
    /// The same count on the assembly's layer.
    pub assembly_features: usize,
    /// The features the design places on the layer's surfaces (the layer's patterns and those
    /// it takes from the layer under it).
    pub designed_features: usize,
}

impl CastCheck {
    /// The cast layer is the assembly's: the difference within its bound, every designed
    /// feature on both.
    pub fn holds(&self) -> bool {
        self.symmetric_difference_mm3 <= self.bound_mm3
            && self.thick_pieces == 0
            && self.cast_features == self.designed_features
            && self.assembly_features == self.designed_features
    }
}

/// Checks every cast layer of `kit`, the kit built from `design` at `tol` with its whole
/// assembly ([`crate::build_kit`]), inner to outer.
///
/// # Errors
/// [`DesignError::Params`] if the design does not validate; [`DesignError::Geometry`] if the
/// kernel fails or a mold part or assembly member the check needs is missing (naming it).
pub fn check_casts(
    design: &Design,
    kit: &Kit,
    tol: ChordTolerance,
) -> Result<Vec<CastCheck>, DesignError> {
    let materials = crate::materials::MaterialsTable::embedded().map_err(DesignError::Yaml)?;
    if design.body.flat_outline().is_some() {
        let layers =
            crate::stack::flat::validate(design, &materials).map_err(DesignError::Params)?;
        let laser_cut = design.mold.laser_cut.is_some();
        // the base sheet's holes under the pocket are taped shut on its top face before the
        // pours (the procedure's first step)
        let taped = design
            .mold
            .laser_cut
            .as_ref()
            .and_then(|lc| lc.plate.as_ref())
            .and_then(|p| p.base_holes.as_ref());
        return layers
            .iter()
            .enumerate()
            .map(|(i, l)| check_flat_layer(&layers[..i], l, (laser_cut, taped), kit, tol))
            .collect();
    }
    let stack = crate::stack::validate(design, &materials, tol)?;
    stack
        .layers
        .iter()
        .filter(|l| l.process == LayerProcess::Cast)
        .map(|l| check_layer(design, &stack, kit, l.index, tol))
        .collect()
}

/// The solid of the assembly's member `name`.
fn member<'a>(kit: &'a Kit, name: &str) -> Result<&'a Solid, DesignError> {
    kit.assembly
        .iter()
        .find(|m| m.name == name)
        .map(|m| &m.solid)
        .ok_or_else(|| missing(format!("the assembly's member {name}")))
}

fn missing(what: String) -> DesignError {
    DesignError::Geometry {
        part: what.clone(),
        params: Vec::new(),
        source: crate::geometry::GeometryError::InvalidPrimitive(format!(
            "the cast check needs {what}, which the kit does not hold"
        )),
    }
}

fn check_layer(
    design: &Design,
    stack: &Stack,
    kit: &Kit,
    i: usize,
    tol: ChordTolerance,
) -> Result<CastCheck, DesignError> {
    let l = &stack.layers[i];
    let name = &l.name;
    let (cast, formed_by) = cast_layer(design, stack, kit, i, tol)?;
    let shown = member(kit, name)?;
    let (sym, thick_pieces) = compare(&cast, shown, tol).part(name)?;
    let placed = layers::place_layer_markers(&design.stack_input(), l, tol);
    let (_, taken) = layers::taken_features(&design.stack_input(), stack, i, tol);
    let sets: Vec<(&layers::PlacedMarkers, MarkerSurface)> = placed
        .iter()
        .map(|p| (p, p.spec.surface))
        .chain(taken.iter().map(|p| (p, MarkerSurface::Inner)))
        .collect();
    let designed = sets.iter().map(|(p, _)| p.markers.len()).sum();
    let probes = Probes::new(&sets).part(name)?;
    let cast_features = probes.present(&cast).part(name)?;
    let assembly_features = probes.present(shown).part(name)?;
    Ok(CastCheck {
        layer: name.clone(),
        strategy: serde_json::to_value(l.mold_strategy)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default(),
        formed_by,
        cast_volume_mm3: cast.volume(),
        assembly_volume_mm3: shown.volume(),
        symmetric_difference_mm3: sym,
        bound_mm3: 2.0 * tol.mm() * shown.surface_area(),
        thick_pieces,
        cast_features,
        assembly_features,
        designed_features: designed,
    })
}

/// One layer of a flat skin: the space its tray (taken back to the sensor frame) leaves within
/// its outline's prism from below its markers' ends up to the brim (the layer's top face),
/// less the cured layers under it (`under`) when it wraps them, against the assembly's layer;
/// the markers found by a probe halfway down each. `trays`: whether the trays are laser-cut,
/// and the base sheet's holes, taped shut on its top face for the pours.
fn check_flat_layer(
    under: &[crate::parts::flat::FlatLayer],
    l: &crate::parts::flat::FlatLayer,
    trays: (bool, Option<&crate::parts::lasercut::HolePattern>),

    kit: &Kit,
    tol: ChordTolerance,
) -> Result<CastCheck, DesignError> {
    let name = &l.name;
    let g = |r: Result<Solid, crate::geometry::GeometryError>| r.part(name);
    let tray_name = format!("{name}_tray");
    let tray = kit
        .parts
        .iter()
        .find(|p| p.name == tray_name)
        .ok_or_else(|| missing(tray_name.clone()))?;
    let t = crate::geometry::transform::from_json(&tray.params["T_print_sensor"])
        .ok_or_else(|| missing(format!("the print pose of {tray_name}")))?;
    let reach = l.marker_grid.as_ref().map_or(0.0, |m| m.feature.height_mm);
    let envelope = g(crate::geometry::prism(
        &l.outline.polygon(tol),
        l.bottom_mm() - reach - 0.1,
        l.z1_mm,
    ))?;
    let mut cast = g(envelope.difference(&tray.solid.transform(&t.inverse())))?;
    let (laser_cut, taped) = trays;
    if let Some(h) = taped {
        // the tape over the base holes: the floor closed where they open
        let floor = l.bottom_mm();
        let tape = h
            .xy_mm
            .iter()
            .map(|&c| {
                let r = h.diameter_mm / 2.0 + 0.1;
                crate::geometry::prism(
                    &crate::parts::lasercut::circle(c, r, tol),
                    floor - reach - 1.0,
                    floor,
                )
            })
            .collect::<Result<Vec<_>, _>>()
            .part(name)?;
        cast = g(cast.difference(&Solid::compose(&tape)))?;
    }
    let mut formed_by = vec![tray_name];
    if l.wraps.is_some() {
        // cast over the cured layers under it, which form its inner faces
        for u in under {
            cast = g(cast.difference(member(kit, &u.name)?))?;
            formed_by.push(u.name.clone());
        }
    }
    let shown = member(kit, name)?;
    let (sym, thick_pieces) = compare(&cast, shown, tol).part(name)?;
    let mut probes = Probes {
        inside: Vec::new(),
        outside: Vec::new(),
        inside_mm3: Vec::new(),
        outside_mm3: Vec::new(),
    };
    if let Some(m) = &l.marker_grid {
        let (h, r) = (m.feature.height_mm, m.feature.diameter_mm / 2.0);
        let a = 0.25 * r.min(h);
        for [x, y] in m.positions_mm() {
            let z = l.z0_mm - h / 2.0;
            probes
                .inside
                .push(g(cuboid([x - a, y - a, z - a], [x + a, y + a, z + a]))?);
            probes.inside_mm3.push(8.0 * a * a * a);
        }
    }
    Ok(CastCheck {
        layer: name.clone(),
        strategy: if laser_cut { "laser_cut_tray" } else { "tray" }.into(),
        formed_by,
        cast_volume_mm3: cast.volume(),
        assembly_volume_mm3: shown.volume(),
        symmetric_difference_mm3: sym,
        bound_mm3: 2.0 * tol.mm() * shown.surface_area(),
        thick_pieces,
        cast_features: probes.present(&cast).part(name)?,
        assembly_features: probes.present(shown).part(name)?,
        designed_features: l.marker_grid.as_ref().map_or(0, |m| m.positions_mm().len()),
    })
}

/// The solid the molds of cast layer `i` of `kit` cast above the base plane, sensor frame, mm
/// (see the module's description), and the names of the parts that form it.
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails or a part the layer's strategy makes is
/// missing from the kit.
pub fn cast_layer(
    design: &Design,
    stack: &Stack,
    kit: &Kit,
    i: usize,
    tol: ChordTolerance,
) -> Result<(Solid, Vec<String>), DesignError> {
    let l = &stack.layers[i];
    let name = &l.name;
    let g = |r: Result<Solid, crate::geometry::GeometryError>| r.part(name);
    // The envelope: the cavity's offset surface, beyond the tallest feature, closed on the
    // base plane.
    let cavity_offset =
        l.outer_offset_mm + layers::cavity_gap_mm(&design.stack_input(), &stack.layers, l);
    let reach = layers::place_layer_markers(&design.stack_input(), l, tol)
        .iter()
        .map(|p| p.spec.feature.height_mm)
        .fold(0.0, f64::max);
    let envelope = g(crate::geometry::revolve(
        &design
            .body
            .solid_profile(cavity_offset + reach + 0.1, 0.0, tol.half()),
        tol,
    )
    .and_then(|m| Solid::from_mesh(&m)))?;
    let kit_pieces = KitPieces {
        name,
        kit,
        envelope,
        tol,
    };
    let (cast, pieces) = strategy_of(l.mold_strategy).cast(&kit_pieces)?;
    let formed_by = pieces.iter().map(|p| p.name.clone()).collect();
    if !l.mold_strategy.holds_core() {
        return Ok((cast, formed_by));
    }
    // Cast onto the stack: the core and the layers in the mold before the pour (those under
    // it and the coats sprayed into the cavity), as the assembly shows them.
    let coats = stack.layers[i + 1..]
        .iter()
        .take_while(|s| s.process == LayerProcess::Sprayed)
        .map(|s| s.name.as_str());
    let before: Vec<&str> = std::iter::once("core_envelope")
        .chain(stack.layers[..i].iter().map(|s| s.name.as_str()))
        .chain(coats)
        .collect();
    let mut in_mold = Vec::new();
    // the core's bore: closed by its round end and by the holder's pin, the pour never fills it
    if let Some(core) = &stack.core {
        in_mold.push(g(crate::geometry::revolve(
            &design
                .body
                .solid_profile(core.inner_offset_mm, 0.0, tol.half()),
            tol,
        )
        .and_then(|m| Solid::from_mesh(&m)))?);
    }
    for b in before {
        in_mold.push(member(kit, b)?.clone());
    }
    Ok((
        g(cast.difference(&g(Solid::union_all(&in_mold))?))?,
        formed_by,
    ))
}

/// The kit's parts of one cast layer as a strategy's cast check sees them
/// ([`CastPieces`]).
struct KitPieces<'k> {
    name: &'k str,
    kit: &'k Kit,
    envelope: Solid,
    tol: ChordTolerance,
}

impl<'k> CastPieces<'k> for KitPieces<'k> {
    fn part(&self, suffix: &str) -> Option<&'k crate::Part> {
        let name = self.name;
        self.kit
            .parts
            .iter()
            .find(|p| p.name == format!("{name}_{suffix}"))
    }

    fn need(&self, suffix: &str) -> Result<&'k crate::Part, DesignError> {
        let name = self.name;
        self.part(suffix)
            .ok_or_else(|| missing(format!("{name}_{suffix}")))
    }

    fn in_sensor(&self, p: &crate::Part) -> Result<Solid, DesignError> {
        let t = crate::geometry::transform::from_json(&p.params["T_print_sensor"])
            .ok_or_else(|| missing(format!("the print pose of {}", p.name)))?;
        Ok(p.solid.transform(&t.inverse()))
    }

    /// The space the closed pieces leave, within the envelope.
    fn negative(&self, pieces: &[&crate::Part]) -> Result<Solid, DesignError> {
        let solids = pieces
            .iter()
            .map(|p| self.in_sensor(p))
            .collect::<Result<Vec<_>, _>>()?;
        let b = self
            .envelope
            .bounding_box()
            .ok_or_else(|| missing(format!("the envelope of {}", self.name)))?;
        let bx = self.named(cuboid(
            [b.min[0] - 1.0, b.min[1] - 1.0, b.min[2]],
            [b.max[0] + 1.0, b.max[1] + 1.0, b.max[2] + 1.0],
        ))?;
        self.named(
            bx.difference(&self.named(Solid::union_all(&solids))?)
                .and_then(|s| s.intersection(&self.envelope)),
        )
    }

    fn envelope(&self) -> &Solid {
        &self.envelope
    }

    fn missing(&self, what: String) -> DesignError {
        missing(what)
    }

    fn tol(&self) -> ChordTolerance {
        self.tol
    }

    fn named(
        &self,
        r: Result<Solid, crate::geometry::GeometryError>,
    ) -> Result<Solid, DesignError> {
        r.part(self.name)
    }
}

/// A small cube inside each feature of a layer, halfway along its axis, split by where the
/// layer has it: inside the layer (a feature that adds to it: raised on its outer surface, or
/// on its inner surface a feature that points inward, into the space under it), or outside (one
/// cut from it). The featureless shell has each the other way round, so a probe tells whether
/// the feature is there.
struct Probes {
    inside: Vec<Solid>,
    outside: Vec<Solid>,
    /// The volume of one probe of each list, mm^3.
    inside_mm3: Vec<f64>,
    outside_mm3: Vec<f64>,
}

impl Probes {
    fn new(
        sets: &[(&layers::PlacedMarkers, MarkerSurface)],
    ) -> Result<Self, crate::geometry::GeometryError> {
        let mut p = Probes {
            inside: Vec::new(),
            outside: Vec::new(),
            inside_mm3: Vec::new(),
            outside_mm3: Vec::new(),
        };
        for (pm, surface) in sets {
            let h = pm.spec.feature.height_mm;
            let a = 0.25 * pm.radius_mm().min(h);
            let adds = match surface {
                MarkerSurface::Outer => pm.direction > 0.0,
                MarkerSurface::Inner => pm.direction < 0.0,
            };
            for m in &pm.markers {
                let c: [f64; 3] = std::array::from_fn(|k| {
                    m.position_mm[k] + pm.direction * m.normal[k] * h / 2.0
                });
                let cube = cuboid(
                    [c[0] - a, c[1] - a, c[2] - a],
                    [c[0] + a, c[1] + a, c[2] + a],
                )?;
                let (list, vols) = if adds {
                    (&mut p.inside, &mut p.inside_mm3)
                } else {
                    (&mut p.outside, &mut p.outside_mm3)
                };
                list.push(cube);
                vols.push(8.0 * a * a * a);
            }
        }
        Ok(p)
    }

    /// How many of the features `s` has: the inside probes it holds whole, and the outside
    /// probes it leaves empty.
    fn present(&self, s: &Solid) -> Result<usize, crate::geometry::GeometryError> {
        let held =
            |probes: &[Solid], vols: &[f64]| -> Result<usize, crate::geometry::GeometryError> {
                if probes.is_empty() {
                    return Ok(0);
                }
                let smallest = vols.iter().copied().fold(f64::INFINITY, f64::min);
                let inter = s.intersection(&Solid::compose(probes))?;
                Ok(shell_volumes(&inter.mesh())
                    .into_iter()
                    .filter(|&v| v > 0.5 * smallest)
                    .count())
            };
        let inside = held(&self.inside, &self.inside_mm3)?;
        let outside = held(&self.outside, &self.outside_mm3)?;
        Ok(inside + self.outside.len() - outside.min(self.outside.len()))
    }
}

/// The volume of the symmetric difference of `a` and `b`, mm^3, and the number of its pieces
/// (edge-connected shells) thicker than twice the chord tolerance ([`CastCheck::thick_pieces`]).
fn compare(
    a: &Solid,
    b: &Solid,
    tol: ChordTolerance,
) -> Result<(f64, usize), crate::geometry::GeometryError> {
    let d = a.difference(b)?.union(&b.difference(a)?)?;
    let thick = d
        .mesh()
        .shell_volumes_and_areas()
        .into_iter()
        .filter(|&(v, area)| 2.0 * v > 2.0 * tol.mm() * area + 1e-9)
        .count();
    Ok((d.volume(), thick))
}

/// The volume of each edge-connected shell of `m`, mm^3 (divergence theorem per shell).
pub fn shell_volumes(m: &crate::Mesh) -> Vec<f64> {
    m.shell_volumes_and_areas()
        .into_iter()
        .map(|(v, _)| v)
        .collect()
}
