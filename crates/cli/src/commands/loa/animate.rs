//! `toonkit loa animate CHARACTER KEYS.json -o OUT.glb|OUT.bvh [--bones SET@FRAME]...
//! [--plane-normal x,y,z] [--contact JOINT@FRAME[:x,y,z]|JOINT@A..B]...
//! [--twist JOINT@FRAME:DEGREES]... [--pose rest|CLIP@FRAME] [--bvh OUT.bvh]
//! [--render OUT.gif|OUT.png]`.
//!
//! The output format follows `-o`'s extension: `.glb` writes the character (skinned meshes,
//! skeleton) with the synthesized clip `loa` as its only animation; `.bvh` writes the
//! skeleton and motion as BVH. `--bvh` writes a BVH in addition to a `.glb`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::flags::loa::MotionFlags;
use anyhow::{bail, Context as _, Result};
use clap::Args;
use loa::animate::{ActionCamera, Character};
use serde_json::json;

use super::{read_keystrokes, warn, Context, LineFlags};
use crate::output::extension;

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
    let known = |p: &Path, exts: &[&str], what: &str| -> Result<()> {
        if exts.contains(&extension(p).as_str()) {
            return Ok(());
        }
        bail!(
            "{}: unknown {what} extension (use {})",
            p.display(),
            exts.join(" or ")
        )
    };
    known(&args.output, &["glb", "bvh"], "output")?;
    if let Some(b) = &args.bvh {
        known(b, &["bvh"], "--bvh")?;
    }
    if let Some(r) = &args.render {
        known(r, &["gif", "png"], "render")?;
    }
    Ok(())
}

/// Runs `toonkit loa animate`.
pub(crate) fn run(ctx: &Context, args: AnimateArgs) -> Result<()> {
    let start = Instant::now();
    check_outputs(&args)?;
    let mut options = args.motion.options()?;
    let pose = args.motion.pose()?;
    let keys = read_keystrokes(&args.keys)?;
    let line_options = args.line.options(&keys)?;
    let fps = line_options.physics.fps;

    let spinner = crate::progress::spinner("synthesizing motion", ctx.json);
    let cpath = args.character.display().to_string();
    let load = tkio::LoadOptions {
        fps: fps as f32,
        ..Default::default()
    };
    let tkio::Loaded::Scene(scene) =
        tkio::load(&args.character, &load).with_context(|| cpath.clone())?
    else {
        bail!("{cpath}: not a character (use a skinned glTF/GLB or a BVH file)");
    };
    let character = Character::from_scene(&scene, &pose, fps).with_context(|| cpath.clone())?;
    let scene_camera = match &args.camera {
        Some(name) => {
            let (action, camera) = ActionCamera::from_scene(&scene, name, &character, fps)
                .with_context(|| format!("{cpath}: --camera {name}"))?;
            options.camera = Some(action);
            Some(camera)
        }
        None => None,
    };
    let line = loa::line(&keys, &line_options).with_context(|| args.keys.display().to_string())?;
    warn(&line, &args.keys);
    let solve_start = Instant::now();
    let motion = loa::animate(&character, &line, &options)
        .with_context(|| format!("{cpath} with {}", args.keys.display()))?;
    let solve_seconds = solve_start.elapsed().as_secs_f64();

    let out_scene = motion.to_scene(&scene);
    let (skeleton, _) = scene.skeleton();
    let bvh = || -> Result<String> {
        let skeletal = motion
            .skeletal_animation(&skeleton)
            .with_context(|| cpath.clone())?;
        Ok(tkio::bvh::write(&skeleton, &skeletal)?)
    };
    if extension(&args.output) == "bvh" {
        tkio::save(&args.output, &tkio::Output::Text(&bvh()?))?;
    } else {
        let bytes =
            tkio::gltf::write_glb(&out_scene).with_context(|| args.output.display().to_string())?;
        tkio::save(&args.output, &tkio::Output::Bytes(&bytes))?;
    }
    if let Some(b) = &args.bvh {
        tkio::save(b, &tkio::Output::Text(&bvh()?))?;
    }
    if let Some(r) = &args.render {
        let gif = extension(r) == "gif";
        let bytes = loa::preview::motion_preview(
            &out_scene,
            &motion,
            &skeleton,
            scene_camera.as_ref(),
            gif,
        )
        .with_context(|| r.display().to_string())?;
        tkio::save(r, &tkio::Output::Bytes(&bytes))?;
    }
    spinner.finish_and_clear();

    let rep = &motion.report;
    let seconds = start.elapsed().as_secs_f64();
    let names = character.joint_names();
    let summary = json!({
        "output": args.output.display().to_string(),
        "frames": motion.frames(),
        "fps": fps,
        "joints": motion.joints,
        "keystroke_frames": line.animation.keystroke_frames,
        "warnings": line.warnings,
        "attachments": character.attachments().iter()
            .map(|&(j, p)| format!("{}->{}", names[j], names[p])).collect::<Vec<_>>(),
        "planar": rep.planar,
        "spatial": rep.spatial,
        // Over every constrained point of every frame with a bone set (see AnimateReport).
        "line_distance_mean_percent": 100.0 * rep.line_distance_mean,
        "line_distance_p95_percent": 100.0 * rep.line_distance_p95,
        "line_distance_worst": {
            "percent": 100.0 * rep.line_distance_worst.distance,
            "joint": rep.line_distance_worst.joint,
            "frame": rep.line_distance_worst.frame,
        },
        "line_distance_joints": rep.measured_joints,
        "line_distance_unmeasured_frames": rep.unmeasured_frames,
        "max_rotation_step_degrees": rep.max_rotation_step.to_degrees(),
        "contact_error_max_percent": 100.0 * rep.contact_error_max,
        "solve_seconds": solve_seconds,
        "seconds": seconds,
    });
    ctx.report(&summary, || {
        format!(
            "{}: {} frames, {} joints; line distance mean {:.2} %, p95 {:.2} %, worst {:.2} % \
             ({} at frame {}){}, max joint step {:.1}°{} in {:.0} ms (solve {:.0} ms)",
            args.output.display(),
            motion.frames(),
            motion.joints,
            100.0 * rep.line_distance_mean,
            100.0 * rep.line_distance_p95,
            100.0 * rep.line_distance_worst.distance,
            rep.line_distance_worst.joint,
            rep.line_distance_worst.frame,
            if rep.unmeasured_frames.is_empty() {
                String::new()
            } else {
                format!(
                    " ({} frames without a bone set not measured)",
                    rep.unmeasured_frames.len()
                )
            },
            rep.max_rotation_step.to_degrees(),
            if options.contacts.is_empty() {
                String::new()
            } else {
                format!(
                    ", contact error {:.2} % of height",
                    100.0 * rep.contact_error_max
                )
            },
            seconds * 1e3,
            solve_seconds * 1e3
        )
    });
    Ok(())
}
