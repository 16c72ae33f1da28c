//! The smear panel: offsets prepared once per file and clip ([`Studio::prepared`]), then
//! `smear::stylize` per change — elongated in-betweens (SMEAR Eq. 10), multiples (SMEAR
//! Eqs. 11–12) and motion lines (SMEAR Eq. 13) back as float32 buffers.

use std::sync::Arc;
use std::time::Instant;

use axum::body::Bytes;
use axum::extract::rejection::{BytesRejection, QueryRejection};
use axum::extract::{Query, State};
use axum::response::Response;
use axum::Json;
use serde::Deserialize;
use serde_json::{json, Value};
use smear::{ElongatePreset, ElongateStyle, OffsetOptions, Style, WeightSource};

use super::changes::pack_changes;
use super::scene::ClipQuery;
use super::shown::pack_shown;
use super::{blocking, body, on_core_pool};
use crate::error::{ApiError, ApiResult};
use crate::files::output_path;
use crate::memory::Reservation;
use crate::pack::{coordinates, Pack};
use crate::state::Studio;

/// The example styles of `examples/smear/` (SMEAR Figs. 11, 12, 15, 16).
pub(crate) const PRESETS: &[(&str, &str)] = &[
    (
        "fig11b_linear",
        include_str!("../../../../examples/smear/fig11b_linear.toml"),
    ),
    (
        "fig11c_speed",
        include_str!("../../../../examples/smear/fig11c_speed.toml"),
    ),
    (
        "fig11d_noise",
        include_str!("../../../../examples/smear/fig11d_noise.toml"),
    ),
    (
        "fig12_warp",
        include_str!("../../../../examples/smear/fig12_warp.toml"),
    ),
    (
        "fig15_sword",
        include_str!("../../../../examples/smear/fig15_sword.toml"),
    ),
    (
        "fig15b_punch_arm",
        include_str!("../../../../examples/smear/fig15b_punch_arm.toml"),
    ),
    (
        "fig16_combined",
        include_str!("../../../../examples/smear/fig16_combined.toml"),
    ),
];

/// `GET /api/smear/presets`: `{"presets": [{"name", "style", "toml"}], "default", "parameters"}`:
/// the smear crate's named presets with their default parameters (the CLI's `--preset`, the
/// Blender panel's), then the example styles; the preset the page starts from and the
/// parameter table (default, min, max, doc) its controls take their ranges from.
pub(crate) async fn presets() -> ApiResult<Json<Value>> {
    let mut out = Vec::new();
    for preset in ElongatePreset::ALL {
        let style = Style {
            elongate: Some(ElongateStyle {
                function: preset.default_function(),
                ..ElongateStyle::default()
            }),
            ..Style::default()
        };
        let toml = style
            .to_toml_string()
            .map_err(|e| ApiError::internal(format!("preset {}: {e}", preset.name())))?;
        out.push(json!({"name": preset.name(), "doc": preset.doc(), "style": style, "toml": toml}));
    }
    for (name, text) in PRESETS {
        let style = Style::from_toml_str(text)
            .map_err(|e| ApiError::internal(format!("preset {name}: {e}")))?;
        out.push(json!({"name": name, "style": style, "toml": text}));
    }
    Ok(Json(json!({
        "presets": out,
        "default": ElongatePreset::default().name(),
        "parameters": smear::PARAMETERS,
    })))
}

/// `GET /api/smear/offsets?file=&clip=`: `offsets` (f32, frames × vertices, δ ∈ [−1, 1]).
pub(crate) async fn offsets(
    State(studio): State<Arc<Studio>>,
    Query(q): Query<ClipQuery>,
) -> ApiResult<Response> {
    blocking(move || {
        let start = Instant::now();
        let p = studio.prepared(q.file, &q.clip)?;
        let pr: &smear::Prepared = &p;
        let frames = pr.scene().frame_count;
        let mut pack = Pack::new();
        pack.f32(
            "offsets",
            (0..frames).flat_map(move |f| {
                (0..pr.object_count()).flat_map(move |i| pr.offsets(i).frame(f).iter().copied())
            }),
        );
        Ok(pack.response(json!({
            "frames": frames,
            "report": p.report(),
            "seconds": start.elapsed().as_secs_f64(),
        })))
    })
    .await
}

/// A stylize or export request.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct StyleRequest {
    #[serde(default)]
    file: usize,
    #[serde(default)]
    clip: String,
    /// The style as JSON (the TOML's structure).
    #[serde(default)]
    style: Option<Value>,
    /// Or the style as TOML text (the expression editor).
    #[serde(default)]
    toml: Option<String>,
    /// Export file name inside the output folder.
    #[serde(default)]
    name: Option<String>,
    /// `[start, end)`: only these clip frames (`smear::stylize_frames`; the page asks for the
    /// current frame first, the rest after). All frames when absent; exports ignore it.
    #[serde(default)]
    frames: Option<[usize; 2]>,
    /// A weight source to set on the style (`Style::set_weights`: the effects' preset chains
    /// then read ω), as the weight-group picker sends it.
    #[serde(default)]
    weights: Option<Value>,
    /// The body as what changed from the input clip ([`super::changes`]): `body.changed`
    /// and the moved vertices instead of `body` (the page's whole-clip request).
    #[serde(default)]
    changes: bool,
}

