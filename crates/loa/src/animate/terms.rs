//! Residuals and analytic Jacobians of the energy terms, per frame (E_x, E_∂, E_twist, E_⊥)
//! and per pair of consecutive frames (E_ẋ, LoA Eq. 3).
//!
//! Degrees of freedom are *increments* on the current pose (the paper's scheme: solve, then
//! set `q_j ← q'_j` and the angles back to 0): a rotation column `(a, w)` turns joint `a`'s
//! subtree by an angle about the world axis `w` through `x_a`, i.e. `q_a ← exp(θ R_p⁻¹ w) q_a`
//! (`R_p` the parent's world rotation); a translation column moves every root along `w`. In
//! the planar stage every rotation axis is the action-plane normal `n` (the paper's
//! `q'_j = q_j exp(θ_j n)`), so the parametrization is exact; in the 3D stage each joint has
//! the three world axes.
//!
//! Derivatives at zero increment: a point `x` below joint `a` moves by `w × (x − x_a)`; a
//! world orientation residual `log(Q_j⁻¹ q*)` changes by `−J_l⁻¹(r) Q_j⁻¹ w`; a relative local
//! rotation `log(q_j(t_i+1)⁻¹ q_j(t_i))` by `±J_l⁻¹(r) q_j(t_i+1)⁻¹ R_p⁻¹ w` (`J_l⁻¹` the
//! inverse left Jacobian of SO(3)).

use glam::{DMat3, DQuat, DVec2, DVec3};

use super::bones::ChainPoint;
use super::camera::ActionCamera;
use super::rig::{Rig, WorldPose};

/// One degree of freedom per frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Dof {
    /// Rotation of `joint`'s subtree about the world axis.
    Rot { joint: usize, axis: DVec3 },
    /// Translation of the roots along the world direction.
    Trans { dir: DVec3 },
}

/// The columns of one stage.
#[derive(Debug, Clone)]
pub(crate) struct Columns {
    pub dofs: Vec<Dof>,
    /// First column and count of every joint's rotation columns (count 0: not a DOF).
    pub joint_cols: Vec<(usize, usize)>,
}

impl Columns {
    pub(super) fn new(
        rig: &Rig,
        dof_joints: &[bool],
        axes: &[DVec3],
        translations: &[DVec3],
    ) -> Self {
        let mut dofs = Vec::new();
        let mut joint_cols = vec![(0, 0); rig.len()];
        for j in 0..rig.len() {
            if dof_joints[j] {
                joint_cols[j] = (dofs.len(), axes.len());
                dofs.extend(axes.iter().map(|&axis| Dof::Rot { joint: j, axis }));
            }
        }
        dofs.extend(translations.iter().map(|&dir| Dof::Trans { dir }));
        Columns { dofs, joint_cols }
    }

    pub(super) fn len(&self) -> usize {
        self.dofs.len()
    }
}

/// Inverse left Jacobian of SO(3) at rotation vector `phi`.
pub(crate) fn jl_inv(phi: DVec3) -> DMat3 {
    let t = phi.length();
    let k = skew(phi);
    let c = if t < 1e-6 {
        1.0 / 12.0
    } else {
        1.0 / (t * t) - (1.0 + t.cos()) / (2.0 * t * t.sin())
    };
    DMat3::IDENTITY - 0.5 * k + c * (k * k)
}

fn skew(v: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, v.z, -v.y),
        DVec3::new(-v.z, 0.0, v.x),
        DVec3::new(v.y, -v.x, 0.0),
    )
}

/// Rotation vector (axis × angle, angle in `[0, π]`) of a unit quaternion.
pub(crate) fn log(q: DQuat) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    let v = DVec3::new(q.x, q.y, q.z);
    let s = v.length();
    if s < 1e-12 {
        return 2.0 * v;
    }
    v * (2.0 * s.atan2(q.w) / s)
}

/// Quaternion of a rotation vector.
pub(crate) fn exp(v: DVec3) -> DQuat {
    let t = v.length();
    if t < 1e-300 {
        return DQuat::IDENTITY;
    }
    DQuat::from_axis_angle(v / t, t)
}

/// Accumulates `Σ ‖r‖²` rows into a small dense normal-equation block (`h = JᵀJ`, `g = Jᵀr`).
#[derive(Debug, Clone)]
pub(crate) struct Block {
    pub n: usize,
    pub h: Vec<f64>,
    pub g: Vec<f64>,
    pub cost: f64,
}

impl Block {
    pub(super) fn new(n: usize) -> Block {
        Block {
            n,
            h: vec![0.0; n * n],
            g: vec![0.0; n],
            cost: 0.0,
        }
    }

