//! Writing results by file extension: the mirror of [`load`](crate::load). One place picks the
//! format for every result kind, and every file is written atomically (temporary file +
//! rename), so an interrupted or failed write never leaves a partial file behind.

use std::path::{Path, PathBuf};

use anim::{Flipbook, Mesh, MeshAnimation};

use crate::shapes::ShapeAnimation;
use crate::usda::{UsdMesh, UsdStage};

use crate::{write_atomic_all, Format, IoError, Result};

mod sequence;

use sequence::{write_frames, write_sequence};

/// How an animation is laid out in the output file.
///
/// The rule for formats that hold one frame (`.obj`, `.stl`, see [`Format::holds_one_frame`]):
/// an animation of several frames is written as a numbered sequence with [`Layout::Sequence`],
/// as one frame with [`Layout::Frame`], and refused otherwise
/// ([`IoError::FramesDoNotFit`]) — never silently cut to its first frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Layout {
    /// glTF: one node per frame, visibility keyed (vertex colours per frame). Other formats:
    /// their natural layout (a point cache, a time-sampled mesh).
    #[default]
    Flipbook,
    /// glTF: one morph target per frame, STEP weights.
    Morph,
    /// One file per frame, `name_0001.obj`, … (`.obj`, `.stl`).
    Sequence,
    /// Only this frame (0-based), in any format.
    Frame(usize),
}

impl Layout {
    /// The layouts a user picks by name (`--layout NAME`); [`Layout::Frame`] is picked by
    /// number (`--frame N`).
    pub const NAMED: [Layout; 3] = [Layout::Flipbook, Layout::Morph, Layout::Sequence];

    /// The name of the layout (`flipbook`, `morph`, `sequence`, `frame`).
    pub fn name(self) -> &'static str {
        match self {
            Layout::Flipbook => "flipbook",
            Layout::Morph => "morph",
            Layout::Sequence => "sequence",
            Layout::Frame(_) => "frame",
        }
    }
}

impl std::str::FromStr for Layout {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Layout, String> {
        Layout::NAMED
            .into_iter()
            .find(|l| l.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("unknown layout '{s}' (use flipbook, morph or sequence)"))
    }
}

