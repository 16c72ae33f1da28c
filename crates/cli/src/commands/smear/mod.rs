//! `toonkit smear`: motion offsets and smear effects of Basset et al. 2024 (SMEAR). Every
//! command is argument parsing, `tkio::load`, one call of the `smear` crate, `tkio::save`
//! and a summary.
//!
//! * [`offsets`]: `smear offsets IN -o OUT.npy|OUT.glb` ([`smear::offsets`]).
//! * [`effects`]: `smear elongate | multiples | lines` ([`smear::prepare`] with all objects
//!   merged, then [`smear::stylize`] with the style the flags describe).
//! * [`style`]: `smear IN --style STYLE.toml -o OUT` ([`smear::prepare`] per object, then
//!   [`smear::stylize`]).
//!
//! The argument structs every command shares live here.

mod effects;
mod offsets;
mod style;

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use clap::{Args, Subcommand};
use smear::{
    CameraSelect, ContactStyle, FunctionSpec, OffsetOptions, PrepareOptions, Prepared, Stage,
    WeightAttribute, WeightGroup, WeightSource,
};

use super::Context;
use crate::input::{self, InputArgs};

/// Arguments of `toonkit smear`: a subcommand, or `IN --style STYLE.toml -o OUT.glb`.
#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true)]
pub(crate) struct SmearArgs {
    #[command(subcommand)]
    pub(crate) command: Option<SmearCommand>,
    #[command(flatten)]
    pub(crate) style: style::StyleArgs,
}

/// Subcommands of `toonkit smear`.
#[derive(Debug, Subcommand)]
pub(crate) enum SmearCommand {
    /// Motion offsets per frame and vertex: leading parts > 0, trailing parts < 0 (§3).
    Offsets(offsets::OffsetsArgs),
    /// Elongated in-betweens: vertices slid along their trajectories by β = S_E(δ) (§4.1).
    Elongate(effects::ElongateArgs),
    /// Multiple in-betweens: displaced copies with per-vertex opacity (§4.2).
    Multiples(effects::MultiplesArgs),
    /// Motion lines: tubes along seed trajectories, length τ = S_L(δ) (§4.3).
    Lines(effects::LinesArgs),
}

/// Runs `toonkit smear`.
pub(crate) fn run(ctx: &Context, args: SmearArgs) -> Result<()> {
    match args.command {
        None => style::run(ctx, args.style),
        Some(SmearCommand::Offsets(a)) => offsets::run(ctx, a),
        Some(SmearCommand::Elongate(a)) => effects::elongate(ctx, a),
        Some(SmearCommand::Multiples(a)) => effects::multiples(ctx, a),
        Some(SmearCommand::Lines(a)) => effects::lines(ctx, a),
    }
}

