//! `toonkit smear IN --style STYLE.toml -o OUT.glb|OUT.usda [--gif PREVIEW.gif] [--clip NAME]
//! [--fps F]`.
//!
//! Applies a whole style (SMEAR Section 4 effects with the Section 5 stylization functions;
//! format in `examples/smear/`) with [`smear::prepare`] and [`smear::stylize`]: per object,
//! the elongated in-betweens (or the input when the style has none), the multiple
//! in-betweens as alpha-coloured copies and the motion lines as tubes, all as flipbooks in
//! one `.glb` (or one Mesh prim per part in `.usda`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, bail, Result};
use clap::Args;
use serde_json::json;
use smear::{PrepareOptions, Style};
use tkio::{Format, Output};

use super::Context;
use crate::flags::io::InputArgs;

/// The top-level form of `toonkit smear` (no subcommand).
#[derive(Debug, Args)]
pub(crate) struct StyleArgs {
    /// Input animation (glTF/GLB with skins, OBJ sequence, PC2/MDD + rest OBJ).
    pub(crate) input: Option<PathBuf>,
    /// Style file (TOML, see examples/smear/).
    #[arg(long)]
    pub(crate) style: Option<PathBuf>,
    /// Output `.glb` (every effect of the style as flipbooks) or `.usda` (one Mesh per part).
    #[arg(short, long)]
    pub(crate) output: Option<PathBuf>,
    /// Also render a GIF preview of the result.
    #[arg(long)]
    pub(crate) gif: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) units: crate::flags::smear::UnitArgs,
    #[command(flatten)]
    pub(crate) input_args: InputArgs,
}

/// Reads a style file.
///
/// # Errors
/// One line naming the file: unreadable, bad TOML, or an invalid function.
fn read_style(path: &Path) -> Result<Style> {
    let bytes = tkio::read_file(path)?;
    let text = String::from_utf8(bytes)
        .map_err(|_| anyhow!("{}: a style file is UTF-8 text", path.display()))?;
    Style::from_toml_str(&text).map_err(|e| anyhow!("{}: {e}", path.display()))
}

/// Runs `toonkit smear IN --style S -o OUT`.
pub(crate) fn run(ctx: &Context, args: StyleArgs) -> Result<()> {
    let start = Instant::now();
    let (Some(input_path), Some(style_path), Some(output)) =
        (&args.input, &args.style, &args.output)
    else {
        bail!(
            "usage: toonkit smear IN --style STYLE.toml -o OUT.glb|OUT.usda (or a subcommand, see --help)"
        );
    };
    if !Format::from_extension(output).is_some_and(Format::holds_scenes) {
        bail!(
            "{}: a styled smear is written as {}",
            output.display(),
            Format::list(&Format::SCENES)
        );
    }
    let mut style = read_style(style_path)?;
    args.units.apply(&mut style);
    let sampled = tkio::open(input_path, &args.input_args.options())?;
    if sampled.objects.is_empty() {
        bail!("{}: the file has no mesh", input_path.display());
    }
    let spinner = crate::progress::spinner("applying the style", ctx.json);
    let with_input = |e: smear::SmearError| anyhow!("{}: {e}", input_path.display());
    let options = PrepareOptions {
        offsets: style.offsets.clone(),
        ..PrepareOptions::default()
    };
    let prepared = smear::prepare(sampled, &options).map_err(with_input)?;
    let styled = smear::stylize(&prepared, &style).map_err(with_input)?;
    let t = Instant::now();
    tkio::save_with(output, &Output::Flipbook(&styled.flipbook), ctx.save)?;
    let write_seconds = t.elapsed().as_secs_f64();
    let mut outputs = vec![output.clone()];
    if let Some(gif) = &args.gif {
        let bytes = render::flipbook_gif(&styled.flipbook, 400, 400)?;
        tkio::save(gif, &Output::Bytes(&bytes))?;
        outputs.push(gif.clone());
    }
    spinner.finish_and_clear();
    let book = &styled.flipbook;
    let seconds = &styled.report.seconds;
    let summary = json!({
        "input": input_path,
        "style": style_path,
        "outputs": outputs,
        "frames": book.frames,
        "fps": book.fps,
        "parts": book.parts.len(),
        "objects": styled.report.objects,
        "speed_units": styled.report.speed_units,
        "size": styled.report.size,
        "timings": {"offsets": prepared.report().seconds, "elongate": seconds.elongate,
                    "multiples": seconds.multiples, "lines": seconds.lines,
                    "write": write_seconds},
        "seconds": start.elapsed().as_secs_f64(),
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({} frames, {} flipbooks) in {:.2} s",
            output.display(),
            book.frames,
            book.parts.len(),
            start.elapsed().as_secs_f64()
        )
    });
    Ok(())
}
