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

use anim::glam::{DVec3, Mat4, Vec3};
use anim::{Channel, Clip, Interpolation, Property, Scene, SkeletalAnimation, Transform};
use anyhow::{bail, Context as _, Result};
use clap::Args;
use loa::animate::{animate, AnimateOptions, BoneSetKey, Character, ContactKey, Motion, TwistKey};
use rayon::prelude::*;
use render::{Color, Coords, DrawList, MeshItem, Overlay, Renderer, View};
use serde_json::json;

use super::loa::ModeArg;
use super::Context;

/// Name of the clip written into the output glb.
pub const CLIP_NAME: &str = "loa";
/// Size of `--render` previews.
pub const RENDER_SIZE: (u32, u32) = (480, 480);
const LINE_RED: Color = [0.85, 0.1, 0.1, 1.0];
const BONE_BLUE: Color = [0.1, 0.3, 0.85, 1.0];
const BONE_GREY: Color = [0.35, 0.35, 0.35, 0.8];

/// Arguments of `toonkit loa animate`.
#[derive(Debug, Args)]
pub struct AnimateArgs {
    /// The character: a skinned glTF/GLB or a BVH skeleton.
    pub character: PathBuf,
    /// Keystrokes (JSON or SVG, as for `loa line`), drawn in the front view from the bone
    /// set's first bone (feet for leg presets) to its last.
    pub keys: PathBuf,
    /// Output: `.glb` (character + clip `loa`) or `.bvh`.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also write a BVH of the motion.
    #[arg(long)]
    pub bvh: Option<PathBuf>,
    /// Bone set at a keystroke frame: a preset (right-leg-spine-head, left-leg-spine-head,
    /// arm-spine, left-arm-spine, arms, legs, full-body) or comma-separated joint names, then
    /// `@FRAME`. Repeat for changing sets.
    #[arg(long = "bones")]
    pub bones: Vec<String>,
    /// Action-plane normal `x,y,z` (default: the view direction).
    #[arg(long, allow_hyphen_values = true)]
    pub plane_normal: Option<String>,
    /// Contact: `JOINT@FRAME` (hold where it is), `JOINT@FRAME:x,y,z`, or `JOINT@A..B`.
    #[arg(long = "contact")]
    pub contacts: Vec<String>,
    /// Twist: `JOINT@FRAME:DEGREES` about the bone's own axis.
    #[arg(long = "twist", allow_hyphen_values = true)]
    pub twists: Vec<String>,
    /// Initial pose: `rest`, or `CLIP@FRAME` (a frame of one of the file's clips).
    #[arg(long, default_value = "rest")]
    pub pose: String,
    /// Line interpolation mode.
    #[arg(long, value_enum, default_value_t = ModeArg::Physics)]
    pub mode: ModeArg,
    /// Frames per second (default: the keystrokes', else 24).
    #[arg(long)]
    pub fps: Option<f64>,
    /// Cap on solver iterations per stage.
    #[arg(long, default_value_t = loa::animate::DEFAULT_MAX_ITERATIONS)]
    pub iterations: usize,
    /// Preview: `.gif` (every frame) or `.png` (first frame), the character with the line.
    #[arg(long)]
    pub render: Option<PathBuf>,
}

#[derive(Clone, Copy, PartialEq)]
enum Out {
    Glb,
    Bvh,
}

fn out_kind(path: &Path) -> Result<Out> {
    match crate::output::extension(path).as_str() {
        "glb" => Ok(Out::Glb),
        "bvh" => Ok(Out::Bvh),
        _ => bail!(
            "{}: unknown output extension (use .glb or .bvh)",
            path.display()
        ),
    }
}

fn parse_vec3(s: &str) -> Result<DVec3> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--plane-normal {s}: expected x,y,z"))?;
    if v.len() != 3 {
        bail!("--plane-normal {s}: expected three numbers x,y,z");
    }
    Ok(DVec3::new(v[0], v[1], v[2]))
}

