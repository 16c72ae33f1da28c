//! `toonkit loa animate --bones`: the presets found from the hierarchy (`foot-head`,
//! `spine-head`, for any joint names) and the raised-arm presets, from the command line.

mod common;

use common::{data, json};

fn jump() -> String {
    let p = format!(
        "{}/../../examples/loa/jump.json",
        env!("CARGO_MANIFEST_DIR")
    );
    assert!(std::path::Path::new(&p).exists(), "missing example {p}");
    p
}

/// The joints `loa animate` measured (its bone set's chain) with `--bones SET@0`.
fn measured(character: &str, pose: &str, set: &str) -> Vec<String> {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.bvh");
    let report = json(&[
        "loa",
        "animate",
        data(character).to_str().unwrap(),
        &jump(),
        "-o",
        out.to_str().unwrap(),
        "--pose",
        pose,
        "--bones",
        &format!("{set}@0"),
    ]);
    let joints: Vec<String> = report["line_distance_joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_str().unwrap().to_string())
        .collect();
    println!("{character} {set}: {}", joints.join(", "));
    joints
}

#[test]
fn hierarchy_presets_reach_the_head_for_any_joint_names() {
    for (character, pose, foot, head) in [
        (
            "characters/RobotExpressive.glb",
            "Dance@1",
            "FootR",
            "Head (tip)",
        ),
        (
            "characters/CesiumMan.glb",
            "rest",
            "leg_joint_L_5",
            "Skeleton_neck_joint_2 (tip)",
        ),
        ("mocap/12_03.bvh", "motion@0", "RightToeBase", "Head (tip)"),
    ] {
        let chain = measured(character, pose, "foot-head");
        assert!(chain.iter().any(|j| j == foot), "{character}: {chain:?}");
        assert!(chain.iter().any(|j| j == head), "{character}: {chain:?}");
        let spine = measured(character, pose, "spine-head");
        assert!(spine.iter().any(|j| j == head), "{character}: {spine:?}");
        assert!(!spine.iter().any(|j| j == foot), "{character}: {spine:?}");
    }
}

#[test]
fn raised_arm_preset_runs_from_the_foot_to_the_hand() {
    let chain = measured(
        "characters/RobotExpressive.glb",
        "rest",
        "right-leg-spine-arm",
    );
    for joint in ["FootR", "LowerLegR", "Torso_1", "UpperArmR", "LowerArmR"] {
        assert!(chain.iter().any(|j| j == joint), "{joint}: {chain:?}");
    }
    assert!(!chain.iter().any(|j| j.starts_with("Head")), "{chain:?}");
}
