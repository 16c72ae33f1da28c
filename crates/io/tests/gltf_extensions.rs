//! glTF files as animators have them: required extensions that do not touch geometry are
//! accepted with a note, `KHR_mesh_quantization` and `EXT_meshopt_compression` geometry is
//! decoded, sparse accessors and several scenes are read, and what cannot be read (Draco, an
//! unknown extension that replaces the geometry) fails with one line naming the extension.
//! The files are made here from the bundled robot: our own (quantized) writer, then the JSON
//! edited the way exporters write it; meshopt data is encoded with meshoptimizer's encoder.

mod common;

use std::borrow::Cow;
use std::path::Path;

use anim::glam::Vec3;
use anim::{MeshAnimation, SampleOptions};
use common::{data, keep_for_validation};
use serde_json::{json, Value};
use tkio::gltf::{write_animations_with, AnimationLayout, GlbOptions};

/// The GLB's JSON and binary chunk.
fn split(bytes: &[u8]) -> (Value, Vec<u8>) {
    let glb = gltf::binary::Glb::from_slice(bytes).unwrap();
    (
        serde_json::from_slice(&glb.json).unwrap(),
        glb.bin.map(|b| b.into_owned()).unwrap_or_default(),
    )
}

/// A GLB from JSON and binary chunk.
fn join(json: &Value, bin: Vec<u8>) -> Vec<u8> {
    let mut bin = bin;
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let mut json = json.clone();
    json["buffers"][0]["byteLength"] = json!(bin.len());
    gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0,
        },
        json: Cow::Owned(serde_json::to_vec(&json).unwrap()),
        bin: Some(Cow::Owned(bin)),
    }
    .to_vec()
    .unwrap()
}

fn write_tmp(dir: &Path, name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// The robot's largest mesh as a 6-frame squash (a point cache that changes every frame).
fn robot_cache() -> MeshAnimation {
    let scene = tkio::gltf::read(&data("characters/RobotExpressive.glb")).unwrap();
    let mesh = scene
        .meshes
        .into_iter()
        .max_by_key(|m| m.mesh.vertex_count())
        .unwrap()
        .mesh;
    let frames = 6;
    let positions: Vec<Vec3> = (0..frames)
        .flat_map(|f| {
            let s = Vec3::new(1.0 + 0.02 * f as f32, 1.0 - 0.05 * f as f32, 1.0);
            mesh.positions
                .iter()
                .map(move |p| *p * s + Vec3::X * 0.1 * f as f32)
        })
        .collect();
    MeshAnimation::new(mesh, 24.0, positions).unwrap()
}

/// Every frame's positions of the loaded file, sampled at 24 fps, objects concatenated.
fn sampled(path: &Path, scene: Option<&str>) -> (Vec<Vec<Vec3>>, Vec<String>) {
    let options = tkio::LoadOptions {
        fps: 24.0,
        scene: scene.map(str::to_string),
        ..Default::default()
    };
    let (loaded, notes) = tkio::load_with_notes(path, &options).unwrap();
    let tkio::Loaded::Scene(s) = loaded else {
        panic!("not a scene")
    };
    let sampled = anim::sample(&s, &SampleOptions::default()).unwrap();
    let frames = sampled.objects[0].animation.frame_count();
    let per_frame = (0..frames)
        .map(|f| {
            sampled
                .objects
                .iter()
                .flat_map(|o| o.animation.frame(f).to_vec())
                .collect()
        })
        .collect();
    (per_frame, notes)
}

fn max_diff(a: &[Vec<Vec3>], b: &[Vec<Vec3>]) -> f32 {
    assert_eq!(a.len(), b.len(), "frame counts differ");
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| {
            assert_eq!(x.len(), y.len(), "vertex counts differ");
            x.iter().zip(y).map(|(p, q)| (*p - *q).abs().max_element())
        })
        .fold(0.0, f32::max)
}

fn extent(frames: &[Vec<Vec3>]) -> f32 {
    let all = frames.iter().flatten();
    let lo = all.clone().fold(Vec3::splat(f32::MAX), |a, p| a.min(*p));
    let hi = all.fold(Vec3::splat(f32::MIN), |a, p| a.max(*p));
    (hi - lo).length()
}

