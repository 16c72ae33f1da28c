//! A multiple's whole clip as the vertices it shows (SMEAR Eq. 11: most of a copy is
//! transparent — on the robot's Dance with Fig. 16's style, 9 % of the copies' vertex-frames
//! have an opacity above 0). A vertex whose opacity is 0, in triangles whose vertices all have
//! opacity 0, draws nothing wherever it is: only the other vertices' positions and opacities
//! are sent, and the page puts the rest at the input's position, transparent
//! (docs/studio.md, "Multiples and motion lines").

use anim::glam::Vec3;
use rayon::prelude::*;

use super::changes::split_frames;
use crate::pack::Pack;

/// Adds `NAME.shown` (u32 words, per frame `⌈vertices / 32⌉`, bit `v % 32` of word `v / 32`
/// set when vertex `v` has an opacity above 0 or belongs to a triangle with such a vertex),
/// `NAME.shown_positions` (f32 xyz) and `NAME.shown_alpha` (f32) of the shown vertices,
/// frame-major in vertex order. `positions(f)` is the copy at frame `f`; `colors` its RGBA
/// (frames × vertices; none: every vertex opaque). Frames are scanned and packed in parallel.
pub(crate) fn pack_shown<'a>(
    pack: &mut Pack,
    name: &str,
    (frames, vertices): (usize, usize),
    triangles: &[[u32; 3]],
    positions: impl Fn(usize) -> &'a [Vec3] + Sync,
    colors: Option<&[[f32; 4]]>,
) {
    let words = vertices.div_ceil(32);
    let alpha = |f: usize, v: usize| match colors {
        Some(c) => c.get(f * vertices + v).map_or(0.0, |c| c[3]),
        None => 1.0,
    };
    let mut mask = vec![0u32; frames * words];
    let counts: Vec<usize> = mask
        .par_chunks_mut(words.max(1))
        .enumerate()
        .map(|(f, bits)| {
            let mut set = |v: usize| {
                if v < vertices {
                    bits[v / 32] |= 1 << (v % 32);
                }
            };
            for v in (0..vertices).filter(|&v| alpha(f, v) > 0.0) {
                set(v);
            }
            for t in triangles {
                if t.iter().any(|&v| alpha(f, v as usize) > 0.0) {
                    t.iter().for_each(|&v| set(v as usize));
                }
            }
            bits.iter().map(|w| w.count_ones() as usize).sum()
        })
        .collect();
    let counts = &counts[..counts.len().min(frames)];
    let total: usize = counts.iter().sum();
    let bits = |f: usize| &mask[f * words..(f + 1) * words];
    let mut xyz = vec![0.0f32; 3 * total];
    split_frames(&mut xyz, counts.iter().map(|n| 3 * n))
        .into_par_iter()
        .for_each(|(f, out)| {
            let p = positions(f);
            each_shown(bits(f), vertices, |k, v| {
                let q = p.get(v).copied().unwrap_or(Vec3::ZERO).to_array();
                out[3 * k..3 * k + 3].copy_from_slice(&q);
            });
        });
    let mut a = vec![0.0f32; total];
    split_frames(&mut a, counts.iter().copied())
        .into_par_iter()
        .for_each(|(f, out)| each_shown(bits(f), vertices, |k, v| out[k] = alpha(f, v)));
    pack.u32(&format!("{name}.shown"), mask);
    // Sent from the vectors themselves, not copied once more into the pack.
    pack.shared(&format!("{name}.shown_positions"), xyz, |m| &m[..]);
    pack.shared(&format!("{name}.shown_alpha"), a, |m| &m[..]);
}

/// Calls `emit(k, v)` for the `k`-th vertex `v` whose bit is set in a frame's `bits`.
fn each_shown(bits: &[u32], vertices: usize, mut emit: impl FnMut(usize, usize)) {
    let shown = (0..vertices).filter(|&v| bits[v / 32] & (1 << (v % 32)) != 0);
    for (k, v) in shown.enumerate() {
        emit(k, v);
    }
}
