//! Library step: the optimal pieces for fixed labels (normal equations of StopShop Eq. 10).
//!
//! # Derivation
//! Write one vertex coordinate across all frames as a row `x ∈ ℝ¹ˣⁿ` of `X` with saliency
//! weight `w`, and the same coordinate of the pieces as `r ∈ ℝ¹ˣᵈ`. With the finite-difference
//! matrix `G` of StopShop Eq. 12 (columns of cut edges are zero), StopShop Eq. 10 restricted to that row is
//!
//! `E = w (x − rS)(x − rS)ᵀ + (λ/2) w (x − rS) G Gᵀ (x − rS)ᵀ = w (x − rS) L (x − rS)ᵀ`,
//! with `L = I + (λ/2) G Gᵀ` (identity plus λ/2 times the chain Laplacian of the clips).
//!
//! Setting `∂E/∂r = −2w (x − rS) L Sᵀ = 0` gives, for every coordinate row at once,
//!
//! `A Rᵀ = B`, with `A = S Sᵀ + (λ/2) S G Gᵀ Sᵀ` (`d × d`) and `B = S L Xᵀ` (`d × 3m`).
//!
//! The printed StopShop Eq. 13 has `A` as `n × n`, `B` with `S G Xᵀ` (wrong dimensions) and λ in place of
//! λ/2. The weight `w` cancels for `w > 0`, so saliency changes the labels, not this step.
//! `S Sᵀ` is the diagonal of label counts and `S G Gᵀ Sᵀ` is the Laplacian of the label
//! transition graph (one edge per non-cut frame pair whose labels differ), so `A` is
//! symmetric positive definite as soon as every free piece is used once ("empty-piece repair").
//! Fixed pieces move to the right-hand side: `A_FF R_F = B_F − A_FX R_X`.

use std::ops::Range;

use anim::MorphAnimation;
use faer::linalg::matmul::matmul;
use faer::linalg::solvers::Solve;
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};
use glam::Vec3;
use rayon::prelude::*;

use super::error::{LibraryError, Result};

/// Rows of a data matrix that can be added into an accumulator.
pub(crate) trait FrameRows: Sync {
    /// Number of columns.
    fn cols(&self) -> usize;
    /// Column granularity of parallel blocks (3 for xyz triples).
    fn align(&self) -> usize;
    /// `out += s · row(f)[c0..c0 + out.len()]`.
    fn axpy(&self, f: usize, c0: usize, s: f64, out: &mut [f64]);
}

/// A row-major `f64` matrix.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Dense<'a> {
    pub data: &'a [f64],
    pub cols: usize,
}

impl FrameRows for Dense<'_> {
    fn cols(&self) -> usize {
        self.cols
    }
    fn align(&self) -> usize {
        1
    }
    fn axpy(&self, f: usize, c0: usize, s: f64, out: &mut [f64]) {
        let row = &self.data[f * self.cols + c0..f * self.cols + c0 + out.len()];
        for (o, v) in out.iter_mut().zip(row) {
            *o += s * v;
        }
    }
}

/// Frame-major vertex positions (`cols = 3 · vertices`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Positions<'a> {
    pub data: &'a [Vec3],
    pub vertices: usize,
}

impl FrameRows for Positions<'_> {
    fn cols(&self) -> usize {
        3 * self.vertices
    }
    fn align(&self) -> usize {
        3
    }
    fn axpy(&self, f: usize, c0: usize, s: f64, out: &mut [f64]) {
        let v0 = c0 / 3;
        let row = &self.data[f * self.vertices + v0..f * self.vertices + v0 + out.len() / 3];
        for (o, p) in out.chunks_exact_mut(3).zip(row) {
            o[0] += s * f64::from(p.x);
            o[1] += s * f64::from(p.y);
            o[2] += s * f64::from(p.z);
        }
    }
}

/// `A = S Sᵀ + (λ/2) S G Gᵀ Sᵀ`, row-major `d × d`.
pub(crate) fn system_matrix(
    labels: &[u32],
    chains: &[Range<usize>],
    lambda: f64,
    d: usize,
) -> Vec<f64> {
    let mut a = vec![0.0; d * d];
    for &l in labels {
        a[l as usize * (d + 1)] += 1.0;
    }
    let h = 0.5 * lambda;
    for ch in chains {
        for f in ch.start + 1..ch.end {
            let (p, q) = (labels[f - 1] as usize, labels[f] as usize);
            if p != q {
                a[p * d + p] += h;
                a[q * d + q] += h;
                a[p * d + q] -= h;
                a[q * d + p] -= h;
            }
        }
    }
    a
}