#[test]
fn quantized_flipbook_and_morph_read_back_within_the_quantization_error_at_half_the_size() {
    let dir = tempfile::tempdir().unwrap();
    let cache = robot_cache();
    for layout in [AnimationLayout::Flipbook, AnimationLayout::Morph] {
        let float =
            write_animations_with(&[(&cache, None)], layout, GlbOptions::default()).unwrap();
        let quant =
            write_animations_with(&[(&cache, None)], layout, GlbOptions::QUANTIZED).unwrap();
        keep_for_validation(&quant, &format!("quantized_{layout:?}"));
        let (json, _) = split(&quant);
        assert_eq!(json["extensionsRequired"], json!(["KHR_mesh_quantization"]));
        // Flipbook frames are all positions and normals; the morph file also holds UVs,
        // indices and the weights timeline, which stay as they are.
        let limit = match layout {
            AnimationLayout::Flipbook => 6,
            AnimationLayout::Morph => 7,
        };
        assert!(
            quant.len() * 10 < float.len() * limit,
            "{layout:?}: quantized {} bytes vs float {}",
            quant.len(),
            float.len()
        );
        let fp = write_tmp(dir.path(), "float.glb", &float);
        let qp = write_tmp(dir.path(), "quant.glb", &quant);
        let (a, _) = sampled(&fp, None);
        let (b, notes) = sampled(&qp, None);
        assert_eq!(a.len(), cache.frame_count());
        let err = max_diff(&a, &b);
        // One rounding of the position (morph: of the delta from the rounded base), on a
        // range per axis: within 1e-5 of the diagonal (the writer's bound).
        let tol = 1e-5 * extent(&a);
        assert!(err <= tol, "{layout:?}: error {err} > {tol}");
        assert!(err > 0.0, "{layout:?}: quantization changed nothing");
        assert!(notes.iter().any(|n| n.starts_with("KHR_mesh_quantization")));
    }
}

/// The robot written by our float writer, to edit.
fn robot_glb() -> Vec<u8> {
    let cache = robot_cache();
    write_animations_with(
        &[(&cache, None)],
        AnimationLayout::Flipbook,
        GlbOptions::default(),
    )
    .unwrap()
}

#[test]
fn extensions_that_do_not_touch_geometry_are_accepted_with_a_note() {
    let dir = tempfile::tempdir().unwrap();
    let plain = robot_glb();
    let (mut json, bin) = split(&plain);
    let required = [
        "KHR_lights_punctual",
        "KHR_texture_transform",
        "KHR_materials_emissive_strength",
    ];
    json["extensionsRequired"] = json!(required);
    json["extensionsUsed"] = json!(required);
    json["extensions"] = json!({"KHR_lights_punctual": {"lights": [{"type": "point"}]}});
    json["nodes"][0]["extensions"] = json!({"KHR_lights_punctual": {"light": 0}});
    json["materials"][0]["extensions"] =
        json!({"KHR_materials_emissive_strength": {"emissiveStrength": 2.0}});
    // A texture whose image is only in an extension (no `source`): gltf-json alone refuses it.
    json["textures"] = json!([{"extensions": {"KHR_texture_basisu": {"source": 0}}}]);
    let edited = write_tmp(dir.path(), "lights.glb", &join(&json, bin));
    let original = write_tmp(dir.path(), "plain.glb", &plain);
    let (a, _) = sampled(&original, None);
    let (b, notes) = sampled(&edited, None);
    assert_eq!(max_diff(&a, &b), 0.0);
    for ext in required {
        assert!(
            notes
                .iter()
                .any(|n| n.starts_with(ext) && n.contains("ignored")),
            "{notes:?}"
        );
    }
}

