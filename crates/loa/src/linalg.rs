//! Small dense linear algebra for `N × N` systems (N ≈ 10) on faer: Cholesky factorization,
//! triangular solves and the symmetric eigendecomposition, on row-major `Vec<f64>` matrices
//! (the layout the chain code builds them in).

use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Mat, Par, Side};

/// A row-major `n × n` slice as a faer matrix.
fn to_mat(a: &[f64], n: usize) -> Mat<f64> {
    Mat::from_fn(n, n, |i, j| a[i * n + j])
}

/// A column vector holding `b`.
fn to_col(b: &[f64], n: usize) -> Mat<f64> {
    Mat::from_fn(n, 1, |i, _| b[i])
}

fn copy_back(x: &Mat<f64>, b: &mut [f64]) {
    for (i, v) in b.iter_mut().enumerate().take(x.nrows()) {
        *v = x[(i, 0)];
    }
}

/// Cholesky factor `L` (`A = L Lᵀ`, row-major, upper triangle zero) of a symmetric
/// positive-definite matrix; `None` when `A` is not numerically positive definite.
pub(crate) fn cholesky(a: &[f64], n: usize) -> Option<Vec<f64>> {
    let llt = to_mat(a, n).llt(Side::Lower).ok()?;
    let l = llt.L();
    let mut out = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            out[i * n + j] = l[(i, j)];
        }
    }
    out.iter().all(|v| v.is_finite()).then_some(out)
}

/// Solves `L y = b` in place (forward substitution).
pub(crate) fn forward(l: &[f64], n: usize, b: &mut [f64]) {
    let mut x = to_col(b, n);
    solve_lower_triangular_in_place(to_mat(l, n).as_ref(), x.as_mut(), Par::Seq);
    copy_back(&x, b);
}

/// Solves `Lᵀ x = y` in place (back substitution).
pub(crate) fn backward(l: &[f64], n: usize, b: &mut [f64]) {
    let mut x = to_col(b, n);
    solve_upper_triangular_in_place(to_mat(l, n).transpose(), x.as_mut(), Par::Seq);
    copy_back(&x, b);
}

/// Solves `L Lᵀ x = b` in place given the Cholesky factor `L`.
pub(crate) fn cholesky_solve(l: &[f64], n: usize, b: &mut [f64]) {
    forward(l, n, b);
    backward(l, n, b);
}

/// Eigen-decomposition of a symmetric matrix (faer's self-adjoint solver): the eigenvalues
/// (ascending) and the eigenvectors as the *columns* of a row-major matrix. A matrix the
/// solver rejects (non-finite entries) gives NaN values instead of an error.
pub(crate) fn symmetric_eigen(a: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    match to_mat(a, n).self_adjoint_eigen(Side::Lower) {
        Ok(evd) => {
            let s = evd.S().column_vector();
            let u = evd.U();
            let values = (0..n).map(|i| s[i]).collect();
            let mut vectors = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    vectors[i * n + j] = u[(i, j)];
                }
            }
            (values, vectors)
        }
        Err(_) => (vec![f64::NAN; n], vec![f64::NAN; n * n]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cholesky_solves_spd_system() {
        let n = 3;
        let a = vec![4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0];
        let l = cholesky(&a, n).unwrap();
        let mut x = vec![1.0, 2.0, 3.0];
        cholesky_solve(&l, n, &mut x);
        for i in 0..n {
            let y: f64 = (0..n).map(|j| a[i * n + j] * x[j]).sum();
            assert!((y - [1.0, 2.0, 3.0][i]).abs() < 1e-12);
        }
        assert!(cholesky(&[1.0, 2.0, 2.0, 1.0], 2).is_none(), "indefinite");
    }

    #[test]
    fn eigen_reconstructs_matrix() {
        for n in [1, 2, 3, 10] {
            let a: Vec<f64> = (0..n * n)
                .map(|k| {
                    let (i, j) = (k / n, k % n);
                    1.0 / (1.0 + i as f64 + j as f64) + if i == j { 2.0 } else { 0.0 }
                })
                .collect();
            let (w, v) = symmetric_eigen(&a, n);
            for i in 0..n {
                for j in 0..n {
                    let r: f64 = (0..n).map(|k| v[i * n + k] * w[k] * v[j * n + k]).sum();
                    assert!((r - a[i * n + j]).abs() < 1e-12, "n={n}");
                    let o: f64 = (0..n).map(|k| v[k * n + i] * v[k * n + j]).sum();
                    assert!((o - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
                }
            }
        }
        // Non-finite input gives a defined (NaN) result instead of an error or a loop.
        let (w, _) = symmetric_eigen(&[f64::NAN, 1.0, 1.0, 2.0], 2);
        assert_eq!(w.len(), 2);
    }
}
