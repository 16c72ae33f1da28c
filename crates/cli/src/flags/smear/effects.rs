//! The flags of `toonkit smear elongate | multiples | lines` (SMEAR Section 4) and the part of
//! the [`Style`] each describes. Expressions are those of `smear::Expression` with the
//! effect's maximum bound as a parameter (`beta_max`, `m_max`, `tau_max`).

use clap::{Args, ValueEnum};

use super::{check, EffectArgs, FlagError};
use ::smear::{
    ElongatePreset, ElongateStyle, FunctionSpec, LineOptions, LinesStyle, MultiplesOptions,
    MultiplesStyle, Param, Prepared, Spacing, Stage, Style,
};

/// `--preset`: the names and docs of [`ElongatePreset`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum PresetArg {
    /// S_E(δ; β_max) = β_max·δ (SMEAR Eq. 10 example, Fig. 9b, 11b): the default, which
    /// needs no speed, so β is in frames in any units.
    Linear,
    /// S_E(δ; v, β_max) = β_max‖v‖δ (Fig. 11c): fast parts stretch, slow parts stay put.
    Speed,
    /// S_E(δ⁻; v, κ, β_max) = β_max‖v‖F1(p(0), κ)δ⁻ (Fig. 11d): a ragged trailing smear.
    Noise,
}

impl From<ElongatePreset> for PresetArg {
    fn from(p: ElongatePreset) -> PresetArg {
        match p {
            ElongatePreset::Linear => PresetArg::Linear,
            ElongatePreset::Speed => PresetArg::Speed,
            ElongatePreset::Noise => PresetArg::Noise,
        }
    }
}

impl From<PresetArg> for ElongatePreset {
    fn from(p: PresetArg) -> ElongatePreset {
        match p {
            PresetArg::Linear => ElongatePreset::Linear,
            PresetArg::Speed => ElongatePreset::Speed,
            PresetArg::Noise => ElongatePreset::Noise,
        }
    }
}

/// Flags of the elongated in-betweens (SMEAR Eq. 10).
#[derive(Debug, Clone, Args)]
pub(crate) struct Elongate {
    /// Stylization preset S_E.
    #[arg(long, value_enum, default_value_t = PresetArg::from(ElongatePreset::default()))]
    pub(crate) preset: PresetArg,
    /// Maximum elongation β_max: frames with `linear`; frames per (size unit per second)
    /// with `speed` and `noise`, which multiply it by the speed (frames per scene unit per
    /// frame with --speed-units scene). Keyframes as FRAME:VALUE,... (e.g. 0:0,12:3).
    #[arg(long, default_value_t = Param::Constant(::smear::DEFAULT_BETA_MAX))]
    pub(crate) beta_max: Param,
    /// Noise scale κ of the `noise` preset: Voronoi cells per size unit (per scene unit with
    /// --speed-units scene); keyframeable.
    #[arg(long, default_value_t = Param::Constant(::smear::DEFAULT_KAPPA))]
    pub(crate) kappa: Param,
    /// User expression for β in frames (replaces the preset), e.g. "beta_max * speed *
    /// past(delta)"; `speed`, `vx, vy, vz` in size units per second, `x, y, z` in size units
    /// (scene units per frame and scene units with --speed-units scene).
    #[arg(long)]
    pub(crate) expr: Option<String>,
}

impl Elongate {
    /// S_E: the expression, or the preset (times ω with painted weights), checked.
    ///
    /// # Errors
    /// A function that does not compile, naming its flag.
    pub(crate) fn function(&self, effect: &EffectArgs) -> Result<FunctionSpec, FlagError> {
        let spec = match &self.expr {
            Some(e) => FunctionSpec::expr(e, &[("beta_max", self.beta_max.clone())]),
            None => effect.weighted(
                ElongatePreset::from(self.preset)
                    .function(self.beta_max.clone(), self.kappa.clone()),
            ),
        };
        let flag = match self.expr {
            Some(_) => "--expr",
            None => "--beta-max/--kappa",
        };
        check(&spec, flag)?;
        Ok(spec)
    }

