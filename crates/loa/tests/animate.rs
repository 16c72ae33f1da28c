//! Acceptance tests of 3D character motion following the dynamic line (Section 4, 4.1), on
//! RobotExpressive (43 joints, IK-style feet) and a CMU BVH skeleton.

use std::path::PathBuf;

use anim::Skeleton;
use loa::animate::{animate, AnimateOptions, BoneSetKey, Character, ContactKey, Motion, TwistKey};
use loa::{Keystrokes, LineOptions, Mode};

fn data(rel: &str) -> PathBuf {
    testdata::asset(rel)
}

fn robot() -> Skeleton {
    let path = data("characters/RobotExpressive.glb");
    let scene = tkio::gltf::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    scene.skeleton().0
}

fn bvh() -> Skeleton {
    let path = data("mocap/02_02.bvh");
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    tkio::bvh::read(&bytes).unwrap().skeleton().0
}

/// A stroke from the feet (screen bottom) up, bowed sideways by `bow` (fraction of length).
fn stroke(bow: f64, lean: f64) -> String {
    let pts: Vec<String> = (0..=20)
        .map(|i| {
            let s = i as f64 / 20.0;
            let x = bow * 100.0 * (std::f64::consts::PI * s).sin() + lean * 100.0 * s;
            format!("[{x:.3}, {:.3}]", -100.0 * s)
        })
        .collect();
    format!("[{}]", pts.join(", "))
}

