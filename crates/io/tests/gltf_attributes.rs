//! Application-specific scalar vertex attributes (`_NAME`, e.g. painted `_SMEAR_WEIGHT`):
//! written by toonkit as FLOAT SCALAR, read back exactly; normalized integer attributes of
//! other exporters read as value / max. Every glb written here is kept for CI's Khronos
//! validator run (`TOONKIT_VALIDATE_DIR`).

mod common;

use common::{data, keep_for_validation};

use anim::glam::Vec3;
use anim::MeshAnimation;
use tkio::gltf::{read_bytes, write_animation, write_glb, AnimationLayout};

/// The GLB's JSON chunk.
fn glb_json(bytes: &[u8]) -> serde_json::Value {
    let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&bytes[20..20 + len]).unwrap()
}

/// Height normalized to [0, 1] over the mesh's bounding box.
fn height(positions: &[Vec3]) -> Vec<f32> {
    let lo = positions.iter().map(|p| p.y).fold(f32::INFINITY, f32::min);
    let hi = positions
        .iter()
        .map(|p| p.y)
        .fold(f32::NEG_INFINITY, f32::max);
    positions
        .iter()
        .map(|p| (p.y - lo) / (hi - lo).max(1e-12))
        .collect()
}

#[test]
fn robot_painted_height_round_trips_exactly() {
    let mut scene = tkio::gltf::read(&data("characters/RobotExpressive.glb")).unwrap();
    let (k, _) = scene
        .meshes
        .iter()
        .enumerate()
        .max_by_key(|(_, m)| m.mesh.vertex_count())
        .unwrap();
    let n = scene.meshes[k].mesh.vertex_count();
    assert!(n > 1000, "largest robot mesh has {n} vertices");
    let h = height(&scene.meshes[k].mesh.positions);
    let m = &mut scene.meshes[k].mesh;
    m.attributes.insert("_SMEAR_WEIGHT".into(), h.clone());
    m.attributes.insert("mask".into(), vec![0.25; n]);
    let bytes = write_glb(&scene).unwrap();
    keep_for_validation(&bytes, "io_attributes_robot_height");

    let json = glb_json(&bytes);
    let attrs = &json["meshes"][k]["primitives"][0]["attributes"];
    assert!(attrs["_SMEAR_WEIGHT"].is_u64(), "attributes: {attrs}");
    assert!(
        attrs["_mask"].is_u64(),
        "'mask' gets a leading underscore: {attrs}"
    );
    let acc = &json["accessors"][attrs["_SMEAR_WEIGHT"].as_u64().unwrap() as usize];
    assert_eq!(acc["type"], "SCALAR");
    assert_eq!(acc["componentType"], 5126);

    let back = read_bytes(&bytes).unwrap();
    let got = &back.meshes[k].mesh.attributes;
    assert_eq!(got.len(), 2, "{:?}", got.keys().collect::<Vec<_>>());
    assert_eq!(got["_SMEAR_WEIGHT"], h);
    assert_eq!(got["_mask"], vec![0.25; n]);
    let (lo, hi) = h
        .iter()
        .fold((1.0f32, 0.0f32), |(a, b), &x| (a.min(x), b.max(x)));
    assert_eq!((lo, hi), (0.0, 1.0));
    // Other meshes were written without attributes and read back without.
    assert!(back
        .meshes
        .iter()
        .enumerate()
        .all(|(j, m)| j == k || m.mesh.attributes.is_empty()));
}

#[test]
fn flipbook_and_morph_frames_share_the_painted_attribute() {
    let scene = tkio::gltf::read(&data("characters/RobotExpressive.glb")).unwrap();
    let mut mesh = scene.meshes[0].mesh.clone();
    let n = mesh.vertex_count();
    let h = height(&mesh.positions);
    mesh.attributes.insert("_SMEAR_WEIGHT".into(), h.clone());
    let frames = 5;
    let positions: Vec<Vec3> = (0..frames)
        .flat_map(|f| mesh.positions.iter().map(move |p| *p + Vec3::Y * f as f32))
        .collect();
    let anim = MeshAnimation::new(mesh, 24.0, positions).unwrap();
    for (layout, tag) in [
        (AnimationLayout::Flipbook, "flipbook"),
        (AnimationLayout::Morph, "morph"),
    ] {
        let bytes = write_animation(&anim, layout, None).unwrap();
        keep_for_validation(&bytes, &format!("io_attributes_{tag}"));
        let json = glb_json(&bytes);
        let used: std::collections::BTreeSet<u64> = json["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| {
                m["primitives"][0]["attributes"]["_SMEAR_WEIGHT"]
                    .as_u64()
                    .unwrap()
            })
            .collect();
        assert_eq!(used.len(), 1, "{tag}: one accessor for every frame");
        let back = read_bytes(&bytes).unwrap();
        let expected_meshes = if layout == AnimationLayout::Flipbook {
            frames
        } else {
            1
        };
        assert_eq!(back.meshes.len(), expected_meshes, "{tag}");
        for m in &back.meshes {
            assert_eq!(m.mesh.vertex_count(), n);
            assert_eq!(m.mesh.attributes["_SMEAR_WEIGHT"], h, "{tag}");
        }
    }
}

