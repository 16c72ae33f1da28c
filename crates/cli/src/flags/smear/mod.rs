//! The command-line flags of the smear jobs, declared in the CLI beside the smear crate's
//! options they fill: [`OffsetArgs`] → [`OffsetOptions`], [`EffectArgs`] → the offset,
//! weight, subdivision and contact parts of a [`Style`], and one struct per effect
//! ([`Elongate`], [`Multiples`], [`Lines`]) that builds the effect's part of the style. The
//! `toonkit smear` commands flatten them.

mod effects;

pub(crate) use effects::{Elongate, Lines, Multiples};

use clap::{Args, ValueEnum};

use ::smear::{
    CameraSelect, ContactStyle, FunctionSpec, OffsetOptions, Prepared, SizeReference, SpeedUnits,
    Stage, Style, WeightAttribute, WeightGroup, WeightSource,
};

use super::FlagError;

/// Motion-offset options (SMEAR Section 3), shared by `smear offsets` and every effect.
#[derive(Debug, Clone, Args)]
pub(crate) struct OffsetArgs {
    /// Temporal smoothing half-window N of SMEAR Eq. 2 (0 = off).
    #[arg(long, default_value_t = ::smear::DEFAULT_SMOOTH)]
    pub(crate) smooth: usize,
    /// Treat each skinned character as one object with one separation plane (Fig. 14).
    #[arg(long)]
    pub(crate) whole_body: bool,
    /// Bones to toggle off (comma-separated): their vertices follow the nearest kept ancestor.
    #[arg(long, value_delimiter = ',')]
    pub(crate) prune: Vec<String>,
    /// Compute offsets relative to this camera (node name, or index).
    #[arg(long)]
    pub(crate) camera: Option<String>,
    /// Disable the collinear weight of the ribbons (paper Fig. 7, shows the shearing it
    /// prevents).
    #[arg(long)]
    pub(crate) no_collinear: bool,
    /// Past-only mode: velocities, smoothing and trajectories of frame f read frames ≤ f only
    /// (as a game or live preview would); the smear lags slightly behind the offline one.
    #[arg(long)]
    pub(crate) causal: bool,
    /// Objects that revolve about an axis (wheels, propellers; comma-separated mesh names, or
    /// `auto` to detect them): offsets and trajectories follow arcs about the fitted axis.
    #[arg(long, value_delimiter = ',')]
    pub(crate) revolve: Vec<String>,
}

impl OffsetArgs {
    /// The library options; `--camera` is a camera name, or an index when no camera has that
    /// name.
    pub(crate) fn options(&self, sampled: &anim::SampledScene) -> OffsetOptions {
        let camera = self.camera.as_ref().map(|c| match c.parse::<usize>() {
            Ok(i) if !sampled.cameras.iter().any(|cam| cam.name == *c) => CameraSelect::Index(i),
            _ => CameraSelect::Name(c.clone()),
        });
        OffsetOptions {
            smooth: self.smooth,
            whole_body: self.whole_body,
            prune: self.prune.clone(),
            camera,
            collinear_weight: !self.no_collinear,
            causal: self.causal,
            revolve: self.revolve.clone(),
        }
    }
}

