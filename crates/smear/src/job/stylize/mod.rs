//! `stylize`: a style applied to prepared offsets — elongated in-betweens (SMEAR Eq. 10),
//! multiple in-betweens (SMEAR Eqs. 11–12), motion lines (SMEAR Eq. 13) — as a flipbook with
//! a report. Never solves offsets: everything style-independent comes from [`Prepared`].

use std::ops::Range;
use std::time::Instant;

use anim::{Aabb, Flipbook, FlipbookPart, MeshAnimation};
use serde::Serialize;

mod displacement;
mod subdivided;

use displacement::displacement;
use subdivided::{subdivided_copy, SubdividedBody};

use super::frames::{animation_at, check_range, elongate_range, lines_range, multiples_range};
use super::prepare::Prepared;
use crate::{CompiledEffects, CompiledLines, EffectInputs, LineStyle, Result, SmearError, Style};

/// One copy of the multiple in-betweens in a [`StylizeReport`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CopyReport {
    /// The index m (negative = past).
    pub m: i32,
    /// Its displacement β_m = m·Δf at frame 0, in frames.
    pub beta: f32,
    /// Vertex-frames drawn with a non-zero opacity.
    pub visible: usize,
    /// Vertex-frames in total.
    pub total: usize,
}

/// What the style did to one object (fields of effects the object does not have are
/// `None` / empty).
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct ObjectReport {
    /// Object name.
    pub name: String,
    /// Number of vertices.
    pub vertices: usize,
    /// Largest vertex displacement of the elongated in-betweens.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elongation_max: Option<f32>,
    /// Mean vertex displacement of the elongated in-betweens.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elongation_mean: Option<f64>,
    /// Number of multiple in-betweens.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub multiples: Option<usize>,
    /// Their spacing Δf at frame 0, in frames.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub multiples_spacing: Option<f32>,
    /// Vertex-frames drawn with a non-zero opacity over all copies.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub multiples_visible_vertices: Option<usize>,
    /// Every copy.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub copies: Vec<CopyReport>,
    /// Motion-line seeds sampled.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seeds: Option<usize>,
    /// Lines drawn per frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lines_per_frame: Option<Vec<usize>>,
    /// Most lines drawn in one frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lines_max: Option<usize>,
    /// Mean length of the lines drawn (scene units, along their centres; 0 without lines).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lines_length_mean: Option<f64>,
    /// With subdivision: the largest output edge length over its rest length (issue #22).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subdivision_max_stretch: Option<f32>,
    /// With subdivision: the most triangles of the body in one frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subdivision_max_triangles: Option<usize>,
    /// With subdivision: the most vertices of the body in one frame (what the fidelity
    /// costs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subdivision_max_vertices: Option<usize>,
    /// With subdivision: the achieved error, the largest distance between the ideal smear
    /// and the body's flat triangles over all frames (scene units; see
    /// [`crate::SubdivisionStats::max_error`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subdivision_max_error: Option<f32>,
    /// Frames squashed on impact with the ground.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub squashed_frames: Option<usize>,
}

/// Seconds per phase of [`stylize`].
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct StylizeTimings {
    /// Elongated in-betweens.
    pub elongate: f64,
    /// Multiple in-betweens.
    pub multiples: f64,
    /// Motion lines (seed offsets included).
    pub lines: f64,
    /// Everything.
    pub total: f64,
}

/// What [`stylize`] did.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct StylizeReport {
    /// Per object.
    pub objects: Vec<ObjectReport>,
    /// Timings.
    pub seconds: StylizeTimings,
    /// Offset solves run by this call: always 0 — the offsets come from [`Prepared`].
    pub offset_solves: usize,
    /// What the style's speeds and lengths were measured in.
    pub speed_units: crate::SpeedUnits,
    /// Scene length of one style length unit (the size; 1 in scene units).
    pub size: f64,
}

/// Where an object's results sit in [`Stylized::flipbook`].
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ObjectParts {
    /// The body: the elongated in-betweens, or the input when the style does not elongate.
    pub body: usize,
    /// The multiple in-betweens (alpha-coloured copies).
    pub copies: std::ops::Range<usize>,
    /// The motion lines (one mesh per frame).
    pub lines: Option<usize>,
}

