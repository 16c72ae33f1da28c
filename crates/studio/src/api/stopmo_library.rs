//! The stopmo panel's later half, on the last segmentation: the library size versus error
//! curve (StopShop Fig. 8) as a job, a click on a point builds that library from the
//! curve's own solve (`stopmo::library_of`), its reconstruction plays beside the original
//! with the piece id of every part per frame, and the library folder (the `stopmo run`
//! layout) is exported into the output folder.

use std::sync::Arc;

use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::State;
use axum::response::Response;
use axum::Json;
use serde::Deserialize;
use serde_json::{json, Value};
use stopmo::{LibraryJobOptions, LibraryResult, SizeCurve};

use super::{blocking, body};
use crate::error::{ApiError, ApiResult};
use crate::files::output_path;
use crate::memory::Reservation;
use crate::pack::{coordinates, Pack};
use crate::state::{lock, Studio};

/// Most sizes one curve request may solve.
pub(crate) const MAX_SIZES: usize = 32;

/// The sizes of a curve when the page gives none: small libraries, where the curve bends.
const DEFAULT_SIZES: [usize; 6] = [1, 2, 3, 4, 6, 8];

/// `POST /api/stopmo/curve` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct CurveRequest {
    /// Pieces per part at every point (default 1, 2, 3, 4, 6, 8).
    #[serde(default)]
    sizes: Vec<usize>,
}

/// `POST /api/stopmo/build` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct BuildRequest {
    /// Pieces per part: a point of the curve.
    pieces: usize,
    /// Print the pieces as solids (default); `false` stops at their surfaces, labels and
    /// errors, ~10× sooner on the face (`LibraryJobOptions::print`).
    #[serde(default = "printed_by_default")]
    print: bool,
    /// A disc magnet, `"DxH"` in millimetres (`LibraryJobOptions::magnets`).
    #[serde(default)]
    magnets: Option<stopmo::library::MagnetOptions>,
    /// Clearance of fits in millimetres (default from the printer resolution).
    #[serde(default)]
    clearance_mm: Option<f64>,
    /// `"stl"`, `"3mf"` or `"stl,3mf"`.
    #[serde(default)]
    print_format: stopmo::PrintFormat,
    /// Build plate of `library.3mf` (millimetres).
    #[serde(default = "default_plate")]
    plate_mm: [f64; 2],
    /// Wall thickness of the pieces in millimetres (default
    /// `stopmo::library::DEFAULT_THICKNESS_MM`): a magnet pocket needs its depth and a wall.
    #[serde(default)]
    thickness_mm: Option<f64>,
    /// The printer's thinnest wall in millimetres (default `stopmo::DEFAULT_MIN_WALL_MM`).
    #[serde(default)]
    min_wall_mm: Option<f64>,
    /// The printer's smallest free-standing feature in millimetres (default
    /// `stopmo::DEFAULT_MIN_FEATURE_MM`).
    #[serde(default)]
    min_feature_mm: Option<f64>,
}

fn default_plate() -> [f64; 2] {
    LibraryJobOptions::default().plate_mm
}

fn printed_by_default() -> bool {
    LibraryJobOptions::default().print
}

/// `POST /api/stopmo/export` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ExportRequest {
    /// The folder to write, relative to the output folder.
    folder: String,
}

/// The last segmentation's version and parts, or a conflict error telling what to do.
fn parts_of(studio: &Studio) -> ApiResult<(u64, Arc<Vec<anim::MeshAnimation>>)> {
    lock(&studio.stopmo)
        .as_ref()
        .map(|s| (s.version, s.parts.clone()))
        .ok_or_else(|| ApiError::conflict("stopmo: run the segmentation first"))
}

