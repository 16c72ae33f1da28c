//! The effects over a range of frames, for [`stylize_frames`](super::stylize_frames): the
//! whole-clip functions when the range is the whole clip, the per-frame ones
//! ([`elongate_frame`], [`multiples_frame`], [`motion_lines_frame`]) otherwise — so an
//! interactive restyle of the current frame costs one frame, not the clip.

use std::ops::Range;

use anim::MeshAnimation;
use glam::Vec3;

use crate::{
    elongate, elongate_frame, motion_lines, motion_lines_frame, multiples, multiples_frame,
    EffectInputs, ElongateOptions, LineFrame, LineOptions, LineStyle, MultipleCopy,
    MultiplesOptions, Result, SmearError, Stylize,
};

/// Checks that `frames` is a non-empty range inside a clip of `count` frames.
pub(super) fn check_range(frames: &Range<usize>, count: usize) -> Result<()> {
    if frames.start >= frames.end || frames.end > count {
        return Err(SmearError::InvalidParameter {
            name: "frames",
            reason: format!(
                "{}..{} is not a non-empty range of the clip's {count} frames",
                frames.start, frames.end
            ),
        });
    }
    Ok(())
}

fn whole(inputs: &EffectInputs<'_>, frames: &Range<usize>) -> bool {
    frames.start == 0 && frames.end == inputs.frame_count()
}

/// `positions` (frames × vertices of `anim`) as an animation of `anim`'s mesh starting at
/// frame `first`.
pub(super) fn animation_at(
    anim: &MeshAnimation,
    first: usize,
    positions: Vec<Vec3>,
) -> Result<MeshAnimation> {
    let mut out = MeshAnimation::new(anim.mesh.clone(), anim.fps, positions)
        .map_err(|e| SmearError::InvalidScene(e.to_string()))?;
    out.start_time = anim.start_time + first as f32 / anim.fps;
    Ok(out)
}

/// The elongated in-betweens (SMEAR Eq. 10) of `frames`.
pub(super) fn elongate_range(
    inputs: &EffectInputs<'_>,
    style: &dyn Stylize,
    options: &ElongateOptions,
    frames: &Range<usize>,
) -> Result<MeshAnimation> {
    if whole(inputs, frames) {
        return elongate(inputs, style, options);
    }
    let anim = inputs.animation()?;
    let n = inputs.point_count();
    let mut positions = vec![Vec3::ZERO; frames.len() * n];
    for (k, f) in frames.clone().enumerate() {
        elongate_frame(
            inputs,
            style,
            f,
            options,
            &mut positions[k * n..(k + 1) * n],
        )?;
    }
    animation_at(anim, frames.start, positions)
}

/// The multiple in-betweens (SMEAR Eqs. 11–12) of `frames`, one copy per index m.
pub(super) fn multiples_range(
    inputs: &EffectInputs<'_>,
    style: &dyn Stylize,
    options: &MultiplesOptions,
    frames: &Range<usize>,
) -> Result<Vec<MultipleCopy>> {
    if whole(inputs, frames) {
        return multiples(inputs, style, options);
    }
    let anim = inputs.animation()?;
    let n = inputs.point_count();
    let ms = options.indices();
    let df0 = options.spacing_at(0.0)?;
    let mut pos = vec![vec![Vec3::ZERO; frames.len() * n]; ms.len()];
    let mut alpha = vec![vec![0.0f32; frames.len() * n]; ms.len()];
    let mut p = vec![Vec3::ZERO; ms.len() * n];
    let mut a = vec![0.0f32; ms.len() * n];
    for (k, f) in frames.clone().enumerate() {
        multiples_frame(inputs, style, f, options, &mut p, &mut a)?;
        for c in 0..ms.len() {
            pos[c][k * n..(k + 1) * n].copy_from_slice(&p[c * n..(c + 1) * n]);
            alpha[c][k * n..(k + 1) * n].copy_from_slice(&a[c * n..(c + 1) * n]);
        }
    }
    ms.into_iter()
        .zip(pos.into_iter().zip(alpha))
        .map(|(m, (p, alpha))| {
            Ok(MultipleCopy {
                m,
                beta: m as f32 * df0,
                animation: animation_at(anim, frames.start, p)?,
                alpha,
            })
        })
        .collect()
}

/// The motion lines (SMEAR Eq. 13) of `frames`.
pub(super) fn lines_range(
    seeds: &EffectInputs<'_>,
    style: &LineStyle<'_>,
    options: &LineOptions,
    frames: &Range<usize>,
) -> Result<Vec<LineFrame>> {
    if whole(seeds, frames) {
        return motion_lines(seeds, style, options);
    }
    frames
        .clone()
        .map(|f| {
            let mut out = LineFrame::default();
            motion_lines_frame(seeds, style, f, options, &mut out)?;
            Ok(out)
        })
        .collect()
}
