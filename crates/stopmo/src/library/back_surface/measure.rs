//! What a shell is checked by: the minimum wall in front of the back surface and the
//! triangles that cross in some piece's solid (the exact test).

use glam::Vec3;
use rayon::prelude::*;

use super::PartShell;
use crate::library::intersect::self_intersecting_triangles;
use crate::library::nearest::TriangleGrid;

impl PartShell {
    /// Smallest distance (mm) from a front vertex of `piece` to the back surface's triangles.
    pub fn min_wall(&self, piece: &[Vec3]) -> f64 {
        self.min_wall_of(&[piece])
    }

    /// Smallest [`min_wall`](Self::min_wall) over `pieces`, with one grid of the back surface.
    pub(super) fn min_wall_of(&self, pieces: &[&[Vec3]]) -> f64 {
        let grid = TriangleGrid::new(&self.back, &self.triangles);
        // The running minimum bounds every later query to a few grid rings.
        pieces.iter().fold(f64::INFINITY, |best, piece| {
            self.front(piece)
                .iter()
                .fold(best, |best, &p| best.min(grid.distance_below(p, best)))
        })
    }

    /// Shell vertices (front or back copies folded onto shell ids) of the triangles that
    /// cross another triangle in some piece's solid.
    pub(super) fn crossing_vertices(&self, pieces: &[&[Vec3]]) -> Vec<u32> {
        let n = self.back.len() as u32;
        let mut out: Vec<u32> = pieces
            .par_iter()
            .flat_map_iter(|p| {
                let solid = self.solid_unchecked(p, "");
                let hits = self_intersecting_triangles(&solid.positions, &solid.triangles);
                hits.unwrap_or_default()
                    .into_iter()
                    .flat_map(move |t| solid.triangles[t as usize].map(|v| v % n))
            })
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }
}
