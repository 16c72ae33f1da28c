//! `toonkit demo`: every tool on the bundled sample (RobotExpressive, CC0).

use std::path::PathBuf;
use std::time::Instant;

use anim::SampleOptions;
use anyhow::Result;
use clap::Args;
use serde_json::json;

use super::Context;
use crate::output::{self, Layout};

/// The bundled sample: RobotExpressive (CC0, see assets/LICENSES.md).
pub const SAMPLE_GLB: &[u8] = include_bytes!("../../../../assets/RobotExpressive.glb");

/// Arguments of `toonkit demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Folder for the results.
    #[arg(short, long, default_value = "out/demo")]
    pub out: PathBuf,
    /// Clip of the sample to use.
    #[arg(long, default_value = "Running")]
    pub clip: String,
    /// Frames per second.
    #[arg(long, default_value_t = anim::DEFAULT_FPS)]
    pub fps: f32,
}

/// Runs `toonkit demo`.
pub fn run(ctx: &Context, args: DemoArgs) -> Result<()> {
    let start = Instant::now();
    let scene = tkio::gltf::read_bytes(SAMPLE_GLB)?;
    let clip = scene.find_clip(&args.clip)?;
    let sampled = anim::sample(
        &scene,
        &SampleOptions {
            fps: args.fps,
            clip: Some(clip),
            meshes: Vec::new(),
        },
    )?;
    let robot = sampled.merged("robot")?;
    let mut written = Vec::new();
    written.extend(output::write_animation(
        &args.out.join("robot.glb"),
        &robot,
        Layout::Flipbook,
        None,
    )?);
    written.extend(output::write_animation(
        &args.out.join("robot.pc2"),
        &robot,
        Layout::Flipbook,
        None,
    )?);
    let summary = json!({
        "outputs": written,
        "frames": robot.frame_count(),
        "vertices": robot.vertex_count(),
        "seconds": start.elapsed().as_secs_f64(),
    });
    ctx.report(&summary, || {
        let mut s = format!(
            "RobotExpressive '{}': {} frames × {} vertices\n",
            args.clip,
            robot.frame_count(),
            robot.vertex_count()
        );
        for w in &written {
            s += &format!("  wrote {}\n", w.display());
        }
        s.trim_end().to_string()
    });
    Ok(())
}
