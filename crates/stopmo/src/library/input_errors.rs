//! Errors against the artist's animation: the library is optimized on the homogenized parts,
//! but what the audience sees is judged against the input (before homogenization), and what
//! homogenization itself changed is reported separately.

use anim::MeshAnimation;
use glam::Vec3;

use super::build::Library;
use super::metrics::FrameErrors;

/// Per-frame position and velocity errors of `approx` against `reference` (same vertex count,
/// `frames` frames; no velocity at frame 0 and at every frame in `cuts`), as defined for
/// [`FrameErrors`].
pub fn compare_frames<'a>(
    frames: usize,
    cuts: &[usize],
    reference: impl Fn(usize) -> &'a [Vec3],
    approx: impl Fn(usize) -> &'a [Vec3],
) -> FrameErrors {
    let mut e = FrameErrors {
        position_mean: Vec::with_capacity(frames),
        position_max: Vec::with_capacity(frames),
        velocity_mean: Vec::with_capacity(frames),
        velocity_max: Vec::with_capacity(frames),
        has_velocity: Vec::with_capacity(frames),
    };
    for f in 0..frames {
        let (x, r) = (reference(f), approx(f));
        let n = x.len().min(r.len()).max(1) as f64;
        let (mut sum, mut max) = (0.0f64, 0.0f64);
        for (a, b) in x.iter().zip(r) {
            let d = f64::from(a.distance(*b));
            sum += d;
            max = max.max(d);
        }
        e.position_mean.push(sum / n);
        e.position_max.push(max);
        let has = f > 0 && !cuts.contains(&f);
        let (mut vs, mut vm) = (0.0f64, 0.0f64);
        if has {
            let (xp, rp) = (reference(f - 1), approx(f - 1));
            for i in 0..x.len().min(r.len()) {
                let d = f64::from(((x[i] - xp[i]) - (r[i] - rp[i])).length());
                vs += d;
                vm = vm.max(d);
            }
        }
        e.velocity_mean.push(if has { vs / n } else { 0.0 });
        e.velocity_max.push(vm);
        e.has_velocity.push(has);
    }
    e
}

impl Library {
    /// Per-frame errors (model units) of part `part`'s stop-motion reconstruction against
    /// `input` — e.g. the part of the artist's animation before seam homogenization — with
    /// the same vertices and frames; `None` when they do not match.
    pub fn errors_against(
        &self,
        part: usize,
        input: &MeshAnimation,
        cuts: &[usize],
    ) -> Option<FrameErrors> {
        let sol = &self.parts.get(part)?.solution;
        let m = input.vertex_count();
        let ok = sol.labels.len() == input.frame_count()
            && sol.pieces.iter().all(|p| p.len() == m)
            && sol.labels.iter().all(|&l| (l as usize) < sol.pieces.len());
        ok.then(|| {
            compare_frames(
                input.frame_count(),
                cuts,
                |f| input.frame(f),
                |f| sol.pieces[sol.labels[f] as usize].as_slice(),
            )
        })
    }
}
