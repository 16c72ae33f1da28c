//! `toonkit loa animate CHARACTER KEYS.json -o OUT.glb|OUT.bvh [--bones SET@FRAME]...
//! [--plane-normal x,y,z] [--contact JOINT@FRAME[:x,y,z]|JOINT@A..B]...
//! [--twist JOINT@FRAME:DEGREES]... [--pose rest|CLIP@FRAME] [--bvh OUT.bvh]
//! [--render OUT.gif|OUT.png]`.
//!
//! The output format follows `-o`'s extension: `.glb` writes the character (skinned meshes,
//! skeleton) with the synthesized clip `loa` as its only animation; `.bvh` writes the
//! skeleton and motion as BVH. `--bvh` writes a BVH in addition to a `.glb`.

use std::path::PathBuf;
use std::time::Instant;

use crate::flags::loa::MotionFlags;
use anyhow::{Context as _, Result};
use clap::Args;
use loa::job;
use serde_json::json;

use super::{read_keystrokes, warn, Context, LineFlags};

/// Arguments of `toonkit loa animate`.
#[derive(Debug, Args)]
pub(crate) struct AnimateArgs {
    /// The character: a skinned glTF/GLB or a BVH skeleton.
    pub(crate) character: PathBuf,
    /// Keystrokes (JSON or SVG, as for `loa line`), drawn in the front view from the bone
    /// set's first bone (feet for leg presets) to its last.
    pub(crate) keys: PathBuf,
    /// Output: `.glb` (character + clip `loa`) or `.bvh`.
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    /// Also write a BVH of the motion.
    #[arg(long)]
    pub(crate) bvh: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) motion: MotionFlags,
    /// The camera the keystrokes are drawn through: a camera node of the character's file
    /// (perspective allowed; default an orthographic front view fitted to the character).
    #[arg(long)]
    pub(crate) camera: Option<String>,
    /// Preview: `.gif` (every frame) or `.png` (first frame), the character with the line, in
    /// a view that follows the character (or through `--camera`).
    #[arg(long)]
    pub(crate) render: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) line: LineFlags,
}

/// Checks the output paths' extensions before any work.
fn check_outputs(args: &AnimateArgs) -> Result<()> {
    job::check_motion_path(&args.output, "output", &job::MOTION_FORMATS)?;
    if let Some(b) = &args.bvh {
        job::check_motion_path(b, "--bvh", &[tkio::Format::Bvh])?;
    }
    if let Some(r) = &args.render {
        job::check_preview_path(r)?;
    }
    Ok(())
}

/// Runs `toonkit loa animate`.
pub(crate) fn run(ctx: &Context, args: AnimateArgs) -> Result<()> {
    let start = Instant::now();
    check_outputs(&args)?;
    let keys = read_keystrokes(&args.keys)?;
    let options = job::SceneOptions {
        line: args.line.options(&keys)?,
        motion: args.motion.options()?,
        pose: args.motion.pose()?,
        camera: args.camera.clone(),
        canvas: None,
    };

    let spinner = crate::progress::spinner("synthesizing motion", ctx.json);
    let cpath = args.character.display().to_string();
    let kpath = args.keys.display();
    let scene = job::open_character(&args.character, options.line.physics.fps)
        .with_context(|| cpath.clone())?;
    let done = job::animate_scene(&scene, &keys, &options).map_err(|e| match e {
        job::SceneJobError::Line(_) => anyhow::Error::new(e).context(kpath.to_string()),
        job::SceneJobError::Animate(_) => {
            anyhow::Error::new(e).context(format!("{cpath} with {kpath}"))
        }
        _ => anyhow::Error::new(e).context(cpath.clone()),
    })?;
    warn(&done.line, &args.keys);
    done.save(&args.output)?;
    if let Some(b) = &args.bvh {
        done.save(b)?;
    }
    if let Some(r) = &args.render {
        done.save_preview(r)?;
    }
    spinner.finish_and_clear();

    let rep = &done.report;
    let seconds = start.elapsed().as_secs_f64();
    let mut summary = serde_json::to_value(rep)?;
    summary["output"] = json!(args.output.display().to_string());
    summary["seconds"] = json!(seconds);
    ctx.report(&summary, || {
        format!(
            "{}: {} frames, {} joints; line distance mean {:.2} %, p95 {:.2} %, worst {:.2} % \
             ({} at frame {}){}, max joint step {:.1}°{} in {:.0} ms (solve {:.0} ms)",
            args.output.display(),
            rep.frames,
            rep.joints,
            rep.line_distance_mean_percent,
            rep.line_distance_p95_percent,
            rep.line_distance_worst.percent,
            rep.line_distance_worst.joint,
            rep.line_distance_worst.frame,
            if rep.line_distance_unmeasured_frames.is_empty() {
                String::new()
            } else {
                format!(
                    " ({} frames without a bone set not measured)",
                    rep.line_distance_unmeasured_frames.len()
                )
            },
            rep.max_rotation_step_degrees,
            if options.motion.contacts.is_empty() {
                String::new()
            } else {
                format!(
                    ", contact error {:.2} % of height",
                    rep.contact_error_max_percent
                )
            },
            seconds * 1e3,
            rep.solve_seconds * 1e3
        )
    });
    Ok(())
}
