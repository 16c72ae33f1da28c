//! `toonkit smear IN --style STYLE.toml -o OUT.glb|OUT.usda [--gif PREVIEW.gif] [--clip NAME]
//! [--fps F]`.
//!
//! Applies a whole style (Basset et al. 2024, Section 4 effects with the Section 5
//! stylization functions; format in `examples/smear/`): per object, the elongated
//! in-betweens (or the input when the style has none), the multiple in-betweens as
//! alpha-coloured copies and the motion lines as tubes, all as flipbooks in one `.glb`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anim::glam::Vec3;
use anim::{Channel, Clip, Mesh, MeshAnimation, SampledScene};
use anyhow::{anyhow, bail, Context as _, Result};
use clap::Args;
use serde_json::json;
use smear::{CompiledEffects, EffectInputs, LineFrame, LineStyle, OffsetSolver, Style};

use super::Context;
use crate::input::{self, InputArgs};

/// Colour of the multiple in-betweens (linear RGB; alpha is S_M).
const MULTIPLE_RGB: [f32; 3] = [0.8, 0.8, 0.8];

/// The top-level form of `toonkit smear` (no subcommand).
#[derive(Debug, Args)]
pub struct StyleArgs {
    /// Input animation (glTF/GLB with skins, OBJ sequence, PC2/MDD + rest OBJ).
    pub input: Option<PathBuf>,
    /// Style file (TOML, see examples/smear/).
    #[arg(long)]
    pub style: Option<PathBuf>,
    /// Output `.glb` (every effect of the style as flipbooks) or `.usda` (one Mesh per part).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Also render a GIF preview of the result.
    #[arg(long)]
    pub gif: Option<PathBuf>,
    #[command(flatten)]
    pub input_args: InputArgs,
}

/// One flipbook of the output.
#[derive(Debug, Clone)]
pub enum Part {
    /// A fixed-topology animation with optional per-frame RGBA vertex colours.
    Animation(MeshAnimation, Option<Vec<[f32; 4]>>),
    /// One (possibly empty) mesh per frame: motion lines.
    Frames(String, Vec<Mesh>),
}

/// The result of a style on a scene.
#[derive(Debug, Clone)]
pub struct Styled {
    /// Frames per second.
    pub fps: f32,
    /// Number of frames.
    pub frames: usize,
    /// Flipbooks, object by object.
    pub parts: Vec<Part>,
    /// Per-object statistics (JSON).
    pub objects: Vec<serde_json::Value>,
    /// Seconds per phase: offsets, elongate, multiples, lines.
    pub timings: [f64; 4],
}

/// Applies `style` to every object of `scene`.
///
/// # Errors
/// Offsets or effect errors (unknown bone to prune, bad parameters).
pub fn apply(scene: &SampledScene, style: &Style) -> Result<Styled> {
    let mut timings = [0.0f64; 4];
    let t = Instant::now();
    let solver = OffsetSolver::new(scene, &style.offsets)?;
    let offsets = solver.all();
    let camera = style.offsets.selected_camera(&scene.cameras)?;
    timings[0] = t.elapsed().as_secs_f64();
    let mut parts = Vec::new();
    let mut objects = Vec::new();
    for (i, obj) in scene.objects.iter().enumerate() {
        let anim = &obj.animation;
        let diagonal = anim::Aabb::from_points(anim.frame(0)).diagonal();
        let fx: CompiledEffects = style.for_object(&obj.name).compile(diagonal)?;
        let weights = match &fx.weights {
            Some(w) => Some(w.vertex_weights(scene, i)?),
            None => None,
        };
        let mut inputs = EffectInputs::new(anim, &offsets[i])?.relative_to_camera(camera);
        if let Some(w) = &weights {
            inputs = inputs.with_weights(w.clone())?;
        }
        let mut stats = json!({"name": obj.name, "vertices": anim.vertex_count()});
        let t = Instant::now();
        let base = match &fx.elongate {
            Some((f, options)) => {
                let e = smear::elongate(anim, &inputs, f, options)?;
                stats["elongation_max"] = json!(max_distance(anim, &e));
                e
            }
            None => anim.clone(),
        };
        timings[1] += t.elapsed().as_secs_f64();
        parts.push(Part::Animation(base, None));
        let t = Instant::now();
        if let Some((f, options)) = &fx.multiples {
            let copies = smear::multiples(anim, &inputs, f, options)?;
            let mut visible = 0usize;
            for c in copies {
                visible += c.alpha.iter().filter(|a| **a > 0.0).count();
                let [r, g, b] = MULTIPLE_RGB;
                let colors = c.alpha.iter().map(|&a| [r, g, b, a]).collect();
                parts.push(Part::Animation(c.animation, Some(colors)));
            }
            stats["multiples"] = json!(options.indices().len());
            stats["multiples_spacing"] = json!(options.spacing_at(0.0)?);
            stats["multiples_visible_vertices"] = json!(visible);
        }
        timings[2] += t.elapsed().as_secs_f64();
        let t = Instant::now();
        if let Some(l) = &fx.lines {
            let points =
                smear::sample_surface(anim.frame(0), &anim.mesh.triangles, l.count, l.seed);
            let seed_offsets = solver.surface_offsets(i, &points)?;
            let seeds = EffectInputs::at_surface_points(anim, &points, seed_offsets)?
                .relative_to_camera(camera);
            let seeds = match &weights {
                Some(w) => seeds.with_weights(smear::surface_point_weights(
                    w,
                    &anim.mesh.triangles,
                    &points,
                )?)?,
                None => seeds,
            };
            let line_style = LineStyle {
                length: &l.length,
                thickness: &l.thickness,
                opacity: &l.opacity,
            };
            let frames: Vec<LineFrame> = smear::motion_lines(&seeds, &line_style, &l.options)?;
            let drawn: Vec<usize> = frames.iter().map(|f| f.lines).collect();
            stats["lines_per_frame"] = json!(drawn);
            stats["lines_max"] = json!(drawn.iter().copied().max().unwrap_or(0));
            let name = format!("{}_lines", obj.name);
            parts.push(Part::Frames(
                name,
                frames.into_iter().map(|f| f.mesh).collect(),
            ));
        }
        timings[3] += t.elapsed().as_secs_f64();
        objects.push(stats);
    }
    Ok(Styled {
        fps: scene.fps,
        frames: scene.frame_count,
        parts,
        objects,
        timings,
    })
}