/// `POST /api/stopmo/curve`: `{"job": id}`; the result is `{"points": [{pieces,
/// total_pieces, energy, mean_error_mm, max_error_mm}], "segmentation"}`.
pub(crate) async fn curve(
    State(studio): State<Arc<Studio>>,
    request: Result<Bytes, BytesRejection>,
) -> ApiResult<Json<Value>> {
    let r: CurveRequest = body(request)?;
    let sizes = if r.sizes.is_empty() {
        DEFAULT_SIZES.to_vec()
    } else {
        r.sizes
    };
    if sizes.len() > MAX_SIZES || sizes.contains(&0) {
        return Err(ApiError::bad(format!(
            "sizes: give 1 to {MAX_SIZES} library sizes of at least 1 piece per part"
        )));
    }
    let (version, parts) = parts_of(&studio)?;
    let frames = parts.first().map_or(0, |p| p.frame_count());
    if let Some(d) = sizes.iter().find(|&&d| d > frames) {
        return Err(ApiError::bad(format!(
            "sizes: {d} pieces per part is more than the clip's {frames} frames"
        )));
    }
    let held = reserve_library(&studio, &parts).await?;
    let job_studio = studio.clone();
    let id = studio.jobs.start("stopmo.curve", move |progress| {
        let _held = held;
        let mut on_point = |done: usize, total: usize| {
            let stage = format!("library size {} of {total}", (done + 1).min(total));
            progress
                .stage(&stage, done as f32 / total.max(1) as f32)
                .is_ok()
        };
        let curve =
            stopmo::size_curve(&parts, &LibraryJobOptions::default(), &sizes, &mut on_point)
                .map_err(|e| format!("size curve: {e}"))?;
        if progress.cancelled() {
            return Err("cancelled".into());
        }
        let points = curve.points.clone();
        if let Some(s) = lock(&job_studio.stopmo).as_mut() {
            if s.version == version {
                s.curve = Some(Arc::new(curve));
                s.built = None;
            }
        }
        Ok(json!({ "points": points, "segmentation": version }))
    });
    Ok(Json(json!({ "job": id })))
}

/// `POST /api/stopmo/build` (`{"pieces", "print"?, "magnets"?: "DxH", "clearance_mm"?,
/// "print_format"?: "stl"|"3mf"|"stl,3mf", "plate_mm"?: [w, d], "thickness_mm"?, "min_wall_mm"?,
/// "min_feature_mm"?}`): `{"job": id}`; the result is
/// `{"pieces", "parts", "frame_ids" (per frame, the piece id of every part), "errors_mm",
/// "total_pieces", "printed", "warnings"}`.
pub(crate) async fn build(
    State(studio): State<Arc<Studio>>,
    request: Result<Bytes, BytesRejection>,
) -> ApiResult<Json<Value>> {
    let r: BuildRequest = body(request)?;
    let (version, parts, curve): (u64, _, Arc<SizeCurve>) = {
        let session = lock(&studio.stopmo);
        let s = session
            .as_ref()
            .ok_or_else(|| ApiError::conflict("stopmo: run the segmentation first"))?;
        let curve = s.curve.clone().ok_or_else(|| {
            ApiError::conflict("stopmo: compute the size curve first, then pick a point")
        })?;
        (s.version, s.parts.clone(), curve)
    };
    if curve.library(r.pieces).is_none() {
        let sizes: Vec<String> = curve.points.iter().map(|p| p.pieces.to_string()).collect();
        return Err(ApiError::bad(format!(
            "pieces: {} is not a point of the curve (sizes {})",
            r.pieces,
            sizes.join(", ")
        )));
    }
    let held = reserve_library(&studio, &parts).await?;
    let job_studio = studio.clone();
    let id = studio.jobs.start("stopmo.build", move |progress| {
        let _held = held;
        let cancelled = |e: crate::jobs::Cancelled| e.to_string();
        progress
            .stage("pieces, assembly and reconstruction", 0.1)
            .map_err(cancelled)?;
        let solved = curve.library(r.pieces).ok_or("the curve lost its point")?;
        let options = LibraryJobOptions {
            print: r.print,
            magnets: r.magnets,
            clearance_mm: r.clearance_mm,
            print_format: r.print_format,
            plate_mm: r.plate_mm,
            thickness_mm: r
                .thickness_mm
                .unwrap_or(stopmo::library::DEFAULT_THICKNESS_MM),
            min_wall_mm: r.min_wall_mm.unwrap_or(stopmo::DEFAULT_MIN_WALL_MM),
            min_feature_mm: r.min_feature_mm.unwrap_or(stopmo::DEFAULT_MIN_FEATURE_MM),
            ..LibraryJobOptions::default()
        };
        let result =
            stopmo::library_of(&parts, &options, solved).map_err(|e| format!("library: {e}"))?;
        progress.stage("done", 1.0).map_err(cancelled)?;
        let answer = json!({
            "pieces": r.pieces,
            "total_pieces": result.library.total_pieces(),
            "parts": result.part_names,
            "frame_ids": result.frame_ids(),
            "errors_mm": result.library.errors_mm,
            "printed": result.report.printing.is_some(),
            // Thin walls, crossing triangles, pieces below the printer resolution.
            "warnings": result.report.warnings,
            "segmentation": version,
        });
        if let Some(s) = lock(&job_studio.stopmo).as_mut() {
            if s.version == version {
                s.built = Some(Arc::new(result));
            }
        }
        Ok(answer)
    });
    Ok(Json(json!({ "job": id })))
}

