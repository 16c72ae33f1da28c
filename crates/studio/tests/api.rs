//! The studio's API through its router (tower's `oneshot`, no socket): safety (foreign
//! Host/Origin, paths outside the output folder, body limits, bad JSON) and the three
//! panels' calls on the bundled robot and face.

use axum::body::Body;
use axum::http::{header, Request, StatusCode};
use serde_json::{json, Value};
use studio::{pack, router};

mod common;
use common::{app, error_of, get, post, send, send_ok, studio_with, HOST, PORT};

#[tokio::test]
async fn a_foreign_host_or_origin_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    let evil = Request::get("/api/info")
        .header(header::HOST, "evil.example")
        .body(Body::empty())
        .unwrap();
    let (status, body) = send(&app, evil).await;
    assert_eq!(status, StatusCode::FORBIDDEN);
    assert!(error_of(&body).contains("evil.example"));

    // A rebinding page on another name but the right port.
    let evil_port = Request::get("/")
        .header(header::HOST, "evil.example:8765")
        .body(Body::empty())
        .unwrap();
    assert_eq!(send(&app, evil_port).await.0, StatusCode::FORBIDDEN);

    // The right Host but a foreign page's Origin (a cross-site POST).
    let cross = Request::post("/api/smear/stylize")
        .header(header::HOST, HOST)
        .header(header::ORIGIN, "http://evil.example")
        .body(Body::from("{}"))
        .unwrap();
    assert_eq!(send(&app, cross).await.0, StatusCode::FORBIDDEN);

    // No Host at all.
    let none = Request::get("/api/info").body(Body::empty()).unwrap();
    assert_eq!(send(&app, none).await.0, StatusCode::FORBIDDEN);

    // The local server itself passes.
    let ok = Request::get("/api/info")
        .header(header::HOST, "localhost:8765")
        .header(header::ORIGIN, "http://localhost:8765")
        .body(Body::empty())
        .unwrap();
    let (status, body) = send(&app, ok).await;
    assert_eq!(status, StatusCode::OK);
    let info: Value = serde_json::from_slice(&body).unwrap();
    assert_eq!(info["files"][0]["name"], "RobotExpressive.glb");
    assert!(info["files"][0]["clips"]
        .as_array()
        .unwrap()
        .iter()
        .any(|c| c == "Dance"));
}

#[tokio::test]
async fn exports_outside_the_output_folder_are_refused_and_only_opened_files_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    let style = json!({"elongate": {"function": {"stages": [{"op": "scale", "by": 2}]}}});
    for name in ["../escape.toml", "/tmp/escape.toml", "a/../../escape.toml"] {
        let (status, body) = send(
            &app,
            post(
                "/api/smear/export",
                json!({"clip": "Wave", "style": style, "name": name}),
            ),
        )
        .await;
        assert_eq!(status, StatusCode::FORBIDDEN, "{name}");
        assert!(
            error_of(&body).contains("outside the output folder"),
            "{name}"
        );
    }
    assert!(!dir.path().parent().unwrap().join("escape.toml").exists());
    // A file the studio was not opened with: refused by index, and the API takes no path.
    let (status, body) = send(&app, get("/api/scene?file=3")).await;
    assert_eq!(status, StatusCode::NOT_FOUND);
    assert!(error_of(&body).contains("reads no other"));
    let (status, _) = send(&app, get("/api/scene?file=/etc/passwd")).await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    let (status, _) = send(&app, get("/vendor/three/../../../Cargo.toml")).await;
    assert!(status == StatusCode::FORBIDDEN || status == StatusCode::NOT_FOUND);
    // Inside the folder it is written.
    let (status, body) = send(
        &app,
        post(
            "/api/smear/export",
            json!({"clip": "Wave", "style": style, "name": "styles/s.toml"}),
        ),
    )
    .await;
    assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&body));
    let written = std::fs::read_to_string(dir.path().join("styles/s.toml")).unwrap();
    assert!(smear::Style::from_toml_str(&written).is_ok());
}

