//! `toonkit loa animate`: character motion from the dynamic line (Guay et al. 2015, §4).

mod common;

use common::{assert_bad_input, data, json, keep_for_validation};

fn examples(rel: &str) -> String {
    let p = format!("{}/../../examples/loa/{rel}", env!("CARGO_MANIFEST_DIR"));
    assert!(std::path::Path::new(&p).exists(), "missing example {p}");
    p
}

#[test]
fn robot_jump_writes_glb_bvh_and_gif() {
    let dir = tempfile::tempdir().unwrap();
    let robot = data("characters/RobotExpressive.glb");
    let out = dir.path().join("jump.glb");
    let bvh = dir.path().join("jump.bvh");
    let gif = dir.path().join("jump.gif");
    let report = json(&[
        "loa",
        "animate",
        robot.to_str().unwrap(),
        &examples("jump.json"),
        "-o",
        out.to_str().unwrap(),
        "--bvh",
        bvh.to_str().unwrap(),
        "--bones",
        "right-leg-spine-head@0",
        "--bones",
        "left-leg-spine-head@22",
        "--contact",
        "FootL@0..3",
        "--twist",
        "Torso_1@22:20",
        "--render",
        gif.to_str().unwrap(),
    ]);
    println!("{report:#}");
    // Keystrokes 0..=46, then the default `--settle`: one key interval (46 - 34 = 12 frames).
    let frames = report["frames"].as_u64().unwrap();
    assert_eq!(frames, 47 + 12);
    assert_eq!(report["joints"].as_u64().unwrap(), 43);
    let dist = report["line_distance_mean_percent"].as_f64().unwrap();
    let step = report["max_rotation_step_degrees"].as_f64().unwrap();
    let contact = report["contact_error_max_percent"].as_f64().unwrap();
    println!("jump: line distance {dist:.2} %, max joint step {step:.1}°, contact {contact:.3} %");
    assert!(dist < 10.0);
    assert!(step < 20.0);
    assert!(contact < 1.0);
    // The glb holds the character and one clip of the right length.
    let scene = tkio::gltf::read(&out).unwrap();
    assert_eq!(scene.clips.len(), 1);
    assert_eq!(scene.clips[0].name, "loa");
    assert!(!scene.meshes.is_empty());
    let duration = scene.clips[0].duration();
    assert!((duration - 58.0 / 24.0).abs() < 1e-3, "{duration}");
    let motion = tkio::bvh::read(&std::fs::read(&bvh).unwrap()).unwrap();
    assert_eq!(motion.clips.len(), 1);
    assert!(std::fs::read(&gif).unwrap().starts_with(b"GIF8"));
    keep_for_validation(dir.path(), "loa_animate");
}

#[test]
fn bvh_character_to_bvh_output() {
    let dir = tempfile::tempdir().unwrap();
    let keys = dir.path().join("keys.json");
    std::fs::write(
        &keys,
        r#"{"keystrokes": [
          {"frame": 0, "points": [[0, 0], [10, -50], [0, -100]]},
          {"frame": 12, "points": [[0, 0], [-10, -50], [0, -100]]}]}"#,
    )
    .unwrap();
    let out = dir.path().join("walk.bvh");
    let report = json(&[
        "loa",
        "animate",
        data("mocap/02_02.bvh").to_str().unwrap(),
        keys.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--pose",
        "motion@0",
        "--plane-normal",
        "0,0,1",
        "--mode",
        "hermite",
    ]);
    let dist = report["line_distance_mean_percent"].as_f64().unwrap();
    println!("BVH: line distance {dist:.2} %");
    assert!(dist < 10.0);
    let scene = tkio::bvh::read(&std::fs::read(&out).unwrap()).unwrap();
    assert_eq!(scene.skeleton().0.len(), 43);
}

#[test]
fn bad_inputs_exit_2_with_one_line() {
    let robot = data("characters/RobotExpressive.glb");
    let r = robot.to_str().unwrap();
    let k = examples("jump.json");
    let dir = tempfile::tempdir().unwrap();
    let o = dir.path().join("x.glb");
    let o = o.to_str().unwrap();
    assert_bad_input(&["loa", "animate", r, &k, "-o", "x.txt"], "x.txt");
    assert_bad_input(
        &["loa", "animate", r, &k, "-o", o, "--bones", "wings@0"],
        "wings",
    );
    assert_bad_input(
        &["loa", "animate", r, &k, "-o", o, "--bones", "arms@5"],
        "keystroke frames",
    );
    assert_bad_input(
        &["loa", "animate", r, &k, "-o", o, "--plane-normal", "0,0,0"],
        "normal",
    );
    assert_bad_input(
        &["loa", "animate", r, &k, "-o", o, "--contact", "Tail@0"],
        "Tail",
    );
}

