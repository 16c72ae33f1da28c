//! Scene-level behaviour: still frames, pruning, whole body, cameras, several objects,
//! surface points, errors.

mod common;

use anim::{Camera, MeshAnimation, MeshObject, Projection, SampledScene, VertexWeights};
use common::*;
use glam::{Mat4, Quat, Vec3};
use smear::{
    mesh_offsets, scene_offsets, CameraSelect, MotionOffsets, OffsetMode, OffsetOptions,
    OffsetSolver, SmearError, SurfacePoint,
};

fn opts(smooth: usize) -> OffsetOptions {
    OffsetOptions {
        smooth,
        ..OffsetOptions::default()
    }
}

fn max_diff(a: &MotionOffsets, b: &MotionOffsets) -> f32 {
    assert_eq!(
        (a.frame_count(), a.vertex_count()),
        (b.frame_count(), b.vertex_count())
    );
    a.values()
        .iter()
        .zip(b.values())
        .fold(0.0f32, |m, (x, y)| m.max((x - y).abs()))
}

/// A scene of unskinned objects.
fn rigid_scene(objects: Vec<MeshAnimation>, cameras: Vec<Camera>) -> SampledScene {
    let frames = objects[0].frame_count();
    SampledScene {
        fps: 24.0,
        start_time: 0.0,
        frame_count: frames,
        objects: objects
            .into_iter()
            .enumerate()
            .map(|(i, a)| MeshObject::new(i, a.mesh.name.clone(), a))
            .collect(),
        skeleton: Default::default(),
        joint_nodes: Vec::new(),
        skeletal: None,
        bones: Vec::new(),
        cameras,
        node_world: Vec::new(),
    }
}

/// A three-bone arm (arm, forearm, hand along +Y) waving about Z.
fn arm_scene(frames: usize, weights: impl Fn(&anim::Mesh) -> VertexWeights) -> SampledScene {
    let ys: Vec<f32> = (0..=30).map(|i| i as f32 * 0.1).collect();
    let mesh = tube(&ys, 16, |y| 0.15 + 0.05 * (3.0 * y).sin());
    let w = weights(&mesh);
    let skel = chain(3, 1.0, Quat::IDENTITY);
    let l0 = bind_locals(&skel);
    skinned_scene(mesh, skel, w, frames, move |f| {
        let t = f as f32;
        let mut l = l0.clone();
        l[0] =
            Mat4::from_translation(Vec3::new(0.05 * t, 0.0, 0.0)) * Mat4::from_rotation_z(0.1 * t);
        l[1] = l0[1] * Mat4::from_rotation_z(0.3 * (0.7 * t).sin());
        l[2] =
            l0[2] * Mat4::from_rotation_z(-0.5 * (0.9 * t).cos()) * Mat4::from_rotation_x(0.3 * t);
        l
    })
}

#[test]
fn still_frames_are_zero_and_finite() {
    // A ball resting for three frames, then moving.
    let anim = translating(sphere(1.0), 6, |f| Vec3::X * f.saturating_sub(3) as f32);
    let d = mesh_offsets(&anim, &opts(0)).unwrap();
    for f in 0..3 {
        assert!(d.frame(f).iter().all(|&x| x == 0.0), "frame {f} is still");
    }
    assert!(d.values().iter().all(|x| x.is_finite()));
    assert!(d.frame(4).iter().any(|&x| x > 0.99));
    // One-frame clip.
    let one = mesh_offsets(&MeshAnimation::still(sphere(1.0)), &opts(2)).unwrap();
    assert_eq!(one.frame_count(), 1);
    assert!(one.values().iter().all(|&x| x == 0.0));
    // A skinned arm that never moves.
    let skel_still = {
        let ys: Vec<f32> = (0..=10).map(|i| i as f32 * 0.2).collect();
        let mesh = tube(&ys, 8, |_| 0.2);
        let w = chain_weights(&mesh, 2, 1.0, 0.2);
        let skel = chain(2, 1.0, Quat::IDENTITY);
        let l0 = bind_locals(&skel);
        skinned_scene(mesh, skel, w, 4, move |_| l0.clone())
    };
    let d = &scene_offsets(&skel_still, &opts(2)).unwrap()[0];
    assert!(d.values().iter().all(|&x| x == 0.0));
}