/// Runs `toonkit loa animate`.
pub fn run(ctx: &Context, args: AnimateArgs) -> Result<()> {
    let start = Instant::now();
    let kind = out_kind(&args.output)?;
    if let Some(b) = &args.bvh {
        if out_kind(b)? != Out::Bvh {
            bail!("{}: --bvh needs a .bvh path", b.display());
        }
    }
    if let Some(r) = &args.render {
        let e = crate::output::extension(r);
        if e != "gif" && e != "png" {
            bail!(
                "{}: unknown render extension (use .gif or .png)",
                r.display()
            );
        }
    }
    let bone_sets: Vec<BoneSetKey> = args
        .bones
        .iter()
        .map(|b| b.parse().with_context(|| format!("--bones {b}")))
        .collect::<Result<_>>()?;
    let mut contacts = Vec::new();
    for c in &args.contacts {
        contacts.extend(ContactKey::parse_all(c).with_context(|| format!("--contact {c}"))?);
    }
    let twists: Vec<TwistKey> = args
        .twists
        .iter()
        .map(|t| t.parse().with_context(|| format!("--twist {t}")))
        .collect::<Result<_>>()?;
    let plane_normal = args.plane_normal.as_deref().map(parse_vec3).transpose()?;
    let keys = super::loa::read_keystrokes(&args.keys)?;
    let fps = args.fps.or(keys.fps()).unwrap_or(loa::DEFAULT_FPS);

    let spinner = crate::progress::spinner("synthesizing motion", ctx.json);
    let cpath = args.character.display().to_string();
    let loaded = tkio::load(
        &args.character,
        &tkio::LoadOptions {
            fps: fps as f32,
            rest: None,
        },
    )
    .with_context(|| cpath.clone())?;
    let tkio::Loaded::Scene(scene) = loaded else {
        bail!("{cpath}: not a character (use a skinned glTF/GLB or a BVH file)");
    };
    let (skeleton, joint_nodes) = scene.skeleton();
    if skeleton.is_empty() {
        bail!("{cpath}: the file has no skeleton (no skin joints)");
    }
    let character =
        initial_character(&scene, &skeleton, &args.pose, fps).with_context(|| cpath.clone())?;

    let options = loa::LineOptions {
        mode: match args.mode {
            ModeArg::Physics => loa::Mode::Physics,
            ModeArg::Hermite => loa::Mode::Hermite,
        },
        physics: loa::PhysicsOptions {
            fps,
            ..Default::default()
        },
        ..Default::default()
    };
    let line =
        loa::line_of_action(&keys, &options).with_context(|| args.keys.display().to_string())?;
    let solve_start = Instant::now();
    let motion = animate(
        &character,
        &line.animation,
        &bone_sets,
        &contacts,
        &twists,
        &AnimateOptions {
            plane_normal,
            max_iterations: args.iterations,
            ..Default::default()
        },
    )
    .with_context(|| format!("{cpath} with {}", args.keys.display()))?;
    let solve_seconds = solve_start.elapsed().as_secs_f64();

    let world = motion.world_matrices();
    let skeletal = SkeletalAnimation::new(fps as f32, skeleton.len(), world.clone())
        .with_context(|| cpath.clone())?;
    let out_scene = scene_with_clip(&scene, &skeleton, &joint_nodes, &world, fps as f32);
    match kind {
        Out::Glb => {
            let bytes = tkio::gltf::write_glb(&out_scene)
                .with_context(|| args.output.display().to_string())?;
            tkio::write_atomic(&args.output, &bytes)?;
        }
        Out::Bvh => write_bvh(&args.output, &skeleton, &skeletal)?,
    }
    if let Some(b) = &args.bvh {
        write_bvh(b, &skeleton, &skeletal)?;
    }
    if let Some(r) = &args.render {
        let bytes = render_motion(&out_scene, &motion, &skeleton, fps as f32, r)
            .with_context(|| r.display().to_string())?;
        tkio::write_atomic(r, &bytes)?;
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
        "attachments": character.attachments().iter()
            .map(|&(j, p)| format!("{}->{}", names[j], names[p])).collect::<Vec<_>>(),
        "planar": {"unknowns": rep.planar.unknowns, "iterations": rep.planar.iterations,
                   "initial_energy": rep.planar.initial_energy, "final_energy": rep.planar.final_energy},
        "spatial": rep.spatial.map(|s| json!({"unknowns": s.unknowns, "iterations": s.iterations,
                   "initial_energy": s.initial_energy, "final_energy": s.final_energy})),
        "line_distance_mean_percent": 100.0 * rep.line_distance_mean,
        "line_distance_max_percent": 100.0 * rep.line_distance_max,
        "max_rotation_step_degrees": rep.max_rotation_step.to_degrees(),
        "contact_error_max_percent": 100.0 * rep.contact_error_max,
        "solve_seconds": solve_seconds,
        "seconds": seconds,
    });
    ctx.report(&summary, || {
        format!(
            "{}: {} frames, {} joints; line distance {:.2} % (max {:.2} %), max joint step {:.1}°{} \
             in {:.0} ms (solve {:.0} ms)",
            args.output.display(),
            motion.frames(),
            motion.joints,
            100.0 * rep.line_distance_mean,
            100.0 * rep.line_distance_max,
            rep.max_rotation_step.to_degrees(),
            if contacts.is_empty() {
                String::new()
            } else {
                format!(", contact error {:.2} % of height", 100.0 * rep.contact_error_max)
            },
            seconds * 1e3,
            solve_seconds * 1e3
        )
    });
    Ok(())
}

