//! Preview pictures of loa results, drawn by `render`: the line with its keystrokes
//! ([`line_preview`]) and the character following it ([`motion_preview`]).

use glam::{Vec2, Vec3};

use crate::animate::Motion;
use crate::{Animation, Keystrokes};

/// Why a preview cannot be drawn.
#[derive(Debug, thiserror::Error)]
pub enum PreviewError {
    /// The character's clip cannot be sampled.
    #[error(transparent)]
    Sample(#[from] anim::AnimError),
    /// The picture cannot be drawn or encoded.
    #[error(transparent)]
    Render(#[from] render::RenderError),
}

/// The line preview (`render::line_preview`): a GIF of every frame, or a PNG onion skin.
///
/// # Errors
/// The picture cannot be encoded.
pub fn line_preview(
    animation: &Animation,
    keys: &Keystrokes,
    gif: bool,
) -> Result<Vec<u8>, PreviewError> {
    let chains: Vec<Vec<Vec2>> = animation
        .frames
        .iter()
        .map(|f| f.chain.joints().iter().map(|p| p.as_vec2()).collect())
        .collect();
    let strokes: Vec<Vec<Vec2>> = keys
        .keys()
        .iter()
        .map(|k| k.stroke.points().iter().map(|p| p.as_vec2()).collect())
        .collect();
    Ok(render::line_preview(
        &chains,
        &strokes,
        animation.fps as f32,
        gif,
    )?)
}

/// The motion preview: the character's meshes sampled from the written clip of `scene`, its
/// bones, the line and the constrained joints, through a view that follows the character
/// (or through `camera`). A GIF of every frame, or a PNG of the first.
///
/// # Errors
/// The clip cannot be sampled or the picture cannot be encoded.
pub fn motion_preview(
    scene: &anim::Scene,
    motion: &Motion,
    skeleton: &anim::Skeleton,
    camera: Option<&anim::Camera>,
    gif: bool,
) -> Result<Vec<u8>, PreviewError> {
    let sampled = anim::sample(
        scene,
        &anim::SampleOptions {
            fps: motion.fps as f32,
            clip: Some(0),
            meshes: Vec::new(),
        },
    )?;
    let meshes: Vec<&anim::MeshAnimation> = sampled.objects.iter().map(|o| &o.animation).collect();
    let positions: Vec<Vec3> = motion.positions.iter().map(|p| p.as_vec3()).collect();
    let bones: Vec<(usize, usize)> = skeleton
        .joints
        .iter()
        .enumerate()
        .filter_map(|(k, j)| j.parent.map(|p| (p, k)))
        .collect();
    let lines: Vec<Vec<Vec3>> = (0..motion.frames())
        .map(|f| motion.line_world(f).iter().map(|p| p.as_vec3()).collect())
        .collect();
    let cam = &motion.camera;
    let preview = render::RigPreview {
        meshes: &meshes,
        joints: motion.joints,
        positions: &positions,
        bones: &bones,
        lines: &lines,
        marked: &motion.constrained,
        fps: motion.fps as f32,
    };
    let axes = render::ViewAxes {
        right: cam.right.as_vec3(),
        up: cam.up.as_vec3(),
        forward: cam.forward.as_vec3(),
    };
    let view = camera.map_or(render::RigView::Follow(axes), render::RigView::Camera);
    Ok(render::rig_preview(&preview, view, gif)?)
}