/// Options of every effect: the motion-offset options of `toonkit smear offsets`, the frame
/// step and painted weights.
#[derive(Debug, Clone, Args)]
pub(crate) struct EffectArgs {
    /// The motion-offset flags.
    #[command(flatten)]
    pub(crate) offsets: OffsetArgs,
    /// Frame step: 2 = "on twos" (displacements scaled by 2, drawings held two frames).
    #[arg(long, default_value_t = ::smear::DEFAULT_FRAME_STEP)]
    pub(crate) step: usize,
    /// Painted weights ω from a weight group (Fig. 15b): the skin weights of these joints and
    /// of every joint below them (comma-separated, case-sensitive). Presets are multiplied by
    /// ω; expressions read it as `weight`.
    #[arg(long, value_delimiter = ',', conflicts_with_all = ["weight_attribute", "weight_expr"])]
    pub(crate) weight_group: Vec<String>,
    /// With --weight-group: only the named joints, not their descendants.
    #[arg(long, requires = "weight_group")]
    pub(crate) weight_group_only: bool,
    /// Painted weights ω from a scalar vertex attribute painted in the animation package
    /// (glTF `_NAME`, e.g. `_SMEAR_WEIGHT`) or a vertex-colour channel (`COLOR_0.r`, `.g`,
    /// `.b`, `.a`), clamped to [0, 1].
    #[arg(long, conflicts_with = "weight_expr")]
    pub(crate) weight_attribute: Option<String>,
    /// Painted weights ω as an expression of the rest position `x, y, z` (size units, scene
    /// units with --speed-units scene), clamped to [0, 1], e.g. "clamp01(y / 0.5)".
    #[arg(long)]
    pub(crate) weight_expr: Option<String>,
    /// Adaptive subdivision: split output edges longer than TOL × their rest length, or whose
    /// smear curves away from them by more than 5 % × (TOL − 1) of it (TOL ≥ 1, e.g. 2). The mesh then changes per frame: write .glb, .usda, .usdc, .usdz or .abc.
    #[arg(long, value_name = "TOL")]
    pub(crate) subdivide: Option<f32>,
    /// A ground plane y = Y that the in-betweens never cross (Y in size units, scene units
    /// with --speed-units scene).
    #[arg(long, value_name = "Y", allow_negative_numbers = true)]
    pub(crate) ground: Option<f32>,
    /// With --ground: squash on impact, the height scaled by 1 − AMOUNT (volume kept),
    /// easing back over --squash-frames.
    #[arg(long, value_name = "AMOUNT", requires = "ground")]
    pub(crate) squash: Option<f32>,
    /// Frames a squash lasts.
    #[arg(long, default_value_t = ::smear::DEFAULT_SQUASH_FRAMES, requires = "squash")]
    pub(crate) squash_frames: usize,
    /// Collider meshes the in-betweens never enter (repeatable): every mesh of FILE (.obj,
    /// .glb, .stl, …), static or animated frame by frame. An open mesh blocks the side
    /// behind its normals, as the ground plane does.
    #[arg(long, value_name = "FILE")]
    pub(crate) collider: Vec<std::path::PathBuf>,
    /// An object of the input used as a collider (repeatable): not smeared, not written.
    #[arg(long, value_name = "NAME")]
    pub(crate) collider_object: Vec<String>,
    /// Units of the style's speeds and lengths.
    #[command(flatten)]
    pub(crate) units: UnitArgs,
}

/// What a style's speeds and lengths are measured in (`docs/smear-units.md`).
#[derive(Debug, Clone, Args)]
pub(crate) struct UnitArgs {
    /// Units of speeds (the `speed` input, --min-speed, thresholds) and lengths (--thickness,
    /// --ground, `x, y, z`, noise κ per length): `size` = the character's own size (one unit
    /// = its bounding-box diagonal at the rest pose, or --size-reference), speeds per
    /// second, so a style looks the same in centimetres and in metres; `scene` = scene units,
    /// speeds per frame (the paper's numbers). With --style: overrides the file's
    /// `speed_units`.
    #[arg(long, value_enum, value_name = "UNITS")]
    pub(crate) speed_units: Option<UnitsArg>,
    /// One size unit: a length in scene units (e.g. 1.8) or the name of an object whose
    /// bounding-box diagonal at the rest pose it is. With --style: overrides the file's
    /// `size_reference`.
    #[arg(long, value_name = "NODE|LENGTH")]
    pub(crate) size_reference: Option<SizeReference>,
}

/// `--speed-units`: the names and docs of [`SpeedUnits`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum UnitsArg {
    /// The character's own size: lengths in size units (one unit = the rest-pose
    /// bounding-box diagonal, or --size-reference), speeds in size units per second. The
    /// same style looks the same on a character modelled in centimetres or in metres.
    Size,
    /// The scene's units: lengths in scene units, speeds in scene units per frame (the
    /// paper's convention: the numbers of SMEAR Figs. 11–16 are tuned on one scale).
    Scene,
}

impl From<UnitsArg> for SpeedUnits {
    fn from(u: UnitsArg) -> SpeedUnits {
        match u {
            UnitsArg::Size => SpeedUnits::Size,
            UnitsArg::Scene => SpeedUnits::Scene,
        }
    }
}

impl UnitArgs {
    /// The units `--speed-units` asks for, if given.
    pub(crate) fn speed_units(&self) -> Option<SpeedUnits> {
        self.speed_units.map(SpeedUnits::from)
    }

    /// Sets the flags' units on `style` (flags given win over the file's).
    pub(crate) fn apply(&self, style: &mut Style) {
        if let Some(u) = self.speed_units() {
            style.speed_units = u;
        }
        if let Some(r) = &self.size_reference {
            style.size_reference = Some(r.clone());
        }
    }
}

