//! Compact answers: a stroke answered as the skeleton's pose and a whole clip answered as
//! 16-bit changes (its multiples as the vertices they show) rebuild the core's positions within
//! their stated bounds
//! (docs/studio.md, "Whole clips").

use serde_json::json;
use studio::pack;

mod common;
use common::{app, get, post, send_ok};

/// The u32 buffer `name` of a pack (panics when absent).
fn read_u32(bytes: &[u8], name: &str) -> Vec<u32> {
    pack::read_u32(bytes, name).unwrap_or_else(|| panic!("no u32 buffer {name}"))
}

/// Reads a float32 buffer of a pack (panics when absent).
fn f32s(bytes: &[u8], name: &str) -> Vec<f32> {
    pack::read_f32(bytes, name)
        .unwrap_or_else(|| panic!("no {name}"))
        .1
}

/// The robot's Dance clip as the page first receives it: its input frame's positions.
async fn dance_input(app: &axum::Router) -> Vec<f32> {
    f32s(
        &send_ok(app, get("/api/scene?clip=Dance")).await,
        "positions",
    )
}

/// A character's skin binding as an answer sends it once (`skin.*`).
struct SkinBinding {
    rest: Vec<f32>,
    weight: Vec<f32>,
    inverse: Vec<f32>,
    index: Vec<u32>,
    node: Vec<u32>,
}

impl SkinBinding {
    fn read(answer: &[u8]) -> SkinBinding {
        SkinBinding {
            rest: f32s(answer, "skin.rest"),
            weight: f32s(answer, "skin.weight"),
            inverse: f32s(answer, "skin.inverse"),
            index: read_u32(answer, "skin.index"),
            node: read_u32(answer, "skin.node"),
        }
    }

    /// The largest distance between linear blend skinning with the pose `world` (frames ×
    /// `nodes` matrices), as the page's renderer does it, and the core's positions.
    fn worst_error(&self, world: &[f32], nodes: usize, core: &[f32]) -> f32 {
        let vertices = self.rest.len() / 3;
        let frames = world.len() / (nodes * 16);
        assert_eq!(core.len(), frames * vertices * 3);
        let mat = |s: &[f32]| anim::glam::Mat4::from_cols_slice(s);
        let mut worst = 0.0f32;
        for f in 0..frames {
            for v in 0..vertices {
                let p = anim::glam::Vec3::from_slice(&self.rest[v * 3..v * 3 + 3]).extend(1.0);
                let mut acc = anim::glam::Vec4::ZERO;
                for k in 0..4 {
                    let e = self.index[v * 4 + k] as usize;
                    let n = self.node[e] as usize;
                    let m = mat(&world[(f * nodes + n) * 16..][..16])
                        * mat(&self.inverse[e * 16..][..16]);
                    acc += m * p * self.weight[v * 4 + k];
                }
                let q = anim::glam::Vec3::from_slice(&core[(f * vertices + v) * 3..][..3]);
                worst = worst.max((acc.truncate() - q).length());
            }
        }
        worst
    }
}

/// The core's positions of the animate answer `version` (`GET /api/loa/motion`).
async fn core_motion(app: &axum::Router, version: u64) -> Vec<f32> {
    f32s(
        &send_ok(app, get(&format!("/api/loa/motion?version={version}"))).await,
        "positions",
    )
}

