//! Carrying per-vertex data of the input through the cut: saliency given in the input's
//! vertex order, and the parts of the artist's animation before homogenization (errors are
//! reported against them).

use anim::MeshAnimation;

use super::error::{Result, SegmentError};
use super::pipeline::{Part, Segmentation};

impl Segmentation {
    /// Maps one value per *input* vertex to one value per vertex of
    /// [`Segmentation::animation`] (cut vertices interpolate like their positions).
    ///
    /// # Errors
    /// [`SegmentError::Parameter`] when `values` does not have one entry per input vertex.
    pub fn map_vertex_values(&self, values: &[f32]) -> Result<Vec<f32>> {
        let m = self.input_vertex_count();
        if values.len() != m {
            return Err(SegmentError::Parameter(format!(
                "{} values for {m} input vertices (give one per vertex of the input mesh, in its order)",
                values.len()
            )));
        }
        use super::cut::VertexSource;
        Ok(self
            .cut
            .sources
            .iter()
            .map(|s| match *s {
                VertexSource::Original(i) => values[i as usize],
                VertexSource::Edge { a, b, t } => {
                    let (x, y) = (f64::from(values[a as usize]), f64::from(values[b as usize]));
                    (x + (y - x) * t) as f32
                }
                VertexSource::Interior { v, w } => (0..3)
                    .map(|k| f64::from(values[v[k] as usize]) * w[k])
                    .sum::<f64>() as f32,
            })
            .collect())
    }

    /// Number of input vertices the cut refers to (the cut keeps them first, in order).
    pub fn input_vertex_count(&self) -> usize {
        self.cut
            .sources
            .iter()
            .take_while(|s| matches!(s, super::cut::VertexSource::Original(_)))
            .count()
    }

    /// Every part of `input` (the clip this segmentation was made on or applied to, before
    /// homogenization) with the vertices and triangles of [`Segmentation::parts`].
    ///
    /// # Errors
    /// [`SegmentError::Parameter`] when `input` has a different vertex or frame count.
    pub fn input_parts(&self, input: &MeshAnimation) -> Result<Vec<Part>> {
        if input.vertex_count() != self.input_vertex_count()
            || input.frame_count() != self.animation.frame_count()
        {
            return Err(SegmentError::Parameter(format!(
                "input has {} vertices and {} frames, the segmentation {} and {}",
                input.vertex_count(),
                input.frame_count(),
                self.input_vertex_count(),
                self.animation.frame_count()
            )));
        }
        let mut parts = self.parts()?;
        for part in &mut parts {
            let sources: Vec<_> = part
                .vertices
                .iter()
                .map(|&v| self.cut.sources[v as usize])
                .collect();
            let positions = input
                .frames()
                .flat_map(|x| sources.iter().map(move |s| s.eval(x)))
                .collect();
            let mut a = MeshAnimation::new(part.animation.mesh.clone(), input.fps, positions)
                .map_err(|e| SegmentError::Invalid(e.to_string()))?;
            a.start_time = input.start_time;
            part.animation = a;
        }
        Ok(parts)
    }

    /// Parts with fewer than `min_fraction` of the triangles (a collapsed part: γ too large
    /// or seeds too close), as `(name, triangles)`.
    pub fn collapsed_parts(&self, min_fraction: f64) -> Vec<(String, usize)> {
        let total = self.triangle_part.len();
        let mut count = vec![0usize; self.part_count()];
        for &p in &self.triangle_part {
            if let Some(c) = count.get_mut(p as usize) {
                *c += 1;
            }
        }
        self.part_names
            .iter()
            .zip(count)
            .filter(|(_, c)| (*c as f64) < min_fraction * total as f64)
            .map(|(n, c)| (n.clone(), c))
            .collect()
    }
}

/// Smallest share of the triangles a part may keep before it counts as collapsed.
pub const DEFAULT_MIN_PART_FRACTION: f64 = 0.005;

impl Segmentation {
    /// Fails when a part kept fewer than [`DEFAULT_MIN_PART_FRACTION`] of the triangles.
    ///
    /// # Errors
    /// [`SegmentError::Parameter`] naming the part, its triangle count and what to change.
    pub fn check_parts(&self) -> Result<()> {
        let collapsed = self.collapsed_parts(DEFAULT_MIN_PART_FRACTION);
        if let Some((name, n)) = collapsed.first() {
            return Err(SegmentError::Parameter(format!(
                "part '{name}' collapsed to {n} of {} triangles (γ {}): lower --gamma (default {}) or move its seed away from the other parts",
                self.triangle_part.len(),
                self.gamma,
                super::problem::DEFAULT_GAMMA
            )));
        }
        Ok(())
    }
}
