//! Exact or sketched reduction of a part's frames to low-dimensional coordinates.
//!
//! Every quantity of the block coordinate descent (StopShop Eqs. 10–16) is built from inner products
//! between frames and pieces, and every optimal piece is a linear combination of frames (the
//! normal equations below StopShop Eq. 10 give `R = A⁻¹ S L X`). So the optimization can run on
//! coordinates `Y` with `Y Yᵀ = Z Zᵀ`, where `Z` stacks the (centred, saliency-scaled) frames
//! and the fixed pieces: the energy restricted to that span is unchanged. When `Z` has more
//! rows and columns than [`SubspaceOptions::max_rank`], a randomized range finder (Halko,
//! Martinsson & Tropp 2011) keeps the span capturing all but `tolerance` of ‖Z‖²; the
//! discarded part adds a constant to the energy and is restored by the final full-space
//! library step.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatRef, Par, Side};

use super::error::{LibraryError, Result};
use anim::SplitMix64;

/// Rank of the first random sketch.
pub const DEFAULT_INITIAL_RANK: usize = 96;
/// Largest sketch rank; above it the reduction is approximate.
pub const DEFAULT_MAX_RANK: usize = 384;
/// Fraction of ‖Z‖² the sketch may leave out.
pub const DEFAULT_SUBSPACE_TOLERANCE: f64 = 1e-5;
/// Eigenvalues below this fraction of the largest are dropped from the coordinates.
const EIGEN_FLOOR: f64 = 1e-13;

/// How the frames are reduced before the optimization.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubspaceOptions {
    /// Rank of the first random sketch.
    pub initial_rank: usize,
    /// Largest rank; data needing more is approximated (see [`PartSolution::captured`]).
    ///
    /// [`PartSolution::captured`]: super::PartSolution::captured
    pub max_rank: usize,
    /// Fraction of the centred energy ‖Z‖² that may be discarded.
    pub tolerance: f64,
}

impl Default for SubspaceOptions {
    fn default() -> Self {
        SubspaceOptions {
            initial_rank: DEFAULT_INITIAL_RANK,
            max_rank: DEFAULT_MAX_RANK,
            tolerance: DEFAULT_SUBSPACE_TOLERANCE,
        }
    }
}

/// Coordinates of the rows of `Z` in an orthonormal basis of (most of) their span.
#[derive(Debug, Clone)]
pub(crate) struct Subspace {
    /// Dimension of the coordinates.
    pub dim: usize,
    /// Row-major `rows × dim` coordinates.
    pub coords: Vec<f64>,
    /// Fraction of ‖Z‖² captured (1 when exact).
    pub captured: f64,
}

fn par() -> Par {
    match rayon::current_num_threads() {
        0 | 1 => Par::Seq,
        t => Par::rayon(t),
    }
}

/// Rows of `Z` on demand: `fill(r0, out)` writes rows `r0..r0 + out.len() / cols`,
/// row-major, into `out`. The frames are centred and scaled as they are streamed, so the
/// reduction never holds a second copy of them.
pub(crate) type RowSource<'a> = &'a (dyn Fn(usize, &mut [f32]) + Sync);

/// Bytes of one streamed block of rows (small in unit tests, so that they cross blocks).
const BLOCK_BYTES: usize = if cfg!(test) { 4096 } else { 8 << 20 };

/// Rows streamed per block: a few MiB of `f32` at face sizes.
fn block_rows(cols: usize) -> usize {
    (BLOCK_BYTES / (4 * cols.max(1))).clamp(8, 1024)
}

/// Calls `each(r0, block)` for consecutive row blocks of `Z` (one reused buffer).
fn stream(z: RowSource<'_>, rows: usize, cols: usize, mut each: impl FnMut(usize, &[f32])) {
    let step = block_rows(cols);
    let mut buf = vec![0.0f32; step.min(rows) * cols];
    let mut r0 = 0;
    while r0 < rows {
        let k = step.min(rows - r0);
        let block = &mut buf[..k * cols];
        z(r0, block);
        each(r0, block);
        r0 += k;
    }
}

