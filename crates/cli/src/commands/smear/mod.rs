//! `toonkit smear`: motion offsets and smear effects of Basset et al. 2024 (SMEAR). Each
//! command is `tkio::load`, [`smear::prepare`] (or [`smear::offsets`]), [`smear::stylize`]
//! with the style its flags (or `--style STYLE.toml`) describe, `tkio::save` and a summary.

mod effects;
mod offsets;
mod style;

use std::path::{Path, PathBuf};

pub(crate) use crate::flags::smear::{EffectArgs, OffsetArgs};
use anyhow::{bail, Result};
use clap::{Args, Subcommand};
use smear::{PrepareOptions, Prepared};

use super::Context;
use crate::flags::io::InputArgs;
use crate::flags::Deferred;

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
    Offsets(Deferred<offsets::OffsetsArgs>),
    /// Elongated in-betweens: vertices slid along their trajectories by β = S_E(δ) (§4.1).
    Elongate(Deferred<effects::ElongateArgs>),
    /// Multiple in-betweens: displaced copies with per-vertex opacity (§4.2).
    Multiples(Deferred<effects::MultiplesArgs>),
    /// Motion lines: tubes along seed trajectories, length τ = S_L(δ) (§4.3).
    Lines(Deferred<effects::LinesArgs>),
}

/// Runs `toonkit smear`.
pub(crate) fn run(ctx: &Context, args: SmearArgs) -> Result<()> {
    match args.command {
        None => style::run(ctx, args.style),
        Some(SmearCommand::Offsets(a)) => offsets::run(ctx, a.0),
        Some(SmearCommand::Elongate(a)) => effects::elongate(ctx, a.0),
        Some(SmearCommand::Multiples(a)) => effects::multiples(ctx, a.0),
        Some(SmearCommand::Lines(a)) => effects::lines(ctx, a.0),
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

/// Loads the input of an effect command and prepares it with every object merged into one
/// (named after the input file, the vertex order of `toonkit convert IN rest.obj`).
///
/// # Errors
/// One line naming the input: unreadable, bad offset options, unknown joint/attribute/camera.
fn prepare(io: &EffectIo, a: &EffectArgs) -> Result<Prepared> {
    let path = io.input.as_path();
    a.check_step()?;
    let sampled = tkio::open(path, &io.input_args.options())?;
    if sampled.objects.is_empty() {
        bail!("{}: the file has no mesh", path.display());
    }
    let options = PrepareOptions {
        offsets: a.offsets.options(&sampled),
        weights: a.weight_source(),
        merge: Some(tkio::sampling::merged_name(path)),
        colliders: a.collider_object.clone(),
    };
    let mut prepared = smear::prepare(sampled, &options).map_err(at_input(path))?;
    for file in &a.collider {
        let scene = tkio::open(file, &tkio::OpenOptions::default())?;
        prepared.add_colliders(&scene).map_err(at_input(file))?;
    }
    Ok(prepared)
}

/// Maps a smear error to one line naming the input.
fn at_input(path: &Path) -> impl Fn(smear::SmearError) -> anyhow::Error + '_ {
    move |e| anyhow::anyhow!("{}: {e}", path.display())
}
