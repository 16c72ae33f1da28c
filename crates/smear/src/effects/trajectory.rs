//! Vertex trajectories (Section 4.1): one uniform Catmull-Rom segment Q_{i,f}(t) per pair of
//! contiguous frames, C1 across frames; beyond the paper (issue #22): arcs for revolving
//! parts, past-only evaluation (causal mode) and a ground plane they never cross.

use glam::Vec3;

use crate::revolve::Arcs;
use crate::Collider;
use crate::{Result, SmearError};

/// Bisection steps when a displacement is shortened to stop at the ground or a collider.
const GROUND_STEPS: usize = 16;

/// The trajectories of a frame-major `frames × points` position buffer (mesh vertices, or
/// surface points after barycentric interpolation — Catmull-Rom is linear in its control
/// points, so the trajectory of a surface point is the barycentric blend of its triangle's
/// vertex trajectories).
///
/// SPEC.md: uniform Catmull-Rom through the integer frames with tangent
/// `(p(f+1) − p(f−1))/2`, end frames duplicated (`p(−1) = p(0)`, `p(F) = p(F−1)`); times before
/// the first or after the last frame clamp to those frames. Nothing is precomputed: a point is
/// four loads and a cubic, so evaluation is allocation-free.
///
/// Beyond the paper (issue #22), set by [`Trajectories::shaped`]:
/// * **causal** — seen from frame `now`, frames after `now` are extrapolated at constant
///   velocity `p(now) − p(now−1)` (the last screw keeps turning for revolving parts), so
///   [`Trajectories::displaced`] at frame f reads no frame after f;
/// * **arcs** — points of revolving parts move along screw arcs (see `crate::revolve`);
/// * **ground** — [`Trajectories::displaced`] shortens a displacement that would end below
///   the plane `y = ground` to where the trajectory reaches it (and lifts what is below
///   already), so elongated and multiple in-betweens never cross it;
/// * **colliders** — the same for collider meshes ([`Trajectories::with_colliders`]): a
///   displacement stops where its trajectory enters one and what is still inside is pushed
///   out (see [`Collider`]).
#[derive(Debug, Clone, Copy)]
pub struct Trajectories<'a> {
    positions: &'a [Vec3],
    frames: usize,
    points: usize,
    causal: bool,
    ground: Option<f32>,
    arcs: Option<&'a Arcs>,
    colliders: &'a [Collider],
    /// The colliders' frame of position frame 0 (a stream keeps only its last frames).
    collider_first: usize,
}

