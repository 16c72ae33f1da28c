//! Fitting a chain of equal rigid elements to a stroke (Section 3.1, LoA Eq. 1).

use glam::DVec2;

use crate::chain::{check_element_count, hierarchy, perp, Chain};
use crate::linalg::{cholesky, cholesky_solve};
use crate::stroke::Stroke;
use crate::LoaError;

/// Number of rigid elements per line used by the paper (`N = 10`).
pub const DEFAULT_ELEMENTS: usize = 10;

/// Maximum Levenberg–Marquardt iterations of the angle fit.
const MAX_ITERATIONS: usize = 100;

/// How well a chain matches its stroke: the value of LoA Eq. 1 and friendlier summaries.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FitResidual {
    /// `Σ_j ‖x_stroke(l·j) − x_loa(s_j)‖²`, the minimized objective of LoA Eq. 1 (squared screen
    /// units).
    pub sum_squares: f64,
    /// Root-mean-square joint distance over the `N` non-root joints (screen units).
    pub rms: f64,
    /// Largest joint distance (screen units).
    pub max: f64,
    /// `rms` divided by the stroke's arc length (scale-free).
    pub relative_rms: f64,
    /// Levenberg–Marquardt iterations used.
    pub iterations: usize,
}

/// A fitted chain and its residual.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainFit {
    /// The fitted chain: root at `x_stroke(0.5)`, `N` elements of length `l = L / N`.
    pub chain: Chain,
    /// The fit residual of LoA Eq. 1.
    pub residual: FitResidual,
}

/// Fits `elements` rigid elements of equal length to `stroke` (LoA Eq. 1).
///
/// The stroke is parametrized by arc length, each element gets `l = L / N`, the root is placed
/// at `x_stroke(0.5)` and the local angles minimize `Σ_j ‖x_stroke(l·j) − x_loa(s_j)‖²` with
/// Levenberg–Marquardt on the analytic Jacobian, starting from the chord directions.
/// `elements` must be even and at least 2.
pub fn fit_chain(stroke: &Stroke, elements: usize) -> Result<ChainFit, LoaError> {
    check_element_count(elements)?;
    let n = elements;
    let r = n / 2;
    let targets = stroke.resample(n);
    let l = stroke.length() / n as f64;
    let initial = Chain::from_joints(&targets)?;
    let mut chain = Chain::new(initial.root(), initial.angles().to_vec(), vec![l; n])?;

    let mut joints = chain.joints();
    let mut cost = cost_of(&joints, &targets);
    let mut lambda = 1e-3;
    let mut jtj = vec![0.0; n * n];
    let mut jtr = vec![0.0; n];
    let mut iterations = 0;
    let scale = stroke.length().max(f64::MIN_POSITIVE);
    for it in 0..MAX_ITERATIONS {
        iterations = it + 1;
        // Normal equations JᵀJ δ = −Jᵀ res, with J_ia = ∂x_i/∂γ_a = perp(x_i − x_pivot(a)).
        jtj.iter_mut().for_each(|v| *v = 0.0);
        jtr.iter_mut().for_each(|v| *v = 0.0);
        let mut columns = vec![DVec2::ZERO; n];
        for i in (0..=n).filter(|&i| i != r) {
            let e = if i > r { i - 1 } else { i };
            for (a, c) in columns.iter_mut().enumerate() {
                *c = if hierarchy::moves(r, a, e) {
                    perp(joints[i] - joints[hierarchy::pivot(r, a)])
                } else {
                    DVec2::ZERO
                };
            }
            let res = joints[i] - targets[i];
            for a in 0..n {
                jtr[a] += columns[a].dot(res);
                for b in 0..=a {
                    jtj[a * n + b] += columns[a].dot(columns[b]);
                }
            }
        }
        for a in 0..n {
            for b in 0..a {
                jtj[b * n + a] = jtj[a * n + b];
            }
        }
        let gradient = jtr.iter().fold(0.0f64, |m, g| m.max(g.abs()));
        if gradient <= 1e-14 * scale * scale {
            break;
        }
        // Try damped steps until one decreases the cost.
        let mut accepted = false;
        for _ in 0..30 {
            let mut a = jtj.clone();
            for k in 0..n {
                a[k * n + k] += lambda * (jtj[k * n + k] + 1e-12 * scale * scale);
            }
            let mut step: Vec<f64> = jtr.iter().map(|g| -g).collect();
            let Some(l) = cholesky(&a, n) else {
                lambda *= 10.0;
                continue;
            };
            cholesky_solve(&l, n, &mut step);
            let mut trial = chain.clone();
            for (g, d) in trial.angles_mut().iter_mut().zip(&step) {
                *g += d;
            }
            let trial_joints = trial.joints();
            let trial_cost = cost_of(&trial_joints, &targets);
            if trial_cost.is_finite() && trial_cost <= cost {
                let small = step.iter().fold(0.0f64, |m, d| m.max(d.abs())) < 1e-13;
                let converged = small || cost - trial_cost <= 1e-15 * cost.max(1e-300);
                chain = trial;
                joints = trial_joints;
                cost = trial_cost;
                lambda = (lambda / 3.0).max(1e-12);
                accepted = !converged;
                break;
            }
            lambda *= 4.0;
        }
        if !accepted {
            break;
        }
    }
    // Keep the bends in (−π, π] (the root angle is unwrapped later against neighbouring keys).
    for (j, g) in chain.angles_mut().iter_mut().enumerate() {
        if j != r {
            *g = crate::chain::wrap_angle(*g);
        }
    }
    let joints = chain.joints();
    let sum_squares = cost_of(&joints, &targets);
    let max = joints
        .iter()
        .zip(&targets)
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, f64::max);
    let rms = (sum_squares / n as f64).sqrt();
    Ok(ChainFit {
        chain,
        residual: FitResidual {
            sum_squares,
            rms,
            max,
            relative_rms: rms / scale,
            iterations,
        },
    })
}

