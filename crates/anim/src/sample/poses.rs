//! The nodes' world matrices of every frame of a clip: shared by [`super::sample`] and
//! [`sample_node_world`], which samples them alone (no mesh).

use glam::Mat4;
use rayon::prelude::*;

use super::{check_sampling, clip_frames, SampleOptions};
use crate::{Result, Scene, Transform};

/// The world matrix of every node for every frame of the clip `options` pick, frame-major
/// (`frames × nodes`, as [`SampledScene::node_world`], bit for bit), and the frame count,
/// without sampling any mesh: what a renderer that skins the meshes itself needs of a clip.
///
/// # Errors
/// As [`sample`]: an invalid scene or frame rate, a clip not found, a clip over the frame
/// budget.
pub fn sample_node_world(scene: &Scene, options: &SampleOptions) -> Result<(usize, Vec<Mat4>)> {
    scene.validate()?;
    let (clip, start, frames) = clip_frames(scene, options)?;
    check_sampling(
        clip.map_or(0.0, |c| c.duration()),
        options.fps,
        frames,
        frames.saturating_mul(scene.nodes.len().max(1)),
    )?;
    let order = scene.topological_order();
    let poses = pose_frames(scene, clip, start, options.fps, frames, &order);
    let mut node_world = Vec::with_capacity(frames * scene.nodes.len());
    for (w, _) in &poses {
        node_world.extend_from_slice(w);
    }
    Ok((frames, node_world))
}

/// Every frame's node world matrices and morph weights (cheap, done once per sampling).
pub(super) fn pose_frames(
    scene: &Scene,
    clip: Option<&crate::Clip>,
    start: f32,
    fps: f32,
    frames: usize,
    order: &[usize],
) -> Vec<(Vec<Mat4>, Vec<Vec<f32>>)> {
    (0..frames)
        .into_par_iter()
        .map_init(Vec::new, |locals: &mut Vec<Transform>, f| {
            let t = start + f as f32 / fps;
            let mut weights: Vec<Vec<f32>> = Vec::new();
            let mut world = Vec::new();
            scene.pose_at(clip, t, locals, &mut weights);
            scene.world_matrices(order, locals, &mut world);
            (world, weights)
        })
        .collect()
}
