//! Sampling a morph-only clip as weights (see [`MorphAnimation`]): when every selected mesh
//! object is unskinned and its node's world matrix is the same on every frame, each frame is
//! `M·rest + Σₖ wₖ · (M·targetₖ)`, so the weights, the rest and the targets describe it whole.

use glam::Vec3;
use rayon::prelude::*;

use super::{check_sampling, clip_frames, SampleOptions};
use crate::{MorphAnimation, Result, Scene};

/// The selected mesh objects of a clip of `scene` as morph weights, in the order of
/// [`sample`](super::sample)'s objects; `None` when one of them is skinned or its node
/// moves (then only positions describe it), when one has at least as many morph targets as
/// the clip has frames (a flipbook of targets, one per frame: its positions are no larger,
/// and the weight form's products over the targets would cost more than the frames
/// themselves), or when the mesh filter matches nothing.
///
/// # Errors
/// As [`sample`](super::sample): an invalid scene, frame rate or clip.
///
/// # Performance
/// Poses every frame (node matrices and weights), never the vertices.
pub fn sample_morph(scene: &Scene, options: &SampleOptions) -> Result<Option<Vec<MorphAnimation>>> {
    scene.validate()?;
    let (clip, start, frames) = clip_frames(scene, options)?;
    let fps = options.fps;
    check_sampling(clip.map_or(0.0, |c| c.duration()), fps, frames, frames)?;
    let nodes: Vec<usize> = scene
        .mesh_nodes()
        .into_iter()
        .filter(|&n| options.meshes.is_empty() || options.meshes.contains(&scene.object_name(n)))
        .collect();
    let skinned = |n: usize| {
        let node = &scene.nodes[n];
        node.skin.is_some()
            && node
                .mesh
                .is_some_and(|m| scene.meshes[m].joint_weights.is_some())
    };
    if nodes.is_empty() || nodes.iter().any(|&n| skinned(n)) {
        return Ok(None);
    }
    let order = scene.topological_order();
    // Per frame: each selected node's world matrix and weights.
    let poses: Vec<Vec<(glam::Mat4, Vec<f32>)>> = (0..frames)
        .into_par_iter()
        .map_init(
            || (Vec::new(), Vec::new(), Vec::new()),
            |(locals, weights, world), f| {
                let t = start + f as f32 / fps;
                scene.pose_at(clip, t, locals, weights);
                scene.world_matrices(&order, locals, world);
                nodes
                    .iter()
                    .map(|&n| (world[n], std::mem::take(&mut weights[n])))
                    .collect()
            },
        )
        .collect();
    let mut out = Vec::with_capacity(nodes.len());
    for (i, &n) in nodes.iter().enumerate() {
        let m = poses[0][i].0;
        if poses.iter().any(|p| p[i].0 != m) {
            return Ok(None);
        }
        let sm = &scene.meshes[scene.nodes[n].mesh.expect("mesh node")];
        let k = sm.morph_targets.len();
        if k >= frames {
            return Ok(None);
        }
        let base: Vec<Vec3> = sm
            .mesh
            .positions
            .iter()
            .map(|&p| m.transform_point3(p))
            .collect();
        let targets: Vec<Vec3> = sm
            .morph_targets
            .iter()
            .flat_map(|t| t.positions.iter().map(|&d| m.transform_vector3(d)))
            .collect();
        let mut weights = Vec::with_capacity(frames * k.max(1));
        for p in &poses {
            let w = &p[i].1;
            if k == 0 {
                weights.push(0.0);
            } else {
                // Missing weights are 0 (the sampler zips targets with weights).
                weights.extend((0..k).map(|j| w.get(j).copied().unwrap_or(0.0)));
            }
        }
        let mut mesh = sm.mesh.clone();
        mesh.name = scene.object_name(n);
        mesh.normals = None;
        let mut a = MorphAnimation::new(mesh, fps, base, targets, weights)?;
        a.start_time = start;
        out.push(a);
    }
    Ok(Some(out))
}
