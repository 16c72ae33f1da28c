//! One part's optimization problem: validated inputs and reduced coordinates.

use std::ops::Range;
use std::sync::OnceLock;

use anim::{Aabb, MeshAnimation, MorphAnimation};
use glam::Vec3;
use rayon::prelude::*;

use super::error::{LibraryError, Result};
use super::source::Source;
use super::subspace::{gram_coords, reduce, Subspace, SubspaceOptions};

/// Per-part inputs beyond the animation (all optional).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PartSetup {
    /// Per-vertex saliency weights `w` (Section 3.3); `None` = all 1.
    pub saliency: Option<Vec<f32>>,
    /// Pre-defined pieces (a fully or partially fixed library), model units, one position per
    /// vertex. They take labels `0..fixed.len()`; free pieces follow.
    pub fixed: Vec<Vec<Vec3>>,
    /// Frames that start a new, unrelated clip (the cut vector `c` of StopShop Eq. 12); 0 is implied.
    pub cuts: Vec<usize>,
}

/// One part, ready to be solved for any library size.
///
/// Building it validates the inputs and reduces the frames once (see
/// [`SubspaceOptions`]); [`PartProblem::solve`] can then be called for many sizes cheaply.
#[derive(Debug, Clone)]
pub struct PartProblem<'a> {
    pub(crate) name: String,
    /// The frames, as positions or morph weights.
    pub(crate) src: Source<'a>,
    /// Saliency per vertex (`None` = uniform).
    pub(crate) weights: Option<Vec<f64>>,
    /// Fixed pieces, row-major `fixed × 3m` (model units).
    pub(crate) fixed_rows: Vec<f64>,
    pub(crate) fixed: usize,
    pub(crate) chains: Vec<Range<usize>>,
    /// Reduced coordinates: frames first, then the fixed pieces.
    pub(crate) sub: Subspace,
    /// ‖y_f‖² per frame.
    pub(crate) xx: Vec<f64>,
    /// ‖y_f − y_{f−1}‖² per frame (0 at chain starts).
    pub(crate) dxx: Vec<f64>,
    /// Bounding box over all frames, kept by the first pass that reads every frame (an
    /// energy evaluation) so that a morph clip is not expanded once more for it.
    pub(crate) bounds: OnceLock<Aabb>,
}

/// Columns (coordinates) per parallel block of the mean frame: 32 KiB of `f64`.
const MEAN_BLOCK: usize = 4096;

/// Splits `0..n` at the cuts.
pub(crate) fn chains(n: usize, cuts: &[usize]) -> Result<Vec<Range<usize>>> {
    let mut c: Vec<usize> = cuts.to_vec();
    if let Some(&bad) = c.iter().find(|&&c| c >= n) {
        return Err(LibraryError::BadCut {
            cut: bad,
            frames: n,
        });
    }
    c.push(0);
    c.push(n);
    c.sort_unstable();
    c.dedup();
    Ok(c.windows(2).map(|w| w[0]..w[1]).collect())
}