/// One result to write. The variant says what the data is; the path's extension says how.
#[derive(Debug, Clone, Copy)]
pub enum Output<'a> {
    /// A point cache (one topology, many frames), with optional per-frame RGBA vertex colours
    /// (frame-major) for glTF flipbooks and USD display colour/opacity.
    Animation {
        /// The animation.
        animation: &'a MeshAnimation,
        /// Flipbook, morph targets or OBJ sequence.
        layout: Layout,
        /// Per-frame vertex colours, `frames × vertices`.
        colors: Option<&'a [[f32; 4]]>,
    },
    /// Several point caches with the same frames, as one multi-node glTF (one node or node
    /// group per part), or one scene cache (`.usda`, `.usdc`, `.usdz`, `.abc`: one mesh per
    /// part).
    Parts {
        /// `(animation, per-frame colours)` per part.
        parts: &'a [(&'a MeshAnimation, Option<&'a [[f32; 4]]>)],
        /// Flipbook or morph targets.
        layout: Layout,
    },
    /// Parts with the same frames, some with a topology that changes per frame (a
    /// stylization result): `.glb` (one root node per part, one child per frame with
    /// geometry, visibility keyed) or a scene cache (`.usda`, `.usdc`, `.usdz`, `.abc`: one
    /// mesh per part).
    Flipbook(&'a Flipbook),
    /// A body and its motion lines (one mesh per frame, possibly empty): `.glb` (the body's
    /// and the lines' frames as visibility-keyed nodes) or a scene cache (the body's point
    /// cache and one `motion_lines` mesh with per-frame topology).
    MotionLines {
        /// The body's point cache.
        body: &'a MeshAnimation,
        /// The lines of every frame.
        lines: &'a [Mesh],
        /// The same lines as curves (the tubes' centre lines with widths and colours): USD
        /// layers write these as a `BasisCurves` prim instead of the tubes.
        curves: Option<&'a [anim::Curves]>,
    },
    /// A whole USD stage (mesh prims with point caches or per-frame topology, e.g. motion
    /// lines) as a scene cache: `.usda`, `.usdc`, `.usdz` or `.abc` (one PolyMesh per prim).
    Stage(&'a UsdStage<'a>),
    /// A scalar per frame and vertex (`.npy`, float32, `frames × vertices`).
    Field {
        /// Number of frames.
        frames: usize,
        /// Number of vertices.
        vertices: usize,
        /// Values, frame-major.
        values: &'a [f32],
    },
    /// One static mesh (`.obj`, `.stl`, `.glb`).
    Mesh(&'a Mesh),
    /// Text written as is (CSV, JSON, Markdown, …).
    Text(&'a str),
    /// Bytes written as is (an encoded PNG or GIF).
    Bytes(&'a [u8]),
    /// Parts with the same frames, each showing one of a few shapes per frame (a stop-motion
    /// replacement library), never expanded to every frame where the format allows: `.glb`
    /// (one morph target per shape, STEP weights), `.pc2` (merged in part order, streamed to
    /// disk; `rest` as a same-name `.obj` beside it); other formats get the expanded parts.
    Shapes {
        /// The parts.
        parts: &'a [ShapeAnimation<'a>],
        /// The merged rest mesh written beside a point cache.
        rest: &'a Mesh,
    },
}

/// How [`save_with`] writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SaveOptions {
    /// glTF flipbooks, parts, motion lines and morph outputs with `KHR_mesh_quantization`
    /// (positions and morph deltas as normalized SHORT, normals as BYTE: about half the
    /// bytes). One dequantization covers every part and frame of an output, so seams that
    /// parts share stay identical; the position error is at most
    /// [`crate::gltf::MAX_ERROR`] of the bounding-box diagonal, else the output stays float.
    /// Default `true`.
    pub quantize: bool,
}

impl Default for SaveOptions {
    fn default() -> Self {
        SaveOptions { quantize: true }
    }
}

/// Writes `output` to `path` in the format its extension names and returns every file written
/// (PC2 and MDD caches get their rest mesh as a same-name `.obj` beside them; OBJ sequences
/// one file per frame). glTF geometry is quantized ([`SaveOptions::default`]).
///
/// # Errors
/// [`IoError::Unsupported`] naming `path` when the extension is unknown or cannot hold the
/// data; [`IoError::Io`] when the file cannot be written (the previous file, if any, is kept).
pub fn save(path: &Path, output: &Output<'_>) -> Result<Vec<PathBuf>> {
    save_with(path, output, SaveOptions::default())
}

/// [`save`] with options (e.g. float glTF geometry: `SaveOptions { quantize: false }`).
///
/// # Errors
/// As [`save`].
pub fn save_with(path: &Path, output: &Output<'_>, options: SaveOptions) -> Result<Vec<PathBuf>> {
    let glb = crate::gltf::GlbOptions {
        quantize: options.quantize,
    };
    // Every file is encoded first, then all are written together (all or nothing).
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    // Encoded files are moved in, never copied (they can be hundreds of megabytes).
    let mut put = |p: &Path, bytes: Vec<u8>| -> Result<()> {
        files.push((p.to_path_buf(), bytes));
        Ok(())
    };
    // Files streamed to disk during the match (listed first among the files written).
    let mut streamed: Vec<PathBuf> = Vec::new();
    match *output {
        Output::Text(text) => put(path, text.as_bytes().to_vec())?,
        Output::Bytes(bytes) => put(path, bytes.to_vec())?,
        Output::Field {
            frames,
            vertices,
            values,
        } => {
            expect_extension(path, Format::Npy, "a per-frame scalar field", ".npy")?;
            // One file, streamed: no encoded copy of a field of megabytes.
            let shape = [frames, vertices];
            crate::atomic::write_atomic_with(path, |f| {
                crate::npy::write_f32_to(f, &shape, values)
            })?;
            return Ok(vec![path.to_path_buf()]);
        }
        Output::Mesh(mesh) => match output_format(path)? {
            #[cfg(feature = "obj")]
            Format::Obj => put(path, crate::obj::write(mesh).into_bytes())?,
            #[cfg(feature = "stl")]
            Format::Stl => put(path, crate::stl::write_binary(mesh))?,
            _ => {
                let anim =
                    MeshAnimation::new(mesh.clone(), anim::DEFAULT_FPS, mesh.positions.clone())
                        .map_err(|e| IoError::from(e).at(path))?;
                return save_with(
                    path,
                    &Output::Animation {
                        animation: &anim,
                        layout: Layout::Flipbook,
                        colors: None,
                    },
                    options,
                );
            }
        },
        Output::Stage(stage) => put(path, write_stage(path, stage)?)?,
        Output::Parts { parts, layout } if output_format(path)?.holds_one_frame() => {
            let frames = parts.first().map_or(0, |(a, _)| a.frame_count());
            if layout != Layout::Sequence && frames > 1 {
                return Err(IoError::FramesDoNotFit {
                    path: Default::default(),
                    frames,
                    extension: output_format(path)?.extension(),
                }
                .at(path));
            }
            let frame = |f| {
                let mut meshes = Vec::with_capacity(parts.len());
                for (a, colors) in parts {
                    let n = a.vertex_count();
                    let colors = colors.and_then(|c| c.get(f * n..(f + 1) * n));
                    if crate::flipbook::shows(a.frame(f), colors) {
                        let mut m = a.mesh_at(f);
                        m.normals = None;
                        m.colors = colors.map(<[_]>::to_vec);
                        meshes.push(m);
                    }
                }
                meshes
            };
            write_frames(path, frames, &frame, &mut put)?;
        }
        Output::Parts { parts, layout } => {
            if matches!(layout, Layout::Sequence | Layout::Frame(_)) {
                return Err(IoError::unsupported(format!(
                    "parts are written whole as .glb or a scene cache: the {} layout does not apply (use flipbook or morph)",
                    layout.name()
                ))
                .at(path));
            }
            let bytes = if output_format(path)? == Format::Glb {
                crate::gltf::write_animations_with(parts, gltf_layout(layout), glb)
                    .map_err(|e| e.at(path))?
            } else {
                let stage = UsdStage::from_parts(parts).map_err(|e| e.at(path))?;
                write_stage(path, &stage)?
            };
            put(path, bytes)?;
        }
        Output::Flipbook(book) if output_format(path)?.holds_one_frame() => {
            let frame = |f| crate::flipbook::frame_meshes(book, f);
            write_frames(path, book.frames, &frame, &mut put)?;
        }
        Output::MotionLines { body, lines, .. } if output_format(path)?.holds_one_frame() => {
            let frame = |f| crate::flipbook::lines_frame(body, lines, f);
            write_frames(path, body.frame_count(), &frame, &mut put)?;
        }
        Output::Flipbook(book) => {
            let bytes = if output_format(path)? == Format::Glb {
                crate::gltf::write_glb_with(&crate::flipbook::flipbook_scene(book), glb)
                    .map_err(|e| e.at(path))?
            } else {
                let holds = curves_in(output_format(path)?);
                write_stage(path, &crate::flipbook::flipbook_stage(book, &holds))?
            };
            put(path, bytes)?;
        }
        Output::MotionLines {
            body,
            lines,
            curves,
        } => {
            let bytes = if output_format(path)? == Format::Glb {
                crate::gltf::write_glb_with(&crate::flipbook::lines_scene(body, lines), glb)
                    .map_err(|e| e.at(path))?
            } else {
                let holds = curves_in(output_format(path)?);
                let stage = crate::flipbook::lines_stage(body, lines, curves, &holds);
                write_stage(path, &stage)?
            };
            put(path, bytes)?;
        }
        Output::Animation {
            animation,
            layout,
            colors,
        } => write_animation(path, animation, layout, colors, glb, &mut put)?,
        Output::Shapes { parts, rest } => {
            crate::shapes::check_parts(parts).map_err(|e| e.at(path))?;
            match output_format(path)? {
                Format::Pc2 => {
                    rest_mesh_of(path, rest, &mut put)?;
                    // The cache streams to disk first; the rest mesh follows, all or nothing
                    // for it.
                    crate::shapes::write_pc2(path, parts)?;
                    streamed.push(path.to_path_buf());
                }
                Format::Glb => put(
                    path,
                    crate::gltf::write_glb_with(&crate::shapes::shapes_scene(parts), glb)
                        .map_err(|e| e.at(path))?,
                )?,
                _ => {
                    let expanded = parts
                        .iter()
                        .map(ShapeAnimation::expand)
                        .collect::<Result<Vec<_>>>()
                        .map_err(|e| e.at(path))?;
                    let layers: Vec<(&MeshAnimation, Option<&[[f32; 4]]>)> =
                        expanded.iter().map(|a| (a, None)).collect();
                    return save_with(
                        path,
                        &Output::Parts {
                            parts: &layers,
                            layout: Layout::Morph,
                        },
                        options,
                    );
                }
            }
        }
    }
    write_atomic_all(&files)?;
    streamed.extend(files.into_iter().map(|(p, _)| p));
    Ok(streamed)
}

/// The format of an output path, or an error naming the extensions toonkit writes.
fn output_format(path: &Path) -> Result<Format> {
    Format::from_extension(path).ok_or_else(|| {
        IoError::unsupported(format!(
            "unknown output extension (use {})",
            Format::list(&Format::MESH_ANIMATIONS)
        ))
        .at(path)
    })
}

/// Which curves a scene cache format writes as curves (`BasisCurves`): all in `.usda`,
/// those `openusd` encodes right in `.usdc`/`.usdz` ([`crate::usdc::holds_curves`]), none in
/// `.abc` (whose writer holds meshes: the tubes are written).
fn curves_in(format: Format) -> impl Fn(&[&anim::Curves]) -> bool {
    move |curves| match format {
        Format::Usda => true,
        Format::Usdc | Format::Usdz => crate::usdc::holds_curves(curves),
        _ => false,
    }
}

/// A stage as a scene cache in the format `path` names.
fn write_stage(path: &Path, stage: &UsdStage) -> Result<Vec<u8>> {
    let bytes = match output_format(path)? {
        Format::Usda => crate::usda::write(stage).map(String::into_bytes),
        Format::Usdc => crate::usdc::write(stage),
        Format::Usdz => crate::usdc::write_usdz(stage),
        Format::Abc => crate::abc::write(stage),
        _ => {
            return Err(IoError::unsupported(
                "a scene cache is written as .usda, .usdc, .usdz, .abc (or .glb for parts)",
            )
            .at(path))
        }
    };
    bytes.map_err(|e| e.at(path))
}

fn expect_extension(path: &Path, want: Format, what: &str, ext: &str) -> Result<()> {
    if output_format(path)? != want {
        return Err(IoError::unsupported(format!("{what} is written as {ext}")).at(path));
    }
    Ok(())
}

fn gltf_layout(layout: Layout) -> crate::gltf::AnimationLayout {
    match layout {
        Layout::Morph => crate::gltf::AnimationLayout::Morph,
        _ => crate::gltf::AnimationLayout::Flipbook,
    }
}

fn write_animation(
    path: &Path,
    anim: &MeshAnimation,
    layout: Layout,
    colors: Option<&[[f32; 4]]>,
    glb: crate::gltf::GlbOptions,
    put: &mut dyn FnMut(&Path, Vec<u8>) -> Result<()>,
) -> Result<()> {
    let format = output_format(path)?;
    if let Layout::Frame(frame) = layout {
        let frames = anim.frame_count();
        if frame >= frames {
            return Err(IoError::NoSuchFrame {
                path: Default::default(),
                frame,
                last: frames.saturating_sub(1),
            }
            .at(path));
        }
        let one = MeshAnimation::new(anim.mesh.clone(), anim.fps, anim.frame(frame).to_vec())
            .map_err(|e| IoError::from(e).at(path))?;
        let n = anim.vertex_count();
        let colors = colors.and_then(|c| c.get(frame * n..(frame + 1) * n));
        return write_animation(path, &one, Layout::Flipbook, colors, glb, put);
    }
    if format.holds_one_frame() {
        if layout == Layout::Sequence && anim.frame_count() > 1 {
            return write_sequence(path, format, anim, put);
        }
        if anim.frame_count() > 1 {
            return Err(IoError::FramesDoNotFit {
                path: Default::default(),
                frames: anim.frame_count(),
                extension: format.extension(),
            }
            .at(path));
        }
    } else if layout == Layout::Sequence {
        return Err(IoError::unsupported(format!(
            "the sequence layout writes one file per frame: name the output .obj or .stl (a .{} holds every frame)",
            format.extension()
        ))
        .at(path));
    }
    match format {
        Format::Glb => {
            let bytes =
                crate::gltf::write_animations_with(&[(anim, colors)], gltf_layout(layout), glb)
                    .map_err(|e| e.at(path))?;
            put(path, bytes)
        }
        Format::Gltf => {
            Err(IoError::unsupported("toonkit writes binary glTF: name the output .glb").at(path))
        }
        format @ (Format::Pc2 | Format::Mdd) => {
            let bytes = if format == Format::Pc2 {
                crate::pc2::write(anim)
            } else {
                crate::mdd::write(anim)
            };
            put(path, bytes)?;
            rest_mesh(path, anim, put)
        }
        #[cfg(feature = "obj")]
        Format::Obj => put(path, crate::obj::write(&anim.mesh_at(0)).into_bytes()),
        #[cfg(feature = "stl")]
        Format::Stl => put(path, crate::stl::write_binary(&anim.mesh_at(0))),
        Format::Npy => {
            let flat: Vec<f32> = anim.positions().iter().flat_map(|p| p.to_array()).collect();
            let shape = [anim.frame_count(), anim.vertex_count(), 3];
            put(
                path,
                crate::npy::write_f32(&shape, &flat).map_err(|e| e.at(path))?,
            )
        }
        Format::Bvh => Err(IoError::unsupported("BVH output holds skeletons, not meshes").at(path)),
        Format::Fbx => Err(IoError::unsupported(
            "toonkit reads FBX but does not write it (write .glb, .usdc or .abc)",
        )
        .at(path)),
        Format::Usda | Format::Usdc | Format::Usdz | Format::Abc => {
            let stage = UsdStage::new(anim.fps, vec![UsdMesh::animation(anim, colors)]);
            put(path, write_stage(path, &stage)?)
        }
        #[allow(unreachable_patterns)]
        _ => Err(IoError::unsupported("this build of toonkit cannot write that format").at(path)),
    }
}

/// The rest mesh of a PC2/MDD cache, as a same-name `.obj` beside it.
#[cfg(feature = "obj")]
fn rest_mesh(
    path: &Path,
    anim: &MeshAnimation,
    put: &mut dyn FnMut(&Path, Vec<u8>) -> Result<()>,
) -> Result<()> {
    rest_mesh_of(path, &anim.mesh, put)
}

/// `mesh` as the same-name `.obj` beside the point cache `path`.
#[cfg(feature = "obj")]
fn rest_mesh_of(
    path: &Path,
    mesh: &Mesh,
    put: &mut dyn FnMut(&Path, Vec<u8>) -> Result<()>,
) -> Result<()> {
    put(
        &path.with_extension("obj"),
        crate::obj::write(mesh).into_bytes(),
    )
}

#[cfg(not(feature = "obj"))]
fn rest_mesh_of(_: &Path, _: &Mesh, _: &mut dyn FnMut(&Path, Vec<u8>) -> Result<()>) -> Result<()> {
    Ok(())
}

#[cfg(not(feature = "obj"))]
fn rest_mesh(
    _: &Path,
    _: &MeshAnimation,
    _: &mut dyn FnMut(&Path, Vec<u8>) -> Result<()>,
) -> Result<()> {
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::sequence::sequence_base;
    use super::*;

    #[test]
    fn sequence_base_strips_frame_number() {
        assert_eq!(
            sequence_base(Path::new("o/walk_0001.obj")),
            PathBuf::from("o/walk")
        );
        assert_eq!(
            sequence_base(Path::new("o/walk.obj")),
            PathBuf::from("o/walk")
        );
    }

    #[test]
    fn unknown_extension_names_the_file() {
        let e = save(
            Path::new("/nonexistent/x.foo"),
            &Output::Field {
                frames: 1,
                vertices: 1,
                values: &[0.0],
            },
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("/nonexistent/x.foo: "), "{e}");
        assert!(e.contains("unknown output extension"), "{e}");
    }
}
