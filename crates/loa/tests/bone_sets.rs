//! Bone sets on a character handed over as BVH, the way the Blender extension hands over its
//! armature (joint heads in world space, no rest rotation, an `End Site` on each leaf's bone
//! axis): the same chains, attachments and motion as the skinned glTF it came from.

mod common;

use anim::{Joint, SkeletalAnimation, Skeleton, Transform};
use common::{character, example};
use glam::Mat4;
use loa::animate::{AnimateOptions, Character, InitialPose};
use loa::LineOptions;

const ROBOT: &str = "characters/RobotExpressive.glb";
const POSE: &str = "Dance@1";

/// RobotExpressive at `POSE` written as BVH (joint world positions, no rest rotation, each
/// leaf's `End Site` out along its world +Y at a length of its own: only the direction is
/// the file's) and read back.
fn robot_as_bvh() -> Character {
    let (scene, _) = character(ROBOT, POSE);
    let (skeleton, _) = scene.skeleton();
    let sampled = anim::sample(
        &scene,
        &anim::SampleOptions {
            fps: 24.0,
            clip: Some(scene.find_clip("Dance").unwrap()),
            meshes: Vec::new(),
        },
    )
    .unwrap();
    let world = sampled.skeletal.unwrap().frame(1).to_vec();
    let head = |k: usize| world[k].w_axis.truncate();
    let mut joints = Vec::new();
    let mut heads = Vec::new();
    for (k, j) in skeleton.joints.iter().enumerate() {
        let at = j.parent.map_or(head(k), |p| head(k) - head(p));
        joints.push(Joint {
            name: j.name.clone(),
            parent: j.parent,
            bind_local: Transform::from_translation(at),
        });
        heads.push(head(k));
    }
    for (k, j) in skeleton.joints.iter().enumerate() {
        if skeleton.joints.iter().any(|c| c.parent == Some(k)) {
            continue;
        }
        let axis = world[k].y_axis.truncate().normalize() * 0.01;
        joints.push(Joint {
            name: format!("{}_end", j.name),
            parent: Some(k),
            bind_local: Transform::from_translation(axis),
        });
        heads.push(head(k) + axis);
    }
    let n = joints.len();
    let skeleton = Skeleton { joints };
    let world: Vec<Mat4> = heads.iter().map(|h| Mat4::from_translation(*h)).collect();
    let motion = SkeletalAnimation::new(24.0, n, world).unwrap();
    let text = tkio::bvh::write(&skeleton, &motion).unwrap();
    let scene = tkio::bvh::read(text.as_bytes()).unwrap();
    // The file's frame 0 is the pose (its rest pose has the root at the origin).
    let pose: InitialPose = "motion@0".parse().unwrap();
    Character::from_scene(&scene, &pose, 24.0).unwrap()
}

fn names(c: &Character, joints: &[usize]) -> Vec<String> {
    joints.iter().map(|&k| c.joint_names()[k].clone()).collect()
}

#[test]
fn robot_as_bvh_keeps_its_ik_feet_on_its_shins() {
    let (_, gltf) = character(ROBOT, POSE);
    let bvh = robot_as_bvh();
    let attached = |c: &Character| {
        let mut v: Vec<(String, String)> = c
            .attachments()
            .into_iter()
            .map(|(j, leaf)| (c.joint_names()[j].clone(), c.joint_names()[leaf].clone()))
            .collect();
        v.sort();
        v
    };
    assert_eq!(
        attached(&gltf),
        [("FootL", "LowerLegL"), ("FootR", "LowerLegR")].map(|(a, b)| (a.into(), b.into()))
    );
    assert_eq!(attached(&bvh), attached(&gltf));
    for set in [
        "FootL,Head",
        "FootR,Head",
        "left-leg-spine-head",
        "right-leg-spine-head",
    ] {
        let set = set.parse().unwrap();
        let (a, b) = (
            gltf.bone_chain(&set).unwrap(),
            bvh.bone_chain(&set).unwrap(),
        );
        assert_eq!(names(&bvh, &b), names(&gltf, &a), "{set}");
    }
    let left = bvh.bone_chain(&"FootL,Head".parse().unwrap()).unwrap();
    let right = bvh.bone_chain(&"FootR,Head".parse().unwrap()).unwrap();
    assert_eq!(names(&bvh, &left)[..3], ["FootL", "LowerLegL", "UpperLegL"]);
    assert_eq!(
        names(&bvh, &right)[..3],
        ["FootR", "LowerLegR", "UpperLegR"]
    );
}

