//! Live tuning on RobotExpressive's Dance (19 meshes, 7,214 vertices, 81 frames): `prepare`
//! (the offsets, once) against `stylize` with another style (SMEAR Eq. 10 on the prepared
//! offsets, no solve) and the restyle of the one frame a studio shows first
//! (`stylize_frames`). `crates/smear/tests/job.rs` checks that restyling never solves
//! offsets; this measures what it costs.
//!
//! Run: `cargo bench -p toonkit-smear --bench restyle`.

// `criterion_group!` generates an undocumented `pub fn`.
#![allow(missing_docs)]

use anim::{sample, SampleOptions};
use criterion::{criterion_group, criterion_main, Criterion};
use smear::{prepare, stylize, stylize_frames, PrepareOptions, Style};

#[path = "../tests/common/mod.rs"]
mod common;

fn style(by: f32) -> Style {
    Style::from_toml_str(&format!(
        "[elongate]\nfunction = {{ stages = [{{ op = \"speed\" }}, {{ op = \"scale\", by = {by} }}] }}"
    ))
    .unwrap()
}

fn bench(c: &mut Criterion) {
    let scene = tkio::gltf::read(&common::asset("characters/RobotExpressive.glb")).unwrap();
    let clip = scene.find_clip("Dance").unwrap();
    let sampled = sample(
        &scene,
        &SampleOptions {
            clip: Some(clip),
            ..SampleOptions::default()
        },
    )
    .unwrap();
    let options = PrepareOptions::default();
    let prepared = prepare(sampled.clone(), &options).unwrap();
    let middle = prepared.report().frames / 2;
    let mut g = c.benchmark_group("restyle_robot_dance");
    g.sample_size(30);
    g.bench_function("prepare", |b| {
        b.iter(|| prepare(sampled.clone(), &options).unwrap())
    });
    // Alternate two strengths, as a dragged slider does.
    let (a, b6) = (style(3.0), style(6.0));
    let mut flip = false;
    g.bench_function("stylize_whole_clip", |b| {
        b.iter(|| {
            flip = !flip;
            stylize(&prepared, if flip { &a } else { &b6 }).unwrap()
        })
    });
    g.bench_function("stylize_current_frame", |b| {
        b.iter(|| {
            flip = !flip;
            stylize_frames(&prepared, if flip { &a } else { &b6 }, middle..middle + 1).unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
