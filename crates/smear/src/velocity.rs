//! Velocities by central differences (SPEC.md), in world or camera space.

use anim::{Camera, MeshAnimation};
use glam::{Mat4, Vec3};
use rayon::prelude::*;

/// Frames `(prev, next)` and scale of the velocity difference at frame `f` of `frames`:
/// central `(p(f+1) − p(f−1))/2` inside, one-sided at the ends, zero for one-frame clips.
/// `causal` (past-only mode, issue #22): the backward difference `p(f) − p(f−1)` (forward
/// at frame 0 would read the future, so frame 0 is still).
#[inline]
pub(crate) fn difference_frames(f: usize, frames: usize, causal: bool) -> (usize, usize, f32) {
    if causal {
        return if f == 0 || frames < 2 {
            (0, 0, 0.0)
        } else {
            (f - 1, f, 1.0)
        };
    }
    if frames < 2 {
        (0, 0, 0.0)
    } else if f == 0 {
        (0, 1, 1.0)
    } else if f + 1 >= frames {
        (frames - 2, frames - 1, 1.0)
    } else {
        (f - 1, f + 1, 0.5)
    }
}

/// Per-frame transforms of a (moving) camera: positions are expressed relative to it by the
/// inverse of its world matrix (SPEC.md, camera space).
#[derive(Debug, Clone)]
pub(crate) struct CameraSpace {
    world: Vec<Mat4>,
    view: Vec<Mat4>,
}

impl CameraSpace {
    /// The camera's matrices for `frames` frames (clamped to its last frame).
    pub(crate) fn new(camera: &Camera, frames: usize) -> CameraSpace {
        let world: Vec<Mat4> = (0..frames)
            .map(|f| {
                camera
                    .world
                    .get(f)
                    .or(camera.world.last())
                    .copied()
                    .unwrap_or(Mat4::IDENTITY)
            })
            .collect();
        let view = world.iter().map(|m| m.inverse()).collect();
        CameraSpace { world, view }
    }

    /// Largest absolute translation coordinate of the camera over the frames.
    pub(crate) fn max_translation(&self) -> f32 {
        self.world.iter().fold(0.0f32, |m, w| {
            m.max(w.w_axis.truncate().abs().max_element())
        })
    }

    /// Velocity at frame `f` of a point whose world position per frame is `track`, measured
    /// relative to the camera and expressed in camera coordinates.
    #[inline]
    pub(crate) fn camera_velocity(
        &self,
        f: usize,
        frames: usize,
        causal: bool,
        track: impl Fn(usize) -> Vec3,
    ) -> Vec3 {
        let (a, b, s) = difference_frames(f, frames, causal);
        let pa = self.view[a].transform_point3(track(a));
        let pb = self.view[b].transform_point3(track(b));
        (pb - pa) * s
    }

    /// The relative velocity of [`CameraSpace::camera_velocity`] expressed in world axes of
    /// frame `f`, so that world-space geometry can be separated by it directly (exact for
    /// cameras whose world matrix is rigid up to a uniform scale).
    #[inline]
    pub(crate) fn relative_velocity(
        &self,
        f: usize,
        frames: usize,
        causal: bool,
        track: impl Fn(usize) -> Vec3,
    ) -> Vec3 {
        self.world[f].transform_vector3(self.camera_velocity(f, frames, causal, track))
    }
}

/// Velocity at frame `f` of a tracked point, world space or relative to a camera.
#[inline]
pub(crate) fn track_velocity(
    f: usize,
    frames: usize,
    space: Option<&CameraSpace>,
    causal: bool,
    track: impl Fn(usize) -> Vec3,
) -> Vec3 {
    match space {
        Some(c) => c.relative_velocity(f, frames, causal, track),
        None => {
            let (a, b, s) = difference_frames(f, frames, causal);
            (track(b) - track(a)) * s
        }
    }
}

/// Per-vertex velocities of a point cache in units per frame (SPEC.md: central difference
/// `(p(f+1) − p(f−1))/2`, one-sided at the first/last frame, zero for one-frame clips).
///
/// # Returns
/// A frame-major `frames × vertices` buffer, like the cache.
///
/// # Performance
/// Parallel over frames, one subtraction per vertex.
pub fn vertex_velocities(anim: &MeshAnimation) -> Vec<Vec3> {
    velocities_impl(anim, None)
}

/// Past-only per-vertex velocities (causal mode, issue #22): `p(f) − p(f−1)`, zero at the
/// first frame; frame `f` reads no frame after `f`.
pub fn causal_vertex_velocities(anim: &MeshAnimation) -> Vec<Vec3> {
    buffer_velocities(
        anim.positions(),
        anim.frame_count(),
        anim.vertex_count(),
        true,
    )
}

/// Per-vertex velocities relative to a (moving, rotating) camera, in camera coordinates:
/// every frame's positions are first transformed by the inverse of that frame's camera world
/// matrix, then differenced as in [`vertex_velocities`].
pub fn camera_vertex_velocities(anim: &MeshAnimation, camera: &Camera) -> Vec<Vec3> {
    let space = CameraSpace::new(camera, anim.frame_count());
    velocities_impl(anim, Some(&space))
}

/// Central-difference velocities of a frame-major buffer of `frames × points` positions
/// (world space), as [`vertex_velocities`]; backward differences when `causal`.
pub(crate) fn buffer_velocities(
    positions: &[Vec3],
    frames: usize,
    points: usize,
    causal: bool,
) -> Vec<Vec3> {
    differences(positions, frames, points, None, causal)
}

