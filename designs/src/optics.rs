//! How the inside of a sensor is lit and imaged (`optics` in a design): the lights, the skin's
//! reflectance, the markers' albedo and the camera's response, from which the tactile images
//! the camera sees are rendered beside the ground-truth depth. Sensor frame, mm
//! (docs/conventions.md).
//!
//! The light model: each light is a point emitter whose radiant intensity falls off as the
//! cosine of the angle from its beam axis (a Lambertian LED: half intensity at 60 deg, the
//! 120 deg viewing angle of the common 2835 and 0603 packages) and is 0 outside its cone. A
//! surface point at distance `d` mm receives `intensity x cos(off-axis) x cos(incidence) / d^2`
//! from it, per colour channel times `colour_rgb`. When a design gives no `optics.lights`, the
//! lights are its section families' ([`crate::parts::family::Family::lights`]): R-Tac0's LED
//! ring under the diffuser, ShadowTac's three RGB LEDs round the light chamber, the TacTip's
//! six-LED ring under the window, UVDtact's white and UV LEDs.

pub mod elements;

pub use crate::schema::optics::{check, CameraResponse, OpticsParams, Reflectance, MAX_LIGHTS};
pub use elements::{ring_of_lights, FlatInterface, Lens, Light, AIR, DEFAULT_LED_INTENSITY};

use crate::error::ParamError;
use crate::parts::context::Stack;
use crate::parts::registry::FAMILIES;
use crate::schema::Design;
use serde::Serialize;

/// A marker's face the camera sees (a TacTip pin's white tip, a UV-ink marker, a painted 3D
/// marker's end), drawn as `marker_albedo_rgb` on the skin's reference surface: the surface
/// points within `radius_mm` of `centre_mm`. Recessed features (ShadowTac's dimples) are not
/// spots: they show by their shape.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MarkerSpot {
    /// The marker's centre moved along its normal onto the reference surface (offset 0),
    /// sensor frame, mm.
    pub centre_mm: [f64; 3],
    /// Outward unit normal of the surface there: the direction the marker moves in when the
    /// skin is pushed in.
    pub normal: [f64; 3],
    /// Radius of the feature, mm.
    pub radius_mm: f64,
}

/// A dimple in the surface the camera sees (ShadowTac's, Sec. III-B, IV-A): a recessed
/// feature of the skin's outer surface, a cylinder with a hemispherical end cut into the
/// elastomer, which from inside stands towards the camera, shades and casts shadows.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Dimple {
    /// Centre of the feature's base on the reference surface (offset 0), sensor frame, mm.
    pub base_mm: [f64; 3],
    /// Outward unit normal there: the feature reaches `height_mm` against it.
    pub normal: [f64; 3],
    /// Radius of the cylinder and of its hemispherical end, mm.
    pub radius_mm: f64,
    /// From the surface to the hemisphere's tip, mm (>= radius).
    pub height_mm: f64,
}

/// The optics a render uses: the design's `optics` (or its defaults) with its lights resolved.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResolvedOptics {
    /// The lights, given or the families'; at least one.
    pub lights: Vec<Light>,
    /// Where each light came from: `optics.lights[i]` or the family key (`housing`).
    pub light_sources: Vec<String>,
    pub surface: Reflectance,
    pub marker_albedo_rgb: [f64; 3],
    pub camera: CameraResponse,
    /// The markers drawn as albedo, from the layers' raised marker features.
    pub markers: Vec<MarkerSpot>,
    /// Where the markers came from: `layers[i].markers[k]` or `layers[i].marker_grid`, one
    /// entry per pattern with its count.
    pub marker_sources: Vec<(String, usize)>,
    /// The recessed features of the surface the camera sees, from the layers' marker
    /// patterns on the outer skin surface.
    pub dimples: Vec<Dimple>,
    /// Where the dimples came from: `layers[i].markers[k]` with its count.
    pub dimple_sources: Vec<(String, usize)>,
}