impl<'a> PartProblem<'a> {
    /// Validates one part and reduces its frames.
    ///
    /// # Arguments
    /// * `anim` — the part's animation (frames × vertices);
    /// * `setup` — saliency, fixed pieces, cuts;
    /// * `subspace` — reduction options;
    /// * `seed` — seed of the random sketch.
    ///
    /// # Errors
    /// [`LibraryError::EmptyPart`], [`LibraryError::BadSaliency`],
    /// [`LibraryError::BadFixedPiece`], [`LibraryError::BadCut`].
    ///
    /// # Performance
    /// The reduction streams centred blocks of frames (see [`SubspaceOptions`]): no copy of
    /// the animation is made.
    pub fn new(
        anim: &'a MeshAnimation,
        setup: &PartSetup,
        subspace: &SubspaceOptions,
        seed: u64,
    ) -> Result<PartProblem<'a>> {
        PartProblem::of(Source::Positions(anim), setup, subspace, seed)
    }

    /// [`PartProblem::new`] for a morph-target clip given as weights: the reduction is exact
    /// in K (+ fixed pieces) dimensions from the Gram matrix of the targets, and the clip is
    /// never expanded into positions (see `docs/stopmo-scale.md`).
    ///
    /// # Errors
    /// As [`PartProblem::new`].
    pub fn morph(
        anim: &'a MorphAnimation,
        setup: &PartSetup,
        subspace: &SubspaceOptions,
        seed: u64,
    ) -> Result<PartProblem<'a>> {
        PartProblem::of(Source::Morph(anim), setup, subspace, seed)
    }

    /// [`PartProblem::new`] for either form of the frames.
    pub(crate) fn of(
        src: Source<'a>,
        setup: &PartSetup,
        subspace: &SubspaceOptions,
        seed: u64,
    ) -> Result<PartProblem<'a>> {
        let name = src.mesh().name.clone();
        let m = src.vertex_count();
        if m == 0 {
            return Err(LibraryError::EmptyPart { part: name });
        }
        let n = src.frame_count();
        let weights = match &setup.saliency {
            None => None,
            Some(w) => {
                let reason = if w.len() != m {
                    Some(format!("{} weights for {m} vertices", w.len()))
                } else if w.iter().any(|v| !v.is_finite() || *v < 0.0) {
                    Some("a weight is negative or not finite".to_string())
                } else if w.iter().all(|&v| v == 0.0) {
                    Some("all weights are zero".to_string())
                } else {
                    None
                };
                if let Some(reason) = reason {
                    return Err(LibraryError::BadSaliency { part: name, reason });
                }
                Some(w.iter().map(|&v| f64::from(v)).collect::<Vec<f64>>())
            }
        };
        let mut fixed_rows = Vec::with_capacity(setup.fixed.len() * 3 * m);
        for (i, piece) in setup.fixed.iter().enumerate() {
            let reason = if piece.len() != m {
                Some(format!("{} positions for {m} vertices", piece.len()))
            } else if !piece.iter().all(|p| p.is_finite()) {
                Some("a position is not finite".to_string())
            } else {
                None
            };
            if let Some(reason) = reason {
                return Err(LibraryError::BadFixedPiece {
                    part: name,
                    piece: i,
                    reason,
                });
            }
            fixed_rows.extend(piece.iter().flat_map(|p| p.to_array().map(f64::from)));
        }
        let chains = chains(n, &setup.cuts)?;

        let scale: Vec<f64> = (0..3 * m)
            .map(|c| weights.as_ref().map_or(1.0, |w| w[c / 3].sqrt()))
            .collect();
        let sub = match src {
            Source::Positions(anim) => dense_coords(anim, &fixed_rows, &scale, subspace, seed)?,
            Source::Morph(anim) => morph_coords(anim, &fixed_rows, &scale)?,
        };
        let q = sub.dim;
        let row = |f: usize| &sub.coords[f * q..(f + 1) * q];
        let xx = (0..n).map(|f| row(f).iter().map(|v| v * v).sum()).collect();
        let mut dxx = vec![0.0; n];
        for ch in &chains {
            for f in ch.start + 1..ch.end {
                dxx[f] = row(f)
                    .iter()
                    .zip(row(f - 1))
                    .map(|(a, b)| (a - b) * (a - b))
                    .sum();
            }
        }
        Ok(PartProblem {
            name,
            src,
            weights,
            fixed_rows,
            fixed: setup.fixed.len(),
            chains,
            sub,
            xx,
            dxx,
            bounds: OnceLock::new(),
        })
    }

    /// Name of the part (its mesh name).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Number of frames.
    pub fn frames(&self) -> usize {
        self.src.frame_count()
    }

    /// Number of vertices.
    pub fn vertices(&self) -> usize {
        self.src.vertex_count()
    }

    /// Number of fixed (pre-defined) pieces.
    pub fn fixed_pieces(&self) -> usize {
        self.fixed
    }

    /// The part's animation when its frames are positions (`None` for morph weights).
    pub fn animation(&self) -> Option<&'a MeshAnimation> {
        match self.src {
            Source::Positions(a) => Some(a),
            Source::Morph(_) => None,
        }
    }

    /// Clips of the frame chain (split at the cuts).
    pub fn chains(&self) -> &[Range<usize>] {
        &self.chains
    }

    /// Fraction of the centred, weighted frame energy kept by the reduction (1 = exact).
    pub fn captured(&self) -> f64 {
        self.sub.captured
    }

    /// Dimension of the reduced coordinates.
    pub fn reduced_dimension(&self) -> usize {
        self.sub.dim
    }

    /// Bounding box of the part over all frames (expanded once for a morph clip, or kept
    /// from an energy evaluation).
    pub(crate) fn bbox(&self) -> Aabb {
        *self.bounds.get_or_init(|| self.src.bbox())
    }

    /// Row-major `frames × dim` reduced coordinates of the frames.
    pub(crate) fn frame_coords(&self) -> &[f64] {
        &self.sub.coords[..self.frames() * self.sub.dim]
    }

    /// The frames' reduced coordinates transposed (`dim × frames`, row-major).
    pub(crate) fn frame_coords_transposed(&self) -> Vec<f64> {
        let (n, q) = (self.frames(), self.sub.dim);
        let y = self.frame_coords();
        let mut t = vec![0.0; n * q];
        for (f, row) in y.chunks_exact(q.max(1)).enumerate() {
            for (c, &v) in row.iter().enumerate() {
                t[c * n + f] = v;
            }
        }
        t
    }

    /// Row-major `fixed × dim` reduced coordinates of the fixed pieces.
    pub(crate) fn fixed_coords(&self) -> &[f64] {
        &self.sub.coords[self.frames() * self.sub.dim..]
    }
}

