use super::*;
use anim::{sample, Joint, SampleOptions, Skeleton};
use glam::{EulerRot, Quat};

const ARM: &str = "HIERARCHY
ROOT hip
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT arm
  {
    OFFSET 0 1 0
    CHANNELS 3 Xrotation Yrotation Zrotation
    End Site
    {
      OFFSET 0 2 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.5
0 0 0 0 0 0 0 0 0
1 2 3 90 0 0 0 0 -90
";

/// World positions of every node in every frame, sampled at the file's rate.
fn world_positions(scene: &Scene, fps: f32) -> Vec<Vec3> {
    let s = sample(
        scene,
        &SampleOptions {
            fps,
            ..SampleOptions::default()
        },
    )
    .unwrap();
    s.node_world.iter().map(|m| m.w_axis.truncate()).collect()
}

#[test]
fn glam_zxy_is_intrinsic_z_then_x_then_y() {
    let (a, b, c) = (0.3, -0.7, 1.1);
    let q = Quat::from_euler(EulerRot::ZXY, a, b, c);
    let p = Quat::from_rotation_z(a) * Quat::from_rotation_x(b) * Quat::from_rotation_y(c);
    assert!(q.abs_diff_eq(p, 1e-6));
}

#[test]
fn arm_nodes_end_site_and_pose() {
    let scene = read(ARM.as_bytes()).unwrap();
    let names: Vec<&str> = scene.nodes.iter().map(|n| n.name.as_str()).collect();
    assert_eq!(names, ["hip", "arm", "arm_end"]);
    // The End Site is a node (for the chain's tip) but not a joint.
    assert_eq!(scene.skins[0].joints.len(), 2);
    assert_eq!(scene.clips[0].channels.len(), 3);
    assert_eq!(scene.clips[0].key_rate(), Some(2.0));
    let (skeleton, _) = scene.skeleton();
    assert_eq!(skeleton.len(), 2);
    let w = world_positions(&scene, 2.0);
    assert_eq!(w.len(), 6);
    assert!(w[2].abs_diff_eq(Vec3::new(0.0, 3.0, 0.0), 1e-6));
    // Frame 1: hip at (1,2,3) turned 90° about Z, so the arm's +Y offset points along -X;
    // the arm's own -90° about Z cancels the turn, so its end site lies along +Y again.
    assert!(w[3].abs_diff_eq(Vec3::new(1.0, 2.0, 3.0), 1e-5), "{}", w[3]);
    assert!(w[4].abs_diff_eq(Vec3::new(0.0, 2.0, 3.0), 1e-5), "{}", w[4]);
    assert!(w[5].abs_diff_eq(Vec3::new(0.0, 4.0, 3.0), 1e-5), "{}", w[5]);
}

#[test]
fn rotation_channels_apply_in_listed_order() {
    let text = ARM.replace("0 0 -90", "30 40 50");
    let scene = read(text.as_bytes()).unwrap();
    let rot = scene.clips[0]
        .channels
        .iter()
        .find(|c| c.node == 1)
        .unwrap();
    assert_eq!(rot.property, Property::Rotation);
    let q = Quat::from_slice(&rot.values[4..8]);
    let r = |d: f32| d.to_radians();
    let expect = Quat::from_rotation_x(r(30.0))
        * Quat::from_rotation_y(r(40.0))
        * Quat::from_rotation_z(r(50.0));
    assert!(q.abs_diff_eq(expect, 1e-6) || q.abs_diff_eq(-expect, 1e-6));
}

#[test]
fn bad_files_name_the_line() {
    let cases: Vec<(String, &str)> = vec![
        (ARM.replacen("  }\n}", "  }\n", 1), "line 16: MOTION before"),
        (
            ARM.replace("CHANNELS 3 Xrotation", "CHANNELS 4 Xrotation"),
            "line 9: CHANNELS 4",
        ),
        (
            ARM.replace("0 0 0 0 0 0 0 0 0\n", "0 0 0 0 0 0 0 0\n"),
            "need 18",
        ),
        (ARM.replace("1 2 3 90", "1 2 3 nan"), "line 20"),
        (ARM.replace("1 2 3 90", "1 2 x 90"), "not a number"),
        (
            ARM.replace("Frame Time: 0.5", "Frame Time: 0"),
            "frame time",
        ),
        (ARM.replace("OFFSET 0 1 0\n", ""), "no OFFSET"),
        (ARM.replace("ROOT hip", "JOINT hip"), "JOINT outside"),
        (
            ARM.replace("Frames: 2", "Frames: 99999999999999999999"),
            "bad frame count",
        ),
        (ARM.replace("Frames: 2", "Frames: 9999999999999"), "need"),
        (
            ARM.replace("-90\n", "-90 7\n"),
            "line 20: MOTION has more values",
        ),
        (
            "HIERARCHY\nMOTION\nFrames: 0\nFrame Time: 1\n".to_string(),
            "no ROOT",
        ),
        (String::new(), "HIERARCHY"),
    ];
    for (text, needle) in cases {
        let e = read(text.as_bytes()).unwrap_err().to_string();
        assert!(e.contains(needle), "expected '{needle}' in: {e}");
        assert!(e.contains("invalid BVH"), "{e}");
    }
}

#[test]
fn zero_frames_give_rest_pose_without_clip() {
    let text = ARM.split("Frames:").next().unwrap().to_string() + "Frames: 0\nFrame Time: 0.1\n";
    let scene = read(text.as_bytes()).unwrap();
    assert!(scene.clips.is_empty());
    let w = world_positions(&scene, 24.0);
    assert_eq!(w.len(), 3);
    assert_eq!(w[2], Vec3::new(0.0, 3.0, 0.0));
}

#[test]
fn arm_round_trip_through_writer() {
    let scene = read(ARM.as_bytes()).unwrap();
    let s = sample(
        &scene,
        &SampleOptions {
            fps: 2.0,
            ..SampleOptions::default()
        },
    )
    .unwrap();
    let text = write(&s.skeleton, s.skeletal.as_ref().unwrap()).unwrap();
    assert!(text.contains("End Site"), "{text}");
    assert!(!text.contains("arm_end"), "{text}");
    let again = read(text.as_bytes()).unwrap();
    assert_eq!(again.nodes.len(), 3);
    // Joints keep their world positions; the End Site is rebuilt from the skeleton (its
    // original offset is not a joint and is not kept).
    let (a, b) = (world_positions(&scene, 2.0), world_positions(&again, 2.0));
    for (k, (p, q)) in a.iter().zip(&b).enumerate() {
        if k % 3 != 2 {
            assert!(p.abs_diff_eq(*q, 1e-5), "{p} vs {q}");
        }
    }
}

#[test]
fn write_local_bakes_scale_and_bind_rotation() {
    // A scaled root with a rotated bind pose: offsets must come out in world units.
    let joint = |name: &str, parent, t: Vec3, r: Quat, s: f32| Joint {
        name: name.into(),
        parent,
        bind_local: Transform {
            translation: t,
            rotation: r,
            scale: Vec3::splat(s),
        },
    };
    let skeleton = Skeleton {
        joints: vec![
            joint("root", None, Vec3::ZERO, Quat::from_rotation_x(0.5), 0.01),
            joint(
                "spine",
                Some(0),
                Vec3::new(0.0, 100.0, 0.0),
                Quat::from_rotation_z(0.3),
                1.0,
            ),
            joint(
                "head",
                Some(1),
                Vec3::new(0.0, 50.0, 0.0),
                Quat::IDENTITY,
                1.0,
            ),
        ],
    };
    let frames = 3;
    let rots: Vec<Quat> = (0..frames)
        .flat_map(|f| {
            let a = f as f32 * 0.4;
            [
                Quat::from_rotation_x(0.5),
                Quat::from_rotation_z(0.3 + a),
                Quat::from_rotation_y(a),
            ]
        })
        .collect();
    let roots: Vec<Vec3> = (0..frames).map(|f| Vec3::new(f as f32, 0.0, 0.0)).collect();
    let text = write_local(&skeleton, &roots, &rots, 30.0).unwrap();
    assert!(text.contains("Frame Time: 0.0333"), "{text}");
    let scene = read(text.as_bytes()).unwrap();
    let got = world_positions(&scene, 30.0);
    // Expected world positions from the skeleton itself.
    let n = skeleton.len();
    let per_frame = got.len() / frames;
    for f in 0..frames {
        let locals: Vec<Mat4> = (0..n)
            .map(|k| {
                let j = &skeleton.joints[k];
                let t = if k == 0 {
                    roots[f]
                } else {
                    j.bind_local.translation
                };
                Mat4::from_scale_rotation_translation(j.bind_local.scale, rots[f * n + k], t)
            })
            .collect();
        let world = skeleton.world_from_local(&locals);
        for k in 0..n {
            let want = world[k].w_axis.truncate();
            let have = got[f * per_frame + k];
            assert!(
                want.abs_diff_eq(have, 1e-5),
                "frame {f} joint {k}: {want} vs {have}"
            );
        }
    }
    assert!(write_local(&skeleton, &roots[..2], &rots, 30.0).is_err());
    assert!(write_local(&skeleton, &roots, &rots, 0.0).is_err());
}

#[test]
fn zero_scaled_joint_writes_finite_angles() {
    let joint = |name: &str, parent, y: f32, s: f32| Joint {
        name: name.into(),
        parent,
        bind_local: Transform {
            translation: Vec3::new(0.0, y, 0.0),
            rotation: Quat::IDENTITY,
            scale: Vec3::splat(s),
        },
    };
    let skeleton = Skeleton {
        joints: vec![
            joint("root", None, 0.0, 1.0),
            joint("hidden", Some(0), 1.0, 0.0),
        ],
    };
    let text = write_local(&skeleton, &[Vec3::ZERO], &[Quat::IDENTITY; 2], 24.0).unwrap();
    assert!(!text.to_lowercase().contains("nan"), "{text}");
    let scene = read(text.as_bytes()).unwrap();
    let w = world_positions(&scene, 24.0);
    assert!(w[1].abs_diff_eq(Vec3::Y, 1e-6), "{}", w[1]);
}