#[tokio::test]
async fn a_stroke_answered_as_the_skeletons_pose_skins_to_the_cores_positions() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    let keys = common::bending_keystrokes();
    let request = json!({"keystrokes": keys, "width": 800.0, "height": 600.0, "skin": ""});
    let answer = send_ok(&app, post("/api/loa/animate", request.clone())).await;
    let (header, _) = pack::split(&answer).unwrap();
    let m = &header["motion"];
    let (frames, vertices) = (
        m["frames"].as_u64().unwrap() as usize,
        m["vertices"].as_u64().unwrap() as usize,
    );
    let nodes = m["skin"]["nodes"].as_u64().unwrap() as usize;
    assert_eq!(
        m["sampled_vertices"], true,
        "the first stroke checks the binding"
    );
    assert!(pack::read_f32(&answer, "positions").is_none());
    let world = f32s(&answer, "skin.world");
    assert_eq!(world.len(), frames * nodes * 16);
    let binding = SkinBinding::read(&answer);
    assert_eq!(
        (binding.rest.len(), binding.index.len()),
        (vertices * 3, vertices * 4)
    );
    let version = header["version"].as_u64().unwrap();
    let worst = binding.worst_error(&world, nodes, &core_motion(&app, version).await);
    assert!(
        worst < 1e-4,
        "the pose skins {worst} off the core's positions"
    );
    // The binding is sent once: a page holding it gets the pose alone. The character's
    // binding is checked now, so another stroke's motion is posed without sampling every
    // vertex; its positions, sampled when asked for, are still the pose's skinning.
    let mut again = request;
    again["skin"] = m["skin"]["id"].clone();
    for k in again["keystrokes"].as_array_mut().unwrap() {
        for p in k["points"].as_array_mut().unwrap() {
            p[0] = json!(p[0].as_f64().unwrap() + 40.0);
        }
    }
    let answer = send_ok(&app, post("/api/loa/animate", again)).await;
    let (header, _) = pack::split(&answer).unwrap();
    assert!(pack::read_f32(&answer, "skin.rest").is_none());
    assert!(answer.len() < 300_000, "{} bytes", answer.len());
    let m2 = &header["motion"];
    assert_eq!(m2["skin"]["id"], m["skin"]["id"]);
    assert_eq!(
        m2["sampled_vertices"], false,
        "the checked binding was not used"
    );
    assert_eq!(m2["vertices"].as_u64().unwrap() as usize, vertices);
    let frames2 = m2["frames"].as_u64().unwrap() as usize;
    let world2 = f32s(&answer, "skin.world");
    assert_eq!(world2.len(), frames2 * nodes * 16);
    assert_ne!(world2, world, "another stroke, the same motion");
    let version2 = header["version"].as_u64().unwrap();
    let core2 = core_motion(&app, version2).await;
    let worst = binding.worst_error(&world2, nodes, &core2);
    assert!(
        worst < 1e-4,
        "the second stroke's pose skins {worst} off the core's positions"
    );
    // Asked again, the same positions (sampled once).
    assert_eq!(core_motion(&app, version2).await, core2);
}