#[test]
fn attribute_names_that_collide_or_miss_values_are_errors() {
    let scene = tkio::gltf::read(&data("characters/RobotExpressive.glb")).unwrap();
    let mut s = scene.clone();
    let n = s.meshes[0].mesh.vertex_count();
    s.meshes[0].mesh.attributes.insert("W".into(), vec![0.0; n]);
    s.meshes[0]
        .mesh
        .attributes
        .insert("_W".into(), vec![1.0; n]);
    let e = write_glb(&s).unwrap_err().to_string();
    assert!(e.contains("_W") && e.contains("rename"), "{e}");
    assert!(!e.contains('\n'));

    let mut s = scene;
    s.meshes[0]
        .mesh
        .attributes
        .insert("_W".into(), vec![0.0; n + 1]);
    let e = write_glb(&s).unwrap_err().to_string();
    assert!(e.contains("attribute _W"), "{e}");
}

/// A hand-made glb: two triangle primitives in one mesh. The first has `_PAINT` as
/// normalized UNSIGNED_BYTE (byteStride 4, as vertex attributes must be 4-byte aligned),
/// `_LEVEL` as plain UNSIGNED_SHORT and `_DIR` as VEC2 float (not a scalar: skipped); the
/// second primitive has no `_PAINT`.
fn hand_made(paint_count: usize) -> Vec<u8> {
    let mut bin = Vec::new();
    let tri: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let far: Vec<f32> = tri.iter().map(|x| x + 2.0).collect();
    for x in tri.iter().chain(&far) {
        bin.extend(x.to_le_bytes()); // views 0 and 1: 36 bytes each
    }
    for v in [0u8, 128, 255] {
        bin.extend([v, 0, 0, 0]); // view 2: u8 with stride 4
    }
    for v in [1u16, 2, 300] {
        bin.extend(v.to_le_bytes());
        bin.extend([0, 0]); // view 3: u16 with stride 4
    }
    for x in [0.5f32; 6] {
        bin.extend(x.to_le_bytes()); // view 4: VEC2 float
    }
    let view = |offset: usize, len: usize, stride: Option<usize>| {
        let mut v = serde_json::json!({"buffer": 0, "byteOffset": offset, "byteLength": len,
            "target": 34962});
        if let Some(s) = stride {
            v["byteStride"] = s.into();
        }
        v
    };
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [view(0, 36, None), view(36, 36, None), view(72, 12, Some(4)),
            view(84, 12, Some(4)), view(96, 24, None)],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [2.0, 2.0, 2.0], "max": [3.0, 3.0, 2.0]},
            {"bufferView": 2, "componentType": 5121, "normalized": true,
             "count": paint_count, "type": "SCALAR"},
            {"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"},
            {"bufferView": 4, "componentType": 5126, "count": 3, "type": "VEC2"}
        ],
        "meshes": [{"primitives": [
            {"attributes": {"POSITION": 0, "_PAINT": 2, "_LEVEL": 3, "_DIR": 4}},
            {"attributes": {"POSITION": 1, "_LEVEL": 3}}
        ]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    let mut text = serde_json::to_vec(&json).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend((total as u32).to_le_bytes());
    glb.extend((text.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(text);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(bin);
    glb
}

#[test]
fn normalized_u8_paint_reads_as_fraction_and_missing_primitive_reads_zero() {
    let bytes = hand_made(3);
    keep_for_validation(&bytes, "io_attributes_hand_u8");
    let scene = read_bytes(&bytes).unwrap();
    let attrs = &scene.meshes[0].mesh.attributes;
    assert_eq!(
        attrs.keys().collect::<Vec<_>>(),
        ["_LEVEL", "_PAINT"],
        "VEC2 _DIR is skipped"
    );
    assert_eq!(attrs["_PAINT"], [0.0, 128.0 / 255.0, 1.0, 0.0, 0.0, 0.0]);
    assert_eq!(attrs["_LEVEL"], [1.0, 2.0, 300.0, 1.0, 2.0, 300.0]);
    // Written back by toonkit as floats, then read again: the same values.
    let again = read_bytes(&write_glb(&scene).unwrap()).unwrap();
    assert_eq!(&again.meshes[0].mesh.attributes, attrs);
}

#[test]
fn attribute_count_unlike_position_count_is_a_one_line_error() {
    let e = read_bytes(&hand_made(2)).unwrap_err().to_string();
    assert!(
        e.contains("_PAINT") && e.contains("has 2 values but POSITION has 3"),
        "{e}"
    );
    assert!(!e.contains('\n'));
}
