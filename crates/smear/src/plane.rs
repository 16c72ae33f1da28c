//! Simple objects: the separation plane of paper SMEAR Eq. 1.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use crate::velocity::{track_velocity, CameraSpace};

/// Area-weighted surface centroid of a triangle mesh (SPEC.md): Σ A_t · centroid_t / Σ A_t,
/// accumulated in f32 per block of 256 triangles and f64 across blocks. Triangles with an
/// out-of-range index are ignored.
///
/// # Returns
/// The centroid; the vertex average when the surface has no area (no or degenerate
/// triangles); `Vec3::ZERO` for no vertex.
///
/// # Performance
/// One pass over the triangles, bound by gathering their corners (a struct-of-arrays,
/// vectorized variant measured slower: the gathers dominate, not the arithmetic).
pub fn surface_centroid(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec3 {
    const BLOCK: usize = 256;
    let n = positions.len();
    let (mut acc, mut area) = (DVec3::ZERO, 0.0f64);
    // f32 per triangle, f64 across blocks of triangles.
    for block in triangles.chunks(BLOCK) {
        let (mut acc32, mut area32) = (Vec3::ZERO, 0.0f32);
        for t in block {
            let [i, j, k] = t.map(|i| i as usize);
            if i >= n || j >= n || k >= n {
                continue;
            }
            let (a, b, c) = (positions[i], positions[j], positions[k]);
            let w = (b - a).cross(c - a).length();
            acc32 += w * (a + b + c);
            area32 += w;
        }
        acc += acc32.as_dvec3();
        area += area32 as f64;
    }
    if area > 0.0 && acc.is_finite() {
        return (acc / (3.0 * area)).as_vec3();
    }
    if positions.is_empty() {
        return Vec3::ZERO;
    }
    let sum: DVec3 = positions.iter().map(|p| p.as_dvec3()).sum();
    (sum / positions.len() as f64).as_vec3()
}

/// One frame's separation plane of SMEAR Eq. 1, pre-scaled: δ_i = (p_i − c) · `normal`, where
/// `normal` = v̂ / max_j |δ̃_j|, or zero for a still frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PlaneFrame {
    pub(crate) centroid: Vec3,
    pub(crate) normal: Vec3,
}

impl PlaneFrame {
    /// SMEAR Eq. 1 at point `p`.
    #[inline]
    pub(crate) fn eval(&self, p: Vec3) -> f32 {
        (p - self.centroid).dot(self.normal)
    }
}

/// Separation planes of every frame of a frame-major `frames × vertices` buffer, and the
/// (unsmoothed) offsets of its vertices.
///
/// # Arguments
/// * `still` — velocities at most this long give a still frame (offsets 0).
/// * `causal` — difference velocities backward (past-only mode).
/// * `space` — measure the centroid's velocity relative to this camera.
/// * `raw` — receives the frame-major `frames × vertices` offsets δ_i(f) of SMEAR Eq. 1.
///
/// # Performance
/// Two parallel passes over frames: centroids, then per frame the maximum of SMEAR Eq. 1 and the
/// offsets back to back (the frame is still in cache for the second read). No allocation
/// per vertex; every `raw` element is written, never read. (Computing each frame's plane
/// right after the next frame's centroid, to read every frame from memory once, measured no
/// faster: the sequential pass is prefetched well, the centroid's gathers are the cost.)
pub(crate) fn plane_frames(
    positions: &[Vec3],
    frames: usize,
    vertices: usize,
    triangles: &[[u32; 3]],
    still: f32,
    causal: bool,
    space: Option<&CameraSpace>,
    raw: &mut [f32],
) -> Vec<PlaneFrame> {
    let frame = |f: usize| &positions[f * vertices..(f + 1) * vertices];
    let centroids: Vec<Vec3> = (0..frames)
        .into_par_iter()
        .map(|f| surface_centroid(frame(f), triangles))
        .collect();
    let plane = |f: usize| {
        let c = centroids[f];
        let v = track_velocity(f, frames, space, causal, |g| centroids[g]);
        let dir = if v.length() > still {
            v.try_normalize()
        } else {
            None
        };
        let Some(dir) = dir else {
            return PlaneFrame {
                centroid: c,
                normal: Vec3::ZERO,
            };
        };
        let max = frame(f)
            .iter()
            .fold(0.0f32, |m, p| m.max((*p - c).dot(dir).abs()));
        let normal = if max > still && max.is_finite() {
            dir / max
        } else {
            Vec3::ZERO
        };
        PlaneFrame {
            centroid: c,
            normal,
        }
    };
    if vertices == 0 {
        return (0..frames).map(plane).collect();
    }
    raw.par_chunks_mut(vertices)
        .enumerate()
        .map(|(f, dst)| {
            let pl = plane(f);
            for (d, p) in dst.iter_mut().zip(frame(f)) {
                *d = pl.eval(*p);
            }
            pl
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centroid_is_area_weighted() {
        // A big triangle and a far tiny one: the centroid stays near the big one, unlike the
        // vertex mean.
        let p = vec![
            Vec3::ZERO,
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 0.0),
            Vec3::new(100.0, 0.0, 0.0),
            Vec3::new(100.01, 0.0, 0.0),
            Vec3::new(100.0, 0.01, 0.0),
        ];
        let c = surface_centroid(&p, &[[0, 1, 2], [3, 4, 5]]);
        assert!((c - Vec3::new(1.0, 1.0, 0.0)).length() < 2e-3, "{c}");
        let mean = surface_centroid(&p, &[]);
        assert!((mean.x - 50.5).abs() < 1e-2);
    }
}
