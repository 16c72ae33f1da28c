//! The studio's smear panel API: keyframed style parameters and the weight-group picker
//! (issue #18), on the bundled robot.

use axum::http::StatusCode;
use serde_json::{json, Value};
use studio::pack;

mod common;
use common::{app, error_of, get, post, send, send_ok};

/// The largest difference between two buffers.
fn max_diff(x: &[f32], y: &[f32]) -> f32 {
    x.iter()
        .zip(y)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max)
}

#[tokio::test]
async fn keyed_parameters_round_trip_and_restyle_each_frame_as_the_keys_say() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    // β max keyed 0 at frame 10 → 12 at frame 40 (SMEAR Section 5.1), as the page's key buttons
    // write it; the past copies keyed too.
    let style = json!({
        "elongate": {"function": {"stages": [{"op": "speed"}, {"op": "scale", "by": [[10, 0.0], [40, 12.0]]}]}},
        "multiples": {"past": [[10, 0.0], [40, 2.0]], "future": 0}
    });
    let request = json!({"clip": "Wave", "style": style});
    let keyed = send_ok(&app, post("/api/smear/stylize", request.clone())).await;
    let (h, body) = pack::read_f32(&keyed, "body").unwrap();
    let (_, scene) = send(&app, get("/api/scene?clip=Wave")).await;
    let (_, input) = pack::read_f32(&scene, "positions").unwrap();
    let n = body.len() / h["frames"].as_u64().unwrap() as usize;
    let frame = |b: &[f32], f: usize| b[f * n..(f + 1) * n].to_vec();
    // Held before the first key, 0 at it: the input; between and at the last key: stretched,
    // more at 40 (β = 12) than at 25 (β = 6, interpolated).
    assert!(max_diff(&frame(&body, 5), &frame(&input, 5)) < 1e-5);
    assert!(max_diff(&frame(&body, 10), &frame(&input, 10)) < 1e-5);
    let mid = max_diff(&frame(&body, 25), &frame(&input, 25));
    assert!(mid > 1e-3, "frame 25 not stretched: {mid}");
    // Frame 25 with a constant β of 6 (the interpolated value) is the same geometry.
    let constant = json!({"clip": "Wave", "frames": [25, 26], "style": {"elongate": {"function": {"stages": [{"op": "speed"}, {"op": "scale", "by": 6.0}]}}}});
    let (_, at25) = send(&app, post("/api/smear/stylize", constant)).await;
    let (_, at25) = pack::read_f32(&at25, "body").unwrap();
    assert!(max_diff(&at25, &frame(&body, 25)) < 1e-4);
    // The answer's TOML keeps the keys and restyles to the same result.
    let toml = h["toml"].as_str().unwrap().to_string();
    assert!(toml.contains("[[10.0, 0.0], [40.0, 12.0]]"), "{toml}");
    let (status, again) = send(
        &app,
        post("/api/smear/stylize", json!({"clip": "Wave", "toml": toml})),
    )
    .await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(pack::read_f32(&again, "body").unwrap().1, body);
    assert_eq!(
        h["style"]["multiples"]["past"],
        json!([[10.0, 0.0], [40.0, 2.0]])
    );
    // The exported .toml carries the keys and the library reads it back to the same style.
    let mut export = request.clone();
    export["name"] = json!("keyed.toml");
    send_ok(&app, post("/api/smear/export", export)).await;
    let text = std::fs::read_to_string(dir.path().join("keyed.toml")).unwrap();
    let back = smear::Style::from_toml_str(&text).unwrap();
    let sent: smear::Style = serde_json::from_value(h["style"].clone()).unwrap();
    assert_eq!(back.elongate, sent.elongate);
    assert_eq!(back.multiples, sent.multiples);
}