fn write_bvh(path: &Path, skeleton: &anim::Skeleton, motion: &SkeletalAnimation) -> Result<()> {
    let text = tkio::bvh::write(skeleton, motion).with_context(|| path.display().to_string())?;
    tkio::write_atomic(path, text.as_bytes())?;
    Ok(())
}

/// The initial pose: rest, or `CLIP@FRAME`.
fn initial_character(
    scene: &Scene,
    skeleton: &anim::Skeleton,
    pose: &str,
    fps: f64,
) -> Result<Character> {
    if pose == "rest" {
        return Ok(Character::rest(skeleton)?);
    }
    let Some((clip, frame)) = pose.rsplit_once('@') else {
        bail!("--pose {pose}: expected rest or CLIP@FRAME");
    };
    let frame: usize = frame
        .parse()
        .with_context(|| format!("--pose {pose}: FRAME must be a frame number"))?;
    let index = scene.find_clip(clip)?;
    let sampled = anim::sample(
        scene,
        &anim::SampleOptions {
            fps: fps as f32,
            clip: Some(index),
            meshes: Vec::new(),
        },
    )?;
    let Some(skeletal) = sampled.skeletal else {
        bail!("--pose {pose}: the clip moves no joint");
    };
    if frame >= skeletal.frame_count() {
        bail!(
            "--pose {pose}: clip '{clip}' has {} frames",
            skeletal.frame_count()
        );
    }
    Ok(Character::from_world(skeleton, skeletal.frame(frame))?)
}

/// The input scene with its clips replaced by one clip holding the motion (translation,
/// rotation and scale of every joint node, LINEAR, one key per frame).
fn scene_with_clip(
    scene: &Scene,
    skeleton: &anim::Skeleton,
    joint_nodes: &[usize],
    world: &[Mat4],
    fps: f32,
) -> Scene {
    let n = skeleton.len();
    let frames = world.len() / n.max(1);
    // Rest world matrices of every node (for joints whose parent node is not a joint).
    let order = scene.topological_order();
    let (mut locals, mut weights, mut rest_world) = (Vec::new(), Vec::new(), Vec::new());
    scene.pose_at(None, 0.0, &mut locals, &mut weights);
    scene.world_matrices(&order, &locals, &mut rest_world);
    let times: Vec<f32> = (0..frames).map(|f| f as f32 / fps).collect();
    let mut channels = Vec::with_capacity(3 * n);
    for (k, j) in skeleton.joints.iter().enumerate() {
        let node = joint_nodes[k];
        let (mut t, mut r, mut s) = (Vec::new(), Vec::new(), Vec::new());
        for f in 0..frames {
            let parent = match j.parent {
                Some(p) => world[f * n + p],
                None => scene.nodes[node]
                    .parent
                    .map_or(Mat4::IDENTITY, |p| rest_world[p]),
            };
            let local = Transform::from_matrix(parent.inverse() * world[f * n + k]);
            t.extend_from_slice(&local.translation.to_array());
            r.extend_from_slice(&local.rotation.normalize().to_array());
            s.extend_from_slice(&local.scale.to_array());
        }
        for (property, values) in [
            (Property::Translation, t),
            (Property::Rotation, r),
            (Property::Scale, s),
        ] {
            channels.push(Channel {
                node,
                property,
                interpolation: Interpolation::Linear,
                times: times.clone(),
                values,
            });
        }
    }
    let mut out = scene.clone();
    out.clips = vec![Clip {
        name: CLIP_NAME.to_string(),
        channels,
    }];
    out
}

