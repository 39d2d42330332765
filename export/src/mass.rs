//! The assembled sensor's mass properties, for simulators and a robot's payload (issue 103):
//! each member's mass, centre of mass and inertia from its written mesh (exact for the
//! polyhedron: [`fabkit_designs::geometry::Mesh::mass_properties`]) at its material's density
//! (designs/materials.yaml, each with its source), and the whole sensor's from them by the
//! parallel-axis theorem. Sensor frame (docs/conventions.md), mm and g.

use fabkit_designs::geometry::Mesh;
use fabkit_designs::materials::MaterialsTable;
use serde::{Deserialize, Serialize};

/// What [`SensorMass`] assumes, in words.
pub const ASSUMPTIONS: [&str; 3] = [
    "each member is of uniform density, its material's (designs/materials.yaml: the datasheet's specific gravity)",
    "printed members are solid (100 % infill); one printed with less infill is lighter",
    "bought items without a material (a camera board, an LED PCB) are not counted: their masses are their datasheets'",
];

/// One member's mass properties.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MemberMass {
    /// g.
    pub mass_g: f64,
    /// Density used, g/cm^3.
    pub density_g_per_cm3: f64,
    /// Centre of mass, sensor frame, mm.
    pub centre_of_mass_mm: [f64; 3],
    /// Inertia tensor about the centre of mass, sensor axes, g mm^2 (products of inertia with
    /// their minus sign: URDF's and MJCF's `fullinertia` convention).
    pub inertia_g_mm2: [[f64; 3]; 3],
}

/// The mass properties of `mesh` (mm, closed) at `density_g_per_cm3`.
pub fn member_mass(mesh: &Mesh, density_g_per_cm3: f64) -> MemberMass {
    let p = mesh.mass_properties();
    // g/cm^3 = 1e-3 g/mm^3
    let rho = density_g_per_cm3 * 1e-3;
    MemberMass {
        mass_g: rho * p.volume_mm3,
        density_g_per_cm3,
        centre_of_mass_mm: p.centroid_mm,
        inertia_g_mm2: p.inertia_mm5.map(|r| r.map(|v| rho * v)),
    }
}

/// The assembled sensor's mass properties: the members with a material, combined.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensorMass {
    /// g.
    pub mass_g: f64,
    /// Sensor frame, mm.
    pub centre_of_mass_mm: [f64; 3],
    /// About the centre of mass, sensor axes, g mm^2.
    pub inertia_g_mm2: [[f64; 3]; 3],
    /// The members counted, in assembly order.
    pub counted: Vec<String>,
    /// The members left out (no material), in assembly order.
    pub not_counted: Vec<String>,
    /// [`ASSUMPTIONS`].
    pub assumptions: Vec<String>,
}

/// The combined mass properties of `members` (name, its mass if it has a material): the total
/// mass, the mass-weighted centre and the sum of each member's inertia moved to that centre
/// (parallel-axis theorem: I + m (|d|^2 E - d d^T), d from the combined centre to the
/// member's). With no member counted, mass 0 and a NaN centre.
pub fn sensor_mass<'a>(
    members: impl IntoIterator<Item = (&'a str, Option<&'a MemberMass>)>,
) -> SensorMass {
    let (mut counted, mut not_counted, mut masses) = (Vec::new(), Vec::new(), Vec::new());
    for (name, m) in members {
        match m {
            Some(m) => {
                counted.push(name.to_string());
                masses.push(*m);
            }
            None => not_counted.push(name.to_string()),
        }
    }
    let total: f64 = masses.iter().map(|m| m.mass_g).sum();
    let centre: [f64; 3] = std::array::from_fn(|k| {
        masses
            .iter()
            .map(|m| m.mass_g * m.centre_of_mass_mm[k])
            .sum::<f64>()
            / total
    });
    let mut inertia = [[0.0; 3]; 3];
    for m in &masses {
        let d: [f64; 3] = std::array::from_fn(|k| m.centre_of_mass_mm[k] - centre[k]);
        let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        for i in 0..3 {
            for j in 0..3 {
                let e = if i == j { d2 } else { 0.0 };
                inertia[i][j] += m.inertia_g_mm2[i][j] + m.mass_g * (e - d[i] * d[j]);
            }
        }
    }
    SensorMass {
        mass_g: total,
        centre_of_mass_mm: centre,
        inertia_g_mm2: inertia,
        counted,
        not_counted,
        assumptions: ASSUMPTIONS.iter().map(|s| (*s).to_string()).collect(),
    }
}

/// The density of material `key`, g/cm^3, when the table has it.
pub fn density(materials: Option<&MaterialsTable>, key: &str) -> Option<f64> {
    materials
        .and_then(|t| t.materials.get(key))
        .map(|m| m.density_g_per_cm3)
}
