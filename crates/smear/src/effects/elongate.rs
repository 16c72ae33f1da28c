//! Elongated in-betweens (Section 4.1, SMEAR Eq. 10): every vertex slides along its own trajectory
//! by β_i(f) = S_E(δ_i(f); args) frames.

use anim::MeshAnimation;
use glam::Vec3;
use rayon::prelude::*;

use super::inputs::{check_frame, check_step, held_frame};
use super::{EffectInputs, Stylize, DEFAULT_FRAME_STEP, STYLE_BLOCK};
use crate::{Result, SmearError};

/// Vertices per parallel task when elongating one frame.
const CHUNK: usize = 2048;

/// Options of [`elongate_frame`] / [`elongate`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ElongateOptions {
    /// Frame step: 2 = "on twos" (β scaled by 2, drawings held two frames; Section 5.2).
    pub step: usize,
}

impl Default for ElongateOptions {
    fn default() -> Self {
        ElongateOptions {
            step: DEFAULT_FRAME_STEP,
        }
    }
}

/// Fills `out` with points `start..start + out.len()` of the drawing at frame `h`: S_E over
/// runs of [`STYLE_BLOCK`] points ([`Stylize::eval_block`]) into `beta` (one per point of
/// `out`), then the points displaced
/// ([`Trajectories::displaced_twins`](super::Trajectories::displaced_twins): a point whose
/// twin is in `out` with the same β is a copy of it).
#[inline]
fn fill(
    inputs: &EffectInputs<'_>,
    style: &dyn Stylize,
    (h, scale): (usize, f32),
    start: usize,
    out: &mut [Vec3],
    beta: &mut [f32],
) {
    let beta = &mut beta[..out.len()];
    for (k, run) in beta.chunks_mut(STYLE_BLOCK).enumerate() {
        let first = start + k * STYLE_BLOCK;
        style.eval_block(&inputs.style_block(h, first, run.len()), run);
    }
    inputs
        .trajectories()
        .displaced_twins(h, start, scale, beta, inputs.twins(), out);
}

/// The elongated in-between of one frame, written into a caller buffer (for interactive
/// scrubbing): `p′_i(f) = Q_{i, f+⌊β_i⌋}(β_i − ⌊β_i⌋)` with `β_i(f) = step · S_E(x_i(f))`
/// (SMEAR Eq. 10), `f` replaced by its held frame when `step > 1`.
///
/// # Arguments
/// * `style` — S_E; the paper's linear example is `|x: &StyleInput| x.delta * beta_max`.
///   A non-finite result counts as β = 0.
/// * `out` — one position per point.
///
/// # Errors
/// [`SmearError::InvalidParameter`] when `frame` is out of range, `step` is 0 or `out` has
/// the wrong length.
///
/// # Performance
/// Allocation-free; parallel over vertices (chunks of 2048). One S_E evaluation and one
/// Catmull-Rom point per vertex.
///
/// # Example
/// ```
/// use anim::{Mesh, MeshAnimation};
/// use glam::Vec3;
/// use smear::{elongate_frame, mesh_offsets, EffectInputs, ElongateOptions, OffsetOptions, StyleInput};
///
/// // A tetrahedron translating along +X, one unit per frame.
/// let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
/// let mesh = Mesh::new("tet", p.clone(), vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]);
/// let frames: Vec<Vec3> = (0..5).flat_map(|f| p.iter().map(move |q| *q + Vec3::X * f as f32)).collect();
/// let anim = MeshAnimation::new(mesh, 24.0, frames)?;
/// let delta = mesh_offsets(&anim, &OffsetOptions::default())?;
/// let inputs = EffectInputs::new(&anim, &delta)?;
/// let linear = |x: &StyleInput| x.delta; // S_E(δ; 1)
/// let mut out = vec![Vec3::ZERO; 4];
/// elongate_frame(&inputs, &linear, 2, &ElongateOptions::default(), &mut out)?;
/// assert!((out[1].x - 4.0).abs() < 1e-5); // the leading vertex reaches its next-frame place
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn elongate_frame(
    inputs: &EffectInputs<'_>,
    style: &dyn Stylize,
    frame: usize,
    options: &ElongateOptions,
    out: &mut [Vec3],
) -> Result<()> {
    let step = check_step(options.step)?;
    check_frame(frame, inputs.frame_count())?;
    if out.len() != inputs.point_count() {
        return Err(SmearError::InvalidParameter {
            name: "output buffer",
            reason: format!(
                "expected {} positions, got {}",
                inputs.point_count(),
                out.len()
            ),
        });
    }
    let h = held_frame(frame, step);
    out.par_chunks_mut(CHUNK).enumerate().for_each(|(c, dst)| {
        let mut beta = [0.0f32; CHUNK];
        fill(inputs, style, (h, step as f32), c * CHUNK, dst, &mut beta);
    });
    Ok(())
}

