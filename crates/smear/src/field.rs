//! Per-frame offset fields: everything needed to evaluate δ at any point of a frame.

use anim::Bone;
use glam::Vec3;
use rayon::prelude::*;

use crate::plane::{plane_frames, PlaneFrame};
use crate::ribbon::{eval_batch, Ribbon, RibbonSample};
use crate::rig::{Hood, Rig};
use crate::velocity::{track_velocity, CameraSpace};

/// The offset field of one group of vertices (one simple object or one skinned character).
#[derive(Debug, Clone)]
pub(crate) enum Field {
    /// SMEAR Eq. 1, one plane per frame.
    Plane(Vec<PlaneFrame>),
    /// SMEAR Eqs. 3–9, one ribbon per bone and frame.
    Ribbons(Box<RibbonField>),
}

/// Ribbons and neighbourhood maxima of SMEAR Eq. 9 for every bone and frame.
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
    /// Past-only velocities (causal mode, issue #22): backward differences.
    pub(crate) causal: bool,
}

impl Field {
    /// The SMEAR Eq. 1 field of a frame-major buffer, and the (unsmoothed) offsets of its vertices.
    ///
    /// # Performance
    /// Parallel over frames, allocation-free per vertex (see [`plane_frames`]).
    pub(crate) fn plane(
        positions: &[Vec3],
        frames: usize,
        vertices: usize,
        triangles: &[[u32; 3]],
        tol: Tolerances,
        space: Option<&CameraSpace>,
    ) -> (Field, Vec<f32>) {
        let mut raw = vec![0.0f32; frames * vertices];
        let planes = plane_frames(
            positions, frames, vertices, triangles, tol.still, tol.causal, space, &mut raw,
        );
        (Field::Plane(planes), raw)
    }

