//! Writes the benchmark tube of the offsets bench (15,002 vertices skinned to a 10-bone
//! chain, 40 frames at 24 fps) as a skinned, animated `.glb`, for whole-process timings of
//! `toonkit smear offsets` (see `scripts/bench_offsets.sh`).
//!
//! Run: `cargo run -p toonkit-smear --example write_tube -- OUT.glb [FRAMES]`.

use anim::{Channel, Clip, Interpolation, Node, Property, Scene, SceneMesh, SkinDef};

#[path = "../tests/common/mod.rs"]
mod common;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let out = args.next().ok_or("usage: write_tube OUT.glb [FRAMES]")?;
    let frames: usize = match args.next() {
        Some(f) => f.parse()?,
        None => 40,
    };
    let (mesh, skeleton, weights, locals) = common::benchmark_tube_parts();
    let nj = skeleton.len();
    let mut scene = Scene::default();
    for (k, j) in skeleton.joints.iter().enumerate() {
        scene.nodes.push(Node {
            name: j.name.clone(),
            parent: j.parent,
            children: if k + 1 < nj { vec![k + 1] } else { Vec::new() },
            transform: j.bind_local,
            ..Default::default()
        });
    }
    let inverse_bind = skeleton.bind_world().iter().map(|m| m.inverse()).collect();
    scene.skins.push(SkinDef {
        name: "chain".into(),
        joints: (0..nj).collect(),
        inverse_bind,
        skeleton: None,
    });
    scene.meshes.push(SceneMesh {
        mesh,
        joint_weights: Some(weights),
        ..Default::default()
    });
    scene.nodes.push(Node {
        name: "tube".into(),
        mesh: Some(0),
        skin: Some(0),
        ..Default::default()
    });
    let times: Vec<f32> = (0..frames).map(|f| f as f32 / anim::DEFAULT_FPS).collect();
    let mut channels = Vec::new();
    // Local transforms per frame and joint as (rotation, translation); the chain has no scale.
    let per_frame: Vec<Vec<_>> = (0..frames)
        .map(|f| {
            locals(f)
                .iter()
                .map(|m| {
                    let (_, r, t) = m.to_scale_rotation_translation();
                    (r, t)
                })
                .collect()
        })
        .collect();
    for k in 0..nj {
        let t = per_frame.iter().flat_map(|l| l[k].1.to_array());
        let r = per_frame.iter().flat_map(|l| l[k].0.to_array());
        for (property, values) in [
            (Property::Translation, t.collect::<Vec<f32>>()),
            (Property::Rotation, r.collect()),
        ] {
            channels.push(Channel {
                node: k,
                property,
                interpolation: Interpolation::Linear,
                times: times.clone(),
                values,
            });
        }
    }
    scene.clips.push(Clip {
        name: "bend".into(),
        channels,
    });
    scene.validate()?;
    let bytes = tkio::gltf::write_glb(&scene)?;
    tkio::write_atomic(std::path::Path::new(&out), &bytes)?;
    println!(
        "wrote {out} ({} vertices, {nj} bones, {frames} frames)",
        scene.meshes[0].mesh.vertex_count()
    );
    Ok(())
}