/// Spots and dimples on the reference surface, each with its sources.
type Features = (
    (Vec<MarkerSpot>, Vec<(String, usize)>),
    (Vec<Dimple>, Vec<(String, usize)>),
);

/// The raised marker features of `design` (placed on `stack`'s layers; a flat skin's marker
/// grids) as spots on its reference surface, and the recessed features of that surface (offset
/// 0) as [`Dimple`]s.
fn marker_features(design: &Design, stack: &Stack) -> Features {
    use crate::markers::Polarity;
    let (mut spots, mut sources) = (Vec::new(), Vec::new());
    if design.body.flat_outline().is_some() {
        let top = design.body.pole_z_mm(0.0);
        for (i, l) in design.layers.iter().enumerate() {
            let Some(g) = &l.marker_grid else { continue };
            if g.feature.side() != Polarity::Raised {
                continue;
            }
            let at = g.positions_mm();
            sources.push((format!("layers[{i}].marker_grid"), at.len()));
            spots.extend(at.into_iter().map(|[x, y]| MarkerSpot {
                centre_mm: [x, y, top],
                normal: [0.0, 0.0, 1.0],
                radius_mm: g.feature.radius_mm(),
            }));
        }
        return ((spots, sources), (Vec::new(), Vec::new()));
    }
    let (mut dimples, mut dimple_sources) = (Vec::new(), Vec::new());
    for layer in &stack.layers {
        let specs = &design.layers[layer.index].markers;
        for (spec, offset, _, markers) in
            crate::parts::layer_markers::placed_patterns(&design.stack_input(), layer)
        {
            let k = specs
                .iter()
                .position(|s| std::ptr::eq(s, spec))
                .unwrap_or(0);
            if spec.feature.side() != Polarity::Raised {
                if offset.abs() < 1e-9 {
                    dimple_sources.push((
                        format!("layers[{}].markers[{k}]", layer.index),
                        markers.len(),
                    ));
                    dimples.extend(markers.into_iter().map(|m| Dimple {
                        base_mm: m.position_mm,
                        normal: m.normal,
                        radius_mm: spec.feature.radius_mm(),
                        height_mm: spec.feature.height_mm,
                    }));
                }
                continue;
            }
            sources.push((
                format!("layers[{}].markers[{k}]", layer.index),
                markers.len(),
            ));
            spots.extend(markers.into_iter().map(|m| MarkerSpot {
                centre_mm: std::array::from_fn(|c| m.position_mm[c] - offset * m.normal[c]),
                normal: m.normal,
                radius_mm: spec.feature.radius_mm(),
            }));
        }
    }
    ((spots, sources), (dimples, dimple_sources))
}

/// The optics of `design` with its resolved `stack`: its `optics` section (or the defaults)
/// with the lights it gives, or else its families' lights in registry order.
///
/// # Errors
/// Every violated rule of `optics` (paths under `optics.`), and `optics.lights` when the design
/// gives none and no family of it has lights.
pub fn resolve(design: &Design, stack: &Stack) -> Result<ResolvedOptics, Vec<ParamError>> {
    let o = design.optics.clone().unwrap_or_default();
    let mut errs = Vec::new();
    check(&o, &mut errs);
    let (lights, light_sources) = match &o.lights {
        Some(l) => (
            l.clone(),
            (0..l.len())
                .map(|i| format!("optics.lights[{i}]"))
                .collect(),
        ),
        None => {
            let mut lights = Vec::new();
            let mut sources = Vec::new();
            for f in FAMILIES {
                for l in f.lights(design, stack) {
                    lights.push(l);
                    sources.push(f.path().to_string());
                }
            }
            if lights.is_empty() {
                errs.push(ParamError::new(
                    "optics.lights",
                    "not given",
                    "the design has no part that carries lights (housing, casing, shaft_body, fingertip_base): give optics.lights",
                ));
            }
            (lights, sources)
        }
    };
    if !errs.is_empty() {
        return Err(errs);
    }
    let ((markers, marker_sources), (dimples, dimple_sources)) = marker_features(design, stack);
    Ok(ResolvedOptics {
        lights,
        light_sources,
        surface: o.surface,
        marker_albedo_rgb: o.marker_albedo_rgb,
        camera: o.camera,
        markers,
        marker_sources,
        dimples,
        dimple_sources,
    })
}