fn read_style(r: &StyleRequest, prepared: &OffsetOptions) -> ApiResult<Style> {
    let mut style = match (&r.toml, &r.style) {
        (Some(text), _) => {
            Style::from_toml_str(text).map_err(|e| ApiError::bad(format!("style: {e}")))?
        }
        (None, Some(v)) => {
            let s: Style = serde_json::from_value(v.clone())
                .map_err(|e| ApiError::bad(format!("style: {e}")))?;
            s.validate()
                .map_err(|e| ApiError::bad(format!("style: {e}")))?;
            s
        }
        (None, None) => return Err(ApiError::bad("style: give \"style\" (JSON) or \"toml\"")),
    };
    if let Some(w) = &r.weights {
        style.set_weights(Some(weight_source(w)?));
    }
    if style.offsets == OffsetOptions::default() {
        style.offsets = prepared.clone();
    }
    Ok(style)
}

/// The style of `r` applied to its frames (`all` = every frame, as exports write), with the
/// memory its job reserved (held while its results are sent or written).
fn stylized(
    studio: &Studio,
    r: &StyleRequest,
    all: bool,
) -> ApiResult<(Style, smear::Stylized, Reservation)> {
    let p = studio.prepared(r.file, &r.clip)?;
    let style = read_style(r, &p.options().offsets)?;
    let label = studio.file(r.file)?.label();
    let frames = match r.frames {
        Some([start, end]) if !all => start..end,
        _ => 0..p.report().frames,
    };
    let refused = |e: smear::SmearError| {
        let over = matches!(e, smear::SmearError::OverBudget(_));
        ApiError::refused(format!("{label}: {e}"), over)
    };
    let memory = smear::stylize_memory(&p, &style, frames.clone()).map_err(refused)?;
    let held = studio.reserve(r.file, &memory)?;
    let s = on_core_pool(|| smear::stylize_frames(&p, &style, frames)).map_err(refused)?;
    Ok((style, s, held))
}

