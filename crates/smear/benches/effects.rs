//! Smear effects on a 15,000-vertex tube skinned to 10 bones, 40 frames (Section 4): one
//! elongated in-between (target ≤ 1 ms), the multiple in-betweens and the motion lines of one
//! frame.
//!
//! Run: `cargo bench -p toonkit-smear --bench effects`.

// `criterion_group!` generates an undocumented `pub fn`.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion};
use glam::Vec3;
use smear::{
    elongate_frame, eq12_opacity, motion_lines_frame, multiples_frame, sample_surface,
    EffectInputs, ElongateOptions, LineFrame, LineOptions, LineStyle, MultiplesOptions,
    OffsetOptions, OffsetSolver, Spacing, StyleInput,
};

#[path = "../tests/common/mod.rs"]
mod common;

const FRAMES: usize = 40;
const FRAME: usize = 20;
const SEEDS: usize = 200;

fn bench(c: &mut Criterion) {
    let scene = common::benchmark_tube(FRAMES);
    let anim = &scene.objects[0].animation;
    assert_eq!(anim.vertex_count(), 15_002);
    let solver = OffsetSolver::new(&scene, &OffsetOptions::default()).unwrap();
    let offsets = solver.vertex_offsets(0).unwrap();
    let inputs = EffectInputs::new(anim, &offsets).unwrap();
    let mut g = c.benchmark_group("effects_15k_vertices_one_frame");
    g.sample_size(50);

    let linear = |x: &StyleInput| 2.0 * x.delta;
    let speed = |x: &StyleInput| 2.0 * x.speed * x.delta;
    let mut out = vec![Vec3::ZERO; anim.vertex_count()];
    let opts = ElongateOptions::default();
    g.bench_function("elongate_linear", |b| {
        b.iter(|| elongate_frame(&inputs, &linear, FRAME, &opts, &mut out).unwrap())
    });
    g.bench_function("elongate_speed", |b| {
        b.iter(|| elongate_frame(&inputs, &speed, FRAME, &opts, &mut out).unwrap())
    });

    let mopts = MultiplesOptions {
        past: 2.0.into(),
        future: 1.0.into(),
        spacing: Spacing::Overlap(1.0.into()),
        step: 1,
    };
    let n = 3 * anim.vertex_count();
    let (mut pos, mut alpha) = (vec![Vec3::ZERO; n], vec![0.0f32; n]);
    let eq12 = eq12_opacity(1.0);
    g.bench_function("multiples_3_copies_eq12", |b| {
        b.iter(|| multiples_frame(&inputs, &eq12, FRAME, &mopts, &mut pos, &mut alpha).unwrap())
    });

    let pts = sample_surface(anim.frame(0), &anim.mesh.triangles, SEEDS, 1);
    let seeds =
        EffectInputs::at_surface_points(anim, &pts, solver.surface_offsets(0, &pts).unwrap())
            .unwrap();
    let length = |x: &StyleInput| 4.0 * x.delta;
    let thin = |_: &StyleInput| 0.01;
    let fade = |x: &StyleInput| 1.0 - x.t;
    let style = LineStyle {
        length: &length,
        thickness: &thin,
        opacity: &fade,
    };
    let lopts = LineOptions::default();
    let mut frame = LineFrame::default();
    g.bench_function("lines_200_seeds", |b| {
        b.iter(|| motion_lines_frame(&seeds, &style, FRAME, &lopts, &mut frame).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
