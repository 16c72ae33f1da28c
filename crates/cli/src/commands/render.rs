//! `toonkit render IN -o OUT.png|OUT.gif [--frame F] [--onion K] [--color none|offsets|speed]
//! [--view front|back|side|top|three-quarter|camera:NAME] [--size WxH] [--supersample S]
//! [--clip NAME] [--fps F] [--sheet [--every N] [--columns C]]`.

use std::time::Instant;

use crate::flags::render::{ColorArg, PreviewFlags};
use anyhow::{anyhow, bail, Context as _, Result};
use clap::Args;
use render::ColorMap;
use serde_json::json;

use super::Context;
use crate::flags::io::InputArgs;

/// Arguments of `toonkit render`.
#[derive(Debug, Args)]
pub(crate) struct RenderArgs {
    /// The animation or mesh to preview (glTF, GLB, OBJ, PC2, MDD, STL).
    pub(crate) input: std::path::PathBuf,
    /// Output image: `.png` (one frame) or `.gif` (every frame, looping).
    #[arg(short, long)]
    pub(crate) output: std::path::PathBuf,
    #[command(flatten)]
    pub(crate) preview: PreviewFlags,
    #[command(flatten)]
    pub(crate) input_args: InputArgs,
}

/// Runs `toonkit render`.
pub(crate) fn run(ctx: &Context, args: RenderArgs) -> Result<()> {
    let start = Instant::now();
    // Check every option before reading or computing anything.
    let checked = args.preview.check(&args.output).map_err(|e| anyhow!(e))?;
    let (width, height) = checked.size;
    let sampled = tkio::open(&args.input, &args.input_args.options())?;
    if sampled.objects.is_empty() {
        bail!("{}: the file has no mesh to render", args.input.display());
    }
    let clip_frames = sampled.frame_count.max(1);
    let mut options = (args.preview)
        .options(checked, clip_frames, sampled.fps, None)
        .map_err(|e| anyhow!(e))?;
    let field: Option<(Vec<f32>, ColorMap)> = match args.preview.color {
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
    options.scalar = field.as_ref().map(|(v, m)| (v.as_slice(), *m));
    let bytes = render::preview_scene(&sampled, &options)
        .with_context(|| args.input.display().to_string())?;
    tkio::write_atomic(&args.output, &bytes)?;
    let frames = options.format.frames(clip_frames);
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