    /// The style: the offsets `prepared` was made with and the elongation.
    ///
    /// # Errors
    /// As [`Elongate::function`] and [`EffectArgs::shaping`].
    pub(crate) fn style(
        &self,
        effect: &EffectArgs,
        prepared: &Prepared,
    ) -> Result<Style, FlagError> {
        Ok(Style {
            elongate: Some(ElongateStyle {
                enabled: true,
                step: effect.step,
                function: self.function(effect)?,
            }),
            ..effect.base_style(prepared)?
        })
    }
}

/// Flags of the multiple in-betweens (SMEAR Eqs. 11–12).
#[derive(Debug, Clone, Args)]
pub(crate) struct Multiples {
    /// Copies in the past, m_p; keyframes (FRAME:VALUE,...) fade copies in and out.
    #[arg(long, default_value_t = Param::Constant(::smear::DEFAULT_COPIES))]
    pub(crate) past: Param,
    /// Copies in the future, m_n; keyframeable.
    #[arg(long, default_value_t = Param::Constant(::smear::DEFAULT_COPIES))]
    pub(crate) future: Param,
    /// Temporal spacing Δf between copies, in frames; keyframes as FRAME:VALUE,...
    #[arg(long, conflicts_with = "overlap")]
    pub(crate) spacing: Option<Param>,
    /// Copies overlapping between consecutive frames, N∩: Δf = 1/(m_p + m_n + 1 − N∩);
    /// keyframeable.
    #[arg(long)]
    pub(crate) overlap: Option<Param>,
    /// m_max of SMEAR Eq. 12 (default: max(m_p, m_n); keyframeable).
    #[arg(long)]
    pub(crate) m_max: Option<Param>,
    /// User expression for the opacity (replaces SMEAR Eq. 12), e.g. "step(delta * m)".
    #[arg(long)]
    pub(crate) opacity_expr: Option<String>,
}

/// What the multiples flags resolve to before the input is read.
#[derive(Debug, Clone)]
pub(crate) struct MultiplesPlan {
    /// Copies, spacing and step.
    pub(crate) options: MultiplesOptions,
    /// Spacing Δf at frame 0.
    pub(crate) spacing: f32,
    /// m_max of SMEAR Eq. 12.
    pub(crate) m_max: Param,
    /// The opacity function (SMEAR Eq. 12 or the user's).
    pub(crate) opacity: FunctionSpec,
}

impl Multiples {
    /// Copies, spacing and opacity, checked.
    ///
    /// # Errors
    /// No copy at all, a bad spacing, or an opacity expression that does not compile.
    pub(crate) fn plan(&self, effect: &EffectArgs) -> Result<MultiplesPlan, FlagError> {
        let spacing = match (self.spacing.clone(), self.overlap.clone()) {
            (_, Some(n)) => Spacing::Overlap(n),
            (Some(df), None) => Spacing::Frames(df),
            (None, None) => Spacing::Frames(::smear::DEFAULT_SPACING.into()),
        };
        let options = MultiplesOptions {
            past: self.past.clone(),
            future: self.future.clone(),
            spacing,
            step: effect.step,
        };
        if options.indices().is_empty() {
            return Err(FlagError::Flag(
                "--past and --future are both 0: there is no copy to draw".into(),
            ));
        }
        let spacing = options.spacing_at(0.0)?;
        let largest = self.past.max_value().max(self.future.max_value()).round();
        let m_max = self.m_max.clone().unwrap_or(Param::Constant(largest));
        let opacity = match &self.opacity_expr {
            Some(e) => FunctionSpec::expr(e, &[("m_max", m_max.clone())]),
            None => effect.weighted(FunctionSpec::multiples(m_max.clone())),
        };
        check(&opacity, "--opacity-expr")?;
        Ok(MultiplesPlan {
            options,
            spacing,
            m_max,
            opacity,
        })
    }

