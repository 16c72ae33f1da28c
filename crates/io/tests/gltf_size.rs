//! Size of the glbs toonkit writes: identical accessor data (a flipbook's triangles in every
//! frame and every copy, still frames, visibility timelines) is stored once, vertex colours
//! take 8 bytes per vertex, and the output is byte-identical across writes. Measured on the
//! real RobotExpressive body mesh; every glb is kept for CI's Khronos validator run.

mod common;

use common::{data, keep_for_validation};
use std::collections::BTreeSet;

use anim::glam::Vec3;
use anim::{Mesh, MeshAnimation};
use tkio::gltf::{read_bytes, write_animations, AnimationLayout};

/// The GLB's JSON chunk and the length of its binary chunk.
fn glb_parts(bytes: &[u8]) -> (serde_json::Value, usize) {
    let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json = serde_json::from_slice(&bytes[20..20 + len]).unwrap();
    let bin = u32::from_le_bytes(bytes[20 + len..24 + len].try_into().unwrap()) as usize;
    (json, bin)
}

/// The robot mesh with the most vertices.
fn robot_body() -> Mesh {
    let scene = tkio::gltf::read(&data("characters/RobotExpressive.glb")).unwrap();
    scene
        .meshes
        .into_iter()
        .max_by_key(|m| m.mesh.vertex_count())
        .unwrap()
        .mesh
}

/// `frames` frames of the body: a squash along y that changes every frame.
fn squash(mesh: &Mesh, frames: usize) -> MeshAnimation {
    let positions: Vec<Vec3> = (0..frames)
        .flat_map(|f| {
            let s = Vec3::new(1.0, 1.0 - 0.05 * f as f32, 1.0);
            mesh.positions.iter().map(move |p| *p * s)
        })
        .collect();
    MeshAnimation::new(mesh.clone(), 24.0, positions).unwrap()
}

/// Byte length of every buffer view whose accessors are used as `semantic` (or `"indices"`).
fn view_bytes(json: &serde_json::Value, semantic: &str) -> (usize, usize) {
    let mut accessors = BTreeSet::new();
    for m in json["meshes"].as_array().unwrap() {
        for p in m["primitives"].as_array().unwrap() {
            let a = if semantic == "indices" {
                &p["indices"]
            } else {
                &p["attributes"][semantic]
            };
            if let Some(a) = a.as_u64() {
                accessors.insert(a as usize);
            }
        }
    }
    let bytes = accessors
        .iter()
        .map(|&a| {
            let v = json["accessors"][a]["bufferView"].as_u64().unwrap() as usize;
            json["bufferViews"][v]["byteLength"].as_u64().unwrap() as usize
        })
        .sum();
    (accessors.len(), bytes)
}

#[test]
fn smear_multiples_flipbooks_store_robot_triangles_once() {
    // The layout of `toonkit smear multiples`: the animation plus two translucent copies,
    // each a flipbook of N frames with the same topology.
    let body = robot_body();
    let (n, tris) = (body.vertex_count(), body.triangle_count());
    let frames = 6;
    let anim = squash(&body, frames);
    let opaque = vec![[1.0, 1.0, 1.0, 1.0]; n * frames];
    let half = vec![[0.2, 0.4, 1.0, 0.5]; n * frames];
    let parts = [
        (&anim, Some(&opaque[..])),
        (&anim, Some(&half[..])),
        (&anim, Some(&half[..])),
    ];
    let bytes = write_animations(&parts, AnimationLayout::Flipbook).unwrap();
    keep_for_validation(&bytes, "io_size_multiples");
    let (json, bin) = glb_parts(&bytes);
    assert_eq!(json["meshes"].as_array().unwrap().len(), 3 * frames);

    let (index_accessors, index_bytes) = view_bytes(&json, "indices");
    assert_eq!(
        index_accessors, 1,
        "one index accessor for 3 × {frames} frames"
    );
    assert!(n <= 65535);
    assert_eq!(index_bytes, tris * 3 * 2, "UNSIGNED_SHORT indices");
    let (pos_accessors, pos_bytes) = view_bytes(&json, "POSITION");
    assert_eq!(
        pos_accessors, frames,
        "copies share their frames' positions"
    );
    assert_eq!(pos_bytes, frames * n * 12);
    let (color_accessors, color_bytes) = view_bytes(&json, "COLOR_0");
    assert_eq!(color_accessors, 2, "one per constant colour");
    assert_eq!(color_bytes, 2 * n * 8, "VEC4 UNSIGNED_SHORT");
    // Timelines: one STEP-scale input per frame, shared by the three parts.
    let inputs: BTreeSet<u64> = json["animations"][0]["samplers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["input"].as_u64().unwrap())
        .collect();
    assert_eq!(inputs.len(), frames);
    assert_eq!(
        json["accessors"].as_array().unwrap().len(),
        json["bufferViews"].as_array().unwrap().len()
    );

    // Positions + normals per frame, triangles and two colour sets once, small timelines.
    let normals = view_bytes(&json, "NORMAL").1;
    let payload = pos_bytes + normals + index_bytes + color_bytes;
    assert!(
        bin >= payload && bin < payload + 4096,
        "bin {bin} vs payload {payload}"
    );
    // The writer before deduplication stored every frame of every part, float colours, and
    // UNSIGNED_INT indices once per part: more than four times as large.
    let naive = 3 * frames * n * (12 + 12 + 16) + 3 * tris * 12;
    assert!(4 * bin < naive, "bin {bin} vs naive {naive}");
    eprintln!("robot body: {n} vertices, {tris} triangles, {frames} frames × 3 parts: bin {bin} bytes, naive {naive}");

    // The colours survive: alpha 0.5 within the UNSIGNED_SHORT step.
    let back = read_bytes(&bytes).unwrap();
    let err = back
        .meshes
        .iter()
        .flat_map(|m| m.mesh.colors.as_ref().unwrap())
        .zip(opaque.iter().chain(&half).chain(&half))
        .flat_map(|(a, b)| (0..4).map(move |k| (a[k] - b[k]).abs()))
        .fold(0.0f32, f32::max);
    assert!(err <= 0.5 / 65535.0 + 1e-7, "colour round-trip error {err}");
}

#[test]
fn robot_flipbook_is_byte_identical_across_writes() {
    let mut body = robot_body();
    let n = body.vertex_count();
    body.attributes.insert(
        "_SMEAR_WEIGHT".into(),
        (0..n).map(|i| (i % 7) as f32 / 6.0).collect(),
    );
    let anim = squash(&body, 4);
    let colors: Vec<[f32; 4]> = (0..4 * n)
        .map(|i| [(i % 3) as f32 / 2.0, 0.5, 0.25, (i % 5) as f32 / 4.0])
        .collect();
    for layout in [AnimationLayout::Flipbook, AnimationLayout::Morph] {
        let a = write_animations(&[(&anim, Some(&colors[..]))], layout).unwrap();
        let b = write_animations(&[(&anim, Some(&colors[..]))], layout).unwrap();
        assert_eq!(a.len(), b.len(), "{layout:?}");
        assert!(a == b, "{layout:?}: two writes differ");
        keep_for_validation(&a, &format!("io_size_determinism_{layout:?}"));
    }
}
