//! The loa panel: strokes drawn over the viewport become keystrokes; `loa::line` gives the
//! dynamic line of action (LoA Section 3) and `loa::animate` the character motion that
//! follows it (LoA Section 4).
//!
//! The page draws through the action camera of [`view`] (the glTF front view fitted to the
//! character, orthographic, as `loa animate` uses by default), so a stroke's pixels map onto
//! the image plane with a [`ScreenMap`] from the canvas size: the character follows the line
//! where it was drawn.

use std::sync::Arc;
use std::time::Instant;

use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{Query, State};
use axum::response::{IntoResponse, Response};
use axum::Json;
use loa::animate::{ActionCamera, AnimateOptions, Character, InitialPose, Preset};
use loa::job;
use serde::Deserialize;
use serde_json::{json, Value};

use super::{blocking, body, on_core_pool};
use crate::error::{ApiError, ApiResult};
use crate::files::{merged, output_path};
use crate::loa_skin::{Binding, CheckedSkin};
use crate::pack::{coordinates, Pack};
use crate::state::{lock, LoaCharacter, LoaSession, Studio};

/// A file index (query string).
#[derive(Debug, Deserialize)]
pub(crate) struct FileQuery {
    #[serde(default)]
    file: usize,
}

/// The character of file `file` at `fps`, prepared once ([`LoaCharacter`]) and shared by
/// every later stroke at that rate (another rate replaces it: one per file is kept).
fn character(studio: &Studio, file: usize, fps: f64) -> ApiResult<Arc<LoaCharacter>> {
    if let Some(c) = lock(&studio.characters).get(&file).filter(|c| c.fps == fps) {
        return Ok(c.clone());
    }
    let f = studio.file(file)?;
    let label = f.label();
    let scene = f.scene().ok_or_else(|| {
        ApiError::bad(format!(
            "{label}: not a character (open a skinned glTF/GLB or a BVH file)"
        ))
    })?;
    let character = Character::from_scene(scene, &InitialPose::Rest, fps)
        .map_err(|e| ApiError::bad(format!("{label}: {e}")))?;
    let (lo, hi) = character.bounds();
    let prepared = Arc::new(LoaCharacter {
        label,
        fps,
        camera: ActionCamera::front_fitted(lo, hi),
        vertices: scene.meshes.iter().map(|m| m.mesh.vertex_count()).sum(),
        character,
        skin: std::sync::OnceLock::new(),
    });
    lock(&studio.characters).insert(file, prepared.clone());
    Ok(prepared)
}

/// `GET /api/loa/view?file=`: the action camera (`center`, `right`, `up`, `forward`,
/// `half_height`), the bone-set presets, the joints, the keystrokes' `stiffness` and
/// `damping` (`{"range": [lo, hi], "default"}`, the loa crate's) and the rest pose's mesh
/// (buffers `triangles`, `positions`: one frame).
pub(crate) async fn view(
    State(studio): State<Arc<Studio>>,
    Query(q): Query<FileQuery>,
) -> ApiResult<Json<Value>> {
    blocking(move || {
        let c = character(&studio, q.file, loa::DEFAULT_FPS)?;
        let presets: Vec<&str> = Preset::ALL.iter().map(|(_, n)| *n).collect();
        Ok(Json(json!({
            "camera": c.camera,
            "presets": presets,
            "joints": c.character.joint_names(),
            "stiffness": {
                "range": [loa::STIFFNESS_RANGE.start(), loa::STIFFNESS_RANGE.end()],
                "default": loa::DEFAULT_STIFFNESS,
            },
            "damping": {
                "range": [loa::DAMPING_RANGE.start(), loa::DAMPING_RANGE.end()],
                "default": loa::DEFAULT_DAMPING,
            },
        })))
    })
    .await
}

/// One keystroke as the page sends it.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PageKeystroke {
    frame: i64,
    /// Canvas pixels (y down).
    points: Vec<[f64; 2]>,
    #[serde(default)]
    stiffness: Option<f64>,
    #[serde(default)]
    damping: Option<f64>,
    /// Bone-set preset (or joint list) the character follows from this keystroke on.
    #[serde(default)]
    bones: Option<String>,
}

