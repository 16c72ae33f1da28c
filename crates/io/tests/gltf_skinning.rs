//! Skinning checked against values computed independently from the file's own buffers
//! (decoded here by hand, without the gltf crate or our reader).

use anim::glam::{Mat4, Quat, Vec3, Vec4};
use anim::{sample, SampleOptions};
use base64::Engine;

fn data(rel: &str) -> String {
    testdata::asset(rel).display().to_string()
}

fn f32s(b: &[u8], off: usize, n: usize) -> Vec<f32> {
    (0..n)
        .map(|i| f32::from_le_bytes(b[off + 4 * i..off + 4 * i + 4].try_into().unwrap()))
        .collect()
}

#[test]
fn simple_skin_matches_hand_computed_skinning() {
    let path = data("characters/SimpleSkin.gltf");
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let bufs: Vec<Vec<u8>> = doc["buffers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| {
            let uri = b["uri"].as_str().unwrap();
            let b64 = uri.split(',').nth(1).unwrap();
            base64::engine::general_purpose::STANDARD
                .decode(b64)
                .unwrap()
        })
        .collect();
    // Layout known from the file: positions buffer 0 @48, joints u16x4 + weights f32x4 in
    // buffer 1 (@0, @160, both with a 16-byte stride), inverse binds buffer 2, animation times/rotations buffer 3.
    let pos: Vec<Vec3> = f32s(&bufs[0], 48, 30)
        .chunks(3)
        .map(Vec3::from_slice)
        .collect();
    let joints: Vec<[u16; 4]> = (0..10)
        .map(|v| {
            std::array::from_fn(|k| {
                u16::from_le_bytes([bufs[1][v * 16 + 2 * k], bufs[1][v * 16 + 2 * k + 1]])
            })
        })
        .collect();
    let weights: Vec<[f32; 4]> = (0..10)
        .map(|v| f32s(&bufs[1], 160 + 16 * v, 4).try_into().unwrap())
        .collect();
    let ibm: Vec<Mat4> = (0..2)
        .map(|j| Mat4::from_cols_slice(&f32s(&bufs[2], 64 * j, 16)))
        .collect();
    let times = f32s(&bufs[3], 0, 12);
    let rots: Vec<Quat> = f32s(&bufs[3], 48, 48)
        .chunks(4)
        .map(|q| Quat::from_slice(q))
        .collect();

    let scene = tkio::gltf::read(std::path::Path::new(&path)).unwrap();
    // At 2 fps every frame lands on a key (keys every 0.5 s).
    let s = sample(
        &scene,
        &SampleOptions {
            fps: 2.0,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(s.frame_count, 12);
    let mut max_err = 0.0f32;
    for (f, &t) in times.iter().enumerate() {
        assert!((t - f as f32 * 0.5).abs() < 1e-6);
        let world1 = Mat4::from_translation(Vec3::Y);
        let world2 = world1 * Mat4::from_quat(rots[f].normalize());
        let m = [world1 * ibm[0], world2 * ibm[1]];
        let got = s.objects[0].animation.frame(f);
        for v in 0..10 {
            let mut want = Vec4::ZERO;
            for k in 0..4 {
                want += weights[v][k] * (m[joints[v][k] as usize] * pos[v].extend(1.0));
            }
            max_err = max_err.max((got[v] - want.truncate()).length());
        }
    }
    assert!(max_err < 1e-5, "max error {max_err}");
    // The strip actually bends: the top vertex moves far from its rest position.
    let top = s.objects[0].animation.frame(6)[9];
    assert!(
        (top - pos[9]).length() > 0.3,
        "top vertex barely moved: {top}"
    );
}

#[test]
fn simple_skin_slerp_between_keys() {
    let path = data("characters/SimpleSkin.gltf");
    let scene = tkio::gltf::read(std::path::Path::new(&path)).unwrap();
    // 4 fps: odd frames are halfway between keys, where the joint rotation is the slerp.
    let s = sample(
        &scene,
        &SampleOptions {
            fps: 4.0,
            ..Default::default()
        },
    )
    .unwrap();
    let sk = s.skeletal.as_ref().unwrap();
    let k = s.skeleton.find("joint2").unwrap_or(1);
    let a = sk.frame(2)[k].to_scale_rotation_translation().1;
    let b = sk.frame(4)[k].to_scale_rotation_translation().1;
    let mid = sk.frame(3)[k].to_scale_rotation_translation().1;
    assert!(mid.abs_diff_eq(a.slerp(b, 0.5), 1e-5) || mid.abs_diff_eq(-a.slerp(b, 0.5), 1e-5));
}

#[test]
fn cesium_man_walks_on_the_ground() {
    let scene = tkio::gltf::read(std::path::Path::new(&data("characters/CesiumMan.glb"))).unwrap();
    let s = sample(&scene, &SampleOptions::default()).unwrap();
    assert_eq!(s.skeleton.len(), 19);
    let a = &s.objects[0].animation;
    assert_eq!(a.vertex_count(), 3273);
    for f in 0..a.frame_count() {
        let b = anim::Aabb::from_points(a.frame(f));
        // Feet stay near the ground, the head near 1.5 m, every frame.
        assert!(
            b.min.y.abs() < 0.05 && (b.max.y - 1.5).abs() < 0.1,
            "frame {f}: {b:?}"
        );
    }
    // Arms and legs move: frames differ.
    let d: f32 = a
        .frame(0)
        .iter()
        .zip(a.frame(12))
        .map(|(p, q)| (*p - *q).length())
        .fold(0.0, f32::max);
    assert!(d > 0.05);
}

/// Influence sets whose counts differ from the positions', or from each other, are an error
/// naming them (the joints and the geometry are read on different threads: the counts are
/// checked after both, and between sets before they are joined per vertex).
#[test]
fn influence_counts_that_differ_are_an_error() {
    let path = data("characters/SimpleSkin.gltf");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(tkio::gltf::read_bytes(text.as_bytes()).is_ok());
    let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    let attrs = &doc["meshes"][0]["primitives"][0]["attributes"];
    let weights = attrs["WEIGHTS_0"].as_u64().unwrap() as usize;
    // A copy of WEIGHTS_0's accessor one vertex short.
    let mut short = doc["accessors"][weights].clone();
    short["count"] = (short["count"].as_u64().unwrap() - 1).into();
    let short_index = doc["accessors"].as_array().unwrap().len();

    // One set, short of the positions.
    let mut one = doc.clone();
    one["accessors"].as_array_mut().unwrap().push(short.clone());
    one["meshes"][0]["primitives"][0]["attributes"]["WEIGHTS_0"] = short_index.into();
    // Two sets, the second one short of the first.
    let mut two = doc.clone();
    two["accessors"].as_array_mut().unwrap().push(short);
    let a = &mut two["meshes"][0]["primitives"][0]["attributes"];
    a["JOINTS_1"] = a["JOINTS_0"].clone();
    a["WEIGHTS_1"] = short_index.into();
    for bad in [one, two] {
        let err = tkio::gltf::read_bytes(bad.to_string().as_bytes()).unwrap_err();
        assert!(
            err.to_string().contains("JOINTS/WEIGHTS count differs"),
            "{err}"
        );
    }
}

#[test]
fn node_world_alone_is_the_sampled_scenes_bit_for_bit() {
    // What the studio sends a renderer that skins the meshes itself: the node matrices of a
    // clip, without sampling any vertex, must be the ones a full sampling computes.
    for (file, clip) in [
        ("characters/RobotExpressive.glb", 0),
        ("characters/RobotExpressive.glb", 5),
        ("characters/CesiumMan.glb", 0),
    ] {
        let scene = tkio::gltf::read(std::path::Path::new(&data(file))).unwrap();
        let options = SampleOptions {
            fps: 24.0,
            clip: Some(clip),
            meshes: Vec::new(),
        };
        let full = sample(&scene, &options).unwrap();
        let (frames, world) = anim::sample_node_world(&scene, &options).unwrap();
        assert_eq!(frames, full.frame_count, "{file} clip {clip}");
        assert!(!world.is_empty());
        assert_eq!(world, full.node_world, "{file} clip {clip}");
    }
}
