//! The line as an elastic articulated chain (Section 3.2).
//!
//! Generalized coordinates are the chain's local angles `γ` (the root position is kinematic).
//! Each element is a uniform rod of mass `1/N`; its kinetic energy (translation of its centre
//! plus rotation) gives the articulated mass matrix
//!
//! `M_ab = Σ_e m_e (∂c_e/∂γ_a)·(∂c_e/∂γ_b) + I_e (∂θ_e/∂γ_a)(∂θ_e/∂γ_b)`,
//!
//! which couples every joint to all joints that share outboard elements with it: turning one
//! joint drags the rest of the line, so motion propagates along it (overlapping action,
//! follow-through and, for joints whose own target barely moves, anticipation). `M` is
//! evaluated at the pose the simulation starts from (the keystroke) and frozen over the
//! interval — the linearization of the chain's Lagrangian dynamics about that pose.
//!
//! Each joint has an angular spring toward the target angle, as in a uniform elastic rod:
//! `K_rr = k · M_rr` for the root element (the line turning rigidly about its root would swing
//! at `√k` rad/s) and `K_jj = k · M_rr / N` for every bend. The damping is modal: with
//! `M = L Lᵀ` and `L⁻¹ K L⁻ᵀ = Q Ω² Qᵀ`, `D = 2 L Q Z Ω Qᵀ Lᵀ`, so mode `i` has the damping ratio
//! `ζ_i = ζ · max(1, ω_i / √k)`: the slow modes that carry the motion have exactly the ratio
//! `ζ` (critical at `ζ = 1`), faster bending modes get proportionally more (stiffness-
//! proportional damping, like internal friction), so the line does not jitter between frames:
//!
//! `M γ̈ + D γ̇ + K (γ − γ_target) = 0`.
//!
//! Integration uses the implicit midpoint (trapezoidal) rule, which is unconditionally stable
//! for any stiffness and sub-step, and conserves the energy `½ γ̇ᵀ M γ̇ + ½ eᵀ K e` exactly when
//! `ζ = 0` (the system is linear within an interval). Because the rule is invariant under
//! linear changes of variables, it is applied in the modal coordinates `z = Qᵀ Lᵀ e`, where the
//! step is `N` independent 2 × 2 updates; angles are reconstructed as `γ = γ_target + L⁻ᵀ Q z`
//! only when asked for. Time is in seconds.

use glam::DVec2;

use crate::chain::{hierarchy, perp, Chain};
use crate::keystroke::check_non_negative;
use crate::linalg::{backward, cholesky, forward, symmetric_eigen};
use crate::LoaError;

/// A forward-simulated elastic chain with a fixed target shape.
#[derive(Debug, Clone)]
pub struct ElasticChain {
    n: usize,
    mass: Vec<f64>,
    mass_factor: Vec<f64>,
    /// Modal frequencies `ω_i` (rad/s) and damping ratios `ζ_i`.
    omega: Vec<f64>,
    zeta: Vec<f64>,
    /// `T = Qᵀ Lᵀ` (angles → modal) and `T⁻¹ = L⁻ᵀ Q` (modal → angles), row-major.
    to_modal: Vec<f64>,
    to_angles: Vec<f64>,
    target: Vec<f64>,
    /// Modal displacement `z = T (γ − γ_target)` and velocity `ż = T γ̇`.
    z: Vec<f64>,
    zdot: Vec<f64>,
    /// Per-mode step coefficients for the last step size: `ż⁺ = a ż − b z`.
    step: f64,
    coef_a: Vec<f64>,
    coef_b: Vec<f64>,
}