/// `POST /api/loa/animate` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct AnimateRequest {
    #[serde(default)]
    file: usize,
    keystrokes: Vec<PageKeystroke>,
    /// Canvas size in pixels (the strokes' screen).
    width: f64,
    height: f64,
    #[serde(default)]
    fps: Option<f64>,
    /// Drag-to-wobble impulses (`loa::Wobble`).
    #[serde(default)]
    wobbles: Vec<loa::Wobble>,
    /// The timeline frame on screen: `positions` then holds only that motion frame (clamped
    /// to the motion) and the page fetches the rest from `GET /api/loa/motion`.
    #[serde(default)]
    frame: Option<i64>,
    /// The page skins the motion itself ([`super::loa_skin`]): the binding id it holds (`""`
    /// for none). The answer then carries the pose (`skin.world`, and the binding when its
    /// id differs) instead of `positions`, whenever the pose reproduces the core's positions.
    #[serde(default)]
    skin: Option<String>,
}

/// `GET /api/loa/motion` query: the `version` of the animate answer the page drew.
#[derive(Debug, Deserialize)]
pub(crate) struct MotionQuery {
    version: u64,
}

/// The keystroke JSON of `loa line` (what the page's strokes export as).
fn keystrokes_json(r: &AnimateRequest, fps: f64) -> Value {
    let keys: Vec<Value> = r
        .keystrokes
        .iter()
        .map(|k| {
            let mut v = json!({"frame": k.frame, "points": k.points});
            if let Some(s) = k.stiffness {
                v["stiffness"] = json!(s);
            }
            if let Some(d) = k.damping {
                v["damping"] = json!(d);
            }
            v
        })
        .collect();
    json!({"fps": fps, "keystrokes": keys})
}

