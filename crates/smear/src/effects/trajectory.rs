//! Vertex trajectories (Section 4.1): one uniform Catmull-Rom segment Q_{i,f}(t) per pair of
//! contiguous frames, C1 across frames.

use glam::Vec3;

use crate::{Result, SmearError};

/// The trajectories of a frame-major `frames × points` position buffer (mesh vertices, or
/// surface points after barycentric interpolation — Catmull-Rom is linear in its control
/// points, so the trajectory of a surface point is the barycentric blend of its triangle's
/// vertex trajectories).
///
/// SPEC.md: uniform Catmull-Rom through the integer frames with tangent
/// `(p(f+1) − p(f−1))/2`, end frames duplicated (`p(−1) = p(0)`, `p(F) = p(F−1)`); times before
/// the first or after the last frame clamp to those frames. Nothing is precomputed: a point is
/// four loads and a cubic, so evaluation is allocation-free.
#[derive(Debug, Clone, Copy)]
pub struct Trajectories<'a> {
    positions: &'a [Vec3],
    frames: usize,
    points: usize,
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
        })
    }

    /// The trajectories of a point cache's vertices.
    pub fn of_animation(anim: &'a anim::MeshAnimation) -> Trajectories<'a> {
        Trajectories {
            positions: anim.positions(),
            frames: anim.frame_count(),
            points: anim.vertex_count(),
        }
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
    /// frame 0 (NaN) or clamps (±∞). `i` must be below the point count.
    ///
    /// # Performance
    /// Four loads and a cubic; no allocation.
    #[inline]
    pub fn at(&self, i: usize, time: f32) -> Vec3 {
        let last = self.frames.saturating_sub(1);
        if last == 0 || time.is_nan() || time <= 0.0 {
            return self.positions[i];
        }
        if time >= last as f32 {
            return self.positions[last * self.points + i];
        }
        let k = (time.floor() as usize).min(last - 1);
        let t = time - k as f32;
        let k = k as isize;
        let p0 = self.at_frame(k - 1, i);
        let p1 = self.at_frame(k, i);
        let p2 = self.at_frame(k + 1, i);
        let p3 = self.at_frame(k + 2, i);
        hermite(p1, p2, (p2 - p0) * 0.5, (p3 - p1) * 0.5, t)
    }

    /// Point `i` of frame `f` displaced by `beta` frames along its trajectory:
    /// `p′_i(f) = Q_{i, f+⌊β⌋}(β − ⌊β⌋)` (Section 4.1). A non-finite `beta` counts as 0.
    #[inline]
    pub fn displaced(&self, f: usize, i: usize, beta: f32) -> Vec3 {
        let beta = if beta.is_finite() { beta } else { 0.0 };
        self.at(i, f as f32 + beta)
    }
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
