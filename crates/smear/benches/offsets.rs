//! Motion offsets of a 15,000-vertex tube skinned to 10 bones, 40 frames (SMEAR Eqs. 1–9).
//!
//! Run: `cargo bench -p toonkit-smear --bench offsets`; divide the reported time by 40 for
//! the time per frame.

// `criterion_group!` generates an undocumented `pub fn`.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion};
use smear::{mesh_offsets, OffsetOptions, OffsetSolver};

#[path = "../tests/common/mod.rs"]
mod common;

const FRAMES: usize = 40;

fn bench(c: &mut Criterion) {
    let scene = common::benchmark_tube(FRAMES);
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
