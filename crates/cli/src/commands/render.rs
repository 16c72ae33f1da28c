//! `toonkit render IN -o OUT.png|OUT.gif [--frame F] [--onion K] [--color none|offsets|speed]
//! [--view front|back|side|top|three-quarter|camera:NAME] [--size WxH] [--supersample S]
//! [--clip NAME] [--fps F] [--sheet [--every N] [--columns C]]`.

use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use clap::{Args, ValueEnum};
use render::{ColorMap, OutputFormat, PreviewOptions, ViewDirection, ViewSpec};
use serde_json::json;

use super::Context;
use crate::input::{self, InputArgs};

/// What the surface colour shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub(crate) enum ColorArg {
    /// The meshes' own vertex colours, or grey.
    #[default]
    None,
    /// Smear motion offsets (Basset et al. 2024, Eqs. 1–9): red leads, blue trails.
    Offsets,
    /// Vertex speed (units per frame), normalized by its maximum over the clip.
    Speed,
}

/// Arguments of `toonkit render`.
#[derive(Debug, Args)]
pub(crate) struct RenderArgs {
    /// The animation or mesh to preview (glTF, GLB, OBJ, PC2, MDD, STL).
    pub(crate) input: std::path::PathBuf,
    /// Output image: `.png` (one frame) or `.gif` (every frame, looping).
    #[arg(short, long)]
    pub(crate) output: std::path::PathBuf,
    /// Frame of a PNG (0-based; default: the first).
    #[arg(long, value_name = "N")]
    pub(crate) frame: Option<usize>,
    /// Onion skin: ghosts of this many neighbouring frames on each side.
    #[arg(long, default_value_t = 0)]
    pub(crate) onion: usize,
    /// Surface colouring.
    #[arg(long, value_enum, default_value_t = ColorArg::None)]
    pub(crate) color: ColorArg,
    /// View: front, back, side, top, three-quarter (orthographic, fitted to the whole
    /// motion), follow[:DIRECTION] (same scale, tracking a travelling subject) or camera:NAME
    /// (a scene camera).
    #[arg(long, default_value = "three-quarter")]
    pub(crate) view: String,
    /// Image size, WxH.
    #[arg(long, default_value = "400x400")]
    pub(crate) size: String,
    /// Supersampling per axis (1 = none, up to 4).
    #[arg(long, default_value_t = 2)]
    pub(crate) supersample: u32,
    /// Write a contact sheet (`.png`): frames 0, N, 2N, … on a grid, numbered.
    #[arg(long)]
    pub(crate) sheet: bool,
    /// Frame stride N of the contact sheet (default: about 16 cells).
    #[arg(long, requires = "sheet")]
    pub(crate) every: Option<usize>,
    /// Columns of the contact sheet (default: square-ish).
    #[arg(long, requires = "sheet", default_value_t = 0)]
    pub(crate) columns: usize,
    #[command(flatten)]
    pub(crate) input_args: InputArgs,
}

fn parse_view(s: &str) -> Result<ViewSpec> {
    if let Some(name) = s.strip_prefix("camera:") {
        return Ok(ViewSpec::Camera(name.to_string()));
    }
    let direction = |d: &str| {
        Ok(match d {
            "front" => ViewDirection::Front,
            "back" => ViewDirection::Back,
            "side" => ViewDirection::Side,
            "top" => ViewDirection::Top,
            "three-quarter" | "3/4" => ViewDirection::ThreeQuarter,
            _ => bail!(
                "--view {s}: expected front, back, side, top, three-quarter, follow[:DIRECTION] \
                 or camera:NAME"
            ),
        })
    };
    match s.strip_prefix("follow") {
        Some("") => Ok(ViewSpec::Follow(ViewDirection::ThreeQuarter)),
        Some(rest) if rest.starts_with(':') => Ok(ViewSpec::Follow(direction(&rest[1..])?)),
        _ => Ok(ViewSpec::Direction(direction(s)?)),
    }
}

fn parse_size(s: &str) -> Result<(u32, u32)> {
    let parse = || -> Option<(u32, u32)> {
        let (w, h) = s.split_once(['x', 'X'])?;
        Some((w.trim().parse().ok()?, h.trim().parse().ok()?))
    };
    match parse() {
        Some((w, h)) if w > 0 && h > 0 => Ok((w, h)),
        _ => bail!("--size {s}: expected WIDTHxHEIGHT, e.g. 400x400"),
    }
}

