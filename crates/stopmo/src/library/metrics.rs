//! Exact energy (StopShop Eq. 10) and per-frame position/velocity errors (Fig. 19).

use anim::Aabb;
use glam::Vec3;
use rayon::prelude::*;
use serde::Serialize;

use super::problem::PartProblem;

/// Per-frame errors of a reconstruction, in model units.
///
/// Position error of frame `f`: distances `‖x_fi − r_{ℓ_f,i}‖` over the vertices `i`;
/// velocity error: distances `‖(x_fi − x_{f−1,i}) − (r_{ℓ_f,i} − r_{ℓ_{f−1},i})‖` (0 at the
/// first frame of each clip). Unweighted (saliency shapes the optimization, not the report).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameErrors {
    /// Mean vertex distance per frame.
    pub position_mean: Vec<f64>,
    /// Largest vertex distance per frame.
    pub position_max: Vec<f64>,
    /// Mean vertex velocity difference per frame.
    pub velocity_mean: Vec<f64>,
    /// Largest vertex velocity difference per frame.
    pub velocity_max: Vec<f64>,
    /// Whether frame `f` has a velocity (not the first frame of a clip).
    pub has_velocity: Vec<bool>,
}

/// Summary of [`FrameErrors`] in some unit (model units × `scale`).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct ErrorSummary {
    /// Mean over frames of the per-frame mean position error.
    pub position_mean: f64,
    /// Largest vertex position error over all frames.
    pub position_max: f64,
    /// Mean over frames (with a velocity) of the per-frame mean velocity error.
    pub velocity_mean: f64,
    /// Largest vertex velocity error over all frames.
    pub velocity_max: f64,
}

impl FrameErrors {
    /// Worst frame error: the largest per-frame mean position error (the criterion of
    /// the max-error library size search, Fig. 16).
    pub fn worst_frame(&self) -> f64 {
        self.position_mean.iter().copied().fold(0.0, f64::max)
    }

    /// Mean and max, multiplied by `scale` (e.g. millimetres per model unit).
    pub fn summary(&self, scale: f64) -> ErrorSummary {
        let n = self.position_mean.len().max(1) as f64;
        let nv = self.has_velocity.iter().filter(|&&v| v).count().max(1) as f64;
        ErrorSummary {
            position_mean: scale * self.position_mean.iter().sum::<f64>() / n,
            position_max: scale * self.position_max.iter().copied().fold(0.0, f64::max),
            velocity_mean: scale * self.velocity_mean.iter().sum::<f64>() / nv,
            velocity_max: scale * self.velocity_max.iter().copied().fold(0.0, f64::max),
        }
    }
}

impl ErrorSummary {
    /// Combines parts: means weighted by vertex counts, maxima of maxima.
    pub fn combine(parts: &[(ErrorSummary, usize)]) -> ErrorSummary {
        let total = parts.iter().map(|p| p.1).sum::<usize>().max(1) as f64;
        let wmean = |get: fn(&ErrorSummary) -> f64| {
            parts.iter().map(|(s, m)| get(s) * *m as f64).sum::<f64>() / total
        };
        let max =
            |get: fn(&ErrorSummary) -> f64| parts.iter().map(|(s, _)| get(s)).fold(0.0, f64::max);
        ErrorSummary {
            position_mean: wmean(|s| s.position_mean),
            position_max: max(|s| s.position_max),
            velocity_mean: wmean(|s| s.velocity_mean),
            velocity_max: max(|s| s.velocity_max),
        }
    }
}

/// One frame's position energy, mean and max distance, velocity energy, mean and max.
type FrameTerms = (f64, f64, f64, f64, f64, f64);

