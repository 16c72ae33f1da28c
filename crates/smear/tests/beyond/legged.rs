//! A procedural low-poly four-legged character (a box body on four box legs, 60 triangles)
//! walking or running along +X with planted feet: in stance a foot stays where it landed on
//! the ground y = 0; in swing it arcs forward to the next footprint.

use anim::{Mesh, MeshAnimation};
use glam::Vec3;

/// Frames per gait cycle.
const PERIOD: f32 = 8.0;
/// Height of the hips (bottom of the body).
const HIP: f32 = 0.7;

/// Appends a box between a bottom and a top centre with half extents `hx`, `hz` in X and Z.
pub(crate) fn push_box(
    p: &mut Vec<Vec3>,
    t: &mut Vec<[u32; 3]>,
    bottom: Vec3,
    top: Vec3,
    hx: f32,
    hz: f32,
) {
    let base = p.len() as u32;
    let ring = [(-hx, -hz), (hx, -hz), (hx, hz), (-hx, hz)];
    for c in [bottom, top] {
        for (x, z) in ring {
            p.push(c + Vec3::new(x, 0.0, z));
        }
    }
    let b = |k: u32| base + k % 4;
    let tp = |k: u32| base + 4 + k % 4;
    t.push([b(0), b(1), b(2)]);
    t.push([b(0), b(2), b(3)]);
    t.push([tp(0), tp(2), tp(1)]);
    t.push([tp(0), tp(3), tp(2)]);
    for k in 0..4 {
        t.push([b(k), tp(k), tp(k + 1)]);
        t.push([b(k), tp(k + 1), b(k + 1)]);
    }
}

/// The character's mesh at time `f` (frames), body speed `speed` units per frame.
fn pose(f: f32, speed: f32, lift: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let (mut p, mut t) = (Vec::new(), Vec::new());
    let x = speed * f;
    push_box(
        &mut p,
        &mut t,
        Vec3::new(x, HIP, 0.0),
        Vec3::new(x, HIP + 0.6, 0.0),
        1.0,
        0.4,
    );
    let legs = [
        (0.7, 0.3, 0.0),
        (0.7, -0.3, 0.5),
        (-0.7, 0.3, 0.5),
        (-0.7, -0.3, 0.0),
    ];
    for (hx, hz, offset) in legs {
        let phase = f / PERIOD + offset;
        let c = phase.floor();
        let u = phase - c;
        let anchor = |c: f32| hx + speed * (c + 0.25 - offset) * PERIOD;
        let foot = if u < 0.5 {
            Vec3::new(anchor(c), 0.0, hz)
        } else {
            let s = (u - 0.5) * 2.0;
            let e = s * s * (3.0 - 2.0 * s);
            let fx = anchor(c) + (anchor(c + 1.0) - anchor(c)) * e;
            Vec3::new(fx, lift * (std::f32::consts::PI * s).sin(), hz)
        };
        push_box(&mut p, &mut t, foot, Vec3::new(x + hx, HIP, hz), 0.08, 0.08);
    }
    (p, t)
}

/// A walk (`speed` ≈ 0.1) or run (`speed` ≈ 0.35) of `frames` frames at 24 fps.
pub(crate) fn gait(frames: usize, speed: f32, lift: f32) -> MeshAnimation {
    let (rest, tris) = pose(0.0, speed, lift);
    let positions = (0..frames)
        .flat_map(|f| pose(f as f32, speed, lift).0)
        .collect();
    MeshAnimation::new(Mesh::new("critter", rest, tris), 24.0, positions).unwrap()
}
