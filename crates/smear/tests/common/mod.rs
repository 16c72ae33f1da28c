//! Synthetic scenes for the smear tests and benchmark: spheres, peanuts, skinned tubes.
#![allow(dead_code)]

use anim::{
    bones, Joint, Mesh, MeshAnimation, MeshObject, SampledScene, Skeleton, Skin, Transform,
    VertexWeights,
};
use glam::{Mat4, Quat, Vec3};

/// A surface of revolution around +X: `profile(t) = (x, radius)` for t ∈ [0, π], poles at
/// t = 0 and π.
pub(crate) fn revolution(
    name: &str,
    rings: usize,
    segments: usize,
    profile: impl Fn(f32) -> (f32, f32),
) -> Mesh {
    let mut p = Vec::new();
    let (x0, _) = profile(0.0);
    p.push(Vec3::new(x0, 0.0, 0.0));
    for i in 1..rings {
        let t = std::f32::consts::PI * i as f32 / rings as f32;
        let (x, r) = profile(t);
        for s in 0..segments {
            let a = std::f32::consts::TAU * s as f32 / segments as f32;
            p.push(Vec3::new(x, r * a.cos(), r * a.sin()));
        }
    }
    let (x1, _) = profile(std::f32::consts::PI);
    p.push(Vec3::new(x1, 0.0, 0.0));
    let last = p.len() as u32 - 1;
    let ring = |i: usize, s: usize| (1 + (i - 1) * segments + s % segments) as u32;
    let mut t = Vec::new();
    for s in 0..segments {
        t.push([0, ring(1, s + 1), ring(1, s)]);
        t.push([last, ring(rings - 1, s), ring(rings - 1, s + 1)]);
        for i in 1..rings - 1 {
            let (a, b, c, d) = (
                ring(i, s),
                ring(i, s + 1),
                ring(i + 1, s),
                ring(i + 1, s + 1),
            );
            t.push([a, b, d]);
            t.push([a, d, c]);
        }
    }
    Mesh::new(name, p, t)
}

/// A UV sphere of radius `r` centred at the origin.
pub(crate) fn sphere(r: f32) -> Mesh {
    revolution("ball", 24, 32, |t| (-r * t.cos(), r * t.sin()))
}

/// The peanut of paper Fig. 4: two lobes along X joined by a narrow waist.
pub(crate) fn peanut() -> Mesh {
    revolution("peanut", 48, 32, |t| {
        (-2.0 * t.cos(), t.sin() * (0.75 + 0.45 * (2.0 * t).cos()))
    })
}

/// A mesh translated by `step * f` at frame f.
pub(crate) fn translating(
    mesh: Mesh,
    frames: usize,
    step: impl Fn(usize) -> Vec3,
) -> MeshAnimation {
    let mut pos = Vec::with_capacity(frames * mesh.vertex_count());
    for f in 0..frames {
        let s = step(f);
        pos.extend(mesh.positions.iter().map(|p| *p + s));
    }
    MeshAnimation::new(mesh, 24.0, pos).unwrap()
}

/// A closed tube along +Y through rings at heights `ys`, radius `radius(y)`.
pub(crate) fn tube(ys: &[f32], segments: usize, radius: impl Fn(f32) -> f32) -> Mesh {
    let mut p = vec![Vec3::new(0.0, ys[0], 0.0)];
    for &y in ys {
        for s in 0..segments {
            let a = std::f32::consts::TAU * s as f32 / segments as f32;
            p.push(Vec3::new(radius(y) * a.cos(), y, radius(y) * a.sin()));
        }
    }
    p.push(Vec3::new(0.0, *ys.last().unwrap(), 0.0));
    let last = p.len() as u32 - 1;
    let n = ys.len();
    let ring = |i: usize, s: usize| (1 + i * segments + s % segments) as u32;
    let mut t = Vec::new();
    for s in 0..segments {
        t.push([0, ring(0, s), ring(0, s + 1)]);
        t.push([last, ring(n - 1, s + 1), ring(n - 1, s)]);
        for i in 0..n - 1 {
            let (a, b, c, d) = (
                ring(i, s),
                ring(i, s + 1),
                ring(i + 1, s),
                ring(i + 1, s + 1),
            );
            t.push([a, c, d]);
            t.push([a, d, b]);
        }
    }
    Mesh::new("tube", p, t)
}

/// A chain of `n` joints along local +Y, `len` apart; the root carries `root_rotation`.
pub(crate) fn chain(n: usize, len: f32, root_rotation: Quat) -> Skeleton {
    Skeleton {
        joints: (0..n)
            .map(|k| Joint {
                name: format!("bone{k}"),
                parent: k.checked_sub(1),
                bind_local: if k == 0 {
                    Transform {
                        rotation: root_rotation,
                        ..Transform::IDENTITY
                    }
                } else {
                    Transform::from_translation(Vec3::new(0.0, len, 0.0))
                },
            })
            .collect(),
    }
}

