//! Styles: which effects to apply to which objects, with which stylization functions and
//! parameters (the paper's per-object stylization of Fig. 17, combined effects of Fig. 16).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::error::StyleError;
use super::function::FunctionSpec;
use super::param::Param;
use super::preset::{ElongatePreset, DEFAULT_COPIES, DEFAULT_LINE_LENGTH};
use super::stage::Stage;
use super::units::{SizeReference, SpeedUnits};
use super::weights::WeightSource;
use crate::{
    ContactStyle, LineOptions, MultiplesOptions, OffsetOptions, Spacing, DEFAULT_FRAME_STEP,
    DEFAULT_LINE_SAMPLES, DEFAULT_LINE_SIDES, DEFAULT_SEED, DEFAULT_SPACING,
};

/// Default number of motion-line seeds.
pub const DEFAULT_LINE_COUNT: usize = 40;

/// Default motion-line radius as a fraction of the object's bounding-box diagonal.
pub const DEFAULT_LINE_THICKNESS: f32 = 0.002;

/// Default colour of the multiple in-betweens (linear RGB, light grey; alpha is S_M).
pub const DEFAULT_MULTIPLE_COLOR: [f32; 3] = [0.8, 0.8, 0.8];

fn is_default_multiple_color(c: &[f32; 3]) -> bool {
    *c == DEFAULT_MULTIPLE_COLOR
}

fn yes() -> bool {
    true
}

fn one() -> usize {
    DEFAULT_FRAME_STEP
}

/// Elongated in-betweens (Section 4.1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ElongateStyle {
    /// false turns the effect off (e.g. for one object).
    pub enabled: bool,
    /// Frame step: 2 = "on twos" (Section 5.2).
    pub step: usize,
    /// S_E of SMEAR Eq. 10: β in frames along the trajectory.
    pub function: FunctionSpec,
}

impl Default for ElongateStyle {
    fn default() -> Self {
        ElongateStyle {
            enabled: yes(),
            step: one(),
            function: ElongatePreset::default().default_function(),
        }
    }
}

/// Multiple in-betweens (Section 4.2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MultiplesStyle {
    /// false turns the effect off.
    pub enabled: bool,
    /// Copies in the past, m_p; keyframeable (copies beyond the count are transparent).
    pub past: Param,
    /// Copies in the future, m_n; keyframeable.
    pub future: Param,
    /// Δf in frames (exclusive with `overlap`; default 0.5); keyframeable.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spacing: Option<Param>,
    /// N∩: copies overlapping between consecutive frames, Δf = 1/(m_p + m_n + 1 − N∩);
    /// keyframeable.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub overlap: Option<Param>,
    /// Frame step: 2 = "on twos".
    pub step: usize,
    /// S_M of SMEAR Eq. 11: opacity per vertex and copy (default SMEAR Eq. 12 with
    /// m_max = max(m_p, m_n)).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub opacity: Option<FunctionSpec>,
    /// Linear RGB colour of the copies in [0, 1] (default [`DEFAULT_MULTIPLE_COLOR`]).
    #[serde(skip_serializing_if = "is_default_multiple_color")]
    pub color: [f32; 3],
}

impl Default for MultiplesStyle {
    fn default() -> Self {
        MultiplesStyle {
            enabled: yes(),
            past: Param::Constant(DEFAULT_COPIES),
            future: Param::Constant(DEFAULT_COPIES),
            spacing: None,
            overlap: None,
            step: one(),
            opacity: None,
            color: DEFAULT_MULTIPLE_COLOR,
        }
    }
}