/// Reduces the row-major `rows × cols` matrix `Z`, streamed from `z`.
///
/// # Performance
/// Exact (a copy) when `cols ≤ max_rank`; a Gram eigendecomposition (`rows² · cols`) when
/// `rows ≤ max_rank`; otherwise two streamed passes of f32 GEMMs of `rows × cols × rank`
/// per sketch attempt, holding one block of rows at a time.
pub(crate) fn reduce(
    z: RowSource<'_>,
    rows: usize,
    cols: usize,
    opts: &SubspaceOptions,
    seed: u64,
) -> Result<Subspace> {
    if cols <= opts.max_rank.max(1) {
        let mut coords = vec![0.0f64; rows * cols];
        stream(z, rows, cols, |r0, block| {
            coords[r0 * cols..r0 * cols + block.len()]
                .iter_mut()
                .zip(block)
                .for_each(|(c, &v)| *c = f64::from(v));
        });
        return Ok(Subspace {
            dim: cols,
            coords,
            captured: 1.0,
        });
    }
    let mut total = 0.0f64;
    if rows <= opts.max_rank {
        let mut z64 = Mat::<f64>::zeros(rows, cols);
        stream(z, rows, cols, |r0, block| {
            for (i, row) in block.chunks_exact(cols).enumerate() {
                for (j, &v) in row.iter().enumerate() {
                    z64[(r0 + i, j)] = f64::from(v);
                    total += f64::from(v) * f64::from(v);
                }
            }
        });
        if total <= 0.0 {
            return Ok(zero(rows));
        }
        let mut gram = Mat::<f64>::zeros(rows, rows);
        matmul(
            gram.as_mut(),
            Accum::Replace,
            z64.as_ref(),
            z64.transpose(),
            1.0,
            par(),
        );
        let coords = eigen_coords(gram.as_ref(), None)?;
        return Ok(Subspace {
            dim: coords.1,
            coords: coords.0,
            captured: 1.0,
        });
    }
    let mut rng = SplitMix64::new(seed, 0x5u64);
    let mut rank = opts.initial_rank.clamp(1, opts.max_rank);
    let mut first = true;
    loop {
        let omega = Mat::<f32>::from_fn(cols, rank, |_, _| rng.normal() as f32);
        let mut sketch = Mat::<f32>::zeros(rows, rank);
        stream(z, rows, cols, |r0, block| {
            let k = block.len() / cols;
            if first {
                total += block
                    .iter()
                    .map(|&v| f64::from(v) * f64::from(v))
                    .sum::<f64>();
            }
            matmul(
                sketch.as_mut().subrows_mut(r0, k),
                Accum::Replace,
                MatRef::from_row_major_slice(block, k, cols),
                omega.as_ref(),
                1.0f32,
                par(),
            );
        });
        first = false;
        if total <= 0.0 {
            return Ok(zero(rows));
        }
        let s64 = Mat::<f64>::from_fn(rows, rank, |i, j| f64::from(sketch[(i, j)]));
        let q = s64.qr().compute_thin_Q();
        let q32 = Mat::<f32>::from_fn(rows, rank, |i, j| q[(i, j)] as f32);
        let mut b = Mat::<f32>::zeros(rank, cols);
        stream(z, rows, cols, |r0, block| {
            let k = block.len() / cols;
            matmul(
                b.as_mut(),
                Accum::Add,
                q32.as_ref().subrows(r0, k).transpose(),
                MatRef::from_row_major_slice(block, k, cols),
                1.0f32,
                par(),
            );
        });
        let b64 = Mat::<f64>::from_fn(rank, cols, |i, j| f64::from(b[(i, j)]));
        let mut bbt = Mat::<f64>::zeros(rank, rank);
        matmul(
            bbt.as_mut(),
            Accum::Replace,
            b64.as_ref(),
            b64.transpose(),
            1.0,
            par(),
        );
        let kept: f64 = (0..rank).map(|i| bbt[(i, i)]).sum();
        let captured = (kept / total).min(1.0);
        if 1.0 - captured <= opts.tolerance || rank >= opts.max_rank || rank >= rows {
            let (coords, dim) = eigen_coords(bbt.as_ref(), Some(q.as_ref()))?;
            return Ok(Subspace {
                dim,
                coords,
                captured,
            });
        }
        rank = (rank * 2).min(opts.max_rank).min(rows);
    }
}

/// Coordinates `Y = C F` of `rows` rows given as combinations `C` (`coefficient(row, j)`) of
/// an `r × cols` basis `D` (`basis(j, col)`), where `F Fᵀ = D Dᵀ` (eigendecomposition of the
/// `r × r` Gram matrix, which a Cholesky factor would not survive when the basis is
/// dependent): `Y Yᵀ = (C D)(C D)ᵀ` exactly, in at most `r` dimensions.
pub(crate) fn gram_coords(
    r: usize,
    cols: usize,
    basis: &(dyn Fn(usize, usize) -> f64 + Sync),
    rows: usize,
    coefficient: &(dyn Fn(usize, usize) -> f64 + Sync),
) -> Result<Subspace> {
    if r == 0 {
        return Ok(zero(rows));
    }
    let d = Mat::<f64>::from_fn(r, cols, basis);
    let mut gram = Mat::<f64>::zeros(r, r);
    matmul(
        gram.as_mut(),
        Accum::Replace,
        d.as_ref(),
        d.transpose(),
        1.0,
        par(),
    );
    if (0..r).all(|i| gram[(i, i)] <= 0.0) {
        return Ok(zero(rows));
    }
    let (f, dim) = eigen_coords(gram.as_ref(), None)?;
    let f = MatRef::from_row_major_slice(&f, r, dim);
    let c = Mat::<f64>::from_fn(rows, r, coefficient);
    let mut coords = vec![0.0; rows * dim];
    matmul(
        faer::MatMut::from_row_major_slice_mut(&mut coords, rows, dim),
        Accum::Replace,
        c.as_ref(),
        f,
        1.0,
        par(),
    );
    Ok(Subspace {
        dim,
        coords,
        captured: 1.0,
    })
}