impl EffectArgs {
    /// The style's subdivision and contact settings, checked.
    ///
    /// # Errors
    /// A tolerance below 1, a non-finite ground or a squash outside [0, 0.9].
    pub(crate) fn shaping(&self) -> Result<(Option<f32>, Option<ContactStyle>), FlagError> {
        let contact = self.ground.map(|g| ContactStyle {
            ground: g,
            squash: self.squash.unwrap_or(0.0),
            squash_frames: self.squash_frames,
        });
        let probe = Style {
            subdivide: self.subdivide,
            contact: contact.clone(),
            ..Style::default()
        };
        if let Err(e) = probe.validate() {
            return Err(FlagError::Flag(
                e.to_string()
                    .replace("subdivide", "--subdivide")
                    .replace("contact", "--ground/--squash"),
            ));
        }
        Ok((self.subdivide, contact))
    }

    /// `--step`, checked.
    ///
    /// # Errors
    /// A step of 0.
    pub(crate) fn check_step(&self) -> Result<(), FlagError> {
        if self.step == 0 {
            return Err(FlagError::Flag(
                "--step must be ≥ 1 (1 = on ones, 2 = on twos)".into(),
            ));
        }
        Ok(())
    }

    /// The painted-weight source the flags ask for, if any.
    pub(crate) fn weight_source(&self) -> Option<WeightSource> {
        if !self.weight_group.is_empty() {
            return Some(WeightSource::Group(WeightGroup {
                group: self.weight_group.clone(),
                descendants: !self.weight_group_only,
            }));
        }
        if let Some(a) = &self.weight_attribute {
            return Some(WeightSource::Attribute(WeightAttribute {
                attribute: a.clone(),
            }));
        }
        self.weight_expr
            .as_ref()
            .map(|e| WeightSource::Function(FunctionSpec::expr(e, &[])))
    }

    /// A preset stylization function, multiplied by ω when painted weights are given.
    pub(crate) fn weighted(&self, mut preset: FunctionSpec) -> FunctionSpec {
        if self.weight_source().is_some() && preset.expr.is_none() {
            preset.stages.push(Stage::Weight);
        }
        preset
    }

    /// A style with only the offsets `prepared` was prepared with and the subdivision and
    /// contact settings of the flags (the effects add themselves).
    ///
    /// # Errors
    /// As [`EffectArgs::shaping`].
    pub(crate) fn base_style(&self, prepared: &Prepared) -> Result<Style, FlagError> {
        let (subdivide, contact) = self.shaping()?;
        // A function of the rest position reads it in the flags' units: resolved with the
        // style, not at preparation.
        let weights = self
            .weight_source()
            .filter(|w| matches!(w, WeightSource::Function(_)));
        let mut style = Style {
            offsets: prepared.options().offsets.clone(),
            subdivide,
            contact,
            weights,
            ..Style::default()
        };
        self.units.apply(&mut style);
        Ok(style)
    }
}

/// Checks that a user function compiles, naming the flag that gave it.
fn check(spec: &FunctionSpec, flag: &str) -> Result<(), FlagError> {
    spec.compile()
        .map(|_| ())
        .map_err(|e| FlagError::Flag(format!("{flag}: {e}")))
}

#[cfg(test)]
mod tests {
    use clap::ValueEnum;

    use super::effects::PresetArg;
    use super::*;

    /// `--preset` and `--speed-units` take exactly the smear crate's names (those of style
    /// files and the Python module), each for its own value.
    #[test]
    fn preset_and_units_flags_take_the_core_names() {
        let presets: Vec<(String, &str)> = PresetArg::value_variants()
            .iter()
            .map(|p| {
                let flag = p.to_possible_value().unwrap().get_name().to_string();
                (flag, ::smear::ElongatePreset::from(*p).name())
            })
            .collect();
        assert_eq!(presets.len(), ::smear::ElongatePreset::ALL.len());
        for (flag, core) in &presets {
            assert_eq!(flag, core);
        }
        for u in UnitsArg::value_variants() {
            let flag = u.to_possible_value().unwrap().get_name().to_string();
            let core = serde_json::to_value(SpeedUnits::from(*u)).unwrap();
            assert_eq!(serde_json::Value::String(flag), core);
        }
    }
}
