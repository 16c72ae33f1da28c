//! Static triangle meshes.

use std::collections::BTreeMap;

use glam::Vec3;

use crate::{AnimError, Result};

/// An axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Minimum corner.
    pub min: Vec3,
    /// Maximum corner.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box (min = +inf, max = -inf); growing it by a point gives that point.
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::INFINITY,
        max: Vec3::NEG_INFINITY,
    };

    /// Box of a set of points; [`Aabb::EMPTY`] when there are none. Non-finite points are ignored.
    pub fn from_points(points: &[Vec3]) -> Aabb {
        let mut b = Aabb::EMPTY;
        for &p in points {
            b.grow(p);
        }
        b
    }

    /// Extends the box to contain `p` (ignored if not finite).
    #[inline]
    pub fn grow(&mut self, p: Vec3) {
        if p.is_finite() {
            self.min = self.min.min(p);
            self.max = self.max.max(p);
        }
    }

    /// Union of two boxes.
    pub fn union(self, other: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// True when the box holds no point.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }

    /// Length of the diagonal; 0 for an empty box.
    pub fn diagonal(&self) -> f32 {
        if self.is_empty() {
            0.0
        } else {
            (self.max - self.min).length()
        }
    }

    /// Centre of the box.
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }
}

/// A triangle mesh: positions, triangles and optional per-vertex attributes.
///
/// Polygons are triangulated on import; where the source format has polygons (OBJ) their
/// structure is kept in [`Mesh::polygons`] so that writers can reproduce it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Object name.
    pub name: String,
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles, counter-clockwise when seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// Original polygons (vertex indices) when the source had faces of more than 3 sides.
    pub polygons: Option<Vec<Vec<u32>>>,
    /// Per-vertex normals.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates in glTF's convention: `u` right and `v` down from the
    /// image's top-left corner (readers of other conventions convert, e.g. OBJ's `v ← 1 − v`).
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Further texture-coordinate sets after [`Mesh::uvs`], in the same convention:
    /// `extra_uvs[k]` is glTF's `TEXCOORD_{k+1}` (a lightmap or detail layout), one per vertex.
    pub extra_uvs: Vec<Vec<[f32; 2]>>,
    /// Per-vertex RGBA colours in linear space.
    pub colors: Option<Vec<[f32; 4]>>,
    /// Scalar per-vertex attributes by name (glTF application-specific attributes such as
    /// `_SMEAR_WEIGHT`, painted weights), one value per vertex each.
    pub attributes: BTreeMap<String, Vec<f32>>,
}