#[tokio::test]
async fn the_whole_clip_sent_as_changes_rebuilds_the_cores_body_within_its_bound() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    let input = dance_input(&app).await;
    // The bound of the quantized displacements: 1e-5 of the clip's bounding-box diagonal.
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for (i, &x) in input.iter().enumerate() {
        lo[i % 3] = lo[i % 3].min(x);
        hi[i % 3] = hi[i % 3].max(x);
    }
    let diagonal = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f32>().sqrt();
    // Speeds are in character sizes per second: β max 2 is a moderate smear of the Dance.
    let style =
        json!({"elongate": {"function": {"stages": [{"op": "speed"}, {"op": "scale", "by": 2}]}}});
    for range in [None, Some([30, 34])] {
        let mut request = json!({"clip": "Dance", "style": style});
        if let Some(r) = range {
            request["frames"] = json!(r);
        }
        let dense = send_ok(&app, post("/api/smear/stylize", request.clone())).await;
        let (header, body) = pack::read_f32(&dense, "body").unwrap();
        request["changes"] = json!(true);
        let sent = send_ok(&app, post("/api/smear/stylize", request)).await;
        assert!(pack::read_f32(&sent, "body").is_none());
        assert!(pack::read_f32(&sent, "body.positions").is_none());
        let twins = read_u32(&sent, "body.twins");
        let mask = read_u32(&sent, "body.changed");
        let (_, steps) = pack::read_f32(&sent, "body.step").unwrap();
        let offsets = read_u32(&sent, "body.offsets");
        let varints = pack::read_u8(&sent, "body.varints").unwrap();
        let frames = header["frames"].as_u64().unwrap() as usize;
        let first = header["first_frame"].as_u64().unwrap() as usize;
        let n = body.len() / frames / 3;
        let words = n.div_ceil(32);
        assert_eq!(twins.len(), n);
        // The page's rebuild: the input clip, sent vertices displaced in vertex order, the
        // others where their twins are.
        let mut rebuilt = input[first * n * 3..(first + frames) * n * 3].to_vec();
        let (mut sent_values, mut moved, mut copied) = (0, 0, 0);
        for f in 0..frames {
            // Each frame's values from its own offsets, as the page reads a frame it draws.
            let values =
                pack::zigzag_varints(&varints[offsets[f] as usize..offsets[f + 1] as usize]);
            let mut k = 0;
            for v in 0..n {
                let o = (f * n + v) * 3;
                let t = twins[v] as usize;
                assert!(
                    t <= v && twins[t] as usize == t,
                    "a twin is its point's first vertex"
                );
                if mask[f * words + v / 32] >> (v % 32) & 1 == 1 {
                    for c in 0..3 {
                        rebuilt[o + c] += values[k + c] as f32 * steps[f];
                    }
                    k += 3;
                } else if t != v {
                    let from = (f * n + t) * 3;
                    rebuilt.copy_within(from..from + 3, o);
                    copied += 1;
                    assert_eq!(
                        body[o..o + 3],
                        body[from..from + 3],
                        "a copy is its twin's bits"
                    );
                } else {
                    assert_eq!(
                        rebuilt[o..o + 3],
                        body[o..o + 3],
                        "unmoved vertices are exact"
                    );
                }
                if body[o..o + 3] != input[(first * n) * 3 + o..(first * n) * 3 + o + 3] {
                    moved += 3;
                }
            }
            assert_eq!(
                k,
                values.len(),
                "{range:?}: every sent vertex of frame {f} is placed"
            );
            sent_values += k;
        }
        assert_eq!(offsets[frames] as usize, varints.len());
        let worst = rebuilt
            .iter()
            .zip(&body)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        assert!(
            worst <= 1e-5 * diagonal,
            "{range:?}: the rebuilt body is {worst} off (diagonal {diagonal})"
        );
        assert!(
            moved * 2 < body.len(),
            "{range:?}: the speed style moves {moved} of {} coordinates",
            body.len()
        );
        // The robot's mesh holds each corner about four times (1,820 points for 7,214
        // vertices): most moved vertices are drawn where their twins are.
        assert!(
            sent_values * 2 < moved && copied > 0,
            "{range:?}: {sent_values} of {moved} moved coordinates sent"
        );
        // Most displacements are a few hundred steps: under two bytes a coordinate.
        assert!(
            varints.len() < 2 * sent_values,
            "{range:?}: {} bytes for {sent_values} coordinates",
            varints.len()
        );
        // The whole clip: a tenth of float32's bytes (the twins, one word a vertex, weigh
        // more in a few frames).
        let ratio = if range.is_none() { 10 } else { 4 };
        assert!(
            sent.len() * ratio < dense.len(),
            "{} of {} bytes",
            sent.len(),
            dense.len()
        );
    }
}