#[test]
fn unknown_geometry_extensions_fail_in_one_line_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let (json, bin) = split(&robot_glb());
    let pos = json["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
        .as_u64()
        .unwrap() as usize;
    for (ext, hint) in [
        ("VENDOR_packed_geometry", "re-export"),
        ("ACME_mesh_codec", "gltfpack"),
    ] {
        let mut j = json.clone();
        j["extensionsRequired"] = json!([ext]);
        j["extensionsUsed"] = json!([ext]);
        j["accessors"][pos]
            .as_object_mut()
            .unwrap()
            .remove("bufferView");
        j["meshes"][0]["primitives"][0]["extensions"] =
            json!({ext: {"bufferView": 0, "attributes": {"POSITION": 0}}});
        let p = write_tmp(dir.path(), "x.glb", &join(&j, bin.clone()));
        let err = tkio::load(&p, &Default::default()).unwrap_err().to_string();
        assert!(!err.contains('\n'), "{err}");
        assert!(
            err.contains(ext) && err.contains(hint) && err.contains("x.glb"),
            "{err}"
        );
    }
    // The same unknown extension with the geometry still present: read, with a note.
    let mut j = json.clone();
    j["extensionsRequired"] = json!(["VENDOR_metadata"]);
    let p = write_tmp(dir.path(), "y.glb", &join(&j, bin));
    let (_, notes) = sampled(&p, None);
    assert!(
        notes
            .iter()
            .any(|n| n.starts_with("VENDOR_metadata") && n.contains("geometry")),
        "{notes:?}"
    );
}

