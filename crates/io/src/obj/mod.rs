//! Wavefront OBJ meshes and OBJ sequences (one file per frame).
//!
//! # Vertex order
//! [`read`] keeps the `v` lines exactly in file order, including vertices no face uses, so
//! that a point cache (PC2/MDD) or a `.npy` field exported for the same file lines up vertex
//! by vertex. This is why the reader is our own: `tobj` 4 (even with `single_index: false`)
//! renumbers positions in order of first use by a face, drops unused ones and splits the file
//! per `o`/`g` group.
//!
//! # What is kept
//! * `v x y z [w]` positions (`w` is ignored), `v x y z r g b` colours (kept only when every
//!   vertex has one).
//! * `f` faces with absolute or negative (relative) indices in all four corner forms. Faces are
//!   fan-triangulated into [`Mesh::triangles`]; when any face has more than three corners, all
//!   faces are also kept as [`Mesh::polygons`]. Faces with fewer than three corners, `l` lines
//!   and `p` points are skipped.
//! * `vt`/`vn` only when they are *per position*: every face corner of a position uses the same
//!   texture coordinate (normal) value. Files with UV seams or split normals (several values
//!   per position) get `uvs: None` (`normals: None`); toonkit never needs them and splitting
//!   vertices would break the vertex order.
//! * The first `o` name (else the first `g` name) as [`Mesh::name`]; empty when there is none.
//!
//! Texture coordinates are converted to toonkit's convention (glTF's: `v` down from the top of
//! the image) on reading, `v ← 1 − v`, and back on writing, so a textured glTF converted to OBJ
//! (or OBJ to glTF) keeps its texture the right way up. Read → write → read is exact.
//!
//! Materials, smoothing groups, curves and free-form surfaces are ignored.
//!
//! Several files at once (OBJ sequences, a folder of pieces) are in `files.rs`.

use std::fmt::Write as _;

use anim::{triangulate_polygon, Mesh};
use glam::Vec3;

use crate::{IoError, Result};

mod files;

pub use files::{read_folder, read_sequence, sequence_paths, write_sequence};

const FORMAT: &str = "OBJ";

/// The statements of OBJ geometry files (Wavefront's specification, Appendix B1).
const OBJ_KEYWORDS: &[&str] = &[
    "v",
    "vt",
    "vn",
    "vp",
    "f",
    "l",
    "p",
    "o",
    "g",
    "s",
    "mg",
    "usemtl",
    "mtllib",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "bevel",
    "c_interp",
    "d_interp",
    "lod",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "call",
    "csh",
    "maplib",
    "usemap",
];