fn line(keys: &[(i64, f64, f64)]) -> loa::Animation {
    let ks: Vec<String> = keys
        .iter()
        .map(|(f, bow, lean)| format!(r#"{{"frame": {f}, "points": {}}}"#, stroke(*bow, *lean)))
        .collect();
    let json = format!(r#"{{"keystrokes": [{}]}}"#, ks.join(", "));
    let keys = Keystrokes::from_json_str(&json).unwrap();
    let options = LineOptions {
        mode: Mode::Hermite,
        ..Default::default()
    };
    loa::line(&keys, &options).unwrap().animation
}

fn sets(s: &[(&str, i64)]) -> Vec<BoneSetKey> {
    s.iter()
        .map(|(n, f)| BoneSetKey {
            frame: *f,
            set: n.parse().unwrap(),
        })
        .collect()
}

/// Largest relative change of any skeleton bone's length over the motion. Joints attached to a
/// leaf for solving (IK effectors such as RobotExpressive's feet, parented to the armature
/// root) are measured against the leaf they follow.
fn bone_length_drift(skeleton: &Skeleton, character: &Character, motion: &Motion) -> f64 {
    let rest = character.initial_positions();
    let attached = character.attachments();
    let mut worst: f64 = 0.0;
    for f in 0..motion.frames() {
        let p = motion.positions_at(f);
        for (k, j) in skeleton.joints.iter().enumerate() {
            let parent = attached.iter().find(|a| a.0 == k).map(|a| a.1).or(j.parent);
            if let Some(q) = parent {
                let l0 = (rest[k] - rest[q]).length();
                if l0 > 1e-12 {
                    worst = worst.max(((p[k] - p[q]).length() - l0).abs() / l0);
                }
            }
        }
    }
    worst
}

#[test]
fn fixed_bone_set_static_line_matches_robot() {
    let skeleton = robot();
    let character = Character::rest(&skeleton).unwrap();
    let line = line(&[(0, 0.15, 0.1), (24, 0.15, 0.1)]);
    let motion = animate(
        &character,
        &line,
        &sets(&[("right-leg-spine-head", 0)]),
        &[],
        &[],
        &AnimateOptions::default(),
    )
    .unwrap();
    let r = &motion.report;
    println!(
        "robot static line: mean 2D distance {:.2} % of line length (max {:.2} %), \
         {} iterations, energy {:.4} -> {:.4}",
        100.0 * r.line_distance_mean,
        100.0 * r.line_distance_worst.distance,
        r.planar.iterations,
        r.planar.initial_energy,
        r.planar.final_energy
    );
    assert!(r.line_distance_mean < 0.08, "{r:?}");
    let drift = bone_length_drift(&skeleton, &character, &motion);
    println!("robot bone length drift {drift:.2e}");
    assert!(drift < 1e-9);
}

#[test]
fn fig5_switching_bone_sets_has_no_jump() {
    let skeleton = robot();
    let character = Character::rest(&skeleton).unwrap();
    let line = line(&[(0, 0.2, 0.1), (12, 0.05, 0.0), (24, -0.2, -0.1)]);
    let motion = animate(
        &character,
        &line,
        &sets(&[("right-leg-spine-head", 0), ("left-leg-spine-head", 24)]),
        &[],
        &[],
        &AnimateOptions::default(),
    )
    .unwrap();
    let r = &motion.report;
    println!(
        "Fig. 5 switch: max per-frame joint rotation {:.2}°, mean line distance {:.2} %",
        r.max_rotation_step.to_degrees(),
        100.0 * r.line_distance_mean
    );
    assert!(r.max_rotation_step.to_degrees() < 5.0, "{r:?}");
    assert!(r.line_distance_mean < 0.06, "{r:?}");
}

#[test]
fn contact_keeps_the_foot_planted() {
    let skeleton = robot();
    let character = Character::rest(&skeleton).unwrap();
    let line = line(&[(0, 0.0, 0.0), (12, 0.2, 0.2), (24, 0.1, 0.3)]);
    let contacts = ContactKey::parse_all("FootL@0..24").unwrap();
    let motion = animate(
        &character,
        &line,
        &sets(&[("right-leg-spine-head", 0)]),
        &contacts,
        &[],
        &AnimateOptions::default(),
    )
    .unwrap();
    let r = &motion.report;
    println!(
        "contact: max foot error {:.3} % of body height ({:.4} units), line distance {:.2} %",
        100.0 * r.contact_error_max,
        r.contact_error_max * r.height,
        100.0 * r.line_distance_mean
    );
    assert!(r.spatial.is_some());
    assert!(r.contact_error_max < 0.01, "{r:?}");
    assert!(bone_length_drift(&skeleton, &character, &motion) < 1e-9);
}

#[test]
fn twist_turns_the_torso_about_its_axis() {
    let skeleton = robot();
    let character = Character::rest(&skeleton).unwrap();
    let line = line(&[(0, 0.1, 0.0), (12, 0.1, 0.0)]);
    let s = sets(&[("right-leg-spine-head", 0)]);
    let opts = AnimateOptions::default();
    let planar = animate(&character, &line, &s, &[], &[], &opts).unwrap();
    let twist: TwistKey = "Torso_1@0:40".parse().unwrap();
    let twisted = animate(&character, &line, &s, &[], &[twist], &opts).unwrap();
    let j = skeleton.find("Torso_1").unwrap();
    let n = planar.joints;
    let f = 6;
    let q = twisted.rotations[f * n + j] * planar.rotations[f * n + j].inverse();
    let (axis, angle) = q.to_axis_angle();
    let bone = (planar.positions_at(f)[skeleton.find("Neck").unwrap()] - planar.positions_at(f)[j])
        .normalize();
    println!(
        "twist: torso turned {:.1}° (target 40°), axis·bone = {:.3}, line distance {:.2} %",
        angle.to_degrees(),
        axis.dot(bone).abs(),
        100.0 * twisted.report.line_distance_mean
    );
    assert!((angle.to_degrees() - 40.0).abs() < 8.0);
    assert!(axis.dot(bone).abs() > 0.9);
}

#[test]
fn runs_on_a_bvh_skeleton() {
    let skeleton = bvh();
    let character = Character::rest(&skeleton).unwrap();
    let line = line(&[(0, 0.15, 0.0), (10, -0.1, 0.1)]);
    let motion = animate(
        &character,
        &line,
        &sets(&[("left-leg-spine-head", 0)]),
        &[],
        &[],
        &AnimateOptions::default(),
    )
    .unwrap();
    let chain = character
        .bone_chain(&"left-leg-spine-head".parse().unwrap())
        .unwrap();
    let names: Vec<&str> = chain
        .iter()
        .map(|&j| character.joint_names()[j].as_str())
        .collect();
    println!(
        "BVH 02_02 chain {names:?}: mean 2D distance {:.2} % (max {:.2} %)",
        100.0 * motion.report.line_distance_mean,
        100.0 * motion.report.line_distance_worst.distance
    );
    assert_eq!(names.first(), Some(&"lFoot"));
    assert_eq!(names.last(), Some(&"head"));
    assert!(motion.report.line_distance_mean < 0.04);
    assert!(bone_length_drift(&skeleton, &character, &motion) < 1e-9);
}
