//! The whole clip's elongated body as what changed: per frame a bit per vertex (set where the
//! style moved it off the input) and the moved vertices' positions. The page holds the input
//! already (`/api/scene`), so it rebuilds the exact core result from fewer bytes — a speed
//! style leaves the slow vertices (~60 % of the robot's Dance) where they were.

use anim::glam::Vec3;

use crate::pack::Pack;

/// Adds `body.changed` (u32 words, per frame `⌈vertices / 32⌉`, bit `v % 32` of word
/// `v / 32` set when vertex `v` moved) and `body.positions` (f32 xyz of the moved vertices,
/// frame-major, in vertex order). `body(f)` and `input(f)` are the merged vertices of frame
/// `f` of the answer and of the input clip.
pub(crate) fn pack_changes<'a>(
    pack: &mut Pack,
    frames: usize,
    vertices: usize,
    body: impl Fn(usize) -> Vec<&'a [Vec3]>,
    input: impl Fn(usize) -> &'a [Vec3],
) {
    let words = vertices.div_ceil(32);
    let mut mask = vec![0u32; frames * words];
    // Room for every vertex at once: no regrowth copies, and the pages no moved vertex
    // reaches are never touched (not resident).
    let mut moved: Vec<f32> = Vec::with_capacity(frames * vertices * 3);
    for f in 0..frames {
        let bits = &mut mask[f * words..(f + 1) * words];
        let before = input(f);
        let mut v = 0;
        for slice in body(f) {
            for p in slice {
                // Bit-exact: the page must draw the core's numbers, not an approximation.
                if before.get(v).is_none_or(|q| q.to_array() != p.to_array()) {
                    bits[v / 32] |= 1 << (v % 32);
                    moved.extend_from_slice(&p.to_array());
                }
                v += 1;
            }
        }
    }
    pack.u32("body.changed", mask);
    // Sent from the vector itself, not copied once more into the pack.
    pack.shared("body.positions", moved, |m| &m[..]);
}