#[tokio::test]
async fn bad_bodies_get_json_errors_and_the_server_keeps_serving() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    let raw = |body: Body| {
        Request::post("/api/smear/stylize")
            .header(header::HOST, HOST)
            .header(header::CONTENT_TYPE, "application/json")
            .body(body)
            .unwrap()
    };
    let (status, body) = send(&app, raw(Body::from("{not json"))).await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    assert!(error_of(&body).starts_with("request body"));
    let big = vec![b' '; studio::MAX_BODY_BYTES + 10];
    let (status, body) = send(&app, raw(Body::from(big))).await;
    assert_eq!(status, StatusCode::PAYLOAD_TOO_LARGE);
    error_of(&body);
    // An expression error is named, as the editor shows it inline.
    let bad_expr =
        json!({"clip": "Wave", "toml": "[elongate]\nfunction = { expr = \"2 * nosuchinput\" }"});
    let (status, body) = send(&app, post("/api/smear/stylize", bad_expr)).await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    assert!(
        error_of(&body).contains("nosuchinput"),
        "{}",
        error_of(&body)
    );
    let (status, body) = send(
        &app,
        post(
            "/api/loa/animate",
            json!({"keystrokes": [], "width": -1, "height": 1}),
        ),
    )
    .await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    error_of(&body);
    // A stiffness outside the documented range: a JSON error naming the range.
    let stroke = json!([[0, 0], [50, -30], [100, 0]]);
    let (status, body) = send(
        &app,
        post(
            "/api/loa/animate",
            json!({"keystrokes": [{"frame": 0, "points": stroke},
                                  {"frame": 12, "points": stroke, "stiffness": 540}],
                   "width": 640, "height": 480}),
        ),
    )
    .await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    assert!(error_of(&body).contains("[5, 100]"), "{}", error_of(&body));
    let (status, body) = send(&app, get("/api/nothing")).await;
    assert_eq!(status, StatusCode::NOT_FOUND);
    error_of(&body);
    let (status, _) = send(&app, get("/api/info")).await;
    assert_eq!(status, StatusCode::OK);
}

#[tokio::test]
async fn a_slider_change_restyles_without_solving_offsets_again() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    let style = |beta: f32| json!({"clip": "Wave", "style": {"elongate": {"function": {"stages": [{"op": "speed"}, {"op": "scale", "by": beta}]}}}});
    let a = send_ok(&app, post("/api/smear/stylize", style(0.0))).await;
    let solves = smear::offset_solves();
    let (_, b) = send(&app, post("/api/smear/stylize", style(12.0))).await;
    assert_eq!(
        smear::offset_solves(),
        solves,
        "restyling solved offsets again"
    );
    let (ha, body_a) = pack::read_f32(&a, "body").unwrap();
    let (_, body_b) = pack::read_f32(&b, "body").unwrap();
    let (_, scene) = send(&app, get("/api/scene?clip=Wave")).await;
    let (hs, input) = pack::read_f32(&scene, "positions").unwrap();
    assert_eq!(body_a.len(), input.len());
    assert_eq!(ha["frames"], hs["frames"]);
    // β = 0 is the input; β = 12 moves vertices.
    let diff = |x: &[f32], y: &[f32]| {
        x.iter()
            .zip(y)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max)
    };
    assert!(diff(&body_a, &input) < 1e-5);
    assert!(diff(&body_b, &input) > 1e-3);
}

#[tokio::test]
async fn a_restyle_of_the_current_frame_is_that_frame_of_the_whole_clip() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    let mut request = json!({"clip": "Wave", "style": {"elongate": {"function": {"stages": [{"op": "speed"}, {"op": "scale", "by": 8}]}}}});
    let whole = send_ok(&app, post("/api/smear/stylize", request.clone())).await;
    let (hw, all) = pack::read_f32(&whole, "body").unwrap();
    let frames = hw["frames"].as_u64().unwrap() as usize;
    assert_eq!(hw["clip_frames"], hw["frames"]);
    let per_frame = all.len() / frames;
    let f = frames / 2;
    request["frames"] = json!([f, f + 1]);
    let one = send_ok(&app, post("/api/smear/stylize", request.clone())).await;
    let (h1, body) = pack::read_f32(&one, "body").unwrap();
    assert_eq!(
        (h1["first_frame"].as_u64(), h1["frames"].as_u64()),
        (Some(f as u64), Some(1))
    );
    assert_eq!(h1["clip_frames"], hw["frames"]);
    assert_eq!(body, all[f * per_frame..(f + 1) * per_frame].to_vec());
    assert!(
        one.len() * 10 < whole.len(),
        "one frame is not smaller: {} vs {} bytes",
        one.len(),
        whole.len()
    );
    // A range past the clip is a JSON error, not a crash.
    request["frames"] = json!([frames, frames + 4]);
    let (status, body) = send(&app, post("/api/smear/stylize", request)).await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    assert!(error_of(&body).contains("frames"), "{}", error_of(&body));
}

