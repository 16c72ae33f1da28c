//! The API under `/api`: JSON in, JSON or packed float32 buffers ([`crate::pack`]) out.
//!
//! | route | what |
//! |---|---|
//! | `GET /api/info` | opened files, clips, output folder |
//! | `GET /api/scene?file=&clip=` | the clip's merged mesh: triangles + positions per frame |
//! | `GET /api/smear/presets` | the example styles (SMEAR Figs. 11–16) |
//! | `GET /api/smear/offsets?file=&clip=` | motion offsets per frame and vertex (prepared once) |
//! | `POST /api/smear/stylize` | a style → elongated body (or what changed), multiples, lines (all frames or a range) |
//! | `POST /api/smear/export` | writes the result (glb/usda/usdc/abc) or the style (toml) |
//! | `GET /api/smear/weight-sources?file=&clip=` | the file's weight groups / attributes (picker) |
//! | `GET /api/smear/weights?file=&clip=&source=` | ω per vertex of one weight source (overlay) |
//! | `GET /api/loa/view?file=` | the action camera the strokes are drawn through |
//! | `POST /api/loa/animate` | keystrokes → line of action + character motion (positions, or the skeleton's pose) |
//! | `GET /api/loa/motion?version=` | the rest of an animate answer's character motion |
//! | `GET /api/loa/line` | the last line in the CLI's JSON layout |
//! | `POST /api/loa/export` | keystrokes / line (json, svg) / motion (glb, bvh) |
//! | `POST /api/stopmo/segment` | part seeds → a segmentation job (parts, seams) |
//! | `POST /api/stopmo/curve` | library size versus error (StopShop Fig. 8) → a job |
//! | `POST /api/stopmo/build` | a point of the curve → a job building that library |
//! | `GET /api/stopmo/reconstruction` | the built library's reconstruction, piece ids per frame |
//! | `POST /api/stopmo/export` | writes the library folder (the `stopmo run` layout) |
//! | `GET /api/jobs/{id}`, `POST /api/jobs/{id}/cancel` | progress, result, cancel |

mod changes;
mod loa_api;
mod scene;
mod shown;
mod smear_api;
mod stopmo_api;
mod stopmo_library;

use std::sync::Arc;

use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{Path, State};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde::de::DeserializeOwned;
use serde_json::Value;

use crate::error::{ApiError, ApiResult};
use crate::jobs::JobStatus;
use crate::state::Studio;

/// The API routes.
pub fn routes() -> Router<Arc<Studio>> {
    Router::new()
        .route("/api/info", get(scene::info))
        .route("/api/scene", get(scene::scene))
        .route("/api/smear/presets", get(smear_api::presets))
        .route("/api/smear/offsets", get(smear_api::offsets))
        .route("/api/smear/stylize", post(smear_api::stylize))
        .route("/api/smear/export", post(smear_api::export))
        .route("/api/smear/weight-sources", get(smear_api::weight_sources))
        .route("/api/smear/weights", get(smear_api::weights))
        .route("/api/loa/view", get(loa_api::view))
        .route("/api/loa/animate", post(loa_api::animate))
        .route("/api/loa/motion", get(loa_api::motion))
        .route("/api/loa/line", get(loa_api::line))
        .route("/api/loa/export", post(loa_api::export))
        .route("/api/stopmo/segment", post(stopmo_api::segment))
        .route("/api/stopmo/curve", post(stopmo_library::curve))
        .route("/api/stopmo/build", post(stopmo_library::build))
        .route(
            "/api/stopmo/reconstruction",
            get(stopmo_library::reconstruction),
        )
        .route("/api/stopmo/export", post(stopmo_library::export))
        .route("/api/jobs/{id}", get(job))
        .route("/api/jobs/{id}/cancel", post(cancel))
}

/// A JSON request body; a body too large, not JSON, or of the wrong shape is a JSON error.
pub(crate) fn body<T: DeserializeOwned>(body: Result<Bytes, BytesRejection>) -> ApiResult<T> {
    let bytes = body.map_err(|r| ApiError {
        status: r.status(),
        message: format!("request body: {}", r.body_text()),
    })?;
    serde_json::from_slice(&bytes).map_err(|e| ApiError::bad(format!("request body: {e}")))
}

/// Runs `work` on the blocking pool, so the server keeps answering meanwhile.
pub(crate) async fn blocking<T, F>(work: F) -> ApiResult<T>
where
    T: Send + 'static,
    F: FnOnce() -> ApiResult<T> + Send + 'static,
{
    tokio::task::spawn_blocking(work)
        .await
        .map_err(|_| ApiError::internal("the request stopped on an internal error"))?
}

/// Runs `work` as a task of the core's thread pool (rayon's) and waits for it: its parallel
/// loops then split on the worker running it, instead of each being handed over from this
/// thread and waited for (a stroke's solver runs one per iteration, hundreds in all;
/// docs/studio.md, "Figures"). `work` must take no lock and wait on nothing: the pool may run
/// it on a worker that suspended another request's loop, which would then wait for it.
pub(crate) fn on_core_pool<R: Send>(work: impl FnOnce() -> R + Send) -> R {
    rayon::scope(|_| work())
}

/// `GET /api/jobs/{id}`.
async fn job(State(studio): State<Arc<Studio>>, Path(id): Path<u64>) -> ApiResult<Json<JobStatus>> {
    studio
        .jobs
        .status(id)
        .map(Json)
        .ok_or_else(|| ApiError::not_found(format!("job {id}: no such job")))
}

/// `POST /api/jobs/{id}/cancel`.
async fn cancel(State(studio): State<Arc<Studio>>, Path(id): Path<u64>) -> ApiResult<Json<Value>> {
    if studio.jobs.cancel(id) {
        Ok(Json(serde_json::json!({ "cancelled": id })))
    } else {
        Err(ApiError::not_found(format!("job {id}: no such job")))
    }
}

#[cfg(test)]
mod tests {
    use super::on_core_pool;
    use rayon::prelude::*;

    #[test]
    fn a_request_computes_on_the_core_pool_and_its_loops_split_there() {
        // From an outside thread (the server's blocking pool), as a request runs.
        let (inside, sum) = std::thread::spawn(|| {
            on_core_pool(|| {
                let inside = rayon::current_thread_index().is_some();
                let sum: u64 = (0..10_000u64).into_par_iter().map(|x| x * x).sum();
                (inside, sum)
            })
        })
        .join()
        .unwrap();
        assert!(inside, "the work ran outside rayon's pool");
        assert_eq!(sum, (0..10_000u64).map(|x| x * x).sum::<u64>());
    }
}