#[test]
fn zero_length_bones_are_skipped() {
    // Joint 2 sits on joint 1: bone 1 has zero length and so has the leaf bone 2.
    let ys: Vec<f32> = (0..=10).map(|i| i as f32 * 0.1).collect();
    let mesh = tube(&ys, 8, |_| 0.2);
    let w = VertexWeights::from_influences(mesh.positions.iter().map(|p| {
        if p.y < 0.5 {
            vec![(0, 1.0)]
        } else if p.y < 0.8 {
            vec![(0, 0.5), (1, 0.5)]
        } else {
            vec![(2, 1.0)]
        }
    }));
    let mut skel = chain(3, 1.0, Quat::IDENTITY);
    skel.joints[2].bind_local = anim::Transform::IDENTITY;
    let l0 = bind_locals(&skel);
    let scene = skinned_scene(mesh, skel, w, 5, move |f| {
        let mut l = l0.clone();
        l[0] = Mat4::from_translation(Vec3::X * 0.1 * f as f32);
        l
    });
    let d = &scene_offsets(&scene, &opts(0)).unwrap()[0];
    let pos = scene.objects[0].animation.frame(2);
    for (p, &x) in pos.iter().zip(d.frame(2)) {
        assert!(x.is_finite());
        if p.y >= 0.8 {
            assert_eq!(x, 0.0, "only zero-length bones drive {p}");
        }
    }
    // Half-weighted vertices: the zero-length bone is skipped and bone 0 renormalized, so they
    // get bone 0's value in full (|δ| reaches 1 on the ring around the blend).
    assert!(d.max_abs() > 0.9);
}

#[test]
fn fig8d_pruned_hand_follows_the_forearm() {
    let hard = |m: &anim::Mesh| chain_weights(m, 3, 1.0, 0.15);
    let full = arm_scene(8, hard);
    let pruned = scene_offsets(
        &full,
        &OffsetOptions {
            prune: vec!["bone2".into()],
            ..opts(2)
        },
    )
    .unwrap();
    // Same positions with the hand's weights handed to the forearm by hand.
    let mut handed = full.clone();
    let skin = handed.objects[0].skin.as_mut().unwrap();
    let w = skin.weights.clone();
    skin.weights = VertexWeights::from_influences((0..w.vertex_count()).map(|v| {
        let (s, x) = w.influences(v);
        s.iter()
            .zip(x)
            .map(|(&s, &x)| (s.min(1), x))
            .collect::<Vec<_>>()
    }));
    let reference = scene_offsets(&handed, &opts(2)).unwrap();
    assert!(max_diff(&pruned[0], &reference[0]) < 1e-6);
    let unpruned = scene_offsets(&full, &opts(2)).unwrap();
    assert!(
        max_diff(&pruned[0], &unpruned[0]) > 0.05,
        "pruning changes the hand"
    );
}

#[test]
fn fig14_whole_body_is_one_simple_object() {
    let mut scene = arm_scene(6, |m| chain_weights(m, 3, 1.0, 0.15));
    // A rigid ball carried by the hand.
    let hand: Vec<Vec3> = (0..6).map(|f| scene.bones_at(f)[2].tip).collect();
    let ball = translating(sphere(0.3), 6, |f| hand[f]);
    scene.objects.push(MeshObject {
        parent_joint: Some(2),
        ..MeshObject::new(9, "ball", ball.clone())
    });

    let whole = OffsetSolver::new(
        &scene,
        &OffsetOptions {
            whole_body: true,
            ..opts(2)
        },
    )
    .unwrap();
    assert_eq!(whole.mode(0), Some(OffsetMode::WholeBody));
    assert_eq!(whole.mode(1), Some(OffsetMode::WholeBody));
    let merged = scene.merged("all").unwrap();
    let expected = mesh_offsets(&merged, &opts(2)).unwrap();
    let got = MotionOffsets::concat(&whole.all()).unwrap();
    assert!(max_diff(&got, &expected) < 1e-6);

    // Outside whole-body mode the prop is a simple object of its own.
    let split = OffsetSolver::new(&scene, &opts(2)).unwrap();
    assert_eq!(split.mode(0), Some(OffsetMode::Articulated));
    assert_eq!(split.mode(1), Some(OffsetMode::Simple));
    let own = mesh_offsets(&ball, &opts(2)).unwrap();
    assert!(max_diff(&split.vertex_offsets(1).unwrap(), &own) < 1e-6);
    let all = split.all();
    assert!(all[0]
        .values()
        .iter()
        .all(|x| x.is_finite() && x.abs() <= 1.5));
}