/// The result of [`stylize`] (or [`stylize_frames`]): every effect of every object as parts of one flipbook (write
/// it with `tkio::save(path, &tkio::Output::Flipbook(&stylized.flipbook))`, preview it with
/// `render::flipbook_gif`), and a report.
#[derive(Debug, Clone)]
pub struct Stylized {
    /// Per object: its body, then its copies, then its lines.
    pub flipbook: Flipbook,
    /// Which parts belong to which object.
    pub objects: Vec<ObjectParts>,
    /// Statistics and timings.
    pub report: StylizeReport,
    /// The clip frame the flipbook's frame 0 is (0 unless [`stylize_frames`] was given a
    /// later range).
    pub first_frame: usize,
}

impl Stylized {
    /// The point cache of part `i`, `None` when it is a per-frame mesh part (or out of range).
    pub fn animation(&self, i: usize) -> Option<&MeshAnimation> {
        match self.flipbook.parts.get(i)? {
            FlipbookPart::Animation { animation, .. } => Some(animation),
            FlipbookPart::Frames { .. } => None,
        }
    }
}

/// Squashes the frames of `anim` that land on the ground (see [`crate::squash_frames`]).
fn squash_animation(
    anim: &mut MeshAnimation,
    squash: &[Option<crate::Squash>],
    ground: Option<f32>,
) {
    let (Some(g), n) = (ground, anim.vertex_count()) else {
        return;
    };
    if squash.iter().all(Option::is_none) || n == 0 {
        return;
    }
    let mut p = anim.positions().to_vec();
    for (f, s) in squash.iter().enumerate() {
        if let Some(s) = s {
            s.apply(g, &mut p[f * n..(f + 1) * n]);
        }
    }
    if let Ok(a) = MeshAnimation::new(anim.mesh.clone(), anim.fps, p) {
        let start = anim.start_time;
        *anim = a;
        anim.start_time = start;
    }
}

/// Applies `style` to every object of `prepared`: per object, the elongated in-betweens (or
/// the input when the style has none), the multiple in-betweens as alpha-coloured copies and
/// the motion lines as per-frame tube meshes.
///
/// `style.offsets` must be the options `prepared` was made with (offsets are never solved
/// here; prepare again to change them). Seeds of motion lines on a merged object are sorted
/// by triangle so that they group by source object.
///
/// # Errors
/// [`SmearError::InvalidParameter`] when `style.offsets` differ from the prepared ones;
/// invalid style functions or parameters; unknown weight joints or attributes.
///
/// # Performance
/// Effects are parallel over frames; the motion-line seeds' offsets evaluate the prepared
/// field at the seeds only (SMEAR Eq. 8), which costs seeds × frames, not a solve.
pub fn stylize(prepared: &Prepared, style: &Style) -> Result<Stylized> {
    stylize_frames(prepared, style, 0..prepared.report().frames)
}