/// Elongated in-betweens of the whole clip (Section 4.1): the input animation with every
/// frame replaced by its elongated in-between; same mesh, frame rate and topology.
///
/// The mesh, frame rate and start time are those of the animation `inputs` were built from
/// ([`EffectInputs::new`]).
///
/// # Errors
/// [`SmearError::InvalidParameter`] when `step` is 0 or `inputs` are surface points (built
/// with [`EffectInputs::at_surface_points`]: there is no mesh to elongate).
///
/// # Performance
/// Parallel over frames; allocates only the output.
pub fn elongate(
    inputs: &EffectInputs<'_>,
    style: &dyn Stylize,
    options: &ElongateOptions,
) -> Result<MeshAnimation> {
    let step = check_step(options.step)?;
    let anim = inputs.animation()?;
    let (frames, n) = (inputs.frame_count(), inputs.point_count());
    let mut positions = vec![Vec3::ZERO; frames * n];
    if n > 0 {
        // Whole frames per task: every twin of a point is in the same task.
        positions.par_chunks_mut(n).enumerate().for_each_init(
            || vec![0.0f32; n],
            |beta, (f, dst)| {
                fill(
                    inputs,
                    style,
                    (held_frame(f, step), step as f32),
                    0,
                    dst,
                    beta,
                )
            },
        );
    }
    let mut out = MeshAnimation::new(anim.mesh.clone(), anim.fps, positions)
        .map_err(|e| SmearError::InvalidScene(e.to_string()))?;
    out.start_time = anim.start_time;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::test_util::{ball, translating_ball};
    use crate::{mesh_offsets, MotionOffsets, OffsetOptions, StyleInput};
    use anim::Aabb;

    #[test]
    fn fig_ball_elongation_covers_neighbour_frames() {
        // Section 5.2 / Fig. 9b: S_E(δ; 1) stretches the object to cover adjacent frames.
        let anim = translating_ball(9, 0.8);
        let delta = mesh_offsets(&anim, &OffsetOptions::default()).unwrap();
        let inputs = EffectInputs::new(&anim, &delta).unwrap();
        let linear = |x: &StyleInput| x.delta;
        let out = elongate(&inputs, &linear, &ElongateOptions::default()).unwrap();
        let f = 4;
        let got = Aabb::from_points(out.frame(f));
        let cover =
            Aabb::from_points(anim.frame(f - 1)).union(Aabb::from_points(anim.frame(f + 1)));
        assert!(
            (got.min.x - cover.min.x).abs() < 1e-3,
            "{got:?} vs {cover:?}"
        );
        assert!(
            (got.max.x - cover.max.x).abs() < 1e-3,
            "{got:?} vs {cover:?}"
        );
        // Length along the motion: 2 + 2 × 0.8; cross-section unchanged.
        assert!((got.max.x - got.min.x - 3.6).abs() < 1e-3);
        assert!((got.max.y - got.min.y - 2.0).abs() < 1e-3);
        // β_max = 2 reaches two frames away.
        let two = |x: &StyleInput| 2.0 * x.delta;
        let out2 = elongate(&inputs, &two, &ElongateOptions::default()).unwrap();
        let got2 = Aabb::from_points(out2.frame(f));
        assert!((got2.max.x - got.max.x - 0.8).abs() < 1e-3);
        // The single-frame entry point agrees with the clip.
        let mut buf = vec![Vec3::ZERO; anim.vertex_count()];
        elongate_frame(&inputs, &linear, f, &ElongateOptions::default(), &mut buf).unwrap();
        assert_eq!(buf.as_slice(), out.frame(f));
    }

    #[test]
    fn on_twos_holds_drawings_and_doubles_beta() {
        let anim = translating_ball(8, 0.5);
        let delta = mesh_offsets(&anim, &OffsetOptions::default()).unwrap();
        let inputs = EffectInputs::new(&anim, &delta).unwrap();
        let linear = |x: &StyleInput| x.delta;
        let twos = ElongateOptions { step: 2 };
        let out = elongate(&inputs, &linear, &twos).unwrap();
        assert_eq!(out.frame(2), out.frame(3));
        let bb = Aabb::from_points(out.frame(2));
        // Held frame 2 displaced by ±2 frames: covers frames 0..4 → 2 + 4 × 0.5.
        assert!((bb.max.x - bb.min.x - 4.0).abs() < 1e-3, "{bb:?}");
        assert!(elongate(&inputs, &linear, &ElongateOptions { step: 0 }).is_err());
    }

    #[test]
    fn twins_of_a_split_mesh_give_the_same_drawing() {
        // Every triangle of the ball with its own three corners (flat shading splits a mesh
        // so): the elongated in-betweens with the twins are those without, bit for bit, for a
        // β every twin shares and for one that reads the offsets (which a split vertex may
        // not share with its twins).
        let ball = translating_ball(7, 0.6);
        let (n, frames) = (ball.vertex_count(), ball.frame_count());
        let corners: Vec<usize> = ball
            .mesh
            .triangles
            .iter()
            .flatten()
            .map(|&v| v as usize)
            .collect();
        let positions = (0..frames)
            .flat_map(|f| corners.iter().map(move |&v| (f, v)))
            .map(|(f, v)| {
                ball.positions()[f * n + v]
                    + Vec3::Y * (0.1 * f as f32 * ball.positions()[v].x).sin()
            })
            .collect();
        let triangles =
            (0..ball.mesh.triangles.len() as u32).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]);
        let mesh = anim::Mesh::new(
            "split",
            corners.iter().map(|&v| ball.mesh.positions[v]).collect(),
            triangles.collect(),
        );
        let split = MeshAnimation::new(mesh, 24.0, positions).unwrap();
        let twins = split.twins();
        assert!(
            twins
                .iter()
                .enumerate()
                .filter(|&(v, &t)| t as usize != v)
                .count()
                > corners.len() / 2
        );
        let delta = mesh_offsets(&split, &OffsetOptions::default()).unwrap();
        let inputs = EffectInputs::new(&split, &delta).unwrap();
        let with = inputs.clone().with_twins(&twins).unwrap();
        let bits = |a: &MeshAnimation| {
            a.positions()
                .iter()
                .map(|p| p.to_array().map(f32::to_bits))
                .collect::<Vec<_>>()
        };
        let fixed = |_: &StyleInput| 1.3f32;
        let offsets = |x: &StyleInput| 2.0 * x.delta;
        for style in [&fixed as &dyn Stylize, &offsets] {
            let options = ElongateOptions::default();
            let a = elongate(&inputs, style, &options).unwrap();
            let b = elongate(&with, style, &options).unwrap();
            assert_eq!(bits(&a), bits(&b));
            let mut one = vec![Vec3::ZERO; split.vertex_count()];
            elongate_frame(&with, style, 3, &options, &mut one).unwrap();
            assert_eq!(one.as_slice(), a.frame(3));
        }
        assert!(inputs.with_twins(&[1; 3]).is_err());
    }

    #[test]
    fn degenerate_inputs_are_defined() {
        // Still clip: offsets 0 → output = input. One frame: identity whatever β.
        let still = translating_ball(4, 0.0);
        let delta = mesh_offsets(&still, &OffsetOptions::default()).unwrap();
        let inputs = EffectInputs::new(&still, &delta).unwrap();
        let nan = |_: &StyleInput| f32::NAN;
        let out = elongate(&inputs, &nan, &ElongateOptions::default()).unwrap();
        assert_eq!(out.positions(), still.positions());
        let one = MeshAnimation::still(ball(1.0, 4, 6));
        let z = MotionOffsets::zeros(1, one.vertex_count());
        let inputs = EffectInputs::new(&one, &z).unwrap();
        let big = |_: &StyleInput| 5.0;
        let out = elongate(&inputs, &big, &ElongateOptions::default()).unwrap();
        assert_eq!(out.positions(), one.positions());
        let mut short = vec![Vec3::ZERO; 3];
        assert!(elongate_frame(&inputs, &big, 0, &ElongateOptions::default(), &mut short).is_err());
    }
}
