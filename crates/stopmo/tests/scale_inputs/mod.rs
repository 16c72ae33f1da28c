//! Feature-film-scale stop-motion inputs made from the bundled talking face, for the scale
//! bench (`benches/scale.rs`) and its small versions in the test suite (`tests/scale.rs`).
//!
//! * [`speech_face`]: the face with a long, seeded, speech-like morph-weight clip: segments
//!   of the recorded talk (random offset, length 1–3 s, amplitude ×0.8–1.2) cross-faded
//!   into each other, one key per frame;
//! * [`refine`]: the face with more vertices (longest edges bisected, morph targets and UVs
//!   interpolated), for StopShop Table 1's 11,595-vertex row.
//!
//! Both return a [`Scene`] that is written as glTF through `tkio`, so the jobs read them the
//! way they read a user's file.
#![allow(dead_code)]

use anim::{Channel, Clip, Interpolation, Property, Scene, SplitMix64};

/// Frames of the cross-fade between two talk segments.
const CROSSFADE_FRAMES: usize = 6;

/// The face scene (`face/ict-face-talk.glb`).
pub(crate) fn face_scene() -> Scene {
    let path = testdata::asset("face/ict-face-talk.glb");
    tkio::gltf::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `face` with a speech-like clip of `frames` frames at `fps` (seeded), one linear key per
/// frame, replacing its clips.
///
/// # Panics
/// If the face has no morph-weight channel.
pub(crate) fn speech_face(face: &Scene, frames: usize, fps: f32, seed: u64) -> Scene {
    let talk = face
        .clips
        .iter()
        .flat_map(|c| &c.channels)
        .find(|c| matches!(c.property, Property::Weights(_)))
        .expect("the face has a morph-weight channel");
    let targets = talk.property.components();
    let (t0, t1) = (talk.times[0], *talk.times.last().expect("keys"));
    let mut rng = SplitMix64::new(seed, 0x5eec);
    let mut values = vec![0.0f32; frames * targets];
    let mut w = vec![0.0f32; targets];
    // Each segment: (first output frame, source start time, amplitude).
    let mut start = 0usize;
    let mut previous: Option<(usize, f32, f32)> = None;
    while start < frames {
        let len = ((1.0 + 2.0 * rng.next_f32()) * fps).round().max(1.0) as usize;
        let src = t0 + rng.next_f32() * (t1 - t0 - len as f32 / fps).max(0.0);
        let amp = 0.8 + 0.4 * rng.next_f32();
        for f in start..(start + len).min(frames) {
            let out = &mut values[f * targets..(f + 1) * targets];
            talk.sample(src + (f - start) as f32 / fps, &mut w);
            let fade = ((f - start) as f32 / CROSSFADE_FRAMES as f32).min(1.0);
            out.iter_mut()
                .zip(&w)
                .for_each(|(o, &v)| *o = fade * amp * v);
            if let (Some((p0, psrc, pamp)), true) = (previous, fade < 1.0) {
                talk.sample(psrc + (f - p0) as f32 / fps, &mut w);
                out.iter_mut()
                    .zip(&w)
                    .for_each(|(o, &v)| *o += (1.0 - fade) * pamp * v);
            }
            out.iter_mut().for_each(|o| *o = o.clamp(0.0, 1.0));
        }
        previous = Some((start, src, amp));
        start += len;
    }
    let mut scene = face.clone();
    scene.clips = vec![Clip {
        name: "Speech".into(),
        channels: vec![Channel {
            node: talk.node,
            property: talk.property,
            interpolation: Interpolation::Linear,
            times: (0..frames).map(|f| f as f32 / fps).collect(),
            values,
        }],
    }];
    scene
}

/// `face` refined to `vertices` vertices: the longest edges (whose two triangles no earlier
/// split touched) are bisected, each split adding one vertex without T-junctions; the new
/// vertex takes the midpoint of positions, morph displacements, UVs and normals, so the
/// animation stays a morph-target blend of the same rank.
///
/// # Panics
/// If one pass cannot add that many vertices (more than about a third of the triangles).
pub(crate) fn refine(face: &Scene, vertices: usize) -> Scene {
    let mut scene = face.clone();
    let sm = &mut scene.meshes[0];
    let m = &mut sm.mesh;
    let extra = vertices.saturating_sub(m.vertex_count());
    // Edges with their triangles (two for interior edges).
    let mut edges: std::collections::BTreeMap<(u32, u32), Vec<usize>> = Default::default();
    for (t, tri) in m.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            edges.entry((a.min(b), a.max(b))).or_default().push(t);
        }
    }
    let length = |e: &(u32, u32)| m.positions[e.0 as usize].distance(m.positions[e.1 as usize]);
    let mut order: Vec<((u32, u32), Vec<usize>)> =
        edges.into_iter().filter(|(_, ts)| ts.len() == 2).collect();
    order.sort_by(|a, b| length(&b.0).total_cmp(&length(&a.0)).then(a.0.cmp(&b.0)));
    let mut touched = vec![false; m.triangles.len()];
    let mut splits = Vec::with_capacity(extra);
    for (e, ts) in order {
        if splits.len() == extra {
            break;
        }
        if ts.iter().any(|&t| touched[t]) {
            continue;
        }
        ts.iter().for_each(|&t| touched[t] = true);
        splits.push((e, ts));
    }
    assert_eq!(splits.len(), extra, "one refinement pass is too few");
    for ((a, b), ts) in splits {
        let mid = m.positions.len() as u32;
        let (ia, ib) = (a as usize, b as usize);
        m.positions.push(0.5 * (m.positions[ia] + m.positions[ib]));
        if let Some(n) = &mut m.normals {
            n.push((n[ia] + n[ib]).normalize_or_zero());
        }
        if let Some(uv) = &mut m.uvs {
            uv.push([0.5 * (uv[ia][0] + uv[ib][0]), 0.5 * (uv[ia][1] + uv[ib][1])]);
        }
        for set in &mut m.extra_uvs {
            set.push([
                0.5 * (set[ia][0] + set[ib][0]),
                0.5 * (set[ia][1] + set[ib][1]),
            ]);
        }
        if let Some(c) = &mut m.colors {
            let (ca, cb) = (c[ia], c[ib]);
            c.push(std::array::from_fn(|k| 0.5 * (ca[k] + cb[k])));
        }
        for values in m.attributes.values_mut() {
            values.push(0.5 * (values[ia] + values[ib]));
        }
        for t in &mut sm.morph_targets {
            t.positions.push(0.5 * (t.positions[ia] + t.positions[ib]));
        }
        for t in ts {
            // (x, y, z) with the edge as x → y keeps the winding: (x, mid, z), (mid, y, z).
            let tri = m.triangles[t];
            let k = (0..3)
                .find(|&k| {
                    let (x, y) = (tri[k], tri[(k + 1) % 3]);
                    (x, y) == (a, b) || (x, y) == (b, a)
                })
                .expect("the edge is in its triangle");
            let (x, y, z) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
            m.triangles[t] = [x, mid, z];
            m.triangles.push([mid, y, z]);
        }
    }
    m.polygons = None;
    assert!(sm.joint_weights.is_none(), "the face has no skin");
    scene
}