impl ElasticChain {
    /// An elastic chain at rest in `pose`, pulled toward `pose` itself, with angular stiffness
    /// `stiffness` (`k`, 1/s²) and damping ratio `damping` (`ζ`); see the module documentation
    /// for the model.
    pub fn new(pose: &Chain, stiffness: f64, damping: f64) -> Result<Self, LoaError> {
        check_non_negative("stiffness", stiffness)?;
        check_non_negative("damping", damping)?;
        let n = pose.elements();
        let mass = mass_matrix(pose);
        // Unreachable after regularization; fall back to the identity inertia.
        let l = cholesky(&mass, n).unwrap_or_else(|| identity(n));
        let k = stiffness_diagonal(&mass, n, stiffness);
        // A = L⁻¹ K L⁻ᵀ = B Bᵀ with B = L⁻¹ diag(√K).
        let mut b = vec![0.0; n * n];
        let mut col = vec![0.0; n];
        for j in 0..n {
            col.iter_mut().for_each(|c| *c = 0.0);
            col[j] = k[j].max(0.0).sqrt();
            forward(&l, n, &mut col);
            for i in 0..n {
                b[i * n + j] = col[i];
            }
        }
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..=i {
                let v: f64 = (0..n).map(|m| b[i * n + m] * b[j * n + m]).sum();
                a[i * n + j] = v;
                a[j * n + i] = v;
            }
        }
        let (lambda, q) = symmetric_eigen(&a, n);
        let omega_ref = stiffness.sqrt();
        let omega: Vec<f64> = lambda.iter().map(|l| l.max(0.0).sqrt()).collect();
        let zeta = omega
            .iter()
            .map(|&w| {
                if w > omega_ref && omega_ref > 0.0 {
                    damping * w / omega_ref
                } else {
                    damping
                }
            })
            .collect();
        // T = Qᵀ Lᵀ: T_ij = Σ_m Q_mi L_jm.
        let mut to_modal = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                to_modal[i * n + j] = (0..=j).map(|m| q[m * n + i] * l[j * n + m]).sum();
            }
        }
        // T⁻¹ = L⁻ᵀ Q: back-substitute every column of Q.
        let mut to_angles = vec![0.0; n * n];
        for j in 0..n {
            for i in 0..n {
                col[i] = q[i * n + j];
            }
            backward(&l, n, &mut col);
            for i in 0..n {
                to_angles[i * n + j] = col[i];
            }
        }
        Ok(Self {
            n,
            mass,
            mass_factor: l,
            omega,
            zeta,
            to_modal,
            to_angles,
            target: pose.angles().to_vec(),
            z: vec![0.0; n],
            zdot: vec![0.0; n],
            step: f64::NAN,
            coef_a: vec![0.0; n],
            coef_b: vec![0.0; n],
        })
    }

    /// Number of joints (elements).
    pub fn elements(&self) -> usize {
        self.n
    }

    /// Sets the target angles the springs pull toward, keeping the current angles.
    pub fn set_target(&mut self, target: &[f64]) {
        let angles = self.angles();
        for (t, v) in self.target.iter_mut().zip(target) {
            *t = *v;
        }
        let velocities = self.velocities();
        self.set_state(&angles, &velocities);
    }

    /// Sets the angles and angular velocities (rad/s).
    pub fn set_state(&mut self, angles: &[f64], velocities: &[f64]) {
        let n = self.n;
        let e: Vec<f64> = (0..n)
            .map(|j| angles.get(j).copied().unwrap_or(self.target[j]) - self.target[j])
            .collect();
        let v: Vec<f64> = (0..n)
            .map(|j| velocities.get(j).copied().unwrap_or(0.0))
            .collect();
        apply(&self.to_modal, n, &e, &mut self.z);
        apply(&self.to_modal, n, &v, &mut self.zdot);
    }

    /// Current local angles `γ = γ_target + T⁻¹ z`.
    pub fn angles(&self) -> Vec<f64> {
        let mut out = vec![0.0; self.n];
        self.angles_into(&mut out);
        out
    }

    /// Current local angles, written into `out` (`N` values).
    pub fn angles_into(&self, out: &mut [f64]) {
        apply(&self.to_angles, self.n, &self.z, out);
        for (o, t) in out.iter_mut().zip(&self.target) {
            *o += t;
        }
    }

    /// Current angular velocities (rad/s).
    pub fn velocities(&self) -> Vec<f64> {
        let mut out = vec![0.0; self.n];
        apply(&self.to_angles, self.n, &self.zdot, &mut out);
        out
    }

    /// The modal state `(z, ż)`; see [`ElasticChain::modal_to_angles`].
    pub fn modal_state(&self) -> (&[f64], &[f64]) {
        (&self.z, &self.zdot)
    }

    /// The matrix `T⁻¹ = L⁻ᵀ Q` (row-major) mapping modal coordinates to angle offsets.
    pub fn modal_to_angles(&self) -> &[f64] {
        &self.to_angles
    }

    /// The target angles.
    pub fn target(&self) -> &[f64] {
        &self.target
    }

    /// The (frozen) articulated mass matrix, row-major `N × N`.
    pub fn mass_matrix(&self) -> &[f64] {
        &self.mass
    }

    /// Angular frequencies (rad/s) of the undamped vibration modes in the order of the modal
    /// coordinates ([`ElasticChain::modal_state`]).
    pub fn modal_frequencies(&self) -> &[f64] {
        &self.omega
    }

    /// Angular frequencies (rad/s) of the undamped vibration modes, ascending.
    pub fn mode_frequencies(&self) -> Vec<f64> {
        let mut w = self.omega.clone();
        w.sort_by(f64::total_cmp);
        w
    }

    /// Kinetic energy `½ γ̇ᵀ M γ̇ = ½ |ż|²`.
    pub fn kinetic_energy(&self) -> f64 {
        0.5 * self.zdot.iter().map(|v| v * v).sum::<f64>()
    }

    /// Elastic energy `½ eᵀ K e = ½ Σ ω_i² z_i²`.
    pub fn potential_energy(&self) -> f64 {
        0.5 * self
            .z
            .iter()
            .zip(&self.omega)
            .map(|(z, w)| (w * z).powi(2))
            .sum::<f64>()
    }

    /// Total mechanical energy.
    pub fn energy(&self) -> f64 {
        self.kinetic_energy() + self.potential_energy()
    }

    /// Applies an impulse `impulse` (mass × screen units / s; the line has unit mass) at
    /// normalized position `u ∈ [0, 1]` along `pose`: `Δγ̇ = M⁻¹ Jᵀ P`, i.e.
    /// `Δż = Qᵀ L⁻¹ Jᵀ P`.
    pub fn apply_impulse(&mut self, pose: &Chain, u: f64, impulse: DVec2) {
        let n = self.n;
        let r = n / 2;
        if !impulse.is_finite() || pose.elements() != n {
            return;
        }
        let (point, element) = pose.point_at(u);
        let joints = pose.joints();
        let mut g: Vec<f64> = (0..n)
            .map(|a| {
                if hierarchy::moves(r, a, element) {
                    perp(point - joints[hierarchy::pivot(r, a)]).dot(impulse)
                } else {
                    0.0
                }
            })
            .collect();
        // Δγ̇ = M⁻¹ g = L⁻ᵀ L⁻¹ g, then Δż = T Δγ̇.
        forward(&self.mass_factor, n, &mut g);
        backward(&self.mass_factor, n, &mut g);
        let mut y = vec![0.0; n];
        apply(&self.to_modal, n, &g, &mut y);
        for (v, dv) in self.zdot.iter_mut().zip(&y) {
            *v += dv;
        }
    }

    /// Advances by `h` seconds with the implicit midpoint rule, per mode:
    /// `(1 + h²ω²/4 + hc/2) ż⁺ = (1 − h²ω²/4 − hc/2) ż − h ω² z`, `z⁺ = z + h (ż + ż⁺)/2`
    /// (`c = 2ζ_i ω_i`), the same as `(M + h²/4 K + h/2 D) γ̇⁺ = (M − h²/4 K − h/2 D) γ̇ − h K e`.
    pub fn step(&mut self, h: f64) {
        if !(h.is_finite() && h > 0.0) {
            return;
        }
        if h != self.step {
            for i in 0..self.n {
                let (w, c) = (self.omega[i], 2.0 * self.zeta[i] * self.omega[i]);
                let stiff = 0.25 * h * h * w * w + 0.5 * h * c;
                self.coef_a[i] = (1.0 - stiff) / (1.0 + stiff);
                self.coef_b[i] = h * w * w / (1.0 + stiff);
            }
            self.step = h;
        }
        for i in 0..self.n {
            let v = self.zdot[i];
            let v_new = self.coef_a[i] * v - self.coef_b[i] * self.z[i];
            self.z[i] += 0.5 * h * (v + v_new);
            self.zdot[i] = v_new;
        }
    }
}