/// `B = S L X`, row-major `d × cols`, accumulated in f64 and in parallel over column blocks.
///
/// # Performance
/// One streaming pass over the data; `O(d · cols)` memory.
pub(crate) fn right_hand_side<R: FrameRows>(
    rows: &R,
    labels: &[u32],
    chains: &[Range<usize>],
    lambda: f64,
    d: usize,
) -> Vec<f64> {
    let cols = rows.cols();
    let block = (1024 / rows.align()).max(1) * rows.align();
    let h = 0.5 * lambda;
    let mut blocks: Vec<(usize, Vec<f64>)> = (0..cols)
        .step_by(block)
        .map(|c0| (c0, vec![0.0; d * block.min(cols - c0)]))
        .collect();
    blocks.par_iter_mut().for_each(|(c0, acc)| {
        let w = acc.len() / d.max(1);
        for ch in chains {
            for f in ch.clone() {
                let k = labels[f] as usize;
                rows.axpy(f, *c0, 1.0, &mut acc[k * w..(k + 1) * w]);
                if f > ch.start && h != 0.0 {
                    let j = labels[f - 1] as usize;
                    if j != k {
                        // (λ/2)(x_f − x_{f−1}) goes to piece ℓ_f, its negative to ℓ_{f−1}.
                        rows.axpy(f, *c0, h, &mut acc[k * w..(k + 1) * w]);
                        rows.axpy(f - 1, *c0, -h, &mut acc[k * w..(k + 1) * w]);
                        rows.axpy(f, *c0, -h, &mut acc[j * w..(j + 1) * w]);
                        rows.axpy(f - 1, *c0, h, &mut acc[j * w..(j + 1) * w]);
                    }
                }
            }
        }
    });
    let mut b = vec![0.0; d * cols];
    for (c0, acc) in blocks {
        let w = acc.len() / d.max(1);
        for k in 0..d {
            b[k * cols + c0..k * cols + c0 + w].copy_from_slice(&acc[k * w..(k + 1) * w]);
        }
    }
    b
}

/// The right-hand side `S L X` of the full-space library step for a morph clip
/// `x_f = b + T w_f`: `(S L W) T + (S L 1) bᵀ`, so only the pieces are expanded, never the
/// frames (`d × K` and `d × 1` right-hand sides, then one `d × K × 3m` GEMM).
pub(crate) fn morph_right_hand_side(
    anim: &MorphAnimation,
    labels: &[u32],
    chains: &[std::ops::Range<usize>],
    lambda: f64,
    d: usize,
) -> Vec<f64> {
    let (n, m, k) = (anim.frame_count(), anim.vertex_count(), anim.target_count());
    let w: Vec<f64> = (0..n)
        .flat_map(|f| anim.frame_weights(f).iter().map(|&v| f64::from(v)))
        .collect();
    let bw = right_hand_side(&Dense { data: &w, cols: k }, labels, chains, lambda, d);
    let ones = vec![1.0; n];
    let b1 = right_hand_side(
        &Dense {
            data: &ones,
            cols: 1,
        },
        labels,
        chains,
        lambda,
        d,
    );
    let base: &[f32] = bytemuck::cast_slice(anim.base());
    // Each piece's row of the base term on its own task (d × 3m values: 56 MB at StopShop
    // Table-1 scale, which one thread wrote for 0.05 s).
    let mut out = vec![0.0f64; d * base.len()];
    out.par_chunks_mut(base.len().max(1))
        .zip(b1.par_iter())
        .for_each(|(row, &s)| {
            for (o, &v) in row.iter_mut().zip(base) {
                *o = s * f64::from(v);
            }
        });
    if k > 0 {
        let t: &[f32] = bytemuck::cast_slice(anim.targets());
        let t64 = faer::Mat::<f64>::from_fn(k, 3 * m, |j, c| f64::from(t[j * 3 * m + c]));
        matmul(
            MatMut::from_row_major_slice_mut(&mut out, d, 3 * m),
            Accum::Add,
            MatRef::from_row_major_slice(&bw, d, k),
            t64.as_ref(),
            1.0,
            Par::rayon(rayon::current_num_threads().max(1)),
        );
    }
    out
}

