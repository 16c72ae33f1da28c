//! What a shell is checked by: the minimum wall in front of the back surface, the
//! triangles that cross in some piece's solid (the exact test), and those that cross in the
//! animated surface alone (the input's own).

use glam::Vec3;
use rayon::prelude::*;

use super::{front_positions, PartShell};
use crate::library::intersect::{
    intersecting_pairs, intersecting_pairs_touching, self_intersecting_triangles,
};
use crate::library::nearest::TriangleGrid;

/// Where a shell's wall is thinnest ([`PartShell::thinnest_wall`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThinnestWall {
    /// Distance from the front vertex to the back surface (mm).
    pub mm: f64,
    /// Index of the piece.
    pub piece: usize,
    /// The front vertex (mm, the piece's coordinates).
    pub at: Vec3,
    /// Whether the vertex lies on the part boundary (next to a wall).
    pub on_boundary: bool,
}

/// The thinnest of per-piece thinnest walls (in piece order): the first of the thinnest.
pub fn first_thinnest(
    walls: impl IntoIterator<Item = Option<ThinnestWall>>,
) -> Option<ThinnestWall> {
    walls
        .into_iter()
        .flatten()
        .fold(None, |best: Option<ThinnestWall>, t| match best {
            Some(b) if b.mm <= t.mm => Some(b),
            _ => Some(t),
        })
}

impl PartShell {
    /// Smallest distance (mm) from a front vertex of `piece` to the back surface's triangles.
    pub fn min_wall(&self, piece: &[Vec3]) -> f64 {
        self.min_wall_of(&[piece])
    }

    /// Smallest [`min_wall`](Self::min_wall) over `pieces`, with one grid of the back surface.
    pub(super) fn min_wall_of(&self, pieces: &[&[Vec3]]) -> f64 {
        self.thinnest_wall(pieces).map_or(f64::INFINITY, |t| t.mm)
    }

    /// Where the wall is thinnest over `pieces`: the front vertex closest to the back surface
    /// (`None` without pieces or triangles); of equally thin ones, the first piece's first.
    ///
    /// # Performance
    /// One grid of the back surface. The first piece is measured alone, the others in
    /// parallel below its minimum: the running minimum bounds every later query to a few
    /// grid rings, so the cost is close to one nearest-triangle query per front vertex.
    pub fn thinnest_wall(&self, pieces: &[&[Vec3]]) -> Option<ThinnestWall> {
        let grid = TriangleGrid::new(&self.back, &self.triangles);
        let (first, rest) = pieces.split_first()?;
        let (head, _) = self.thinnest_in(&grid, 0, first, f64::INFINITY, None);
        let limit = head.map_or(f64::INFINITY, |t| t.mm);
        let tail: Vec<Option<ThinnestWall>> = rest
            .par_iter()
            .enumerate()
            .map(|(k, piece)| self.thinnest_in(&grid, k + 1, piece, limit, None).0)
            .collect();
        first_thinnest(std::iter::once(head).chain(tail))
    }

    /// [`PartShell::thinnest_wall`] of every piece on its own; [`first_thinnest`] of them is
    /// the thinnest over all.
    ///
    /// # Performance
    /// One grid of the back surface; the first piece is measured alone, the others in
    /// parallel, each starting below its own wall at the first piece's thinnest vertex (the
    /// pieces of a part are thin in the same places): every query after it is bounded to a
    /// few grid rings.
    pub fn thinnest_walls(&self, pieces: &[&[Vec3]]) -> Vec<Option<ThinnestWall>> {
        let grid = TriangleGrid::new(&self.back, &self.triangles);
        let Some((first, rest)) = pieces.split_first() else {
            return Vec::new();
        };
        let (head, at) = self.thinnest_in(&grid, 0, first, f64::INFINITY, None);
        let tail: Vec<Option<ThinnestWall>> = rest
            .par_iter()
            .enumerate()
            .map(|(k, piece)| self.thinnest_in(&grid, k + 1, piece, f64::INFINITY, at).0)
            .collect();
        std::iter::once(head).chain(tail).collect()
    }

    /// The first front vertex of `piece` (index `k`) closest to the back surface (`grid`), if
    /// closer than `limit`, and its index. With `seed`, that vertex is measured first and
    /// bounds the others' queries to just above its distance: which vertex is the first
    /// thinnest does not change (only queries that cannot win are cut short).
    fn thinnest_in(
        &self,
        grid: &TriangleGrid<'_>,
        k: usize,
        piece: &[Vec3],
        limit: f64,
        seed: Option<usize>,
    ) -> (Option<ThinnestWall>, Option<usize>) {
        let front = self.front(piece);
        let mut limit = limit;
        if let Some(&p) = seed.and_then(|v| front.get(v)) {
            let d = grid.distance_below(p, limit);
            if d < limit {
                // Just above `d`, so that the seed (or an equal vertex before it) is taken.
                limit = d + (d.abs() * 1e-9).max(1e-12);
            }
        }
        let mut best: Option<(ThinnestWall, usize)> = None;
        for (v, &p) in front.iter().enumerate() {
            let limit = best.as_ref().map_or(limit, |b| b.0.mm);
            let d = grid.distance_below(p, limit);
            if d < limit {
                let t = ThinnestWall {
                    mm: d,
                    piece: k,
                    at: p,
                    on_boundary: self.on_boundary.get(v).copied().unwrap_or(false),
                };
                best = Some((t, v));
            }
        }
        (best.map(|b| b.0), best.map(|b| b.1))
    }

