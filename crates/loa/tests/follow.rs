//! Issue 20 acceptance, the character: how closely RobotExpressive and a CMU BVH skeleton
//! follow the line (screen scale fitted to all keystrokes, pelvis free in the planar stage,
//! iterations to a tolerance), smooth contact release, and a perspective scene camera.

mod common;

use common::{character, example};
use loa::animate::{AnimateOptions, ContactKey, Motion};
use loa::{Keystrokes, LineOptions};

fn report(name: &str, m: &Motion) {
    let r = &m.report;
    println!(
        "{name}: line distance mean {:.2} % p95 {:.2} % worst {:.2} % ({} at frame {}), \
         max joint step {:.1}°, planar {} iterations, contact {:.3} %",
        100.0 * r.line_distance_mean,
        100.0 * r.line_distance_p95,
        100.0 * r.line_distance_worst.distance,
        r.line_distance_worst.joint,
        r.line_distance_worst.frame,
        r.max_rotation_step.to_degrees(),
        r.planar.iterations,
        100.0 * r.contact_error_max
    );
}

/// `keys`' keystroke `i` held from frame 0 to frame 24.
fn held(keys: &Keystrokes, i: usize) -> Keystrokes {
    let mut a = keys.keys()[i].clone();
    let mut b = a.clone();
    a.frame = 0;
    b.frame = 24;
    Keystrokes::new(vec![a, b], keys.fps()).unwrap()
}

fn options(json: &str) -> AnimateOptions {
    serde_json::from_str(json).unwrap()
}

#[test]
fn static_line_with_the_default_bone_set_is_within_3_percent() {
    let jump = example("jump.json");
    for (asset, pose) in [
        ("characters/RobotExpressive.glb", "rest"),
        ("mocap/02_02.bvh", "motion@0"),
    ] {
        let (_, character) = character(asset, pose);
        for i in [0, 2] {
            let line = loa::line(&held(&jump, i), &LineOptions::default()).unwrap();
            let motion = loa::animate(&character, &line, &AnimateOptions::default()).unwrap();
            report(&format!("{asset} static jump stroke {i}"), &motion);
            assert!(
                motion.report.line_distance_mean <= 0.03,
                "{:?}",
                motion.report
            );
        }
    }
}

#[test]
fn robot_follows_jump_within_5_percent_mean_8_p95() {
    let (_, character) = character("characters/RobotExpressive.glb", "rest");
    let line = loa::line(&example("jump.json"), &LineOptions::default()).unwrap();
    for json in [
        r#"{}"#,
        r#"{"bone_sets": [{"frame": 0, "set": "right-leg-spine-head"},
                          {"frame": 22, "set": "left-leg-spine-head"}]}"#,
    ] {
        let motion = loa::animate(&character, &line, &options(json)).unwrap();
        report(&format!("robot jump {json}"), &motion);
        assert!(
            motion.report.line_distance_mean <= 0.05,
            "{:?}",
            motion.report
        );
        assert!(
            motion.report.line_distance_p95 <= 0.08,
            "{:?}",
            motion.report
        );
    }
}

/// Largest step (degrees) of any joint's rotation relative to its skeleton parent between
/// consecutive frames of `frames`.
fn largest_joint_step(
    m: &Motion,
    parents: &[Option<usize>],
    frames: std::ops::Range<usize>,
) -> f64 {
    let n = m.joints;
    let world = |f: usize, j: usize| m.rotations[f * n + j];
    let mut worst: f64 = 0.0;
    for f in frames {
        for (j, parent) in parents.iter().enumerate() {
            let (a, b) = match parent {
                Some(p) => (
                    world(f, *p).inverse() * world(f, j),
                    world(f + 1, *p).inverse() * world(f + 1, j),
                ),
                None => (world(f, j), world(f + 1, j)),
            };
            worst = worst.max(a.angle_between(b).to_degrees());
        }
    }
    worst
}

#[test]
fn contact_release_turns_joints_at_most_15_degrees_per_frame() {
    let line = loa::line(&example("jump.json"), &LineOptions::default()).unwrap();
    // The robot's planted foot, which the line pulls out of reach by frame 10, and a CMU
    // skeleton's hand (a case the release was not tuned on).
    for (asset, pose, contact) in [
        ("characters/RobotExpressive.glb", "rest", "FootL@0..10"),
        ("mocap/12_03.bvh", "motion@0", "RightHand@0..10"),
    ] {
        let (_, character) = character(asset, pose);
        let options = AnimateOptions {
            contacts: ContactKey::parse_all(contact).unwrap(),
            ..Default::default()
        };
        let motion = loa::animate(&character, &line, &options).unwrap();
        report(&format!("{asset} jump {contact}"), &motion);
        // Joint rotation steps from frame 4 to 18 (the release is at frame 10), and over the
        // whole clip.
        let around = largest_joint_step(&motion, character.parents(), 4..18);
        let all = largest_joint_step(&motion, character.parents(), 0..motion.frames() - 1);
        println!("{asset} {contact}: largest joint rotation step {around:.1}° around frame 10, {all:.1}° in the clip");
        assert!(around <= 15.0 && all <= 15.0, "{around} {all}");
        assert!(
            motion.report.contact_error_max < 0.01,
            "{:?}",
            motion.report
        );
    }
}