/// [`stylize`] for the clip frames `frames` only (an interactive restyle draws the current
/// frame first, then the rest): the flipbook holds `frames.len()` frames, frame 0 being clip
/// frame `frames.start` ([`Stylized::first_frame`]); each frame equals the same frame of
/// [`stylize`]'s result, and the report covers these frames.
///
/// # Errors
/// As [`stylize`]; [`SmearError::InvalidParameter`] when `frames` is empty or runs past the
/// clip.
///
/// # Performance
/// Costs the frames asked for: the per-frame effect functions, no whole-clip pass (the
/// motion-line seeds' offsets still cost seeds × clip frames).
///
/// # Errors
/// [`SmearError::OverBudget`] when the motion lines asked for (count, samples, sides, frames)
/// exceed [`anim::budget::DEFAULT_MAX_LINE_VERTICES`] or their seeds' trajectories
/// [`anim::budget::DEFAULT_MAX_POINTS`], or when the stylized meshes, multiples and lines
/// with the prepared clip exceed [`anim::budget::DEFAULT_MAX_JOB_BYTES`]; the errors of the
/// effects.
pub fn stylize_frames(
    prepared: &Prepared,
    style: &Style,
    frames: Range<usize>,
) -> Result<Stylized> {
    let start = Instant::now();
    stylize_memory(prepared, style, frames.clone())?;
    let mut book = Flipbook {
        fps: prepared.report().fps,
        frames: frames.len(),
        parts: Vec::new(),
    };
    let mut objects = Vec::with_capacity(prepared.object_count());
    let mut report = StylizeReport::default();
    let camera = prepared.camera();
    let merged = prepared.options().merge.is_some();
    let units = prepared.units(style.speed_units, style.size_reference.as_ref())?;
    report.speed_units = style.speed_units;
    report.size = units.length;
    let contact = style.contact.as_ref().map(|c| crate::ContactStyle {
        ground: units.length_to_scene(c.ground),
        ..c.clone()
    });
    for i in 0..prepared.object_count() {
        let anim = prepared.animation(i);
        let name = prepared.name(i);
        let fx = compiled(prepared, style, i, &units)?;
        let weights = match &fx.weights {
            Some(w) => Some(prepared.resolve_weights_in(w, i, &units)?),
            None => prepared.weights(i).map(<[f32]>::to_vec),
        };
        let mut stats = ObjectReport {
            name: name.to_string(),
            vertices: anim.vertex_count(),
            ..ObjectReport::default()
        };
        let ground = contact.as_ref().map(|c| c.ground);
        let inputs = prepared.inputs(i, weights.clone())?.with_ground(ground);
        let squash = match &contact {
            Some(c) => crate::squash_frames(anim, c),
            None => Vec::new(),
        };
        let squashed = squash.iter().filter(|s| s.is_some()).count();
        if contact.as_ref().is_some_and(|c| c.squash > 0.0) {
            stats.squashed_frames = Some(squashed);
        }
        let mut parts = ObjectParts {
            body: book.parts.len(),
            ..ObjectParts::default()
        };

        let t = Instant::now();
        let n = anim.vertex_count();
        let input = &anim.positions()[frames.start * n..frames.end * n];
        let mut body = match &fx.elongate {
            Some((f, options)) => {
                let e = elongate_range(&inputs, f, options, &frames)?;
                let (max, mean) = displacement(e.positions(), input);
                stats.elongation_max = Some(max);
                stats.elongation_mean = Some(mean);
                e
            }
            None if frames.len() == anim.frame_count() => anim.clone(),
            None => animation_at(anim, frames.start, input.to_vec())?,
        };
        let range_squash = squash.get(frames.clone()).unwrap_or(&[]);
        match (style.subdivide, &fx.elongate) {
            (Some(tol), Some((f, options))) => {
                let step = options.step.max(1);
                let sub = SubdividedBody {
                    inputs: &inputs,
                    f,
                    step,
                    squash: &squash,
                    ground,
                    tol,
                };
                let (meshes, velocities) = sub.frames(anim, &frames, &mut stats);
                book.parts.push(FlipbookPart::Frames {
                    name: anim.mesh.name.clone(),
                    meshes,
                    curves: None,
                    velocities: Some(velocities),
                });
            }
            _ => {
                squash_animation(&mut body, range_squash, ground);
                book.parts.push(FlipbookPart::Animation {
                    animation: body,
                    colors: None,
                });
            }
        }
        report.seconds.elongate += t.elapsed().as_secs_f64();

        let t = Instant::now();
        let first_copy = book.parts.len();
        if let Some((f, options)) = &fx.multiples {
            let [r, g, b] = style
                .for_object(name)
                .multiples
                .map_or(crate::DEFAULT_MULTIPLE_COLOR, |m| m.color);
            let copies = multiples_range(&inputs, f, options, &frames)?;
            let mut visible = 0usize;
            for mut c in copies {
                let shown = c.alpha.iter().filter(|a| **a > 0.0).count();
                visible += shown;
                stats.copies.push(CopyReport {
                    m: c.m,
                    beta: c.beta,
                    visible: shown,
                    total: c.alpha.len(),
                });
                if let Some(tol) = style.subdivide {
                    let (meshes, velocities) =
                        subdivided_copy(&inputs, options, &c, [r, g, b], tol, frames.start)?;
                    book.parts.push(FlipbookPart::Frames {
                        name: c.animation.mesh.name.clone(),
                        meshes,
                        curves: None,
                        velocities: Some(velocities),
                    });
                    continue;
                }
                squash_animation(&mut c.animation, range_squash, ground);
                let colors = c.alpha.iter().map(|&a| [r, g, b, a]).collect();
                book.parts.push(FlipbookPart::Animation {
                    animation: c.animation,
                    colors: Some(colors),
                });
            }
            stats.multiples = Some(options.indices().len());
            stats.multiples_spacing = Some(options.spacing_at(0.0)?);
            stats.multiples_visible_vertices = Some(visible);
        }
        parts.copies = first_copy..book.parts.len();
        report.seconds.multiples += t.elapsed().as_secs_f64();

        let t = Instant::now();
        if let Some(l) = &fx.lines {
            let tris = &anim.mesh.triangles;
            let mut points = crate::sample_surface(anim.frame(0), tris, l.count, l.seed);
            if merged {
                points.sort_by_key(|s| s.triangle);
            }
            let seed_offsets = prepared.surface_offsets(i, &points)?;
            let seed_arcs = prepared.arcs(i).map(|a| {
                std::borrow::Cow::Owned(a.remap(points.len(), |k| {
                    tris.get(points[k].triangle as usize)
                        .map_or(usize::MAX, |t| t[0] as usize)
                }))
            });
            let mut seeds = EffectInputs::at_surface_points(anim, &points, seed_offsets)?
                .with_causal(prepared.options().offsets.causal)
                .with_arcs(seed_arcs)?
                .relative_to_camera(camera);
            if let Some(w) = &weights {
                seeds = seeds.with_weights(crate::surface_point_weights(w, tris, &points)?)?;
            }
            let line_style = LineStyle {
                length: &l.length,
                thickness: &l.thickness,
                opacity: &l.opacity,
            };
            let line_frames = lines_range(&seeds, &line_style, &l.options, &frames)?;
            let drawn: Vec<usize> = line_frames.iter().map(|f| f.lines).collect();
            let length: f64 = line_frames.iter().map(|f| f.length as f64).sum();
            let count: usize = drawn.iter().sum();
            stats.lines_length_mean = Some(length / count.max(1) as f64);
            stats.seeds = Some(points.len());
            stats.lines_max = Some(drawn.iter().copied().max().unwrap_or(0));
            stats.lines_per_frame = Some(drawn);
            parts.lines = Some(book.parts.len());
            let (meshes, curves) = line_frames.into_iter().map(|f| (f.mesh, f.curves)).unzip();
            book.parts.push(FlipbookPart::Frames {
                name: format!("{name}_lines"),
                meshes,
                curves: Some(curves),
                velocities: None,
            });
        }
        report.seconds.lines += t.elapsed().as_secs_f64();
        // A user expression that was NaN or infinite somewhere drew zeros there: an error
        // naming it, the frame and the vertex, not a silently flat smear.
        fx.check_finite()?;
        report.objects.push(stats);
        objects.push(parts);
    }
    report.seconds.total = start.elapsed().as_secs_f64();
    Ok(Stylized {
        flipbook: book,
        objects,
        report,
        first_frame: frames.start,
    })
}