/// Reserves what a library job of `parts` holds ([`stopmo::library_memory`]) for the job,
/// waiting on the blocking pool.
async fn reserve_library(
    studio: &Arc<Studio>,
    parts: &Arc<Vec<anim::MeshAnimation>>,
) -> ApiResult<Reservation> {
    let (pool, parts) = (studio.memory.clone(), parts.clone());
    blocking(move || pool.reserve("stopmo library", &stopmo::library_memory(&parts))).await
}

/// The built library, or a conflict error telling what to do.
fn built_of(studio: &Studio) -> ApiResult<Arc<LibraryResult>> {
    lock(&studio.stopmo)
        .as_ref()
        .and_then(|s| s.built.clone())
        .ok_or_else(|| ApiError::conflict("stopmo: build a library from the curve first"))
}

/// `GET /api/stopmo/reconstruction`: the built library's reconstruction as its pieces and
/// the piece of every frame (StopShop Section 5: each frame *is* one piece per part), not
/// every frame expanded — a clip of 1,440 frames is a few pieces. Buffers `triangles` (u32,
/// every part merged in part order), `pieces` (f32, part by part: its pieces × its vertices
/// × 3, model units), `labels` (u32, frames × parts: the piece each part shows); the header
/// has `parts`, `part_vertices`, `part_pieces`, `frame_ids`, `frames`, `vertices`, `bbox`.
pub(crate) async fn reconstruction(State(studio): State<Arc<Studio>>) -> ApiResult<Response> {
    let built = built_of(&studio)?;
    blocking(move || {
        let parts = &built.library.parts;
        let meshes: Vec<&anim::Mesh> = built.reconstruction.iter().map(|r| &r.mesh).collect();
        if meshes.len() != parts.len() {
            return Err(ApiError::internal(
                "reconstruction: parts and pieces disagree",
            ));
        }
        let frames = parts.first().map_or(0, |p| p.solution.labels.len());
        let mut pack = Pack::new();
        let mut base = 0u32;
        let mut triangles = Vec::new();
        for m in &meshes {
            triangles.extend(m.triangles.iter().flatten().map(|&v| v + base));
            base += m.positions.len() as u32;
        }
        pack.u32("triangles", triangles);
        let pieces = parts.iter().flat_map(|p| p.solution.pieces.iter());
        pack.f32_slices("pieces", pieces.clone().map(|piece| coordinates(piece)));
        pack.u32(
            "labels",
            (0..frames).flat_map(|f| parts.iter().map(move |p| p.solution.labels[f])),
        );
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for q in pieces.flatten() {
            for k in 0..3 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        Ok(pack.response(json!({
            "parts": built.part_names,
            "part_vertices": meshes.iter().map(|m| m.positions.len()).collect::<Vec<_>>(),
            "part_pieces": parts.iter().map(|p| p.solution.pieces.len()).collect::<Vec<_>>(),
            "frame_ids": built.frame_ids(),
            "frames": frames,
            "vertices": base,
            "bbox": [lo, hi],
        })))
    })
    .await
}

/// `POST /api/stopmo/export`: writes the built library's folder (the `stopmo run` layout:
/// pieces, assembly, reconstruction, report) to `folder` inside the output folder.
pub(crate) async fn export(
    State(studio): State<Arc<Studio>>,
    request: Result<Bytes, BytesRejection>,
) -> ApiResult<Json<Value>> {
    let r: ExportRequest = body(request)?;
    let dir = output_path(&studio.out_dir, &r.folder)?;
    let built = built_of(&studio)?;
    blocking(move || {
        if dir.is_file() {
            return Err(ApiError::bad(format!(
                "{}: is a file; give a folder name",
                r.folder
            )));
        }
        let files = built
            .files()
            .map_err(|e| ApiError::internal(format!("library files: {e}")))?;
        let written =
            tkio::save_files(&dir, &files).map_err(|e| ApiError::internal(e.to_string()))?;
        let mut names: Vec<String> = written
            .iter()
            .filter_map(|p| p.strip_prefix(&studio.out_dir).ok())
            .map(|p| p.display().to_string())
            .collect();
        names.sort();
        Ok(Json(
            json!({ "folder": dir.display().to_string(), "written": names }),
        ))
    })
    .await
}