impl MultiplesStyle {
    /// The effect's options.
    ///
    /// Returns [`StyleError::Parameter`] when both `spacing` and `overlap` are given.
    pub fn options(&self) -> Result<MultiplesOptions, StyleError> {
        let spacing = match (self.spacing.clone(), self.overlap.clone()) {
            (Some(_), Some(_)) => {
                return Err(StyleError::Parameter {
                    name: "multiples.spacing".into(),
                    problem: "give either 'spacing' or 'overlap', not both".into(),
                })
            }
            (Some(df), None) => Spacing::Frames(df),
            (None, Some(n)) => Spacing::Overlap(n),
            (None, None) => Spacing::Frames(DEFAULT_SPACING.into()),
        };
        let options = MultiplesOptions {
            past: self.past.clone(),
            future: self.future.clone(),
            spacing,
            step: self.step,
        };
        // Check the spacing at frame 0 and at every key of the counts and the overlap.
        let keys = |p: &Option<&Param>| match p {
            Some(Param::Curve(k)) => k.iter().map(|k| k[0]).collect(),
            _ => Vec::new(),
        };
        let frames = std::iter::once(0.0)
            .chain(keys(&Some(&self.past)))
            .chain(keys(&Some(&self.future)))
            .chain(keys(&self.overlap.as_ref()));
        for f in frames {
            options.spacing_at(f).map_err(|e| StyleError::Parameter {
                name: "multiples".into(),
                problem: e.to_string(),
            })?;
        }
        Ok(options)
    }

    /// The opacity function (SMEAR Eq. 12 with m_max = max(m_p, m_n, 1) when none is given).
    pub fn opacity_spec(&self) -> FunctionSpec {
        self.opacity.clone().unwrap_or_else(|| {
            let largest = self.past.max_value().max(self.future.max_value()).round();
            FunctionSpec::multiples(largest.max(1.0))
        })
    }
}

/// Motion lines (Section 4.3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LinesStyle {
    /// false turns the effect off.
    pub enabled: bool,
    /// Number of lines (seeds sampled on the surface, area-uniform); keyframeable — a curve
    /// samples as many seeds as its largest key and draws a fixed random subset of them.
    pub count: Param,
    /// Seed of the seed sampling.
    pub seed: u64,
    /// Gap between the surface and the line, in frames along the trajectory; keyframeable.
    pub gap: Param,
    /// Seeds slower than this draw no line; keyframeable. In size units per second (one
    /// unit = the character's bounding-box diagonal), scene units per frame with
    /// `speed_units = "scene"`.
    pub min_speed: Param,
    /// Only trace the past.
    pub past_only: bool,
    /// Tube sides.
    pub sides: usize,
    /// Rings along a line.
    pub samples: usize,
    /// Frame step: 2 = "on twos".
    pub step: usize,
    /// Linear RGB colour in [0, 1]; each component keyframeable, e.g.
    /// `color = [[[0, 0.0], [12, 1.0]], 0.1, 0.1]` turns the lines red.
    pub color: [Param; 3],
    /// S_L of SMEAR Eq. 13: signed length τ in frames (default S_L(δ; 1) = δ).
    pub length: FunctionSpec,
    /// Tube radius along the line, in size units (one unit = the character's bounding-box
    /// diagonal; scene units with `speed_units = "scene"`). Default
    /// [`DEFAULT_LINE_THICKNESS`] × the object's own bounding-box diagonal in either.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thickness: Option<FunctionSpec>,
    /// Opacity along the line (default 1 − t, fading toward the end).
    pub opacity: FunctionSpec,
}

impl Default for LinesStyle {
    fn default() -> Self {
        LinesStyle {
            enabled: yes(),
            count: Param::Constant(DEFAULT_LINE_COUNT as f32),
            seed: DEFAULT_SEED,
            gap: Param::Constant(0.0),
            min_speed: Param::Constant(0.0),
            past_only: false,
            sides: DEFAULT_LINE_SIDES,
            samples: DEFAULT_LINE_SAMPLES,
            step: one(),
            color: LineOptions::default().color,
            length: FunctionSpec::linear(DEFAULT_LINE_LENGTH),
            thickness: None,
            opacity: FunctionSpec::stages(vec![Stage::Set { value: 1.0.into() }, Stage::Fade]),
        }
    }
}

