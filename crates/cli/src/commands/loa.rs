//! `toonkit loa line KEYS.json|KEYS.svg -o OUT.json|OUT.svg [--mode physics|hermite] [--fps F]
//! [--substeps K] [--simulated-frames M|gap] [--elements N]`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use clap::{Args, Subcommand, ValueEnum};
use serde_json::json;

use super::Context;

/// Arguments of `toonkit loa`.
#[derive(Debug, Args)]
pub struct LoaArgs {
    #[command(subcommand)]
    pub command: LoaCommand,
}

/// Subcommands of `toonkit loa`.
#[derive(Debug, Subcommand)]
pub enum LoaCommand {
    /// Interpolate sketched keystrokes into a dynamic line of action (Guay et al. 2015, §3).
    Line(LineArgs),
    /// Synthesize 3D character motion that follows the dynamic line (Guay et al. 2015, §4).
    Animate(super::loa_animate::AnimateArgs),
}

/// Interpolation mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum ModeArg {
    /// Elastic chain simulation re-targeted onto every keystroke (anticipation, follow-through).
    #[default]
    Physics,
    /// Hermite splines of angles, lengths and root (geometric in-betweens).
    Hermite,
}

/// Arguments of `toonkit loa line`.
#[derive(Debug, Args)]
pub struct LineArgs {
    /// Keystrokes: JSON (`{"keystrokes": [{"frame", "points", "stiffness"?, "damping"?}]}`) or
    /// SVG (one `<path>`/`<polyline>` per keystroke with a `data-frame` attribute).
    pub input: PathBuf,
    /// Output: `.json` (frames of joint points, angles, lengths) or `.svg` (onion skin).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Interpolation mode.
    #[arg(long, value_enum, default_value_t = ModeArg::Physics)]
    pub mode: ModeArg,
    /// Frames per second (default: the input's, else 24).
    #[arg(long)]
    pub fps: Option<f64>,
    /// Integration sub-steps per frame.
    #[arg(long, default_value_t = loa::DEFAULT_SUBSTEPS)]
    pub substeps: u32,
    /// Frames simulated from each keystroke (`M`), or `gap` for the frame gap between keys.
    #[arg(long, default_value = "40")]
    pub simulated_frames: String,
    /// Rigid elements per chain (even).
    #[arg(long, default_value_t = loa::DEFAULT_ELEMENTS)]
    pub elements: usize,
}

/// Runs `toonkit loa …`.
pub fn run(ctx: &Context, args: LoaArgs) -> Result<()> {
    match args.command {
        LoaCommand::Line(a) => line(ctx, a),
        LoaCommand::Animate(a) => super::loa_animate::run(ctx, a),
    }
}

/// The output kinds `loa line` can write.
enum OutputKind {
    Json,
    Svg,
    Png,
    Gif,
}

fn output_kind(path: &Path) -> Result<OutputKind> {
    let ext = crate::output::extension(path);
    match ext.as_str() {
        "json" => Ok(OutputKind::Json),
        "svg" => Ok(OutputKind::Svg),
        "png" => Ok(OutputKind::Png),
        "gif" => Ok(OutputKind::Gif),
        _ => bail!(
            "{}: unknown output extension (use .json, .svg, .png or .gif)",
            path.display()
        ),
    }
}

pub(super) fn read_keystrokes(path: &Path) -> Result<loa::Keystrokes> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let is_svg = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"))
        || text.trim_start().starts_with('<');
    let keys = if is_svg {
        loa::Keystrokes::from_svg_str(&text)
    } else {
        loa::Keystrokes::from_json_str(&text)
    };
    keys.with_context(|| format!("{}", path.display()))
}

fn line(ctx: &Context, args: LineArgs) -> Result<()> {
    let start = Instant::now();
    // Check the output first so a typo does not cost a computation.
    let kind = output_kind(&args.output)?;
    let keys = read_keystrokes(&args.input)?;
    let simulated_frames = match args.simulated_frames.trim() {
        "gap" => loa::SimulatedFrames::FrameGap,
        m => loa::SimulatedFrames::Fixed(m.parse().with_context(|| {
            format!("--simulated-frames {m}: expected a frame count or \"gap\"")
        })?),
    };
    let options = loa::LineOptions {
        mode: match args.mode {
            ModeArg::Physics => loa::Mode::Physics,
            ModeArg::Hermite => loa::Mode::Hermite,
        },
        elements: args.elements,
        physics: loa::PhysicsOptions {
            fps: args.fps.or(keys.fps()).unwrap_or(loa::DEFAULT_FPS),
            substeps: args.substeps,
            simulated_frames,
            ..Default::default()
        },
    };
    let line = loa::line_of_action(&keys, &options)
        .with_context(|| format!("{}", args.input.display()))?;
    let bytes = match kind {
        OutputKind::Json => line.animation.to_json_string().into_bytes(),
        OutputKind::Svg => loa::to_svg_string(&line.animation, Some(&keys)).into_bytes(),
        OutputKind::Png | OutputKind::Gif => {
            let gif = matches!(kind, OutputKind::Gif);
            super::loa_render::render_line(&line.animation, &keys, gif)
                .with_context(|| args.output.display().to_string())?
        }
    };
    tkio::write_atomic(&args.output, &bytes)?;
    let seconds = start.elapsed().as_secs_f64();
    let summary = json!({
        "output": args.output.display().to_string(),
        "mode": format!("{:?}", args.mode).to_lowercase(),
        "fps": line.animation.fps,
        "frames": line.animation.frames.len(),
        "keystroke_frames": line.animation.keystroke_frames,
        "fit_residuals": line.keys.iter().map(|k| k.residual).collect::<Vec<_>>(),
        "retargets": line.retargets,
        "seconds": seconds,
    });
    ctx.report(&summary, || {
        let worst = line.keys.iter().map(|k| k.residual.rms).fold(0.0, f64::max);
        format!(
            "{}: {} frames from {} keystrokes ({} mode, fit rms ≤ {worst:.3}) in {:.1} ms",
            args.output.display(),
            line.animation.frames.len(),
            line.keys.len(),
            format!("{:?}", args.mode).to_lowercase(),
            seconds * 1e3
        )
    });
    Ok(())
}
