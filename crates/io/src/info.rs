//! What a file holds, for `toonkit info`: meshes, vertices, triangles, joints, morph targets,
//! clips, bounds and the reader's notes, as JSON ([`summary`]) and as text ([`summary_text`]).

use std::path::Path;

use anim::{Aabb, SampleOptions, Scene};
use serde_json::{json, Value};

use crate::Loaded;

/// The summary of what was loaded (clip frame counts at `fps`) with the reader's `notes`.
///
/// # Errors
/// The rest pose of a scene cannot be sampled.
pub fn summary(loaded: &Loaded, fps: f32, notes: &[String]) -> Result<Value, anim::AnimError> {
    let mut summary = match loaded {
        Loaded::Scene(scene) => scene_summary(scene, fps)?,
        Loaded::Cache(c) => json!({
            "meshes": [mesh_json(&c.mesh.name, c.vertex_count(), c.mesh.triangle_count(), 0)],
            "joints": 0,
            "clips": [{"name": "cache", "duration": c.duration(), "frames": c.frame_count(), "fps": c.fps}],
            "bbox": bbox_json(c.bbox()),
        }),
        Loaded::Mesh(m) => json!({
            "meshes": [mesh_json(&m.name, m.vertex_count(), m.triangle_count(), 0)],
            "joints": 0,
            "clips": [],
            "bbox": bbox_json(m.bbox()),
        }),
    };
    summary["notes"] = json!(notes);
    Ok(summary)
}

fn mesh_json(name: &str, v: usize, t: usize, m: usize) -> Value {
    json!({"name": name, "vertices": v, "triangles": t, "morph_targets": m})
}

fn bbox_json(b: Aabb) -> Value {
    if b.is_empty() {
        json!([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    } else {
        json!([b.min.to_array(), b.max.to_array()])
    }
}

fn scene_summary(scene: &Scene, fps: f32) -> Result<Value, anim::AnimError> {
    let meshes: Vec<_> = scene
        .meshes
        .iter()
        .map(|m| {
            mesh_json(
                &m.mesh.name,
                m.mesh.vertex_count(),
                m.mesh.triangle_count(),
                m.morph_targets.len(),
            )
        })
        .collect();
    let (skeleton, _) = scene.skeleton();
    let clips: Vec<_> = scene
        .clips
        .iter()
        .map(|c| {
            json!({"name": c.name, "duration": c.duration(), "frames": c.frame_count(fps),
                   "key_rate": c.key_rate()})
        })
        .collect();
    // Bounds of the rest pose (meshes, or joints when there is no mesh).
    let rest = Scene {
        clips: Vec::new(),
        ..scene.clone()
    };
    let sampled = anim::sample(&rest, &SampleOptions::default())?;
    let mut bbox = Aabb::EMPTY;
    for o in &sampled.objects {
        bbox = bbox.union(o.animation.bbox());
    }
    if sampled.objects.is_empty() {
        for b in &sampled.bones {
            bbox.grow(b.root);
        }
    }
    let mut names: Vec<&str> = scene
        .meshes
        .iter()
        .flat_map(|m| m.morph_targets.iter().map(|t| t.name.as_str()))
        .collect();
    names.sort_unstable();
    names.dedup();
    Ok(json!({
        "meshes": meshes,
        "morph_targets": names.len(),
        "joints": skeleton.len(),
        "clips": clips,
        "bbox": bbox_json(bbox),
        "cameras": scene.cameras.len(),
        "nodes": scene.nodes.len(),
    }))
}

/// The summary as text: one line per mesh and clip, the bounds and the reader's notes.
pub fn summary_text(path: &Path, s: &Value, fps: f32) -> String {
    let mut out = format!("{}\n", path.display());
    if let Some(meshes) = s["meshes"].as_array() {
        let v: u64 = meshes.iter().filter_map(|m| m["vertices"].as_u64()).sum();
        let t: u64 = meshes.iter().filter_map(|m| m["triangles"].as_u64()).sum();
        out += &format!("  meshes: {} ({v} vertices, {t} triangles)\n", meshes.len());
        for m in meshes {
            out += &format!(
                "    {:<24} {:>7} v {:>7} tri {:>3} morph targets\n",
                m["name"].as_str().unwrap_or(""),
                m["vertices"],
                m["triangles"],
                m["morph_targets"]
            );
        }
    }
    out += &format!(
        "  morph targets: {}\n",
        s["morph_targets"].as_u64().unwrap_or(0)
    );
    out += &format!("  joints: {}\n", s["joints"]);
    if let Some(clips) = s["clips"].as_array() {
        out += &format!("  clips: {} (frames at {fps} fps)\n", clips.len());
        for c in clips {
            out += &format!(
                "    {:<24} {:>8.3} s {:>6} frames\n",
                c["name"].as_str().unwrap_or(""),
                c["duration"].as_f64().unwrap_or(0.0),
                c["frames"]
            );
        }
    }
    out += &format!("  bbox: {} .. {}", s["bbox"][0], s["bbox"][1]);
    for note in s["notes"].as_array().into_iter().flatten() {
        out += &format!("\n  note: {}", note.as_str().unwrap_or(""));
    }
    out
}