#[test]
fn settle_wobble_and_reversed_strokes_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("whip.json");
    let report = json(&[
        "loa",
        "line",
        &examples("whip.json"),
        "-o",
        out.to_str().unwrap(),
        "--settle",
        "24",
        "--wobble",
        "20:1:0,-800",
    ]);
    // 41 frames of keystrokes (0..=40) + 24 settle frames (the wobble's tail may add more).
    let frames = report["frames"].as_u64().unwrap();
    println!("whip --settle 24 --wobble: {frames} frames");
    assert!(frames >= 65, "{frames}");
    let keyed = json(&[
        "loa",
        "line",
        &examples("whip.json"),
        "-o",
        out.to_str().unwrap(),
        "--settle",
        "key",
    ]);
    assert_eq!(keyed["frames"].as_u64().unwrap(), 41 + 20);
    // `key` is the default; `--settle 0` ends on the last keystroke.
    let default = json(&[
        "loa",
        "line",
        &examples("whip.json"),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(default["frames"], keyed["frames"]);
    let none = json(&[
        "loa",
        "line",
        &examples("whip.json"),
        "-o",
        out.to_str().unwrap(),
        "--settle",
        "0",
    ]);
    assert_eq!(none["frames"].as_u64().unwrap(), 41);
    assert_bad_input(
        &[
            "loa",
            "line",
            &examples("whip.json"),
            "-o",
            out.to_str().unwrap(),
            "--wobble",
            "20:2:0,1",
        ],
        "wobble",
    );
    // A keystroke drawn backwards is reversed, with a warning on stderr.
    let text = std::fs::read_to_string(examples("whip.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let pts = v["keystrokes"][1]["points"].as_array_mut().unwrap();
    pts.reverse();
    let flipped = dir.path().join("flipped.json");
    std::fs::write(&flipped, v.to_string()).unwrap();
    let out = common::toonkit(&[
        "loa",
        "line",
        flipped.to_str().unwrap(),
        "-o",
        dir.path().join("f.json").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("warning") && err.contains("frame 20"), "{err}");
}

#[test]
fn perspective_camera_node_and_following_render() {
    let dir = tempfile::tempdir().unwrap();
    let mut scene = tkio::gltf::read(&data("characters/RobotExpressive.glb")).unwrap();
    // A perspective camera 12 units in front of the robot, 2 units up, looking at it.
    scene.cameras.push(anim::SceneCamera {
        name: "Cam".into(),
        projection: anim::Projection::Perspective {
            yfov: 0.6,
            aspect: None,
            znear: 0.1,
            zfar: Some(100.0),
        },
    });
    scene.nodes.push(anim::Node {
        name: "Cam".into(),
        transform: anim::Transform::from_translation(anim::glam::Vec3::new(0.0, 2.0, 12.0)),
        camera: Some(scene.cameras.len() - 1),
        ..Default::default()
    });
    let with_camera = dir.path().join("robot_cam.glb");
    std::fs::write(&with_camera, tkio::gltf::write_glb(&scene).unwrap()).unwrap();
    let out = dir.path().join("jump.glb");
    let png = dir.path().join("jump.png");
    let report = json(&[
        "loa",
        "animate",
        with_camera.to_str().unwrap(),
        &examples("jump.json"),
        "-o",
        out.to_str().unwrap(),
        "--camera",
        "Cam",
        "--render",
        png.to_str().unwrap(),
    ]);
    let dist = report["line_distance_mean_percent"].as_f64().unwrap();
    println!("perspective camera: line distance {dist:.2} %");
    assert!(dist < 8.0);
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    assert_bad_input(
        &[
            "loa",
            "animate",
            with_camera.to_str().unwrap(),
            &examples("jump.json"),
            "-o",
            out.to_str().unwrap(),
            "--camera",
            "Nope",
        ],
        "Cam",
    );
}
