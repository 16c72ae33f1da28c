//! BVH: any bytes give Ok or Err; a scene that reads samples without NaN (when short enough)
//! and its BVH export reads back.
#![no_main]

use anim::{sample, SampleOptions};
use libfuzzer_sys::fuzz_target;
use tkio::bvh;

fuzz_target!(|data: &[u8]| {
    let Ok(scene) = bvh::read(data) else { return };
    let fps = scene
        .clips
        .first()
        .and_then(|c| c.key_rate())
        .unwrap_or(24.0);
    // Keep each run small: a huge `Frame Time` is valid but would sample millions of frames.
    let frames = scene
        .clips
        .first()
        .map_or(1.0, |c| c.duration() as f64 * fps as f64 + 1.0);
    if !(frames * scene.nodes.len() as f64 <= 100_000.0) {
        return;
    }
    let Ok(s) = sample(
        &scene,
        &SampleOptions {
            fps,
            ..SampleOptions::default()
        },
    ) else {
        return;
    };
    if let Some(motion) = &s.skeletal {
        if let Ok(text) = bvh::write(&s.skeleton, motion) {
            bvh::read(text.as_bytes()).expect("re-read of written BVH");
        }
    }
});