/// Natural frequency (rad/s) of `pose`'s elastic chain (stiffness `k`) moving rigidly along
/// the angle change `direction`: the Rayleigh quotient `√(dᵀ K d / dᵀ M d)`, i.e. the chain's
/// dynamics reduced to that one degree of freedom (Rayleigh–Ritz). Proportional to `√k`;
/// `√k` itself for a zero direction.
pub(crate) fn change_frequency(pose: &Chain, stiffness: f64, direction: &[f64]) -> f64 {
    let n = pose.elements();
    let mass = mass_matrix(pose);
    let k = stiffness_diagonal(&mass, n, stiffness.max(0.0));
    let mut md = vec![0.0; n];
    apply(&mass, n, direction, &mut md);
    let inertia: f64 = md.iter().zip(direction).map(|(a, b)| a * b).sum();
    let elastic: f64 = k.iter().zip(direction).map(|(a, b)| a * b * b).sum();
    if inertia > 0.0 && elastic.is_finite() && inertia.is_finite() {
        (elastic / inertia).sqrt()
    } else {
        stiffness.max(0.0).sqrt()
    }
}

/// `y = A x` for a row-major `n × n` matrix.
pub(crate) fn apply(a: &[f64], n: usize, x: &[f64], y: &mut [f64]) {
    for i in 0..n {
        y[i] = a[i * n..(i + 1) * n]
            .iter()
            .zip(x)
            .map(|(p, q)| p * q)
            .sum();
    }
}