#[tokio::test]
async fn the_robot_offers_its_bones_as_weight_groups_and_a_picked_group_restyles() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    let (status, list) = send(&app, get("/api/smear/weight-sources?clip=Wave")).await;
    assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&list));
    let list: Value = serde_json::from_slice(&list).unwrap();
    let sources = list["sources"].as_array().unwrap();
    let shoulder = sources
        .iter()
        .find(|s| s["source"]["group"] == json!(["ShoulderR"]))
        .unwrap_or_else(|| panic!("no ShoulderR group in {sources:?}"));
    assert_eq!(shoulder["label"], "bone ShoulderR and below");
    assert!(sources.len() > 20, "{} sources", sources.len());
    // ω of the right arm: 1 on the arm, 0 elsewhere, one per vertex of the body.
    let uri = format!(
        "/api/smear/weights?clip=Wave&source={}",
        urlencode(&shoulder["source"].to_string())
    );
    let (status, w) = send(&app, get(&uri)).await;
    assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&w));
    let (hw, w) = pack::read_f32(&w, "weights").unwrap();
    assert_eq!(w.len(), 7214);
    assert_eq!(hw["min"].as_f64(), Some(0.0));
    assert!(hw["max"].as_f64().unwrap() > 0.99, "{hw}");
    let on_arm = w.iter().filter(|&&x| x > 0.5).count();
    assert!(
        on_arm > 100 && on_arm < w.len() / 2,
        "{on_arm} arm vertices"
    );
    // Picking it restyles: the elongation reads ω, so vertices off the arm no longer move.
    let style =
        json!({"elongate": {"function": {"stages": [{"op": "speed"}, {"op": "scale", "by": 12}]}}});
    let (_, all) = send(
        &app,
        post(
            "/api/smear/stylize",
            json!({"clip": "Wave", "style": style}),
        ),
    )
    .await;
    let (status, arm) = send(
        &app,
        post(
            "/api/smear/stylize",
            json!({"clip": "Wave", "style": style, "weights": shoulder["source"]}),
        ),
    )
    .await;
    assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&arm));
    let (ha, arm) = pack::read_f32(&arm, "body").unwrap();
    let (_, all) = pack::read_f32(&all, "body").unwrap();
    let (_, scene) = send(&app, get("/api/scene?clip=Wave")).await;
    let (_, input) = pack::read_f32(&scene, "positions").unwrap();
    assert_eq!(ha["style"]["weights"]["group"], json!(["ShoulderR"]));
    assert_eq!(
        ha["style"]["elongate"]["function"]["stages"][2],
        json!({"op": "weight"})
    );
    let n = w.len();
    let moved = |b: &[f32], v: usize| {
        (0..b.len() / (n * 3))
            .map(|f| {
                max_diff(
                    &b[(f * n + v) * 3..(f * n + v + 1) * 3],
                    &input[(f * n + v) * 3..(f * n + v + 1) * 3],
                )
            })
            .fold(0.0f32, f32::max)
    };
    let off_arm: Vec<usize> = (0..n).filter(|&v| w[v] == 0.0).collect();
    assert!(off_arm.iter().all(|&v| moved(&arm, v) < 1e-5));
    assert!(off_arm.iter().any(|&v| moved(&all, v) > 1e-3));
    assert!((0..n)
        .filter(|&v| w[v] > 0.9)
        .any(|v| moved(&arm, v) > 1e-3));
}