impl LinesStyle {
    /// The effect's options.
    pub fn options(&self) -> LineOptions {
        LineOptions {
            sides: self.sides,
            samples: self.samples,
            gap: self.gap.clone(),
            min_speed: self.min_speed.clone(),
            count: self.count.is_keyframed().then(|| self.count.clone()),
            past_only: self.past_only,
            step: self.step,
            color: self.color.clone(),
        }
    }

    /// How many seeds to sample: the largest value of `count` (rounded).
    pub fn seed_count(&self) -> usize {
        let c = self.count.max_value();
        if c.is_finite() {
            c.round().clamp(0.0, 1e7) as usize
        } else {
            0
        }
    }

    /// The thickness function, given the object's bounding-box diagonal for the default.
    pub fn thickness_spec(&self, diagonal: f32) -> FunctionSpec {
        self.thickness.clone().unwrap_or_else(|| {
            FunctionSpec::stages(vec![Stage::Set {
                value: (DEFAULT_LINE_THICKNESS * diagonal).into(),
            }])
        })
    }
}

/// Per-object overrides: a section given here replaces the style's section for the object
/// (mesh) of that name; missing sections fall back to the style's.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ObjectStyle {
    /// Painted weights ω for this object (see [`WeightSource`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub weights: Option<WeightSource>,
    /// Elongation for this object.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elongate: Option<ElongateStyle>,
    /// Multiples for this object.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub multiples: Option<MultiplesStyle>,
    /// Motion lines for this object.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lines: Option<LinesStyle>,
}

/// A whole style: the motion-offset options and up to three effects, each with its
/// stylization functions, plus per-object overrides (paper Figs. 16, 17).
///
/// Units (`docs/smear-units.md`): speeds (`speed`, `vx, vy, vz`, `threshold`,
/// `lines.min_speed`) are in size units per second and lengths (`x, y, z`, noise κ per
/// length, `lines.thickness`, `contact.ground`) in size units, one size unit being the
/// character's bounding-box diagonal at its rest pose (or [`Style::size_reference`]);
/// `speed_units = "scene"` reads them as the paper does, in scene units (per frame).
/// Displacements β, τ and spacings stay in frames.
///
/// ```
/// let style = smear::Style::from_toml_str(r#"
///     [elongate]
///     function = { stages = [{ op = "speed" }, { op = "scale", by = 6 }] }
///     [lines]
///     count = 20
///     length = { expr = "10 * step(speed - 0.01) * delta" }
/// "#)?;
/// let fx = style.for_object("Robot");
/// assert!(fx.elongate.is_some() && fx.lines.is_some() && fx.multiples.is_none());
/// # Ok::<(), smear::StyleError>(())
/// ```
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Style {
    /// Motion-offset options (Section 3).
    pub offsets: OffsetOptions,
    /// What the style's speeds and lengths are measured in: `"size"` (default, the
    /// character's own size, speeds per second) or `"scene"` (scene units, speeds per
    /// frame: the paper's numbers, reproduced bit for bit).
    #[serde(skip_serializing_if = "SpeedUnits::is_size")]
    pub speed_units: SpeedUnits,
    /// One size unit: a length in scene units (`1.8`) or an object whose bounding-box
    /// diagonal at its rest pose it is (`"Body"`). Default: the diagonal of every object
    /// at the rest pose. Ignored with `speed_units = "scene"`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub size_reference: Option<SizeReference>,
    /// Painted weights ω (paper Fig. 15b): a weight group, a vertex attribute or a function
    /// of the rest position (see [`WeightSource`]). Default 1.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub weights: Option<WeightSource>,
    /// Elongated in-betweens.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elongate: Option<ElongateStyle>,
    /// Multiple in-betweens.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub multiples: Option<MultiplesStyle>,
    /// Motion lines.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lines: Option<LinesStyle>,
    /// Adaptive subdivision (issue #22): output edges of the elongated and multiple
    /// in-betweens longer than this × their rest length, or whose smear bends away from them
    /// by more than [`crate::BEND`] × (this − 1) of it, are split (≥ 1; e.g. 2). The results
    /// then have one mesh per frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subdivide: Option<f32>,
    /// A ground plane the in-betweens never cross, with optional squash on impact (issue #22).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact: Option<ContactStyle>,
    /// Per-object overrides keyed by mesh name.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub objects: BTreeMap<String, ObjectStyle>,
}

