//! End-to-end character motion synthesis (Section 4): 5 keystrokes, RobotExpressive's 43
//! joints, 120 frames (no settle tail), changing bone sets — the interactive target is
//! ≤ 100 ms on 2 cores.
//!
//! `cargo bench -p toonkit-loa --bench animate`

// `criterion_group!` generates an undocumented `pub fn`.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion};
use loa::animate::{animate, AnimateOptions, BoneSetKey, Character};
use loa::{Keystrokes, LineOptions};

fn stroke(bow: f64, lean: f64) -> String {
    let pts: Vec<String> = (0..=20)
        .map(|i| {
            let s = i as f64 / 20.0;
            let x = bow * 100.0 * (std::f64::consts::PI * s).sin() + lean * 100.0 * s;
            format!("[{x:.3}, {:.3}]", -100.0 * s)
        })
        .collect();
    format!("[{}]", pts.join(", "))
}

fn bench(c: &mut Criterion) {
    let path = testdata::asset("characters/RobotExpressive.glb");
    let scene = tkio::gltf::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let skeleton = scene.skeleton().0;
    assert_eq!(skeleton.len(), 43);
    let keys: Vec<String> = [
        (0, 0.2, 0.1),
        (30, 0.0, 0.0),
        (60, -0.2, -0.1),
        (90, 0.1, 0.2),
        (119, 0.0, 0.0),
    ]
    .iter()
    .map(|(f, b, l)| format!(r#"{{"frame": {f}, "points": {}}}"#, stroke(*b, *l)))
    .collect();
    let json = format!(r#"{{"keystrokes": [{}]}}"#, keys.join(", "));
    let keys = Keystrokes::from_json_str(&json).unwrap();
    let sets: Vec<BoneSetKey> = [
        "right-leg-spine-head@0",
        "left-leg-spine-head@60",
        "right-leg-spine-head@119",
    ]
    .iter()
    .map(|s| s.parse().unwrap())
    .collect();
    c.bench_function("animate_robot_5keys_120frames", |b| {
        b.iter(|| {
            let character = Character::rest(&skeleton).unwrap();
            let options = LineOptions {
                physics: loa::PhysicsOptions {
                    settle: loa::Settle::Frames(0),
                    ..Default::default()
                },
                ..Default::default()
            };
            let line = loa::line(&keys, &options).unwrap();
            let motion = animate(
                &character,
                &line.animation,
                &sets,
                &[],
                &[],
                &AnimateOptions::default(),
            )
            .unwrap();
            assert_eq!(motion.frames(), 120);
            motion
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
