//! The whole clip's elongated body as what changed: per frame a bit per vertex (set where the
//! style moved it off the input) and the moved vertices' displacements from the input,
//! quantized to 16 bits with a per-frame step. The page holds the input already
//! (`/api/scene`), so it rebuilds the core's result from few bytes — a speed style leaves the
//! slow vertices (~60 % of the robot's Dance) where they were. The error bound is in
//! docs/studio.md ("Whole clips").

use anim::glam::Vec3;
use rayon::prelude::*;

use crate::pack::Pack;

/// Largest quantization error of a moved vertex coordinate, as a fraction of the input clip's
/// bounding-box diagonal: a frame whose displacements would need a coarser step sends the
/// whole answer as float32 (`body.positions`).
pub(crate) const MAX_QUANTIZATION_ERROR: f32 = 1e-5;

/// Adds `body.changed` (u32 words, per frame `⌈vertices / 32⌉`, bit `v % 32` of word
/// `v / 32` set when vertex `v` moved), `body.step` (f32 per frame) and `body.delta` (i16 xyz
/// of the moved vertices, frame-major, in vertex order: the position is the input's plus
/// `delta × step`). When a frame's displacements are too large for 16 bits within
/// [`MAX_QUANTIZATION_ERROR`] of `diagonal` (the input's bounding box over the frames
/// answered, [`crate::files::Clip::diagonal`]), `body.positions` (f32 xyz of the moved
/// vertices) replaces `body.step` and `body.delta`. `body(f)` and `input(f)` are the merged
/// vertices of frame `f` of the answer and of the input clip. Each frame is compared and
/// quantized by one task while its vertices are in cache, frames in parallel; the answer's
/// buffers are handed to the pack, not copied.
pub(crate) fn pack_changes<'a>(
    pack: &mut Pack,
    (frames, vertices): (usize, usize),
    diagonal: f32,
    body: impl Fn(usize) -> Vec<&'a [Vec3]> + Sync,
    input: impl Fn(usize) -> &'a [Vec3] + Sync,
) {
    let words = vertices.div_ceil(32);
    let limit = 2.0 * f32::from(i16::MAX) * MAX_QUANTIZATION_ERROR * diagonal;
    let mut mask = vec![0u32; frames * words];
    // Per frame: its step (0 when it does not fit in 16 bits) and its moved vertices' deltas.
    let quantized: Vec<(f32, Vec<i16>)> = mask
        .par_chunks_mut(words.max(1))
        .enumerate()
        .map(|(f, bits)| {
            let (slices, before) = (body(f), input(f));
            let (mut count, mut largest) = (0, 0.0f32);
            each_vertex(&slices, |v, p| {
                // Bit-exact: an unmoved vertex is drawn from the input itself.
                match before.get(v) {
                    Some(q) if q.to_array() == p.to_array() => {}
                    q => {
                        bits[v / 32] |= 1 << (v % 32);
                        count += 1;
                        largest =
                            largest.max(q.map_or(f32::INFINITY, |q| (p - *q).abs().max_element()));
                    }
                }
            });
            if largest > limit {
                return (0.0, Vec::new());
            }
            let step = if largest > 0.0 {
                largest / f32::from(i16::MAX)
            } else {
                1.0
            };
            let mut delta = Vec::with_capacity(3 * count);
            each_moved(&slices, before, bits, |_, p, q| {
                delta.extend(((p - q) / step).to_array().map(round_i16));
            });
            (step, delta)
        })
        .collect();
    if quantized.iter().all(|(step, _)| *step > 0.0) {
        let (steps, delta): (Vec<f32>, Vec<Vec<i16>>) = quantized.into_iter().unzip();
        pack.u32_vec("body.changed", mask);
        pack.f32("body.step", steps);
        pack.i16_parts("body.delta", delta);
    } else {
        let counts: Vec<usize> = mask
            .chunks(words.max(1))
            .map(|w| w.iter().map(|x| x.count_ones() as usize).sum())
            .collect();
        let bits = |f: usize| &mask[f * words..(f + 1) * words];
        let mut positions = vec![0.0f32; 3 * counts.iter().sum::<usize>()];
        split_frames(&mut positions, counts.iter().map(|n| 3 * n))
            .into_par_iter()
            .for_each(|(f, out)| {
                each_moved(&body(f), input(f), bits(f), |k, p, _| {
                    out[k..k + 3].copy_from_slice(&p.to_array());
                });
            });
        pack.u32("body.changed", mask);
        // Sent from the vector itself, not copied once more into the pack.
        pack.shared("body.positions", positions, |m| &m[..]);
    }
}

/// `x` (|x| ≤ 32,767) rounded to the nearest integer, ties to even, without a call into the
/// C library: adding and taking away 1.5 × 2²³ leaves no bit for a fraction.
#[inline]
fn round_i16(x: f32) -> i16 {
    const SHIFT: f32 = 12_582_912.0;
    ((x + SHIFT) - SHIFT) as i16
}

/// Calls `visit(v, p)` for every vertex of a frame given as its objects' slices.
fn each_vertex(slices: &[&[Vec3]], mut visit: impl FnMut(usize, Vec3)) {
    let mut v = 0;
    for slice in slices {
        for p in *slice {
            visit(v, *p);
            v += 1;
        }
    }
}

/// Calls `emit(k, p, q)` for every moved vertex (its bit set) of a frame: `k` its first value
/// in the frame's slice, `p` its position, `q` the input's.
fn each_moved(
    slices: &[&[Vec3]],
    before: &[Vec3],
    bits: &[u32],
    mut emit: impl FnMut(usize, Vec3, Vec3),
) {
    let mut k = 0;
    each_vertex(slices, |v, p| {
        if bits[v / 32] & (1 << (v % 32)) != 0 {
            emit(k, p, before.get(v).copied().unwrap_or(Vec3::ZERO));
            k += 3;
        }
    });
}

/// `buffer` cut into every frame's slice (`lengths`: the values of each frame in turn).
pub(super) fn split_frames<T>(
    buffer: &mut [T],
    lengths: impl Iterator<Item = usize>,
) -> Vec<(usize, &mut [T])> {
    let mut out = Vec::new();
    let mut rest = buffer;
    for (f, n) in lengths.enumerate() {
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(n);
        out.push((f, head));
        rest = tail;
    }
    out
}