/// The effects that apply to one object (disabled ones are `None`).
#[derive(Debug, Clone, Copy)]
pub struct ObjectEffects<'a> {
    /// Painted weights, if any.
    pub weights: Option<&'a WeightSource>,
    /// Elongation.
    pub elongate: Option<&'a ElongateStyle>,
    /// Multiples.
    pub multiples: Option<&'a MultiplesStyle>,
    /// Motion lines.
    pub lines: Option<&'a LinesStyle>,
}

impl Style {
    /// Parses and validates a style from TOML text (every function is compiled once to check
    /// it).
    ///
    /// Returns [`StyleError::Syntax`] naming the line and key for malformed TOML or unknown
    /// keys, the validation errors of [`Style::validate`] otherwise.
    pub fn from_toml_str(text: &str) -> Result<Style, StyleError> {
        let style: Style =
            toml::from_str(text).map_err(|e| StyleError::Syntax(one_line(&e.to_string())))?;
        style.validate()?;
        Ok(style)
    }

    /// The style as TOML text ([`Style::from_toml_str`] reads it back to an equal style).
    pub fn to_toml_string(&self) -> Result<String, StyleError> {
        toml::to_string(self).map_err(|e| StyleError::Syntax(e.to_string()))
    }

    /// Sets the painted weights ω (`None`: ω = 1 everywhere) and makes the style's effects
    /// read them, as the CLI's `--weight-group` does: every preset chain among the elongation
    /// function, the lines' length and a given multiples opacity that has no `weight` stage
    /// gets one (appended, or before the chain's `multiples`/`fade` stage, so ω scales the
    /// offset and not an opacity curve). Expressions read `weight` themselves and are kept;
    /// per-object overrides are kept.
    pub fn set_weights(&mut self, source: Option<WeightSource>) {
        let weigh = |f: &mut FunctionSpec| {
            if f.expr.is_some() || f.stages.contains(&Stage::Weight) {
                return;
            }
            let at = f
                .stages
                .iter()
                .position(|s| matches!(s, Stage::Multiples { .. } | Stage::Fade))
                .unwrap_or(f.stages.len());
            f.stages.insert(at, Stage::Weight);
        };
        if source.is_some() {
            if let Some(e) = &mut self.elongate {
                weigh(&mut e.function);
            }
            if let Some(o) = self.multiples.as_mut().and_then(|m| m.opacity.as_mut()) {
                weigh(o);
            }
            if let Some(l) = &mut self.lines {
                weigh(&mut l.length);
            }
        }
        self.weights = source;
    }