/// Reduced coordinates of `Z = [X; R_fixed]` (centred on the mean frame, saliency-scaled by
/// `scale` per coordinate) streamed from the positions (see [`reduce`]).
fn dense_coords(
    anim: &MeshAnimation,
    fixed_rows: &[f64],
    scale: &[f64],
    subspace: &SubspaceOptions,
    seed: u64,
) -> Result<Subspace> {
    let (n, m) = (anim.frame_count(), anim.vertex_count());
    // Centred, saliency-scaled rows Z = [X; R_fixed] (x̄ = mean frame).
    // Parallel over column blocks, each summed over the frames in order (the same sums
    // as one sequential pass).
    let mut mean = vec![0.0f64; 3 * m];
    mean.par_chunks_mut(MEAN_BLOCK)
        .enumerate()
        .for_each(|(b, acc)| {
            let (c0, w) = (b * MEAN_BLOCK, acc.len());
            for f in anim.frames() {
                let x: &[f32] = bytemuck::cast_slice(f);
                for (a, &v) in acc.iter_mut().zip(&x[c0..c0 + w]) {
                    *a += f64::from(v);
                }
            }
            acc.iter_mut().for_each(|v| *v /= n as f64);
        });
    let rows = n + fixed_rows.len() / (3 * m);
    // Rows of Z streamed straight from the frames (no second copy of the animation).
    let fill = |r0: usize, out: &mut [f32]| {
        out.par_chunks_mut(3 * m).enumerate().for_each(|(i, row)| {
            let r = r0 + i;
            if r < n {
                let frame: &[f32] = bytemuck::cast_slice(anim.frame(r));
                for (((o, &v), &mu), &s) in row.iter_mut().zip(frame).zip(&mean).zip(scale) {
                    *o = ((f64::from(v) - mu) * s) as f32;
                }
            } else {
                let fixed = &fixed_rows[(r - n) * 3 * m..(r - n + 1) * 3 * m];
                for (c, o) in row.iter_mut().enumerate() {
                    *o = ((fixed[c] - mean[c]) * scale[c]) as f32;
                }
            }
        });
    };
    reduce(&fill, rows, 3 * m, subspace, seed)
}

/// Exact reduced coordinates of `Z` for a morph clip `x_f = b + T w_f`: with the basis
/// `D = [T; R_fixed − b]` (saliency-scaled), a frame is `(w_f − w̄, 0) D` and fixed piece `j`
/// is `(−w̄, e_j) D`, so `Z Zᵀ = C (D Dᵀ) Cᵀ` and `Y = C F` with `F Fᵀ = D Dᵀ` (a
/// `(K + fixed)²` Gram matrix) has `Y Yᵀ = Z Zᵀ`: StopShop Eq. 10 is unchanged.
fn morph_coords(anim: &MorphAnimation, fixed_rows: &[f64], scale: &[f64]) -> Result<Subspace> {
    let (n, m, k) = (anim.frame_count(), anim.vertex_count(), anim.target_count());
    let nf = fixed_rows.len() / (3 * m);
    let t: &[f32] = bytemuck::cast_slice(anim.targets());
    let b: &[f32] = bytemuck::cast_slice(anim.base());
    let basis = |r: usize, c: usize| -> f64 {
        let v = if r < k {
            f64::from(t[r * 3 * m + c])
        } else {
            fixed_rows[(r - k) * 3 * m + c] - f64::from(b[c])
        };
        v * scale[c]
    };
    let wbar = anim.mean_weights();
    let coefficient = |r: usize, j: usize| -> f64 {
        match (r < n, j < k) {
            (true, true) => f64::from(anim.frame_weights(r)[j]) - wbar[j],
            (true, false) => 0.0,
            (false, true) => -wbar[j],
            (false, false) => f64::from(u8::from(r - n == j - k)),
        }
    };
    gram_coords(k + nf, 3 * m, &basis, n + nf, &coefficient)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuts_split_the_chain() {
        assert_eq!(chains(10, &[]).unwrap(), vec![0..10]);
        assert_eq!(chains(10, &[0, 3, 7, 3]).unwrap(), vec![0..3, 3..7, 7..10]);
        assert_eq!(
            chains(10, &[10]),
            Err(LibraryError::BadCut {
                cut: 10,
                frames: 10
            })
        );
    }
}
