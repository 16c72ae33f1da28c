//! Per-frame offset fields: everything needed to evaluate δ at any point of a frame.

use anim::Bone;
use glam::Vec3;
use rayon::prelude::*;

use crate::plane::{plane_frames, PlaneFrame};
use crate::ribbon::{Interp, Ribbon, RibbonSample};
use crate::rig::{HoodEntry, Rig, IN_ROOT, IN_TIP};
use crate::velocity::{track_velocity, CameraSpace};

/// The offset field of one group of vertices (one simple object or one skinned character).
#[derive(Debug, Clone)]
pub(crate) enum Field {
    /// Eq. 1, one plane per frame.
    Plane(Vec<PlaneFrame>),
    /// Eqs. 3–9, one ribbon per bone and frame.
    Ribbons(RibbonField),
}

/// Ribbons and neighbourhood maxima of Eq. 9 for every bone and frame.
#[derive(Debug, Clone)]
pub(crate) struct RibbonField {
    pub(crate) rig: Rig,
    joints: usize,
    collinear: bool,
    /// `frames × joints`; `None` for zero-length bones.
    ribbons: Vec<Option<Ribbon>>,
    /// `frames × joints`: [max over V_k,r, max over V_k,t] of |δ̃_jk|.
    maxima: Vec<[f32; 2]>,
}

/// Tolerances of a field, absolute (already scaled by the bounding-box diagonal).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tolerances {
    pub(crate) still: f32,
    pub(crate) zero_length: f32,
}

impl Field {
    /// The Eq. 1 field of a frame-major buffer, and the (unsmoothed) offsets of its vertices.
    ///
    /// # Performance
    /// Parallel over frames, allocation-free per vertex.
    pub(crate) fn plane(
        positions: &[Vec3],
        frames: usize,
        vertices: usize,
        triangles: &[[u32; 3]],
        tol: Tolerances,
        space: Option<&CameraSpace>,
    ) -> (Field, Vec<f32>) {
        let planes = plane_frames(positions, frames, vertices, triangles, tol.still, space);
        let mut raw = vec![0.0f32; frames * vertices];
        if vertices > 0 {
            raw.par_chunks_mut(vertices)
                .enumerate()
                .for_each(|(f, dst)| {
                    let pl = planes[f];
                    for (d, p) in dst
                        .iter_mut()
                        .zip(&positions[f * vertices..(f + 1) * vertices])
                    {
                        *d = pl.eval(*p);
                    }
                });
        }
        (Field::Plane(planes), raw)
    }

    /// The Eqs. 3–9 field of a skinned group, and the (unsmoothed) offsets of its vertices.
    ///
    /// # Arguments
    /// * `bones` — bones of the whole skeleton, frame-major `frames × joints`.
    ///
    /// # Returns
    /// The field (for surface points) and the frame-major `frames × vertices` offsets.
    ///
    /// # Performance
    /// Ribbons once per bone and frame. Then, parallel over frames and bone-major, every
    /// neighbourhood V_k,r ∪ V_k,t is evaluated once: the maxima of Eq. 9 come out of that
    /// pass, and the skinned entries are kept in a per-thread scratch and accumulated into
    /// Eq. 7's sum once the bone's maxima are known. No allocation per frame or vertex.
    pub(crate) fn ribbons(
        rig: Rig,
        positions: &[Vec3],
        frames: usize,
        bones: &[Bone],
        tol: Tolerances,
        space: Option<&CameraSpace>,
        collinear: bool,
    ) -> (Field, Vec<f32>) {
        let joints = rig.joint_count();
        let vertices = rig.vertex_count();
        let mut raw = vec![0.0f32; frames * vertices];
        let mut ribbons = vec![None; frames * joints];
        let mut maxima = vec![[0.0f32; 2]; frames * joints];
        if joints == 0 || vertices == 0 {
            return (
                Field::Ribbons(RibbonField {
                    rig,
                    joints,
                    collinear,
                    ribbons,
                    maxima,
                }),
                raw,
            );
        }
        ribbons
            .par_chunks_mut(joints)
            .enumerate()
            .for_each(|(f, out)| {
                for (k, r) in out.iter_mut().enumerate() {
                    let bone = bones[f * joints + k];
                    let vr = track_velocity(f, frames, space, |g| bones[g * joints + k].root);
                    let vt = track_velocity(f, frames, space, |g| bones[g * joints + k].tip);
                    *r = Ribbon::new(bone.root, bone.tip, vr, vt, tol.still, tol.zero_length);
                }
            });
        raw.par_chunks_mut(vertices)
            .zip(maxima.par_chunks_mut(joints))
            .enumerate()
            .for_each_init(
                || {
                    (
                        Vec::<(u32, f32, RibbonSample)>::new(),
                        vec![0.0f32; vertices],
                    )
                },
                |(skinned, wsum), (f, (dst, mx))| {
                    let pos = &positions[f * vertices..(f + 1) * vertices];
                    wsum.fill(0.0);
                    for (k, m) in mx.iter_mut().enumerate() {
                        let Some(rib) = &ribbons[f * joints + k] else {
                            continue;
                        };
                        skinned.clear();
                        let hood = rig.hood(k);
                        let (mr, mt) = match rib.interp() {
                            Interp::Slerp => hood_pass(hood, pos, skinned, |x| rib.eval_slerp(x)),
                            Interp::Lerp => hood_pass(hood, pos, skinned, |x| rib.eval_lerp(x)),
                            Interp::Still => hood_pass(hood, pos, skinned, |x| rib.eval_still(x)),
                        };
                        *m = [mr, mt];
                        for &(v, w, s) in skinned.iter() {
                            dst[v as usize] += w * normalized(s, mr, mt, collinear);
                            wsum[v as usize] += w;
                        }
                    }
                    // Zero-length bones were skipped: renormalize over the remaining weights.
                    for (d, &w) in dst.iter_mut().zip(wsum.iter()) {
                        if w > 0.0 {
                            *d /= w;
                        }
                    }
                },
            );
        (
            Field::Ribbons(RibbonField {
                rig,
                joints,
                collinear,
                ribbons,
                maxima,
            }),
            raw,
        )
    }

