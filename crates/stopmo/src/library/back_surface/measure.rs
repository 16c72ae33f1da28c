//! What a shell is checked by: the minimum wall in front of the back surface, the
//! triangles that cross in some piece's solid (the exact test), and those that cross in the
//! animated surface alone (the input's own).

use glam::Vec3;
use rayon::prelude::*;

use super::{front_positions, position_key, PartShell};
use crate::library::intersect::{intersecting_pairs_touching, self_intersecting_triangles};
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
        let (head, _) = self.thinnest_in(&grid, 0, &self.front(first), f64::INFINITY, None);
        let limit = head.map_or(f64::INFINITY, |t| t.mm);
        let tail: Vec<Option<ThinnestWall>> = rest
            .par_iter()
            .enumerate()
            .map(|(k, piece)| {
                let front = self.front(piece);
                self.thinnest_in(&grid, k + 1, &front, limit, None).0
            })
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
        let (head, at) = self.thinnest_in(&grid, 0, &self.front(first), f64::INFINITY, None);
        let tail: Vec<Option<ThinnestWall>> = rest
            .par_iter()
            .enumerate()
            .map(|(k, piece)| {
                let front = self.front(piece);
                self.thinnest_in(&grid, k + 1, &front, f64::INFINITY, at).0
            })
            .collect();
        std::iter::once(head).chain(tail).collect()
    }

    /// The first vertex of the front of piece `k` closest to the back surface (`grid`), if
    /// closer than `limit`, and its index. With `seed`, that vertex is measured first and
    /// bounds the others' queries to just above its distance: which vertex is the first
    /// thinnest does not change (only queries that cannot win are cut short).
    fn thinnest_in(
        &self,
        grid: &TriangleGrid<'_>,
        k: usize,
        front: &[Vec3],
        limit: f64,
        seed: Option<usize>,
    ) -> (Option<ThinnestWall>, Option<usize>) {
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
    /// The crossings among front triangles do not depend on the back: for the part's own
    /// pieces (fronts equal bit for bit to those the shell was laid out with) they were found
    /// once, for every direction field and repair round, and only the pairs touching the
    /// back are tested here.
    pub(super) fn crossings(&self, pieces: &[&[Vec3]]) -> (Vec<u32>, usize) {
        let fronts: Vec<Vec<Vec3>> = pieces.par_iter().map(|p| self.front(p)).collect();
        let known = fronts.len() == self.front_crossings.fronts.len()
            && fronts
                .iter()
                .zip(&self.front_crossings.fronts)
                .all(|(a, b)| same_bits(a, b));
        if known {
            return self.crossings_with(&self.front_crossings);
        }
        // Measured once: the front's pairs are not worth finding apart.
        let whole = FrontCrossings::unsplit(fronts, self.solid_topology(), self.back.len());
        self.crossings_with(&whole)
    }

    /// How many triangles of `solid` cross another one ([`self_intersecting_triangles`]'s
    /// count; `None` when a coordinate is beyond the exact test's range), for a solid of this
    /// shell: a piece's front over its back (displaced, an ID raised on it).
    ///
    /// # Performance
    /// When the solid's front is one the shell was laid out with (bit for bit) and its
    /// triangles are the shell's solid's, the front's own crossings are known: only the
    /// pairs touching the back are tested. Any other mesh is tested whole.
    pub fn solid_crossings(&self, solid: &anim::Mesh) -> Option<usize> {
        let fixed = &self.front_crossings;
        let n = self.back.len();
        let front = solid.positions.get(..n);
        let known = front.and_then(|front| fixed.fronts.iter().position(|f| same_bits(f, front)));
        let (Some(k), true, Some(front_pairs)) = (
            known,
            solid.triangles == fixed.tris,
            fixed.front_pairs.as_ref(),
        ) else {
            return self_intersecting_triangles(&solid.positions, &solid.triangles)
                .map(|t| t.len());
        };
        let own = intersecting_pairs_touching(&solid.positions, &fixed.tris, &fixed.kinds, BACK)?;
        let mut hits: Vec<u32> = own
            .into_iter()
            .chain(front_pairs[k].as_ref()?.iter().copied())
            .flat_map(|(i, j)| [i, j])
            .collect();
        hits.sort_unstable();
        hits.dedup();
        Some(hits.len())
    }

    /// [`PartShell::crossings`] of the pieces `fixed` was made from, with the back as it is
    /// now: when `fixed` holds the front's own crossings, only the pairs with a triangle on
    /// the back (the back and the walls) are tested; otherwise every pair.
    ///
    /// # Performance
    /// The pairs among triangles that are the same in every solid are tested once, and each
    /// piece's solid only tests the pairs touching a triangle of its own.
    pub(super) fn crossings_with(&self, fixed: &FrontCrossings) -> (Vec<u32>, usize) {
        let n = self.back.len();
        let FrontCrossings {
            fronts,
            same,
            tris,
            kinds,
            front_pairs,
        } = fixed;
        let Some(first) = fronts.first() else {
            return (Vec::new(), 0);
        };
        let positions_of = |front: &[Vec3]| {
            let mut positions = front.to_vec();
            positions.extend_from_slice(&self.back);
            positions
        };
        let mut same_solid = same.clone();
        same_solid.resize(2 * n, true);
        // With the front's pairs known, the pairs left are those touching the back.
        let (shared_need, own_need) = match front_pairs {
            Some(_) => (BACK, VARYING | BACK),
            None => (0, VARYING),
        };
        let shared = shared_pairs(&positions_of(first), &same_solid, tris, kinds, shared_need);
        let per_piece: Vec<(Vec<u32>, usize)> = fronts
            .par_iter()
            .enumerate()
            .map(|(k, front)| {
                let positions = positions_of(front);
                let own = intersecting_pairs_touching(&positions, tris, kinds, own_need);
                let front_pairs = match front_pairs {
                    Some(pairs) => pairs[k].as_deref(),
                    None => Some(&[][..]),
                };
                let mut hits: Vec<u32> = match (own, front_pairs) {
                    (Some(own), Some(front_pairs)) => own
                        .into_iter()
                        .chain(shared.iter().copied())
                        .chain(front_pairs.iter().copied())
                        .flat_map(|(i, j)| [i, j])
                        .collect(),
                    _ => Vec::new(),
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

/// Whether two fronts are the same positions bit for bit.
fn same_bits(a: &[Vec3], b: &[Vec3]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(&p, &q)| position_key(p) == position_key(q))
}

/// A solid triangle with a vertex that differs between the pieces.
const VARYING: u8 = 1;
/// A solid triangle with a vertex on the back (the back's and the walls').
const BACK: u8 = 2;

/// The crossings of a part's pieces that do not depend on the back: each piece's front,
/// which solid triangles differ between pieces or touch the back, and the crossing pairs
/// among each piece's front triangles.
#[derive(Debug, Default)]
pub(super) struct FrontCrossings {
    /// Every piece's front (shell vertices).
    fronts: Vec<Vec<Vec3>>,
    /// Per shell vertex: whether the front is at the same place in every piece.
    same: Vec<bool>,
    /// The solid's triangles ([`PartShell::solid_topology`]).
    tris: Vec<[u32; 3]>,
    /// [`VARYING`] and [`BACK`] flags per solid triangle.
    kinds: Vec<u8>,
    /// Per piece: the crossing pairs among front triangles (`None` when a coordinate is
    /// beyond the exact test's range); `None` for all when they were not found apart
    /// ([`FrontCrossings::unsplit`]).
    front_pairs: Option<Vec<Option<Pairs>>>,
}

/// Crossing pairs of triangles `(i, j)`, `i ≤ j`.
type Pairs = Vec<(u32, u32)>;

impl FrontCrossings {
    /// Finds the crossings among the front triangles of every piece's solid.
    ///
    /// # Arguments
    /// * `fronts` — every piece's front over the `n` shell vertices;
    /// * `tris` — the solid's triangles ([`PartShell::solid_topology`]), whose first
    ///   `front_count` are the front's (over front vertices only).
    ///
    /// # Performance
    /// The pieces share every front vertex they agree on (the seams): the pairs among front
    /// triangles that are the same in every piece are tested once, and each piece's front
    /// only tests the pairs touching a triangle of its own.
    pub(super) fn new(
        fronts: Vec<Vec<Vec3>>,
        tris: Vec<[u32; 3]>,
        front_count: usize,
        n: usize,
    ) -> FrontCrossings {
        let mut fixed = FrontCrossings::unsplit(fronts, tris, n);
        let FrontCrossings {
            fronts,
            same,
            tris,
            kinds,
            ..
        } = &fixed;
        let Some(first) = fronts.first() else {
            return fixed;
        };
        let (front_tris, front_kinds) = (&tris[..front_count], &kinds[..front_count]);
        let shared = shared_pairs(first, same, front_tris, front_kinds, 0);
        let front_pairs = fronts
            .par_iter()
            .map(|front| {
                let own = intersecting_pairs_touching(front, front_tris, front_kinds, VARYING)?;
                Some(own.into_iter().chain(shared.iter().copied()).collect())
            })
            .collect();
        fixed.front_pairs = Some(front_pairs);
        fixed
    }

    /// The pieces' fronts and the flags of the solid's triangles, without the front's own
    /// crossings: [`PartShell::crossings_with`] then tests every pair (each shared one once).
    pub(super) fn unsplit(fronts: Vec<Vec<Vec3>>, tris: Vec<[u32; 3]>, n: usize) -> FrontCrossings {
        let Some(first) = fronts.first() else {
            return FrontCrossings {
                tris,
                ..FrontCrossings::default()
            };
        };
        // Front vertices at the same place in every piece.
        let same: Vec<bool> = (0..n)
            .map(|v| {
                fronts
                    .iter()
                    .all(|f| position_key(f[v]) == position_key(first[v]))
            })
            .collect();
        let kinds: Vec<u8> = tris
            .iter()
            .map(|t| {
                let varying = t.iter().any(|&v| (v as usize) < n && !same[v as usize]);
                let back = t.iter().any(|&v| v as usize >= n);
                (u8::from(varying) * VARYING) | (u8::from(back) * BACK)
            })
            .collect();
        FrontCrossings {
            fronts,
            same,
            tris,
            kinds,
            front_pairs: None,
        }
    }
}

/// The crossing pairs (ids in `tris`) among the triangles of `tris` that are not
/// [`VARYING`] and carry the bits `need` between them, over `positions` (where only the
/// vertices that are the same in every piece, `same`, are read).
fn shared_pairs(
    positions: &[Vec3],
    same: &[bool],
    tris: &[[u32; 3]],
    kinds: &[u8],
    need: u8,
) -> Vec<(u32, u32)> {
    let ids: Vec<u32> = (0..tris.len() as u32)
        .filter(|&t| kinds[t as usize] & VARYING == 0)
        .collect();
    let sub: Vec<[u32; 3]> = ids.iter().map(|&t| tris[t as usize]).collect();
    let sub_kinds: Vec<u8> = ids.iter().map(|&t| kinds[t as usize]).collect();
    // Vertices only varying triangles use are never read there.
    let positions: Vec<Vec3> = positions
        .iter()
        .zip(same)
        .map(|(&p, &s)| if s { p } else { Vec3::ZERO })
        .collect();
    intersecting_pairs_touching(&positions, &sub, &sub_kinds, need)
        .unwrap_or_default()
        .into_iter()
        .map(|(i, j)| (ids[i as usize], ids[j as usize]))
        .collect()
}
