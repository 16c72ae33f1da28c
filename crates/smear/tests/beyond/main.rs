//! Smears beyond the paper (issue #22): adaptive subdivision, revolving parts, ground
//! contact, causal mode and streaming.

mod causal;
mod contact;
mod fidelity;
mod legged;
mod revolve;
mod subdivide;
mod swing;

use anim::{FlipbookPart, MeshAnimation, SampledScene};
use smear::{prepare, ElongateStyle, FunctionSpec, PrepareOptions, Prepared, Style};

/// Prepares a point cache with the given offset options (default offsets otherwise).
pub(crate) fn prepared(anim: &MeshAnimation, edit: impl FnOnce(&mut PrepareOptions)) -> Prepared {
    let mut options = PrepareOptions::default();
    edit(&mut options);
    prepare(SampledScene::from_animation(anim.clone()), &options).unwrap()
}

/// A style elongating by S_E(δ; β_max) = β_max·δ with the prepared offsets.
pub(crate) fn elongation(p: &Prepared, beta_max: f32) -> Style {
    Style {
        offsets: p.options().offsets.clone(),
        elongate: Some(ElongateStyle {
            function: FunctionSpec::linear(beta_max),
            ..ElongateStyle::default()
        }),
        ..Style::default()
    }
}

/// The positions of every frame of a flipbook part (point cache or per-frame meshes).
pub(crate) fn part_frames(part: &FlipbookPart) -> Vec<Vec<glam::Vec3>> {
    match part {
        FlipbookPart::Animation { animation, .. } => (0..animation.frame_count())
            .map(|f| animation.frame(f).to_vec())
            .collect(),
        FlipbookPart::Frames { meshes, .. } => meshes.iter().map(|m| m.positions.clone()).collect(),
    }
}
