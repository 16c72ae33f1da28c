//! Space-time Levenberg–Marquardt over the Hermite-reduced degrees of freedom (Section 4).
//!
//! Each iteration evaluates every frame's residuals and analytic Jacobians in parallel
//! (rayon), folds them into small per-frame normal-equation blocks `JᵀJ`, maps the blocks onto
//! the `(2N − 1) × columns` node unknowns through the reduction's basis weights (each frame
//! touches at most four nodes, so the system is banded in node order), adds the pair terms of
//! LoA Eq. 3 between consecutive frames, and solves the damped system with a dense Cholesky
//! factorization (faer; a few hundred unknowns). Accepted steps are folded into the pose
//! (`q ← q'`, increments back to 0), as in the paper.

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use glam::{DQuat, DVec3};
use rayon::prelude::*;

use super::camera::ActionCamera;
use super::reduction::Reduction;
use super::rig::{Rig, WorldPose};
use super::targets::FrameTargets;
use super::terms::{
    add, exp, jl_inv, log, orientation_residual, point_jacobian, point_position, project_jacobian,
    Block, Columns, Dof, SparseJ,
};
use super::Weights;

/// Initial Levenberg–Marquardt damping (relative to the normal matrix's diagonal).
pub const DEFAULT_INITIAL_DAMPING: f64 = 1e-3;
/// Stop when an accepted step lowers the energy by less than this fraction. On the bench's
/// 5 keystrokes × 120 frames, 1e-7 took 40 iterations in the final planar stage for an energy
/// 0.004 % lower than 1e-5's 28 (the tail creeps by ~1e-6 per step).
pub const DEFAULT_TOLERANCE: f64 = 1e-5;
/// Tolerance of a staging solve whose solution only starts the next one (the planar stage's
/// first solve, with the turn joints held): the next solve refines it anyway. On the bench it
/// stops after 5 iterations instead of 57, 0.03 % above the energy it would creep down to.
pub const STAGING_TOLERANCE: f64 = 1e-3;

/// Largest rotation (radians) of any node in one step.
pub(super) const MAX_STEP_ANGLE: f64 = 0.35;

/// Pose of every frame: local rotations (frames × joints) and the root offset per frame.
#[derive(Debug, Clone)]
pub(crate) struct Poses {
    pub joints: usize,
    pub rotations: Vec<DQuat>,
    pub offsets: Vec<DVec3>,
}

impl Poses {
    pub(super) fn frames(&self) -> usize {
        self.offsets.len()
    }

    pub(super) fn frame(&self, f: usize) -> &[DQuat] {
        &self.rotations[f * self.joints..(f + 1) * self.joints]
    }

    pub(super) fn worlds(&self, rig: &Rig) -> Vec<WorldPose> {
        (0..self.frames())
            .into_par_iter()
            .map(|f| rig.world(self.frame(f), self.offsets[f]))
            .collect()
    }
}

/// What one stage did.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct StageReport {
    /// Unknowns (nodes × degrees of freedom per frame).
    pub unknowns: usize,
    /// Accepted iterations.
    pub iterations: usize,
    /// Energy before.
    pub initial_energy: f64,
    /// Energy after.
    pub final_energy: f64,
}

/// One optimization stage (planar or 3D).
pub(crate) struct Stage<'a> {
    pub rig: &'a Rig,
    pub camera: &'a ActionCamera,
    pub cols: Columns,
    pub targets: &'a [FrameTargets],
    pub reduction: &'a Reduction,
    pub weights: &'a Weights,
    /// Length normalizing image distances (the longest chain).
    pub ref_length: f64,
    /// Body height normalizing 3D distances.
    pub height: f64,
}

#[derive(Default)]
struct Scratch {
    j3: SparseJ<DVec3>,
    j2: SparseJ<glam::DVec2>,
}