/// [`buffer_velocities`] relative to a camera (as [`camera_vertex_velocities`]).
pub(crate) fn camera_buffer_velocities(
    positions: &[Vec3],
    frames: usize,
    points: usize,
    space: &CameraSpace,
    causal: bool,
) -> Vec<Vec3> {
    differences(positions, frames, points, Some(space), causal)
}

fn velocities_impl(anim: &MeshAnimation, space: Option<&CameraSpace>) -> Vec<Vec3> {
    differences(
        anim.positions(),
        anim.frame_count(),
        anim.vertex_count(),
        space,
        false,
    )
}

fn differences(
    positions: &[Vec3],
    frames: usize,
    n: usize,
    space: Option<&CameraSpace>,
    causal: bool,
) -> Vec<Vec3> {
    // Zeroed by the allocator (fresh pages, no memset: `vec![Vec3::ZERO; _]` writes every
    // element); each worker maps the pages of the frames it writes.
    let mut out: Vec<Vec3> = bytemuck::allocation::zeroed_vec(frames * n);
    if n == 0 || positions.len() < frames * n {
        return out;
    }
    out.par_chunks_mut(n).enumerate().for_each(|(f, dst)| {
        let frames = difference_frames(f, frames, causal);
        run_differences(positions, n, frames, 0, space, dst, |v| v);
    });
    out
}

/// Writes `each(v)` of the velocity `v` of points `start..start + out.len()` into `out`, from
/// the difference `frames` of [`difference_frames`] in a frame-major buffer of `n` points
/// per frame: one loop per space, the camera's transforms looked up once.
#[inline(always)]
fn run_differences<T>(
    positions: &[Vec3],
    n: usize,
    (a, b, s): (usize, usize, f32),
    start: usize,
    space: Option<&CameraSpace>,
    out: &mut [T],
    each: impl Fn(Vec3) -> T,
) {
    let len = out.len();
    let pa = &positions[a * n + start..a * n + start + len];
    let pb = &positions[b * n + start..b * n + start + len];
    match space {
        None => {
            for ((o, p), q) in out.iter_mut().zip(pa).zip(pb) {
                *o = each((*q - *p) * s);
            }
        }
        Some(c) => {
            let (va, vb) = (c.view[a], c.view[b]);
            for ((o, p), q) in out.iter_mut().zip(pa).zip(pb) {
                *o = each((vb.transform_point3(*q) - va.transform_point3(*p)) * s);
            }
        }
    }
}

/// The velocity at frame `f` of point `i` of a frame-major `frames × n` buffer, as
/// [`buffer_velocities`] / [`camera_buffer_velocities`] compute it (the same operations,
/// so the same value bit for bit), without a buffer: what a prepared scene's stylization
/// reads, frame by frame. `f < frames`, `i < n` and `positions` of `frames × n`.
#[inline]
pub(crate) fn point_velocity(
    positions: &[Vec3],
    (frames, n): (usize, usize),
    (f, i): (usize, usize),
    space: Option<&CameraSpace>,
    causal: bool,
) -> Vec3 {
    let (a, b, s) = difference_frames(f, frames, causal);
    let (p, q) = (positions[a * n + i], positions[b * n + i]);
    match space {
        None => (q - p) * s,
        Some(c) => (c.view[b].transform_point3(q) - c.view[a].transform_point3(p)) * s,
    }
}

/// The speeds `|v|` at frame `f` of points `start..start + out.len()` of a frame-major
/// `frames × n` buffer: those of [`point_velocity`] (the same operations, so the same values
/// bit for bit) with the frames and the camera's transforms looked up once for the run.
pub(crate) fn run_speeds(
    positions: &[Vec3],
    (frames, n): (usize, usize),
    (f, start): (usize, usize),
    space: Option<&CameraSpace>,
    causal: bool,
    out: &mut [f32],
) {
    let frames = difference_frames(f, frames, causal);
    run_differences(positions, n, frames, start, space, out, |v| v.length());
}

/// Speeds |v| of a velocity buffer (units per frame), as stylization uses them.
pub fn speeds(velocities: &[Vec3]) -> Vec<f32> {
    velocities.par_iter().map(|v| v.length()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::test_util::camera;
    use anim::Mesh;

    fn moving_point(xs: &[f32]) -> MeshAnimation {
        let m = Mesh::new("p", vec![Vec3::ZERO], vec![]);
        MeshAnimation::new(
            m,
            24.0,
            xs.iter().map(|&x| Vec3::new(x, 0.0, 0.0)).collect(),
        )
        .unwrap()
    }

    #[test]
    fn central_and_one_sided_differences() {
        let v = vertex_velocities(&moving_point(&[0.0, 1.0, 4.0, 9.0]));
        let x: Vec<f32> = v.iter().map(|v| v.x).collect();
        assert_eq!(x, vec![1.0, 2.0, 4.0, 5.0]);
        assert_eq!(vertex_velocities(&moving_point(&[3.0])), vec![Vec3::ZERO]);
    }

    #[test]
    fn camera_following_the_point_sees_it_still() {
        let anim = moving_point(&[0.0, 1.0, 2.0]);
        let cam = camera(
            (0..3)
                .map(|f| Mat4::from_translation(Vec3::new(f as f32, 0.0, 5.0)))
                .collect(),
        );
        for v in camera_vertex_velocities(&anim, &cam) {
            assert!(v.length() < 1e-6);
        }
        assert_eq!(speeds(&vertex_velocities(&anim)), vec![1.0, 1.0, 1.0]);
    }
}
