//! The stopmo panel's later half through the router, on the bundled face: segment (seams
//! returned) → size-versus-error curve job → build a point's library → its reconstruction
//! with the assembly's piece per frame → export of the library folder, confined to `--out`.

use std::time::Duration;

use axum::body::Body;
use axum::http::{header, Request, StatusCode};
use axum::Router;
use serde_json::{json, Value};
use studio::{pack, router};

mod common;
use common::{send, studio_with, HOST, PORT};

/// The router with the face opened, answering as the local server on port 8765.
struct Client {
    app: Router,
}

impl Client {
    fn face(out: &std::path::Path) -> Client {
        Client {
            app: router(studio_with(&["face/ict-face-talk.glb"], out), PORT),
        }
    }

    /// Status and body of `method uri` (JSON body for POST).
    async fn call(&self, method: &str, uri: &str, body: Option<Value>) -> (StatusCode, Vec<u8>) {
        let req = Request::builder()
            .method(method)
            .uri(uri)
            .header(header::HOST, HOST)
            .header(header::CONTENT_TYPE, "application/json")
            .body(body.map_or_else(Body::empty, |b| Body::from(b.to_string())))
            .unwrap();
        send(&self.app, req).await
    }

    /// Starts a job with `POST uri body` and waits for its result.
    async fn job(&self, uri: &str, body: Value) -> Value {
        let (status, answer) = self.call("POST", uri, Some(body)).await;
        assert_eq!(
            status,
            StatusCode::OK,
            "{}",
            String::from_utf8_lossy(&answer)
        );
        let id = serde_json::from_slice::<Value>(&answer).unwrap()["job"].clone();
        for _ in 0..6000 {
            let (_, st) = self.call("GET", &format!("/api/jobs/{id}"), None).await;
            let st: Value = serde_json::from_slice(&st).unwrap();
            match st["state"].as_str() {
                Some("running") => tokio::time::sleep(Duration::from_millis(100)).await,
                Some("done") => return st["result"].clone(),
                _ => panic!("{uri}: {st}"),
            }
        }
        panic!("{uri}: the job did not finish in 10 minutes")
    }

    /// The JSON error of a refused request, with its status.
    async fn refused(&self, method: &str, uri: &str, body: Option<Value>) -> (StatusCode, String) {
        let (status, bytes) = self.call(method, uri, body).await;
        let v: Value = serde_json::from_slice(&bytes).expect("a JSON error");
        (status, v["error"].as_str().expect("an error string").into())
    }
}

/// The highest and lowest triangle of the face's first frame (forehead and chin).
fn forehead_and_chin(scene: &[u8]) -> (u32, u32) {
    let (_, positions) = pack::read_f32(scene, "positions").unwrap();
    let (header, data) = pack::split(scene).unwrap();
    let count = header["triangle_count"].as_u64().unwrap() as usize;
    let corner = |t: usize, k: usize| {
        let at = (t * 3 + k) * 4;
        u32::from_le_bytes(data[at..at + 4].try_into().unwrap()) as usize
    };
    let height = |t: &usize| {
        (0..3)
            .map(|k| positions[corner(*t, k) * 3 + 1])
            .sum::<f32>()
    };
    let top = (0..count).max_by(|a, b| height(a).total_cmp(&height(b)));
    let bottom = (0..count).min_by(|a, b| height(a).total_cmp(&height(b)));
    (top.unwrap() as u32, bottom.unwrap() as u32)
}

