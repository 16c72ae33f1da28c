//! The whole clip's elongated body as what changed: per frame a bit per vertex (set where its
//! values are sent) and those vertices' displacements from the input, quantized on a step
//! fixed by the error bound and sent as variable-length integers (one byte for most
//! coordinates). The page holds the input already (`/api/scene`), so it rebuilds the core's
//! result from few bytes: a vertex the style left where it was is the input's (a speed style
//! leaves ~60 % of the robot's Dance), and a vertex the style moved as its twin — the same
//! corner of a mesh split at its seams — is drawn where the twin is (three in four of the
//! Dance's moved vertices). The format and its error bound are in docs/studio.md ("Smear:
//! what the style moved").

use anim::glam::Vec3;
use rayon::prelude::*;

use crate::pack::{push_zigzag_varint, Pack};

/// Largest quantization error of a moved vertex coordinate, as a fraction of the input clip's
/// bounding-box diagonal: a frame whose displacements would need more than
/// [`MAX_STEPS`] steps sends the whole answer as float32 (`body.positions`).
pub(crate) const MAX_QUANTIZATION_ERROR: f32 = 1e-5;

/// The quantization step as a fraction of the diagonal: a rounding error of half a step stays
/// a tenth below [`MAX_QUANTIZATION_ERROR`], which leaves room for float32's own rounding of
/// the displacement and of the page's sum.
const STEP: f32 = 2.0 * 0.9 * MAX_QUANTIZATION_ERROR;

/// Largest displacement coordinate in steps: below 2²², where float32 still holds every
/// integer and [`round_i32`] is exact (about 75 diagonals of the clip).
const MAX_STEPS: f32 = (1 << 22) as f32;

/// Adds `body.twins` (u32 per vertex: [`crate::files::Clip::twins`]), `body.changed` (u32
/// words, per frame `⌈vertices / 32⌉`, bit `v % 32` of word `v / 32` set when vertex `v`'s
/// values are sent), `body.step` (f32 per frame: the quantization step, [`STEP`] of
/// `diagonal`), `body.offsets` (u32 per frame and one more: where each frame's values start in
/// `body.varints`) and `body.varints` (u8: the sent vertices' displacements from the input in
/// steps, x, y, z, frame-major in vertex order, each as a zigzag LEB128 integer — 7 bits a
/// byte, the low bit the sign: the position is the input's plus `value × step`). A vertex
/// whose bit is clear is where its twin is drawn (its twin itself: the input's position): the
/// server clears it only when the core's position is the same bits as the twin's. When a
/// frame's displacements are larger than [`MAX_STEPS`] steps, `body.positions` (f32 xyz of
/// the sent vertices) replaces `body.step`, `body.offsets` and `body.varints`. `diagonal` is
/// the input's bounding box over the frames answered ([`crate::files::Clip::diagonal`]);
/// `body(f)` and `input(f)` are the merged vertices of frame `f` of the answer and of the
/// input clip. Each frame is compared and encoded by one task while its vertices are in
/// cache, frames in parallel; the answer's buffers are handed to the pack, not copied.
pub(crate) fn pack_changes<'a>(
    pack: &mut Pack,
    (frames, vertices): (usize, usize),
    (diagonal, twins): (f32, &[u32]),
    body: impl Fn(usize) -> Vec<&'a [Vec3]> + Sync,
    input: impl Fn(usize) -> &'a [Vec3] + Sync,
) {
    let words = vertices.div_ceil(32);
    let step = STEP * diagonal;
    // Steps per unit (infinite for a clip without extent: nothing then fits).
    let per_unit = 1.0 / step;
    let mut mask = vec![0u32; frames * words];
    // Per frame, in one pass over its vertices: the bits, whether its displacements fit, and
    // the sent vertices' values.
    let encoded: Vec<(bool, Vec<u8>)> = mask
        .par_chunks_mut(words.max(1))
        .enumerate()
        .map_init(Vec::new, |merged, (f, bits)| {
            let before = input(f);
            merged.clear();
            for object in body(f) {
                merged.extend_from_slice(object);
            }
            let mut values = Vec::with_capacity(3 * before.len());
            let mut fits = true;
            // Compared as bits: a vertex not sent is drawn from its twin or the input itself,
            // exactly.
            let now: &[[u32; 3]] = bytemuck::cast_slice(&merged[..]);
            let was: &[[u32; 3]] = bytemuck::cast_slice(before);
            // A vertex with no input vertex or no twin (a body larger than the input) is sent.
            let known = now.len().min(was.len()).min(twins.len());
            for (v, &p) in now.iter().enumerate() {
                if v < known {
                    let t = twins[v] as usize;
                    // Both compared, one taken: no branch on the mesh's irregular twins.
                    let (as_input, as_twin) = (p == was[v], now.get(t) == Some(&p));
                    if if t == v { as_input } else { as_twin } {
                        continue;
                    }
                }
                bits[v / 32] |= 1 << (v % 32);
                // Not finite, too far, or no input vertex: not sent in steps.
                let d = before
                    .get(v)
                    .map_or(Vec3::NAN, |&q| (merged[v] - q) * per_unit);
                if d.abs().max_element() <= MAX_STEPS && !d.is_nan() {
                    for x in d.to_array() {
                        push_zigzag_varint(&mut values, round_i32(x));
                    }
                } else {
                    fits = false;
                }
            }
            (fits, values)
        })
        .collect();
    pack.u32(
        "body.twins",
        (0..vertices).map(|v| twins.get(v).map_or(v as u32, |&t| t)),
    );
    if encoded.iter().all(|(fits, _)| *fits) {
        let offsets = std::iter::once(0)
            .chain(encoded.iter().scan(0u32, |at, (_, v)| {
                *at += v.len() as u32;
                Some(*at)
            }))
            .collect::<Vec<u32>>();
        pack.u32_vec("body.changed", mask);
        pack.f32("body.step", std::iter::repeat_n(step, frames));
        pack.u32_vec("body.offsets", offsets);
        pack.u8_parts(
            "body.varints",
            encoded.into_iter().map(|(_, v)| v).collect(),
        );
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

/// `x` (|x| ≤ 2²²) rounded to the nearest integer, ties to even, without a call into the C
/// library: adding and taking away 1.5 × 2²³ leaves no bit for a fraction.
#[inline]
fn round_i32(x: f32) -> i32 {
    const SHIFT: f32 = 12_582_912.0;
    ((x + SHIFT) - SHIFT) as i32
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

/// Calls `emit(k, p, q)` for every sent vertex (its bit set) of a frame: `k` its first value
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_counts_round_to_nearest_even_up_to_the_largest() {
        assert_eq!(round_i32(2.5), 2);
        assert_eq!(round_i32(-3.5), -4);
        assert_eq!(round_i32(MAX_STEPS), 1 << 22);
    }
}