/// `POST /api/loa/animate`: buffers `line` (f32, line frames × joints × 2, canvas pixels),
/// `positions` (f32, every motion frame × vertices × 3 in one answer — or only the motion
/// frame `motion.positions_first` when the request names a `frame`; or, when the request
/// asks for `skin` and `motion.skin` is set, the pose `skin.world` and the binding
/// [`super::loa_skin`] instead), `triangles` (u32);
/// `version` names the answer for `GET /api/loa/motion`.
pub(crate) async fn animate(
    State(studio): State<Arc<Studio>>,
    request: Result<Bytes, BytesRejection>,
) -> ApiResult<Response> {
    let r: AnimateRequest = body(request)?;
    if !(r.width > 0.0 && r.height > 0.0 && r.width.is_finite() && r.height.is_finite()) {
        return Err(ApiError::bad("width and height must be positive"));
    }
    blocking(move || {
        let start = Instant::now();
        let fps = r.fps.unwrap_or(loa::DEFAULT_FPS);
        let keys_json = keystrokes_json(&r, fps);
        let keys = loa::Keystrokes::from_json_str(&keys_json.to_string()).map_err(|e| {
            let over = matches!(e, loa::LoaError::OverBudget(_));
            ApiError::refused(format!("keystrokes: {e}"), over)
        })?;
        let mut options = loa::LineOptions::default();
        options.physics.fps = fps;
        options.wobbles = r.wobbles.clone();
        // The line first (the job's first half), so the sampled motion's memory is reserved
        // before the solve.
        let line = on_core_pool(|| loa::line(&keys, &options)).map_err(|e| {
            let over = matches!(e, loa::LoaError::OverBudget(_));
            ApiError::refused(format!("line: {e}"), over)
        })?;
        let line_seconds = start.elapsed().as_secs_f64();

        let prepared = character(&studio, r.file, fps)?;
        let label = &prepared.label;
        let f = studio.file(r.file)?;
        let scene = f
            .scene()
            .ok_or_else(|| ApiError::bad(format!("{label}: not a character")))?;
        // The motion is sampled over the line's frames on every vertex the file's meshes
        // have (as `anim::sample` counts them): reserved before the solve and the sampling.
        let held = studio.reserve(
            r.file,
            &anim::SampledScene::merged_memory(line.animation.frames.len(), prepared.vertices),
        )?;
        let mut bone_sets = Vec::new();
        for k in &r.keystrokes {
            if let Some(b) = k.bones.as_deref().filter(|b| !b.is_empty()) {
                let key = format!("{b}@{}", k.frame);
                let set: loa::animate::BoneSetKey = key
                    .parse()
                    .map_err(|e: loa::animate::AnimateError| ApiError::bad(format!("bones {b}: {e}")))?;
                bone_sets.push(set);
            }
        }
        let options = job::SceneOptions {
            motion: AnimateOptions {
                bone_sets,
                ..Default::default()
            },
            canvas: Some([r.width, r.height]),
            ..Default::default()
        };
        // The pose serves a whole-motion answer to a page that skins (a one-frame answer
        // sends that frame's positions).
        let want_pose = r.skin.is_some() && r.frame.is_none();
        let motion = on_core_pool(|| follow(scene, &prepared, line, &options, want_pose))?;
        let Motion {
            done,
            merged,
            pose,
            frames: motion_frames,
            vertices,
            triangles,
        } = motion;
        let (motion, line) = (&done.motion, &done.line);
        let animate_seconds = start.elapsed().as_secs_f64() - line_seconds;

        let frames = &line.animation.frames;
        let joints = frames.first().map_or(0, |f| f.chain.joints().len());
        let mut pack = Pack::new();
        pack.keep(held);
        pack.f32(
            "line",
            frames
                .iter()
                .flat_map(|f| f.chain.joints().into_iter().flat_map(|p| [p.x as f32, p.y as f32])),
        );
        pack.u32("triangles", triangles.iter().flatten().copied());
        let mut skin = Value::Null;
        let shown = match (r.frame, pose, &merged) {
            // The skeleton's pose for every frame; the binding when the page lacks it.
            (None, Some((checked, world)), _) => {
                let binding = &checked.binding;
                if r.skin.as_deref() != Some(binding.id.as_str()) {
                    binding.pack(&mut pack);
                }
                pack.shared("skin.world", world, |w| &w[..]);
                skin = json!({"id": binding.id, "nodes": binding.node_count()});
                0..motion_frames
            }
            (Some(f), _, Some(m)) => {
                let k = (f - motion.first_frame).clamp(0, motion_frames.max(1) as i64 - 1) as usize;
                pack.f32_slices("positions", [coordinates(m.frame(k))]);
                k..k + 1
            }
            // The whole motion in this answer: sent from the session's copy, not another.
            (None, None, Some(m)) => {
                pack.shared("positions", m.clone(), |m| coordinates(m.positions()));
                0..motion_frames
            }
            _ => return Err(ApiError::internal("the motion was neither sampled nor posed")),
        };
        let sampled_vertices = merged.is_some();
        let mut session = lock(&studio.loa);
        let version = session.as_ref().map_or(1, |s| s.version + 1);
        let rep = &motion.report;
        let header = json!({
            "line": {
                "first_frame": frames.first().map_or(0, |f| f.frame),
                "frames": frames.len(),
                "joints": joints,
                "keystroke_frames": line.animation.keystroke_frames,
            },
            "motion": {
                "first_frame": motion.first_frame,
                "frames": motion_frames,
                "vertices": vertices,
                "fps": motion.fps,
                "positions_first": shown.start,
                "positions_frames": shown.len(),
                "skin": skin,
                // Whether every vertex was sampled for this answer (not when the character's
                // binding was checked by an earlier stroke and the pose is sent).
                "sampled_vertices": sampled_vertices,
            },
            "version": version,
            "warnings": line.warnings,
            "report": {
                "line_distance_mean": rep.line_distance_mean,
                "line_distance_p95": rep.line_distance_p95,
                "line_distance_worst": rep.line_distance_worst,
                "max_rotation_step": rep.max_rotation_step,
                "height": rep.height,
            },
            "keystrokes": keys_json,
            "seconds": {"line": line_seconds, "animate": animate_seconds, "total": start.elapsed().as_secs_f64()},
        });
        *session = Some(LoaSession {
            file: r.file,
            keys,
            keys_json: keys_json.to_string(),
            merged: merged.map(std::sync::OnceLock::from).unwrap_or_default(),
            version,
            done,
        });
        Ok(pack.response(header))
    })
    .await
}