/// What [`stylize_frames`] will hold for `frames` of `prepared` styled by `style` — the
/// prepared clip, each object's stylized meshes, multiples and motion lines, each with the
/// file it is written to — checked against the job budget before anything is made (a server
/// reserves it before stylizing).
///
/// # Errors
/// As [`stylize_frames`] before it allocates: [`SmearError::OverBudget`] when the smoothing,
/// the motion lines or the estimate are over their budgets (said in that order, so a request
/// naming `--smooth 1e9` hears the limit); a range past the clip; offsets that differ from the
/// prepared ones; style functions that do not compile.
pub fn stylize_memory(
    prepared: &Prepared,
    style: &Style,
    frames: Range<usize>,
) -> Result<anim::budget::JobMemory> {
    check_range(&frames, prepared.report().frames)?;
    style.offsets.check_budget()?;
    if style.offsets != prepared.options().offsets {
        return Err(SmearError::InvalidParameter {
            name: "style.offsets",
            reason: "differ from the options the scene was prepared with; prepare it again".into(),
        });
    }
    let mut memory = anim::budget::JobMemory::new().positions(
        "copies of the prepared clip (positions, velocities)",
        prepared.report().frames,
        prepared.scene().vertex_count(),
        2,
    );
    // The style's units into the scene's, once (docs/smear-units.md).
    let units = prepared.units(style.speed_units, style.size_reference.as_ref())?;
    for i in 0..prepared.object_count() {
        let fx = compiled(prepared, style, i, &units)?;
        if let Some(l) = &fx.lines {
            check_line_budget(l, prepared.report().frames, frames.len())?;
        }
        memory = object_memory(
            memory,
            &fx,
            frames.len(),
            prepared.animation(i).vertex_count(),
        );
        memory.check(MEMORY_HINT)?;
    }
    Ok(memory)
}

