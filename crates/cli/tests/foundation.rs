//! Foundation acceptance: every shared asset loads, `info` reports the right counts, round
//! trips keep positions, corrupt inputs fail cleanly.

mod common;

use common::*;

#[test]
fn info_reports_robot_expressive() {
    let v = json(&[
        "info",
        data("characters/RobotExpressive.glb").to_str().unwrap(),
    ]);
    assert_eq!(v["joints"], 43);
    assert_eq!(v["clips"].as_array().unwrap().len(), 14);
    assert_eq!(v["morph_targets"], 3);
    let verts: u64 = v["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["vertices"].as_u64().unwrap())
        .sum();
    assert_eq!(verts, 7214);
    let names: Vec<&str> = v["clips"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert!(names.contains(&"Dance") && names.contains(&"Wave"));
}

#[test]
fn info_reports_cesium_man_and_face() {
    let v = json(&["info", data("characters/CesiumMan.glb").to_str().unwrap()]);
    assert_eq!(v["joints"], 19);
    let face = data("face/ict-face-talk.glb");
    let v = json(&["info", face.to_str().unwrap(), "--fps", "30"]);
    assert_eq!(v["meshes"][0]["morph_targets"], 55);
    assert_eq!(v["meshes"][0]["vertices"], 9409);
    assert_eq!(v["clips"][0]["frames"], 1800);
    assert_eq!(v["clips"][0]["key_rate"], 30.0);
}

#[test]
fn every_shared_asset_loads() {
    for f in [
        "characters/RobotExpressive.glb",
        "characters/CesiumMan.glb",
        "characters/SimpleSkin.gltf",
        "morph/MorphStressTest/MorphStressTest.gltf",
        "morph/AnimatedMorphSphere/AnimatedMorphSphere.gltf",
        "meshes/spot.obj",
        "mocap/02_02.bvh",
        "mocap/12_03.bvh",
        "face/ict-face-talk.glb",
    ] {
        let v = json(&["info", data(f).to_str().unwrap()]);
        let bbox = v["bbox"].as_array().unwrap();
        let lo = bbox[0].as_array().unwrap();
        let hi = bbox[1].as_array().unwrap();
        assert!(
            (0..3).all(|k| lo[k].as_f64().unwrap() <= hi[k].as_f64().unwrap()),
            "{f}: bbox {bbox:?}"
        );
        assert!(
            (0..3).any(|k| lo[k].as_f64().unwrap() < hi[k].as_f64().unwrap()),
            "{f}: empty bbox"
        );
    }
}

fn read_cache(path: &std::path::Path) -> anim::MeshAnimation {
    match tkio::load(path, &tkio::LoadOptions::default()).unwrap() {
        tkio::Loaded::Cache(c) => c,
        tkio::Loaded::Scene(s) => {
            let sampled = anim::sample(&s, &anim::SampleOptions::default()).unwrap();
            sampled.merged("m").unwrap()
        }
        tkio::Loaded::Mesh(m) => anim::MeshAnimation::still(m),
    }
}

fn max_diff(a: &anim::MeshAnimation, b: &anim::MeshAnimation) -> f32 {
    assert_eq!(a.frame_count(), b.frame_count());
    assert_eq!(a.vertex_count(), b.vertex_count());
    a.positions()
        .iter()
        .zip(b.positions())
        .map(|(p, q)| (*p - *q).abs().max_element())
        .fold(0.0, f32::max)
}

#[test]
fn round_trip_glb_pc2_glb_keeps_positions() {
    let dir = tempfile::tempdir().unwrap();
    let robot = data("characters/RobotExpressive.glb");
    let pc2 = dir.path().join("dance.pc2");
    let back = dir.path().join("dance_back.glb");
    ok(&[
        "convert",
        robot.to_str().unwrap(),
        pc2.to_str().unwrap(),
        "--clip",
        "Dance",
    ]);
    assert!(
        dir.path().join("dance.obj").exists(),
        "rest mesh written beside the cache"
    );
    ok(&[
        "--no-quantize",
        "convert",
        pc2.to_str().unwrap(),
        back.to_str().unwrap(),
        "--as",
        "morph",
    ]);
    // The default output is quantized: within 1e-5 of the diagonal, at about half the size.
    let quantized = dir.path().join("dance_quantized.glb");
    ok(&[
        "convert",
        pc2.to_str().unwrap(),
        quantized.to_str().unwrap(),
        "--as",
        "morph",
    ]);
    let (float_len, quant_len) = (
        std::fs::metadata(&back).unwrap().len(),
        std::fs::metadata(&quantized).unwrap().len(),
    );
    assert!(
        quant_len * 10 < float_len * 7,
        "{quant_len} vs {float_len} bytes"
    );
    let scene = tkio::gltf::read(&robot).unwrap();
    let clip = scene.find_clip("Dance").unwrap();
    let opts = anim::SampleOptions {
        clip: Some(clip),
        ..Default::default()
    };
    let original = anim::sample(&scene, &opts).unwrap().merged("m").unwrap();
    let cached = read_cache(&pc2);
    let glb = read_cache(&back);
    assert!(max_diff(&original, &cached) <= 1e-5);
    assert!(
        max_diff(&original, &glb) <= 1e-5,
        "morph glb differs by {}",
        max_diff(&original, &glb)
    );
    let all = original.positions();
    let lo = all.iter().fold(anim::glam::Vec3::MAX, |a, p| a.min(*p));
    let hi = all.iter().fold(anim::glam::Vec3::MIN, |a, p| a.max(*p));
    let q = max_diff(&original, &read_cache(&quantized));
    assert!(
        q > 0.0 && q <= tkio::gltf::MAX_ERROR * (hi - lo).length(),
        "quantized morph glb differs by {q}"
    );
    keep_for_validation(dir.path(), "roundtrip_pc2");
}

#[test]
fn round_trip_glb_obj_sequence_glb_keeps_positions() {
    let dir = tempfile::tempdir().unwrap();
    let cesium = data("characters/CesiumMan.glb");
    let seq = dir.path().join("seq/walk.obj");
    ok(&[
        "convert",
        cesium.to_str().unwrap(),
        seq.to_str().unwrap(),
        "--as",
        "sequence",
    ]);
    let first = dir.path().join("seq/walk_0001.obj");
    assert!(first.exists());
    let back = dir.path().join("walk_morph.glb");
    let flip = dir.path().join("walk_flipbook.glb");
    ok(&[
        "--no-quantize",
        "convert",
        first.to_str().unwrap(),
        back.to_str().unwrap(),
        "--as",
        "morph",
    ]);
    ok(&[
        "convert",
        "--no-quantize",
        first.to_str().unwrap(),
        flip.to_str().unwrap(),
    ]);
    let original = read_cache(&cesium);
    let from_seq = read_cache(&first);
    assert_eq!(from_seq.frame_count(), 48);
    assert!(max_diff(&original, &from_seq) <= 1e-5);
    assert!(max_diff(&original, &read_cache(&back)) <= 1e-5);
    // The flipbook holds one mesh node per frame, each with the frame's positions.
    let scene = tkio::gltf::read(&flip).unwrap();
    assert_eq!(scene.meshes.len(), 48);
    let f7 = &scene.meshes[7].mesh.positions;
    let d = f7
        .iter()
        .zip(original.frame(7))
        .map(|(p, q)| (*p - *q).length())
        .fold(0.0, f32::max);
    assert!(d <= 1e-5);
    keep_for_validation(dir.path(), "roundtrip_seq");
}

#[test]
fn bvh_converts_to_a_glb_skeleton() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("walk.glb");
    ok(&[
        "convert",
        data("mocap/02_02.bvh").to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    let scene = tkio::gltf::read(&out).unwrap();
    assert_eq!(scene.clips.len(), 1);
    assert!(scene.skeleton().0.len() >= 31);
    keep_for_validation(dir.path(), "bvh");
}

#[test]
fn corrupt_inputs_exit_2_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let robot = std::fs::read(data("characters/RobotExpressive.glb")).unwrap();
    let trunc = dir.path().join("truncated.glb");
    std::fs::write(&trunc, &robot[..robot.len() / 2]).unwrap();
    assert_bad_input(&["info", trunc.to_str().unwrap()], "truncated.glb");

    // A glTF whose POSITION accessor claims more vertices than its buffer holds.
    let b64 = "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA";
    let gltf = |count: usize, data: &str| {
        format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,{data}"}}],
            "bufferViews":[{{"buffer":0,"byteLength":36}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":{count},"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}]}}"#
        )
    };
    let good = dir.path().join("good.gltf");
    std::fs::write(&good, gltf(3, b64)).unwrap();
    ok(&["info", good.to_str().unwrap()]);
    let counts = dir.path().join("counts.gltf");
    std::fs::write(&counts, gltf(30, b64)).unwrap();
    assert_bad_input(&["info", counts.to_str().unwrap()], "counts.gltf");
    // NaN in a position: 0x7fc00000.
    let nan = dir.path().join("nan.gltf");
    std::fs::write(
        &nan,
        gltf(3, "AADAfwAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"),
    )
    .unwrap();
    assert_bad_input(&["info", nan.to_str().unwrap()], "non-finite");

    let bvh = dir.path().join("bad.bvh");
    std::fs::write(&bvh, "HIERARCHY\nROOT hip\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition Yposition\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0\n").unwrap();
    assert_bad_input(&["info", bvh.to_str().unwrap()], "bad.bvh");
    let garbage = dir.path().join("garbage.bin");
    std::fs::write(&garbage, [0u8, 1, 2, 3, 250, 251]).unwrap();
    assert_bad_input(&["info", garbage.to_str().unwrap()], "garbage.bin");
    assert_bad_input(
        &["info", dir.path().join("missing.glb").to_str().unwrap()],
        "missing.glb",
    );
    assert_bad_input(
        &[
            "convert",
            data("characters/RobotExpressive.glb").to_str().unwrap(),
            "x.glb",
            "--clip",
            "Nope",
        ],
        "Nope",
    );
}