    /// The style: the offsets `prepared` was made with and the copies of `plan`.
    ///
    /// # Errors
    /// As [`EffectArgs::shaping`].
    pub(crate) fn style(
        &self,
        effect: &EffectArgs,
        plan: &MultiplesPlan,
        prepared: &Prepared,
    ) -> Result<Style, FlagError> {
        Ok(Style {
            multiples: Some(MultiplesStyle {
                enabled: true,
                past: self.past.clone(),
                future: self.future.clone(),
                spacing: self.spacing.clone(),
                overlap: self.overlap.clone(),
                step: effect.step,
                opacity: Some(plan.opacity.clone()),
                color: [1.0; 3],
            }),
            ..effect.base_style(prepared)?
        })
    }
}

/// Flags of the motion lines (SMEAR Eq. 13).
#[derive(Debug, Clone, Args)]
pub(crate) struct Lines {
    /// Number of lines K (random surface points, area-weighted). Keyframes (FRAME:VALUE,...)
    /// sample as many seeds as the largest key and draw a fixed random subset per frame.
    #[arg(long, default_value_t = Param::Constant(::smear::DEFAULT_LINE_COUNT as f32))]
    pub(crate) count: Param,
    /// Maximum length τ_max in frames: S_L(δ; τ_max) = τ_max·δ (SMEAR Eq. 13); keyframeable.
    #[arg(long, default_value_t = Param::Constant(::smear::DEFAULT_LINE_LENGTH))]
    pub(crate) length_max: Param,
    /// Seed of every random choice (default: the tool's fixed seed; runs are reproducible).
    #[arg(long, value_name = "SEED")]
    pub(crate) seed: Option<u64>,
    /// User expression for τ in frames (replaces the linear one), e.g. "tau_max * speed *
    /// past(delta)"; inputs in size units (per second) as for --expr of `elongate`.
    #[arg(long)]
    pub(crate) length_expr: Option<String>,
    /// Tube radius in size units (one unit = the character's rest-pose bounding-box
    /// diagonal; scene units with --speed-units scene), default 0.002 × the body's diagonal;
    /// keyframeable.
    #[arg(long, conflicts_with = "thickness_expr")]
    pub(crate) thickness: Option<Param>,
    /// User expression for the tube radius along the line in size units (scene units with
    /// --speed-units scene; `t` = 0 at the surface), e.g. "0.01 * (1 - t)" for tapering
    /// lines.
    #[arg(long)]
    pub(crate) thickness_expr: Option<String>,
    /// User expression for the opacity along the line (`t` = 0 at the surface), e.g. "1 - t".
    #[arg(long)]
    pub(crate) opacity_expr: Option<String>,
    /// Gap between surface and line, in frames along the trajectory; keyframeable.
    #[arg(long, default_value = "0")]
    pub(crate) gap: Param,
    /// Seeds slower than this draw no line, in size units per second (one unit = the
    /// character's bounding-box diagonal; scene units per frame with --speed-units scene);
    /// keyframeable.
    #[arg(long, default_value = "0")]
    pub(crate) min_speed: Param,
    /// Line colour, linear R,G,B in [0, 1] (default near-black).
    #[arg(long, value_delimiter = ',')]
    pub(crate) color: Vec<f32>,
    /// Only trace the past (τ clamped to ≤ 0).
    #[arg(long)]
    pub(crate) past_only: bool,
    /// Sides of each tube.
    #[arg(long, default_value_t = ::smear::DEFAULT_LINE_SIDES)]
    pub(crate) sides: usize,
    /// Rings along each line.
    #[arg(long, default_value_t = ::smear::DEFAULT_LINE_SAMPLES)]
    pub(crate) samples: usize,
}

/// What the lines flags resolve to before the input is read.
#[derive(Debug, Clone)]
pub(crate) struct LinesPlan {
    /// S_L, the length function.
    pub(crate) length: FunctionSpec,
    /// The opacity along a line.
    pub(crate) opacity: FunctionSpec,
    /// The line colour.
    pub(crate) color: [Param; 3],
}

