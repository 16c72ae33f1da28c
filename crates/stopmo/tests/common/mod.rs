//! Helpers shared by the stopmo integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

/// Path of a bundled asset (same relative names as under `assets/`); fails loudly if missing.
pub(crate) fn asset(rel: &str) -> PathBuf {
    let p = PathBuf::from(format!("{}/../../assets/{rel}", env!("CARGO_MANIFEST_DIR")));
    assert!(p.exists(), "missing test asset {}", p.display());
    p
}

/// The face's single mesh sampled at `fps`.
pub(crate) fn face(fps: f32) -> anim::MeshAnimation {
    let scene = tkio::gltf::read(&asset("face/ict-face-talk.glb")).unwrap();
    let s = anim::sample(
        &scene,
        &anim::SampleOptions {
            fps,
            ..Default::default()
        },
    )
    .unwrap();
    s.objects.into_iter().next().unwrap().animation
}

/// The triangles of a `side × side` vertex grid numbered row by row, counter-clockwise seen
/// from +Z when rows grow along +Y and columns along +X.
pub(crate) fn grid_triangles(side: usize) -> Vec<[u32; 3]> {
    let s = side as u32;
    let mut triangles = Vec::new();
    for y in 0..s.saturating_sub(1) {
        for x in 0..s - 1 {
            let i = y * s + x;
            triangles.push([i, i + 1, i + s + 1]);
            triangles.push([i, i + s + 1, i + s]);
        }
    }
    triangles
}