/// A skinned object posed by `locals(f)` (joint local matrices of frame f), sampled like
/// `anim::sample` does: linear blend skinning from the bind pose, bones per frame.
pub(crate) fn skinned_scene(
    mesh: Mesh,
    skeleton: Skeleton,
    weights: VertexWeights,
    frames: usize,
    locals: impl Fn(usize) -> Vec<Mat4>,
) -> SampledScene {
    let bind = skeleton.bind_world();
    let inverse_bind: Vec<Mat4> = bind.iter().map(|m| m.inverse()).collect();
    let children = skeleton.children();
    let nj = skeleton.len();
    let (mut pos, mut all_bones, mut world_all) = (Vec::new(), Vec::new(), Vec::new());
    let mut tmp = Vec::new();
    for f in 0..frames {
        let world = skeleton.world_from_local(&locals(f));
        let mats: Vec<Mat4> = world
            .iter()
            .zip(&inverse_bind)
            .map(|(w, ib)| *w * *ib)
            .collect();
        let mut out = vec![Vec3::ZERO; mesh.vertex_count()];
        anim::skin_positions(&weights, &mats, &mesh.positions, &mut out);
        pos.extend(out);
        bones(&skeleton, &children, &world, &mut tmp);
        all_bones.extend_from_slice(&tmp);
        world_all.extend_from_slice(&world);
    }
    let skin = Skin {
        joints: (0..nj).collect(),
        inverse_bind,
        weights,
    };
    let animation = MeshAnimation::new(mesh, 24.0, pos).unwrap();
    let name = animation.mesh.name.clone();
    SampledScene {
        fps: 24.0,
        start_time: 0.0,
        frame_count: frames,
        objects: vec![MeshObject {
            skin: Some(skin),
            ..MeshObject::new(0, name, animation)
        }],
        skeleton,
        joint_nodes: (0..nj).collect(),
        skeletal: Some(anim::SkeletalAnimation::new(24.0, nj, world_all).unwrap()),
        bones: all_bones,
        cameras: Vec::new(),
        node_world: Vec::new(),
    }
}

/// Bind-pose local matrices of a skeleton.
pub(crate) fn bind_locals(s: &Skeleton) -> Vec<Mat4> {
    s.joints.iter().map(|j| j.bind_local.matrix()).collect()
}

/// Skin weights of a tube along a chain of bones `len` apart: linear blend across each joint
/// over ±`blend` (0 gives hard weights: vertex on bone ⌊y / len⌋).
pub(crate) fn chain_weights(mesh: &Mesh, bones: usize, len: f32, blend: f32) -> VertexWeights {
    VertexWeights::from_influences(mesh.positions.iter().map(|p| {
        let y = p.y / len;
        let k = (y.floor().max(0.0) as usize).min(bones - 1);
        let mut inf = vec![(k as u32, 1.0f32)];
        if blend > 0.0 {
            let frac = y - k as f32;
            if k + 1 < bones && frac > 1.0 - blend {
                let t = (frac - (1.0 - blend)) / (2.0 * blend);
                inf = vec![(k as u32, 1.0 - t), (k as u32 + 1, t)];
            } else if k > 0 && frac < blend {
                let t = (blend - frac) / (2.0 * blend);
                inf = vec![(k as u32, 1.0 - t), (k as u32 - 1, t)];
            }
        }
        inf
    }))
}

/// The benchmark tube's parts: a 15,002-vertex wavy tube, a 10-bone chain, skin weights and
/// the chain's local joint matrices at frame f (it translates, bends and twists).
pub(crate) fn benchmark_tube_parts() -> (Mesh, Skeleton, VertexWeights, impl Fn(usize) -> Vec<Mat4>)
{
    let ys: Vec<f32> = (0..300).map(|i| i as f32 * 10.0 / 299.0).collect();
    let mesh = tube(&ys, 50, |y| 0.3 + 0.1 * (2.0 * y).sin());
    let w = chain_weights(&mesh, 10, 1.0, 0.25);
    let skel = chain(10, 1.0, Quat::IDENTITY);
    let l0 = bind_locals(&skel);
    let locals = move |f: usize| {
        let t = f as f32;
        let mut l = l0.clone();
        l[0] =
            Mat4::from_translation(Vec3::new(0.2 * t, 0.0, 0.0)) * Mat4::from_rotation_z(0.02 * t);
        for k in 1..10 {
            l[k] = l0[k]
                * Mat4::from_rotation_z(0.3 * (0.4 * t + k as f32).sin())
                * Mat4::from_rotation_x(0.1 * (0.3 * t).cos());
        }
        l
    };
    (mesh, skel, w, locals)
}

/// The benchmark scene (SPEC target): a 15,002-vertex wavy tube skinned to a 10-bone chain
/// that translates, bends and twists over `frames` frames.
pub(crate) fn benchmark_tube(frames: usize) -> SampledScene {
    let (mesh, skel, w, locals) = benchmark_tube_parts();
    skinned_scene(mesh, skel, w, frames, locals)
}

/// Path of a bundled asset (`assets/…` at the workspace root, same relative names as the
/// shared data folder); panics if it is missing.
pub(crate) fn asset(rel: &str) -> std::path::PathBuf {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets")
        .join(rel);
    assert!(p.exists(), "missing test asset {}", p.display());
    p
}