/// Exact energy of StopShop Eq. 10 (saliency-weighted, model units²) and the per-frame errors.
///
/// # Performance
/// One parallel pass over the frames, f64 accumulation.
pub(crate) fn evaluate(
    p: &PartProblem<'_>,
    pieces: &[Vec<Vec3>],
    labels: &[u32],
    lambda: f64,
) -> (f64, FrameErrors) {
    let (n, m) = (p.frames(), p.vertices());
    let mut start = vec![false; n];
    p.chains.iter().for_each(|c| start[c.start] = true);
    let w = p.weights.as_deref();
    let mut per_frame: Vec<(FrameTerms, Aabb)> = Vec::with_capacity(n);
    // The part's bounding box rides along the first evaluation (see `PartProblem::bbox`).
    let want_bounds = p.bounds.get().is_none();
    // The last frame of the previous block (morph weights are expanded block by block).
    let mut last: Vec<Vec3> = Vec::new();
    p.src.blocks(|f0, block| {
        let frame = |f: usize| -> &[Vec3] {
            if f >= f0 {
                &block[(f - f0) * m..(f - f0 + 1) * m]
            } else {
                &last
            }
        };
        let k = block.len() / m.max(1);
        per_frame.par_extend((f0..f0 + k).into_par_iter().map(|f| {
            let previous = (!start[f]).then(|| (frame(f - 1), &pieces[labels[f - 1] as usize][..]));
            frame_terms(
                frame(f),
                &pieces[labels[f] as usize],
                previous,
                w,
                want_bounds,
            )
        }));
        if k > 0 {
            last.clear();
            last.extend_from_slice(&block[(k - 1) * m..]);
        }
    });
    if want_bounds {
        // Unions of minima and maxima: the same box as any other pass over the frames.
        let bounds = per_frame.iter().fold(Aabb::EMPTY, |b, t| b.union(t.1));
        let _ = p.bounds.set(bounds);
    }
    let per_frame: Vec<FrameTerms> = per_frame.into_iter().map(|t| t.0).collect();
    let energy = per_frame.iter().map(|t| t.0 + 0.5 * lambda * t.3).sum();
    let errors = FrameErrors {
        position_mean: per_frame.iter().map(|t| t.1).collect(),
        position_max: per_frame.iter().map(|t| t.2).collect(),
        velocity_mean: per_frame.iter().map(|t| t.4).collect(),
        velocity_max: per_frame.iter().map(|t| t.5).collect(),
        has_velocity: start.iter().map(|s| !s).collect(),
    };
    (energy, errors)
}

/// One frame's [`FrameTerms`] and, with `want_bounds`, the bounding box of its vertices:
/// `x` the frame, `r` its piece, `previous` the previous frame and its piece (none at a
/// clip's first frame), `w` the saliency weights.
///
/// The distances of a chunk of vertices are found first (their square roots are
/// independent, so they vectorize), then added in vertex order, both terms in one loop
/// (their sums are independent chains of additions): every sum is the same sequence of f64
/// additions as a loop over single vertices, so the energy and errors do not depend on the
/// chunk size.
fn frame_terms(
    x: &[Vec3],
    r: &[Vec3],
    previous: Option<(&[Vec3], &[Vec3])>,
    w: Option<&[f64]>,
    want_bounds: bool,
) -> (FrameTerms, Aabb) {
    pulp::Arch::new().dispatch(FrameTermsOp {
        x,
        r,
        previous,
        w,
        want_bounds,
    })
}

/// Arguments of [`frame_terms`], as a [`pulp::WithSimd`] operation: compiled once per
/// instruction set (AVX2 on x86-64), the same sums in the same order.
struct FrameTermsOp<'a> {
    x: &'a [Vec3],
    r: &'a [Vec3],
    previous: Option<(&'a [Vec3], &'a [Vec3])>,
    w: Option<&'a [f64]>,
    want_bounds: bool,
}