fn cost_of(joints: &[DVec2], targets: &[DVec2]) -> f64 {
    joints
        .iter()
        .zip(targets)
        .map(|(a, b)| (*a - *b).length_squared())
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_stroke_fits_exactly() {
        let s = Stroke::new([DVec2::new(-3.0, 1.0), DVec2::new(7.0, 1.0)]).unwrap();
        let fit = fit_chain(&s, DEFAULT_ELEMENTS).unwrap();
        assert!(fit.residual.max < 1e-9, "{:?}", fit.residual);
        assert!((fit.chain.root() - DVec2::new(2.0, 1.0)).length() < 1e-12);
        assert!(fit.chain.lengths().iter().all(|l| (l - 1.0).abs() < 1e-12));
    }

    #[test]
    fn circular_arc_fit_beats_chord_initialization() {
        // Half circle of radius 10: chords are shorter than l, so the initial guess is off.
        let pts: Vec<DVec2> = (0..=200)
            .map(|i| {
                let t = std::f64::consts::PI * i as f64 / 200.0;
                DVec2::new(10.0 * t.cos(), 10.0 * t.sin())
            })
            .collect();
        let s = Stroke::new(pts).unwrap();
        let fit = fit_chain(&s, DEFAULT_ELEMENTS).unwrap();
        let initial = Chain::from_joints(&s.resample(10)).unwrap();
        let init = Chain::new(
            initial.root(),
            initial.angles().to_vec(),
            vec![s.length() / 10.0; 10],
        )
        .unwrap();
        let init_cost = cost_of(&init.joints(), &s.resample(10));
        assert!(
            fit.residual.sum_squares < init_cost,
            "{} vs {init_cost}",
            fit.residual.sum_squares
        );
        assert!(fit.residual.relative_rms < 0.01, "{:?}", fit.residual);
    }
}
