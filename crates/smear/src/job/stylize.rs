//! `stylize`: a style applied to prepared offsets — elongated in-betweens (SMEAR Eq. 10),
//! multiple in-betweens (SMEAR Eqs. 11–12), motion lines (SMEAR Eq. 13) — as a flipbook with
//! a report. Never solves offsets: everything style-independent comes from [`Prepared`].

use std::time::Instant;

use anim::{Aabb, Flipbook, FlipbookPart, MeshAnimation};
use serde::Serialize;

use super::prepare::Prepared;
use crate::{CompiledEffects, EffectInputs, LineStyle, Result, SmearError, Style};

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

/// The result of [`stylize`]: every effect of every object as parts of one flipbook (write
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

/// Largest and mean vertex displacement between two animations of the same mesh.
fn displacement(a: &MeshAnimation, b: &MeshAnimation) -> (f32, f64) {
    let (mut max, mut sum) = (0.0f32, 0.0f64);
    for (p, q) in a.positions().iter().zip(b.positions()) {
        let d = p.distance(*q);
        max = max.max(d);
        sum += d as f64;
    }
    (max, sum / a.positions().len().max(1) as f64)
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
    let start = Instant::now();
    if style.offsets != prepared.options().offsets {
        return Err(SmearError::InvalidParameter {
            name: "style.offsets",
            reason: "differ from the options the scene was prepared with; prepare it again".into(),
        });
    }
    let mut book = Flipbook {
        fps: prepared.report().fps,
        frames: prepared.report().frames,
        parts: Vec::new(),
    };
    let mut objects = Vec::with_capacity(prepared.object_count());
    let mut report = StylizeReport::default();
    let camera = prepared.camera();
    let merged = prepared.options().merge.is_some();
    for i in 0..prepared.object_count() {
        let anim = prepared.animation(i);
        let name = prepared.name(i);
        let diagonal = Aabb::from_points(anim.frame(0)).diagonal();
        let fx: CompiledEffects = style.for_object(name).compile(diagonal)?;
        let weights = match &fx.weights {
            Some(w) => Some(prepared.resolve_weights(w, i)?),
            None => prepared.weights(i).map(<[f32]>::to_vec),
        };
        let inputs = prepared.inputs(i, weights.clone())?;
        let mut stats = ObjectReport {
            name: name.to_string(),
            vertices: anim.vertex_count(),
            ..ObjectReport::default()
        };
        let mut parts = ObjectParts {
            body: book.parts.len(),
            ..ObjectParts::default()
        };

        let t = Instant::now();
        let body = match &fx.elongate {
            Some((f, options)) => {
                let e = crate::elongate(&inputs, f, options)?;
                let (max, mean) = displacement(&e, anim);
                stats.elongation_max = Some(max);
                stats.elongation_mean = Some(mean);
                e
            }
            None => anim.clone(),
        };
        report.seconds.elongate += t.elapsed().as_secs_f64();
        book.parts.push(FlipbookPart::Animation {
            animation: body,
            colors: None,
        });

        let t = Instant::now();
        let first_copy = book.parts.len();
        if let Some((f, options)) = &fx.multiples {
            let [r, g, b] = style
                .for_object(name)
                .multiples
                .map_or(crate::DEFAULT_MULTIPLE_COLOR, |m| m.color);
            let copies = crate::multiples(&inputs, f, options)?;
            let mut visible = 0usize;
            for c in copies {
                let shown = c.alpha.iter().filter(|a| **a > 0.0).count();
                visible += shown;
                stats.copies.push(CopyReport {
                    m: c.m,
                    beta: c.beta,
                    visible: shown,
                    total: c.alpha.len(),
                });
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
            let mut seeds = EffectInputs::at_surface_points(anim, &points, seed_offsets)?
                .relative_to_camera(camera);
            if let Some(w) = &weights {
                seeds = seeds.with_weights(crate::surface_point_weights(w, tris, &points)?)?;
            }
            let line_style = LineStyle {
                length: &l.length,
                thickness: &l.thickness,
                opacity: &l.opacity,
            };
            let frames = crate::motion_lines(&seeds, &line_style, &l.options)?;
            let drawn: Vec<usize> = frames.iter().map(|f| f.lines).collect();
            stats.seeds = Some(points.len());
            stats.lines_max = Some(drawn.iter().copied().max().unwrap_or(0));
            stats.lines_per_frame = Some(drawn);
            parts.lines = Some(book.parts.len());
            book.parts.push(FlipbookPart::Frames {
                name: format!("{name}_lines"),
                meshes: frames.into_iter().map(|f| f.mesh).collect(),
            });
        }
        report.seconds.lines += t.elapsed().as_secs_f64();
        report.objects.push(stats);
        objects.push(parts);
    }
    report.seconds.total = start.elapsed().as_secs_f64();
    Ok(Stylized {
        flipbook: book,
        objects,
        report,
    })
}
