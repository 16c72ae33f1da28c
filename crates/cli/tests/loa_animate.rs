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
    let frames = report["frames"].as_u64().unwrap();
    assert_eq!(frames, 47);
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
    assert!((duration - 46.0 / 24.0).abs() < 1e-3, "{duration}");
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