fn v3(p: DVec3) -> Vec3 {
    p.as_vec3()
}

/// Renders the character (or its bones, for a BVH) with the line overlaid, in the action
/// camera's view.
fn render_motion(
    scene: &Scene,
    motion: &Motion,
    skeleton: &anim::Skeleton,
    fps: f32,
    path: &Path,
) -> Result<Vec<u8>> {
    let sampled = anim::sample(
        scene,
        &anim::SampleOptions {
            fps,
            clip: Some(0),
            meshes: Vec::new(),
        },
    )?;
    let renderer = Renderer::new(RENDER_SIZE.0, RENDER_SIZE.1)?;
    let cam = &motion.camera;
    // Fit the whole motion and line.
    let (mut lo, mut hi) = (
        anim::glam::DVec2::splat(f64::INFINITY),
        anim::glam::DVec2::splat(f64::NEG_INFINITY),
    );
    for f in 0..motion.frames() {
        for p in motion.positions_at(f).iter().chain(&motion.line_world(f)) {
            let q = cam.project(*p);
            lo = lo.min(q);
            hi = hi.max(q);
        }
    }
    if !(lo.x <= hi.x && lo.y <= hi.y) {
        (lo, hi) = (anim::glam::DVec2::splat(-1.0), anim::glam::DVec2::ONE);
    }
    let half = ((hi - lo) * 0.5 * 1.1).max_element().max(1e-6);
    let hh = half as f32;
    let eye = cam.unproject((lo + hi) * 0.5) - cam.forward * (4.0 * half + 1.0);
    let cam_world = Mat4::from_cols(
        v3(cam.right).extend(0.0),
        v3(cam.up).extend(0.0),
        (-v3(cam.forward)).extend(0.0),
        v3(eye).extend(1.0),
    );
    let far = 8.0 * hh + 2.0;
    let projection = anim::Projection::Orthographic {
        xmag: hh * renderer.aspect(),
        ymag: hh,
        znear: 0.0,
        zfar: far,
    }
    .matrix(renderer.aspect());
    let view = View::new(cam_world.inverse(), projection);
    let children = skeleton.children();
    let gif = crate::output::extension(path) == "gif";
    let frames: Vec<usize> = if gif {
        (0..motion.frames()).collect()
    } else {
        vec![0]
    };
    let images: Vec<render::Image> = frames
        .par_iter()
        .map(|&f| {
            let mut list = DrawList::new();
            for o in &sampled.objects {
                list = list.mesh(MeshItem::from_animation(&o.animation, f));
            }
            let p = motion.positions_at(f);
            for (k, kids) in children.iter().enumerate() {
                for &c in kids {
                    list = list.overlay(Overlay::polyline(
                        Coords::World(vec![v3(p[k]), v3(p[c])]),
                        BONE_GREY,
                        1.5,
                    ));
                }
            }
            let line: Vec<Vec3> = motion.line_world(f).into_iter().map(v3).collect();
            list = list.overlay(Overlay::polyline(Coords::World(line), LINE_RED, 3.0));
            let constrained: Vec<Vec3> = motion.constrained[f].iter().map(|&j| v3(p[j])).collect();
            list = list.overlay(Overlay::points(Coords::World(constrained), BONE_BLUE, 6.0));
            renderer.render(&list, &view)
        })
        .collect::<Result<_, _>>()?;
    Ok(if gif {
        render::encode_gif(&images, fps)?
    } else {
        render::encode_png(&images[0])?
    })
}
