//! `toonkit loa line|animate`: argument parsing and printing around `loa::line` and
//! `loa::animate` (Guay et al. 2015, the LoA paper).

mod animate;
mod line;

use std::path::Path;

use anyhow::{Context as _, Result};
use clap::{Args, Subcommand, ValueEnum};

use super::Context;

/// Arguments of `toonkit loa`.
#[derive(Debug, Args)]
pub(crate) struct LoaArgs {
    #[command(subcommand)]
    pub(crate) command: LoaCommand,
}

/// Subcommands of `toonkit loa`.
#[derive(Debug, Subcommand)]
pub(crate) enum LoaCommand {
    /// Interpolate sketched keystrokes into a dynamic line of action (Guay et al. 2015, §3).
    Line(line::LineArgs),
    /// Synthesize 3D character motion that follows the dynamic line (Guay et al. 2015, §4).
    Animate(Box<animate::AnimateArgs>),
}

/// Runs `toonkit loa …`.
pub(crate) fn run(ctx: &Context, args: LoaArgs) -> Result<()> {
    match args.command {
        LoaCommand::Line(a) => line::run(ctx, a),
        LoaCommand::Animate(a) => animate::run(ctx, *a),
    }
}

/// Interpolation mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub(crate) enum ModeArg {
    /// Elastic chain simulation re-targeted onto every keystroke (anticipation, follow-through).
    #[default]
    Physics,
    /// Hermite splines of angles, lengths and root (geometric in-betweens).
    Hermite,
}

/// Line options shared by `loa line` and `loa animate`.
#[derive(Debug, Args)]
pub(crate) struct LineFlags {
    /// Interpolation mode.
    #[arg(long, value_enum, default_value_t = ModeArg::Physics)]
    pub(crate) mode: ModeArg,
    /// Frames per second (default: the keystrokes', else 24).
    #[arg(long, value_name = "FPS")]
    pub(crate) fps: Option<f32>,
    /// Integration sub-steps per frame.
    #[arg(long, default_value_t = loa::DEFAULT_SUBSTEPS)]
    pub(crate) substeps: u32,
    /// Frames simulated from each keystroke (`M`), or `gap` for the frame gap between keys.
    #[arg(long, default_value = "40")]
    pub(crate) simulated_frames: String,
    /// Rigid elements per chain (even).
    #[arg(long, default_value_t = loa::DEFAULT_ELEMENTS)]
    pub(crate) elements: usize,
    /// Follow-through after the last keystroke, ending on it at rest: a frame count (0 = end
    /// on the last keystroke), or `key` for one key interval (the last one).
    #[arg(long, default_value = "key")]
    pub(crate) settle: String,
    /// Drag-to-wobble `FRAME:S:DX,DY`: hit the line at frame FRAME, at arc-length position
    /// S (0..1), with impulse DX,DY (screen units per second). Repeatable.
    #[arg(long = "wobble", allow_hyphen_values = true)]
    pub(crate) wobbles: Vec<String>,
    /// Stroke smoothing before the fit: Gaussian σ as a fraction of the stroke's length
    /// (0 = fit the raw samples).
    #[arg(long, default_value_t = loa::DEFAULT_STROKE_SMOOTHING)]
    pub(crate) smoothing: f64,
}

impl LineFlags {
    /// The library options for keystrokes `keys`.
    fn options(&self, keys: &loa::Keystrokes) -> Result<loa::LineOptions> {
        let simulated_frames = match self.simulated_frames.trim() {
            "gap" => loa::SimulatedFrames::FrameGap,
            m => loa::SimulatedFrames::Fixed(m.parse().with_context(|| {
                format!("--simulated-frames {m}: expected a frame count or \"gap\"")
            })?),
        };
        let settle = match self.settle.trim() {
            "key" => loa::Settle::KeyInterval,
            s => loa::Settle::Frames(
                s.parse()
                    .with_context(|| format!("--settle {s}: expected a frame count or \"key\""))?,
            ),
        };
        let wobbles = self
            .wobbles
            .iter()
            .map(|w| w.parse().with_context(|| format!("--wobble {w}")))
            .collect::<Result<_>>()?;
        Ok(loa::LineOptions {
            mode: match self.mode {
                ModeArg::Physics => loa::Mode::Physics,
                ModeArg::Hermite => loa::Mode::Hermite,
            },
            elements: self.elements,
            physics: loa::PhysicsOptions {
                fps: self
                    .fps
                    .map(f64::from)
                    .or(keys.fps())
                    .unwrap_or(loa::DEFAULT_FPS),
                substeps: self.substeps,
                simulated_frames,
                settle,
                ..Default::default()
            },
            smoothing: self.smoothing,
            wobbles,
            ..Default::default()
        })
    }
}

/// Reads keystrokes (JSON or SVG).
fn read_keystrokes(path: &Path) -> Result<loa::Keystrokes> {
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    loa::Keystrokes::parse(&text).with_context(|| path.display().to_string())
}

/// Prints the line's warnings (reversed keystrokes) on stderr, one line each.
fn warn(line: &loa::Line, keys: &Path) {
    for w in &line.warnings {
        eprintln!("warning: {}: {w}", keys.display());
    }
}

/// The lower-case extension of `path`.
fn extension(path: &Path) -> String {
    crate::output::extension(path)
}

/// The line preview (`render::line_preview`): a GIF of every frame, or a PNG onion skin.
pub(crate) fn render_line(
    animation: &loa::Animation,
    keys: &loa::Keystrokes,
    gif: bool,
) -> Result<Vec<u8>> {
    use anim::glam::Vec2;
    let chains: Vec<Vec<Vec2>> = animation
        .frames
        .iter()
        .map(|f| f.chain.joints().iter().map(|p| p.as_vec2()).collect())
        .collect();
    let strokes: Vec<Vec<Vec2>> = keys
        .keys()
        .iter()
        .map(|k| k.stroke.points().iter().map(|p| p.as_vec2()).collect())
        .collect();
    Ok(render::line_preview(
        &chains,
        &strokes,
        animation.fps as f32,
        gif,
    )?)
}
