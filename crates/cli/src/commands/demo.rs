//! `toonkit demo`: every tool on bundled samples, written to one folder with an `index.html`
//! that shows each picture with a caption and the command that reproduces it.
//!
//! Each step is an ordinary `toonkit` command line run in this process, so the page's commands
//! are exactly what ran: copy one into a shell (from the same folder) and get the same file.
//! The inputs are written next to the results (`inputs/`), so the commands need nothing else.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context as _, Result};
use clap::Args;
use serde_json::json;

use super::Context;

/// The bundled 3D sample: RobotExpressive (CC0, see assets/README.md).
pub(crate) const SAMPLE_GLB: &[u8] =
    include_bytes!("../../../../assets/characters/RobotExpressive.glb");
/// The bundled face for stop-motion: ICT-FaceKit face with a speech-like animation (MIT).
pub(crate) const SAMPLE_FACE: &[u8] = include_bytes!("../../../../assets/face/ict-face-talk.glb");
/// The bundled smear style: all three effects (paper Fig. 16).
pub(crate) const SAMPLE_STYLE: &str =
    include_str!("../../../../examples/smear/fig16_combined.toml");
/// The bundled keystrokes: a jump-like arc.
pub(crate) const SAMPLE_KEYS: &str = include_str!("../../../../examples/loa/jump.json");

/// The robot's clip the demo uses unless `--clip` names another.
const DEMO_CLIP: &str = "Running";

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
    #[arg(long, value_name = "FPS")]
    pub(crate) fps: Option<f32>,
}

/// One demo step: a command line, what it shows, and the files it makes.
struct Step {
    /// Which tool: the page's section.
    tool: &'static str,
    /// One line for a newcomer.
    caption: &'static str,
    /// The command line after `toonkit`.
    args: Vec<String>,
    /// Files (relative to the output folder) the page shows or links.
    files: Vec<&'static str>,
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
    let fps = crate::input::check_fps(args.fps.unwrap_or(anim::DEFAULT_FPS))?;
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

/// The demo's command lines: smear, stopmo and loa on the bundled inputs.
fn steps(out: &Path, clip: &str, fps: f32) -> Vec<Step> {
    let p = |rel: &str| out.join(rel).display().to_string();
    let fps = fps.to_string();
    let step = |tool, caption, args: &[&str], files: Vec<&'static str>| Step {
        tool,
        caption,
        args: args.iter().map(|s| s.to_string()).collect(),
        files,
    };
    let robot = p("inputs/robot.glb");
    let face = p("inputs/face.glb");
    let keys = p("inputs/jump.json");
    vec![
        step(
            "smear",
            "The robot's clip as a glTF flipbook and a point cache for Blender's Mesh Cache modifier.",
            &["convert", &robot, &p("robot.glb"), "--clip", clip, "--fps", &fps],
            vec!["robot.glb"],
        ),
        step(
            "smear",
            "Motion offsets (SMEAR §3): red parts lead the motion, blue parts trail.",
            &["render", &robot, "-o", &p("robot_offsets.gif"), "--clip", clip, "--fps", &fps,
              "--color", "offsets", "--size", "320x320"],
            vec!["robot_offsets.gif"],
        ),
        step(
            "smear",
            "A whole stylization (SMEAR Fig. 16): elongated in-betweens, multiple in-betweens and motion lines.",
            &["smear", &robot, "--clip", clip, "--fps", &fps, "--style", &p("inputs/fig16_combined.toml"),
              "-o", &p("robot_smear.glb"), "--gif", &p("robot_smear.gif")],
            vec!["robot_smear.gif", "robot_smear.glb", "inputs/fig16_combined.toml"],
        ),
        step(
            "smear",
            "The same smear as a numbered contact sheet: every third frame.",
            &["render", &p("robot_smear.glb"), "-o", &p("robot_smear_sheet.png"), "--sheet",
              "--every", "3", "--size", "200x200"],
            vec!["robot_smear_sheet.png"],
        ),
        step(
            "stopmo",
            "StopShop on the talking face at 4 fps: cut into upper and lower parts along a low-motion seam, \
             a 12-piece replacement library searched on the size-vs-error curve, printable pieces, \
             assembly sheet and shooting order.",
            &["stopmo", "run", &face, "-o", &p("stopmo"), "--fps", "4",
              "--part", "upper=point:0,10,13", "--part", "lower=point:0,-14,10",
              "--budget", "12", "--restarts", "2", "--render"],
            vec!["stopmo/segmentation.png", "stopmo/error_curve.png", "stopmo/assembly.csv",
                 "stopmo/shooting_order.csv", "stopmo/report.json"],
        ),
        step(
            "stopmo",
            "The replacement animation every 5 s (numbered frames): each face assembled from library pieces.",
            &["render", &p("stopmo/reconstruction.glb"), "-o", &p("stopmo/reconstruction_sheet.png"),
              "--sheet", "--every", "20", "--view", "front", "--size", "160x160"],
            vec!["stopmo/reconstruction_sheet.png", "stopmo/reconstruction.glb"],
        ),
        step(
            "stopmo",
            "One printable piece of the lower face (closed STL solid, ready for a slicer).",
            &["render", &p("stopmo/pieces/lower_00.stl"), "-o", &p("stopmo/lower_00.png"),
              "--view", "front", "--size", "300x300"],
            vec!["stopmo/lower_00.png", "stopmo/pieces/lower_00.stl"],
        ),
        step(
            "loa",
            "Sketched keystrokes become a dynamic line of action with anticipation and follow-through (LoA §3).",
            &["loa", "line", &keys, "-o", &p("jump_line.gif")],
            vec!["jump_line.gif", "inputs/jump.json"],
        ),
        step(
            "loa",
            "The robot follows the moving line (space-time optimization with changing bone sets).",
            &["loa", "animate", &robot, &keys, "-o", &p("jump.glb"), "--render", &p("jump.gif")],
            vec!["jump.gif", "jump.glb"],
        ),
    ]
}

/// The demo page: one figure per picture, links to the other files, the command under each.
fn index_html(steps: &[Step], seconds: &[f64]) -> String {
    let mut html = String::from(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>toonkit demo</title><style>\
         body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;color:#222}\
         figure{display:inline-block;vertical-align:top;margin:0 1em 1.5em 0;max-width:520px}\
         img{max-width:100%;border:1px solid #ddd}code{display:block;font-size:12px;background:#f4f4f4;\
         padding:.4em;white-space:pre-wrap;word-break:break-all}</style></head><body>\n\
         <h1>toonkit demo</h1>\n<p>Every result below was made by the command under it \
         (run from the folder you ran <code style=\"display:inline\">toonkit demo</code> in).</p>\n",
    );
    let mut section = "";
    for (step, t) in steps.iter().zip(seconds) {
        if step.tool != section {
            section = step.tool;
            html += &format!("<h2>{section}</h2>\n");
        }
        html += "<figure>";
        let (pictures, others): (Vec<&str>, Vec<&str>) = step
            .files
            .iter()
            .partition(|f| f.ends_with(".png") || f.ends_with(".gif"));
        for f in &pictures {
            html += &format!("<img src=\"{f}\" alt=\"{f}\">");
        }
        html += &format!("<figcaption>{}", escape(step.caption));
        for f in &others {
            html += &format!(" <a href=\"{f}\">{f}</a>");
        }
        html += &format!(
            "<code>toonkit {}</code><small>{t:.1} s</small></figcaption></figure>\n",
            escape(&step.args.join(" "))
        );
    }
    html + "</body></html>\n"
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