fn identity(n: usize) -> Vec<f64> {
    let mut m = vec![0.0; n * n];
    for i in 0..n {
        m[i * n + i] = 1.0;
    }
    m
}

/// The articulated mass matrix of `pose` (rods of mass `1/N`), slightly regularized so that
/// zero-length elements keep it positive definite.
pub(crate) fn mass_matrix(pose: &Chain) -> Vec<f64> {
    let n = pose.elements();
    let r = n / 2;
    let joints = pose.joints();
    let m_e = 1.0 / n as f64;
    let mut mass = vec![0.0; n * n];
    let mut column = vec![DVec2::ZERO; n];
    for e in 0..n {
        let centre = 0.5 * (joints[e] + joints[e + 1]);
        let l = pose.lengths()[e];
        let inertia = m_e * l * l / 12.0;
        for (a, c) in column.iter_mut().enumerate() {
            *c = perp(centre - joints[hierarchy::pivot(r, a)]);
        }
        for a in (0..n).filter(|&a| hierarchy::moves(r, a, e)) {
            for b in (0..=a).filter(|&b| hierarchy::moves(r, b, e)) {
                mass[a * n + b] += m_e * column[a].dot(column[b]) + inertia;
            }
        }
    }
    for a in 0..n {
        for b in 0..a {
            mass[b * n + a] = mass[a * n + b];
        }
    }
    let max_diag = (0..n).map(|i| mass[i * n + i]).fold(0.0, f64::max);
    let eps = if max_diag > 0.0 && max_diag.is_finite() {
        1e-9 * max_diag
    } else {
        1.0
    };
    for i in 0..n {
        mass[i * n + i] += eps;
    }
    mass
}