impl Lines {
    /// Length, opacity, count and colour, checked.
    ///
    /// # Errors
    /// A non-positive thickness, a function that does not compile, a count out of range or
    /// a colour that is not three numbers.
    pub(crate) fn plan(&self, effect: &EffectArgs) -> Result<LinesPlan, FlagError> {
        let flag = |s: String| Err(FlagError::Flag(s));
        if let Some(t) = &self.thickness {
            if t.validate("--thickness", (0.0, true), (f32::MAX, false))
                .is_err()
            {
                return flag(format!(
                    "--thickness {t}: the tube radius must be a positive number"
                ));
            }
        }
        let length = match &self.length_expr {
            Some(e) => FunctionSpec::expr(e, &[("tau_max", self.length_max.clone())]),
            None => effect.weighted(FunctionSpec::linear(self.length_max.clone())),
        };
        check(&length, "--length-expr")?;
        let opacity = match &self.opacity_expr {
            Some(e) => FunctionSpec::expr(e, &[]),
            None => FunctionSpec::stages(vec![Stage::Set { value: 1.0.into() }]),
        };
        check(&opacity, "--opacity-expr")?;
        if self
            .count
            .validate("--count", (0.0, false), (1e7, false))
            .is_err()
        {
            return flag(format!(
                "--count {}: give a number of lines from 0 to 10000000",
                self.count
            ));
        }
        let color = match self.color.as_slice() {
            [] => LineOptions::default().color,
            &[r, g, b] => [r, g, b].map(Param::Constant),
            c => {
                return flag(format!(
                    "--color takes R,G,B (3 numbers in [0, 1]), got {} numbers",
                    c.len()
                ))
            }
        };
        Ok(LinesPlan {
            length,
            opacity,
            color,
        })
    }

    /// The tube radius in scene units: `--thickness` (in the units of `effect`), or 0.002 ×
    /// the bounding-box diagonal of the body.
    ///
    /// # Errors
    /// An unknown `--size-reference` object.
    pub(crate) fn radius(
        &self,
        effect: &EffectArgs,
        prepared: &Prepared,
    ) -> Result<Param, FlagError> {
        let u = &effect.units;
        let units = prepared.units(
            u.speed_units().unwrap_or_default(),
            u.size_reference.as_ref(),
        )?;
        Ok(match &self.thickness {
            Some(t) => units.length_param_to_scene(t),
            None => Param::Constant(
                ::smear::DEFAULT_LINE_THICKNESS * prepared.animation(0).bbox().diagonal(),
            ),
        })
    }

    /// The style: the offsets `prepared` was made with and the lines of `plan`.
    ///
    /// # Errors
    /// A thickness function that does not compile, or as [`EffectArgs::shaping`].
    pub(crate) fn style(
        &self,
        effect: &EffectArgs,
        plan: &LinesPlan,
        prepared: &Prepared,
    ) -> Result<Style, FlagError> {
        // No thickness given: the style's default (a fraction of the body's diagonal).
        let thickness = match (&self.thickness_expr, &self.thickness) {
            (Some(e), _) => Some(FunctionSpec::expr(e, &[])),
            (None, Some(t)) => Some(FunctionSpec::stages(vec![Stage::Set { value: t.clone() }])),
            // In scene units the body's default radius as given before units existed (bit
            // for bit); in size units the style's default, the same fraction of the body.
            (None, None) if effect.units.speed_units() == Some(::smear::SpeedUnits::Scene) => {
                Some(FunctionSpec::stages(vec![Stage::Set {
                    value: Param::Constant(
                        ::smear::DEFAULT_LINE_THICKNESS * prepared.animation(0).bbox().diagonal(),
                    ),
                }]))
            }
            (None, None) => None,
        };
        let flag = match self.thickness_expr {
            Some(_) => "--thickness-expr",
            None => "--thickness",
        };
        if let Some(t) = &thickness {
            check(t, flag)?;
        }
        Ok(Style {
            lines: Some(LinesStyle {
                enabled: true,
                count: self.count.clone(),
                seed: self.seed.unwrap_or(::smear::DEFAULT_SEED),
                gap: self.gap.clone(),
                min_speed: self.min_speed.clone(),
                past_only: self.past_only,
                sides: self.sides,
                samples: self.samples,
                step: effect.step,
                color: plan.color.clone(),
                length: plan.length.clone(),
                thickness,
                opacity: plan.opacity.clone(),
            }),
            ..effect.base_style(prepared)?
        })
    }
}