/// The motion of a stroke: the core's result, its frame and vertex counts and triangles,
/// the character's meshes merged over every motion frame (unless the pose is sent: sampled
/// on first use then), and the skeleton's pose per frame with the checked binding when the
/// page asked for it and skinning reproduces the merged meshes ([`Binding::pose`]).
struct Motion {
    done: job::SceneMotion,
    merged: Option<Arc<anim::MeshAnimation>>,
    pose: Option<(Arc<CheckedSkin>, Vec<f32>)>,
    frames: usize,
    vertices: usize,
    triangles: Arc<Vec<[u32; 3]>>,
}

/// The character of `scene` following `line` (`loa::animate`), sampled at the line's frame
/// rate ([`motion_sampling`]): as the pose alone when `want_pose` and the character's binding was checked before, else every
/// vertex merged, with the pose when `want_pose` and skinning reproduces it (the binding is
/// then kept as checked). The stroke's computation: it takes no lock and waits on nothing
/// (it runs on the core's pool, [`on_core_pool`]).
fn follow(
    scene: &anim::Scene,
    prepared: &LoaCharacter,
    line: loa::Line,
    options: &job::SceneOptions,
    want_pose: bool,
) -> ApiResult<Motion> {
    let label = &prepared.label;
    let refused = |e| sampling_refused(label, e);
    let done = job::animate_character(scene, &prepared.character, line, options).map_err(|e| {
        let over = e.over_budget();
        ApiError::refused(format!("{label}: {e}"), over)
    })?;
    let out = &done.scene;
    let sampling = motion_sampling(&done)?;
    if let Some(checked) = prepared.skin.get().filter(|_| want_pose) {
        let (frames, node_world) = anim::sample_node_world(out, &sampling).map_err(refused)?;
        if let Some(world) = checked.binding.world(&node_world, frames) {
            return Ok(Motion {
                done,
                merged: None,
                pose: Some((checked.clone(), world)),
                frames,
                vertices: checked.binding.vertex_count(),
                triangles: checked.triangles.clone(),
            });
        }
    }
    let sampled = anim::sample(out, &sampling).map_err(refused)?;
    let m = merged(label, &sampled)?;
    let triangles = Arc::new(m.mesh.triangles.clone());
    let pose = want_pose
        .then(|| Binding::new(out, &sampled))
        .flatten()
        .and_then(|b| b.pose(&sampled, &m).map(|w| (b, w)))
        .map(|(binding, world)| {
            let checked = Arc::new(CheckedSkin {
                binding,
                triangles: triangles.clone(),
            });
            // Another stroke may have checked it meanwhile: either is the same binding.
            let _ = prepared.skin.set(checked.clone());
            (checked, world)
        });
    Ok(Motion {
        frames: m.frame_count(),
        vertices: m.vertex_count(),
        triangles,
        done,
        merged: Some(Arc::new(m)),
        pose,
    })
}

/// A sampling error of `label`'s motion: 413 when over a budget, else 400.
fn sampling_refused(label: &str, e: anim::AnimError) -> ApiError {
    let over = matches!(e, anim::AnimError::OverBudget(_));
    ApiError::refused(format!("{label}: {e}"), over)
}

/// How the motion's clip is sampled: the synthesized clip of `done`'s scene at the line's
/// frame rate, every mesh.
fn motion_sampling(done: &job::SceneMotion) -> ApiResult<anim::SampleOptions> {
    let clip = done
        .scene
        .find_clip(loa::animate::CLIP_NAME)
        .map_err(|e| ApiError::internal(e.to_string()))?;
    Ok(anim::SampleOptions {
        fps: done.motion.fps as f32,
        clip: Some(clip),
        meshes: Vec::new(),
    })
}

