//! Pieces where a part ends: never farther apart than the input moves there.
//!
//! StopShop Eq. 10's velocity term makes a piece a signed combination of frames (the normal
//! equations in [`update`](super::update) put the clip's chain Laplacian on the right-hand
//! side), so a piece may reach a little outside the positions the input ever takes: on the
//! ICT face, the lower pieces' inner lip edge spread up to 2.9 % more than the input's own
//! 5 mm motion there. Where a part ends (the neck, the scalp, the mouth's edge, the seams)
//! that breaks the promise that pieces seat on one body and meet their neighbours as the
//! input does. There, every free piece becomes the mean of the frames it shows — a mean never
//! leaves their hull, so pieces differ by no more than the input moves — blending back to the
//! StopShop Eq. 10 solution over [`BORDER_RINGS`] rings of vertices, so no step appears.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::problem::PartProblem;
use super::solver::PartSolution;
use super::source::Source;
use crate::segment::{open_border, Topology, Weld};

/// Rings of vertices over which a piece blends from the frames' mean at the part's border
/// back to the StopShop Eq. 10 solution.
pub const BORDER_RINGS: usize = 3;

impl PartProblem<'_> {
    /// The vertices within [`BORDER_RINGS`] of the part's border and the weight of the
    /// frames' mean there (see [`PartProblem::confine_borders`]); once per part.
    pub(crate) fn border_weights(&self) -> Vec<(usize, f32)> {
        border_weights(&self.src.mesh().positions, &self.src.mesh().triangles)
            .into_iter()
            .enumerate()
            .filter(|(_, w)| *w > 0.0)
            .collect()
    }

    /// Confines the free pieces of `solution` at the part's border (see the module): the
    /// vertices of `near` ([`PartProblem::border_weights`]) take the mean of the frames each
    /// piece shows, by their weight.
    ///
    /// # Performance
    /// One pass over the frames for the vertices of `near`.
    pub(crate) fn confine_borders(&self, solution: &mut PartSolution, near: &[(usize, f32)]) {
        if near.is_empty() {
            return;
        }
        let pieces = solution.pieces.len();
        // In f64: a still vertex's mean is then its position exactly (seams stay bit-equal).
        let mut sums = vec![DVec3::ZERO; pieces * near.len()];
        let mut counts = vec![0usize; pieces];
        match self.src {
            Source::Positions(anim) => {
                for (f, &label) in solution.labels.iter().enumerate() {
                    let k = label as usize;
                    if k < self.fixed || k >= pieces || f >= anim.frame_count() {
                        continue;
                    }
                    counts[k] += 1;
                    let x = anim.frame(f);
                    for (s, &(v, _)) in sums[k * near.len()..(k + 1) * near.len()]
                        .iter_mut()
                        .zip(near)
                    {
                        *s += x[v].as_dvec3();
                    }
                }
            }
            Source::Morph(anim) => {
                // Σ_f (b + T w_f) = count · b + T Σ_f w_f: the frames' weights summed per piece.
                let (nt, m) = (anim.target_count(), anim.vertex_count());
                let mut wsum = vec![0.0f64; pieces * nt];
                for (f, &label) in solution.labels.iter().enumerate() {
                    let k = label as usize;
                    if k < self.fixed || k >= pieces || f >= anim.frame_count() {
                        continue;
                    }
                    counts[k] += 1;
                    for (a, &w) in wsum[k * nt..(k + 1) * nt]
                        .iter_mut()
                        .zip(anim.frame_weights(f))
                    {
                        *a += f64::from(w);
                    }
                }
                let (base, targets) = (anim.base(), anim.targets());
                // Pieces on their own tasks; per piece, target by target over the border's
                // vertices (each sum still adds the targets in order, so the same values).
                sums.par_chunks_mut(near.len())
                    .zip(counts.par_iter())
                    .enumerate()
                    .for_each(|(k, (sums, &count))| {
                        for (s, &(v, _)) in sums.iter_mut().zip(near) {
                            *s = base[v].as_dvec3() * count as f64;
                        }
                        for (j, &w) in wsum[k * nt..(k + 1) * nt].iter().enumerate() {
                            let target = &targets[j * m..(j + 1) * m];
                            for (s, &(v, _)) in sums.iter_mut().zip(near) {
                                *s += target[v].as_dvec3() * w;
                            }
                        }
                    });
            }
        }
        let m = self.src.vertex_count();
        for (k, piece) in solution.pieces.iter_mut().enumerate().skip(self.fixed) {
            if counts[k] == 0 || piece.len() != m {
                continue;
            }
            let n = counts[k] as f64;
            for (s, &(v, w)) in sums[k * near.len()..(k + 1) * near.len()].iter().zip(near) {
                let (mean, now) = (*s / n, piece[v].as_dvec3());
                piece[v] = (now + (mean - now) * f64::from(w)).as_vec3();
            }
        }
    }
}

