//! `toonkit loa line KEYS.json|KEYS.svg -o OUT.json|OUT.svg|OUT.png|OUT.gif [line options]`.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context as _, Result};
use clap::Args;
use serde_json::json;

use super::{read_keystrokes, warn, Context, LineFlags};

/// Arguments of `toonkit loa line`.
#[derive(Debug, Args)]
pub(crate) struct LineArgs {
    /// Keystrokes: JSON (`{"keystrokes": [{"frame", "points", "stiffness"?, "damping"?}]}`) or
    /// SVG (one `<path>`/`<polyline>` per keystroke with a `data-frame` attribute).
    pub(crate) input: PathBuf,
    /// Output: `.json` (frames of joint points, angles, lengths), `.svg` (onion skin), `.png`
    /// (onion skin) or `.gif` (animation).
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    #[command(flatten)]
    pub(crate) line: LineFlags,
}

/// Runs `toonkit loa line`.
pub(crate) fn run(ctx: &Context, args: LineArgs) -> Result<()> {
    let start = Instant::now();
    // Check the output first so a typo does not cost a computation.
    let ext = loa::job::check_line_path(&args.output)?;
    let keys = read_keystrokes(&args.input)?;
    let options = args.line.options(&keys)?;
    let line = loa::line(&keys, &options).with_context(|| args.input.display().to_string())?;
    warn(&line, &args.input);
    let a = &line.animation;
    let text;
    let bytes;
    let output = match ext.as_str() {
        "json" => {
            text = a.to_json_string();
            tkio::Output::Text(&text)
        }
        "svg" => {
            text = loa::to_svg_string(a, Some(&keys));
            tkio::Output::Text(&text)
        }
        _ => {
            bytes = loa::preview::line_preview(a, &keys, ext == "gif")
                .with_context(|| args.output.display().to_string())?;
            tkio::Output::Bytes(&bytes)
        }
    };
    tkio::save(&args.output, &output)?;
    let seconds = start.elapsed().as_secs_f64();
    let mode = format!("{:?}", options.mode).to_lowercase();
    let summary = json!({
        "output": args.output.display().to_string(),
        "mode": mode,
        "fps": a.fps,
        "frames": a.frames.len(),
        "keystroke_frames": a.keystroke_frames,
        "fit_residuals": line.keys.iter().map(|k| k.residual).collect::<Vec<_>>(),
        "retargets": line.retargets,
        "warnings": line.warnings,
        "seconds": seconds,
    });
    ctx.report(&summary, || {
        let worst = line.keys.iter().map(|k| k.residual.rms).fold(0.0, f64::max);
        format!(
            "{}: {} frames from {} keystrokes ({mode} mode, fit rms ≤ {worst:.3}) in {:.1} ms",
            args.output.display(),
            a.frames.len(),
            line.keys.len(),
            seconds * 1e3
        )
    });
    Ok(())
}