fn output_format(path: &Path) -> Result<OutputFormat> {
    let ext = crate::output::extension(path);
    match ext.as_str() {
        "png" => Ok(OutputFormat::Png),
        "gif" => Ok(OutputFormat::Gif),
        _ => bail!(
            "{}: unknown output extension (use .png or .gif)",
            path.display()
        ),
    }
}

/// Runs `toonkit render`.
pub(crate) fn run(ctx: &Context, args: RenderArgs) -> Result<()> {
    let start = Instant::now();
    // Check every option before reading or computing anything.
    let format = output_format(&args.output)?;
    let view = parse_view(&args.view)?;
    let (width, height) = parse_size(&args.size)?;
    if args.sheet && format != OutputFormat::Png {
        bail!(
            "{}: a contact sheet is written as .png",
            args.output.display()
        );
    }
    let sampled = input::open(&args.input, &args.input_args)?;
    if sampled.objects.is_empty() {
        bail!("{}: the file has no mesh to render", args.input.display());
    }
    let clip_frames = sampled.frame_count.max(1);
    let format = match (args.sheet, args.every) {
        (false, _) => format,
        (true, Some(0)) => bail!("--every must be ≥ 1"),
        (true, every) => OutputFormat::Sheet {
            every: every.unwrap_or(clip_frames.div_ceil(16)),
            columns: args.columns,
        },
    };
    let field: Option<(Vec<f32>, ColorMap)> = match args.color {
        ColorArg::None => None,
        ColorArg::Offsets => {
            let parts = smear::scene_offsets(&sampled, &smear::OffsetOptions::default())
                .with_context(|| args.input.display().to_string())?;
            let all = smear::MotionOffsets::concat(&parts)?;
            Some((all.into_values(), ColorMap::Diverging))
        }
        ColorArg::Speed => {
            let frames = sampled.frame_count.max(1);
            let per: Vec<Vec<f32>> = sampled
                .objects
                .iter()
                .map(|o| smear::speeds(&smear::vertex_velocities(&o.animation)))
                .collect();
            let mut values = Vec::with_capacity(frames * sampled.vertex_count());
            for f in 0..frames {
                for (o, s) in sampled.objects.iter().zip(&per) {
                    let n = o.animation.vertex_count();
                    values.extend_from_slice(&s[f * n..(f + 1) * n]);
                }
            }
            Some((render::normalize_by_max(&values), ColorMap::Sequential))
        }
    };
    let options = PreviewOptions {
        width,
        height,
        view,
        frame: args.frame.unwrap_or(0),
        onion: args.onion,
        scalar: field.as_ref().map(|(v, m)| (v.as_slice(), *m)),
        format,
        fps: Some(sampled.fps),
        supersample: args.supersample,
    };
    let bytes = render::preview_scene(&sampled, &options)
        .with_context(|| args.input.display().to_string())?;
    tkio::write_atomic(&args.output, &bytes)?;
    let frames = match format {
        OutputFormat::Png => 1,
        OutputFormat::Gif => clip_frames,
        OutputFormat::Sheet { every, .. } => clip_frames.div_ceil(every.max(1)),
    };
    let seconds = start.elapsed().as_secs_f64();
    let summary = json!({
        "output": args.output.display().to_string(),
        "frames": frames,
        "width": width,
        "height": height,
        "bytes": bytes.len(),
        "seconds": seconds,
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({frames} frame{}, {width}x{height}) in {seconds:.2} s",
            args.output.display(),
            if frames == 1 { "" } else { "s" }
        )
    });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_views_and_sizes() {
        assert_eq!(parse_size("320x200").unwrap(), (320, 200));
        assert!(parse_size("0x10").is_err());
        assert!(parse_size("big").is_err());
        assert_eq!(
            parse_view("camera:Cam").unwrap(),
            ViewSpec::Camera("Cam".into())
        );
        assert_eq!(
            parse_view("top").unwrap(),
            ViewSpec::Direction(ViewDirection::Top)
        );
        assert!(parse_view("diagonal").is_err());
        assert_eq!(
            parse_view("follow").unwrap(),
            ViewSpec::Follow(ViewDirection::ThreeQuarter)
        );
        assert_eq!(
            parse_view("follow:side").unwrap(),
            ViewSpec::Follow(ViewDirection::Side)
        );
        assert!(parse_view("follow:up").is_err());
        assert!(parse_view("followme").is_err());
        assert!(output_format(Path::new("a.jpg")).is_err());
        assert_eq!(
            output_format(Path::new("a.GIF")).unwrap(),
            OutputFormat::Gif
        );
    }
}