/// Parses an OBJ file.
///
/// # Errors
/// [`IoError::Malformed`] naming the line of a non-number, a missing coordinate, a NaN or
/// infinite value, an index of 0 or out of range, a face of fewer than 3 vertices, more
/// than `u32::MAX` vertices, or bytes with no OBJ statement at all.
pub fn read(bytes: &[u8]) -> Result<Mesh> {
    let text = String::from_utf8_lossy(bytes);
    let mut positions: Vec<Vec3> = Vec::new();
    let mut colors: Vec<[f32; 4]> = Vec::new();
    let mut uvs: Vec<[f32; 2]> = Vec::new();
    let mut normals: Vec<Vec3> = Vec::new();
    // Face corners, flat: (position, uv, normal); uv/normal u32::MAX = absent.
    let mut corners: Vec<[u32; 3]> = Vec::new();
    let mut faces: Vec<(usize, usize)> = Vec::new(); // (first corner, line)
    let mut object_name: Option<String> = None;
    let mut group_name: Option<String> = None;
    // Lines with an OBJ keyword and lines with none: bytes that are not OBJ at all (random
    // or binary data named .obj) are refused instead of read as an empty mesh.
    let (mut known, mut unknown) = (0usize, 0usize);

    for (ln, raw) in text.split('\n').enumerate() {
        let line_no = ln + 1;
        let line = raw.split('#').next().unwrap_or("").trim();
        let mut words = line.split_ascii_whitespace();
        let Some(key) = words.next() else { continue };
        let bad = |msg: String| IoError::malformed(FORMAT, format!("line {line_no}: {msg}"));
        let nums = |words: std::str::SplitAsciiWhitespace<'_>, what: &str| -> Result<Vec<f32>> {
            words
                .map(|w| match w.parse::<f32>() {
                    Ok(v) if v.is_finite() => Ok(v),
                    Ok(_) => Err(bad(format!("{what} value '{w}' is NaN or infinite"))),
                    Err(_) => Err(bad(format!("{what} value '{w}' is not a number"))),
                })
                .collect()
        };
        match key {
            "v" => {
                let v = nums(words, "vertex")?;
                if v.len() < 3 {
                    return Err(bad(format!(
                        "vertex has {} coordinates, expected 3",
                        v.len()
                    )));
                }
                positions.push(Vec3::new(v[0], v[1], v[2]));
                if v.len() >= 6 {
                    colors.push([v[3], v[4], v[5], 1.0]);
                }
            }
            "vt" => {
                let v = nums(words, "texture coordinate")?;
                if v.is_empty() {
                    return Err(bad("texture coordinate has no value".into()));
                }
                // OBJ's v runs up from the image's bottom; toonkit's (glTF's) down from its top.
                uvs.push([v[0], 1.0 - v.get(1).copied().unwrap_or(0.0)]);
            }
            "vn" => {
                let v = nums(words, "normal")?;
                if v.len() < 3 {
                    return Err(bad(format!(
                        "normal has {} coordinates, expected 3",
                        v.len()
                    )));
                }
                normals.push(Vec3::new(v[0], v[1], v[2]));
            }
            "f" => {
                let start = corners.len();
                for w in words {
                    let mut c = [u32::MAX; 3];
                    let counts = [positions.len(), uvs.len(), normals.len()];
                    for (k, part) in w.split('/').enumerate() {
                        if k > 2 {
                            return Err(bad(format!("face corner '{w}' has more than 3 indices")));
                        }
                        if part.is_empty() {
                            if k == 0 {
                                return Err(bad(format!("face corner '{w}' has no vertex index")));
                            }
                            continue;
                        }
                        c[k] = resolve_index(part, counts[k]).ok_or_else(|| {
                            bad(format!("bad index '{part}' in face corner '{w}'"))
                        })?;
                    }
                    corners.push(c);
                }
                let found = corners.len() - start;
                if found < 3 {
                    return Err(bad(format!(
                        "a face needs at least 3 vertices, this one has {found} \
                         (an edge is written as an 'l' line; remove the face or re-export)"
                    )));
                }
                faces.push((start, line_no));
            }
            "o" if object_name.is_none() => object_name = Some(rest_of(line)),
            "g" if group_name.is_none() => group_name = Some(rest_of(line)),
            key if OBJ_KEYWORDS.contains(&key) => {}
            _ => unknown += 1,
        }
        known += usize::from(OBJ_KEYWORDS.contains(&key));
    }
    if positions.is_empty() && known == 0 && unknown > 0 {
        return Err(IoError::malformed(
            FORMAT,
            "no line starts with an OBJ keyword (v, vt, vn, f, o, g, …): not an OBJ file",
        ));
    }
    if positions.len() > u32::MAX as usize {
        return Err(IoError::unsupported("OBJ has more than 2^32 vertices"));
    }

    // Validate indices (absolute indices may refer forward) and build faces.
    let counts = [positions.len(), uvs.len(), normals.len()];
    let names = ["vertex", "texture coordinate", "normal"];
    let mut triangles = Vec::new();
    let mut polygons = Vec::with_capacity(faces.len());
    for (f, &(start, line_no)) in faces.iter().enumerate() {
        let end = faces.get(f + 1).map_or(corners.len(), |n| n.0);
        for c in &corners[start..end] {
            for k in 0..3 {
                if c[k] != u32::MAX && c[k] as usize >= counts[k] {
                    return Err(IoError::malformed(
                        FORMAT,
                        format!(
                            "line {line_no}: face refers to {} {} but the file has {}",
                            names[k],
                            c[k] as u64 + 1,
                            counts[k]
                        ),
                    ));
                }
            }
        }
        let poly: Vec<u32> = corners[start..end].iter().map(|c| c[0]).collect();
        triangulate_polygon(&poly, &mut triangles);
        polygons.push(poly);
    }
    let has_ngons = polygons.iter().any(|p| p.len() > 3);

    let n = positions.len();
    let per_position_uvs = per_position(&corners, 1, n, &uvs, [0.0; 2]);
    let per_position_normals = per_position(&corners, 2, n, &normals, Vec3::Y);
    let mesh = Mesh {
        name: object_name.or(group_name).unwrap_or_default(),
        positions,
        triangles,
        polygons: has_ngons.then_some(polygons),
        normals: per_position_normals,
        uvs: per_position_uvs,
        colors: (colors.len() == n && n > 0).then_some(colors),
        extra_uvs: Vec::new(),
        attributes: Default::default(),
    };
    mesh.validate()?;
    Ok(mesh)
}