impl pulp::WithSimd for FrameTermsOp<'_> {
    type Output = (FrameTerms, Aabb);
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> Self::Output {
        let FrameTermsOp {
            x,
            r,
            previous,
            w,
            want_bounds,
        } = self;
        const CHUNK: usize = 16;
        let (mut eu, mut pm, mut ev, mut vm) = (0.0, 0.0, 0.0, 0.0f64);
        // Maxima per lane (a distance is +0 or more, or NaN, which `>` passes over as
        // `f64::max` does): the same largest value in any order.
        let (mut px, mut vx) = ([0.0f64; CHUNK], [0.0f64; CHUNK]);
        // The box per lane and coordinate, in the distance loop (no extra pass over the frame).
        let mut lo = [[f32::INFINITY; CHUNK]; 3];
        let mut hi = [[f32::NEG_INFINITY; CHUNK]; 3];
        let (mut sq, mut dist) = ([0.0f64; CHUNK], [0.0f64; CHUNK]);
        let (mut vsq, mut vdist) = ([0.0f64; CHUNK], [0.0f64; CHUNK]);
        let n = x.len().min(r.len());
        let mut i0 = 0;
        while i0 < n {
            let len = CHUNK.min(n - i0);
            let (xc, rc) = (&x[i0..i0 + len], &r[i0..i0 + len]);
            for l in 0..len {
                let s = length_squared((xc[l] - rc[l]).as_dvec3());
                sq[l] = s;
                dist[l] = s.sqrt();
                px[l] = if dist[l] > px[l] { dist[l] } else { px[l] };
            }
            if want_bounds {
                grow_lanes(&mut lo, &mut hi, xc);
            }
            let wc = w.map(|w| &w[i0..i0 + len]);
            if let Some((xp, rp)) = previous {
                let (xpc, rpc) = (&xp[i0..i0 + len], &rp[i0..i0 + len]);
                for l in 0..len {
                    let dv = (xc[l] - xpc[l]).as_dvec3() - (rc[l] - rpc[l]).as_dvec3();
                    let s = length_squared(dv);
                    vsq[l] = s;
                    vdist[l] = s.sqrt();
                    vx[l] = if vdist[l] > vx[l] { vdist[l] } else { vx[l] };
                }
                for l in 0..len {
                    let wl = wc.map_or(1.0, |w| w[l]);
                    eu += wl * sq[l];
                    pm += dist[l];
                    ev += wl * vsq[l];
                    vm += vdist[l];
                }
            } else {
                for l in 0..len {
                    eu += wc.map_or(1.0, |w| w[l]) * sq[l];
                    pm += dist[l];
                }
            }
            i0 += len;
        }
        let largest = |v: [f64; CHUNK]| v.into_iter().fold(0.0, |a, b| if b > a { b } else { a });
        let bb = if want_bounds {
            let lane = |c: usize| {
                let min = lo[c].into_iter().fold(f32::INFINITY, f32::min);
                let max = hi[c].into_iter().fold(f32::NEG_INFINITY, f32::max);
                (min, max)
            };
            let ((x0, x1), (y0, y1), (z0, z1)) = (lane(0), lane(1), lane(2));
            Aabb {
                min: Vec3::new(x0, y0, z0),
                max: Vec3::new(x1, y1, z1),
            }
        } else {
            Aabb::EMPTY
        };
        let m = x.len().max(1) as f64;
        ((eu, pm / m, largest(px), ev, vm / m, largest(vx)), bb)
    }
}

/// Grows the per-lane box of [`frame_terms`] by the points of one chunk, leaving out points
/// that are not finite (as [`Aabb::grow`] does).
#[inline(always)]
fn grow_lanes<const L: usize>(lo: &mut [[f32; L]; 3], hi: &mut [[f32; L]; 3], points: &[Vec3]) {
    for (l, p) in points.iter().enumerate().take(L) {
        let finite = p.x.is_finite() & p.y.is_finite() & p.z.is_finite();
        for (c, v) in [p.x, p.y, p.z].into_iter().enumerate() {
            lo[c][l] = if finite && v < lo[c][l] { v } else { lo[c][l] };
            hi[c][l] = if finite && v > hi[c][l] { v } else { hi[c][l] };
        }
    }
}

/// `‖v‖²` summed as glam's `DVec3::length_squared` sums it (x, then y, then z).
#[inline(always)]
fn length_squared(v: glam::DVec3) -> f64 {
    v.x * v.x + v.y * v.y + v.z * v.z
}

