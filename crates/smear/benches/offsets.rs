//! Motion offsets of a 15,000-vertex tube skinned to 10 bones, 40 frames (Eqs. 1–9).
//!
//! Run: `cargo bench -p toonkit-smear --bench offsets`; divide the reported time by 40 for
//! the time per frame.

use criterion::{criterion_group, criterion_main, Criterion};
use glam::{Mat4, Quat, Vec3};
use smear::{mesh_offsets, OffsetOptions, OffsetSolver};

#[path = "../tests/common/mod.rs"]
mod common;

const FRAMES: usize = 40;

fn tube_scene() -> anim::SampledScene {
    let ys: Vec<f32> = (0..300).map(|i| i as f32 * 10.0 / 299.0).collect();
    let mesh = common::tube(&ys, 50, |y| 0.3 + 0.1 * (2.0 * y).sin());
    let w = common::chain_weights(&mesh, 10, 1.0, 0.25);
    let skel = common::chain(10, 1.0, Quat::IDENTITY);
    let l0 = common::bind_locals(&skel);
    common::skinned_scene(mesh, skel, w, FRAMES, move |f| {
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
    })
}

fn bench(c: &mut Criterion) {
    let scene = tube_scene();
    assert_eq!(scene.vertex_count(), 15_002);
    let options = OffsetOptions::default();
    let mut g = c.benchmark_group("offsets_15k_vertices_40_frames");
    g.sample_size(30);
    g.bench_function("articulated_10_bones", |b| {
        b.iter(|| OffsetSolver::new(&scene, &options).unwrap().all())
    });
    let whole = OffsetOptions {
        whole_body: true,
        ..OffsetOptions::default()
    };
    g.bench_function("whole_body", |b| {
        b.iter(|| OffsetSolver::new(&scene, &whole).unwrap().all())
    });
    let anim = &scene.objects[0].animation;
    g.bench_function("simple_object", |b| {
        b.iter(|| mesh_offsets(anim, &options).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