/// Weight of the frames' mean at every vertex: 1 on the border (edges of one triangle, after
/// welding vertices at the same position, so UV seams are not borders), falling linearly to
/// 0 at [`BORDER_RINGS`] rings from it.
fn border_weights(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<f32> {
    let weld = Weld::new(positions, 0.0);
    let tris: Vec<[u32; 3]> = triangles
        .iter()
        .filter(|t| t.iter().all(|&v| (v as usize) < positions.len()))
        .copied()
        .collect();
    let tris = weld.triangles(&tris);
    let neighbors = Topology::new(weld.len(), &tris).neighbors;
    let mut ring = vec![usize::MAX; weld.len()];
    let mut front: Vec<u32> = Vec::new();
    for (c, on) in open_border(weld.len(), &tris).into_iter().enumerate() {
        if on {
            ring[c] = 0;
            front.push(c as u32);
        }
    }
    for d in 1..BORDER_RINGS {
        let mut next = Vec::new();
        for &c in &front {
            for &w in neighbors.row(c as usize) {
                if ring[w as usize] == usize::MAX {
                    ring[w as usize] = d;
                    next.push(w);
                }
            }
        }
        front = next;
    }
    weld.class
        .iter()
        .map(|&c| match ring[c as usize] {
            usize::MAX => 0.0,
            d => 1.0 - d as f32 / BORDER_RINGS as f32,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip of two triangles between two rows of three: the outer rows are border, and a
    /// copy of a vertex at the same position (a UV seam) does not make a border.
    #[test]
    fn border_weights_fall_over_the_rings() {
        let p = |x: f32, y: f32| Vec3::new(x, y, 0.0);
        // A 4×4 grid of vertices; its centre 2×2 is one ring inside the border.
        let mut positions = Vec::new();
        for y in 0..4 {
            for x in 0..4 {
                positions.push(p(x as f32, y as f32));
            }
        }
        let mut triangles = Vec::new();
        for y in 0..3u32 {
            for x in 0..3u32 {
                let v = y * 4 + x;
                triangles.push([v, v + 1, v + 5]);
                triangles.push([v, v + 5, v + 4]);
            }
        }
        let w = border_weights(&positions, &triangles);
        assert_eq!(w[0], 1.0);
        assert_eq!(w[3], 1.0);
        assert!((w[5] - (1.0 - 1.0 / BORDER_RINGS as f32)).abs() < 1e-6);
        assert!((w[10] - w[5]).abs() < 1e-6);
        // Split the grid along x = 1.5 by duplicating the vertices of column 1 for the
        // triangles right of it: the same positions weld, no new border appears.
        let mut split = positions.clone();
        let copies: Vec<u32> = (0..4)
            .map(|y| {
                split.push(positions[y * 4 + 1]);
                (split.len() - 1) as u32
            })
            .collect();
        let tris: Vec<[u32; 3]> = triangles
            .iter()
            .map(|t| {
                let right = t.iter().any(|&v| v % 4 >= 2);
                t.map(|v| {
                    if right && v % 4 == 1 {
                        copies[(v / 4) as usize]
                    } else {
                        v
                    }
                })
            })
            .collect();
        let ws = border_weights(&split, &tris);
        assert_eq!(&ws[..16], &w[..]);
        assert_eq!(ws[16 + 1], w[5]);
    }
}
