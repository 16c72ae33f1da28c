//! FBX through ufbx: a small file Blender wrote (`tests/data/bend_box.fbx`, see the README
//! there) reads with its skeleton, skin, shape key, camera and clip, converted to Y-up metres,
//! and its sampled positions equal those of Blender's glTF export of the same scene (at rest
//! and in every frame of its animation; whole characters in `tests/exporters.rs`).

use std::path::PathBuf;

use anim::glam::Vec3;
use anim::{SampleOptions, Scene};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn load(name: &str) -> (Scene, Vec<String>) {
    let path = fixture(name);
    let (loaded, notes) = tkio::load_with_notes(&path, &tkio::LoadOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    match loaded {
        tkio::Loaded::Scene(s) => (*s, notes),
        _ => panic!("{name}: not a scene"),
    }
}

/// Vertices of every object at every frame of `clip` (rest pose: `None`), sorted so that
/// files with another vertex order compare equal.
fn frames(scene: &Scene, clip: Option<usize>) -> Vec<Vec<Vec3>> {
    let s = anim::sample(
        scene,
        &SampleOptions {
            fps: 24.0,
            clip,
            ..Default::default()
        },
    )
    .unwrap();
    let n = s.objects[0].animation.frame_count();
    (0..n)
        .map(|f| {
            let mut v: Vec<Vec3> = s
                .objects
                .iter()
                .flat_map(|o| o.animation.frame(f).to_vec())
                .collect();
            v.sort_by(|a, b| {
                a.x.total_cmp(&b.x)
                    .then(a.y.total_cmp(&b.y))
                    .then(a.z.total_cmp(&b.z))
            });
            v
        })
        .collect()
}

#[test]
fn blender_fbx_reads_skeleton_skin_shape_key_camera_and_clip() {
    let (scene, notes) = load("bend_box.fbx");
    assert!(notes[0].starts_with("FBX 7400 (binary)"), "{notes:?}");
    assert!(
        notes
            .iter()
            .any(|n| n.contains("metres") && n.contains("Y-up")),
        "{notes:?}"
    );
    assert_eq!(scene.meshes.len(), 1);
    let box_mesh = &scene.meshes[0];
    assert_eq!(box_mesh.mesh.vertex_count(), 8);
    assert_eq!(box_mesh.mesh.triangles.len(), 12);
    assert!(box_mesh.joint_weights.is_some());
    assert_eq!(box_mesh.morph_targets.len(), 1);
    assert_eq!(box_mesh.morph_targets[0].name, "bulge");
    let (skeleton, _) = scene.skeleton();
    assert!(skeleton.len() >= 2, "{} joints", skeleton.len());
    assert!(scene.nodes.iter().any(|n| n.name == "tip"));
    assert_eq!(scene.cameras.len(), 1);
    assert_eq!(scene.skins.len(), 1);
    assert_eq!(scene.skins[0].joints.len(), 2);
    assert!(!scene.clips.is_empty());
    assert_eq!(scene.clips[0].frame_count(24.0), 13);
    // Y-up metres: the 4 m tall box stands along +Y.
    let f = frames(&scene, Some(0));
    let lo = f[0].iter().fold(Vec3::MAX, |a, p| a.min(*p));
    let hi = f[0].iter().fold(Vec3::MIN, |a, p| a.max(*p));
    assert!(((hi - lo).y - 4.0).abs() < 1e-4, "{lo} .. {hi}");
    assert!((lo.y).abs() < 1e-4, "{lo}");
}

/// The scene without clips (its rest pose) and with its shape keys off (the exporters
/// disagree on the rest weight of a shape key: FBX writes its value when exported, glTF 0).
fn at_rest(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    s.clips.clear();
    for m in &mut s.meshes {
        m.default_weights.iter_mut().for_each(|w| *w = 0.0);
    }
    s
}

/// Largest distance from a point of either set to the nearest point of the other.
fn set_distance(a: &[Vec3], b: &[Vec3]) -> f32 {
    let directed = |a: &[Vec3], b: &[Vec3]| {
        a.iter()
            .map(|p| b.iter().map(|q| p.distance(*q)).fold(f32::MAX, f32::min))
            .fold(0.0f32, f32::max)
    };
    directed(a, b).max(directed(b, a))
}

#[test]
fn blender_fbx_positions_equal_its_gltf_export_at_rest_and_every_frame() {
    let (fbx, _) = load("bend_box.fbx");
    let (glb, _) = load("bend_box.glb");
    // 1e-5 of the box's 4.24 m diagonal.
    let tolerance = 1e-5 * Vec3::new(1.0, 4.0, 1.0).length();

    let (a, b) = (frames(&at_rest(&fbx), None), frames(&at_rest(&glb), None));
    assert_eq!((a.len(), b.len()), (1, 1));
    // The glTF splits each corner of the box into its own vertex: compare as point sets.
    let d = set_distance(&a[0], &b[0]);
    assert!(d < tolerance, "rest pose: largest distance {d}");

    // Blender's glTF export splits the armature action and the shape-key action into two
    // clips; its FBX export bakes both into one stack. Merged, they are the same animation.
    assert_eq!(fbx.clips.len(), 1);
    assert_eq!(glb.clips.len(), 2);
    let mut merged = glb.clone();
    let key_action = merged.clips.pop().unwrap();
    merged.clips[0].channels.extend(key_action.channels);
    let (a, b) = (frames(&fbx, Some(0)), frames(&merged, Some(0)));
    assert_eq!(a.len(), 13, "frame count");
    assert_eq!(a.len(), b.len(), "frame counts");
    for (f, (fa, fb)) in a.iter().zip(&b).enumerate() {
        let d = set_distance(fa, fb);
        assert!(d < tolerance, "frame {f}: largest distance {d}");
    }
    // The tip bends and the box bulges: the clip's last frame differs from its first.
    assert!(set_distance(&a[0], &a[12]) > 0.5);
}

#[test]
fn blender_fbx_uvs_are_those_of_its_gltf_export() {
    let (fbx, _) = load("bend_box.fbx");
    let (glb, _) = load("bend_box.glb");
    let (f, g) = (&fbx.meshes[0].mesh, &glb.meshes[0].mesh);
    let (fu, gu) = (f.uvs.as_ref().unwrap(), g.uvs.as_ref().unwrap());
    assert!(f.extra_uvs.is_empty(), "one UV set");
    // FBX keeps one vertex per control point (the UVs of its first corner), the glTF one per
    // corner: every FBX vertex has a glTF copy at its rest position with its UV (v flipped
    // from FBX's bottom-left origin to glTF's top-left one).
    let f_world = anim::sample(&at_rest(&fbx), &SampleOptions::default()).unwrap();
    let g_world = anim::sample(&at_rest(&glb), &SampleOptions::default()).unwrap();
    let (fw, gw) = (
        f_world.objects[0].animation.frame(0),
        g_world.objects[0].animation.frame(0),
    );
    for (v, (p, uv)) in fw.iter().zip(fu).enumerate() {
        let found = gw.iter().zip(gu).any(|(q, w)| {
            p.distance(*q) < 1e-4 && (uv[0] - w[0]).abs() + (uv[1] - w[1]).abs() < 1e-5
        });
        assert!(
            found,
            "FBX vertex {v} at {p} with UV {uv:?} has no glTF copy"
        );
    }
}

#[test]
fn fbx_is_detected_by_content_and_bad_bytes_fail_in_one_line() {
    let bytes = std::fs::read(fixture("bend_box.fbx")).unwrap();
    assert_eq!(
        tkio::detect(&bytes, std::path::Path::new("x.bin")),
        Some(tkio::Format::Fbx)
    );
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("broken.fbx");
    std::fs::write(&p, &bytes[..bytes.len() / 3]).unwrap();
    let err = tkio::load(&p, &Default::default()).unwrap_err().to_string();
    assert!(err.contains("broken.fbx") && !err.contains('\n'), "{err}");
}
