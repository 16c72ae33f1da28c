//! Foundation benchmark: sampling + skinning RobotExpressive `Dance` at 120 fps.
//! Target: ≥ 50 M vertex-frames per second on 2 cores. Prints the rate after criterion's
//! own timing.

// `criterion_group!` generates an undocumented `pub fn`.
#![allow(missing_docs)]

use std::time::Instant;

use anim::{sample, SampleOptions};
use criterion::{criterion_group, criterion_main, Criterion};

fn robot() -> anim::Scene {
    let p = testdata::asset("characters/RobotExpressive.glb");
    tkio::gltf::read(&p).expect("read RobotExpressive")
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
    // CPU time too: on a shared machine wall time says little.
    let runs = 20;
    let (t, cpu0) = (Instant::now(), cpu_seconds());
    for _ in 0..runs {
        std::hint::black_box(sample(&scene, &opts).unwrap());
    }
    let secs = t.elapsed().as_secs_f64() / runs as f64;
    let cpu = (cpu_seconds() - cpu0) / runs as f64;
    println!(
        "RobotExpressive Dance @120 fps: {} frames x {} vertices: wall {:.2} ms = {:.1} M vertex-frames/s; \
         CPU {:.2} ms = {:.1} M vertex-frames per CPU-second",
        s.frame_count,
        s.vertex_count(),
        secs * 1e3,
        vertex_frames / secs / 1e6,
        cpu * 1e3,
        vertex_frames / cpu / 1e6
    );
}

/// User + system CPU seconds of this process (Linux `/proc/self/stat`; 0 elsewhere).
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    let fields: Vec<&str> = stat
        .rsplit(')')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect();
    let ticks: f64 = fields.get(11..13).map_or(0.0, |f| {
        f.iter().filter_map(|x| x.parse::<f64>().ok()).sum()
    });
    ticks / 100.0
}

criterion_group!(benches, sampling);
criterion_main!(benches);