fn rest_of(line: &str) -> String {
    line.split_once(char::is_whitespace)
        .map(|(_, r)| r.trim().to_string())
        .unwrap_or_default()
}

/// 0-based index of an OBJ index (1-based, or negative = relative to `count`).
fn resolve_index(text: &str, count: usize) -> Option<u32> {
    let i: i64 = text.parse().ok()?;
    let i = match i {
        0 => return None,
        i if i > 0 => i - 1,
        i => i64::try_from(count)
            .ok()?
            .checked_add(i)
            .filter(|&r| r >= 0)?,
    };
    u32::try_from(i).ok().filter(|&i| i != u32::MAX)
}

/// Per-position attribute values when every corner of every position agrees on one value;
/// positions on no face get `default`.
fn per_position<T: Copy + PartialEq>(
    corners: &[[u32; 3]],
    slot: usize,
    n: usize,
    values: &[T],
    default: T,
) -> Option<Vec<T>> {
    if values.is_empty() || corners.is_empty() {
        return None;
    }
    let mut out: Vec<Option<T>> = vec![None; n];
    for c in corners {
        let idx = c[slot];
        if idx == u32::MAX {
            return None;
        }
        let v = values[idx as usize];
        match &mut out[c[0] as usize] {
            Some(old) if *old != v => return None,
            slot @ None => *slot = Some(v),
            _ => {}
        }
    }
    Some(out.into_iter().map(|v| v.unwrap_or(default)).collect())
}

/// Writes a mesh as OBJ text.
///
/// Writes `o` (when the mesh has a name), one `v` per vertex in order (with `r g b` when the
/// mesh has colours), `vt`/`vn` per vertex when present (sharing the vertex's index), and one
/// `f` per polygon when [`Mesh::polygons`] is set, else per triangle. Numbers are written in
/// the shortest form that reads back to the same `f32`, so `read(write(m))` is exact.
pub fn write(mesh: &Mesh) -> String {
    let mut out = String::with_capacity(mesh.positions.len() * 40 + mesh.triangles.len() * 24);
    out.push_str("# written by toonkit\n");
    if !mesh.name.is_empty() {
        // A line break or '#' would end the name early when read back.
        let _ = writeln!(out, "o {}", mesh.name.replace(['\n', '#'], "_"));
    }
    let colors = mesh
        .colors
        .as_ref()
        .filter(|c| c.len() == mesh.positions.len());
    for (i, p) in mesh.positions.iter().enumerate() {
        let _ = write!(out, "v {} {} {}", p.x, p.y, p.z);
        if let Some(c) = colors {
            let _ = write!(out, " {} {} {}", c[i][0], c[i][1], c[i][2]);
        }
        out.push('\n');
    }
    let uvs = mesh
        .uvs
        .as_ref()
        .filter(|u| u.len() == mesh.positions.len());
    let normals = mesh
        .normals
        .as_ref()
        .filter(|n| n.len() == mesh.positions.len());
    for uv in uvs.into_iter().flatten() {
        let _ = writeln!(out, "vt {} {}", uv[0], 1.0 - uv[1]);
    }
    for n in normals.into_iter().flatten() {
        let _ = writeln!(out, "vn {} {} {}", n.x, n.y, n.z);
    }
    let mut face = |poly: &[u32]| {
        out.push('f');
        for &i in poly {
            let k = i as u64 + 1;
            let _ = match (uvs.is_some(), normals.is_some()) {
                (false, false) => write!(out, " {k}"),
                (true, false) => write!(out, " {k}/{k}"),
                (false, true) => write!(out, " {k}//{k}"),
                (true, true) => write!(out, " {k}/{k}/{k}"),
            };
        }
        out.push('\n');
    };
    match &mesh.polygons {
        Some(polys) => polys.iter().for_each(|p| face(p)),
        None => mesh.triangles.iter().for_each(|t| face(t)),
    }
    out
}