    pub(super) fn clear(&mut self) {
        self.h.iter_mut().for_each(|x| *x = 0.0);
        self.g.iter_mut().for_each(|x| *x = 0.0);
        self.cost = 0.0;
    }
}

/// A sparse vector residual: the touched columns and the residual's derivative along each.
#[derive(Debug, Clone, Default)]
pub(crate) struct SparseJ<V> {
    pub cols: Vec<usize>,
    pub d: Vec<V>,
}

impl<V: Copy + std::ops::AddAssign> SparseJ<V> {
    pub(super) fn clear(&mut self) {
        self.cols.clear();
        self.d.clear();
    }

    pub(super) fn add(&mut self, col: usize, d: V) {
        if let Some(i) = self.cols.iter().position(|&c| c == col) {
            self.d[i] += d;
        } else {
            self.cols.push(col);
            self.d.push(d);
        }
    }
}

/// A 2D or 3D residual vector.
pub(crate) trait Residual: Copy + std::ops::Mul<f64, Output = Self> {
    fn dot(self, other: Self) -> f64;
}

impl Residual for DVec2 {
    fn dot(self, other: Self) -> f64 {
        DVec2::dot(self, other)
    }
}

impl Residual for DVec3 {
    fn dot(self, other: Self) -> f64 {
        DVec3::dot(self, other)
    }
}

/// Adds `‖s · r‖²` with Jacobian `s · J` to the block (Gauss–Newton: gradient Jᵀr, JᵀJ).
pub(crate) fn add<V: Residual>(block: &mut Block, j: &SparseJ<V>, r: V, s: f64, jacobian: bool) {
    let r = r * s;
    block.cost += r.dot(r);
    if !jacobian {
        return;
    }
    let n = block.n;
    for (p, &cp) in j.cols.iter().enumerate() {
        let dp = j.d[p] * s;
        block.g[cp] += dp.dot(r);
        for (q, &cq) in j.cols.iter().enumerate() {
            block.h[cp * n + cq] += dp.dot(j.d[q] * s);
        }
    }
}

/// World position of a chain point.
#[inline]
pub(crate) fn point_position(rig: &Rig, w: &WorldPose, p: ChainPoint) -> DVec3 {
    match p {
        ChainPoint::Joint(j) => w.position[j],
        ChainPoint::Tip(j) => w.tip(rig, j),
    }
}

/// Adds `sign ·` the derivatives of a point's world position to `out`.
pub(crate) fn point_jacobian(
    rig: &Rig,
    cols: &Columns,
    w: &WorldPose,
    p: ChainPoint,
    sign: f64,
    out: &mut SparseJ<DVec3>,
) {
    let x = point_position(rig, w, p);
    let mut a = match p {
        ChainPoint::Joint(j) => rig.parent[j],
        ChainPoint::Tip(j) => Some(j),
    };
    while let Some(k) = a {
        let (c0, nc) = cols.joint_cols[k];
        for c in c0..c0 + nc {
            if let Dof::Rot { axis, .. } = cols.dofs[c] {
                out.add(c, sign * axis.cross(x - w.position[k]));
            }
        }
        a = rig.parent[k];
    }
    for (c, d) in cols.dofs.iter().enumerate() {
        if let Dof::Trans { dir } = d {
            out.add(c, sign * *dir);
        }
    }
}

/// Projects world-space derivatives at the world point `at` through the camera.
pub(crate) fn project_jacobian(
    camera: &ActionCamera,
    at: DVec3,
    j: &SparseJ<DVec3>,
    out: &mut SparseJ<DVec2>,
) {
    out.clear();
    out.cols.extend_from_slice(&j.cols);
    out.d
        .extend(j.d.iter().map(|d| camera.project_direction(at, *d)));
}

/// Residual `log(Q_j⁻¹ target)` of a world orientation target, and its Jacobian.
pub(crate) fn orientation_residual(
    rig: &Rig,
    cols: &Columns,
    w: &WorldPose,
    joint: usize,
    target: DQuat,
    out: &mut SparseJ<DVec3>,
) -> DVec3 {
    out.clear();
    let qj = w.rotation[joint];
    let r = log(qj.inverse() * target);
    let m = jl_inv(r);
    let mut a = Some(joint);
    while let Some(k) = a {
        let (c0, nc) = cols.joint_cols[k];
        for c in c0..c0 + nc {
            if let Dof::Rot { axis, .. } = cols.dofs[c] {
                out.add(c, -(m * (qj.inverse() * axis)));
            }
        }
        a = rig.parent[k];
    }
    r
}