/// The effects of `style` for object `i` of `prepared`, compiled in the scene's units.
fn compiled(
    prepared: &Prepared,
    style: &Style,
    i: usize,
    units: &crate::StyleUnits,
) -> Result<CompiledEffects> {
    let diagonal = Aabb::from_points(prepared.animation(i).frame(0)).diagonal();
    Ok(style
        .for_object(prepared.name(i))
        .compile_in(diagonal, units)?)
}

/// What to lower when a stylization is over the job's memory budget.
const MEMORY_HINT: &str =
    "lower --fps, pick a shorter clip or ask for fewer multiples or motion lines";

/// Bytes of one stylized vertex of one frame: its position and its RGBA colour (f32).
const STYLIZED_VERTEX_BYTES: u64 = 12 + 16;

/// Bytes of one motion-line vertex of one frame: position, normal and RGBA colour (f32).
const LINE_VERTEX_BYTES: u64 = 12 + 12 + 16;

/// `memory` and what stylizing `frames` frames of one object of `vertices` vertices with `fx`
/// will hold: the body and each multiple, the motion lines, each twice (the flipbook and the
/// file it is written to), checked against [`anim::budget::DEFAULT_MAX_JOB_BYTES`] before
/// they are made.
fn object_memory(
    memory: anim::budget::JobMemory,
    fx: &CompiledEffects,
    frames: usize,
    vertices: usize,
) -> anim::budget::JobMemory {
    use anim::budget::product;
    let copies = 1 + fx.multiples.as_ref().map_or(0, |(_, o)| o.indices().len()) as u64;
    let meshes = product(&[
        frames as u64,
        vertices as u64,
        copies,
        STYLIZED_VERTEX_BYTES,
        2,
    ]);
    let memory = memory.bytes(
        format!("{copies} stylized meshes and their file, {frames} frames × {vertices} vertices"),
        meshes,
    );
    match &fx.lines {
        Some(l) => {
            let lines = product(&[
                l.count as u64,
                l.options.samples as u64,
                l.options.sides as u64,
                frames as u64,
                LINE_VERTEX_BYTES,
                2,
            ]);
            memory.bytes(format!("{} motion lines and their file", l.count), lines)
        }
        None => memory,
    }
}

/// Motion lines (SMEAR Eq. 13) are checked against their budgets before their seeds are
/// sampled: each seed's trajectory spans the clip, and each drawn line holds samples × sides
/// vertices per frame.
fn check_line_budget(l: &CompiledLines, clip_frames: usize, frames: usize) -> Result<()> {
    use anim::budget::{product, DEFAULT_MAX_LINE_VERTICES, DEFAULT_MAX_POINTS};
    let (count, samples, sides) = (
        l.count as u64,
        l.options.samples as u64,
        l.options.sides as u64,
    );
    anim::check_budget(
        "lines count × clip frames",
        product(&[count, clip_frames as u64]),
        DEFAULT_MAX_POINTS,
        "lower the motion-line --count",
    )?;
    anim::check_budget(
        "lines count × samples × sides × frames",
        product(&[count, samples, sides, frames as u64]),
        DEFAULT_MAX_LINE_VERTICES,
        "lower the motion-line --count, --samples or --sides",
    )?;
    Ok(())
}