#[tokio::test]
async fn strokes_give_a_line_through_them_and_a_moving_character() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    let (w, h) = (800.0, 600.0);
    let keys = common::bending_keystrokes();
    let (status, bytes) = send(
        &app,
        post(
            "/api/loa/animate",
            json!({"keystrokes": keys, "width": w, "height": h}),
        ),
    )
    .await;
    assert_eq!(
        status,
        StatusCode::OK,
        "{}",
        String::from_utf8_lossy(&bytes)
    );
    let (header, positions) = pack::read_f32(&bytes, "positions").unwrap();
    let (frames, vertices) = (
        header["motion"]["frames"].as_u64().unwrap() as usize,
        header["motion"]["vertices"].as_u64().unwrap() as usize,
    );
    assert!(frames >= 25);
    let first = &positions[..vertices * 3];
    let last = &positions[(frames - 1) * vertices * 3..frames * vertices * 3];
    let moved = first
        .iter()
        .zip(last)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    assert!(moved > 0.01, "the character did not move ({moved})");

    let (status, line) = send(&app, get("/api/loa/line")).await;
    assert_eq!(status, StatusCode::OK);
    let line: Value = serde_json::from_slice(&line).unwrap();
    for key in keys.as_array().unwrap() {
        let k = key["frame"].as_u64().unwrap();
        let stroke: Vec<[f64; 2]> = serde_json::from_value(key["points"].clone()).unwrap();
        let frame = line["frames"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["frame"] == k)
            .unwrap();
        let pts: Vec<[f64; 2]> = serde_json::from_value(frame["points"].clone()).unwrap();
        let far = stroke
            .iter()
            .map(|p| {
                pts.iter()
                    .map(|q| (p[0] - q[0]).hypot(p[1] - q[1]))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max);
        assert!(
            far < 30.0,
            "frame {k}: the line passes {far} px from the stroke"
        );
    }
    // The current frame first: the same keystrokes with `frame` give that motion frame only,
    // and `GET /api/loa/motion` the rest of that answer (a stale version is refused).
    let (status, fast) = send(
        &app,
        post(
            "/api/loa/animate",
            json!({"keystrokes": keys, "width": w, "height": h, "frame": 12}),
        ),
    )
    .await;
    assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&fast));
    let (hf, one) = pack::read_f32(&fast, "positions").unwrap();
    let k = (12 - header["motion"]["first_frame"].as_i64().unwrap()) as usize;
    assert_eq!(hf["motion"]["positions_first"].as_u64(), Some(k as u64));
    assert_eq!(
        one,
        positions[k * vertices * 3..(k + 1) * vertices * 3].to_vec()
    );
    let version = hf["version"].as_u64().unwrap();
    assert_eq!(version, header["version"].as_u64().unwrap() + 1);
    let (status, rest) = send(&app, get(&format!("/api/loa/motion?version={version}"))).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(pack::read_f32(&rest, "positions").unwrap().1, positions);
    let (status, body) = send(
        &app,
        get(&format!("/api/loa/motion?version={}", version - 1)),
    )
    .await;
    assert_eq!(status, StatusCode::CONFLICT);
    error_of(&body);
    // Exports.
    for (name, what) in [
        ("k.json", "keystrokes"),
        ("l.json", "line"),
        ("m.glb", "motion"),
        ("m.bvh", "motion"),
    ] {
        let (status, body) = send(
            &app,
            post("/api/loa/export", json!({"name": name, "what": what})),
        )
        .await;
        assert_eq!(
            status,
            StatusCode::OK,
            "{name}: {}",
            String::from_utf8_lossy(&body)
        );
    }
    let keys = std::fs::read_to_string(dir.path().join("k.json")).unwrap();
    assert!(loa::Keystrokes::from_json_str(&keys).is_ok());
}