/// Joint springs of a uniform elastic rod: `K_rr = k · M_rr` for the root (the line turning
/// rigidly about its root swings at `√k` rad/s) and `K_jj = k · M_rr / N` for every bend.
pub(crate) fn stiffness_diagonal(mass: &[f64], n: usize, k: f64) -> Vec<f64> {
    let r = n / 2;
    let whole = mass[r * n + r];
    (0..n)
        .map(|j| {
            if j == r {
                k * whole
            } else {
                k * whole / n as f64
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bent_chain() -> Chain {
        let angles = vec![0.3, -0.2, 0.1, 0.4, -0.5, 0.7, 0.2, -0.3, 0.25, 0.1];
        Chain::new(DVec2::new(3.0, 4.0), angles, vec![10.0; 10]).unwrap()
    }

    #[test]
    fn modal_coordinates_round_trip_and_match_the_mass_matrix() {
        let pose = bent_chain();
        let mut chain = ElasticChain::new(&pose, 60.0, 0.3).unwrap();
        let angles: Vec<f64> = pose.angles().iter().map(|a| a + 0.1).collect();
        let velocities: Vec<f64> = (0..10).map(|j| 0.5 - 0.1 * j as f64).collect();
        chain.set_state(&angles, &velocities);
        for (a, b) in chain.angles().iter().zip(&angles) {
            assert!((a - b).abs() < 1e-10);
        }
        for (a, b) in chain.velocities().iter().zip(&velocities) {
            assert!((a - b).abs() < 1e-10);
        }
        let m = chain.mass_matrix();
        let direct: f64 = 0.5
            * (0..10)
                .map(|i| {
                    (0..10)
                        .map(|j| velocities[i] * m[i * 10 + j] * velocities[j])
                        .sum::<f64>()
                })
                .sum::<f64>();
        assert!((chain.kinetic_energy() - direct).abs() < 1e-9 * direct);
        let k = stiffness_diagonal(m, 10, 60.0);
        let elastic: f64 = 0.5 * (0..10).map(|j| k[j] * 0.01).sum::<f64>();
        assert!((chain.potential_energy() - elastic).abs() < 1e-9 * elastic);
    }

    #[test]
    fn modal_step_equals_the_full_trapezoidal_step() {
        // (M + h²/4 K) v⁺ = (M − h²/4 K) v − h K e without damping, solved densely.
        let pose = bent_chain();
        let mut chain = ElasticChain::new(&pose, 60.0, 0.0).unwrap();
        let e: Vec<f64> = (0..10).map(|j| 0.05 * j as f64 - 0.2).collect();
        let angles: Vec<f64> = pose.angles().iter().zip(&e).map(|(a, d)| a + d).collect();
        let v: Vec<f64> = (0..10).map(|j| 0.3 * (j as f64).sin()).collect();
        chain.set_state(&angles, &v);
        let h = 0.01;
        chain.step(h);
        let m = chain.mass_matrix().to_vec();
        let k = stiffness_diagonal(&m, 10, 60.0);
        let mut lhs = m.clone();
        let mut rhs = vec![0.0; 10];
        for i in 0..10 {
            lhs[i * 10 + i] += 0.25 * h * h * k[i];
            rhs[i] = (0..10).map(|j| m[i * 10 + j] * v[j]).sum::<f64>()
                - 0.25 * h * h * k[i] * v[i]
                - h * k[i] * e[i];
        }
        let l = cholesky(&lhs, 10).unwrap();
        crate::linalg::cholesky_solve(&l, 10, &mut rhs);
        for (a, b) in chain.velocities().iter().zip(&rhs) {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
        }
    }
}