#[test]
fn several_objects_get_their_own_offsets() {
    let a = translating(sphere(1.0), 5, |f| Vec3::X * f as f32);
    let b = translating(sphere(0.5), 5, |f| {
        Vec3::new(5.0, 0.0, 0.0) - Vec3::Y * f as f32
    });
    let scene = rigid_scene(vec![a.clone(), b.clone()], Vec::new());
    let d = scene_offsets(&scene, &opts(2)).unwrap();
    let f = 2;
    // Each object's leading extreme is along its own motion.
    let lead = |anim: &MeshAnimation, o: &MotionOffsets, dir: Vec3| {
        let pos = anim.frame(f);
        let v = (0..pos.len())
            .max_by(|&i, &j| pos[i].dot(dir).total_cmp(&pos[j].dot(dir)))
            .unwrap();
        o.frame(f)[v]
    };
    assert!((lead(&a, &d[0], Vec3::X) - 1.0).abs() < 1e-5);
    assert!((lead(&b, &d[1], -Vec3::Y) - 1.0).abs() < 1e-5);
    assert!((lead(&b, &d[1], Vec3::Y) + 1.0).abs() < 1e-5);
    let merged = MotionOffsets::concat(&d).unwrap();
    assert_eq!(merged.vertex_count(), scene.vertex_count());
}

fn camera(world: Vec<Mat4>) -> Camera {
    Camera {
        name: "cam".into(),
        projection: Projection::Perspective {
            yfov: 0.8,
            aspect: None,
            znear: 0.1,
            zfar: None,
        },
        world,
    }
}

#[test]
fn camera_space_offsets() {
    let ball = translating(sphere(1.0), 5, |f| Vec3::X * f as f32);
    let follow = camera(
        (0..5)
            .map(|f| Mat4::from_translation(Vec3::new(f as f32, 0.0, 8.0)))
            .collect(),
    );
    let faster = camera(
        (0..5)
            .map(|f| Mat4::from_translation(Vec3::new(2.0 * f as f32, 0.0, 8.0)))
            .collect(),
    );
    let scene = rigid_scene(vec![ball.clone()], vec![follow, faster]);
    let world = scene_offsets(&scene, &opts(2)).unwrap();
    let cam0 = OffsetOptions {
        camera: Some(CameraSelect::Name("cam".into())),
        ..opts(2)
    };
    let d = scene_offsets(&scene, &cam0).unwrap();
    assert!(
        d[0].values().iter().all(|&x| x == 0.0),
        "a following camera sees no motion"
    );
    let cam1 = OffsetOptions {
        camera: Some(CameraSelect::Index(1)),
        ..opts(2)
    };
    let d = scene_offsets(&scene, &cam1).unwrap();
    let negated: Vec<f32> = world[0].values().iter().map(|x| -x).collect();
    let negated = MotionOffsets::new(5, ball.vertex_count(), negated).unwrap();
    assert!(
        max_diff(&d[0], &negated) < 1e-5,
        "a faster camera reverses the motion"
    );

    // A still ball in front of a camera panning left appears to move right (+X).
    let still = translating(sphere(1.0), 5, |_| Vec3::new(0.0, 0.0, -5.0));
    let pan = camera(
        (0..5)
            .map(|f| Mat4::from_rotation_y(0.05 * f as f32))
            .collect(),
    );
    let scene = rigid_scene(vec![still.clone()], vec![pan]);
    let d = scene_offsets(
        &scene,
        &OffsetOptions {
            camera: Some(CameraSelect::Index(0)),
            ..opts(0)
        },
    )
    .unwrap();
    let f = 2;
    // Relative to the camera the ball circles around it: tangent = world +X at the ball.
    let right = Vec3::X;
    let pos = still.frame(f);
    let v = (0..pos.len())
        .max_by(|&i, &j| pos[i].dot(right).total_cmp(&pos[j].dot(right)))
        .unwrap();
    assert!(
        (d[0].frame(f)[v] - 1.0).abs() < 1e-3,
        "{}",
        d[0].frame(f)[v]
    );

    let bad = OffsetOptions {
        camera: Some(CameraSelect::Name("nope".into())),
        ..opts(2)
    };
    assert!(matches!(
        scene_offsets(&scene, &bad),
        Err(SmearError::UnknownCamera { .. })
    ));
}

