//! `toonkit demo`: every tool on bundled samples — RobotExpressive (CC0) for the 3D tools,
//! the jump keystrokes of `examples/loa/` for the line of action.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anim::SampleOptions;
use anyhow::{Context as _, Result};
use clap::Args;
use serde_json::json;

use super::Context;
use crate::output::{self, Layout};

/// The bundled 3D sample: RobotExpressive (CC0, see assets/README.md).
pub const SAMPLE_GLB: &[u8] = include_bytes!("../../../../assets/characters/RobotExpressive.glb");
/// The bundled smear style: all three effects (paper Fig. 16).
pub const SAMPLE_STYLE: &str = include_str!("../../../../examples/smear/fig16_combined.toml");
/// The bundled keystrokes: a jump-like arc.
pub const SAMPLE_KEYS: &str = include_str!("../../../../examples/loa/jump.json");

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
    let spinner = crate::progress::spinner("demo", ctx.json);
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
    let out = |name: &str| args.out.join(name);

    // Foundation: the clip as a glTF flipbook and a Blender point cache.
    written.extend(output::write_animation(
        &out("robot.glb"),
        &robot,
        Layout::Flipbook,
        None,
    )?);
    written.extend(output::write_animation(
        &out("robot.pc2"),
        &robot,
        Layout::Flipbook,
        None,
    )?);

    // smear: motion offsets as colours (red leading, blue trailing) and a preview.
    let parts = smear::scene_offsets(&sampled, &smear::OffsetOptions::default())?;
    let offsets = smear::MotionOffsets::concat(&parts)?;
    let colors = render::offset_colors(offsets.values());
    written.extend(output::write_animation(
        &out("robot_offsets.glb"),
        &robot,
        Layout::Flipbook,
        Some(&colors),
    )?);
    let preview = |format, frame, onion| {
        render::preview_scene(
            &sampled,
            &render::PreviewOptions {
                frame,
                onion,
                format,
                scalar: Some((offsets.values(), render::ColorMap::Diverging)),
                ..render::PreviewOptions::default()
            },
        )
    };
    let mid = sampled.frame_count / 2;
    put(
        &out("robot_offsets.png"),
        &preview(render::OutputFormat::Png, mid, 2)?,
        &mut written,
    )?;
    put(
        &out("robot_offsets.gif"),
        &preview(render::OutputFormat::Gif, 0, 0)?,
        &mut written,
    )?;

    // smear: the bundled style (elongation, multiples, motion lines) as a GIF.
    let style = smear::Style::from_toml_str(SAMPLE_STYLE).context("bundled smear style")?;
    let prepared = smear::prepare(
        sampled.clone(),
        &smear::PrepareOptions {
            offsets: style.offsets.clone(),
            ..smear::PrepareOptions::default()
        },
    )?;
    let styled = smear::stylize(&prepared, &style)?;
    put(
        &out("robot_smear.gif"),
        &render::flipbook_gif(&styled.flipbook, 320, 320)?,
        &mut written,
    )?;

    // loa: the jump keystrokes as a dynamic line of action.
    let keys = loa::Keystrokes::from_json_str(SAMPLE_KEYS).context("bundled keystrokes")?;
    let line = loa::line(&keys, &loa::LineOptions::default())?;
    put(
        &out("jump_line.json"),
        line.animation.to_json_string().as_bytes(),
        &mut written,
    )?;
    put(
        &out("jump_line.svg"),
        loa::to_svg_string(&line.animation, Some(&keys)).as_bytes(),
        &mut written,
    )?;
    put(
        &out("jump_line.gif"),
        &super::loa::render_line(&line.animation, &keys, true)?,
        &mut written,
    )?;
    spinner.finish_and_clear();

    let summary = json!({
        "outputs": written,
        "frames": robot.frame_count(),
        "vertices": robot.vertex_count(),
        "line_frames": line.animation.frames.len(),
        "seconds": start.elapsed().as_secs_f64(),
    });
    ctx.report(&summary, || {
        let mut s = format!(
            "RobotExpressive '{}': {} frames × {} vertices; jump line: {} frames\n",
            args.clip,
            robot.frame_count(),
            robot.vertex_count(),
            line.animation.frames.len()
        );
        for w in &written {
            s += &format!("  wrote {}\n", w.display());
        }
        s.trim_end().to_string()
    });
    Ok(())
}

fn put(path: &Path, bytes: &[u8], written: &mut Vec<PathBuf>) -> Result<()> {
    tkio::write_atomic(path, bytes)?;
    written.push(path.to_path_buf());
    Ok(())
}