/// `GET /api/loa/motion?version=`: buffer `positions` (f32, every motion frame × vertices × 3)
/// of the animate answer `version`; a newer answer exists → 409 (the page drops it).
pub(crate) async fn motion(
    State(studio): State<Arc<Studio>>,
    Query(q): Query<MotionQuery>,
) -> ApiResult<Response> {
    blocking(move || {
        // The memory of sampling the motion, when the answer sent the pose, is reserved
        // before the session is locked again (a stroke holding memory waits for that lock).
        let sampling = {
            let guard = lock(&studio.loa);
            let s = current(&guard, q.version)?;
            let vertices = s
                .done
                .scene
                .meshes
                .iter()
                .map(|m| m.mesh.vertex_count())
                .sum();
            s.merged
                .get()
                .is_none()
                .then(|| (s.file, s.done.motion.frames(), vertices))
        };
        let _held = match sampling {
            Some((file, frames, vertices)) => {
                Some(studio.reserve(file, &anim::SampledScene::merged_memory(frames, vertices))?)
            }
            None => None,
        };
        let guard = lock(&studio.loa);
        let s = current(&guard, q.version)?;
        let merged = match s.merged.get() {
            Some(m) => m.clone(),
            // The answer sent the pose: the core's positions are sampled now, once.
            None => {
                let label = studio.file(s.file)?.label();
                let sampled = anim::sample(&s.done.scene, &motion_sampling(&s.done)?)
                    .map_err(|e| sampling_refused(&label, e))?;
                let m = Arc::new(merged(&label, &sampled)?);
                s.merged.get_or_init(|| m).clone()
            }
        };
        let mut pack = Pack::new();
        pack.shared("positions", merged, |m| coordinates(m.positions()));
        Ok(pack.response(json!({ "version": s.version })))
    })
    .await
}

/// The session of the animate answer `version`: none yet or a newer one → 409.
fn current(session: &Option<LoaSession>, version: u64) -> ApiResult<&LoaSession> {
    let s = session
        .as_ref()
        .ok_or_else(|| ApiError::conflict("no line yet: draw keystrokes first"))?;
    if s.version != version {
        return Err(ApiError::conflict(format!(
            "motion {version} was replaced by motion {}",
            s.version
        )));
    }
    Ok(s)
}

/// `GET /api/loa/line`: the last line in the CLI's JSON layout (`toonkit loa line -o x.json`).
pub(crate) async fn line(State(studio): State<Arc<Studio>>) -> ApiResult<Response> {
    let guard = lock(&studio.loa);
    let s = guard
        .as_ref()
        .ok_or_else(|| ApiError::conflict("no line yet: draw keystrokes first"))?;
    let text = s.done.line.animation.to_json_string();
    Ok((
        [(axum::http::header::CONTENT_TYPE, "application/json")],
        text,
    )
        .into_response())
}

/// `POST /api/loa/export` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ExportRequest {
    /// File name in the output folder: `.json` with `what = "keystrokes"` or `"line"`,
    /// `.svg` (line onion skin), `.glb` / `.bvh` (the motion).
    name: String,
    #[serde(default)]
    what: Option<String>,
}

/// `POST /api/loa/export`.
pub(crate) async fn export(
    State(studio): State<Arc<Studio>>,
    request: Result<Bytes, BytesRejection>,
) -> ApiResult<Json<Value>> {
    let r: ExportRequest = body(request)?;
    let path = output_path(&studio.out_dir, &r.name)?;
    blocking(move || {
        let guard = lock(&studio.loa);
        let s = guard
            .as_ref()
            .ok_or_else(|| ApiError::conflict("no line yet: draw keystrokes first"))?;
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        let io = |e: String| ApiError::internal(format!("{}: {e}", r.name));
        let text = |t: &str| {
            tkio::save(&path, &tkio::Output::Text(t))
                .map(|_| ())
                .map_err(|e| ApiError::from_io(&e))
        };
        match (ext.as_str(), r.what.as_deref()) {
            ("json", Some("keystrokes")) => text(&s.keys_json)?,
            ("json", _) => text(&s.done.line.animation.to_json_string())?,
            ("svg", _) => text(&loa::to_svg_string(&s.done.line.animation, Some(&s.keys)))?,
            ("glb" | "bvh", _) => s.done.save(&path).map_err(|e| match e {
                job::SceneJobError::Write(e) => ApiError::from_io(&e),
                e => io(e.to_string()),
            })?,
            _ => {
                return Err(ApiError::bad(format!(
                "{}: export keystrokes/line as .json, the line as .svg, the motion as .glb or .bvh",
                r.name
            )))
            }
        }
        Ok(Json(json!({ "written": path.display().to_string() })))
    })
    .await
}
