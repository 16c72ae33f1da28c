//! Test fixtures: a UV sphere, a translating ball and a camera.

use anim::{Camera, Mesh, MeshAnimation, Projection};
use glam::{Mat4, Vec3};

/// A UV sphere of radius `r`.
pub(crate) fn ball(r: f32, rings: usize, segments: usize) -> Mesh {
    let mut p = vec![Vec3::Y * r, -Vec3::Y * r];
    for a in 1..rings {
        let th = std::f32::consts::PI * a as f32 / rings as f32;
        for b in 0..segments {
            let ph = std::f32::consts::TAU * b as f32 / segments as f32;
            p.push(r * Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()));
        }
    }
    let idx = |a: usize, b: usize| (2 + (a - 1) * segments + b % segments) as u32;
    let mut t = Vec::new();
    for b in 0..segments {
        t.push([0, idx(1, b + 1), idx(1, b)]);
        t.push([1, idx(rings - 1, b), idx(rings - 1, b + 1)]);
        for a in 1..rings - 1 {
            t.push([idx(a, b), idx(a, b + 1), idx(a + 1, b)]);
            t.push([idx(a + 1, b), idx(a, b + 1), idx(a + 1, b + 1)]);
        }
    }
    Mesh::new("ball", p, t)
}

/// A ball translating along +X by `speed` per frame.
pub(crate) fn translating_ball(frames: usize, speed: f32) -> MeshAnimation {
    let mesh = ball(1.0, 12, 24);
    let pos = (0..frames)
        .flat_map(|f| {
            let p = mesh.positions.clone();
            p.into_iter().map(move |q| q + Vec3::X * speed * f as f32)
        })
        .collect();
    MeshAnimation::new(mesh, 24.0, pos).unwrap()
}

/// An orthographic camera placed by `world` (one matrix per frame).
pub(crate) fn camera(world: Vec<Mat4>) -> Camera {
    Camera {
        name: "c".into(),
        projection: Projection::Orthographic {
            xmag: 1.0,
            ymag: 1.0,
            znear: 0.1,
            zfar: 10.0,
        },
        world,
    }
}