/// `POST /api/smear/stylize`: the header's `first_frame` and `frames` say which clip frames
/// the buffers hold (`clip_frames` in all); buffers `body` (f32, frames × vertices × 3, every object's
/// elongated in-betweens merged in object order), per copy `copyN.positions`,
/// `copyN.alpha` (frames × copy vertices), `copyN.triangles`; per line set
/// `linesN.counts` (u32 per frame: vertices, triangles), `linesN.positions`,
/// `linesN.triangles`, `linesN.alpha`. With `"changes": true` the body comes as
/// `body.changed` and `body.step`, `body.offsets` + `body.varints` (or `body.positions`) instead
/// ([`super::changes`]), each copy as `copyN.shown`, `copyN.shown_positions` and
/// `copyN.shown_alpha` with its `first_vertex` in the input ([`super::shown`]), and the lines'
/// triangles as `linesN.triangles16` (i16) when every frame's tubes have at most 32,767
/// vertices.
pub(crate) async fn stylize(
    State(studio): State<Arc<Studio>>,
    request: Result<Bytes, BytesRejection>,
) -> ApiResult<Response> {
    let r: StyleRequest = body(request)?;
    blocking(move || {
        let start = Instant::now();
        let (style, s, held) = stylized(&studio, &r, false)?;
        // Shared with the answer: the multiples are sent from the result, not copied.
        let s = Arc::new(s);
        let toml = style.to_toml_string().unwrap_or_default();
        let mut pack = Pack::new();
        pack.keep(held);
        let frames = s.flipbook.frames;
        let bodies: Vec<&anim::MeshAnimation> = s
            .objects
            .iter()
            .filter_map(|o| s.animation(o.body))
            .collect();
        let bodies = &bodies;
        let vertices: usize = bodies.iter().map(|a| a.vertex_count()).sum();
        let input = studio.sampled(r.file, &r.clip)?;
        let clip = r.changes.then_some(&input);
        match clip.map(|c| c.merged()) {
            Some(m) if m.vertex_count() == vertices => {
                // Found once per clip (it may wait for another request finding it): before
                // the pool's task, which must not wait.
                let diagonal = input.diagonal(s.first_frame..s.first_frame + frames);
                let twins = input.twins();
                on_core_pool(|| {
                    pack_changes(
                        &mut pack,
                        (frames, vertices),
                        (diagonal, twins),
                        |f| bodies.iter().map(|a| a.frame(f)).collect(),
                        |f| m.frame(s.first_frame + f),
                    )
                })
            }
            _ => {
                pack.f32_slices(
                    "body",
                    (0..frames)
                        .flat_map(move |f| bodies.iter().map(move |a| coordinates(a.frame(f)))),
                );
            }
        }
        // Each multiple's object in the merged input (its first vertex, vertex count): whole
        // clips by changes send the vertices a copy shows, the page puts the rest there.
        let inputs: Option<Vec<(usize, usize)>> = {
            let objects = &input.sampled.objects;
            (objects.len() == s.objects.len()).then(|| {
                objects
                    .iter()
                    .scan(0, |first, o| {
                        let n = o.animation.vertex_count();
                        *first += n;
                        Some((*first - n, n))
                    })
                    .collect()
            })
        };
        let mut copies = Vec::new();
        let mut lines = Vec::new();
        for (j, o) in s.objects.iter().enumerate() {
            for i in o.copies.clone() {
                if let Some(anim::FlipbookPart::Animation { animation, colors }) =
                    s.flipbook.parts.get(i)
                {
                    let n = copies.len();
                    pack.u32(
                        &format!("copy{n}.triangles"),
                        animation.mesh.triangles.iter().flatten().copied(),
                    );
                    let v = animation.vertex_count();
                    let first = inputs
                        .as_ref()
                        .and_then(|x| x.get(j))
                        .and_then(|&(first, count)| (count == v).then_some(first));
                    if first.is_some() && r.changes {
                        pack_shown(
                            &mut pack,
                            &format!("copy{n}"),
                            (frames, v),
                            &animation.mesh.triangles,
                            |f| animation.frame(f),
                            colors.as_deref(),
                        );
                    } else {
                        pack.shared(&format!("copy{n}.positions"), (s.clone(), i), |(s, i)| {
                            copy_positions(s, *i)
                        });
                        let count = animation.positions().len();
                        match colors {
                            Some(c) => pack.f32(&format!("copy{n}.alpha"), c.iter().map(|c| c[3])),
                            None => {
                                pack.f32(&format!("copy{n}.alpha"), std::iter::repeat_n(1.0, count))
                            }
                        };
                    }
                    copies.push(
                        json!({"name": animation.mesh.name, "vertices": v, "first_vertex": first}),
                    );
                }
            }
            if let Some(anim::FlipbookPart::Frames { name, meshes, .. }) =
                o.lines.and_then(|i| s.flipbook.parts.get(i))
            {
                let n = lines.len();
                pack.u32(
                    &format!("lines{n}.counts"),
                    meshes
                        .iter()
                        .flat_map(|m| [m.positions.len() as u32, m.triangles.len() as u32]),
                );
                pack.f32_slices(
                    &format!("lines{n}.positions"),
                    meshes.iter().map(|m| coordinates(&m.positions)),
                );
                let indices = meshes.iter().flat_map(|m| m.triangles.iter().flatten());
                // A frame's tubes index at most a few thousand vertices: 16 bits when they fit.
                if r.changes
                    && meshes
                        .iter()
                        .all(|m| m.positions.len() <= i16::MAX as usize)
                {
                    pack.i16(&format!("lines{n}.triangles16"), indices.map(|&k| k as i16));
                } else {
                    pack.u32(&format!("lines{n}.triangles"), indices.copied());
                }
                pack.f32(
                    &format!("lines{n}.alpha"),
                    meshes.iter().flat_map(|m| match &m.colors {
                        Some(c) => c.iter().map(|c| c[3]).collect::<Vec<_>>(),
                        None => vec![1.0; m.positions.len()],
                    }),
                );
                lines.push(json!({"name": name}));
            }
        }
        Ok(pack.response(json!({
            "frames": frames,
            "first_frame": s.first_frame,
            "clip_frames": studio.prepared(r.file, &r.clip)?.report().frames,
            "style": style,
            "toml": toml,
            "copies": copies,
            "lines": lines,
            "report": s.report,
            "seconds": start.elapsed().as_secs_f64(),
        })))
    })
    .await
}

/// The positions of flipbook part `i` of `s` when it is an animation (a multiple).
fn copy_positions(s: &smear::Stylized, i: usize) -> &[f32] {
    match s.flipbook.parts.get(i) {
        Some(anim::FlipbookPart::Animation { animation, .. }) => coordinates(animation.positions()),
        _ => &[],
    }
}

