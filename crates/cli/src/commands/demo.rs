//! `toonkit demo`: every tool on bundled samples, written to one folder with an `index.html`
//! that shows each picture with a caption and the command that reproduces it.
//!
//! Each step is an ordinary `toonkit` command line run in this process, so the page's commands
//! are exactly what ran: copy one into a shell (from the same folder) and get the same file.
//! The inputs are written next to the results (`inputs/`), so the commands need nothing else.
//! The steps and the page are the `batch` crate's ([`batch::demo`](::batch::demo)).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context as _, Result};
use clap::Args;
use serde_json::json;

use ::batch::demo::{
    index_html, steps, DEMO_CLIP, SAMPLE_FACE, SAMPLE_GLB, SAMPLE_KEYS, SAMPLE_STYLE,
};

use super::Context;

/// Arguments of `toonkit demo`.
#[derive(Debug, Args)]
pub(crate) struct DemoArgs {
    /// Folder for the results.
    #[arg(short, long, default_value = "out/demo")]
    pub(crate) out: PathBuf,
    /// Clip of the robot to use (default: Running).
    #[arg(long)]
    pub(crate) clip: Option<String>,
    /// Frames per second (default: 24).
    #[arg(long, value_name = "FPS", allow_negative_numbers = true)]
    pub(crate) fps: Option<f32>,
}

/// Runs `toonkit demo`.
pub(crate) fn run(ctx: &Context, args: DemoArgs) -> Result<()> {
    let start = Instant::now();
    let out = &args.out;
    let inputs = out.join("inputs");
    for (name, bytes) in [
        ("robot.glb", SAMPLE_GLB),
        ("face.glb", SAMPLE_FACE),
        ("fig16_combined.toml", SAMPLE_STYLE.as_bytes()),
        ("jump.json", SAMPLE_KEYS.as_bytes()),
    ] {
        tkio::write_atomic(&inputs.join(name), bytes)?;
    }
    let clip = args.clip.as_deref().unwrap_or(DEMO_CLIP);
    let fps = tkio::sampling::check_fps(args.fps.unwrap_or(anim::DEFAULT_FPS))?;
    let steps = steps(out, clip, fps);
    let mut timings = Vec::with_capacity(steps.len());
    for (i, step) in steps.iter().enumerate() {
        if !ctx.json && !ctx.quiet {
            eprintln!(
                "[{}/{}] toonkit {}",
                i + 1,
                steps.len(),
                step.args.join(" ")
            );
        }
        let t = Instant::now();
        crate::run_args(&step.args)
            .with_context(|| format!("demo step `toonkit {}`", step.args.join(" ")))?;
        timings.push(t.elapsed().as_secs_f64());
    }
    let page = out.join("index.html");
    tkio::save(&page, &tkio::Output::Text(&index_html(&steps, &timings)))?;

    // The summary's counts: the robot's clip as the steps sampled it.
    let scene = tkio::gltf::read_bytes(SAMPLE_GLB)?;
    let sampled = anim::sample(
        &scene,
        &anim::SampleOptions {
            fps,
            clip: Some(scene.find_clip(clip)?),
            meshes: Vec::new(),
        },
    )?;
    let written: Vec<PathBuf> = steps
        .iter()
        .flat_map(|s| s.files.iter().map(|f| out.join(f)))
        .chain([page.clone()])
        .collect();
    let summary = json!({
        "outputs": written,
        "page": page,
        "frames": sampled.frame_count,
        "vertices": sampled.objects.iter().map(|o| o.animation.vertex_count()).sum::<usize>(),
        "steps": steps.iter().zip(&timings).map(|(s, t)| json!({
            "tool": s.tool,
            "command": format!("toonkit {}", s.args.join(" ")),
            "seconds": t,
        })).collect::<Vec<_>>(),
        "seconds": start.elapsed().as_secs_f64(),
    });
    ctx.report(&summary, || {
        format!(
            "demo: {} steps in {:.1} s; open {}",
            steps.len(),
            start.elapsed().as_secs_f64(),
            page.display()
        )
    });
    Ok(())
}
