//! Points on an object's surface (SMEAR Section 4.3: motion lines start at them).

use crate::{Result, SmearError};

/// A point on an object's surface: a triangle and barycentric coordinates (normalized to sum
/// 1 on use). Motion lines start at such points (paper Section 4.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// Triangle index in the object's mesh.
    pub triangle: u32,
    /// Barycentric weights of the triangle's three vertices.
    pub barycentric: [f32; 3],
}

impl SurfacePoint {
    /// The point's three corners as (vertex, weight) with the weights normalized to sum 1,
    /// checked against the mesh's `triangles`; `index` names the point in errors.
    pub(crate) fn corners(
        &self,
        index: usize,
        triangles: &[[u32; 3]],
    ) -> Result<[(usize, f32); 3]> {
        let bad = |reason: String| SmearError::InvalidSurfacePoint { index, reason };
        let tri = triangles.get(self.triangle as usize).ok_or_else(|| {
            bad(format!(
                "triangle {} does not exist ({} triangles)",
                self.triangle,
                triangles.len()
            ))
        })?;
        let b = self.barycentric;
        let sum = b[0] + b[1] + b[2];
        if !(b.iter().all(|x| x.is_finite() && *x >= 0.0) && sum > 0.0) {
            return Err(bad(format!(
                "barycentric coordinates {b:?} must be finite, ≥ 0, not all 0"
            )));
        }
        Ok([0, 1, 2].map(|j| (tri[j] as usize, b[j] / sum)))
    }
}
