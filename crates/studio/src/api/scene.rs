//! `GET /api/info` and `GET /api/scene`: what is open, and a clip's mesh per frame.

use std::sync::Arc;

use axum::extract::{Query, State};
use axum::response::Response;
use axum::Json;
use serde::Deserialize;
use serde_json::{json, Value};

use crate::error::ApiResult;
use crate::pack::Pack;
use crate::state::Studio;

/// A file index and clip name (query string).
#[derive(Debug, Deserialize)]
pub(crate) struct ClipQuery {
    /// Opened file index.
    #[serde(default)]
    pub(crate) file: usize,
    /// Clip name (empty: the first clip).
    #[serde(default)]
    pub(crate) clip: String,
}

/// `GET /api/info`.
pub(crate) async fn info(State(studio): State<Arc<Studio>>) -> Json<Value> {
    let files: Vec<Value> = studio
        .files
        .iter()
        .enumerate()
        .map(|(i, f)| {
            json!({
                "index": i,
                "name": f.label(),
                "clips": f.clips(),
                "character": f.scene().is_some_and(|s| !s.skins.is_empty()),
            })
        })
        .collect();
    Json(json!({
        "files": files,
        "out_dir": studio.out_dir.display().to_string(),
    }))
}

/// `GET /api/scene?file=&clip=`: `triangles` (u32), `positions` (f32, frames × vertices × 3).
pub(crate) async fn scene(
    State(studio): State<Arc<Studio>>,
    Query(q): Query<ClipQuery>,
) -> ApiResult<Response> {
    super::blocking(move || {
        let label = studio.file(q.file)?.label();
        let clip = studio.sampled(q.file, &q.clip)?;
        let header = json!({"file": q.file, "clip": q.clip, "name": label});
        // The positions go out from the cached clip itself, not from a copy.
        let mut pack = Pack::new();
        let m = clip.merged();
        pack.u32("triangles", m.mesh.triangles.iter().flatten().copied());
        let header = describe(m, header);
        pack.shared("positions", clip.clone(), |c| c.coordinates());
        Ok(pack.response(header))
    })
    .await
}

/// `header` with the animation's frames, vertices, triangles, fps and bounding box.
fn describe(m: &anim::MeshAnimation, mut header: Value) -> Value {
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in m.positions() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if let Value::Object(h) = &mut header {
        h.insert("frames".into(), json!(m.frame_count()));
        h.insert("vertices".into(), json!(m.vertex_count()));
        h.insert("triangle_count".into(), json!(m.mesh.triangles.len()));
        h.insert("fps".into(), json!(m.fps));
        h.insert("bbox".into(), json!([lo, hi]));
    }
    header
}
