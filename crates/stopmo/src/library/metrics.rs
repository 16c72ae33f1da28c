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
            let x = frame(f);
            let r = &pieces[labels[f] as usize];
            let (mut eu, mut pm, mut px) = (0.0, 0.0, 0.0f64);
            // In the distance loop, the box costs no extra pass over the frame.
            let mut bb = Aabb::EMPTY;
            for (i, (a, b)) in x.iter().zip(r).enumerate() {
                if want_bounds {
                    bb.grow(*a);
                }
                let dv = (*a - *b).as_dvec3();
                let sq = dv.length_squared();
                eu += w.map_or(1.0, |w| w[i]) * sq;
                let dist = sq.sqrt();
                pm += dist;
                px = px.max(dist);
            }
            let (mut ev, mut vm, mut vx) = (0.0, 0.0, 0.0f64);
            if !start[f] {
                let (xp, rp) = (frame(f - 1), &pieces[labels[f - 1] as usize]);
                for i in 0..x.len() {
                    let dv = (x[i] - xp[i]).as_dvec3() - (r[i] - rp[i]).as_dvec3();
                    let sq = dv.length_squared();
                    ev += w.map_or(1.0, |w| w[i]) * sq;
                    let dist = sq.sqrt();
                    vm += dist;
                    vx = vx.max(dist);
                }
            }
            let m = x.len().max(1) as f64;
            ((eu, pm / m, px, ev, vm / m, vx), bb)
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