    /// Where the animated surface of `piece` (millimetres, input vertex order) crosses
    /// itself over the welded front (without the caps), before any untangling: the triangles
    /// that cross and the centre of the first, `None` when none does (or a coordinate is
    /// beyond the exact test's range). These come with the input (lips or lids pressing
    /// into each other inside the part, degenerate triangles), not from the back.
    ///
    /// # Performance
    /// One exact self-intersection test of the front (see [`self_intersecting_triangles`]).
    pub fn surface_crossings(&self, piece: &[Vec3]) -> Option<(usize, Vec3)> {
        let f = front_positions(&self.source, &self.caps, piece);
        let surface = &self.triangles[..self.triangles.len() - self.cap_triangle_count()];
        let hits = self_intersecting_triangles(&f, surface)?;
        let first = *hits.first()?;
        let at = self.triangles[first as usize]
            .iter()
            .map(|&v| f[v as usize])
            .sum::<Vec3>()
            / 3.0;
        Some((hits.len(), at))
    }

    /// Shell vertices (front or back copies folded onto shell ids) of the triangles that
    /// cross another triangle in some piece's solid, and how many triangles cross, summed
    /// over the pieces.
    ///
    /// # Performance
    /// The pieces share the back, the walls and every front vertex they agree on (the seams):
    /// the pairs among triangles that are the same in every solid are tested once, and each
    /// piece's solid only tests the pairs touching a triangle of its own.
    pub(super) fn crossings(&self, pieces: &[&[Vec3]]) -> (Vec<u32>, usize) {
        let n = self.back.len();
        let tris = self.solid_topology();
        let fronts: Vec<Vec<Vec3>> = pieces.par_iter().map(|p| self.front(p)).collect();
        let Some(first) = fronts.first() else {
            return (Vec::new(), 0);
        };
        // Solid vertices (fronts, then the back) at the same place in every piece.
        let bits = |p: Vec3| p.to_array().map(f32::to_bits);
        let same: Vec<bool> = (0..n)
            .map(|v| fronts.iter().all(|f| bits(f[v]) == bits(first[v])))
            .chain(std::iter::repeat_n(true, n))
            .collect();
        let varying: Vec<bool> = tris
            .iter()
            .map(|t| t.iter().any(|&v| !same[v as usize]))
            .collect();
        let shared_ids: Vec<u32> = (0..tris.len() as u32)
            .filter(|&t| !varying[t as usize])
            .collect();
        let shared_tris: Vec<[u32; 3]> = shared_ids.iter().map(|&t| tris[t as usize]).collect();
        // Vertices only varying triangles use are never read there.
        let shared_positions: Vec<Vec3> = first
            .iter()
            .zip(&same)
            .map(|(&p, &s)| if s { p } else { Vec3::ZERO })
            .chain(self.back.iter().copied())
            .collect();
        let shared_pairs: Vec<(u32, u32)> = intersecting_pairs(&shared_positions, &shared_tris)
            .unwrap_or_default()
            .into_iter()
            .map(|(i, j)| (shared_ids[i as usize], shared_ids[j as usize]))
            .collect();
        let per_piece: Vec<(Vec<u32>, usize)> = fronts
            .par_iter()
            .map(|front| {
                let mut positions = front.clone();
                positions.extend_from_slice(&self.back);
                let mut hits: Vec<u32> =
                    match intersecting_pairs_touching(&positions, &tris, &varying) {
                        Some(own) => own
                            .into_iter()
                            .chain(shared_pairs.iter().copied())
                            .flat_map(|(i, j)| [i, j])
                            .collect(),
                        None => Vec::new(),
                    };
                hits.sort_unstable();
                hits.dedup();
                let vertices = hits
                    .iter()
                    .flat_map(|&t| tris[t as usize].map(|v| v % n as u32))
                    .collect();
                (vertices, hits.len())
            })
            .collect();
        let count = per_piece.iter().map(|(_, c)| c).sum();
        let mut out: Vec<u32> = per_piece.into_iter().flat_map(|(v, _)| v).collect();
        out.sort_unstable();
        out.dedup();
        (out, count)
    }
}
