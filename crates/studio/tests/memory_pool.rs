//! The studio's memory pool through real requests: requests each under the job budget that
//! run at once share one pool; the ones that do not fit beside the others are answered 503
//! (one JSON line saying the studio is busy, retry), the others succeed, a request over the
//! whole pool is 413, and once the others are done the next request succeeds.

mod common;

use std::sync::Arc;
use std::time::Duration;

use anim::budget::JobMemory;
use axum::http::StatusCode;
use axum::Router;
use serde_json::{json, Value};
use studio::files::{output_folder, OpenedFile};
use studio::memory::MemoryPool;
use studio::{router, Studio};

use common::{error_of, post, send, PORT};

const CLIP: &str = "Wave";

/// A style with motion lines on every frame: heavy enough that requests sent together run
/// together.
const STYLE: &str = "[elongate]\n[lines]\ncount = 200\n";

/// The robot's studio, its clip prepared, and what one stylize request of [`STYLE`] reserves
/// (the smear crate's estimate, `smear::stylize_memory`).
fn robot(out: &std::path::Path) -> (Studio, u64) {
    let opened =
        vec![OpenedFile::open(&testdata::asset("characters/RobotExpressive.glb")).unwrap()];
    let studio = Studio::new(opened, output_folder(out).unwrap());
    let p = studio.prepared(0, CLIP).unwrap();
    let mut style = smear::Style::from_toml_str(STYLE).unwrap();
    style.offsets = p.options().offsets.clone();
    let estimate = smear::stylize_memory(&p, &style, 0..p.report().frames)
        .unwrap()
        .total();
    (studio, estimate)
}

/// The router over `studio` with `pool` as its memory pool.
fn app(studio: Studio, pool: &Arc<MemoryPool>) -> Router {
    router(Arc::new(studio.with_memory_pool(pool.clone())), PORT)
}

fn stylize() -> axum::http::Request<axum::body::Body> {
    post("/api/smear/stylize", json!({"clip": CLIP, "toml": STYLE}))
}

/// `n` stylize requests sent at once (each on its own task); their answers.
async fn at_once(app: &Router, n: usize) -> Vec<(StatusCode, Vec<u8>)> {
    let tasks: Vec<_> = (0..n)
        .map(|_| {
            let app = app.clone();
            tokio::spawn(async move { send(&app, stylize()).await })
        })
        .collect();
    let mut answers = Vec::new();
    for t in tasks {
        answers.push(t.await.unwrap());
    }
    answers
}

fn assert_busy(status: StatusCode, body: &[u8]) {
    assert_eq!(
        status,
        StatusCode::SERVICE_UNAVAILABLE,
        "{}",
        String::from_utf8_lossy(body)
    );
    let e = error_of(body);
    assert!(
        e.contains("busy with other jobs") && e.contains("retry") && !e.contains('\n'),
        "{e}"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn concurrent_requests_over_the_pool_get_503_for_the_excess_and_the_next_succeeds() {
    let dir = tempfile::tempdir().unwrap();
    let (studio, estimate) = robot(dir.path());
    // Room for one request, not two; no wait, so the excess is refused at once.
    let pool = MemoryPool::new(estimate * 3 / 2, Duration::ZERO);
    let app = app(studio, &pool);
    let answers = at_once(&app, 8).await;
    let (mut ok, mut busy) = (0, 0);
    for (status, body) in answers {
        if status == StatusCode::OK {
            ok += 1;
        } else {
            assert_busy(status, &body);
            busy += 1;
        }
    }
    assert!(ok >= 1 && busy >= 1, "{ok} succeeded, {busy} refused");
    // Every answer was sent: nothing stays reserved, and the next request succeeds.
    assert_eq!(pool.reserved(), 0);
    let (status, body) = send(&app, stylize()).await;
    assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&body));
    assert_eq!(pool.reserved(), 0);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_request_beside_a_running_job_is_503_until_that_job_gives_its_memory_back() {
    let dir = tempfile::tempdir().unwrap();
    let (studio, estimate) = robot(dir.path());
    let pool = MemoryPool::new(estimate * 3 / 2, Duration::from_millis(50));
    let app = app(studio, &pool);
    // Another job holds the pool: stylize, animate and segment are each refused with 503.
    let whole = pool.capacity();
    let running = pool
        .reserve(
            "another job",
            &JobMemory::new().bytes("a running job", whole),
        )
        .unwrap();
    let (status, body) = send(&app, stylize()).await;
    assert_busy(status, &body);
    let keys = common::bending_keystrokes();
    let animate = json!({"keystrokes": keys, "width": 800, "height": 600});
    let (status, body) = send(&app, post("/api/loa/animate", animate.clone())).await;
    assert_busy(status, &body);
    let (status, body) = send(
        &app,
        post(
            "/api/stopmo/segment",
            json!({"clip": CLIP, "seeds": [[0], [1]]}),
        ),
    )
    .await;
    assert_busy(status, &body);
    assert_eq!(pool.reserved(), whole, "only the running job holds memory");
    // Once it is done, the same requests succeed.
    drop(running);
    let (status, body) = send(&app, stylize()).await;
    assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&body));
    let (status, body) = send(&app, post("/api/loa/animate", animate)).await;
    assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&body));
    assert_eq!(pool.reserved(), 0);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn requests_that_fit_one_after_another_wait_for_each_other_within_the_wait() {
    let dir = tempfile::tempdir().unwrap();
    let (studio, estimate) = robot(dir.path());
    // Room for one at a time, and a wait longer than three requests take.
    let pool = MemoryPool::new(estimate, Duration::from_secs(120));
    let app = app(studio, &pool);
    let answers = at_once(&app, 3).await;
    for (status, body) in answers {
        assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&body));
    }
    assert_eq!(pool.reserved(), 0);
}

#[tokio::test]
async fn a_request_larger_than_the_whole_pool_is_413_naming_its_memory() {
    let dir = tempfile::tempdir().unwrap();
    let (studio, estimate) = robot(dir.path());
    let pool = MemoryPool::new(estimate / 2, Duration::ZERO);
    let app = app(studio, &pool);
    let (status, body) = send(&app, stylize()).await;
    assert_eq!(status, StatusCode::PAYLOAD_TOO_LARGE);
    let e = error_of(&body);
    assert!(
        e.starts_with("RobotExpressive.glb: memory of the job (")
            && e.contains("is over the limit of"),
        "{e}"
    );
    // A smaller request still fits.
    let v: Value = json!({"clip": CLIP, "toml": "[elongate]\n", "frames": [0, 1]});
    let (status, body) = send(&app, post("/api/smear/stylize", v)).await;
    assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&body));
}