#[test]
fn surface_points_for_motion_lines() {
    let scene = arm_scene(6, |m| chain_weights(m, 3, 1.0, 0.2));
    let solver = OffsetSolver::new(&scene, &opts(2)).unwrap();
    let verts = solver.vertex_offsets(0).unwrap();
    let tris = &scene.objects[0].animation.mesh.triangles;
    let corner: Vec<SurfacePoint> = (0..tris.len())
        .step_by(11)
        .map(|t| SurfacePoint {
            triangle: t as u32,
            barycentric: [1.0, 0.0, 0.0],
        })
        .collect();
    let at = solver.surface_offsets(0, &corner).unwrap();
    for f in 0..6 {
        for (k, p) in corner.iter().enumerate() {
            let v = tris[p.triangle as usize][0] as usize;
            assert!((at.frame(f)[k] - verts.frame(f)[v]).abs() < 1e-5);
        }
    }
    // Inside triangles the offsets stay close to the corners' and finite.
    let mid: Vec<SurfacePoint> = (0..tris.len())
        .map(|t| SurfacePoint {
            triangle: t as u32,
            barycentric: [1.0, 1.0, 1.0],
        })
        .collect();
    let m = solver.surface_offsets(0, &mid).unwrap();
    assert!(m.values().iter().all(|x| x.is_finite() && x.abs() < 1.5));

    // Simple objects are linear: an edge midpoint is the corners' average.
    let ball = translating(sphere(1.0), 4, |f| Vec3::new(f as f32, 0.3 * f as f32, 0.0));
    let s = OffsetSolver::from_animation(&ball, &opts(1), &[]).unwrap();
    let vo = s.vertex_offsets(0).unwrap();
    let t = ball.mesh.triangles[40];
    let e = s
        .surface_offsets(
            0,
            &[SurfacePoint {
                triangle: 40,
                barycentric: [0.5, 0.5, 0.0],
            }],
        )
        .unwrap();
    for f in 0..4 {
        let avg = 0.5 * (vo.frame(f)[t[0] as usize] + vo.frame(f)[t[1] as usize]);
        assert!((e.frame(f)[0] - avg).abs() < 1e-5);
    }
    let bad = s.surface_offsets(
        0,
        &[SurfacePoint {
            triangle: 1 << 30,
            barycentric: [1.0, 0.0, 0.0],
        }],
    );
    assert!(matches!(
        bad,
        Err(SmearError::InvalidSurfacePoint { index: 0, .. })
    ));
    let bad = s.surface_offsets(
        0,
        &[SurfacePoint {
            triangle: 0,
            barycentric: [f32::NAN, 0.0, 0.0],
        }],
    );
    assert!(matches!(bad, Err(SmearError::InvalidSurfacePoint { .. })));
    assert!(matches!(
        s.vertex_offsets(3),
        Err(SmearError::UnknownObject { index: 3, count: 1 })
    ));
}