#[tokio::test]
async fn a_whole_clip_sends_the_multiples_shown_vertices_and_16_bit_line_indices() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    let input = dance_input(&app).await;
    // SMEAR Fig. 16: elongation, two past and one future copy, motion lines.
    let toml = include_str!("../../../examples/smear/fig16_combined.toml");
    let mut request = json!({"clip": "Dance", "toml": toml});
    let dense = send_ok(&app, post("/api/smear/stylize", request.clone())).await;
    request["changes"] = json!(true);
    let sent = send_ok(&app, post("/api/smear/stylize", request)).await;
    let (header, _) = pack::split(&sent).unwrap();
    let frames = header["frames"].as_u64().unwrap() as usize;
    let n = input.len() / 3 / frames;
    let copies = header["copies"].as_array().unwrap();
    assert!(!copies.is_empty());
    let (mut shown, mut all) = (0, 0);
    for (i, c) in copies.iter().enumerate() {
        let v = c["vertices"].as_u64().unwrap() as usize;
        let first = c["first_vertex"].as_u64().unwrap() as usize;
        let triangles = read_u32(&sent, &format!("copy{i}.triangles"));
        let (positions, alpha) = (
            f32s(&dense, &format!("copy{i}.positions")),
            f32s(&dense, &format!("copy{i}.alpha")),
        );
        assert!(pack::read_f32(&sent, &format!("copy{i}.positions")).is_none());
        let mask = read_u32(&sent, &format!("copy{i}.shown"));
        let xyz = f32s(&sent, &format!("copy{i}.shown_positions"));
        let a = f32s(&sent, &format!("copy{i}.shown_alpha"));
        // The page's rebuild: shown vertices as sent, the others at the input, transparent.
        let words = v.div_ceil(32);
        let mut k = 0;
        let (mut p, mut q) = (vec![0.0f32; frames * v * 3], vec![0.0f32; frames * v]);
        for f in 0..frames {
            for x in 0..v {
                let o = f * v + x;
                if mask[f * words + x / 32] >> (x % 32) & 1 == 1 {
                    p[3 * o..3 * o + 3].copy_from_slice(&xyz[3 * k..3 * k + 3]);
                    q[o] = a[k];
                    k += 1;
                } else {
                    let from = (f * n + first + x) * 3;
                    p[3 * o..3 * o + 3].copy_from_slice(&input[from..from + 3]);
                }
            }
        }
        assert_eq!(k, a.len(), "copy {i}: every shown vertex is placed");
        assert_eq!(q, alpha, "copy {i}: every opacity is the core's");
        for f in 0..frames {
            for t in triangles.chunks(3) {
                if t.iter().any(|&x| alpha[f * v + x as usize] > 0.0) {
                    for &x in t {
                        let o = 3 * (f * v + x as usize);
                        assert_eq!(p[o..o + 3], positions[o..o + 3], "copy {i} frame {f}");
                    }
                }
            }
        }
        shown += k;
        all += frames * v;
    }
    assert!(shown * 4 < all, "{shown} of {all} vertex-frames shown");
    for i in 0..header["lines"].as_array().unwrap().len() {
        let wide = read_u32(&dense, &format!("lines{i}.triangles"));
        let narrow = pack::read_i16(&sent, &format!("lines{i}.triangles16")).unwrap();
        assert_eq!(wide, narrow.iter().map(|&x| x as u32).collect::<Vec<_>>());
    }
    assert!(
        sent.len() * 2 < dense.len(),
        "{} of {} bytes",
        sent.len(),
        dense.len()
    );
}

#[test]
fn buffers_after_a_megabyte_chunk_read_back_at_their_offsets() {
    // A whole clip's answer: megabytes of value-by-value buffers end their chunks (so the
    // growth of one does not copy those before it); every buffer still reads back in place.
    let big: Vec<f32> = (0..300_000).map(|i| i as f32 * 0.5).collect();
    let words: Vec<u32> = (0..400_000).collect();
    let mut p = pack::Pack::new();
    p.f32("big", big.iter().copied())
        .u32("words", words.iter().copied())
        .i16("small", [-3, 7, 1])
        .f32_slices("slices", [&big[..10], &big[10..20]])
        .u8_parts("parts", vec![vec![1, 254], vec![3]])
        .f32("alpha", big.iter().copied().filter(|v| *v > 1.0));
    let bytes = p.finish(json!({}));
    assert_eq!(f32s(&bytes, "big"), big);
    assert_eq!(read_u32(&bytes, "words"), words);
    assert_eq!(pack::read_i16(&bytes, "small").unwrap(), vec![-3, 7, 1]);
    assert_eq!(f32s(&bytes, "slices"), big[..20].to_vec());
    // Three bytes, padded: the float32 buffer after them stays aligned.
    assert_eq!(pack::read_u8(&bytes, "parts").unwrap(), vec![1, 254, 3]);
    assert_eq!(f32s(&bytes, "alpha"), big[3..].to_vec());
}