/// `POST /api/smear/export`: `name` ending in `.toml` writes the style (as the CLI and the
/// Blender extension read it); `.glb`, `.usda`, `.usdc`, `.usdz`, `.abc` write the result as
/// `toonkit smear IN --style S -o NAME` does. Always inside the output folder, atomically.
pub(crate) async fn export(
    State(studio): State<Arc<Studio>>,
    request: Result<Bytes, BytesRejection>,
) -> ApiResult<Json<Value>> {
    let r: StyleRequest = body(request)?;
    let name = r
        .name
        .clone()
        .ok_or_else(|| ApiError::bad("export: give \"name\" (a file name in the output folder)"))?;
    let path = output_path(&studio.out_dir, &name)?;
    blocking(move || {
        let io = |e: tkio::IoError| ApiError::from_io(&e);
        if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml")) {
            let p = studio.prepared(r.file, &r.clip)?;
            let style = read_style(&r, &p.options().offsets)?;
            let text = style
                .to_toml_string()
                .map_err(|e| ApiError::bad(format!("style: {e}")))?;
            tkio::save(&path, &tkio::Output::Text(&text)).map_err(io)?;
        } else {
            if !tkio::Format::from_extension(&path).is_some_and(tkio::Format::holds_scenes) {
                return Err(ApiError::bad(format!(
                    "{name}: a styled smear is written as .glb, .usda, .usdc, .usdz or .abc (a style as .toml)"
                )));
            }
            let (_, s, _held) = stylized(&studio, &r, true)?;
            tkio::save(&path, &tkio::Output::Flipbook(&s.flipbook)).map_err(io)?;
        }
        Ok(Json(json!({ "written": path.display().to_string() })))
    })
    .await
}

/// A weight source as JSON (the style's `weights` form), validated.
fn weight_source(v: &Value) -> ApiResult<WeightSource> {
    let w: WeightSource = serde_json::from_value(v.clone()).map_err(|_| {
        ApiError::bad(format!(
            "weights: {v} is not a weight source (give {{\"group\": [\"JOINT\"]}}, {{\"attribute\": \"NAME\"}} or {{\"expr\": \"...\"}})"
        ))
    })?;
    w.validate()
        .map_err(|e| ApiError::bad(format!("weights: {e}")))?;
    Ok(w)
}

/// `GET /api/smear/weight-sources?file=&clip=`: `{"sources": [{"label", "source"}]}`, the
/// weight groups (one per bone), vertex attributes and colour channels of the file
/// (`smear::WeightSource::available`, SMEAR Fig. 15b).
pub(crate) async fn weight_sources(
    State(studio): State<Arc<Studio>>,
    Query(q): Query<ClipQuery>,
) -> ApiResult<Json<Value>> {
    blocking(move || {
        let p = studio.prepared(q.file, &q.clip)?;
        let sources: Vec<Value> = WeightSource::available(p.scene())
            .into_iter()
            .map(|w| json!({"label": w.to_string(), "source": w}))
            .collect();
        Ok(Json(json!({ "sources": sources })))
    })
    .await
}

/// Longest `source` accepted by [`weights`] (a JSON weight source, not a file).
const MAX_SOURCE_LEN: usize = 4096;

/// The query of [`weights`].
#[derive(Debug, Deserialize)]
pub(crate) struct WeightsQuery {
    #[serde(default)]
    file: usize,
    #[serde(default)]
    clip: String,
    /// The weight source as JSON, e.g. `{"group":["ShoulderR"]}`.
    source: String,
}

/// `GET /api/smear/weights?file=&clip=&source=`: `weights` (f32 ω ∈ [0, 1] per vertex, every
/// object's vertices in object order as `body` of the stylize answer) for the overlay.
pub(crate) async fn weights(
    State(studio): State<Arc<Studio>>,
    query: Result<Query<WeightsQuery>, QueryRejection>,
) -> ApiResult<Response> {
    let Query(q) = query.map_err(|r| ApiError::bad(format!("query: {}", r.body_text())))?;
    if q.source.len() > MAX_SOURCE_LEN {
        return Err(ApiError::bad(format!(
            "source: {} bytes, at most {MAX_SOURCE_LEN}",
            q.source.len()
        )));
    }
    let value: Value = serde_json::from_str(&q.source)
        .map_err(|e| ApiError::bad(format!("source: not JSON ({e})")))?;
    let source = weight_source(&value)?;
    blocking(move || {
        let p = studio.prepared(q.file, &q.clip)?;
        let label = studio.file(q.file)?.label();
        let mut all = Vec::new();
        for i in 0..p.object_count() {
            let w = p
                .resolve_weights(&source, i)
                .map_err(|e| ApiError::bad(format!("{label}: weights: {e}")))?;
            all.extend(w);
        }
        let mut pack = Pack::new();
        let (lo, hi) = all
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &w| {
                (a.min(w), b.max(w))
            });
        pack.f32("weights", all.iter().copied());
        Ok(pack.response(json!({
            "label": source.to_string(),
            "vertices": all.len(),
            "min": if all.is_empty() { 0.0 } else { lo },
            "max": if all.is_empty() { 0.0 } else { hi },
        })))
    })
    .await
}