/// Largest vertex displacement between two animations of the same mesh.
fn max_distance(a: &MeshAnimation, b: &MeshAnimation) -> f32 {
    a.positions()
        .iter()
        .zip(b.positions())
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f32::max)
}

impl Styled {
    /// All parts as one glTF scene: one root node per part with one child per frame, the
    /// visible child switched by STEP scale keys (the flipbook layout of `tkio`). Frames
    /// without geometry (no motion line) have no child.
    pub fn to_scene(&self) -> anim::Scene {
        let mut scene = anim::Scene::default();
        let mut channels = Vec::new();
        let times: Vec<f32> = (0..self.frames).map(|f| f as f32 / self.fps).collect();
        for part in &self.parts {
            let (name, mesh_at): (String, Box<dyn Fn(usize) -> Option<Mesh> + '_>) = match part {
                Part::Animation(a, colors) => (
                    a.mesh.name.clone(),
                    Box::new(move |f| {
                        let n = a.vertex_count();
                        let mut m = Mesh::new(
                            format!("{}_f{:04}", a.mesh.name, f + 1),
                            a.frame(f).to_vec(),
                            a.mesh.triangles.clone(),
                        );
                        m.uvs = a.mesh.uvs.clone();
                        m.colors = colors.as_ref().map(|c| c[f * n..(f + 1) * n].to_vec());
                        Some(m)
                    }),
                ),
                Part::Frames(name, meshes) => (
                    name.clone(),
                    Box::new(move |f| {
                        let m = meshes.get(f)?;
                        (!m.triangles.is_empty()).then(|| {
                            let mut m = m.clone();
                            m.name = format!("{name}_f{:04}", f + 1);
                            m
                        })
                    }),
                ),
            };
            let root = scene.nodes.len();
            scene.nodes.push(anim::Node {
                name,
                ..Default::default()
            });
            for f in 0..self.frames {
                let Some(mesh) = mesh_at(f) else { continue };
                let node = scene.nodes.len();
                scene.nodes.push(anim::Node {
                    name: mesh.name.clone(),
                    parent: Some(root),
                    mesh: Some(scene.meshes.len()),
                    transform: anim::Transform {
                        scale: if f == 0 { Vec3::ONE } else { Vec3::ZERO },
                        ..Default::default()
                    },
                    ..Default::default()
                });
                scene.nodes[root].children.push(node);
                scene.meshes.push(anim::SceneMesh {
                    mesh,
                    ..Default::default()
                });
                channels.extend(Channel::flipbook_visibility(node, f, &times));
            }
        }
        if !channels.is_empty() {
            scene.clips.push(Clip {
                name: "smear".into(),
                channels,
            });
        }
        scene
    }