#[test]
fn sparse_accessors_substitute_their_values() {
    let dir = tempfile::tempdir().unwrap();
    let (mut json, mut bin) = split(&robot_glb());
    let pos = json["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
        .as_u64()
        .unwrap() as usize;
    // Vertices 3 and 7 of frame 1 move to (9, 9, 9) and (−9, 0, 1).
    let offset = bin.len();
    bin.extend([3u32, 7].iter().flat_map(|i| i.to_le_bytes()));
    bin.extend(
        [9.0f32, 9.0, 9.0, -9.0, 0.0, 1.0]
            .iter()
            .flat_map(|v| v.to_le_bytes()),
    );
    let views = json["bufferViews"].as_array_mut().unwrap();
    views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": 8}));
    views.push(json!({"buffer": 0, "byteOffset": offset + 8, "byteLength": 24}));
    let n = views.len();
    let acc = &mut json["accessors"][pos];
    acc["sparse"] = json!({"count": 2, "indices": {"bufferView": n - 2, "componentType": 5125},
                           "values": {"bufferView": n - 1}});
    acc["min"] = json!([-100.0, -100.0, -100.0]);
    acc["max"] = json!([100.0, 100.0, 100.0]);
    let p = write_tmp(dir.path(), "sparse.glb", &join(&json, bin));
    let (frames, _) = sampled(&p, None);
    assert_eq!(frames[0][3], Vec3::splat(9.0));
    assert_eq!(frames[0][7], Vec3::new(-9.0, 0.0, 1.0));
    let cache = robot_cache();
    assert_eq!(frames[0][4], cache.frame(0)[4]);
}

#[test]
fn meshopt_compressed_views_decode_to_the_original_data() {
    use meshoptimizer_rs::codec::{encode_vertex_buffer, VertexEncoding};
    let dir = tempfile::tempdir().unwrap();
    let quant = {
        let cache = robot_cache();
        write_animations_with(
            &[(&cache, None)],
            AnimationLayout::Flipbook,
            GlbOptions::QUANTIZED,
        )
        .unwrap()
    };
    let (mut json, bin) = split(&quant);
    // Compress every strided (vertex attribute) view, as gltfpack does, into buffer 1; buffer
    // 0 keeps only what is not compressed, and the compressed views point at a fallback.
    let mut compressed = Vec::new();
    let mut ws = meshoptimizer_rs::Workspace::default();
    let mut count = 0;
    for view in json["bufferViews"].as_array_mut().unwrap() {
        let Some(stride) = view["byteStride"].as_u64().map(|s| s as usize) else {
            continue;
        };
        let off = view["byteOffset"].as_u64().unwrap_or(0) as usize;
        let len = view["byteLength"].as_u64().unwrap() as usize;
        let data = &bin[off..off + len];
        let enc = encode_vertex_buffer(
            data,
            len / stride,
            stride,
            VertexEncoding::new(0, 2).unwrap(),
            &mut ws,
        )
        .unwrap();
        while !compressed.len().is_multiple_of(4) {
            compressed.push(0);
        }
        view["extensions"] = json!({"EXT_meshopt_compression": {
            "buffer": 2, "byteOffset": compressed.len(), "byteLength": enc.len(),
            "byteStride": stride, "count": len / stride, "mode": "ATTRIBUTES"}});
        view["buffer"] = json!(1);
        view["byteOffset"] = json!(0);
        compressed.extend(enc);
        count += 1;
    }
    assert!(count > 0);
    json["buffers"] = json!([{"byteLength": 0}, {"byteLength": 100_000_000,
        "extensions": {"EXT_meshopt_compression": {"fallback": true}}},
        {"byteLength": 0, "uri": "compressed.bin"}]);
    json["buffers"][2]["byteLength"] = json!(compressed.len());
    let used = ["KHR_mesh_quantization", "EXT_meshopt_compression"];
    json["extensionsRequired"] = json!(used);
    json["extensionsUsed"] = json!(used);
    std::fs::write(dir.path().join("compressed.bin"), &compressed).unwrap();
    // A .gltf with the uncompressed data embedded in the GLB-less form: keep buffer 0 as a file.
    json["buffers"][0] = json!({"byteLength": bin.len(), "uri": "plain.bin"});
    std::fs::write(dir.path().join("plain.bin"), &bin).unwrap();
    let p = write_tmp(
        dir.path(),
        "meshopt.gltf",
        &serde_json::to_vec(&json).unwrap(),
    );
    let q = write_tmp(dir.path(), "quant.glb", &quant);
    let (a, _) = sampled(&q, None);
    let (b, notes) = sampled(&p, None);
    assert_eq!(max_diff(&a, &b), 0.0);
    assert!(
        notes
            .iter()
            .any(|n| n.starts_with("EXT_meshopt_compression")),
        "{notes:?}"
    );
    assert!(compressed.len() < bin.len());
}

#[test]
fn one_of_several_scenes_is_read_and_scene_picks_it() {
    let dir = tempfile::tempdir().unwrap();
    let a = robot_cache();
    let mut b = robot_cache();
    b.mesh.name = "other".into();
    let bytes =
        tkio::gltf::write_animations(&[(&a, None), (&b, None)], AnimationLayout::Morph).unwrap();
    let (mut json, bin) = split(&bytes);
    json["scenes"] = json!([{"name": "first", "nodes": [0]}, {"name": "second", "nodes": [1]}]);
    json["scene"] = json!(1);
    let p = write_tmp(dir.path(), "scenes.glb", &join(&json, bin));
    let both = a.vertex_count();
    let (default, notes) = sampled(&p, None);
    assert_eq!(
        default[0].len(),
        both,
        "the default scene has one of the two meshes"
    );
    assert!(
        notes
            .iter()
            .any(|n| n.contains("2 scene(s)") && n.contains("'second'")),
        "{notes:?}"
    );
    let (first, notes) = sampled(&p, Some("first"));
    assert_eq!(first[0].len(), both);
    assert!(notes.iter().any(|n| n.contains("'first'")));
    let (by_index, _) = sampled(&p, Some("0"));
    assert_eq!(by_index, first);
    let options = tkio::LoadOptions {
        scene: Some("third".into()),
        ..Default::default()
    };
    let err = tkio::load(&p, &options).unwrap_err().to_string();
    assert!(
        err.contains("third") && err.contains("'first'") && err.contains("'second'"),
        "{err}"
    );
}

/// A .gltf copied without its .bin (as in an engine's asset folder fetched partially): one line
/// naming the missing file and how to fix it, not the OS error.
#[test]
fn gltf_without_its_bin_names_the_missing_file() {
    let dir = tempfile::tempdir().unwrap();
    let (mut json, _) = split(&robot_glb());
    json["buffers"][0]["uri"] = json!("Robot_data.bin");
    let p = write_tmp(
        dir.path(),
        "robot.gltf",
        &serde_json::to_vec(&json).unwrap(),
    );
    let err = tkio::load(&p, &Default::default()).unwrap_err().to_string();
    assert!(!err.contains('\n'), "{err}");
    assert!(
        err.contains("robot.gltf")
            && err.contains("Robot_data.bin is missing")
            && err.contains(".glb"),
        "{err}"
    );
    assert!(!err.contains("os error"), "{err}");
}