#[tokio::test]
async fn a_bad_weight_source_is_a_json_error() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    for (source, needle) in [
        (r#"{"group":["NoSuchBone"]}"#, "NoSuchBone"),
        (r#"{"attribute":"_NOPE"}"#, "_NOPE"),
        (r#"{"grup":["Head"]}"#, "weight source"),
        ("{not json", "source"),
    ] {
        let uri = format!("/api/smear/weights?clip=Wave&source={}", urlencode(source));
        let (status, body) = send(&app, get(&uri)).await;
        assert_eq!(status, StatusCode::BAD_REQUEST, "{source}");
        let e = error_of(&body);
        assert!(e.contains(needle), "{source}: {e}");
    }
    let (status, body) = send(&app, get("/api/smear/weights?clip=Wave")).await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    assert!(error_of(&body).contains("source"));
    let long = urlencode(&format!(r#"{{"group":["{}"]}}"#, "x".repeat(5000)));
    let (status, _) = send(&app, get(&format!("/api/smear/weights?source={long}"))).await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    // The same bad group given to stylize is a JSON error too.
    let request = json!({"clip": "Wave", "style": {}, "weights": {"group": ["NoSuchBone"]}});
    let (status, body) = send(&app, post("/api/smear/stylize", request)).await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    assert!(
        error_of(&body).contains("NoSuchBone"),
        "{}",
        error_of(&body)
    );
}

/// Percent-encodes a query value.
fn urlencode(s: &str) -> String {
    s.bytes()
        .map(|b| match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' => (b as char).to_string(),
            _ => format!("%{b:02X}"),
        })
        .collect()
}

#[tokio::test]
async fn presets_and_parameter_ranges_are_the_smear_crates() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    let answer: Value =
        serde_json::from_slice(&send_ok(&app, get("/api/smear/presets")).await).unwrap();
    // The page starts from the crate's default preset, with the crate's default parameters.
    assert_eq!(answer["default"], smear::ElongatePreset::default().name());
    assert_eq!(answer["parameters"], json!(smear::PARAMETERS));
    for preset in smear::ElongatePreset::ALL {
        let listed = answer["presets"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == preset.name())
            .unwrap_or_else(|| panic!("preset {} not listed", preset.name()));
        assert_eq!(
            listed["style"]["elongate"]["function"],
            json!(preset.default_function()),
            "{}",
            preset.name()
        );
        // Its TOML is the same style (what "export style" and the CLI's --style read).
        let toml = smear::Style::from_toml_str(listed["toml"].as_str().unwrap()).unwrap();
        assert_eq!(json!(toml), listed["style"]);
    }
}

/// The robot exported in other units gets the same smear from the studio relative to its
/// size (`docs/smear-units.md`): fig16's style (elongation, multiples, lines) on the robot
/// with its root scaled by 0.01, 1 and 100; the report's mean elongation and line length
/// over the size agree within 1 %, and the size follows the scale.
#[tokio::test]
async fn a_style_means_the_same_on_the_robot_in_centimetres_and_metres() {
    let dir = tempfile::tempdir().unwrap();
    let toml = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/smear/fig16_combined.toml"),
    )
    .unwrap();
    let mut runs = Vec::new();
    for scale in [1.0f32, 0.01, 100.0] {
        let robot = testdata::scaled_glb("characters/RobotExpressive.glb", scale, dir.path());
        let opened = vec![studio::files::OpenedFile::open(&robot).unwrap()];
        let out = studio::files::output_folder(&dir.path().join("out")).unwrap();
        let app = studio::router(
            std::sync::Arc::new(studio::Studio::new(opened, out)),
            common::PORT,
        );
        let body = send_ok(
            &app,
            post("/api/smear/stylize", json!({"clip": "Wave", "toml": toml})),
        )
        .await;
        let (h, _) = pack::read_f32(&body, "body").unwrap();
        let report = &h["report"];
        let size = report["size"].as_f64().unwrap();
        let objects = report["objects"].as_array().unwrap();
        let mean = |key: &str| {
            let v: Vec<f64> = objects.iter().filter_map(|o| o[key].as_f64()).collect();
            v.iter().sum::<f64>() / v.len().max(1) as f64 / size
        };
        runs.push((
            scale as f64,
            size,
            mean("elongation_mean"),
            mean("lines_length_mean"),
        ));
    }
    let (_, size, e, l) = runs[0];
    assert!(e > 1e-4 && l > 1e-4, "{runs:?}");
    for &(k, size_k, ek, lk) in &runs[1..] {
        assert!(
            (size_k / (size * k) - 1.0).abs() < 1e-4,
            "size {size_k} at ×{k}"
        );
        assert!((ek / e - 1.0).abs() < 0.01, "×{k}: elongation {ek} vs {e}");
        assert!((lk / l - 1.0).abs() < 0.01, "×{k}: line length {lk} vs {l}");
    }
}