    /// All parts as one USD layer (`.usda`): one `Mesh` prim per part, point caches with
    /// their per-frame colours, motion lines with per-frame topology.
    ///
    /// # Errors
    /// Inconsistent parts (frame counts, colour lengths).
    pub fn to_usda(&self) -> tkio::Result<String> {
        use tkio::usda::{UsdMesh, UsdStage};
        let meshes = self
            .parts
            .iter()
            .map(|part| match part {
                Part::Animation(a, colors) => UsdMesh::animation(a, colors.as_deref()),
                Part::Frames(name, meshes) => {
                    UsdMesh::frames(name.clone(), meshes.iter().collect())
                }
            })
            .collect();
        tkio::usda::write(&UsdStage::new(self.fps, meshes))
    }

    /// A GIF of the result: every part of every frame, fitted to the whole motion.
    ///
    /// # Errors
    /// Rendering or encoding errors.
    pub fn render_gif(&self, width: u32, height: u32) -> Result<Vec<u8>> {
        use rayon::prelude::*;
        use render::{DrawList, MeshColors, MeshItem, Renderer, View, ViewDirection};
        let renderer = Renderer::new(width, height)?;
        let mut bbox = anim::Aabb::EMPTY;
        for p in &self.parts {
            if let Part::Animation(a, None) = p {
                bbox = bbox.union(render::animation_bbox(a));
            }
        }
        let view = View::fit(
            bbox,
            ViewDirection::ThreeQuarter,
            width as f32 / height as f32,
        );
        let images: Vec<render::Image> = (0..self.frames)
            .into_par_iter()
            .map(|f| {
                let mut list = DrawList::new();
                for p in &self.parts {
                    match p {
                        Part::Animation(a, colors) => {
                            let n = a.vertex_count();
                            let mut item = MeshItem::from_animation(a, f);
                            if let Some(c) = colors {
                                item = item.colors(MeshColors::PerVertex(&c[f * n..(f + 1) * n]));
                            }
                            list = list.mesh(item);
                        }
                        Part::Frames(_, meshes) => {
                            if let Some(m) = meshes.get(f).filter(|m| !m.triangles.is_empty()) {
                                list = list.mesh(MeshItem::from_mesh(m));
                            }
                        }
                    }
                }
                renderer.render(&list, &view)
            })
            .collect::<std::result::Result<_, _>>()?;
        Ok(render::encode_gif(&images, self.fps)?)
    }
}

/// Reads a style file.
///
/// # Errors
/// One line naming the file: unreadable, bad TOML, or an invalid function.
pub fn read_style(path: &Path) -> Result<Style> {
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    Style::from_toml_str(&text).map_err(|e| anyhow!("{}: {e}", path.display()))
}

/// Runs `toonkit smear IN --style S -o OUT`.
pub fn run(ctx: &Context, args: StyleArgs) -> Result<()> {
    let start = Instant::now();
    let (Some(input_path), Some(style_path), Some(output)) =
        (&args.input, &args.style, &args.output)
    else {
        bail!(
            "usage: toonkit smear IN --style STYLE.toml -o OUT.glb|OUT.usda (or a subcommand, see --help)"
        );
    };
    let usda = tkio::Format::from_extension(output) == Some(tkio::Format::Usda);
    if !usda && tkio::Format::from_extension(output) != Some(tkio::Format::Glb) {
        bail!(
            "{}: a styled smear is written as .glb or .usda",
            output.display()
        );
    }
    let style = read_style(style_path)?;
    let sampled = input::open(input_path, &args.input_args)?;
    if sampled.objects.is_empty() {
        bail!("{}: the file has no mesh", input_path.display());
    }
    let spinner = crate::progress::spinner("applying the style", ctx.json);
    let styled = apply(&sampled, &style).map_err(|e| anyhow!("{}: {e:#}", input_path.display()))?;
    let t = Instant::now();
    let bytes = if usda {
        styled.to_usda().map(String::into_bytes)
    } else {
        tkio::gltf::write_glb(&styled.to_scene())
    }
    .map_err(|e| e.at(output))?;
    tkio::write_atomic(output, &bytes)?;
    let write_seconds = t.elapsed().as_secs_f64();
    let mut outputs = vec![output.clone()];
    if let Some(gif) = &args.gif {
        tkio::write_atomic(gif, &styled.render_gif(400, 400)?)?;
        outputs.push(gif.clone());
    }
    spinner.finish_and_clear();
    let [offsets, elongate, multiples, lines] = styled.timings;
    let summary = json!({
        "input": input_path,
        "style": style_path,
        "outputs": outputs,
        "frames": styled.frames,
        "fps": styled.fps,
        "parts": styled.parts.len(),
        "objects": styled.objects,
        "timings": {"offsets": offsets, "elongate": elongate, "multiples": multiples,
                    "lines": lines, "write": write_seconds},
        "seconds": start.elapsed().as_secs_f64(),
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({} frames, {} flipbooks) in {:.2} s",
            output.display(),
            styled.frames,
            styled.parts.len(),
            start.elapsed().as_secs_f64()
        )
    });
    Ok(())
}
