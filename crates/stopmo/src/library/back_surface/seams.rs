//! Where a part's back surface meets other parts and other shots: the seam vertices and
//! walls shared with neighbouring parts, and a printed back surface reused by new pieces
//! (`--fixed`).

use std::collections::HashSet;

use glam::Vec3;

use super::PartShell;
use crate::library::error::{LibraryError, Result};

impl PartShell {
    /// `(average front position, back position)` of every boundary vertex, to share the seam
    /// walls with the next part ([`PartShell::new_sharing`]).
    pub fn boundary_pairs(&self, average: &[Vec3]) -> Vec<(Vec3, Vec3)> {
        let mut out: Vec<(Vec3, Vec3)> = (0..self.back.len())
            .filter(|&v| self.on_boundary[v])
            .filter_map(|v| {
                average
                    .get(self.source[v] as usize)
                    .map(|a| (*a, self.back[v]))
            })
            .collect();
        out.dedup();
        out
    }

    /// Boundary shell vertices on the seam with another part: those whose average front
    /// position (`average`, this part's) is the first element of a pair in `other` (that
    /// part's [`PartShell::boundary_pairs`]).
    pub fn seam_vertices(&self, average: &[Vec3], other: &[(Vec3, Vec3)]) -> Vec<u32> {
        let theirs: HashSet<[u32; 3]> = other
            .iter()
            .map(|(a, _)| a.to_array().map(f32::to_bits))
            .collect();
        (0..self.back.len())
            .filter(|&v| self.on_boundary[v])
            .filter(|&v| {
                average
                    .get(self.source[v] as usize)
                    .is_some_and(|a| theirs.contains(&a.to_array().map(f32::to_bits)))
            })
            .map(|v| v as u32)
            .collect()
    }

    /// The seams this part (`part`, in part order) shares with every other part:
    /// [`PartShell::seam_vertices`] against each other part's boundary pairs in
    /// `boundaries` (indexed by part), empty seams left out.
    pub fn shared_seams(
        &self,
        average: &[Vec3],
        boundaries: &[Vec<(Vec3, Vec3)>],
        part: usize,
    ) -> Vec<Vec<u32>> {
        boundaries
            .iter()
            .enumerate()
            .filter(|(q, _)| *q != part)
            .map(|(_, other)| self.seam_vertices(average, other))
            .filter(|v| !v.is_empty())
            .collect()
    }

    /// Replaces the back surface by a printed one (shell vertex order, millimetres, before
    /// keys and IDs: [`PartShell::back`] of an earlier run, `pieces/<part>_back.obj`), so
    /// new pieces seat on the same head as the printed ones; `pieces` are the part's pieces
    /// (millimetres) to measure the wall against.
    ///
    /// # Errors
    /// [`LibraryError::InvalidParameter`] when the vertex count differs (another mesh or
    /// segmentation) or a position is not finite.
    pub fn use_back(&mut self, back: &[Vec3], pieces: &[&[Vec3]]) -> Result<()> {
        if back.len() != self.back.len() || back.iter().any(|p| !p.is_finite()) {
            return Err(LibraryError::InvalidParameter(format!(
                "the printed back surface has {} vertices, this part's has {}: it belongs to another mesh or segmentation",
                back.len(),
                self.back.len()
            )));
        }
        self.back = back.to_vec();
        self.stats.min_wall_mm = self.min_wall_of(pieces);
        self.stats.self_intersecting_triangles = self.crossing_vertices(pieces).len();
        Ok(())
    }

    /// The back surface as a mesh (millimetres, outward = away from the front), named `name`.
    pub fn back_mesh(&self, name: &str) -> anim::Mesh {
        anim::Mesh::new(
            name,
            self.back.clone(),
            self.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect(),
        )
    }
}