#[test]
fn bad_prune_names_are_errors() {
    let scene = arm_scene(3, |m| chain_weights(m, 3, 1.0, 0.2));
    let e = scene_offsets(
        &scene,
        &OffsetOptions {
            prune: vec!["wrist".into()],
            ..opts(2)
        },
    );
    assert!(matches!(e, Err(SmearError::UnknownJoint { ref name, .. }) if name == "wrist"));
    let e = scene_offsets(
        &scene,
        &OffsetOptions {
            prune: vec!["bone0".into()],
            ..opts(2)
        },
    );
    assert!(matches!(e, Err(SmearError::PruneWithoutAncestor { .. })));
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

        /// Simple objects: |δ| ≤ 1 and finite for any rigid motion, including pauses.
        #[test]
        fn simple_offsets_are_bounded(
            v in prop::array::uniform3(-2.0f32..2.0),
            spin in -1.0f32..1.0,
            pause in 0usize..4,
            smooth in 0usize..4,
        ) {
            let mesh = peanut();
            let frames: usize = 6;
            let pos: Vec<Vec3> = (0..frames)
                .flat_map(|f: usize| {
                    let t = f.saturating_sub(pause) as f32;
                    let m = Mat4::from_translation(Vec3::from(v) * t) * Mat4::from_rotation_y(spin * t);
                    mesh.positions.iter().map(move |p| m.transform_point3(*p)).collect::<Vec<_>>()
                })
                .collect();
            let anim = MeshAnimation::new(mesh, 24.0, pos).unwrap();
            let d = mesh_offsets(&anim, &opts(smooth)).unwrap();
            prop_assert!(d.values().iter().all(|x| x.is_finite() && x.abs() <= 1.0 + 1e-5));
        }

        /// Articulated arms: finite and within [−1.5, 1.5] for random bends.
        #[test]
        fn articulated_offsets_are_bounded(a in -1.0f32..1.0, b in -1.0f32..1.0, c in -0.3f32..0.3) {
            let ys: Vec<f32> = (0..=20).map(|i| i as f32 * 0.1).collect();
            let mesh = tube(&ys, 12, |y| 0.2 + 0.1 * y);
            let w = chain_weights(&mesh, 2, 1.0, 0.3);
            let skel = chain(2, 1.0, Quat::IDENTITY);
            let l0 = bind_locals(&skel);
            let scene = skinned_scene(mesh, skel, w, 6, move |f| {
                let t = f as f32;
                let mut l = l0.clone();
                l[0] = Mat4::from_translation(Vec3::new(c * t, 0.0, 0.0)) * Mat4::from_rotation_z(a * 0.2 * t);
                l[1] = l0[1] * Mat4::from_rotation_x(b * 0.3 * t);
                l
            });
            let d = &scene_offsets(&scene, &opts(2)).unwrap()[0];
            prop_assert!(d.values().iter().all(|x| x.is_finite() && x.abs() <= 1.5));
        }
    }
}

/// `scene` with its single object's vertices reordered: new vertex i is old vertex
/// `(i · 7919) mod n` (scatters every bone's vertices over the index range).
fn shuffled(mut scene: SampledScene) -> (SampledScene, Vec<usize>) {
    let obj = &mut scene.objects[0];
    let (n, frames) = (obj.animation.vertex_count(), obj.animation.frame_count());
    let old_of: Vec<usize> = (0..n).map(|i| i * 7919 % n).collect();
    let mut new_of = vec![0u32; n];
    for (i, &o) in old_of.iter().enumerate() {
        new_of[o] = i as u32;
    }
    let mesh = &obj.animation.mesh;
    let positions = old_of.iter().map(|&o| mesh.positions[o]).collect();
    let triangles = mesh
        .triangles
        .iter()
        .map(|t| t.map(|v| new_of[v as usize]))
        .collect();
    let mesh = anim::Mesh::new(&mesh.name, positions, triangles);
    let frames_pos = (0..frames)
        .flat_map(|f| old_of.iter().map(move |&o| (f, o)))
        .map(|(f, o)| obj.animation.frame(f)[o])
        .collect();
    let skin = obj.skin.as_mut().unwrap();
    let weights = VertexWeights::from_influences(old_of.iter().map(|&o| {
        let (s, w) = skin.weights.influences(o);
        s.iter().zip(w).map(|(&s, &w)| (s, w)).collect::<Vec<_>>()
    }));
    skin.weights = weights;
    obj.animation = MeshAnimation::new(mesh, 24.0, frames_pos).unwrap();
    (scene, old_of)
}

