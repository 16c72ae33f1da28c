//! The `toonkit demo` run as data: every tool on the bundled samples ([`SAMPLE_GLB`],
//! [`SAMPLE_FACE`], [`SAMPLE_STYLE`], [`SAMPLE_KEYS`]), as the [`Step`]s a user would type
//! ([`steps`]), and the page that shows each result with its command ([`index_html`]).

use std::path::Path;

/// The bundled 3D sample: RobotExpressive (CC0, see assets/README.md).
pub const SAMPLE_GLB: &[u8] = include_bytes!("../../../assets/characters/RobotExpressive.glb");
/// The bundled face for stop-motion: ICT-FaceKit face with a speech-like animation (MIT).
pub const SAMPLE_FACE: &[u8] = include_bytes!("../../../assets/face/ict-face-talk.glb");
/// The bundled smear style: all three effects (paper Fig. 16).
pub const SAMPLE_STYLE: &str = include_str!("../../../examples/smear/fig16_combined.toml");
/// The bundled keystrokes: a jump-like arc.
pub const SAMPLE_KEYS: &str = include_str!("../../../examples/loa/jump.json");

/// The robot's clip the demo uses unless `--clip` names another.
pub const DEMO_CLIP: &str = "Running";

/// One demo step: a command line, what it shows, and the files it makes.
#[derive(Debug, Clone)]
pub struct Step {
    /// Which tool: the page's section.
    pub tool: &'static str,
    /// One line for a newcomer.
    pub caption: &'static str,
    /// The command line after `toonkit`.
    pub args: Vec<String>,
    /// Files (relative to the output folder) the page shows or links.
    pub files: Vec<&'static str>,
}

/// The demo's command lines (after `toonkit`): smear, stopmo and loa on the bundled inputs
/// written to `out/inputs`, results in `out`.
pub fn steps(out: &Path, clip: &str, fps: f32) -> Vec<Step> {
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

/// The demo page: one figure per picture, links to the other files, the command under each
/// with the `seconds` it took.
pub fn index_html(steps: &[Step], seconds: &[f64]) -> String {
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
