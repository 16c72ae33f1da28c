//! The stopmo panel: part seeds clicked on the mesh → `stopmo::segment` (StopShop Section 4:
//! multi-label graph cut, StopShop Eqs. 1–3) on a worker thread; the page polls
//! `/api/jobs/{id}` and colours the input triangles by `triangle_part` and draws the seams.
//! Then the size-versus-error curve (StopShop Fig. 8) as a job, a library built from one
//! of its points, its reconstruction and the export of its folder (see `stopmo_library`).

use std::sync::Arc;

use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::State;
use axum::Json;
use serde::Deserialize;
use serde_json::{json, Value};
use stopmo::segment::{PartSpec, Seed};
use stopmo::SegmentJobOptions;

use super::body;
use crate::error::{ApiError, ApiResult};
use crate::state::{lock, StopmoSession, Studio};

/// Most parts a segmentation request may ask for.
pub(crate) const MAX_PARTS: usize = 16;

/// `POST /api/stopmo/segment` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SegmentRequest {
    #[serde(default)]
    file: usize,
    #[serde(default)]
    clip: String,
    /// Per part, the seed triangles (indices into `/api/scene`'s triangles).
    seeds: Vec<Vec<u32>>,
    /// Part names (default `part1`, `part2`, ...).
    #[serde(default)]
    names: Vec<String>,
}

/// `POST /api/stopmo/segment`: `{"job": id}` at once; the job's result is
/// `{"summary", "triangle_part" (per input triangle), "parts"}`.
pub(crate) async fn segment(
    State(studio): State<Arc<Studio>>,
    request: Result<Bytes, BytesRejection>,
) -> ApiResult<Json<Value>> {
    let r: SegmentRequest = body(request)?;
    if r.seeds.len() < 2 || r.seeds.len() > MAX_PARTS {
        return Err(ApiError::bad(format!(
            "seeds: give 2 to {MAX_PARTS} parts, each with at least one seed triangle"
        )));
    }
    if let Some(i) = r.seeds.iter().position(Vec::is_empty) {
        return Err(ApiError::bad(format!("seeds: part {} has no seed", i + 1)));
    }
    // The clip is sampled and the seeds checked here, before the job starts: a clip over a
    // budget or a seed past the mesh is the request's error (4xx), not a failed job.
    let label = studio.file(r.file)?.label();
    let (clip, held) = {
        let studio = studio.clone();
        let (file, clip, label) = (r.file, r.clip.clone(), label.clone());
        super::blocking(move || {
            let clip = studio.sampled(file, &clip)?;
            stopmo::check_segment_memory(clip.merged())
                .map_err(|e| ApiError::too_large(format!("{label}: {e}")))?;
            // Held by the job until it ends (done, failed, cancelled or panicked).
            let held = studio.reserve(file, &stopmo::segment_memory(clip.merged()))?;
            Ok((clip, held))
        })
        .await?
    };
    let parts = part_specs(&r, clip.merged().mesh.triangles.len())?;
    let job_studio = studio.clone();
    let id = studio.jobs.start("stopmo.segment", move |progress| {
        let cancelled = |e: crate::jobs::Cancelled| e.to_string();
        let options = SegmentJobOptions {
            parts,
            ..Default::default()
        };
        progress
            .stage("graph cut and homogenization", 0.2)
            .map_err(cancelled)?;
        let _held = held;
        // The parts will hold the clip's frames: the cached clip is handed to the job (a new
        // segmentation samples it again), whose cut grows in its buffer instead of copying it
        // and is given back as the parts are filled (the clip resident about once).
        job_studio.forget_clip(r.file, &r.clip);
        let input = crate::files::Clip::into_merged(clip);
        let s = stopmo::segment_into_parts(input, &options).map_err(|e| format!("{label}: {e}"))?;
        progress.stage("done", 1.0).map_err(cancelled)?;
        let (seam_vertices, seam_weights) = seam_lines(&s);
        let mut answer = json!({
            "summary": s.summary(),
            "triangle_part": s.segmentation.input_triangle_part,
            "parts": s.segmentation.part_names,
            "seam_vertices": seam_vertices,
            "seam_weights": seam_weights,
            "seconds": s.seconds,
        });
        // The parts move into the session (the curve's input), not copied beside `s`.
        let version = job_studio.store_segmentation(s.parts.into_iter().map(|p| p.animation));
        answer["segmentation"] = json!(version);
        Ok(answer)
    });
    Ok(Json(json!({ "job": id })))
}

/// The parts of a segmentation request: each part's seed triangles (checked against the
/// mesh's `triangles`) and its name.
fn part_specs(r: &SegmentRequest, triangles: usize) -> ApiResult<Vec<PartSpec>> {
    let mut parts = Vec::new();
    for (i, seeds) in r.seeds.iter().enumerate() {
        if let Some(t) = seeds.iter().find(|&&t| t as usize >= triangles) {
            return Err(ApiError::bad(format!(
                "seeds: triangle {t} of part {} is past the mesh's {triangles}",
                i + 1
            )));
        }
        let name = r
            .names
            .get(i)
            .cloned()
            .unwrap_or_else(|| format!("part{}", i + 1));
        parts.push(PartSpec::new(
            name,
            seeds.iter().map(|&t| Seed::Triangle(t)).collect(),
        ));
    }
    Ok(parts)
}

/// The seams as line segments over the input mesh: point `2i` and `2i + 1` bound segment
/// `i`; every point is `Σ w_k x_{v_k}` of three input vertices (so the page places it on
/// any frame of the clip it shows). Returns (vertices, weights), three per point.
fn seam_lines(s: &stopmo::Segmented) -> (Vec<u32>, Vec<f32>) {
    use stopmo::segment::VertexSource;
    let mut vertices = Vec::new();
    let mut weights = Vec::new();
    for v in s.seam_edges().into_iter().flatten() {
        let (v3, w3) = match s.segmentation.cut.sources.get(v as usize) {
            Some(VertexSource::Original(a)) => ([*a; 3], [1.0, 0.0, 0.0]),
            Some(VertexSource::Edge { a, b, t }) => ([*a, *b, *b], [1.0 - *t, *t, 0.0]),
            Some(VertexSource::Interior { v, w }) => (*v, *w),
            None => ([0; 3], [0.0; 3]),
        };
        vertices.extend(v3);
        weights.extend(w3.map(|w| w as f32));
    }
    (vertices, weights)
}

impl Studio {
    /// Keeps a finished segmentation's parts for the curve; returns its version.
    fn store_segmentation(&self, parts: impl Iterator<Item = anim::MeshAnimation>) -> u64 {
        let mut session = lock(&self.stopmo);
        let version = session.as_ref().map_or(1, |old| old.version + 1);
        *session = Some(StopmoSession {
            version,
            parts: std::sync::Arc::new(parts.collect()),
            curve: None,
            built: None,
        });
        version
    }
}