/// The optics of `design` for a render: the design validated as `fabkit validate` does (its
/// stack for a curved skin; a flat skin has no stack and carries no family's lights), then
/// [`resolve`]d.
///
/// # Errors
/// [`DesignError::Params`] with every violated rule of the design and of its `optics` (paths
/// under `optics.`); [`DesignError::Yaml`] if the embedded materials table does not load.
pub fn of_design(
    design: &Design,
    tol: crate::geometry::ChordTolerance,
) -> Result<ResolvedOptics, crate::error::DesignError> {
    use crate::error::DesignError;
    let (stack, _) = validated_stack(design, tol)?;
    resolve(design, &stack).map_err(|e| DesignError::Params(crate::ParamErrors(e)))
}

/// The design's stack resolved at `tol` (none for a flat skin, whose parameters are checked),
/// and the embedded materials table it was checked against.
///
/// # Errors
/// The design's validation errors.
fn validated_stack(
    design: &Design,
    tol: crate::geometry::ChordTolerance,
) -> Result<(Stack, crate::materials::MaterialsTable), crate::error::DesignError> {
    use crate::error::DesignError;
    let materials = crate::materials::MaterialsTable::embedded().map_err(DesignError::Yaml)?;
    let stack = if design.body.flat_outline().is_some() {
        crate::stack::flat::validate(design, &materials)?;
        Stack {
            core: None,
            layers: Vec::new(),
        }
    } else {
        crate::stack::validate(design, &materials, tol)?
    };
    Ok((stack, materials))
}

/// The flat optical path ([`optical_path`]) of `design`, its stack resolved at `tol` and the
/// indices from the embedded materials table.
///
/// # Errors
/// The design's validation errors, and [`optical_path`]'s.
pub fn optical_path_of_design(
    design: &Design,
    tol: crate::geometry::ChordTolerance,
) -> Result<OpticalPath, crate::error::DesignError> {
    use crate::error::DesignError;
    let (stack, materials) = validated_stack(design, tol)?;
    optical_path(design, &stack, &materials)
        .map_err(|e| DesignError::Params(crate::ParamErrors(vec![e])))
}

/// The lens of the first section family of `design` that places one ([`Lens`]).
pub fn lens(design: &Design, stack: &Stack) -> Option<Lens> {
    FAMILIES.iter().find_map(|f| f.lens(design, stack))
}

/// What the camera of `design` sees through: its [`Lens`] and the [`OpticalPath`] in front of
/// it, the stack resolved at `tol` and the indices from the embedded materials table. `None`
/// when no section family places a lens.
///
/// # Errors
/// The design's validation errors, and [`optical_path`]'s.
pub fn camera_view_of_design(
    design: &Design,
    tol: crate::geometry::ChordTolerance,
) -> Result<Option<(Lens, OpticalPath)>, crate::error::DesignError> {
    use crate::error::DesignError;
    let (stack, materials) = validated_stack(design, tol)?;
    let Some(lens) = lens(design, &stack) else {
        return Ok(None);
    };
    let path = optical_path(design, &stack, &materials)
        .map_err(|e| DesignError::Params(crate::ParamErrors(vec![e])))?;
    Ok(Some((lens, path)))
}