/// Motion-offset options (SMEAR Section 3), shared by `smear offsets` and every effect.
#[derive(Debug, Clone, Args)]
pub(crate) struct OffsetArgs {
    /// Temporal smoothing half-window N of SMEAR Eq. 2 (0 = off).
    #[arg(long, default_value_t = smear::DEFAULT_SMOOTH)]
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

/// Input and output of an effect command.
#[derive(Debug, Args)]
pub(crate) struct EffectIo {
    /// Input animation (glTF/GLB with skins, OBJ sequence, PC2/MDD + rest OBJ).
    pub(crate) input: PathBuf,
    /// Output file (see the command's description for the formats).
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    #[command(flatten)]
    pub(crate) input_args: InputArgs,
}

/// Options of every effect: the motion-offset options of `toonkit smear offsets`, the frame
/// step and painted weights.
#[derive(Debug, Clone, Args)]
pub(crate) struct EffectArgs {
    #[command(flatten)]
    pub(crate) offsets: OffsetArgs,
    /// Frame step: 2 = "on twos" (displacements scaled by 2, drawings held two frames).
    #[arg(long, default_value_t = smear::DEFAULT_FRAME_STEP)]
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
    /// Painted weights ω as an expression of the rest position `x, y, z`, clamped to [0, 1],
    /// e.g. "clamp01(y / 2)".
    #[arg(long)]
    pub(crate) weight_expr: Option<String>,
    /// Adaptive subdivision: split output edges longer than TOL × their rest length (TOL ≥ 1,
    /// e.g. 2). The mesh then changes per frame: write .glb, .usda, .usdc, .usdz or .abc.
    #[arg(long, value_name = "TOL")]
    pub(crate) subdivide: Option<f32>,
    /// A ground plane y = Y that the in-betweens never cross.
    #[arg(long, value_name = "Y", allow_negative_numbers = true)]
    pub(crate) ground: Option<f32>,
    /// With --ground: squash on impact, the height scaled by 1 − AMOUNT (volume kept),
    /// easing back over --squash-frames.
    #[arg(long, value_name = "AMOUNT", requires = "ground")]
    pub(crate) squash: Option<f32>,
    /// Frames a squash lasts.
    #[arg(long, default_value_t = smear::DEFAULT_SQUASH_FRAMES, requires = "squash")]
    pub(crate) squash_frames: usize,
    /// Collider meshes the in-betweens never enter (repeatable): every mesh of FILE (.obj,
    /// .glb, .stl, …), static or animated frame by frame. An open mesh blocks the side
    /// behind its normals, as the ground plane does.
    #[arg(long, value_name = "FILE")]
    pub(crate) collider: Vec<PathBuf>,
    /// An object of the input used as a collider (repeatable): not smeared, not written.
    #[arg(long, value_name = "NAME")]
    pub(crate) collider_object: Vec<String>,
}

impl EffectArgs {
    /// The style's subdivision and contact settings (issue #22), checked.
    ///
    /// # Errors
    /// A tolerance below 1, a non-finite ground or a squash outside [0, 0.9].
    pub(crate) fn shaping(&self) -> Result<(Option<f32>, Option<ContactStyle>)> {
        let contact = self.ground.map(|g| ContactStyle {
            ground: g,
            squash: self.squash.unwrap_or(0.0),
            squash_frames: self.squash_frames,
        });
        let probe = smear::Style {
            subdivide: self.subdivide,
            contact: contact.clone(),
            ..smear::Style::default()
        };
        if let Err(e) = probe.validate() {
            bail!(
                "{}",
                e.to_string()
                    .replace("subdivide", "--subdivide")
                    .replace("contact", "--ground/--squash")
            );
        }
        Ok((self.subdivide, contact))
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
}

/// Loads the input of an effect command and prepares it with every object merged into one
/// (named after the input file, the vertex order of `toonkit convert IN rest.obj`).
///
/// # Errors
/// One line naming the input: unreadable, bad offset options, unknown joint/attribute/camera.
fn prepare(io: &EffectIo, a: &EffectArgs) -> Result<Prepared> {
    let path = io.input.as_path();
    if a.step == 0 {
        bail!("--step must be ≥ 1 (1 = on ones, 2 = on twos)");
    }
    let sampled = input::open(path, &io.input_args)?;
    if sampled.objects.is_empty() {
        bail!("{}: the file has no mesh", path.display());
    }
    let options = PrepareOptions {
        offsets: a.offsets.options(&sampled),
        weights: a.weight_source(),
        merge: Some(input::merged_name(path)),
        colliders: a.collider_object.clone(),
    };
    let mut prepared = smear::prepare(sampled, &options).map_err(at_input(path))?;
    for file in &a.collider {
        let scene = input::open(file, &InputArgs::default())?;
        if scene.objects.is_empty() {
            bail!("{}: the collider file has no mesh", file.display());
        }
        for o in &scene.objects {
            prepared.add_collider(smear::Collider::from_animation(&o.animation));
        }
    }
    Ok(prepared)
}

/// Maps a smear error to one line naming the input.
fn at_input(path: &Path) -> impl Fn(smear::SmearError) -> anyhow::Error + '_ {
    move |e| anyhow::anyhow!("{}: {e}", path.display())
}