/// The reduction of all-zero rows: one zero coordinate each.
fn zero(rows: usize) -> Subspace {
    Subspace {
        dim: 1,
        coords: vec![0.0; rows],
        captured: 1.0,
    }
}

/// Coordinates `Y = Q U √Λ` from the eigendecomposition `M = U Λ Uᵀ` (`Q = I` when `None`),
/// so that `Y Yᵀ = Q M Qᵀ`. Returns row-major coordinates and their dimension.
fn eigen_coords(m: MatRef<'_, f64>, q: Option<MatRef<'_, f64>>) -> Result<(Vec<f64>, usize)> {
    let evd = m
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| LibraryError::Numerical(format!("subspace eigendecomposition: {e:?}")))?;
    let s = evd.S().column_vector();
    let u = evd.U();
    let k = m.nrows();
    let top = (0..k).map(|i| s[i]).fold(0.0f64, f64::max);
    let keep: Vec<usize> = (0..k).rev().filter(|&i| s[i] > EIGEN_FLOOR * top).collect();
    let dim = keep.len().max(1);
    let mut us = Mat::<f64>::zeros(k, dim);
    for (c, &i) in keep.iter().enumerate() {
        let sq = s[i].max(0.0).sqrt();
        for r in 0..k {
            us[(r, c)] = u[(r, i)] * sq;
        }
    }
    let y = match q {
        Some(q) => {
            let mut y = Mat::<f64>::zeros(q.nrows(), dim);
            matmul(y.as_mut(), Accum::Replace, q, us.as_ref(), 1.0, par());
            y
        }
        None => us,
    };
    let rows = y.nrows();
    let mut coords = vec![0.0; rows * dim];
    for r in 0..rows {
        for c in 0..dim {
            coords[r * dim + c] = y[(r, c)];
        }
    }
    Ok((coords, dim))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gram(c: &[f64], rows: usize, dim: usize) -> Vec<f64> {
        let mut g = vec![0.0; rows * rows];
        for i in 0..rows {
            for j in 0..rows {
                g[i * rows + j] = (0..dim).map(|k| c[i * dim + k] * c[j * dim + k]).sum();
            }
        }
        g
    }

    /// `z` as a row source.
    fn rows_of(z: &[f32], cols: usize) -> impl Fn(usize, &mut [f32]) + Sync + '_ {
        move |r0, out: &mut [f32]| out.copy_from_slice(&z[r0 * cols..r0 * cols + out.len()])
    }

    fn low_rank(rows: usize, cols: usize, rank: usize) -> Vec<f32> {
        let mut rng = SplitMix64::new(3, 0);
        let a: Vec<f64> = (0..rows * rank).map(|_| rng.normal()).collect();
        let b: Vec<f64> = (0..rank * cols).map(|_| rng.normal()).collect();
        (0..rows * cols)
            .map(|i| {
                let (r, c) = (i / cols, i % cols);
                (0..rank)
                    .map(|k| a[r * rank + k] * b[k * cols + c])
                    .sum::<f64>() as f32
            })
            .collect()
    }

    #[test]
    fn gram_path_preserves_inner_products() {
        let (rows, cols) = (12, 40);
        let z = low_rank(rows, cols, 12);
        let opts = SubspaceOptions {
            max_rank: 16,
            ..Default::default()
        };
        let s = reduce(&rows_of(&z, cols), rows, cols, &opts, 1).unwrap();
        let z64: Vec<f64> = z.iter().map(|&v| f64::from(v)).collect();
        let (g0, g1) = (gram(&z64, rows, cols), gram(&s.coords, rows, s.dim));
        let err = g0
            .iter()
            .zip(&g1)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-3, "max Gram error {err}");
    }

    #[test]
    fn sketch_captures_low_rank_data() {
        let (rows, cols) = (60, 90);
        let z = low_rank(rows, cols, 5);
        let opts = SubspaceOptions {
            initial_rank: 8,
            max_rank: 20,
            tolerance: 1e-6,
        };
        let s = reduce(&rows_of(&z, cols), rows, cols, &opts, 2).unwrap();
        assert!(s.captured > 1.0 - 1e-5, "captured {}", s.captured);
        assert!(s.dim <= 8, "dim {}", s.dim);
        let z64: Vec<f64> = z.iter().map(|&v| f64::from(v)).collect();
        let (g0, g1) = (gram(&z64, rows, cols), gram(&s.coords, rows, s.dim));
        let scale = g0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let err = g0
            .iter()
            .zip(&g1)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-4 * scale, "max Gram error {err} of {scale}");
    }
}
