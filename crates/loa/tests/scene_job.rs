//! The scene-level job (`loa::job`): the same motion as the steps it joins, written and read
//! back through `tkio` on two characters, and its refusals.

mod common;

use loa::animate::{AnimateOptions, Character};
use loa::job::{self, SceneJobError, SceneOptions};
use loa::LineOptions;

use common::{data, example};

/// Options of a short physics line on `bones` (at the first keystroke).
fn options(keys: &loa::Keystrokes, bones: &str) -> SceneOptions {
    let first = keys.keys()[0].frame;
    SceneOptions {
        line: LineOptions::default(),
        motion: AnimateOptions {
            bone_sets: vec![format!("{bones}@{first}").parse().unwrap()],
            max_iterations: 30,
            ..Default::default()
        },
        ..Default::default()
    }
}

#[test]
fn scene_job_gives_the_steps_motion_and_writes_glb_and_bvh_on_two_characters() {
    let keys = example("jump.json");
    let dir = tempfile::tempdir().unwrap();
    for (rel, bones) in [
        ("characters/RobotExpressive.glb", "right-leg-spine-head"),
        ("characters/CesiumMan.glb", "foot-head"),
    ] {
        let options = options(&keys, bones);
        let scene = job::open_character(&data(rel), options.line.physics.fps).unwrap();
        let done = job::animate_scene(&scene, &keys, &options).unwrap();

        // The steps the front ends used to join themselves.
        let line = loa::line(&keys, &options.line).unwrap();
        let fps = line.animation.fps;
        let character = Character::from_scene(&scene, &options.pose, fps).unwrap();
        let motion = loa::animate(&character, &line, &options.motion).unwrap();
        assert_eq!(done.motion.positions, motion.positions, "{rel}");
        assert_eq!(done.motion.rotations, motion.rotations, "{rel}");
        assert_eq!(done.joint_names, character.joint_names(), "{rel}");
        assert_eq!(done.report.frames, motion.frames(), "{rel}");
        assert_eq!(
            done.report.line_distance_mean_percent,
            100.0 * motion.report.line_distance_mean
        );

        let glb = dir.path().join("motion.glb");
        let bvh = dir.path().join("motion.bvh");
        done.save(&glb).unwrap();
        done.save(&bvh).unwrap();
        let load = tkio::LoadOptions {
            fps: fps as f32,
            ..Default::default()
        };
        let tkio::Loaded::Scene(back) = tkio::load(&glb, &load).unwrap() else {
            panic!("{rel}: the .glb is not a scene");
        };
        assert_eq!(back.clips.len(), 1, "{rel}");
        assert_eq!(back.clips[0].name, loa::animate::CLIP_NAME);
        assert_eq!(
            back.meshes.len(),
            scene.meshes.len(),
            "{rel}: the skin is kept"
        );
        let tkio::Loaded::Scene(back) = tkio::load(&bvh, &load).unwrap() else {
            panic!("{rel}: the .bvh is not a scene");
        };
        let (skeleton, _) = back.skeleton();
        assert_eq!(skeleton.len(), done.skeleton.len(), "{rel}");
        let sampled = anim::sample(
            &back,
            &anim::SampleOptions {
                fps: fps as f32,
                clip: Some(0),
                meshes: Vec::new(),
            },
        )
        .unwrap();
        assert_eq!(sampled.frame_count, motion.frames(), "{rel}");
    }
}

#[test]
fn scene_job_refuses_unknown_outputs_and_files_without_a_character() {
    let keys = example("whip.json");
    let path = data("characters/RobotExpressive.glb");
    let options = options(&keys, "right-leg-spine-head");
    let scene = job::open_character(&path, 24.0).unwrap();
    let mut short = options.clone();
    short.motion.max_iterations = 1;
    let done = job::animate_scene(&scene, &keys, &short).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("motion.obj");
    let err = done.save(&obj).unwrap_err();
    assert!(matches!(err, SceneJobError::Extension { .. }), "{err}");
    assert!(err.to_string().contains("use .glb or .bvh"), "{err}");
    assert!(!obj.exists(), "nothing is written");
    let err = done
        .save_preview(&dir.path().join("motion.mp4"))
        .unwrap_err();
    assert!(err.to_string().contains("use .png or .gif"), "{err}");

    let err = job::open_character(&data("meshes/spot.obj"), 24.0).unwrap_err();
    assert!(matches!(err, SceneJobError::NotACharacter(_)), "{err}");
    assert!(
        err.to_string().contains("spot.obj: not a character"),
        "{err}"
    );

    let mut camera = options;
    camera.camera = Some("nowhere".into());
    let err = job::animate_scene(&scene, &keys, &camera).unwrap_err();
    assert!(matches!(err, SceneJobError::Camera { .. }), "{err}");
}
