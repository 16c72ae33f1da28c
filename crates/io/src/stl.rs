//! STL solids: binary writing (for printable pieces) and binary/ASCII reading.
//!
//! A binary STL is an 80-byte header, a little-endian `u32` triangle count, then 50 bytes per
//! triangle (facet normal, three vertices, a 2-byte attribute). Writing is a few lines, so it
//! is our own; ASCII reading uses `stl_io`. STL stores every triangle with its own corners, so
//! [`read`] welds corners with bit-identical coordinates (`-0.0` = `0.0`) back into shared
//! vertices: a closed solid written by [`write_binary`] reads back as a closed manifold.

use std::collections::HashMap;
use std::io::Cursor;

use anim::Mesh;
use glam::Vec3;

use crate::{IoError, Result};

const FORMAT: &str = "STL";
/// Size of the binary header plus triangle count.
pub const BINARY_HEADER_LEN: usize = 84;
/// Bytes per triangle in a binary STL.
pub const BINARY_TRIANGLE_LEN: usize = 50;
/// The header text of written files (padded with spaces). It must not start with `solid`,
/// which readers take as the mark of an ASCII file.
pub const HEADER_TEXT: &[u8] = b"binary STL written by toonkit";

/// Writes a binary STL with unit facet normals (zero for degenerate triangles).
///
/// # Returns
/// `84 + 50 × triangles` bytes. Meshes of more than `u32::MAX` triangles are not supported by
/// the format; only the first `u32::MAX` would be counted.
pub fn write_binary(mesh: &Mesh) -> Vec<u8> {
    let count = u32::try_from(mesh.triangles.len()).unwrap_or(u32::MAX);
    let mut out = Vec::with_capacity(BINARY_HEADER_LEN + BINARY_TRIANGLE_LEN * count as usize);
    let mut header = [b' '; 80];
    header[..HEADER_TEXT.len()].copy_from_slice(HEADER_TEXT);
    out.extend_from_slice(&header);
    out.extend_from_slice(&count.to_le_bytes());
    let p = |i: u32| {
        mesh.positions
            .get(i as usize)
            .copied()
            .unwrap_or(Vec3::ZERO)
    };
    for t in mesh.triangles.iter().take(count as usize) {
        let [a, b, c] = t.map(p);
        let n = (b - a).cross(c - a).try_normalize().unwrap_or(Vec3::ZERO);
        for v in [n, a, b, c] {
            for x in v.to_array() {
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
        out.extend_from_slice(&[0, 0]);
    }
    out
}

/// Reads a binary or ASCII STL and welds identical corners.
///
/// A file whose length is exactly `84 + 50 × count` is binary (even if its header starts with
/// `solid`, as many exporters write); otherwise a file starting with `solid` is ASCII.
/// Stored facet normals are ignored (they are recomputed from the winding when needed).
///
/// # Errors
/// [`IoError::Malformed`] for a length that fits neither form, an ASCII syntax error, or a NaN
/// or infinite coordinate.
pub fn read(bytes: &[u8]) -> Result<Mesh> {
    let corners = if is_binary(bytes) {
        read_binary_corners(bytes)
    } else if bytes.trim_ascii_start().starts_with(b"solid") {
        read_ascii_corners(bytes)?
    } else if bytes.len() >= BINARY_HEADER_LEN {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        return Err(IoError::malformed(
            FORMAT,
            format!(
                "binary STL of {n} triangles needs {} bytes, the file has {}",
                BINARY_HEADER_LEN as u64 + BINARY_TRIANGLE_LEN as u64 * n,
                bytes.len()
            ),
        ));
    } else {
        return Err(IoError::malformed(
            FORMAT,
            "file is too short and does not start with 'solid'",
        ));
    };
    if !corners.iter().all(|c| c.is_finite()) {
        return Err(IoError::malformed(
            FORMAT,
            "a vertex coordinate is NaN or infinite",
        ));
    }
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::with_capacity(corners.len() / 3);
    for tri in corners.chunks_exact(3) {
        let mut t = [0u32; 3];
        for (k, &c) in tri.iter().enumerate() {
            // + 0.0 turns -0.0 into 0.0 so both weld.
            let key = (c + Vec3::ZERO).to_array().map(f32::to_bits);
            t[k] = *index.entry(key).or_insert_with(|| {
                positions.push(c);
                (positions.len() - 1) as u32
            });
        }
        triangles.push(t);
    }
    if positions.len() > u32::MAX as usize {
        return Err(IoError::unsupported(
            "STL has more than 2^32 distinct vertices",
        ));
    }
    Ok(Mesh::new("", positions, triangles))
}

fn is_binary(bytes: &[u8]) -> bool {
    if bytes.len() < BINARY_HEADER_LEN {
        return false;
    }
    let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
    BINARY_HEADER_LEN as u64 + BINARY_TRIANGLE_LEN as u64 * n == bytes.len() as u64
}

fn read_binary_corners(bytes: &[u8]) -> Vec<Vec3> {
    bytes[BINARY_HEADER_LEN..]
        .chunks_exact(BINARY_TRIANGLE_LEN)
        .flat_map(|t| {
            let f = |o: usize| f32::from_le_bytes([t[o], t[o + 1], t[o + 2], t[o + 3]]);
            [12, 24, 36].map(|o| Vec3::new(f(o), f(o + 4), f(o + 8)))
        })
        .collect()
}

fn read_ascii_corners(bytes: &[u8]) -> Result<Vec<Vec3>> {
    let mut cursor = Cursor::new(bytes);
    let reader = stl_io::create_stl_reader(&mut cursor)
        .map_err(|e| IoError::malformed(FORMAT, format!("ASCII STL: {e}")))?;
    let mut corners = Vec::new();
    for t in reader {
        let t = t.map_err(|e| IoError::malformed(FORMAT, format!("ASCII STL: {e}")))?;
        corners.extend(t.vertices.iter().map(|v| Vec3::from_array(v.0)));
    }
    Ok(corners)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed tetrahedron (outward-facing, counter-clockwise).
    pub(crate) fn tetra() -> Mesh {
        Mesh::new(
            "tet",
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        )
    }

    #[test]
    fn binary_round_trip_welds_into_closed_solid() {
        let bytes = write_binary(&tetra());
        assert_eq!(bytes.len(), 84 + 50 * 4);
        assert!(!bytes.starts_with(b"solid"));
        let m = read(&bytes).unwrap();
        assert_eq!(m.vertex_count(), 4);
        assert_eq!(m.triangle_count(), 4);
        // Closed manifold: every undirected edge is used by exactly two triangles.
        let mut edges = HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        assert_eq!(edges.len(), 6);
        assert!(edges.values().all(|&c| c == 2));
        // Facet normal of the last face points away from the origin.
        let n = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
        let base = 84 + 3 * 50;
        assert!((n(base) - 1.0 / 3f32.sqrt()).abs() < 1e-6);
    }

    #[test]
    fn ascii_and_solid_headed_binary_are_read() {
        let ascii = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
            vertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
        let m = read(ascii).unwrap();
        assert_eq!((m.vertex_count(), m.triangle_count()), (3, 1));
        let mut bin = write_binary(&tetra());
        bin[..6].copy_from_slice(b"solid ");
        assert_eq!(read(&bin).unwrap().triangle_count(), 4);
    }

    #[test]
    fn corrupt_inputs_are_errors() {
        let bytes = write_binary(&tetra());
        assert!(read(&bytes[..bytes.len() - 1])
            .unwrap_err()
            .to_string()
            .contains("needs"));
        assert!(read(&bytes[..40]).is_err());
        let mut nan = bytes.clone();
        nan[84 + 12..84 + 16].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(read(&nan).unwrap_err().to_string().contains("NaN"));
        let mut huge = bytes;
        huge[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(read(&huge).is_err());
        assert!(read(b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n").is_err());
    }
}
