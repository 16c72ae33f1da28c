//! Foundation benchmark: sampling + skinning RobotExpressive `Dance` at 120 fps.
//! Target: ≥ 50 M vertex-frames per second on 2 cores. Prints the rate after criterion's
//! own timing.

use std::path::Path;
use std::time::Instant;

use anim::{sample, SampleOptions};
use criterion::{criterion_group, criterion_main, Criterion};

fn robot() -> anim::Scene {
    let p = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/characters/RobotExpressive.glb"
    );
    assert!(Path::new(p).exists(), "missing benchmark asset {p}");
    tkio::gltf::read(Path::new(p)).expect("read RobotExpressive")
}

fn sampling(c: &mut Criterion) {
    let scene = robot();
    let clip = scene.find_clip("Dance").unwrap();
    let opts = SampleOptions {
        fps: 120.0,
        clip: Some(clip),
        meshes: Vec::new(),
    };
    let s = sample(&scene, &opts).unwrap();
    let vertex_frames = (s.vertex_count() * s.frame_count) as f64;
    c.bench_function("sample_skin_robot_dance_120fps", |b| {
        b.iter(|| sample(&scene, &opts).unwrap())
    });
    // A plain wall-clock figure in the unit of the target.
    let runs = 20;
    let t = Instant::now();
    for _ in 0..runs {
        std::hint::black_box(sample(&scene, &opts).unwrap());
    }
    let secs = t.elapsed().as_secs_f64() / runs as f64;
    println!(
        "RobotExpressive Dance @120 fps: {} frames x {} vertices in {:.2} ms = {:.1} M vertex-frames/s",
        s.frame_count,
        s.vertex_count(),
        secs * 1e3,
        vertex_frames / secs / 1e6
    );
}

criterion_group!(benches, sampling);
criterion_main!(benches);