#[tokio::test]
async fn segment_curve_build_reconstruct_and_export_the_library_folder() {
    let out = tempfile::tempdir().unwrap();
    let c = Client::face(out.path());
    // Before a segmentation, the later steps say what to do first.
    let (status, e) = c
        .refused("POST", "/api/stopmo/curve", Some(json!({})))
        .await;
    assert_eq!(status, StatusCode::CONFLICT);
    assert!(e.contains("segmentation first"), "{e}");

    let (_, scene) = c.call("GET", "/api/scene", None).await;
    let (top, bottom) = forehead_and_chin(&scene);
    let seg = c
        .job("/api/stopmo/segment", json!({"seeds": [[top], [bottom]]}))
        .await;
    // Seams: segments of two points, each three input vertices with weights summing to 1.
    let seam_v = seg["seam_vertices"].as_array().unwrap();
    let seam_w: Vec<f64> = serde_json::from_value(seg["seam_weights"].clone()).unwrap();
    assert!(
        seam_v.len() >= 6 * 10 && seam_v.len() % 6 == 0,
        "{}",
        seam_v.len()
    );
    assert_eq!(seam_w.len(), seam_v.len());
    assert!(seam_w
        .chunks(3)
        .all(|w| (w.iter().sum::<f64>() - 1.0).abs() < 1e-4));

    let (status, e) = c
        .refused("POST", "/api/stopmo/build", Some(json!({"pieces": 2})))
        .await;
    assert_eq!(status, StatusCode::CONFLICT, "{e}");
    let (status, e) = c
        .refused("POST", "/api/stopmo/curve", Some(json!({"sizes": [0]})))
        .await;
    assert_eq!(status, StatusCode::BAD_REQUEST, "{e}");

    let curve = c
        .job("/api/stopmo/curve", json!({"sizes": [1, 3, 2]}))
        .await;
    let points = curve["points"].as_array().unwrap();
    let sizes: Vec<u64> = points
        .iter()
        .map(|p| p["pieces"].as_u64().unwrap())
        .collect();
    assert_eq!(sizes, [1, 2, 3]);
    let error = |i: usize| points[i]["mean_error_mm"].as_f64().unwrap();
    assert!(error(2) < error(0), "{points:?}");
    assert_eq!(points[1]["total_pieces"], 4);

    let (status, e) = c
        .refused("POST", "/api/stopmo/build", Some(json!({"pieces": 5})))
        .await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    assert!(e.contains("not a point of the curve"), "{e}");
    let built = c.job("/api/stopmo/build", json!({"pieces": 2})).await;
    assert_eq!(built["total_pieces"], 4);
    let frame_ids: Vec<Vec<String>> = serde_json::from_value(built["frame_ids"].clone()).unwrap();

    // The reconstruction: every part merged, the assembly's piece on every frame — sent as
    // the pieces and the piece of every frame, expanded here as the page does.
    let (status, recon) = c.call("GET", "/api/stopmo/reconstruction", None).await;
    assert_eq!(status, StatusCode::OK);
    let (header, pieces) = pack::read_f32(&recon, "pieces").unwrap();
    let labels = pack::read_u32(&recon, "labels").unwrap();
    let frames = header["frames"].as_u64().unwrap() as usize;
    let vertices = header["vertices"].as_u64().unwrap() as usize;
    let part_vertices: Vec<usize> =
        serde_json::from_value(header["part_vertices"].clone()).unwrap();
    let part_pieces: Vec<usize> = serde_json::from_value(header["part_pieces"].clone()).unwrap();
    assert_eq!(header["frame_ids"], built["frame_ids"]);
    assert_eq!(frame_ids.len(), frames);
    assert_eq!(part_vertices.iter().sum::<usize>(), vertices);
    assert_eq!(part_pieces, [2, 2]);
    let sizes = part_vertices.iter().zip(&part_pieces);
    assert_eq!(pieces.len(), sizes.map(|(v, p)| v * p * 3).sum::<usize>());
    assert_eq!(labels.len(), frames * part_vertices.len());
    let mut positions = Vec::with_capacity(frames * vertices * 3);
    for f in 0..frames {
        let mut start = 0;
        for (i, (&n, &p)) in part_vertices.iter().zip(&part_pieces).enumerate() {
            let k = labels[f * part_vertices.len() + i] as usize;
            assert!(k < p, "frame {f}: piece {k} of {p}");
            positions.extend_from_slice(&pieces[start + k * n * 3..start + (k + 1) * n * 3]);
            start += p * n * 3;
        }
    }
    // Two pieces per part: some frames show different pieces, and frames showing the same
    // pieces show the same geometry (a replacement face, not the animation).
    let frame = |f: usize| &positions[f * vertices * 3..(f + 1) * vertices * 3];
    let other = (1..frames)
        .find(|&f| frame_ids[f] != frame_ids[0])
        .expect("a frame with other pieces");
    assert_ne!(frame(0), frame(other));
    let same = (1..frames)
        .find(|&f| frame_ids[f] == frame_ids[0])
        .expect("a frame with the same pieces");
    assert_eq!(frame(0), frame(same));
    let ids: std::collections::BTreeSet<&String> = frame_ids.iter().flatten().collect();
    assert_eq!(ids.len(), 4, "{ids:?}");

    // Export: the `stopmo run` layout under --out, and no way out of it.
    for bad in ["../x", "/tmp/x", "a/../../x"] {
        let (status, e) = c
            .refused("POST", "/api/stopmo/export", Some(json!({"folder": bad})))
            .await;
        assert_eq!(status, StatusCode::FORBIDDEN, "{bad}: {e}");
    }
    assert!(!out.path().parent().unwrap().join("x").exists());
    let (status, answer) = c
        .call(
            "POST",
            "/api/stopmo/export",
            Some(json!({"folder": "libs/face"})),
        )
        .await;
    assert_eq!(
        status,
        StatusCode::OK,
        "{}",
        String::from_utf8_lossy(&answer)
    );
    let answer: Value = serde_json::from_slice(&answer).unwrap();
    let written: Vec<String> = serde_json::from_value(answer["written"].clone()).unwrap();
    let dir = out.path().join("libs/face");
    for f in [
        "assembly.csv",
        "report.json",
        "reconstruction.pc2",
        "pieces/part1_00.stl",
        "pieces/part2_01.stl",
    ] {
        assert!(dir.join(f).is_file(), "{f} missing; written: {written:?}");
        assert!(
            written.contains(&format!("libs/face/{f}")),
            "{f}: {written:?}"
        );
    }
    // The build answer carries the printing warnings the exported report has.
    let report: Value =
        serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap();
    assert!(built["warnings"].is_array(), "{built}");
    assert_eq!(built["warnings"], report["warnings"]);
    let csv = std::fs::read_to_string(dir.join("assembly.csv")).unwrap();
    assert!(csv.starts_with("frame,part1,part2\n"), "{csv:.80}");
    assert_eq!(csv.lines().count(), frames + 1);
    assert_eq!(built["printed"], true);

    // Without printing: the same library (pieces and assembly), surfaces but no solids.
    let surfaces = c
        .job("/api/stopmo/build", json!({"pieces": 2, "print": false}))
        .await;
    assert_eq!(surfaces["printed"], false);
    assert_eq!(surfaces["frame_ids"], built["frame_ids"]);
    assert_eq!(surfaces["errors_mm"], built["errors_mm"]);
    let (status, _) = c
        .call(
            "POST",
            "/api/stopmo/export",
            Some(json!({"folder": "libs/surfaces"})),
        )
        .await;
    assert_eq!(status, StatusCode::OK);
    let pieces: Vec<String> = std::fs::read_dir(out.path().join("libs/surfaces/pieces"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(pieces.contains(&"part1_00.obj".to_string()), "{pieces:?}");
    assert!(!pieces.iter().any(|f| f.ends_with(".stl")), "{pieces:?}");
    let report: Value = serde_json::from_slice(
        &std::fs::read(out.path().join("libs/surfaces/report.json")).unwrap(),
    )
    .unwrap();
    assert!(report["printing"].is_null(), "{}", report["printing"]);
}
