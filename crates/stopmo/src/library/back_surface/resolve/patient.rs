//! One part under the search: its solids per piece, and the exact count of the crossings a
//! move leaves near it.

use glam::Vec3;
use rayon::prelude::*;

use super::grid::{bounds, boxes_overlap, BoxGrid};
use super::Move;
use crate::library::back_surface::PartShell;
use crate::library::intersect::{degenerate, intersecting_pairs, triangles_cross};
use crate::library::nearest::closest_point_on_triangle;

/// One part under search: its solids' topology and positions per piece.
pub(super) struct Patient {
    /// Back vertex count `n` (back copy of `v` is `n + v` in a solid).
    pub(super) n: usize,
    pub(super) tris: Vec<[u32; 3]>,
    /// Front and back positions of every piece's solid.
    pub(super) solids: Vec<Vec<Vec3>>,
    /// Solid triangles incident to each solid vertex (front `v`, back `n + v`).
    pub(super) incident: Vec<Vec<u32>>,
    /// Previous and next vertex along the boundary loops.
    pub(super) along: Vec<[u32; 2]>,
    /// Mean front over the pieces.
    pub(super) mean_front: Vec<Vec3>,
    /// Vertex normals of the mean front (outward).
    pub(super) normals: Vec<Vec3>,
    /// Nearest a back triangle may come to a front vertex.
    pub(super) floor: f32,
    /// Mean triangle box size (grid cells).
    pub(super) size: f32,
}

impl Patient {
    pub(super) fn new(shell: &PartShell, pieces: &[&[Vec3]], wall_mm: f64) -> Patient {
        let n = shell.back.len();
        let tris = shell.solid_topology();
        let fronts: Vec<Vec<Vec3>> = pieces.iter().map(|p| shell.front(p)).collect();
        let mean_front: Vec<Vec3> = (0..n)
            .map(|v| fronts.iter().map(|f| f[v]).sum::<Vec3>() / fronts.len().max(1) as f32)
            .collect();
        let normals = anim::vertex_normals(&mean_front, &shell.triangles);
        let mut incident: Vec<Vec<u32>> = vec![Vec::new(); 2 * n];
        for (t, tri) in tris.iter().enumerate() {
            for &v in tri {
                incident[v as usize].push(t as u32);
            }
        }
        let mut along: Vec<[u32; 2]> = vec![[u32::MAX; 2]; n];
        for &(a, b) in &shell.boundary {
            along[a as usize][1] = b;
            along[b as usize][0] = a;
        }
        // A little under the thinnest wall now, so rounding never rejects the current state.
        let floor = (shell.min_wall_of(pieces).min(wall_mm) - 1e-4) as f32;
        let size = {
            let s: f32 = tris
                .iter()
                .map(|t| {
                    let (lo, hi) = bounds(t.map(|v| shell.back[v as usize % n]));
                    (hi - lo).max_element()
                })
                .sum();
            (s / tris.len().max(1) as f32).max(1e-3)
        };
        let solids = fronts
            .into_iter()
            .map(|mut f| {
                f.extend_from_slice(&shell.back);
                f
            })
            .collect();
        Patient {
            n,
            tris,
            solids,
            incident,
            along,
            mean_front,
            normals,
            floor,
            size,
        }
    }

    /// Shell vertices whose back copy (first) or front (second) belongs to a triangle that
    /// crosses in some piece, and the crossing triangles summed over pieces.
    pub(super) fn hot(&self) -> (Vec<bool>, Vec<bool>, usize) {
        let pairs: Vec<Vec<(u32, u32)>> = self
            .solids
            .par_iter()
            .map(|p| intersecting_pairs(p, &self.tris).unwrap_or_default())
            .collect();
        let mut hot = vec![false; self.n];
        let mut hot_front = vec![false; self.n];
        let mut count = 0;
        for piece in &pairs {
            let mut crossing: Vec<u32> = piece.iter().flat_map(|&(i, j)| [i, j]).collect();
            crossing.sort_unstable();
            crossing.dedup();
            count += crossing.len();
            for t in crossing {
                for &v in &self.tris[t as usize] {
                    if v as usize >= self.n {
                        hot[v as usize - self.n] = true;
                    } else {
                        hot_front[v as usize] = true;
                    }
                }
            }
        }
        (hot, hot_front, count)
    }

    /// Solid triangles incident to the solid vertices `at`, sorted.
    pub(super) fn moving(&self, at: &[usize]) -> Vec<u32> {
        let mut moving: Vec<u32> = at
            .iter()
            .flat_map(|&a| self.incident[a].iter().copied())
            .collect();
        moving.sort_unstable();
        moving.dedup();
        moving
    }