/// One plane of a design's [`OpticalPath`], resolved against the materials table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathPlane {
    /// Height of the plane, sensor frame z, mm.
    pub z_mm: f64,
    /// What the plane is, naming its parameters.
    pub what: String,
    /// The medium above it: a material key or `air`.
    pub above: String,
    /// The refractive index above it (n_D).
    pub index_above: f64,
    /// Where that index comes from (the materials table's source; `ASSUMPTION: ...` where no
    /// maker publishes one).
    pub index_source: String,
}

/// One curved interface of a design's [`OpticalPath`]: a face of the core or of a cast layer
/// on a spherical body, coaxial with the sensor's z axis: the sphere of `radius_mm` centred on
/// the axis at `centre_z_mm`, above `join_z_mm`, and below it the cylinder of the sphere's
/// section there down to `bottom_z_mm` (a test tube's hemisphere on its cylinder: join at the
/// centre). Resolved against the materials table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathShell {
    pub radius_mm: f64,
    pub centre_z_mm: f64,
    pub join_z_mm: f64,
    pub bottom_z_mm: f64,
    /// Where the medium outside begins, mm: the core's open end for its inner face, the base
    /// plane for the faces of the layers cast above it (below it is the housing's seat).
    pub outside_bottom_z_mm: f64,
    /// What the face is, naming its parameters (`core: the core's inner face`).
    pub what: String,
    /// The medium outside it: a material key.
    pub outside: String,
    /// The refractive index outside it (n_D).
    pub index_outside: f64,
    /// Where that index comes from (the materials table's source).
    pub index_source: String,
}

/// The optical path of a design from the camera up: air under the lowest plane (where the
/// camera sits), then each plane with the medium above it, increasing in z; then, inside the
/// medium above the last plane, the curved faces of a spherical core and of the clear layers
/// cast on it, innermost first, up to the first layer the camera cannot see through (no
/// refractive index: the coat it images). Not in it: the faces of a half-ellipsoidal core
/// (UVDtact's acrylic shell), which are not spheres.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OpticalPath {
    pub planes: Vec<PathPlane>,
    /// The curved faces (empty without a spherical core); left out of JSON when empty.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub shells: Vec<PathShell>,
}

/// The index and its source of the medium `key` (a material key or [`AIR`]); `None` for a
/// material without a refractive index (an opaque one) or not in the table.
fn index_of(key: &str, materials: &crate::materials::MaterialsTable) -> Option<(f64, String)> {
    if key == AIR {
        return Some((
            1.0,
            "air, n = 1.000 (1.0003 at 589 nm, taken as 1)".to_string(),
        ));
    }
    materials
        .get(key)
        .and_then(|m| m.refractive_index.as_ref())
        .map(|r| (r.n, r.source.clone()))
}

/// The curved faces of the design's optical path ([`OpticalPath::shells`]): the core's inner
/// and outer faces and the outer face of each cast layer on it, while the medium outside is
/// clear (has a refractive index), for a body whose offsets are spheres (a hemisphere on a
/// cylinder, a spherical cap); none without a core or when the core is not clear. The core
/// reaches `below_base_mm` under the base plane; the layers end at it.
pub fn curved_interfaces(
    design: &Design,
    stack: &Stack,
    materials: &crate::materials::MaterialsTable,
) -> Vec<PathShell> {
    let (Some(core), Some(core_params), Some(r_body)) =
        (&stack.core, &design.core, design.body.sphere_radius_mm())
    else {
        return Vec::new();
    };
    let base = design.body.base_z_mm();
    let join = base.max(0.0);
    let shell = |offset: f64, bottom: f64, outside_bottom: f64, outside: &str, what: String| {
        index_of(outside, materials).map(|(n, source)| PathShell {
            radius_mm: r_body + offset,
            centre_z_mm: 0.0,
            join_z_mm: join,
            bottom_z_mm: bottom,
            outside_bottom_z_mm: outside_bottom,
            what,
            outside: outside.to_string(),
            index_outside: n,
            index_source: source,
        })
    };
    let core_bottom = base - core.below_base_mm;
    let mut out = Vec::new();
    let Some(inner) = shell(
        core.inner_offset_mm,
        core_bottom,
        core_bottom,
        &core_params.material,
        "core: the core's inner face".into(),
    ) else {
        return out;
    };
    out.push(inner);
    // outside the core: the first layer when it is cast on the core, else air
    let first = stack
        .layers
        .first()
        .filter(|l| (l.inner_offset_mm - core.outer_offset_mm).abs() < 1e-9);
    let outside = first.map_or(AIR, |l| l.material.as_str());
    match shell(
        core.outer_offset_mm,
        core_bottom,
        base,
        outside,
        "core: the core's outer face".into(),
    ) {
        Some(s) => out.push(s),
        None => return out,
    }
    if first.is_none() {
        return out;
    }
    for (k, w) in stack.layers.windows(2).enumerate() {
        if (w[1].inner_offset_mm - w[0].outer_offset_mm).abs() > 1e-9 {
            break;
        }
        match shell(
            w[0].outer_offset_mm,
            base,
            base,
            &w[1].material,
            format!("layers[{k}]: the outer face of {}", w[0].name),
        ) {
            Some(s) => out.push(s),
            None => break,
        }
    }
    out
}