/// Solves `A_FF R_F = B_F − A_FX R_X` for the free pieces (indices `fixed..d`).
///
/// # Arguments
/// * `a`, `b` — from [`system_matrix`] and [`right_hand_side`];
/// * `fixed_rows` — row-major `fixed × cols` values of the fixed pieces (indices `0..fixed`).
///
/// # Returns
/// All `d` pieces, row-major `d × cols` (fixed ones copied), solved in place over `b`: the
/// step holds one `d × cols` buffer.
pub(crate) fn solve_pieces(
    a: &[f64],
    mut b: Vec<f64>,
    d: usize,
    cols: usize,
    fixed: usize,
    fixed_rows: &[f64],
) -> Result<Vec<f64>> {
    let nf = d - fixed;
    b[..fixed * cols].copy_from_slice(&fixed_rows[..fixed * cols]);
    if nf == 0 {
        return Ok(b);
    }
    let aff = Mat::<f64>::from_fn(nf, nf, |i, j| a[(i + fixed) * d + j + fixed]);
    let llt = aff
        .llt(Side::Lower)
        .map_err(|e| LibraryError::Numerical(format!("library normal equations: {e:?}")))?;
    // Solved where it stands, row-major (faer takes either layout): no column-major copy of
    // the `pieces × cols` right-hand side in and out (docs/stopmo-scale.md, "Per instruction
    // set, with the same sums").
    let mut rhs = MatMut::from_row_major_slice_mut(&mut b[fixed * cols..], nf, cols);
    if fixed > 0 {
        for i in 0..nf {
            for j in 0..fixed {
                let aij = a[(i + fixed) * d + j];
                if aij != 0.0 {
                    for c in 0..cols {
                        rhs[(i, c)] -= aij * fixed_rows[j * cols + c];
                    }
                }
            }
        }
    }
    llt.solve_in_place(rhs.as_mut());
    Ok(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Direct evaluation of StopShop Eq. 10 for one scalar coordinate row.
    fn energy(x: &[f64], r: &[f64], labels: &[u32], chains: &[Range<usize>], lambda: f64) -> f64 {
        let mut e = 0.0;
        for ch in chains {
            for f in ch.clone() {
                e += (x[f] - r[labels[f] as usize]).powi(2);
                if f > ch.start {
                    let dv =
                        (x[f] - x[f - 1]) - (r[labels[f] as usize] - r[labels[f - 1] as usize]);
                    e += 0.5 * lambda * dv * dv;
                }
            }
        }
        e
    }

    #[test]
    fn normal_equations_minimize_eq10() {
        let x = [0.0, 0.3, 1.1, 2.0, 2.2, 1.0, 0.1, 3.0];
        let labels = [0u32, 0, 1, 2, 2, 1, 0, 2];
        let chains = [0..5, 5..8];
        for lambda in [0.0, 2.0, 7.5] {
            let a = system_matrix(&labels, &chains, lambda, 3);
            let b = right_hand_side(&Dense { data: &x, cols: 1 }, &labels, &chains, lambda, 3);
            let r = solve_pieces(&a, b, 3, 1, 0, &[]).unwrap();
            let e0 = energy(&x, &r, &labels, &chains, lambda);
            // Any perturbation of the solution raises the energy (the minimum is unique).
            for k in 0..3 {
                for eps in [-1e-3, 1e-3] {
                    let mut rp = r.clone();
                    rp[k] += eps;
                    let e1 = energy(&x, &rp, &labels, &chains, lambda);
                    assert!(
                        e1 > e0,
                        "λ={lambda}: perturbing piece {k} lowered {e0} to {e1}"
                    );
                }
            }
        }
        // λ = 0: pieces are the means of their frames (Lloyd's step).
        let a = system_matrix(&labels, &chains, 0.0, 3);
        let b = right_hand_side(&Dense { data: &x, cols: 1 }, &labels, &chains, 0.0, 3);
        let r = solve_pieces(&a, b, 3, 1, 0, &[]).unwrap();
        assert!((r[0] - (0.0 + 0.3 + 0.1) / 3.0).abs() < 1e-12, "{r:?}");
    }

    #[test]
    fn fixed_pieces_stay_and_free_ones_adapt() {
        let x = [0.0, 0.2, 1.0, 1.2, 0.1];
        let labels = [0u32, 0, 1, 1, 0];
        let chains = std::iter::once(0..5).collect::<Vec<_>>();
        let a = system_matrix(&labels, &chains, 2.0, 2);
        let b = right_hand_side(&Dense { data: &x, cols: 1 }, &labels, &chains, 2.0, 2);
        let r = solve_pieces(&a, b, 2, 1, 1, &[5.0]).unwrap();
        assert_eq!(r[0], 5.0);
        let e0 = energy(&x, &r, &labels, &chains, 2.0);
        for eps in [-1e-3, 1e-3] {
            let e1 = energy(&x, &[5.0, r[1] + eps], &labels, &chains, 2.0);
            assert!(e1 > e0, "{e1} <= {e0}");
        }
    }
}