#[test]
fn robot_as_bvh_moves_as_the_gltf_and_its_feet_sets_differ() {
    let (_, gltf) = character(ROBOT, POSE);
    let bvh = robot_as_bvh();
    let line = loa::line(&example("jump.json"), &LineOptions::default()).unwrap();
    let height = gltf.height();
    let mut by_set = Vec::new();
    for set in ["FootL,Head", "FootR,Head"] {
        let options: AnimateOptions = serde_json::from_str(&format!(
            r#"{{"bone_sets": [{{"frame": 0, "set": "{set}"}}]}}"#
        ))
        .unwrap();
        let a = loa::animate(&gltf, &line, &options).unwrap();
        let b = loa::animate(&bvh, &line, &options).unwrap();
        let gap = a
            .positions
            .iter()
            .zip(&b.positions)
            .map(|(p, q)| (*p - *q).length())
            .fold(0.0, f64::max);
        println!(
            "{set}: BVH vs glTF joints {:.4} % of the height",
            100.0 * gap / height
        );
        assert!(gap <= 0.01 * height, "{set}: {gap} of {height}");
        by_set.push(b.positions);
    }
    let apart = by_set[0]
        .iter()
        .zip(&by_set[1])
        .map(|(p, q)| (*p - *q).length())
        .fold(0.0, f64::max);
    println!(
        "FootL,Head vs FootR,Head: {:.2} % of the height",
        100.0 * apart / height
    );
    assert!(apart > 0.05 * height, "{apart} of {height}");
}

/// The chain's first and last joint names of `set` on `c`.
fn ends(c: &Character, set: &str) -> (String, String) {
    let chain = c.bone_chain(&set.parse().unwrap()).unwrap();
    let n = names(c, &chain);
    (n[0].clone(), n[n.len() - 1].clone())
}

#[test]
fn hierarchy_presets_end_at_the_head_on_every_skeleton() {
    for (asset, pose, foot, root, head) in [
        (ROBOT, "rest", "FootR", "Bone", "Head"),
        (ROBOT, POSE, "FootR", "Bone", "Head"),
        (
            "characters/CesiumMan.glb",
            "rest",
            "leg_joint_L_5",
            "Skeleton_torso_joint_1",
            "Skeleton_neck_joint_2",
        ),
        ("mocap/02_02.bvh", "motion@0", "rFoot", "hip", "head"),
        (
            "mocap/12_03.bvh",
            "motion@0",
            "RightToeBase",
            "Hips",
            "Head",
        ),
    ] {
        let (_, c) = character(asset, pose);
        let foot_head = ends(&c, "foot-head");
        let spine_head = ends(&c, "spine-head");
        println!("{asset}: foot-head {foot_head:?}, spine-head {spine_head:?}");
        assert_eq!(foot_head, (foot.to_string(), head.to_string()), "{asset}");
        assert_eq!(spine_head, (root.to_string(), head.to_string()), "{asset}");
    }
}

#[test]
fn hierarchy_head_stays_the_head_with_raised_arms() {
    // RobotExpressive's rest pose with both upper arms swung up past the head.
    let (scene, _) = character(ROBOT, "rest");
    let (skeleton, _) = scene.skeleton();
    let mut pose: Vec<Transform> = skeleton.joints.iter().map(|j| j.bind_local).collect();
    for (k, j) in skeleton.joints.iter().enumerate() {
        if j.name.starts_with("UpperArm") {
            pose[k].rotation *= glam::Quat::from_rotation_x(170f32.to_radians());
        }
    }
    let c = Character::new(&skeleton, &pose).unwrap();
    let at = c.initial_positions();
    let index = |n: &str| c.joint_names().iter().position(|x| x == n).unwrap();
    let top = (0..at.len())
        .max_by(|&a, &b| at[a].y.total_cmp(&at[b].y))
        .unwrap();
    println!("highest joint with raised arms: {}", c.joint_names()[top]);
    assert!(
        at[top].y > at[index("Head")].y && c.joint_names()[top] != "Head",
        "the arms are not raised above the head"
    );
    assert_eq!(ends(&c, "foot-head"), ("FootR".into(), "Head".into()));
    assert_eq!(ends(&c, "spine-head"), ("Bone".into(), "Head".into()));
    // The raised-arm preset runs from the foot through the spine into that arm.
    let raised = names(
        &c,
        &c.bone_chain(&"right-leg-spine-arm".parse().unwrap())
            .unwrap(),
    );
    assert_eq!(raised[0], "FootR");
    assert!(raised.iter().any(|n| n == "Torso_1"), "{raised:?}");
    assert_eq!(raised[raised.len() - 1], "LowerArmR");
}