impl<'a> Trajectories<'a> {
    /// Wraps a frame-major position buffer.
    ///
    /// # Errors
    /// [`SmearError::LengthMismatch`] when `positions.len() != frames × points`.
    pub fn new(positions: &'a [Vec3], frames: usize, points: usize) -> Result<Trajectories<'a>> {
        if positions.len() != frames * points {
            return Err(SmearError::LengthMismatch {
                expected: frames * points,
                found: positions.len(),
            });
        }
        Ok(Trajectories {
            positions,
            frames,
            points,
            causal: false,
            ground: None,
            arcs: None,
            colliders: &[],
            collider_first: 0,
        })
    }

    /// The same trajectories evaluated past-only (`causal`), along the `arcs` of revolving
    /// parts (one entry per point, ignored otherwise) and stopped at the plane `y = ground`.
    pub fn shaped(self, causal: bool, ground: Option<f32>, arcs: Option<&'a Arcs>) -> Self {
        Trajectories {
            causal,
            ground: ground.filter(|g| g.is_finite()),
            arcs: arcs.filter(|a| !a.is_empty() && a.point_count() == self.points),
            ..self
        }
    }

    /// The trajectories of a point cache's vertices.
    pub fn of_animation(anim: &'a anim::MeshAnimation) -> Trajectories<'a> {
        Trajectories {
            positions: anim.positions(),
            frames: anim.frame_count(),
            points: anim.vertex_count(),
            causal: false,
            ground: None,
            arcs: None,
            colliders: &[],
            collider_first: 0,
        }
    }

    /// The same trajectories stopped at `colliders` too (frame f of a displacement uses each
    /// collider's frame f).
    pub fn with_colliders(self, colliders: &'a [Collider]) -> Self {
        Trajectories { colliders, ..self }
    }

    /// The same trajectories with position frame f meeting the colliders' frame `first + f`
    /// (for a window of the last frames of a longer animation, as [`crate::Stream`] keeps).
    pub fn with_collider_frames_from(self, first: usize) -> Self {
        Trajectories {
            collider_first: first,
            ..self
        }
    }

    /// Whether `p` is below the ground or inside a collider at frame `f`.
    #[inline]
    pub fn is_blocked(&self, f: usize, p: Vec3) -> bool {
        let f = f + self.collider_first;
        self.ground.is_some_and(|g| p.y < g) || self.colliders.iter().any(|c| c.inside(f, p))
    }

    /// `p` lifted onto the ground if below it, then pushed out of every collider it is
    /// inside at frame `f` ([`Collider::push_out`]).
    #[inline]
    pub fn lifted(&self, f: usize, mut p: Vec3) -> Vec3 {
        if let Some(g) = self.ground {
            p.y = p.y.max(g);
        }
        for c in self.colliders {
            p = c.push_out(f + self.collider_first, p);
        }
        p
    }

    /// The ground plane height displacements stop at, if any.
    pub fn ground(&self) -> Option<f32> {
        self.ground
    }

    /// Whether frames after the displaced one are extrapolated (causal mode).
    pub fn is_causal(&self) -> bool {
        self.causal
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.frames
    }

    /// Number of points (vertices).
    pub fn point_count(&self) -> usize {
        self.points
    }

    /// The sampled positions of frame `f` (`f` must be below the frame count).
    pub fn frame(&self, f: usize) -> &'a [Vec3] {
        &self.positions[f * self.points..(f + 1) * self.points]
    }

    #[inline]
    fn at_frame(&self, f: isize, i: usize) -> Vec3 {
        let f = f.clamp(0, self.frames as isize - 1) as usize;
        self.positions[f * self.points + i]
    }

    /// Point `i` at (fractional) time `time` in frames: with `k = ⌊time⌋` and `t = time − k`,
    /// `Q_{i,k}(t)` — the floor rule of Section 4.1 (e.g. time 6.4 → segment 6, t = 0.4).
    ///
    /// Times outside `[0, F − 1]` clamp to the first/last frame; a non-finite time reads
    /// frame 0 (NaN) or clamps (±∞). `i` must be below the point count. This is the offline
    /// trajectory (arcs apply, causal mode does not: see [`Trajectories::seen_from`]).
    ///
    /// # Performance
    /// Four loads and a cubic; no allocation.
    #[inline]
    pub fn at(&self, i: usize, time: f32) -> Vec3 {
        self.sample(None, i, time)
    }

    /// Point `i` at time `time` as seen from frame `now`: [`Trajectories::at`] offline; in
    /// causal mode frames after `now` are extrapolated (never read) and times past `now` are
    /// not clamped to the clip.
    #[inline]
    pub fn seen_from(&self, now: usize, i: usize, time: f32) -> Vec3 {
        self.sample(self.causal.then_some(now), i, time)
    }

    /// Plain trajectories: no past-only mode, arcs, ground or colliders (the common case,
    /// which [`Self::catmull_rom`] evaluates without the general path's branches).
    #[inline]
    fn is_plain(&self) -> bool {
        !self.causal && self.arcs.is_none() && self.ground.is_none() && self.colliders.is_empty()
    }

    /// [`Self::sample`] of plain trajectories ([`Self::is_plain`]): the same arithmetic,
    /// small enough to inline into the per-vertex loops.
    #[inline(always)]
    fn catmull_rom(&self, i: usize, time: f32) -> Vec3 {
        let last = self.frames.saturating_sub(1);
        if last == 0 || time.is_nan() || time <= 0.0 {
            return self.positions[i];
        }
        if time >= last as f32 {
            return self.positions[last * self.points + i];
        }
        let k = (time as usize).min(last - 1);
        let t = time - k as f32;
        let n = self.points;
        let p1 = self.positions[k * n + i];
        let p2 = self.positions[(k + 1) * n + i];
        let p0 = self.positions[k.saturating_sub(1) * n + i];
        let p3 = self.positions[(k + 2).min(last) * n + i];
        hermite(p1, p2, (p2 - p0) * 0.5, (p3 - p1) * 0.5, t)
    }

    #[inline]
    fn sample(&self, now: Option<usize>, i: usize, time: f32) -> Vec3 {
        let last = self.frames.saturating_sub(1);
        let now = now.map(|n| n.min(last));
        if last == 0 || time.is_nan() || time <= 0.0 {
            return self.positions[i];
        }
        let arcs = self.arcs.and_then(|a| a.screws_of(i));
        if let Some(n) = now {
            if time >= n as f32 {
                return self.extrapolate(n, i, time - n as f32, arcs);
            }
        } else if time >= last as f32 {
            return self.positions[last * self.points + i];
        }
        // 0 < time < last here, so truncation is the floor (and needs no libm call).
        let k = (time as usize).min(last - 1);
        let t = time - k as f32;
        if let Some(screws) = arcs {
            let (p1, p2) = (
                self.at_frame(k as isize, i),
                self.at_frame(k as isize + 1, i),
            );
            let s = screws[k.min(screws.len() - 1)];
            return s.apply(p1, t) + (p2 - s.apply(p1, 1.0)) * t;
        }
        let k = k as isize;
        let fetch = |g: isize| match now {
            Some(n) if g > n as isize => self.extrapolate(n, i, (g - n as isize) as f32, None),
            _ => self.at_frame(g, i),
        };
        let p0 = fetch(k - 1);
        let p1 = fetch(k);
        let p2 = fetch(k + 1);
        let p3 = fetch(k + 2);
        hermite(p1, p2, (p2 - p0) * 0.5, (p3 - p1) * 0.5, t)
    }

    /// Point `i`, `dt ≥ 0` frames after frame `now`, extrapolated from frames `now − 1` and
    /// `now`: constant velocity, or the last screw turning on for a revolving part.
    #[inline]
    fn extrapolate(
        &self,
        now: usize,
        i: usize,
        dt: f32,
        arcs: Option<&[crate::revolve::Screw]>,
    ) -> Vec3 {
        let p = self.at_frame(now as isize, i);
        if now == 0 {
            return p;
        }
        match arcs {
            Some(screws) => screws[(now - 1).min(screws.len() - 1)].apply(p, dt),
            None => p + (p - self.at_frame(now as isize - 1, i)) * dt,
        }
    }

    /// Point `i` of frame `f` displaced by `beta` frames along its trajectory:
    /// `p′_i(f) = Q_{i, f+⌊β⌋}(β − ⌊β⌋)` (Section 4.1). A non-finite `beta` counts as 0.
    /// With a ground plane or colliders, a displacement that would end below the ground or
    /// inside a collider stops where the trajectory reaches it (bisection on β), and a point
    /// already there is lifted out ([`Trajectories::lifted`]).
    #[inline(always)]
    pub fn displaced(&self, f: usize, i: usize, beta: f32) -> Vec3 {
        let beta = if beta.is_finite() { beta } else { 0.0 };
        if self.is_plain() {
            return self.catmull_rom(i, f as f32 + beta);
        }
        self.displaced_shaped(f, i, beta)
    }

    /// Points `start..start + out.len()` of frame `f`, point `start + k` displaced by
    /// `scale · betas[k]` frames: [`Trajectories::displaced`] of each, the same bits. On plain
    /// trajectories a point that does not move (β = 0, what a past-only or thresholded style
    /// gives most points) is its sampled position, without the cubic: `Q_{i,f}(0)` is that
    /// position but for the sign of a zero coordinate, so a −0 coordinate takes the cubic.
    pub fn displaced_run(
        &self,
        f: usize,
        start: usize,
        scale: f32,
        betas: &[f32],
        out: &mut [Vec3],
    ) {
        self.displaced_twins(f, start, scale, betas, None, out);
    }

    /// [`Self::displaced_run`], where a point whose twin (`twins[i] < i`, a point with the
    /// same positions in every frame: [`anim::MeshAnimation::twins`]) is in the run, has the
    /// same β and moves along the same arcs, is a copy of the twin's result: the same bits,
    /// one cubic per point of the surface instead of one per vertex of a split mesh.
    pub fn displaced_twins(
        &self,
        f: usize,
        start: usize,
        scale: f32,
        betas: &[f32],
        twins: Option<&[u32]>,
        out: &mut [Vec3],
    ) {
        let n = self.points;
        // Frames past 2²⁴ are not exact as f32 times: the general path.
        let plain = self.is_plain() && f < self.frames && f <= 1 << 24;
        let here = if plain {
            &self.positions[f * n + start..f * n + start + out.len()]
        } else {
            &[]
        };
        for k in 0..out.len().min(betas.len()) {
            let i = start + k;
            if let Some(t) = twins.map(|t| t[i] as usize) {
                let same = t < i && t >= start && betas[t - start].to_bits() == betas[k].to_bits();
                if same && self.same_arcs(i, t) {
                    out[k] = out[t - start];
                    continue;
                }
            }
            let beta = scale * betas[k];
            out[k] = match here.get(k) {
                Some(&p) if beta == 0.0 && !has_negative_zero(p) => p,
                _ => self.displaced(f, i, beta),
            };
        }
    }

    /// Whether points `i` and `j` move along the same arcs (or neither revolves): with the
    /// same positions in every frame, they have the same trajectory.
    #[inline]
    pub(crate) fn same_arcs(&self, i: usize, j: usize) -> bool {
        self.arcs.is_none_or(|a| a.same_part(i, j))
    }

    /// [`Self::displaced`] of shaped trajectories (past-only, arcs, ground, colliders): kept
    /// out of line so that the plain path inlines into the per-vertex loops.
    #[inline(never)]
    fn displaced_shaped(&self, f: usize, i: usize, beta: f32) -> Vec3 {
        let q = self.seen_from(f, i, f as f32 + beta);
        if self.is_blocked(f, q) {
            self.stopped(f, i, beta)
        } else {
            q
        }
    }

    /// [`Trajectories::displaced`] when the full displacement ends blocked: the largest
    /// fraction of β whose point is free (the trajectory may dip and return, so this finds
    /// one crossing, not necessarily the first), lifted out if needed.
    #[cold]
    fn stopped(&self, f: usize, i: usize, beta: f32) -> Vec3 {
        let at = |s: f32| self.seen_from(f, i, f as f32 + beta * s);
        let mut q = at(0.0);
        if !self.is_blocked(f, q) {
            let (mut lo, mut hi) = (0.0f32, 1.0f32);
            for _ in 0..GROUND_STEPS {
                let mid = 0.5 * (lo + hi);
                if self.is_blocked(f, at(mid)) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            q = at(lo);
        }
        self.lifted(f, q)
    }
}

/// Whether a coordinate of `p` is −0 (which [`hermite`] at `t = 0` may turn into +0).
#[inline]
fn has_negative_zero(p: Vec3) -> bool {
    p.to_array()
        .iter()
        .any(|c| c.to_bits() == (-0.0f32).to_bits())
}

/// Cubic Hermite segment from `a` (tangent `ma`) to `b` (tangent `mb`) at `t ∈ [0, 1]`.
#[inline]
fn hermite(a: Vec3, b: Vec3, ma: Vec3, mb: Vec3, t: f32) -> Vec3 {
    let t2 = t * t;
    let t3 = t2 * t;
    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
    let h10 = t3 - 2.0 * t2 + t;
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h11 = t3 - t2;
    a * h00 + ma * h10 + b * h01 + mb * h11
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track(f: impl Fn(f32) -> Vec3, frames: usize) -> Vec<Vec3> {
        (0..frames).map(|k| f(k as f32)).collect()
    }

    #[test]
    fn interpolates_frames_and_reproduces_lines() {
        // Catmull-Rom reproduces linear motion exactly away from the duplicated ends.
        let p = track(|t| Vec3::new(2.0 * t, 1.0, -t), 6);
        let tr = Trajectories::new(&p, 6, 1).unwrap();
        for k in 0..6 {
            assert_eq!(tr.at(0, k as f32), p[k]);
        }
        let q = tr.displaced(2, 0, 1.4); // paper: segment 3, t = 0.4
        assert!((q - Vec3::new(6.8, 1.0, -3.4)).length() < 1e-5, "{q}");
        let q = tr.displaced(3, 0, -0.5);
        assert!((q - Vec3::new(5.0, 1.0, -2.5)).length() < 1e-5, "{q}");
    }

    #[test]
    fn clamps_beyond_the_clip_and_handles_degenerate_input() {
        let p = track(|t| Vec3::X * t * t, 4);
        let tr = Trajectories::new(&p, 4, 1).unwrap();
        assert_eq!(tr.displaced(0, 0, -3.0), p[0]);
        assert_eq!(tr.displaced(3, 0, 2.0), p[3]);
        assert_eq!(tr.displaced(1, 0, f32::NAN), p[1]);
        assert_eq!(tr.at(0, f32::INFINITY), p[3]);
        let one = [Vec3::ONE];
        assert_eq!(Trajectories::new(&one, 1, 1).unwrap().at(0, 0.7), Vec3::ONE);
        assert!(Trajectories::new(&one, 2, 1).is_err());
    }

    #[test]
    fn the_plain_path_is_the_general_path_bit_for_bit() {
        // `displaced` takes `catmull_rom` when nothing shapes the trajectories; elongated
        // in-betweens must keep their bytes whichever path draws them.
        let (frames, points) = (7, 3);
        let p: Vec<Vec3> = (0..frames * points)
            .map(|k| {
                let t = k as f32;
                Vec3::new((0.7 * t).sin(), t * t * 0.01, (1.3 * t).cos())
            })
            .collect();
        let tr = Trajectories::new(&p, frames, points).unwrap();
        assert!(tr.is_plain());
        for step in -80..=110 {
            let time = step as f32 * 0.073;
            for i in 0..points {
                let (plain, general) = (tr.catmull_rom(i, time), tr.sample(None, i, time));
                assert_eq!(plain.to_array(), general.to_array(), "point {i} at {time}");
            }
        }
        for time in [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            0.0,
            6.0,
            5.999_999,
        ] {
            assert_eq!(tr.catmull_rom(1, time), tr.sample(None, 1, time), "{time}");
        }
        let shaped = tr.shaped(true, None, None);
        assert!(!shaped.is_plain() && !tr.shaped(false, Some(0.0), None).is_plain());
    }

    #[test]
    fn a_run_is_each_point_displaced_bit_for_bit() {
        // Points still at zero (both signs, with tangents of both signs, where the cubic at
        // t = 0 turns −0 into +0), still and moving, displaced by zero, −0, non-finite, small
        // and large β: the run's values are `displaced`'s, on plain and on shaped trajectories.
        let (frames, points) = (6, 8);
        let p: Vec<Vec3> = (0..frames * points)
            .map(|k| {
                let (f, i) = ((k / points) as f32, k % points);
                match i {
                    0 => Vec3::new(-0.0, 0.0, -0.0),
                    1 => Vec3::new(-0.0, f - 2.0, 0.0),
                    2 => Vec3::new(0.3 * f, -0.0, 2.0 - f),
                    _ => Vec3::new((0.9 * f + i as f32).sin(), f * f * 0.1, -0.5 * f),
                }
            })
            .collect();
        let betas = [0.0, -0.0, f32::NAN, 0.4, -1.7, f32::INFINITY, 9.0, 0.0];
        let plain = Trajectories::new(&p, frames, points).unwrap();
        for tr in [plain, plain.shaped(false, Some(0.1), None)] {
            for f in 0..frames {
                for (start, scale) in [(0, 1.0), (3, 2.0)] {
                    let len = points - start;
                    let mut run = vec![Vec3::NAN; len];
                    tr.displaced_run(f, start, scale, &betas[..len], &mut run);
                    for (k, q) in run.iter().enumerate() {
                        let one = tr.displaced(f, start + k, scale * betas[k]);
                        assert_eq!(
                            q.to_array().map(f32::to_bits),
                            one.to_array().map(f32::to_bits),
                            "frame {f}, point {}",
                            start + k
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn a_twin_with_the_same_beta_is_a_copy_of_its_twin() {
        // Points 3 and 4 are points 1 and 2 again (a split mesh's seam); 5 is 0 again but
        // displaced by another β. With the twins the run is the run without them, bit for bit;
        // a twin outside the run is not read.
        let (frames, points) = (6, 6);
        let base = |i: usize, f: f32| match i {
            0 | 5 => Vec3::new(0.3 * f, -0.0, 2.0 - f),
            1 | 3 => Vec3::new((0.9 * f).sin(), f * f * 0.1, -0.5 * f),
            _ => Vec3::new(1.0, (0.4 * f).cos(), 0.2 * f),
        };
        let p: Vec<Vec3> = (0..frames * points)
            .map(|k| base(k % points, (k / points) as f32))
            .collect();
        let twins = [0, 1, 2, 1, 2, 0];
        let betas = [0.4, -1.7, 0.0, -1.7, 0.0, 1.1];
        let plain = Trajectories::new(&p, frames, points).unwrap();
        for tr in [plain, plain.shaped(true, Some(0.1), None)] {
            for f in 0..frames {
                for start in [0, 2] {
                    let len = points - start;
                    let mut run = vec![Vec3::NAN; len];
                    let mut copied = vec![Vec3::NAN; len];
                    tr.displaced_run(f, start, 2.0, &betas[start..], &mut run);
                    tr.displaced_twins(f, start, 2.0, &betas[start..], Some(&twins), &mut copied);
                    let bits = |v: &[Vec3]| {
                        v.iter()
                            .map(|q| q.to_array().map(f32::to_bits))
                            .collect::<Vec<_>>()
                    };
                    assert_eq!(bits(&run), bits(&copied), "frame {f}, start {start}");
                }
            }
        }
        // The copy is taken (not recomputed): a point declared a twin gets the twin's result.
        let mut out = [Vec3::NAN; 2];
        plain.displaced_twins(3, 0, 1.0, &[0.5, 0.5], Some(&[0, 0]), &mut out);
        assert_eq!(out[1], out[0]);
        assert_ne!(out[0], plain.displaced(3, 1, 0.5));
    }

    #[test]
    fn tangents_are_continuous_across_frames() {
        let p = track(|t| Vec3::new(t.sin(), (0.3 * t).cos(), t * t * 0.1), 8);
        let tr = Trajectories::new(&p, 8, 1).unwrap();
        let h = 1e-3;
        for k in 1..7 {
            let left = (tr.at(0, k as f32) - tr.at(0, k as f32 - h)) / h;
            let right = (tr.at(0, k as f32 + h) - tr.at(0, k as f32)) / h;
            assert!(
                (left - right).length() < 5e-2,
                "frame {k}: {left} vs {right}"
            );
            let expected = (p[k + 1] - p[k - 1]) * 0.5;
            assert!((right - expected).length() < 5e-2);
        }
    }
}