/// The optimized vertex pass (batched ribbons over neighbourhoods read by runs of
/// consecutive vertices, or gathered when the vertex order is scattered) equals the
/// straightforward pointwise evaluation of SMEAR Eqs. 3–9 (surface points at the vertices) at
/// every vertex and frame, and both vertex orders give the same offsets.
#[test]
fn vertex_pass_matches_pointwise_evaluation() {
    let no_smooth = opts(0);
    let frames = 7;
    let scene = arm_scene(frames, |m| chain_weights(m, 3, 1.0, 0.2));
    let (mixed, old_of) = shuffled(arm_scene(frames, |m| chain_weights(m, 3, 1.0, 0.2)));
    let mut per_order = Vec::new();
    for s in [&scene, &mixed] {
        let solver = OffsetSolver::new(s, &no_smooth).unwrap();
        let verts = solver.vertex_offsets(0).unwrap();
        let tris = &s.objects[0].animation.mesh.triangles;
        let n = verts.vertex_count();
        // One surface point exactly at every vertex.
        let mut points = vec![None; n];
        for (t, tri) in tris.iter().enumerate() {
            for (c, &v) in tri.iter().enumerate() {
                let mut barycentric = [0.0; 3];
                barycentric[c] = 1.0;
                points[v as usize].get_or_insert(SurfacePoint {
                    triangle: t as u32,
                    barycentric,
                });
            }
        }
        let points: Vec<SurfacePoint> = points.into_iter().map(Option::unwrap).collect();
        let at = solver.surface_offsets(0, &points).unwrap();
        let worst = max_diff(&verts, &at);
        assert!(worst <= 1e-5, "vertex pass vs pointwise: {worst}");
        assert!(verts.max_abs() > 0.5, "range {:?}", verts.range());
        per_order.push(verts);
    }
    let mut worst = 0.0f32;
    for f in 0..frames {
        for (i, &o) in old_of.iter().enumerate() {
            worst = worst.max((per_order[1].frame(f)[i] - per_order[0].frame(f)[o]).abs());
        }
    }
    assert!(worst <= 1e-6, "vertex orders differ by {worst}");
}

#[test]
fn camera_following_the_ball_sees_no_speed() {
    // With --camera, the speed that stylization functions read is camera-relative like the
    // offsets: a ball the camera follows gets no speed-weighted smear (Fig. 11c preset).
    let ball = translating(sphere(1.0), 6, |f| Vec3::X * f as f32);
    let follow = camera(
        (0..6)
            .map(|f| Mat4::from_translation(Vec3::new(f as f32, 0.0, 8.0)))
            .collect(),
    );
    let scene = rigid_scene(vec![ball.clone()], vec![follow]);
    let options = OffsetOptions {
        camera: Some(CameraSelect::Index(0)),
        ..opts(0)
    };
    let cam = options.selected_camera(&scene.cameras).unwrap().unwrap();
    let world = scene_offsets(&scene, &opts(0)).unwrap();
    let world_inputs = smear::EffectInputs::new(&ball, &world[0]).unwrap();
    let seen = world_inputs.clone().relative_to_camera(Some(cam));
    let world_speed = world_inputs.style_input(3, 0).speed;
    assert!(
        (world_speed - 1.0).abs() < 1e-5,
        "world speed {world_speed}"
    );
    let max_seen = seen
        .velocities()
        .iter()
        .map(|v| v.length())
        .fold(0.0, f32::max);
    assert!(max_seen < 1e-5, "camera-relative speed {max_seen}");
    let speed_preset = smear::FunctionSpec::speed(2.0).compile().unwrap();
    let options = smear::ElongateOptions::default();
    let moved = |inputs: &smear::EffectInputs<'_>| {
        let e = smear::elongate(inputs, &speed_preset, &options).unwrap();
        e.positions()
            .iter()
            .zip(ball.positions())
            .map(|(a, b)| a.distance(*b))
            .fold(0.0f32, f32::max)
    };
    assert!(moved(&world_inputs) > 1.0);
    assert!(moved(&seen) < 1e-4);
    let unknown = OffsetOptions {
        camera: Some(CameraSelect::Name("nope".into())),
        ..opts(0)
    };
    let e = unknown
        .selected_camera(&scene.cameras)
        .unwrap_err()
        .to_string();
    assert!(e.contains("nope") && e.contains("cam"), "{e}");
}