    /// Per piece, what the triangles `moving` may meet while their moved vertices take any
    /// of the points `extra` (or shift by up to `pad`): the triangles near them (`touched`
    /// ones, moved after `grids` were built, always) and the front vertices among those.
    pub(super) fn neighbourhood(
        &self,
        grids: &[BoxGrid],
        touched: &[u32],
        moving: &[u32],
        extra: &[Vec3],
        pad: f32,
    ) -> Vec<Near> {
        let reach = self.floor + pad;
        self.solids
            .par_iter()
            .zip(grids)
            .map(|(pos, grid)| {
                let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
                for &t in moving {
                    let (a, b) = bounds(self.tris[t as usize].map(|i| pos[i as usize]));
                    lo = lo.min(a);
                    hi = hi.max(b);
                }
                for &q in extra {
                    lo = lo.min(q);
                    hi = hi.max(q);
                }
                let (lo, hi) = (lo - reach, hi + reach);
                let mut tris = grid.near(lo, hi);
                tris.extend_from_slice(touched);
                tris.sort_unstable();
                tris.dedup();
                // The moving triangles are tested against each other apart.
                tris.retain(|t| moving.binary_search(t).is_err());
                let boxes: Vec<(Vec3, Vec3)> = tris
                    .iter()
                    .map(|&t| bounds(self.tris[t as usize].map(|i| pos[i as usize])))
                    .collect();
                let mut fronts: Vec<u32> = tris
                    .iter()
                    .chain(moving)
                    .flat_map(|&t| self.tris[t as usize])
                    .filter(|&f| (f as usize) < self.n)
                    .collect();
                fronts.sort_unstable();
                fronts.dedup();
                let back_tris = tris
                    .iter()
                    .copied()
                    .filter(|&t| self.tris[t as usize].iter().all(|&i| i as usize >= self.n))
                    .collect();
                Near {
                    tris,
                    boxes,
                    fronts,
                    back_tris,
                }
            })
            .collect()
    }

    /// Crossing pairs of the triangles `moving` (those incident to the moved vertices) over
    /// all pieces after `moves` (`near` from [`Patient::neighbourhood`] for these moves), or
    /// with `thin`, whether a back triangle comes nearer than the floor to a front vertex
    /// (1) or not (0).
    pub(super) fn count(&self, near: &[Near], moving: &[u32], moves: &[Move], thin: bool) -> usize {
        let (n, tris) = (self.n, &self.tris);
        let floor = self.floor;
        let per_piece = |k: usize| -> usize {
            let pos = &self.solids[k];
            let near = &near[k];
            let at = |i: u32| {
                let i = i as usize;
                moves.iter().find(|m| m.at == i).map_or(pos[i], |m| {
                    if m.shift {
                        pos[i] + m.to
                    } else {
                        m.to
                    }
                })
            };
            let corners = |t: u32| tris[t as usize].map(at);
            let mut hits = 0;
            for &t in moving {
                let a = corners(t);
                let ba = bounds(a);
                if thin {
                    if tris[t as usize].iter().all(|&i| i as usize >= n) {
                        // The wall in front of a moved back triangle.
                        let reach = (ba.0 - floor, ba.1 + floor);
                        for &f in &near.fronts {
                            let p = at(f);
                            if !(p.cmplt(reach.0).any() || p.cmpgt(reach.1).any())
                                && p.distance(closest_point_on_triangle(p, a[0], a[1], a[2]))
                                    < floor
                            {
                                return 1;
                            }
                        }
                    }
                    continue;
                }
                if degenerate(a) {
                    hits += 1;
                    continue;
                }
                for (&u, &bu) in near.tris.iter().zip(&near.boxes) {
                    if boxes_overlap(ba, bu)
                        && triangles_cross(
                            tris[t as usize],
                            a,
                            tris[u as usize],
                            tris[u as usize].map(|i| pos[i as usize]),
                        )
                    {
                        hits += 1;
                    }
                }
                // Pairs of moving triangles, each once.
                for &u in moving.iter().filter(|&&u| u > t) {
                    let b = corners(u);
                    if boxes_overlap(ba, bounds(b))
                        && triangles_cross(tris[t as usize], a, tris[u as usize], b)
                    {
                        hits += 1;
                    }
                }
            }
            if !thin {
                return hits;
            }
            // The wall behind a moved front vertex.
            for m in moves.iter().filter(|m| m.at < n) {
                let p = at(m.at as u32);
                for &u in near.back_tris.iter().chain(moving) {
                    if tris[u as usize].iter().any(|&i| (i as usize) < n) {
                        continue;
                    }
                    let b = corners(u);
                    let (lo, hi) = bounds(b);
                    if !(p.cmplt(lo - floor).any() || p.cmpgt(hi + floor).any())
                        && p.distance(closest_point_on_triangle(p, b[0], b[1], b[2])) < floor
                    {
                        return 1;
                    }
                }
            }
            0
        };
        if thin {
            usize::from(
                (0..self.solids.len())
                    .into_par_iter()
                    .any(|k| per_piece(k) > 0),
            )
        } else {
            (0..self.solids.len()).into_par_iter().map(per_piece).sum()
        }
    }
}

/// What moving triangles may meet in one piece ([`Patient::neighbourhood`]).
pub(super) struct Near {
    /// Solid triangles that do not move (sorted).
    tris: Vec<u32>,
    /// Their bounding boxes.
    boxes: Vec<(Vec3, Vec3)>,
    /// Front vertices of those triangles.
    fronts: Vec<u32>,
    /// Those triangles that belong to the back.
    back_tris: Vec<u32>,
}
