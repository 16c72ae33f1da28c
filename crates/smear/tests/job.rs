//! The whole smear job on a real character: `prepare` once, `stylize` many times. A second
//! `stylize` with another style reuses the prepared offsets (no solve, and much faster than
//! preparing), and the merged job gives the offsets of the per-object solve.

mod common;

use std::time::Instant;

use anim::{sample, SampleOptions, SampledScene};
use smear::{prepare, stylize, OffsetOptions, PrepareOptions, Style};

fn robot_dance() -> SampledScene {
    let path = common::asset("characters/RobotExpressive.glb");
    let scene = tkio::gltf::read(&path).unwrap();
    let clip = scene.find_clip("Dance").unwrap();
    sample(
        &scene,
        &SampleOptions {
            clip: Some(clip),
            ..SampleOptions::default()
        },
    )
    .unwrap()
}

fn example_style(name: &str) -> Style {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/smear")
        .join(name);
    Style::from_toml_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

#[test]
fn second_stylize_reuses_prepared_offsets() {
    let scene = robot_dance();
    let first_style = example_style("fig11c_speed.toml");
    let mut second_style = first_style.clone();
    second_style.elongate = None;
    second_style.multiples = Some(smear::MultiplesStyle::default());
    let options = PrepareOptions {
        offsets: first_style.offsets.clone(),
        ..PrepareOptions::default()
    };

    let t = Instant::now();
    let prepared = prepare(scene, &options).unwrap();
    let solves = smear::offset_solves();
    let a = stylize(&prepared, &first_style).unwrap();
    let first = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let b = stylize(&prepared, &second_style).unwrap();
    let second = t.elapsed().as_secs_f64();
    println!(
        "prepare {:.4} s (solve {:.4} s), first (prepare + stylize) {first:.4} s, second stylize {second:.4} s, {:.1}x",
        prepared.report().seconds,
        prepared.report().solve_seconds,
        first / second
    );

    // Structural: stylize never solved offsets, and says so.
    assert_eq!(
        smear::offset_solves(),
        solves,
        "stylize solved offsets again"
    );
    assert_eq!((a.report.offset_solves, b.report.offset_solves), (0, 0));
    // The second style is really another style on the same prepared offsets.
    let objects = prepared.object_count();
    assert!(objects > 1, "RobotExpressive has several meshes");
    assert_eq!(a.flipbook.parts.len(), objects);
    assert!(a
        .report
        .objects
        .iter()
        .any(|o| o.elongation_max.unwrap() > 0.0));
    assert!(b.flipbook.parts.len() > objects);
    assert!(b.report.objects.iter().all(|o| o.elongation_max.is_none()));
    // Restyling costs a fraction of preparing (the offset solve dominates).
    assert!(
        second < first,
        "second stylize {second:.4} s not faster than the first run {first:.4} s"
    );
}

#[test]
fn merged_prepare_matches_per_object_offsets() {
    let scene = robot_dance();
    let per_object = smear::scene_offsets(&scene, &OffsetOptions::default()).unwrap();
    let expected = smear::MotionOffsets::concat(&per_object).unwrap();
    let offsets = smear::offsets(&scene, &OffsetOptions::default()).unwrap();
    assert_eq!(offsets.offsets, expected);
    assert_eq!(offsets.report.objects.len(), scene.objects.len());
    let (lo, hi) = expected.range();
    assert_eq!(offsets.report.range, (lo, hi));

    let merged = prepare(
        scene.clone(),
        &PrepareOptions {
            merge: Some("robot".into()),
            ..PrepareOptions::default()
        },
    )
    .unwrap();
    assert_eq!(merged.object_count(), 1);
    assert_eq!(merged.offsets(0), &expected);
    assert_eq!(merged.animation(0).vertex_count(), scene.vertex_count());
    assert_eq!(merged.animation(0).mesh.name, "robot");
    // A style with other offset options is refused rather than silently ignored.
    let other = Style {
        offsets: OffsetOptions {
            smooth: 0,
            ..OffsetOptions::default()
        },
        ..Style::default()
    };
    assert!(stylize(&merged, &other).is_err());
}
