//! Binary STL: our own small writer, so that the header and the bytes are ours to fix.
//!
//! Layout (little endian): 80-byte header, `u32` triangle count, then per triangle the facet
//! normal and three vertices as `f32` x, y, z (mm) and a zero `u16` attribute: 50 bytes.

use crate::ExportError;
use fabkit_designs::geometry::Mesh;

/// Size of a binary STL header, bytes.
pub(crate) const HEADER_LEN: usize = 80;

/// The 80-byte header: `fabkit <version> <design> <part> sha256:<first 16 hex> mm`, non-ASCII
/// bytes replaced by `?`, padded with spaces to 80 bytes. It starts with `fabkit`, never with
/// `solid` (which makes some readers take the file for ASCII STL), and always ends in the unit
/// word `mm`: a text too long for 80 bytes loses the end of the part name first (cut names end
/// in `~`), then, if still too long, the end of what comes before the unit.
pub(crate) fn header(
    version: &str,
    design: &str,
    part: &str,
    design_sha256: &str,
) -> [u8; HEADER_LEN] {
    let ascii = |s: &str| -> Vec<u8> {
        s.bytes()
            .map(|c| {
                if c.is_ascii() && !c.is_ascii_control() {
                    c
                } else {
                    b'?'
                }
            })
            .collect()
    };
    let hash16: String = design_sha256.chars().take(16).collect();
    let head = ascii(&format!("fabkit {version} {design} "));
    let tail = ascii(&format!(" sha256:{hash16}"));
    const UNIT: &[u8] = b" mm";
    let mut part = ascii(part);
    let room = HEADER_LEN.saturating_sub(head.len() + tail.len() + UNIT.len());
    if part.len() > room {
        part.truncate(room.saturating_sub(1));
        if room > 0 {
            part.push(b'~');
        }
    }
    let mut text = [head, part, tail].concat();
    text.truncate(HEADER_LEN - UNIT.len());
    text.extend_from_slice(UNIT);
    let mut out = [b' '; HEADER_LEN];
    out[..text.len()].copy_from_slice(&text);
    out
}

/// Encodes `mesh` (coordinates already rounded to f32) as binary STL with `header`.
///
/// Facet normals are the unit right-hand normals of the f32 vertices, computed in f64; a
/// zero-area facet gets the zero normal. Winding is kept as in the mesh.
///
/// # Errors
/// [`ExportError::TooManyTriangles`] beyond `u32::MAX` triangles (`part` names the part).
pub(crate) fn encode(
    part: &str,
    mesh: &Mesh,
    header: &[u8; HEADER_LEN],
) -> Result<Vec<u8>, ExportError> {
    let count = u32::try_from(mesh.triangles.len()).map_err(|_| ExportError::TooManyTriangles {
        part: part.to_owned(),
        triangles: mesh.triangles.len(),
    })?;
    let mut out = Vec::with_capacity(HEADER_LEN + 4 + 50 * mesh.triangles.len());
    out.extend_from_slice(header);
    out.extend_from_slice(&count.to_le_bytes());
    for t in &mesh.triangles {
        // Indices were checked by `check_printable_mesh`; `get` keeps a bad index from panicking.
        let corner = |k: usize| -> [f64; 3] {
            mesh.vertices
                .get(t[k] as usize)
                .copied()
                .unwrap_or([f64::NAN; 3])
        };
        let (a, b, c) = (corner(0), corner(1), corner(2));
        for c in facet_normal(a, b, c) {
            out.extend_from_slice(&(c as f32).to_le_bytes());
        }
        for v in [a, b, c] {
            for c in v {
                out.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        out.extend_from_slice(&0u16.to_le_bytes());
    }
    Ok(out)
}

fn facet_normal(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let n = fabkit_designs::geometry::triangle_cross(a, b, c);
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len > 0.0 && len.is_finite() {
        n.map(|c| c / len)
    } else {
        [0.0; 3]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_is_80_bytes_and_does_not_start_with_solid() {
        let h = header("0.1.0", "rtac0", "core_holder", &"ab".repeat(32));
        assert_eq!(h.len(), 80);
        assert!(h.starts_with(b"fabkit 0.1.0 rtac0 core_holder sha256:abababababababab mm"));
        assert!(!h.starts_with(b"solid"));
        let long = header(&"é".repeat(60), "d", "p", &"0".repeat(64));
        assert!(long.iter().all(|b| b.is_ascii()));
    }

    /// The unit word survives a long part name: the part name is cut, not `mm`.
    #[test]
    fn long_part_name_is_shortened_and_the_unit_kept() {
        let part = "semidome_pattern_with_a_very_long_name_that_does_not_fit_in_eighty_bytes";
        let h = header("0.1.0", "rtac0", part, &"ab".repeat(32));
        let text = std::str::from_utf8(&h).unwrap().trim_end();
        assert_eq!(text.len(), 80);
        assert!(text.starts_with("fabkit 0.1.0 rtac0 semidome_pattern_with"));
        assert!(text.ends_with("~ sha256:abababababababab mm"), "{text}");
        // A fitting name is kept whole.
        let h = header("0.1.0", "rtac0", "core_holder", &"ab".repeat(32));
        assert!(std::str::from_utf8(&h)
            .unwrap()
            .trim_end()
            .ends_with("core_holder sha256:abababababababab mm"));
        // Even when the version and design alone overflow, the unit stays last.
        let h = header(&"9".repeat(70), "d", "p", &"0".repeat(64));
        assert!(std::str::from_utf8(&h).unwrap().ends_with(" mm"));
        let h = header(&"é".repeat(60), "d", "p", &"0".repeat(64));
        assert!(h.ends_with(b" mm") && h.iter().all(|b| b.is_ascii()));
    }

    #[test]
    fn tetrahedron_bytes() {
        let m = Mesh {
            vertices: vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
            triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        };
        let bytes = encode("t", &m, &[b' '; 80]).unwrap();
        assert_eq!(bytes.len(), 84 + 4 * 50);
        assert_eq!(&bytes[80..84], &4u32.to_le_bytes());
        // first facet is the bottom face: normal -z
        let nz = f32::from_le_bytes([bytes[92], bytes[93], bytes[94], bytes[95]]);
        assert_eq!(nz, -1.0);
    }
}