impl Stage<'_> {
    fn frame_block(&self, f: usize, w: &WorldPose, jac: bool, b: &mut Block, s: &mut Scratch) {
        b.clear();
        let t = &self.targets[f];
        let (rig, cam, cols) = (self.rig, self.camera, &self.cols);
        let sx = self.weights.position.sqrt() / self.ref_length;
        for p in &t.points {
            let x = point_position(rig, w, p.point);
            let r = cam.project(x) - p.target;
            if jac {
                s.j3.clear();
                point_jacobian(rig, cols, w, p.point, 1.0, &mut s.j3);
                project_jacobian(cam, x, &s.j3, &mut s.j2);
            }
            add(b, &s.j2, r, sx * p.weight.sqrt(), jac);
        }
        let st = self.weights.tangent.sqrt();
        for g in &t.segments {
            let (pa, pb) = (point_position(rig, w, g.a), point_position(rig, w, g.b));
            // The segment's direction projected at its midpoint (exact for orthographic
            // cameras; the local perspective scale otherwise).
            let mid = 0.5 * (pa + pb);
            let r = cam.project_direction(mid, pb - pa) * g.inv_length - g.tangent;
            if jac {
                s.j3.clear();
                point_jacobian(rig, cols, w, g.b, g.inv_length, &mut s.j3);
                point_jacobian(rig, cols, w, g.a, -g.inv_length, &mut s.j3);
                project_jacobian(cam, mid, &s.j3, &mut s.j2);
            }
            add(b, &s.j2, r, st * g.weight.sqrt(), jac);
        }
        let sq = self.weights.twist.sqrt();
        for o in &t.twists {
            let r = orientation_residual(rig, cols, w, o.joint, o.rotation, &mut s.j3);
            add(b, &s.j3, r, sq, jac);
        }
        let scp = self.weights.contact_position.sqrt() / self.height;
        let sco = self.weights.contact_orientation.sqrt();
        for c in &t.contacts {
            let r = w.position[c.joint] - c.position;
            s.j3.clear();
            if jac {
                let p = super::bones::ChainPoint::Joint(c.joint);
                point_jacobian(rig, cols, w, p, 1.0, &mut s.j3);
            }
            add(b, &s.j3, r, scp, jac);
            let r = orientation_residual(rig, cols, w, c.joint, c.rotation, &mut s.j3);
            add(b, &s.j3, r, sco, jac);
        }
    }

    /// LoA Eq. 3 between frames `i` and `i + 1`, plus a weak smoothness of the unconstrained
    /// degrees of freedom; adds to the global system when `h` is given. Returns the energy.
    fn pair_terms(
        &self,
        poses: &Poses,
        worlds: &[WorldPose],
        mut sys: Option<(&mut [f64], &mut [f64])>,
    ) -> f64 {
        let nc = self.cols.len();
        let n = self.reduction.nodes() * nc;
        let mut cost = 0.0;
        let mut row: Vec<(usize, DVec3)> = Vec::new();
        let add_row =
            |row: &[(usize, DVec3)], r: DVec3, sys: &mut Option<(&mut [f64], &mut [f64])>| {
                if let Some((h, g)) = sys {
                    for &(p, dp) in row {
                        g[p] += dp.dot(r);
                        for &(q, dq) in row {
                            h[p * n + q] += dp.dot(dq);
                        }
                    }
                }
            };
        let wts = &self.reduction.weights;
        for i in 0..poses.frames().saturating_sub(1) {
            let (qi, qn) = (poses.frame(i), poses.frame(i + 1));
            for j in 0..self.rig.len() {
                let (c0, k) = self.cols.joint_cols[j];
                if k == 0 {
                    continue;
                }
                let constrained = self.targets[i].bones.contains(&j);
                let w = self.weights.smoothness
                    * if constrained {
                        1.0
                    } else {
                        self.weights.free_smoothness
                    };
                let s = w.sqrt();
                let r0 = log(qn[j].inverse() * qi[j]);
                let r = r0 * s;
                cost += r.length_squared();
                if sys.is_none() {
                    continue;
                }
                let m = jl_inv(r0) * s;
                let (rpi, rpn) = (
                    self.rig.parent_rotation(&worlds[i], j),
                    self.rig.parent_rotation(&worlds[i + 1], j),
                );
                row.clear();
                for c in c0..c0 + k {
                    let Dof::Rot { axis, .. } = self.cols.dofs[c] else {
                        continue;
                    };
                    let di = m * (qn[j].inverse() * (rpi.inverse() * axis));
                    let dn = -(m * (qn[j].inverse() * (rpn.inverse() * axis)));
                    row.extend(wts[i].iter().map(|&(node, bw)| (node * nc + c, di * bw)));
                    row.extend(
                        wts[i + 1]
                            .iter()
                            .map(|&(node, bw)| (node * nc + c, dn * bw)),
                    );
                }
                add_row(&row, r, &mut sys);
            }
            // Root velocity.
            let s = self.weights.root_velocity.sqrt() / self.ref_length;
            let r = (poses.offsets[i + 1] - poses.offsets[i]) * s;
            cost += r.length_squared();
            if sys.is_some() {
                row.clear();
                for (c, d) in self.cols.dofs.iter().enumerate() {
                    if let Dof::Trans { dir } = d {
                        row.extend(
                            wts[i]
                                .iter()
                                .map(|&(node, bw)| (node * nc + c, -*dir * s * bw)),
                        );
                        row.extend(
                            wts[i + 1]
                                .iter()
                                .map(|&(node, bw)| (node * nc + c, *dir * s * bw)),
                        );
                    }
                }
                add_row(&row, r, &mut sys);
            }
        }
        cost
    }

    /// Regularization scale of column `c` (pulls the accumulated increments toward 0).
    fn reg_scale(&self, c: usize) -> f64 {
        let s = self.weights.regularization.sqrt();
        match self.cols.dofs[c] {
            Dof::Rot { .. } => s,
            Dof::Trans { .. } => s / self.ref_length,
        }
    }

    fn energy(&self, poses: &Poses, worlds: &[WorldPose], total: &[f64]) -> f64 {
        let nc = self.cols.len();
        let frames: f64 = worlds
            .par_iter()
            .enumerate()
            .map_init(
                || (Block::new(nc), Scratch::default()),
                |(b, s), (f, w)| {
                    self.frame_block(f, w, false, b, s);
                    b.cost
                },
            )
            .sum();
        let reg: f64 = total
            .iter()
            .enumerate()
            .map(|(i, x)| (x * self.reg_scale(i % nc)).powi(2))
            .sum();
        frames + self.pair_terms(poses, worlds, None) + reg
    }

    /// Applies node increments `delta` to every frame.
    fn apply(&self, poses: &Poses, worlds: &[WorldPose], delta: &[f64]) -> Poses {
        let nc = self.cols.len();
        let nj = self.rig.len();
        let mut out = poses.clone();
        out.rotations
            .par_chunks_mut(nj)
            .zip(out.offsets.par_iter_mut())
            .enumerate()
            .for_each(|(f, (rot, off))| {
                let v = |c: usize| -> f64 {
                    self.reduction.weights[f]
                        .iter()
                        .map(|&(m, b)| b * delta[m * nc + c])
                        .sum()
                };
                for j in 0..nj {
                    let (c0, k) = self.cols.joint_cols[j];
                    if k == 0 {
                        continue;
                    }
                    let mut omega = DVec3::ZERO;
                    for c in c0..c0 + k {
                        if let Dof::Rot { axis, .. } = self.cols.dofs[c] {
                            omega += axis * v(c);
                        }
                    }
                    let rp = self.rig.parent_rotation(&worlds[f], j);
                    rot[j] = (exp(rp.inverse() * omega) * rot[j]).normalize();
                }
                for (c, d) in self.cols.dofs.iter().enumerate() {
                    if let Dof::Trans { dir } = d {
                        *off += *dir * v(c);
                    }
                }
            });
        out
    }

    /// Runs Levenberg–Marquardt from `poses` for at most `max_iterations` accepted steps,
    /// stopping when an accepted step lowers the energy by less than the fraction
    /// `tolerance`.
    pub(super) fn solve(
        &self,
        poses: &mut Poses,
        max_iterations: usize,
        tolerance: f64,
    ) -> StageReport {
        let nc = self.cols.len();
        let nodes = self.reduction.nodes();
        let n = nodes * nc;
        let mut total = vec![0.0; n];
        let mut worlds = poses.worlds(self.rig);
        let mut energy = self.energy(poses, &worlds, &total);
        let mut report = StageReport {
            unknowns: n,
            initial_energy: energy,
            final_energy: energy,
            iterations: 0,
        };
        if n == 0 {
            return report;
        }
        let mut lambda = DEFAULT_INITIAL_DAMPING;
        let mut h = vec![0.0; n * n];
        let mut g = vec![0.0; n];
        while report.iterations < max_iterations {
            // Normal equations.
            h.iter_mut().for_each(|x| *x = 0.0);
            g.iter_mut().for_each(|x| *x = 0.0);
            let blocks: Vec<Block> = worlds
                .par_iter()
                .enumerate()
                .map_init(Scratch::default, |s, (f, w)| {
                    let mut b = Block::new(nc);
                    self.frame_block(f, w, true, &mut b, s);
                    b
                })
                .collect();
            for (f, b) in blocks.iter().enumerate() {
                let wf = &self.reduction.weights[f];
                for &(m, bm) in wf {
                    for a in 0..nc {
                        g[m * nc + a] += bm * b.g[a];
                    }
                    for &(m2, bm2) in wf {
                        let s = bm * bm2;
                        for a in 0..nc {
                            let row = (m * nc + a) * n + m2 * nc;
                            let src = &b.h[a * nc..(a + 1) * nc];
                            for (dst, v) in h[row..row + nc].iter_mut().zip(src) {
                                *dst += s * v;
                            }
                        }
                    }
                }
            }
            self.pair_terms(poses, &worlds, Some((&mut h, &mut g)));
            for i in 0..n {
                let s = self.reg_scale(i % nc).powi(2);
                h[i * n + i] += s;
                g[i] += s * total[i];
            }
            // Damped solves until a step lowers the energy.
            let mut accepted = false;
            for _ in 0..10 {
                let a = Mat::<f64>::from_fn(n, n, |i, j| {
                    let v = h[i * n + j];
                    if i == j {
                        v + lambda * (v + 1e-9)
                    } else {
                        v
                    }
                });
                let Ok(llt) = a.llt(Side::Lower) else {
                    lambda *= 10.0;
                    continue;
                };
                let mut rhs = Mat::<f64>::from_fn(n, 1, |i, _| -g[i]);
                llt.solve_in_place(rhs.as_mut());
                let mut delta: Vec<f64> = (0..n).map(|i| rhs[(i, 0)]).collect();
                // Trust region on rotations: a step never turns a node by more than
                // MAX_STEP_ANGLE, so angles cannot wrap around to an equivalent pose.
                let biggest = (0..n)
                    .filter(|&i| matches!(self.cols.dofs[i % nc], Dof::Rot { .. }))
                    .map(|i| delta[i].abs())
                    .fold(0.0, f64::max);
                if biggest > MAX_STEP_ANGLE {
                    let s = MAX_STEP_ANGLE / biggest;
                    delta.iter_mut().for_each(|d| *d *= s);
                }
                if delta.iter().any(|d| !d.is_finite()) {
                    lambda *= 10.0;
                    continue;
                }
                let trial = self.apply(poses, &worlds, &delta);
                let trial_worlds = trial.worlds(self.rig);
                let trial_total: Vec<f64> = total.iter().zip(&delta).map(|(a, b)| a + b).collect();
                let e = self.energy(&trial, &trial_worlds, &trial_total);
                if e < energy {
                    let gain = (energy - e) / energy.max(1e-300);
                    *poses = trial;
                    worlds = trial_worlds;
                    total = trial_total;
                    energy = e;
                    lambda = (lambda * 0.3).max(1e-9);
                    accepted = true;
                    report.iterations += 1;
                    if gain < tolerance {
                        report.final_energy = energy;
                        return report;
                    }
                    break;
                }
                lambda *= 5.0;
            }
            if !accepted {
                break;
            }
        }
        report.final_energy = energy;
        report
    }
}