    /// The SMEAR Eqs. 3–9 field of a skinned group, and the (unsmoothed) offsets of its vertices.
    ///
    /// # Arguments
    /// * `bones` — bones of the whole skeleton, frame-major `frames × joints`.
    ///
    /// # Returns
    /// The field (for surface points) and the frame-major `frames × vertices` offsets.
    ///
    /// # Performance
    /// Ribbons once per bone and frame. Then, parallel over frames and bone-major, every
    /// neighbourhood V_k,r ∪ V_k,t (precomputed once per rig, struct-of-arrays) is read
    /// run by run from the frame's position columns (or gathered into per-worker columns
    /// when fragmented, see [`Hood::runs`]) and evaluated once by the vectorized
    /// [`eval_batch`]:
    /// the maxima of SMEAR Eq. 9 come out of that pass, then every entry is normalized
    /// (vectorized) and the bone's skinned ones are accumulated into SMEAR Eq. 7's sum in a
    /// per-worker buffer, and each output frame is written once into a buffer fresh from the
    /// allocator (each worker maps the pages of the frames it writes; no read of zeroed pages).
    /// No allocation per frame or vertex.
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
        // Zeroed by the allocator, untouched until the workers write their frames.
        let mut raw = vec![0.0f32; frames * vertices];
        let mut ribbons = vec![None; frames * joints];
        let mut maxima = vec![[0.0f32; 2]; frames * joints];
        if joints == 0 || vertices == 0 {
            return (
                Field::Ribbons(Box::new(RibbonField {
                    rig,
                    joints,
                    collinear,
                    ribbons,
                    maxima,
                })),
                raw,
            );
        }
        ribbons
            .par_chunks_mut(joints)
            .enumerate()
            .for_each(|(f, out)| {
                for (k, r) in out.iter_mut().enumerate() {
                    let bone = bones[f * joints + k];
                    let vr = track_velocity(f, frames, space, tol.causal, |g| {
                        bones[g * joints + k].root
                    });
                    let vt =
                        track_velocity(f, frames, space, tol.causal, |g| bones[g * joints + k].tip);
                    *r = Ribbon::new(bone.root, bone.tip, vr, vt, tol.still, tol.zero_length);
                }
            });
        raw.par_chunks_mut(vertices)
            .zip(maxima.par_chunks_mut(joints))
            .enumerate()
            .for_each_init(
                || Scratch::new(rig.max_hood_len(), vertices, rig.has_runs()),
                |sc, (f, (dst, mx))| {
                    let pos = &positions[f * vertices..(f + 1) * vertices];
                    sc.start_frame(pos);
                    for (k, m) in mx.iter_mut().enumerate() {
                        if let Some(rib) = &ribbons[f * joints + k] {
                            *m = sc.bone(rib, rig.hood(k), pos, collinear);
                        }
                    }
                    // Zero-length bones were skipped: renormalize over the remaining weights.
                    weighted_means(dst, &sc.acc, &sc.wsum);
                },
            );
        (
            Field::Ribbons(Box::new(RibbonField {
                rig,
                joints,
                collinear,
                ribbons,
                maxima,
            })),
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

/// Per-worker columns of the articulated pass, allocated once per rayon job.
struct Scratch {
    xs: Vec<f32>,
    ys: Vec<f32>,
    zs: Vec<f32>,
    raw: Vec<f32>,
    u: Vec<f32>,
    coll: Vec<f32>,
    /// Σ_k w_k·δ_k of SMEAR Eq. 7 per vertex.
    acc: Vec<f32>,
    /// Σ_k w_k over the non-skipped bones per vertex.
    wsum: Vec<f32>,
    /// The frame's positions as columns, for neighbourhoods evaluated by runs.
    px: Vec<f32>,
    py: Vec<f32>,
    pz: Vec<f32>,
    /// Whether some neighbourhood is evaluated by runs (the columns then hold whole frames).
    runs: bool,
}

impl Scratch {
    /// Columns for neighbourhoods of up to `hood` vertices; the per-vertex buffers are filled
    /// per frame ([`Scratch::start_frame`]), so they are not zeroed here (a zeroed allocation
    /// is a memset of reused memory for every rayon job).
    fn new(hood: usize, vertices: usize, runs: bool) -> Scratch {
        let col = || vec![0.0f32; hood];
        let pcol = || Vec::with_capacity(if runs { vertices } else { 0 });
        Scratch {
            xs: col(),
            ys: col(),
            zs: col(),
            raw: col(),
            u: col(),
            coll: col(),
            acc: Vec::with_capacity(vertices),
            wsum: Vec::with_capacity(vertices),
            px: pcol(),
            py: pcol(),
            pz: pcol(),
            runs,
        }
    }

    /// Zeroes SMEAR Eq. 7's sums and fills the position columns with a frame (when some
    /// neighbourhood is run-based).
    fn start_frame(&mut self, pos: &[Vec3]) {
        for sum in [&mut self.acc, &mut self.wsum] {
            sum.clear();
            sum.resize(pos.len(), 0.0);
        }
        if !self.runs {
            return;
        }
        // Sized once per worker (every frame has as many vertices), then filled in one pass.
        for col in [&mut self.px, &mut self.py, &mut self.pz] {
            col.resize(pos.len(), 0.0);
        }
        let cols = self.px.iter_mut().zip(&mut self.py).zip(&mut self.pz);
        for (((x, y), z), p) in cols.zip(pos) {
            (*x, *y, *z) = (p.x, p.y, p.z);
        }
    }

    /// Evaluates one bone's ribbon over its neighbourhood (batched, SMEAR Eqs. 3–6), accumulates
    /// the normalized offsets of its skinned vertices (SMEAR Eqs. 7–9) into `acc`/`wsum`.
    ///
    /// # Returns
    /// The maxima of |δ̃| over V_k,r and V_k,t.
    fn bone(&mut self, rib: &Ribbon, hood: Hood<'_>, pos: &[Vec3], collinear: bool) -> [f32; 2] {
        let n = hood.vertex.len();
        let (raw, u, coll) = (&mut self.raw[..n], &mut self.u[..n], &mut self.coll[..n]);
        if hood.runs.is_empty() {
            let (xs, ys, zs) = (&mut self.xs[..n], &mut self.ys[..n], &mut self.zs[..n]);
            for (i, &v) in hood.vertex.iter().enumerate() {
                let p = pos[v as usize];
                (xs[i], ys[i], zs[i]) = (p.x, p.y, p.z);
            }
            eval_batch(rib, xs, ys, zs, raw, u, coll);
        } else {
            // Straight from the frame's columns (filled by `start_frame`), run by run.
            let mut o = 0;
            for &(v, len) in hood.runs {
                let (v, len) = (v as usize, len as usize);
                let (a, b) = (v, v + len);
                eval_batch(
                    rib,
                    &self.px[a..b],
                    &self.py[a..b],
                    &self.pz[a..b],
                    &mut raw[o..o + len],
                    &mut u[o..o + len],
                    &mut coll[o..o + len],
                );
                o += len;
            }
        }
        let (raw, u, coll) = (&mut self.raw[..n], &self.u[..n], &self.coll[..n]);
        let [mr, mt] = masked_maxima(raw, hood.in_root, hood.in_tip);
        // Every entry normalized at once (vectorized), then the skinned ones gathered.
        normalize_columns(raw, u, coll, mr, mt, collinear);
        for (&i, &w) in hood.skinned_at.iter().zip(hood.skinned_weight) {
            let i = i as usize;
            let v = hood.vertex[i] as usize;
            self.acc[v] += w * raw[i];
            self.wsum[v] += w;
        }
        [mr, mt]
    }
}

/// [max |raw| over V_k,r, max over V_k,t] given the 0/1 masks of [`Hood::in_root`] and
/// [`Hood::in_tip`]: NaN (and ±inf outside the set, masked to NaN) are ignored, 0 when none.
/// Same value as folding `f32::max` over the flagged entries, in lanes the compiler vectorizes.
fn masked_maxima(raw: &[f32], in_root: &[f32], in_tip: &[f32]) -> [f32; 2] {
    // One pass per mask: with both in one loop the compiler pairs (root, tip) per point in
    // half-empty registers instead of filling them with 4 points (callgrind: ~2× the
    // instructions). `raw` (one neighbourhood) is still in L1 for the second pass.
    [masked_max(raw, in_root), masked_max(raw, in_tip)]
}

/// max |raw| over the entries flagged 1 in `mask` (see [`masked_maxima`]), compiled for
/// baseline x86-64 and AVX2 like [`eval_batch`].
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn masked_max(raw: &[f32], mask: &[f32]) -> f32 {
    const L: usize = 8;
    #[inline(always)]
    fn lane(m: &mut f32, x: f32) {
        // NaN compares false: ignored, like `f32::max`.
        if x > *m {
            *m = x;
        }
    }
    // Two accumulators of 4 lanes (one SSE register each) map one to one onto vector maxima.
    let (mut m, mut m2) = ([0.0f32; 4], [0.0f32; 4]);
    let (rc, ac) = (raw.chunks_exact(L), mask.chunks_exact(L));
    let (rr, ar) = (rc.remainder(), ac.remainder());
    for (r, a) in rc.zip(ac) {
        for l in 0..4 {
            lane(&mut m[l], r[l].abs() * a[l]);
        }
        for l in 0..4 {
            lane(&mut m2[l], r[4 + l].abs() * a[4 + l]);
        }
    }
    for (r, a) in rr.iter().zip(ar) {
        lane(&mut m[0], r.abs() * a);
    }
    m.iter().chain(&m2).fold(0.0f32, |a, &b| a.max(b))
}

/// SMEAR Eq. 8 with SMEAR Eq. 9's normalizer M = (1 − u)·max_{V_k,r} + u·max_{V_k,t} (SPEC.md's
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

/// [`normalized`] over a neighbourhood's columns, in place: `raw[i]` becomes entry i's
/// w_coll·δ̃ / M (SMEAR Eqs. 8–9), or 0 where M vanishes. The compiler turns the branch into
/// selects and vectorizes the loop; compiled for baseline x86-64 and AVX2 like
/// [`eval_batch`].
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn normalize_columns(
    raw: &mut [f32],
    u: &[f32],
    coll: &[f32],
    max_root: f32,
    max_tip: f32,
    collinear: bool,
) {
    for ((r, &u), &coll) in raw.iter_mut().zip(u).zip(coll) {
        let s = RibbonSample { u, raw: *r, coll };
        *r = normalized(s, max_root, max_tip, collinear);
    }
}

/// SMEAR Eq. 7's weighted mean per vertex, `acc / wsum` (0 without weight), vectorized like
/// [`normalize_columns`].
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn weighted_means(dst: &mut [f32], acc: &[f32], wsum: &[f32]) {
    for ((d, &a), &w) in dst.iter_mut().zip(acc).zip(wsum) {
        *d = if w > 0.0 { a / w } else { 0.0 };
    }
}

impl RibbonField {
    /// SMEAR Eqs. 7–9 at one point: Σ_k w_k · w_coll(u_k) · δ̃_k / M_k with
    /// M_k = (1 − u_k)·max_{V_k,r} + u_k·max_{V_k,t} (SPEC.md's orientation of SMEAR Eq. 9).
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The lane-split maxima equal a plain fold of `f32::max` over the flagged entries, for
    /// every length around the block size (tails), with the extreme in every position, NaN
    /// anywhere and infinities outside the sets.
    #[test]
    fn masked_maxima_equal_plain_fold() {
        let plain = |raw: &[f32], mask: &[f32]| {
            raw.iter()
                .zip(mask)
                .filter(|(_, &m)| m == 1.0)
                .fold(0.0f32, |a, (&r, _)| a.max(r.abs()))
        };
        for n in 0..=27usize {
            for peak in 0..n.max(1) {
                let mut raw: Vec<f32> = (0..n).map(|i| ((i * 7 % 5) as f32 - 2.0) * 0.1).collect();
                let in_root: Vec<f32> = (0..n).map(|i| f32::from(i % 3 != 1)).collect();
                let in_tip: Vec<f32> = (0..n).map(|i| f32::from(i % 2 == 0)).collect();
                if n > 0 {
                    raw[peak] = -0.9;
                    raw[(peak + 1) % n] = f32::NAN;
                    if in_root[(peak + 2) % n] == 0.0 && in_tip[(peak + 2) % n] == 0.0 {
                        raw[(peak + 2) % n] = f32::INFINITY;
                    }
                }
                let got = masked_maxima(&raw, &in_root, &in_tip);
                let want = [plain(&raw, &in_root), plain(&raw, &in_tip)];
                assert_eq!(got, want, "n {n}, peak {peak}");
            }
        }
    }
}
