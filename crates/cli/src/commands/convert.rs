//! `toonkit convert IN OUT [--clip NAME] [--fps F] [--mesh NAME] [--layout flipbook|morph|sequence]
//! [--frame N]`.

use std::path::PathBuf;
use std::time::Instant;

use anim::Scene;
use anyhow::Result;
use clap::Args;
use serde_json::json;
use tkio::{Format, Loaded};

use super::Context;
use crate::flags::io::{InputArgs, LayoutArgs};
use crate::output;

/// Arguments of `toonkit convert`.
#[derive(Debug, Args)]
pub(crate) struct ConvertArgs {
    /// Input animation (glTF/GLB, OBJ or OBJ sequence, PC2/MDD + rest OBJ, BVH).
    pub(crate) input: PathBuf,
    /// Output file; the extension picks the format (.glb, .usda, .pc2, .mdd, .obj, .stl, .npy).
    pub(crate) output: PathBuf,
    #[command(flatten)]
    pub(crate) input_args: InputArgs,
    #[command(flatten)]
    pub(crate) layout: LayoutArgs,
}

/// Runs `toonkit convert`.
pub(crate) fn run(ctx: &Context, args: ConvertArgs) -> Result<()> {
    let start = Instant::now();
    let loaded = tkio::sampling::load(&args.input, &args.input_args.options())?;
    let spinner = crate::progress::spinner("converting", ctx.json);
    // A skeleton without mesh (BVH) to glTF: keep the joint hierarchy and its clip.
    if let Loaded::Scene(scene) = &loaded {
        if scene.meshes.is_empty() && Format::from_extension(&args.output) == Some(Format::Glb) {
            let mut out = Scene::clone(scene);
            if let Some(name) = &args.input_args.clip {
                let k = scene.find_clip(name)?;
                out.clips = vec![scene.clips[k].clone()];
            }
            let bytes = tkio::gltf::write_glb(&out).map_err(|e| e.at(&args.output))?;
            tkio::write_atomic(&args.output, &bytes)?;
            spinner.finish_and_clear();
            let summary = json!({"input": args.input, "outputs": [args.output], "joints": scene.skeleton().0.len(),
                                 "seconds": start.elapsed().as_secs_f64()});
            ctx.report(&summary, || {
                format!("wrote {} (skeleton)", args.output.display())
            });
            return Ok(());
        }
    }
    let sampled = tkio::sampling::sample(&args.input, &loaded, &args.input_args.options())?;
    let layout = args.layout.layout();
    let one_frame_files = Format::from_extension(&args.output).is_some_and(Format::holds_one_frame);
    if layout == tkio::Layout::Sequence && one_frame_files && sampled.objects.len() > 1 {
        // Several objects (e.g. a flipbook's one node per frame): each file holds what its
        // frame shows, so hidden objects are left out and the vertex count may change.
        return write_frames(ctx, &args, sampled, start, &spinner);
    }
    let merged = tkio::sampling::merged(&args.input, &sampled)?;
    let written = output::write_animation(&args.output, &merged, layout, None, ctx.save)?;
    spinner.finish_and_clear();
    let summary = json!({
        "input": args.input,
        "outputs": written,
        "frames": merged.frame_count(),
        "vertices": merged.vertex_count(),
        "fps": merged.fps,
        "seconds": start.elapsed().as_secs_f64(),
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({} × {} vertices at {} fps)",
            output::files(&written),
            output::frames_written(layout, merged.frame_count()),
            merged.vertex_count(),
            merged.fps
        )
    });
    Ok(())
}

/// Writes every frame's visible objects as its own file of a sequence.
fn write_frames(
    ctx: &Context,
    args: &ConvertArgs,
    sampled: anim::SampledScene,
    start: Instant,
    spinner: &indicatif::ProgressBar,
) -> Result<()> {
    let book = anim::Flipbook {
        fps: sampled.fps,
        frames: sampled.frame_count,
        parts: sampled
            .objects
            .into_iter()
            .map(|o| {
                let mut animation = o.animation;
                animation.mesh.name = o.name;
                anim::FlipbookPart::Animation {
                    animation,
                    colors: None,
                }
            })
            .collect(),
    };
    let written = tkio::save_with(&args.output, &tkio::Output::Flipbook(&book), ctx.save)?;
    spinner.finish_and_clear();
    let summary = json!({
        "input": args.input,
        "outputs": written,
        "frames": book.frames,
        "objects": book.parts.len(),
        "fps": book.fps,
        "seconds": start.elapsed().as_secs_f64(),
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({} frames, each file the objects its frame shows)",
            output::files(&written),
            book.frames
        )
    });
    Ok(())
}
