//! Physics interpolation benchmark: 10 keystrokes × 40 frames (Section 3.2).

// `criterion_group!` generates an undocumented `pub fn`.
#![allow(missing_docs)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use glam::DVec2;
use loa::{fit_keystrokes, interpolate_physics, Keystroke, Keystrokes, PhysicsOptions, Stroke};

fn keystrokes() -> Keystrokes {
    let keys = (0..10)
        .map(|k| {
            let bend = if k % 2 == 0 { 1.0 } else { -1.0 } * (0.5 + 0.05 * k as f64);
            let points = (0..=50).map(|i| {
                let s = i as f64 / 50.0;
                DVec2::new(
                    200.0 * s + 10.0 * k as f64,
                    60.0 * bend * (std::f64::consts::PI * s).sin(),
                )
            });
            Keystroke::new(40 * k, Stroke::new(points).expect("valid stroke"))
        })
        .collect();
    Keystrokes::new(keys, None).expect("valid keystrokes")
}

fn bench(c: &mut Criterion) {
    let keys = keystrokes();
    let poses = fit_keystrokes(&keys, loa::DEFAULT_ELEMENTS).expect("fit");
    let options = PhysicsOptions::default();
    c.bench_function("physics_10_keys_x_40_frames", |b| {
        b.iter(|| interpolate_physics(black_box(&poses), &options).expect("physics"))
    });
    c.bench_function("elastic_chain_setup", |b| {
        b.iter(|| loa::ElasticChain::new(black_box(&poses[0].chain), 60.0, 0.35).expect("chain"))
    });
    c.bench_function("simulate_one_interval_40_frames", |b| {
        b.iter(|| {
            loa::simulate(
                black_box(&poses[0]),
                poses[1].chain.angles(),
                &[0.0; 10],
                40,
                &options,
            )
            .expect("simulate")
        })
    });
    c.bench_function("fit_10_keystrokes", |b| {
        b.iter(|| fit_keystrokes(black_box(&keys), loa::DEFAULT_ELEMENTS).expect("fit"))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