/// The design's optical path ([`OpticalPath`]): its families' flat interfaces
/// ([`crate::parts::family::Family::flat_interfaces`]) and the backing plate's faces (air
/// under it; above it the skin's innermost layer when that is solid, else air), sorted by
/// height, each medium's index from `materials`; then the curved faces of a spherical core
/// and its clear layers ([`curved_interfaces`]).
///
/// # Errors
/// The parameter path of a medium whose material is not in the table or has no
/// `refractive_index`, and of two planes at the same height.
pub fn optical_path(
    design: &Design,
    stack: &Stack,
    materials: &crate::materials::MaterialsTable,
) -> Result<OpticalPath, ParamError> {
    let mut planes: Vec<FlatInterface> = Vec::new();
    for f in FAMILIES {
        planes.extend(f.flat_interfaces(design, stack));
    }
    if let Some(b) = &design.backing {
        let top = design.body.base_z_mm();
        planes.push(FlatInterface {
            z_mm: top - b.thickness_mm,
            above: b.material.clone(),
            what: "backing: the plate's bottom face".into(),
        });
        // a solid innermost layer fills the skin down to the plate; else the skin's inside is air
        let (above, what) = match design.layers.first().filter(|l| l.solid) {
            Some(l) => (
                l.material.clone(),
                "backing: the plate's top face, under the solid skin (layers[0])",
            ),
            None => (
                AIR.to_string(),
                "backing: the plate's top face, under the skin's inside (air)",
            ),
        };
        planes.push(FlatInterface {
            z_mm: top,
            above,
            what: what.into(),
        });
    }
    planes.sort_by(|a, b| a.z_mm.total_cmp(&b.z_mm));
    for w in planes.windows(2) {
        if !(w[1].z_mm > w[0].z_mm) {
            return Err(ParamError::new(
                w[1].what.split(':').next().unwrap_or("optics"),
                w[1].z_mm,
                format!(
                    "two flat interfaces at the same height ({} and {})",
                    w[0].what, w[1].what
                ),
            ));
        }
    }
    let planes = planes
        .into_iter()
        .map(|p| {
            let (n, source) = index_of(&p.above, materials).ok_or_else(|| {
                ParamError::new(
                    p.what.split(':').next().unwrap_or("optics"),
                    &p.above,
                    "the camera looks through this material: it needs a refractive_index in the materials table",
                )
            })?;
            Ok(PathPlane {
                z_mm: p.z_mm,
                what: p.what,
                above: p.above,
                index_above: n,
                index_source: source,
            })
        })
        .collect::<Result<Vec<_>, ParamError>>()?;
    Ok(OpticalPath {
        planes,
        shells: curved_interfaces(design, stack, materials),
    })
}