impl Mesh {
    /// A mesh from positions and triangles, with no other attributes.
    pub fn new(name: impl Into<String>, positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Mesh {
        Mesh {
            name: name.into(),
            positions,
            triangles,
            ..Mesh::default()
        }
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Checks indices and attribute lengths, and that positions are finite.
    pub fn validate(&self) -> Result<()> {
        let n = self.positions.len();
        for (t, tri) in self.triangles.iter().enumerate() {
            for &i in tri {
                if i as usize >= n {
                    return Err(AnimError::IndexOutOfRange {
                        triangle: t,
                        index: i,
                        vertices: n,
                    });
                }
            }
        }
        let check = |what: &str, len: Option<usize>| match len {
            Some(l) if l != n => Err(AnimError::LengthMismatch {
                what: format!("mesh '{}' {what}", self.name),
                expected: n,
                found: l,
            }),
            _ => Ok(()),
        };
        check("normals", self.normals.as_ref().map(Vec::len))?;
        check("uvs", self.uvs.as_ref().map(Vec::len))?;
        for (k, set) in self.extra_uvs.iter().enumerate() {
            check(&format!("uv set {}", k + 1), Some(set.len()))?;
        }
        check("colors", self.colors.as_ref().map(Vec::len))?;
        for (name, values) in &self.attributes {
            check(&format!("attribute {name}"), Some(values.len()))?;
        }
        if !self.positions.iter().all(|p| p.is_finite()) {
            return Err(AnimError::NonFinite {
                what: format!("mesh '{}' positions", self.name),
            });
        }
        Ok(())
    }

    /// Bounding box of the positions.
    pub fn bbox(&self) -> Aabb {
        Aabb::from_points(&self.positions)
    }

    /// Area-weighted vertex normals of the given positions (same topology).
    ///
    /// Vertices on no triangle, or on degenerate ones only, get +Y.
    pub fn vertex_normals(&self, positions: &[Vec3]) -> Vec<Vec3> {
        vertex_normals(positions, &self.triangles)
    }

    /// Appends another mesh (vertex indices shifted); attributes present on only one side are
    /// filled with defaults so that every attribute keeps one value per vertex.
    pub fn append(&mut self, other: &Mesh) {
        let base = self.positions.len() as u32;
        let (n_self, n_other) = (self.positions.len(), other.positions.len());
        fn merge<T: Clone>(a: &mut Option<Vec<T>>, b: &Option<Vec<T>>, na: usize, nb: usize, d: T) {
            match (a.as_mut(), b) {
                (None, None) => {}
                (Some(a), Some(b)) => a.extend_from_slice(b),
                (Some(a), None) => a.extend(std::iter::repeat_n(d, nb)),
                (None, Some(b)) => {
                    let mut v = vec![d; na];
                    v.extend_from_slice(b);
                    *a = Some(v);
                }
            }
        }
        merge(&mut self.normals, &other.normals, n_self, n_other, Vec3::Y);
        merge(&mut self.uvs, &other.uvs, n_self, n_other, [0.0, 0.0]);
        // A set missing on one side reads (0, 0) there, as a missing `uvs` does.
        let sets = self.extra_uvs.len().max(other.extra_uvs.len());
        self.extra_uvs.resize(sets, vec![[0.0, 0.0]; n_self]);
        for (k, set) in self.extra_uvs.iter_mut().enumerate() {
            match other.extra_uvs.get(k) {
                Some(b) => set.extend_from_slice(b),
                None => set.extend(std::iter::repeat_n([0.0, 0.0], n_other)),
            }
        }
        merge(&mut self.colors, &other.colors, n_self, n_other, [1.0; 4]);
        // An attribute missing on one side reads 0 there (nothing painted).
        let names: Vec<String> = other
            .attributes
            .keys()
            .filter(|k| !self.attributes.contains_key(*k))
            .cloned()
            .collect();
        for name in names {
            self.attributes.insert(name, vec![0.0; n_self]);
        }
        for (name, values) in &mut self.attributes {
            match other.attributes.get(name) {
                Some(b) => values.extend_from_slice(b),
                None => values.extend(std::iter::repeat_n(0.0, n_other)),
            }
        }
        let self_polys = self.polygons.take();
        if self_polys.is_some() || other.polygons.is_some() {
            let mut polys = self_polys.unwrap_or_else(|| tri_polys(&self.triangles, 0));
            match &other.polygons {
                Some(p) => polys.extend(p.iter().map(|f| f.iter().map(|i| i + base).collect())),
                None => polys.extend(tri_polys(&other.triangles, base)),
            }
            self.polygons = Some(polys);
        }
        self.positions.extend_from_slice(&other.positions);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
    }
}

fn tri_polys(tris: &[[u32; 3]], base: u32) -> Vec<Vec<u32>> {
    tris.iter()
        .map(|t| t.iter().map(|i| i + base).collect())
        .collect()
}

/// Area-weighted vertex normals of `positions` over `triangles` (indices must be valid).
/// Vertices on no triangle, or only on degenerate or non-finite ones, get +Y.
pub fn vertex_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    area_normals(positions, triangles)
        .into_iter()
        .map(|n| n.try_normalize().unwrap_or(Vec3::Y))
        .collect()
}

/// Unnormalized [`vertex_normals`]: per vertex, the sum of its triangles' normals scaled by
/// twice their area (zero on no triangle; degenerate or non-finite triangles add nothing),
/// for weighting normals by area over several vertices.
pub fn area_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut acc = vec![Vec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| i as usize);
        let n = (positions[b] - positions[a]).cross(positions[c] - positions[a]);
        if n.is_finite() {
            acc[a] += n;
            acc[b] += n;
            acc[c] += n;
        }
    }
    acc
}

/// Fan-triangulates a polygon (indices into the vertex array). Polygons with fewer than
/// three vertices give no triangle.
pub fn triangulate_polygon(polygon: &[u32], out: &mut Vec<[u32; 3]>) {
    for k in 1..polygon.len().saturating_sub(1) {
        out.push([polygon[0], polygon[k], polygon[k + 1]]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn append_keeps_attributes_per_vertex() {
        let mut a = Mesh::new("a", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
        let mut b = a.clone();
        b.colors = Some(vec![[1.0, 0.0, 0.0, 1.0]; 3]);
        a.append(&b);
        assert_eq!(a.vertex_count(), 6);
        assert_eq!(a.triangles[1], [3, 4, 5]);
        assert_eq!(a.colors.as_ref().unwrap().len(), 6);
        a.validate().unwrap();
    }

    #[test]
    fn append_keeps_every_uv_set_per_vertex() {
        let mut a = Mesh::new("a", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
        let mut b = a.clone();
        b.extra_uvs = vec![vec![[0.5, 0.25]; 3], vec![[1.0, 1.0]; 3]];
        a.append(&b);
        assert_eq!(a.extra_uvs.len(), 2);
        assert_eq!(a.extra_uvs[0][..3], [[0.0, 0.0]; 3]);
        assert_eq!(a.extra_uvs[0][3..], [[0.5, 0.25]; 3]);
        assert_eq!(a.extra_uvs[1][5], [1.0, 1.0]);
        a.validate().unwrap();
        a.extra_uvs[1].pop();
        assert!(matches!(
            a.validate(),
            Err(AnimError::LengthMismatch { .. })
        ));
    }

    #[test]
    fn bad_index_is_an_error() {
        let m = Mesh::new("m", vec![Vec3::ZERO], vec![[0, 1, 2]]);
        assert!(matches!(
            m.validate(),
            Err(AnimError::IndexOutOfRange { .. })
        ));
    }

    #[test]
    fn quad_fan() {
        let mut t = Vec::new();
        triangulate_polygon(&[0, 1, 2, 3], &mut t);
        assert_eq!(t, vec![[0, 1, 2], [0, 2, 3]]);
    }
}