/// Writes several meshes as one OBJ file, one `o` object per mesh (named after it), vertex
/// indices running on across objects: what one frame of a flipbook (a body with its copies or
/// motion lines) shows. Each mesh is written as [`write`] writes it alone.
pub fn write_objects(meshes: &[Mesh]) -> String {
    let mut out = String::from("# written by toonkit\n");
    // Rows written so far of `v`, `vt` and `vn`: a later object's faces refer past them.
    let mut written = [0u64; 3];
    for mesh in meshes {
        let mut named = mesh.clone();
        if named.name.is_empty() {
            named.name = "mesh".into();
        }
        let text = write(&named);
        let mut rows = [0u64; 3];
        for line in text.lines().skip(1) {
            let key = line.split(' ').next().unwrap_or("");
            if let Some(slot) = ["v", "vt", "vn"].iter().position(|k| *k == key) {
                rows[slot] += 1;
            }
            match line.strip_prefix("f ") {
                Some(corners) if written != [0; 3] => {
                    out.push('f');
                    for corner in corners.split(' ') {
                        out.push(' ');
                        for (slot, index) in corner.split('/').enumerate() {
                            if slot > 0 {
                                out.push('/');
                            }
                            if let Ok(k) = index.parse::<u64>() {
                                let _ = write!(out, "{}", k + written[slot]);
                            }
                        }
                    }
                }
                _ => out.push_str(line),
            }
            out.push('\n');
        }
        for (w, r) in written.iter_mut().zip(rows) {
            *w += r;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const QUAD_AND_TRI: &str = "# test\no thing\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
        v 2 2 2\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\nf -4/-3 -2/-1 -1/-1\n";

    #[test]
    fn keeps_file_order_polygons_and_unused_vertices() {
        let m = read(QUAD_AND_TRI.as_bytes()).unwrap();
        assert_eq!(m.name, "thing");
        assert_eq!(m.vertex_count(), 5);
        assert_eq!(m.positions[4], Vec3::splat(2.0));
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [1, 3, 4]]);
        assert_eq!(m.polygons.as_ref().unwrap()[0], vec![0, 1, 2, 3]);
        // Relative corners reuse each vertex's own vt, so UVs are per position.
        // (OBJ v = 1 is the top of the image: glTF v = 0.)
        assert_eq!(m.uvs.as_ref().unwrap()[3], [0.0, 0.0]);
        assert_eq!(m.uvs.as_ref().unwrap()[4], [0.0, 0.0]);
        let again = read(write(&m).as_bytes()).unwrap();
        assert_eq!(again, m);
    }

    #[test]
    fn uv_seams_drop_uvs() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 0.5 0.5\n\
            f 1/1 2/2 3/3\nf 1/4 3/3 2/2\n";
        let m = read(text.as_bytes()).unwrap();
        assert!(m.uvs.is_none());
        assert_eq!(m.triangles.len(), 2);
    }

    #[test]
    fn bad_inputs_name_the_line() {
        let cases = [
            ("v 0 0\n", "line 1"),
            ("v 0 0 0\nv 0 nan 0\n", "line 2"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "line 4"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "line 4"),
            ("v 0 0 0\nf -2 1 1\n", "line 2"),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/9 2 3\n",
                "texture coordinate 9",
            ),
            ("v x 0 0\n", "not a number"),
        ];
        for (text, needle) in cases {
            let e = read(text.as_bytes()).unwrap_err().to_string();
            assert!(e.contains(needle), "{text:?}: {e}");
        }
    }
}
