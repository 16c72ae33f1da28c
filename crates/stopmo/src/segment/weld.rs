//! Welding of coincident vertices (glTF duplicates vertices along UV seams).

use std::collections::HashMap;

use glam::Vec3;

/// Default welding tolerance, relative to the bounding-box diagonal of the average mesh.
pub const DEFAULT_WELD_EPSILON: f32 = 1e-6;

/// A map from the original vertices to classes of coincident vertices.
///
/// Connectivity, geodesics and Laplacians are computed on the welded mesh; results are mapped
/// back to the original vertex order with [`Weld::class`].
#[derive(Debug, Clone, PartialEq)]
pub struct Weld {
    /// Welded class of every original vertex.
    pub class: Vec<u32>,
    /// The first original vertex of every class.
    pub representative: Vec<u32>,
}

impl Weld {
    /// Welds vertices closer than `epsilon` (absolute units) to an earlier vertex.
    ///
    /// Deterministic: classes are numbered in the order of their first vertex, and a vertex
    /// joins the class of the lowest-numbered earlier vertex within `epsilon`. With
    /// `epsilon = 0` only bit-identical positions are welded.
    ///
    /// # Performance
    /// O(m) expected with a hash grid of cell size `epsilon`.
    pub fn new(positions: &[Vec3], epsilon: f32) -> Weld {
        let mut class = Vec::with_capacity(positions.len());
        let mut representative: Vec<u32> = Vec::new();
        if epsilon > 0.0 && epsilon.is_finite() {
            let inv = 1.0 / epsilon as f64;
            let cell = |p: Vec3| {
                let q = p.as_dvec3() * inv;
                [q.x.floor() as i64, q.y.floor() as i64, q.z.floor() as i64]
            };
            let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
            let eps2 = epsilon * epsilon;
            for &p in positions {
                let c = cell(p);
                let mut best: Option<u32> = None;
                for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            let Some(list) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                                continue;
                            };
                            for &k in list {
                                let q = positions[representative[k as usize] as usize];
                                if q.distance_squared(p) <= eps2 && best.is_none_or(|b| k < b) {
                                    best = Some(k);
                                }
                            }
                        }
                    }
                }
                let k = best.unwrap_or_else(|| {
                    let k = representative.len() as u32;
                    representative.push(class.len() as u32);
                    grid.entry(c).or_default().push(k);
                    k
                });
                class.push(k);
            }
        } else {
            let mut map: HashMap<[u32; 3], u32> = HashMap::new();
            for &p in positions {
                let key = p.to_array().map(f32::to_bits);
                let k = *map.entry(key).or_insert_with(|| {
                    representative.push(class.len() as u32);
                    representative.len() as u32 - 1
                });
                class.push(k);
            }
        }
        Weld {
            class,
            representative,
        }
    }

    /// The identity weld (no two vertices merged).
    pub fn identity(vertices: usize) -> Weld {
        let ids: Vec<u32> = (0..vertices as u32).collect();
        Weld {
            class: ids.clone(),
            representative: ids,
        }
    }

    /// Number of welded vertices.
    pub fn len(&self) -> usize {
        self.representative.len()
    }

    /// True when there is no vertex.
    pub fn is_empty(&self) -> bool {
        self.representative.is_empty()
    }

    /// Triangles re-indexed to welded vertices.
    pub fn triangles(&self, triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
        triangles
            .iter()
            .map(|t| t.map(|i| self.class[i as usize]))
            .collect()
    }

    /// Positions of the class representatives.
    pub fn gather(&self, positions: &[Vec3]) -> Vec<Vec3> {
        self.representative
            .iter()
            .map(|&r| positions[r as usize])
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uv_seam_duplicates_are_welded() {
        let p = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::X + Vec3::splat(1e-9),
            Vec3::Y,
            Vec3::ZERO,
        ];
        let w = Weld::new(&p, 1e-6);
        assert_eq!(w.class, vec![0, 1, 1, 2, 0]);
        assert_eq!(w.representative, vec![0, 1, 3]);
        let exact = Weld::new(&p, 0.0);
        assert_eq!(exact.class, vec![0, 1, 2, 3, 0]);
    }
}
