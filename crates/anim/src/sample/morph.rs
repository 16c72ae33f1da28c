//! Morph targets on rest positions (glTF: `rest + Σ wₖ · targetₖ`, added in target order, so
//! every path gives the same sums), for the skinned path frame by frame and for unskinned
//! objects in batches of frames.

use std::ops::Range;

use glam::Vec3;

use super::Pose;
use crate::MorphTarget;

/// Most frames of an unskinned object morphed together (see [`rigid_batch`]).
pub(super) const MORPH_BATCH: usize = 32;
/// Vertices per block of [`rigid_batch`]: the blocks of all morph targets stay in cache.
const MORPH_BLOCK: usize = 256;

/// `m += w · d`, component-wise (the same operations as on `Vec3`, vectorized).
fn add_scaled(m: &mut [Vec3], d: &[Vec3], w: f32) {
    let m: &mut [f32] = bytemuck::cast_slice_mut(m);
    let d: &[f32] = bytemuck::cast_slice(d);
    for (m, d) in m.iter_mut().zip(d) {
        *m += w * *d;
    }
}

/// Vertices `range` of `rest` morphed by `weights` (one per target), written in `scratch`;
/// `rest[range]` itself when no target is active (no copy).
pub(super) fn morphed<'a>(
    rest: &'a [Vec3],
    targets: &[MorphTarget],
    weights: &[f32],
    range: Range<usize>,
    scratch: &'a mut Vec<Vec3>,
) -> &'a [Vec3] {
    let active = || targets.iter().zip(weights).filter(|(_, &w)| w != 0.0);
    if active().next().is_none() {
        return &rest[range];
    }
    scratch.clear();
    scratch.extend_from_slice(&rest[range.clone()]);
    for (t, &w) in active() {
        add_scaled(scratch, &t.positions[range.clone()], w);
    }
    scratch
}

/// Frames `batch` of an unskinned object into `out` (`batch.len()` frames): [`morphed`],
/// then the node's world matrix. Block by block of vertices, so each block of the targets is
/// read once for the whole batch. Whether every position is finite.
pub(super) fn rigid_batch(
    rest: &[Vec3],
    targets: &[MorphTarget],
    node: usize,
    batch: &[Pose],
    out: &mut [Vec3],
    scratch: &mut Vec<Vec3>,
) -> bool {
    let nv = rest.len();
    for c0 in (0..nv).step_by(MORPH_BLOCK) {
        let c1 = (c0 + MORPH_BLOCK).min(nv);
        for ((world, weights), out) in batch.iter().zip(out.chunks_mut(nv)) {
            let source = morphed(rest, targets, &weights[node], c0..c1, scratch);
            let m = world[node];
            for (o, p) in out[c0..c1].iter_mut().zip(source) {
                *o = m.transform_point3(*p);
            }
        }
    }
    out.iter().all(|p| p.is_finite())
}
