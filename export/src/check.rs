//! Checks made before anything touches the disk: names, options and printable meshes.

use crate::{ExportError, ExportOptions};
use fabkit_designs::geometry::Mesh;
use fabkit_designs::kit::Kit;
use std::collections::BTreeSet;

/// Checks that `mesh`, exactly as it will be written (already rounded to f32, see
/// [`Mesh::rounded_to_f32`]), is a printable solid: a closed, consistently oriented 2-manifold
/// with positive volume whose distinct vertices also have distinct positions, so that readers
/// which merge vertices by position (STL) see the same closed manifold.
///
/// `part` only names the part in the error. Nothing is repaired or welded.
///
/// # Errors
/// [`ExportError::NotManifold`] with the [`fabkit_designs::geometry::TopologyError`] as source,
/// or [`ExportError::CoincidentVertices`].
///
/// ```
/// use fabkit_designs::geometry::Mesh;
/// use fabkit_export::{check_printable_mesh, ExportError};
/// // a tetrahedron with one face missing
/// let open = Mesh {
///     vertices: vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
///     triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3]],
/// };
/// let err = check_printable_mesh("lid", &open).unwrap_err();
/// assert!(matches!(err, ExportError::NotManifold { ref part, .. } if part == "lid"));
/// ```
pub fn check_printable_mesh(part: &str, mesh: &Mesh) -> Result<(), ExportError> {
    mesh.check_closed_manifold()
        .map_err(|source| ExportError::NotManifold {
            part: part.to_owned(),
            source,
        })?;
    // Positions as exact bit patterns (+0 and -0 are one position).
    let mut keys: Vec<[u64; 3]> = mesh
        .vertices
        .iter()
        .map(|v| v.map(|c| if c == 0.0 { 0 } else { c.to_bits() }))
        .collect();
    keys.sort_unstable();
    let count = keys.windows(2).filter(|w| w[0] == w[1]).count();
    if count > 0 {
        return Err(ExportError::CoincidentVertices {
            part: part.to_owned(),
            count,
        });
    }
    Ok(())
}

/// Part names `[a-z0-9_]+`, unique; design name `[A-Za-z0-9_-]+`; at least one part; group
/// names non-empty, one line, no surrounding spaces.
pub(crate) fn check_names(kit: &Kit) -> Result<(), ExportError> {
    let design_ok = !kit.design.is_empty()
        && kit
            .design
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if !design_ok {
        return Err(ExportError::InvalidDesignName {
            name: kit.design.clone(),
        });
    }
    if kit.parts.is_empty() {
        return Err(ExportError::NoParts {
            design: kit.design.clone(),
        });
    }
    // printed and machined parts share the file stems (parts/, machined/, step/)
    let mut seen = BTreeSet::new();
    let mut unique = |name: &str| {
        let ok = !name.is_empty()
            && name
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
        if !ok {
            return Err(ExportError::InvalidPartName { name: name.into() });
        }
        if !seen.insert(name.to_string()) {
            return Err(ExportError::DuplicatePartName { name: name.into() });
        }
        Ok(())
    };
    for part in &kit.parts {
        unique(&part.name)?;
        if let Some(g) = &part.group {
            if g.is_empty() || g.trim() != g || g.chars().any(char::is_control) {
                return Err(ExportError::InvalidGroupName {
                    part: part.name.clone(),
                    group: g.clone(),
                });
            }
        }
    }
    for m in &kit.machined_parts {
        unique(&m.name)?;
    }
    Ok(())
}

pub(crate) fn check_options(opts: &ExportOptions) -> Result<(), ExportError> {
    let hash = &opts.design_sha256;
    if hash.len() != 64
        || !hash
            .chars()
            .all(|c| c.is_ascii_digit() || ('a'..='f').contains(&c))
    {
        return Err(ExportError::InvalidOption {
            field: "design_sha256",
            value: hash.clone(),
            rule: "must be 64 lowercase hexadecimal digits (the sha256 of the design text)",
        });
    }
    if !(opts.chord_tolerance_mm.is_finite() && opts.chord_tolerance_mm > 0.0) {
        return Err(ExportError::InvalidOption {
            field: "chord_tolerance_mm",
            value: opts.chord_tolerance_mm.to_string(),
            rule: "must be a finite number above 0",
        });
    }
    if opts.fabkit_version.trim().is_empty() {
        return Err(ExportError::InvalidOption {
            field: "fabkit_version",
            value: opts.fabkit_version.clone(),
            rule: "must not be empty",
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetra() -> Mesh {
        Mesh {
            vertices: vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
            triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        }
    }

    #[test]
    fn closed_tetrahedron_passes() {
        assert!(check_printable_mesh("t", &tetra()).is_ok());
    }

    #[test]
    fn inside_out_mesh_is_refused() {
        let mut m = tetra();
        for t in &mut m.triangles {
            t.swap(1, 2);
        }
        assert!(matches!(
            check_printable_mesh("t", &m),
            Err(ExportError::NotManifold { .. })
        ));
    }

    #[test]
    fn two_tetrahedra_touching_at_a_vertex_are_refused() {
        // Index-manifold, but vertex 4 sits where vertex 3 is: a pinch for an STL reader.
        let mut m = tetra();
        let off = [0.0, 0.0, 1.0];
        let base = m.vertices.len() as u32;
        m.vertices.extend(
            tetra()
                .vertices
                .iter()
                .map(|v| [v[0] + off[0], v[1] + off[1], v[2] + off[2]]),
        );
        m.triangles
            .extend(tetra().triangles.iter().map(|t| t.map(|i| i + base)));
        assert!(matches!(
            check_printable_mesh("pinch", &m),
            Err(ExportError::CoincidentVertices { count: 1, .. })
        ));
    }
}