    /// δ at frame `f` for a point at `p` with influences `(joints, weights)` (ignored by
    /// planes).
    pub(crate) fn eval(&self, f: usize, p: Vec3, joints: &[u32], weights: &[f32]) -> f32 {
        match self {
            Field::Plane(planes) => planes[f].eval(p),
            Field::Ribbons(rf) => rf.eval(f, p, joints, weights),
        }
    }
}

/// Evaluates one bone's ribbon over its neighbourhood: returns the maxima of |δ̃| over
/// V_k,r and V_k,t, and keeps the samples of the vertices skinned to the bone.
#[inline(always)]
fn hood_pass(
    hood: &[HoodEntry],
    pos: &[Vec3],
    skinned: &mut Vec<(u32, f32, RibbonSample)>,
    eval: impl Fn(Vec3) -> RibbonSample,
) -> (f32, f32) {
    let (mut mr, mut mt) = (0.0f32, 0.0f32);
    for e in hood {
        let s = eval(pos[e.vertex as usize]);
        let a = s.raw.abs();
        if e.flags & IN_ROOT != 0 {
            mr = mr.max(a);
        }
        if e.flags & IN_TIP != 0 {
            mt = mt.max(a);
        }
        if e.weight > 0.0 {
            skinned.push((e.vertex, e.weight, s));
        }
    }
    (mr, mt)
}

/// Eq. 8 with Eq. 9's normalizer M = (1 − u)·max_{V_k,r} + u·max_{V_k,t} (SPEC.md's
/// orientation, continuous across joints): w_coll(u)·δ̃ / M, or 0 when M vanishes.
#[inline]
fn normalized(s: RibbonSample, max_root: f32, max_tip: f32, collinear: bool) -> f32 {
    let m = (1.0 - s.u) * max_root + s.u * max_tip;
    if m > 0.0 {
        let coll = if collinear { s.coll } else { 1.0 };
        coll * s.raw / m
    } else {
        0.0
    }
}

impl RibbonField {
    /// Eqs. 7–9 at one point: Σ_k w_k · w_coll(u_k) · δ̃_k / M_k with
    /// M_k = (1 − u_k)·max_{V_k,r} + u_k·max_{V_k,t} (SPEC.md's orientation of Eq. 9).
    /// Zero-length bones are skipped and the remaining weights renormalized.
    #[inline]
    fn eval(&self, f: usize, p: Vec3, joints: &[u32], weights: &[f32]) -> f32 {
        let base = f * self.joints;
        let (mut acc, mut wsum) = (0.0f32, 0.0f32);
        for (&k, &w) in joints.iter().zip(weights) {
            let Some(rib) = &self.ribbons[base + k as usize] else {
                continue;
            };
            wsum += w;
            let [mr, mt] = self.maxima[base + k as usize];
            acc += w * normalized(rib.eval(p), mr, mt, self.collinear);
        }
        if wsum > 0.0 {
            acc / wsum
        } else {
            0.0
        }
    }
}
