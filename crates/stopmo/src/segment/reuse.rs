//! Reusing one segmentation on other clips of the same mesh, so that parts printed for one
//! shot assemble with parts printed for the next.
//!
//! A cut is frame-invariant (its vertices sit at fixed barycentric coordinates of the input
//! mesh) and homogenization pins the seams to fixed target positions; saving both — the cut
//! and the targets — and applying them to another clip gives seam vertices at exactly the same
//! positions in every frame of every clip.

use std::borrow::Cow;

use anim::MeshAnimation;
use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::cut::CutMesh;
use super::error::{Result, SegmentError};
use super::pipeline::{finish, Labels, SegmentOptions, Segmentation};

/// A segmentation as saved for reuse (`segmentation.json`, key `"reuse"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SavedSegmentation {
    /// Part names, in part order.
    pub parts: Vec<String>,
    /// Vertex count of the input mesh the cut applies to.
    pub input_vertices: usize,
    /// Triangle count of the input mesh the cut applies to.
    pub input_triangles: usize,
    /// γ the cut was made with.
    pub gamma: f64,
    /// Seed triangles per part (input triangle ids).
    pub seeds: Vec<Vec<u32>>,
    /// Graph-cut label of every input triangle.
    pub input_triangle_part: Vec<u32>,
    /// The cut.
    pub cut: CutMesh,
    /// Homogenization targets: average position of every cut vertex on the defining clip.
    pub reference: Vec<[f32; 3]>,
}

impl Segmentation {
    /// This segmentation in its reusable form (for `input`'s vertex and triangle counts).
    pub fn saved(&self, input_vertices: usize, input_triangles: usize) -> SavedSegmentation {
        SavedSegmentation {
            parts: self.part_names.clone(),
            input_vertices,
            input_triangles,
            gamma: self.gamma,
            seeds: self.seeds.clone(),
            input_triangle_part: self.input_triangle_part.clone(),
            cut: self.cut.clone(),
            reference: self.reference.iter().map(|p| p.to_array()).collect(),
        }
    }
}

/// Applies a saved segmentation to another clip of the same mesh: the same cut, seams
/// homogenized to the same targets (only `homogenize`, `keep_open_borders` of `options` are
/// used).
///
/// # Errors
/// [`SegmentError::Parameter`] when the clip's mesh does not match the saved one (vertex or
/// triangle count, or a cut vertex referring to a missing input vertex), or a failed
/// factorization.
pub fn segment_reusing(
    anim: &MeshAnimation,
    saved: &SavedSegmentation,
    options: &SegmentOptions,
) -> Result<Segmentation> {
    reuse_input(Cow::Borrowed(anim), saved, options)
}

/// [`segment_reusing`] on an input that is borrowed or handed over (an owned input's frames
/// become the cut animation's).
pub(crate) fn reuse_input(
    anim: Cow<'_, MeshAnimation>,
    saved: &SavedSegmentation,
    options: &SegmentOptions,
) -> Result<Segmentation> {
    let (m, k) = (anim.vertex_count(), anim.mesh.triangle_count());
    if m != saved.input_vertices || k != saved.input_triangles {
        return Err(SegmentError::Parameter(format!(
            "the saved segmentation is for a mesh of {} vertices and {} triangles, this clip has {m} and {k}: reuse a segmentation only on clips of the same mesh",
            saved.input_vertices, saved.input_triangles
        )));
    }
    let n = saved.cut.sources.len();
    let consistent = saved.reference.len() == n
        && saved.cut.weld_class.len() == n
        && saved.cut.triangle_part.len() == saved.cut.triangles.len()
        && saved
            .cut
            .triangles
            .iter()
            .flatten()
            .all(|&i| (i as usize) < n)
        && saved
            .cut
            .weld_class
            .iter()
            .all(|&c| (c as usize) < saved.cut.welded_count)
        && saved
            .cut
            .triangle_part
            .iter()
            .all(|&p| (p as usize) < saved.parts.len())
        && saved.cut.sources.iter().all(|s| source_ok(s, m));
    if !consistent {
        return Err(SegmentError::Parameter(
            "the saved segmentation is inconsistent (cut, parts and targets disagree): write it again with `stopmo segment --report`".into(),
        ));
    }
    finish(
        anim,
        saved.cut.clone(),
        Labels {
            part_names: saved.parts.clone(),
            seeds: saved.seeds.clone(),
            input_triangle_part: saved.input_triangle_part.clone(),
            gamma: saved.gamma,
        },
        saved
            .reference
            .iter()
            .map(|p| Vec3::from_array(*p))
            .collect(),
        options,
    )
}

fn source_ok(s: &super::cut::VertexSource, m: usize) -> bool {
    use super::cut::VertexSource;
    match *s {
        VertexSource::Original(i) => (i as usize) < m,
        VertexSource::Edge { a, b, t } => (a as usize) < m && (b as usize) < m && t.is_finite(),
        VertexSource::Interior { v, w } => {
            v.iter().all(|&i| (i as usize) < m) && w.iter().all(|x| x.is_finite())
        }
    }
}
