//! USD export benchmark: RobotExpressive `Dance` at 24 fps (7,214 vertices × 81 frames) as a
//! `.usda` layer, without and with per-frame vertex colours. Target: well under a second.

// `criterion_group!` with a `config` generates an undocumented `pub fn`.
#![allow(missing_docs)]

use std::time::Instant;

use anim::{sample, MeshAnimation, SampleOptions};
use criterion::{criterion_group, criterion_main, Criterion};

fn dance() -> MeshAnimation {
    let p = testdata::asset("characters/RobotExpressive.glb");
    let scene = tkio::gltf::read(&p).expect("read RobotExpressive");
    let options = SampleOptions {
        fps: 24.0,
        clip: Some(scene.find_clip("Dance").unwrap()),
        meshes: Vec::new(),
    };
    sample(&scene, &options).unwrap().merged("robot").unwrap()
}

fn usda(c: &mut Criterion) {
    let anim = dance();
    let n = anim.vertex_count() * anim.frame_count();
    let colors: Vec<[f32; 4]> = (0..n)
        .map(|i| [0.8, 0.8, 0.8, (i % 7) as f32 / 7.0])
        .collect();
    c.bench_function("usda_robot_dance_7k_x_81", |b| {
        b.iter(|| tkio::usda::write_animation(&anim, None).unwrap())
    });
    c.bench_function("usda_robot_dance_7k_x_81_colors", |b| {
        b.iter(|| tkio::usda::write_animation(&anim, Some(&colors)).unwrap())
    });
    let runs = 5;
    let t = Instant::now();
    let mut bytes = 0;
    for _ in 0..runs {
        bytes = std::hint::black_box(tkio::usda::write_animation(&anim, None).unwrap()).len();
    }
    let secs = t.elapsed().as_secs_f64() / runs as f64;
    println!(
        "usda: {} vertices x {} frames -> {:.1} MB in {:.3} s ({:.1} MB/s)",
        anim.vertex_count(),
        anim.frame_count(),
        bytes as f64 / 1e6,
        secs,
        bytes as f64 / 1e6 / secs
    );
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = usda
}
criterion_main!(benches);