impl PartProblem<'_> {
    /// Exact StopShop Eq. 10 energy and per-frame errors of any library and labeling of this part.
    ///
    /// `pieces` must have the part's vertex count and `labels` one entry per frame with values
    /// below `pieces.len()`; otherwise `None`.
    pub fn evaluate(
        &self,
        pieces: &[Vec<Vec3>],
        labels: &[u32],
        lambda: f64,
    ) -> Option<(f64, FrameErrors)> {
        let ok = labels.len() == self.frames()
            && labels.iter().all(|&l| (l as usize) < pieces.len())
            && pieces.iter().all(|p| p.len() == self.vertices());
        ok.then(|| evaluate(self, pieces, labels, lambda))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim::SplitMix64;

    /// [`frame_terms`] as a loop over single vertices: every sum in vertex order,
    /// `f64::max` for the maxima, [`Aabb::grow`] for the box.
    fn per_vertex(
        x: &[Vec3],
        r: &[Vec3],
        previous: Option<(&[Vec3], &[Vec3])>,
        w: Option<&[f64]>,
    ) -> (FrameTerms, Aabb) {
        let (mut eu, mut pm, mut px, mut ev, mut vm, mut vx) = (0.0, 0.0, 0.0f64, 0.0, 0.0, 0.0f64);
        let mut bb = Aabb::EMPTY;
        for i in 0..x.len() {
            let wl = w.map_or(1.0, |w| w[i]);
            let s = length_squared((x[i] - r[i]).as_dvec3());
            eu += wl * s;
            pm += s.sqrt();
            px = px.max(s.sqrt());
            bb.grow(x[i]);
            if let Some((xp, rp)) = previous {
                let s = length_squared((x[i] - xp[i]).as_dvec3() - (r[i] - rp[i]).as_dvec3());
                ev += wl * s;
                vm += s.sqrt();
                vx = vx.max(s.sqrt());
            }
        }
        let m = x.len().max(1) as f64;
        ((eu, pm / m, px, ev, vm / m, vx), bb)
    }

    fn same(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    /// Chunks of 16 vertices, maxima and the box per lane: the same bits as one vertex at a
    /// time, on frames whose lengths are not whole chunks, with points that are not finite.
    #[test]
    fn chunked_frame_terms_are_the_per_vertex_sums() {
        let mut rng = SplitMix64::new(5, 2);
        let mut point = |odd: bool| {
            let mut p = Vec3::new(
                rng.normal() as f32,
                rng.normal() as f32,
                rng.normal() as f32,
            );
            if odd {
                match rng.below(3) {
                    0 => p.x = f32::NAN,
                    1 => p.y = f32::INFINITY,
                    _ => p.z = -0.0,
                }
            }
            p
        };
        for (len, odd) in [
            (0, false),
            (1, false),
            (15, true),
            (16, false),
            (17, true),
            (203, true),
        ] {
            let mut frame = |k: usize| -> Vec<Vec3> {
                (0..len)
                    .map(|i| point(odd && (i * 7 + k) % 11 == 3))
                    .collect()
            };
            let (x, r, xp, rp) = (frame(0), frame(1), frame(2), frame(3));
            let w: Vec<f64> = (0..len).map(|i| 0.5 + (i % 5) as f64 * 0.25).collect();
            for weights in [None, Some(&w[..])] {
                for previous in [None, Some((&xp[..], &rp[..]))] {
                    let (got, bb) = frame_terms(&x, &r, previous, weights, true);
                    let (want, want_bb) = per_vertex(&x, &r, previous, weights);
                    let g = [got.0, got.1, got.2, got.3, got.4, got.5];
                    let e = [want.0, want.1, want.2, want.3, want.4, want.5];
                    for (a, b) in g.iter().zip(&e) {
                        assert!(same(*a, *b), "{len} vertices: {g:?} vs {e:?}");
                    }
                    assert!(
                        bb.min == want_bb.min && bb.max == want_bb.max,
                        "{bb:?} vs {want_bb:?}"
                    );
                }
            }
        }
    }
}
