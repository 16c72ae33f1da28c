//! Helpers shared by the studio's API tests: the router on bundled assets, answering as the
//! local server, and requests with the local `Host`.
// Each test binary uses some of these.
#![allow(dead_code)]

use std::path::Path;
use std::sync::Arc;

use axum::body::{to_bytes, Body};
use axum::http::{header, Request, StatusCode};
use axum::Router;
use serde_json::Value;
use studio::files::{output_folder, OpenedFile};
use studio::{router, Studio};
use tower::ServiceExt;

pub(crate) const PORT: u16 = 8765;
pub(crate) const HOST: &str = "127.0.0.1:8765";

pub(crate) fn studio_with(files: &[&str], out: &Path) -> Arc<Studio> {
    let opened = files
        .iter()
        .map(|f| OpenedFile::open(&testdata::asset(f)).unwrap())
        .collect();
    Arc::new(Studio::new(opened, output_folder(out).unwrap()))
}

pub(crate) fn app(out: &Path) -> Router {
    router(studio_with(&["characters/RobotExpressive.glb"], out), PORT)
}

pub(crate) async fn send(app: &Router, req: Request<Body>) -> (StatusCode, Vec<u8>) {
    let res = app.clone().oneshot(req).await.unwrap();
    let status = res.status();
    (
        status,
        to_bytes(res.into_body(), usize::MAX)
            .await
            .unwrap()
            .to_vec(),
    )
}

/// Sends a request that must succeed (200) and returns the body; a failure shows the body.
pub(crate) async fn send_ok(app: &Router, req: Request<Body>) -> Vec<u8> {
    let (status, body) = send(app, req).await;
    assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&body));
    body
}

pub(crate) fn get(uri: &str) -> Request<Body> {
    Request::get(uri)
        .header(header::HOST, HOST)
        .body(Body::empty())
        .unwrap()
}

pub(crate) fn post(uri: &str, body: Value) -> Request<Body> {
    Request::post(uri)
        .header(header::HOST, HOST)
        .header(header::CONTENT_TYPE, "application/json")
        .body(Body::from(body.to_string()))
        .unwrap()
}

pub(crate) fn error_of(bytes: &[u8]) -> String {
    let v: Value = serde_json::from_slice(bytes).expect("a JSON error body");
    v["error"]
        .as_str()
        .expect("an \"error\" string")
        .to_string()
}

/// Three keystrokes on an 800×600 canvas at frames 0, 12 and 24: a vertical arc bending
/// from left to right (a line of action with anticipation and follow-through to animate).
pub(crate) fn bending_keystrokes() -> Value {
    let arc = |bend: f64| -> Vec<[f64; 2]> {
        (0..=20)
            .map(|i| {
                let t = i as f64 / 20.0;
                [
                    400.0 + bend * (std::f64::consts::PI * t).sin(),
                    150.0 + 300.0 * t,
                ]
            })
            .collect()
    };
    serde_json::json!([
        {"frame": 0, "points": arc(-60.0)},
        {"frame": 12, "points": arc(0.0)},
        {"frame": 24, "points": arc(60.0)},
    ])
}