#[tokio::test]
async fn two_seeds_give_two_parts_on_a_worker_thread() {
    let dir = tempfile::tempdir().unwrap();
    let s = studio_with(
        &["characters/RobotExpressive.glb", "face/ict-face-talk.glb"],
        dir.path(),
    );
    let app = router(s, PORT);
    let (_, scene) = send(&app, get("/api/scene?file=1")).await;
    let (header, positions) = pack::read_f32(&scene, "positions").unwrap();
    let (_, data) = pack::split(&scene).unwrap();
    let tri_entry = header["buffers"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["name"] == "triangles")
        .unwrap()
        .clone();
    let count = tri_entry["count"].as_u64().unwrap() as usize / 3;
    let tris: Vec<u32> = data[..count * 12]
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    // The highest and the lowest triangle (forehead / chin) as the two seeds.
    let y = |t: usize| {
        (0..3)
            .map(|k| positions[tris[t * 3 + k] as usize * 3 + 1])
            .sum::<f32>()
    };
    let top = (0..count).max_by(|&a, &b| y(a).total_cmp(&y(b))).unwrap() as u32;
    let bottom = (0..count).min_by(|&a, &b| y(a).total_cmp(&y(b))).unwrap() as u32;
    let (status, body) = send(
        &app,
        post(
            "/api/stopmo/segment",
            json!({"file": 1, "seeds": [[top], [bottom]]}),
        ),
    )
    .await;
    assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&body));
    let id = serde_json::from_slice::<Value>(&body).unwrap()["job"]
        .as_u64()
        .unwrap();
    // The server answers while the job runs.
    let (status, _) = send(&app, get("/api/info")).await;
    assert_eq!(status, StatusCode::OK);
    let mut result = Value::Null;
    for _ in 0..1200 {
        let (_, st) = send(&app, get(&format!("/api/jobs/{id}"))).await;
        let st: Value = serde_json::from_slice(&st).unwrap();
        match st["state"].as_str().unwrap() {
            "running" => tokio::time::sleep(std::time::Duration::from_millis(100)).await,
            "done" => {
                result = st["result"].clone();
                break;
            }
            other => panic!("job {other}: {}", st["error"]),
        }
    }
    let labels: Vec<u32> = serde_json::from_value(result["triangle_part"].clone()).unwrap();
    assert_eq!(labels.len(), count);
    assert_eq!(labels[top as usize], 0);
    assert_eq!(labels[bottom as usize], 1);
    let ones = labels.iter().filter(|&&l| l == 1).count();
    assert!(
        ones > count / 20 && ones < count * 19 / 20,
        "{ones} of {count}"
    );
    // Bad seeds are a JSON error, not a crash.
    let (status, body) = send(
        &app,
        post("/api/stopmo/segment", json!({"file": 1, "seeds": [[top]]})),
    )
    .await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    error_of(&body);
    // A seed past the mesh is the request's error, before any job starts.
    let past = json!({"file": 1, "seeds": [[top], [4_000_000_000u32]]});
    let (status, body) = send(&app, post("/api/stopmo/segment", past)).await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    assert!(
        error_of(&body).contains("triangle 4000000000 of part 2 is past the mesh's"),
        "{}",
        String::from_utf8_lossy(&body)
    );
    let (status, _) = send(&app, post("/api/jobs/999/cancel", json!({}))).await;
    assert_eq!(status, StatusCode::NOT_FOUND);
}

#[tokio::test]
async fn the_loa_view_gives_the_keystroke_ranges_and_defaults_of_the_loa_crate() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    let (status, body) = send(&app, get("/api/loa/view?file=0")).await;
    assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&body));
    let view: Value = serde_json::from_slice(&body).unwrap();
    for (name, range, default) in [
        ("stiffness", loa::STIFFNESS_RANGE, loa::DEFAULT_STIFFNESS),
        ("damping", loa::DAMPING_RANGE, loa::DEFAULT_DAMPING),
    ] {
        assert_eq!(
            view[name],
            json!({"range": [range.start(), range.end()], "default": default}),
            "{name}"
        );
    }
}
