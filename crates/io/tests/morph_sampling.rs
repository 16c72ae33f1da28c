//! Sampling the bundled talking face (a morph-target animation): every frame equals, bit for
//! bit, the rest positions plus each target of non-zero weight in target order, then the
//! node's world matrix. Sampling reads the targets once per batch of frames (see
//! `docs/stopmo-scale.md`) and must keep exactly these sums.

use anim::glam::Vec3;
use anim::{sample, SampleOptions};

#[test]
fn sampled_face_frames_are_the_morph_target_sums() {
    let scene = tkio::gltf::read(&testdata::asset("face/ict-face-talk.glb")).unwrap();
    let s = sample(
        &scene,
        &SampleOptions {
            fps: 10.0,
            ..SampleOptions::default()
        },
    )
    .unwrap();
    let clip = scene.clips.first();
    let nn = scene.nodes.len();
    let (mut locals, mut weights) = (Vec::new(), Vec::new());
    let mut morphed_frames = 0;
    for obj in &s.objects {
        let sm = &scene.meshes[scene.nodes[obj.node].mesh.unwrap()];
        assert!(sm.morph_targets.len() > 1, "the face has morph targets");
        for f in 0..s.frame_count {
            scene.pose_at(
                clip,
                s.start_time + f as f32 / s.fps,
                &mut locals,
                &mut weights,
            );
            let w = &weights[obj.node];
            morphed_frames += usize::from(w.iter().any(|&w| w != 0.0));
            let mut m = sm.mesh.positions.clone();
            for (t, &w) in sm.morph_targets.iter().zip(w) {
                if w != 0.0 {
                    for (m, d) in m.iter_mut().zip(&t.positions) {
                        *m += w * *d;
                    }
                }
            }
            let world = s.node_world[f * nn + obj.node];
            let want: Vec<Vec3> = m.iter().map(|p| world.transform_point3(*p)).collect();
            assert!(obj.animation.frame(f) == &want[..], "frame {f} differs");
        }
    }
    assert!(morphed_frames > 10, "{morphed_frames} frames are morphed");
}
