//! Shared helpers of the render integration tests: synthetic meshes and reference images.

#![allow(dead_code)]

use glam::Vec3;
use render::{decode_png, encode_png, Image};

/// Per-channel tolerance of reference comparisons.
pub(crate) const REF_TOLERANCE: u8 = 3;
/// Largest fraction of pixels allowed to differ beyond the tolerance.
pub(crate) const REF_MAX_FRACTION: f64 = 0.01;

/// Compares `image` with `tests/refs/<name>.png`; with `TOONKIT_BLESS=1` writes it instead.
/// A missing reference is a failure.
pub(crate) fn check_ref(name: &str, image: &Image) {
    let path = format!("{}/tests/refs/{name}.png", env!("CARGO_MANIFEST_DIR"));
    if std::env::var("TOONKIT_BLESS").as_deref() == Ok("1") {
        std::fs::write(&path, encode_png(image).unwrap()).unwrap();
        return;
    }
    let bytes = std::fs::read(&path).unwrap_or_else(|e| {
        panic!("missing reference image {path} ({e}); create it with TOONKIT_BLESS=1")
    });
    let reference = decode_png(&bytes).unwrap();
    let d = image.compare(&reference, REF_TOLERANCE).unwrap();
    if d.fraction > REF_MAX_FRACTION {
        let out = format!("{}/{name}.actual.png", env!("CARGO_TARGET_TMPDIR"));
        std::fs::write(&out, encode_png(image).unwrap()).unwrap();
        panic!("{name}: {d:?} differs from {path}; actual written to {out}");
    }
}

/// An axis-aligned cube of half-size `h` centred at `c` (12 triangles, CCW outside).
pub(crate) fn cube(c: Vec3, h: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let p: Vec<Vec3> = (0..8)
        .map(|i| {
            c + Vec3::new(
                if i & 1 == 0 { -h } else { h },
                if i & 2 == 0 { -h } else { h },
                if i & 4 == 0 { -h } else { h },
            )
        })
        .collect();
    let quads = [
        [0, 2, 3, 1], // -z
        [4, 5, 7, 6], // +z
        [0, 1, 5, 4], // -y
        [2, 6, 7, 3], // +y
        [0, 4, 6, 2], // -x
        [1, 3, 7, 5], // +x
    ];
    let t = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    (p, t)
}

/// A square of half-size `h` in the plane z = `z`, facing +Z.
pub(crate) fn quad(cx: f32, cy: f32, z: f32, h: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    (
        vec![
            Vec3::new(cx - h, cy - h, z),
            Vec3::new(cx + h, cy - h, z),
            Vec3::new(cx + h, cy + h, z),
            Vec3::new(cx - h, cy + h, z),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    )
}

/// A tiny OBJ reader (positions and faces, fan-triangulated) for test assets.
pub(crate) fn read_obj(path: &str) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"));
    let mut v = Vec::new();
    let mut t = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f32> = it.take(3).map(|s| s.parse().unwrap()).collect();
                v.push(Vec3::new(c[0], c[1], c[2]));
            }
            Some("f") => {
                let idx: Vec<u32> = it
                    .map(|s| s.split('/').next().unwrap().parse::<u32>().unwrap() - 1)
                    .collect();
                for k in 1..idx.len() - 1 {
                    t.push([idx[0], idx[k], idx[k + 1]]);
                }
            }
            _ => {}
        }
    }
    (v, t)
}
