//! A procedural low-poly animal running in place (a box body, a tail, a front and a hind leg;
//! 48 triangles): each leg and the tail is a rigid box swinging about its root through an
//! arc, `θ(t) = A sin(2π t / P + φ)`. The pose is defined at any time, so the true path of
//! every surface point is known between frames.

use anim::{Mesh, MeshAnimation};
use glam::{Quat, Vec3};

use super::legged::push_box;

/// Frames per stride.
const PERIOD: f32 = 16.0;
/// Swing amplitude of legs and tail (radians).
const AMPLITUDE: f32 = 0.7;
/// Length of a leg (hip to foot).
pub(crate) const LEG: f32 = 1.0;
/// Height of the hips.
const HIP: f32 = 1.0;
/// Vertices of the body box (the legs and tail come after them, 8 each).
pub(crate) const BODY_VERTICES: usize = 8;

/// Whether vertex `v` is at the tip of a limb (a foot or the tail's end): every limb's box
/// starts with its tip ring.
pub(crate) fn is_tip(v: usize) -> bool {
    v >= BODY_VERTICES && (v - BODY_VERTICES) % 8 < 4
}

/// Appends a limb of length `len` and half width `w` hanging from `root`, turned by `angle`
/// about +Z through `root`.
fn push_limb(p: &mut Vec<Vec3>, t: &mut Vec<[u32; 3]>, root: Vec3, len: f32, w: f32, angle: f32) {
    let start = p.len();
    push_box(p, t, Vec3::new(0.0, -len, 0.0), Vec3::ZERO, w, w);
    let turn = Quat::from_rotation_z(angle);
    for q in &mut p[start..] {
        *q = root + turn * *q;
    }
}

/// The animal's vertices and triangles at time `f` (frames, fractional allowed).
pub(crate) fn pose(f: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let (mut p, mut t) = (Vec::new(), Vec::new());
    let phase = std::f32::consts::TAU * f / PERIOD;
    let swing = |offset: f32| AMPLITUDE * (phase + offset).sin();
    // Body: a box 2 × 0.6 × 0.6 above the hips (not animated).
    push_box(
        &mut p,
        &mut t,
        Vec3::Y * HIP,
        Vec3::Y * (HIP + 0.6),
        1.0,
        0.3,
    );
    // Front and hind legs swing in antiphase; the tail (pointing back) swings up and down.
    push_limb(
        &mut p,
        &mut t,
        Vec3::new(0.8, HIP, 0.0),
        LEG,
        0.08,
        swing(0.0),
    );
    push_limb(
        &mut p,
        &mut t,
        Vec3::new(-0.8, HIP, 0.0),
        LEG,
        0.08,
        swing(std::f32::consts::PI),
    );
    let tail = -std::f32::consts::FRAC_PI_2 + swing(1.0);
    push_limb(
        &mut p,
        &mut t,
        Vec3::new(-1.0, HIP + 0.4, 0.0),
        0.9,
        0.06,
        tail,
    );
    (p, t)
}

/// `frames` frames of the run at 24 fps.
pub(crate) fn run(frames: usize) -> MeshAnimation {
    let (rest, tris) = pose(0.0);
    let positions = (0..frames).flat_map(|f| pose(f as f32).0).collect();
    MeshAnimation::new(Mesh::new("swinger", rest, tris), 24.0, positions).unwrap()
}