    /// Compiles every function and checks every option.
    pub fn validate(&self) -> Result<(), StyleError> {
        match &self.size_reference {
            Some(SizeReference::Length(l)) if !(l.is_finite() && *l > 0.0) => {
                return Err(StyleError::Parameter {
                    name: "size_reference".into(),
                    problem: format!("a length must be > 0 (scene units), got {l}"),
                });
            }
            Some(SizeReference::Node(n)) if n.trim().is_empty() => {
                return Err(StyleError::Parameter {
                    name: "size_reference".into(),
                    problem: "give a length or an object's name".into(),
                });
            }
            _ => {}
        }
        if let Some(t) = self.subdivide {
            if !(t.is_finite() && t >= 1.0) {
                return Err(StyleError::Parameter {
                    name: "subdivide".into(),
                    problem: format!("the tolerance must be a number ≥ 1 (e.g. 2), got {t}"),
                });
            }
        }
        if let Some(c) = &self.contact {
            if !c.ground.is_finite() || !(0.0..=crate::MAX_SQUASH).contains(&c.squash) {
                return Err(StyleError::Parameter {
                    name: "contact".into(),
                    problem: format!(
                        "ground must be finite and squash in [0, {}], got {} and {}",
                        crate::MAX_SQUASH,
                        c.ground,
                        c.squash
                    ),
                });
            }
        }
        let sections = std::iter::once((
            "",
            ObjectStyle {
                weights: self.weights.clone(),
                elongate: self.elongate.clone(),
                multiples: self.multiples.clone(),
                lines: self.lines.clone(),
            },
        ))
        .chain(self.objects.iter().map(|(k, v)| (k.as_str(), v.clone())));
        for (object, s) in sections {
            let at = |e: StyleError| match e {
                StyleError::Parameter { name, problem } if !object.is_empty() => {
                    StyleError::Parameter {
                        name: format!("objects.{object}.{name}"),
                        problem,
                    }
                }
                e => e,
            };
            if let Some(w) = &s.weights {
                w.validate().map_err(at)?;
            }
            if let Some(e) = &s.elongate {
                e.function.compile().map_err(at)?;
                check_step("elongate.step", e.step).map_err(at)?;
            }
            if let Some(m) = &s.multiples {
                m.options().map_err(at)?;
                m.opacity_spec().compile().map_err(at)?;
                check_step("multiples.step", m.step).map_err(at)?;
                if !m.color.iter().all(|c| (0.0..=1.0).contains(c)) {
                    return Err(at(StyleError::Parameter {
                        name: "multiples.color".into(),
                        problem: format!("components must be in [0, 1], got {:?}", m.color),
                    }));
                }
            }
            if let Some(l) = &s.lines {
                l.length.compile().map_err(at)?;
                l.opacity.compile().map_err(at)?;
                l.thickness_spec(1.0).compile().map_err(at)?;
                check_step("lines.step", l.step).map_err(at)?;
                l.gap
                    .validate("lines.gap", (0.0, false), (f32::MAX, false))
                    .map_err(at)?;
                l.min_speed.validate_finite("lines.min_speed").map_err(at)?;
                for c in &l.color {
                    c.validate("lines.color", (0.0, false), (1.0, false))
                        .map_err(at)?;
                }
                l.count
                    .validate("lines.count", (0.0, false), (1e7, false))
                    .map_err(at)?;
                if l.sides < 3 || l.samples < 2 {
                    return Err(at(StyleError::Parameter {
                        name: "lines".into(),
                        problem: "need sides ≥ 3 and samples ≥ 2".into(),
                    }));
                }
            }
        }
        Ok(())
    }

    /// The effects for the object (mesh) `name`: its overrides, else the style's sections;
    /// disabled sections are `None`.
    pub fn for_object(&self, name: &str) -> ObjectEffects<'_> {
        let o = self.objects.get(name);
        let elongate = pick(o.and_then(|o| o.elongate.as_ref()), self.elongate.as_ref());
        let multiples = pick(
            o.and_then(|o| o.multiples.as_ref()),
            self.multiples.as_ref(),
        );
        let lines = pick(o.and_then(|o| o.lines.as_ref()), self.lines.as_ref());
        ObjectEffects {
            weights: o.and_then(|o| o.weights.as_ref()).or(self.weights.as_ref()),
            elongate: elongate.filter(|e| e.enabled),
            multiples: multiples.filter(|e| e.enabled),
            lines: lines.filter(|e| e.enabled),
        }
    }
}

fn pick<'a, T>(local: Option<&'a T>, global: Option<&'a T>) -> Option<&'a T> {
    local.or(global)
}

fn check_step(name: &str, step: usize) -> Result<(), StyleError> {
    if step == 0 {
        return Err(StyleError::Parameter {
            name: name.into(),
            problem: "the frame step must be ≥ 1 (1 = on ones, 2 = on twos)".into(),
        });
    }
    Ok(())
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}
