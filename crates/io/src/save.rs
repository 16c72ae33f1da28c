//! Writing results by file extension: the mirror of [`load`](crate::load). One place picks the
//! format for every result kind, and every file is written atomically (temporary file +
//! rename), so an interrupted or failed write never leaves a partial file behind.

use std::path::{Path, PathBuf};

use anim::{Flipbook, Mesh, MeshAnimation};

use crate::usda::{UsdMesh, UsdStage};

use crate::{write_atomic, Format, IoError, Result};

/// How an animation is laid out in the output file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Layout {
    /// glTF: one node per frame, visibility keyed (vertex colours per frame).
    #[default]
    Flipbook,
    /// glTF: one morph target per frame, STEP weights.
    Morph,
    /// OBJ: one file per frame, `name_0001.obj`, ….
    Sequence,
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
    let mut written = Vec::new();
    let mut put = |p: &Path, bytes: &[u8]| -> Result<()> {
        write_atomic(p, bytes)?;
        written.push(p.to_path_buf());
        Ok(())
    };
    match *output {
        Output::Text(text) => put(path, text.as_bytes())?,
        Output::Bytes(bytes) => put(path, bytes)?,
        Output::Field {
            frames,
            vertices,
            values,
        } => {
            expect_extension(path, Format::Npy, "a per-frame scalar field", ".npy")?;
            put(
                path,
                &crate::npy::write_f32(&[frames, vertices], values).map_err(|e| e.at(path))?,
            )?
        }
        Output::Mesh(mesh) => match output_format(path)? {
            #[cfg(feature = "obj")]
            Format::Obj => put(path, crate::obj::write(mesh).as_bytes())?,
            #[cfg(feature = "stl")]
            Format::Stl => put(path, &crate::stl::write_binary(mesh))?,
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
        Output::Stage(stage) => put(path, &write_stage(path, stage)?)?,
        Output::Parts { parts, layout } => {
            let bytes = if output_format(path)? == Format::Glb {
                crate::gltf::write_animations_with(parts, gltf_layout(layout), glb)
                    .map_err(|e| e.at(path))?
            } else {
                let stage = UsdStage::from_parts(parts).map_err(|e| e.at(path))?;
                write_stage(path, &stage)?
            };
            put(path, &bytes)?;
        }
        Output::Flipbook(book) => {
            let bytes = if output_format(path)? == Format::Glb {
                crate::gltf::write_glb_with(&crate::flipbook::flipbook_scene(book), glb)
                    .map_err(|e| e.at(path))?
            } else {
                write_stage(path, &crate::flipbook::flipbook_stage(book))?
            };
            put(path, &bytes)?;
        }
        Output::MotionLines { body, lines } => {
            let bytes = if output_format(path)? == Format::Glb {
                crate::gltf::write_glb_with(&crate::flipbook::lines_scene(body, lines), glb)
                    .map_err(|e| e.at(path))?
            } else {
                write_stage(path, &crate::flipbook::lines_stage(body, lines))?
            };
            put(path, &bytes)?;
        }
        Output::Animation {
            animation,
            layout,
            colors,
        } => write_animation(path, animation, layout, colors, glb, &mut put)?,
    }
    Ok(written)
}

/// The format of an output path, or an error naming the extensions toonkit writes.
fn output_format(path: &Path) -> Result<Format> {
    Format::from_extension(path).ok_or_else(|| {
        IoError::unsupported(
            "unknown output extension (use .glb, .usda, .usdc, .usdz, .abc, .pc2, .mdd, .obj, .stl or .npy)",
        )
        .at(path)
    })
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
    put: &mut dyn FnMut(&Path, &[u8]) -> Result<()>,
) -> Result<()> {
    match output_format(path)? {
        Format::Glb => {
            let bytes =
                crate::gltf::write_animations_with(&[(anim, colors)], gltf_layout(layout), glb)
                    .map_err(|e| e.at(path))?;
            put(path, &bytes)
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
            put(path, &bytes)?;
            rest_mesh(path, anim, put)
        }
        #[cfg(feature = "obj")]
        Format::Obj => {
            if layout == Layout::Sequence && anim.frame_count() > 1 {
                for (p, text) in crate::obj::write_sequence(anim, &sequence_base(path)) {
                    put(&p, text.as_bytes())?;
                }
                Ok(())
            } else {
                put(path, crate::obj::write(&anim.mesh_at(0)).as_bytes())
            }
        }
        #[cfg(feature = "stl")]
        Format::Stl => put(path, &crate::stl::write_binary(&anim.mesh_at(0))),
        Format::Npy => {
            let flat: Vec<f32> = anim.positions().iter().flat_map(|p| p.to_array()).collect();
            let shape = [anim.frame_count(), anim.vertex_count(), 3];
            put(
                path,
                &crate::npy::write_f32(&shape, &flat).map_err(|e| e.at(path))?,
            )
        }
        Format::Bvh => Err(IoError::unsupported("BVH output holds skeletons, not meshes").at(path)),
        Format::Fbx => Err(IoError::unsupported(
            "toonkit reads FBX but does not write it (write .glb, .usdc or .abc)",
        )
        .at(path)),
        Format::Usda | Format::Usdc | Format::Usdz | Format::Abc => {
            let stage = UsdStage::new(anim.fps, vec![UsdMesh::animation(anim, colors)]);
            put(path, &write_stage(path, &stage)?)
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
    put: &mut dyn FnMut(&Path, &[u8]) -> Result<()>,
) -> Result<()> {
    put(
        &path.with_extension("obj"),
        crate::obj::write(&anim.mesh).as_bytes(),
    )
}

#[cfg(not(feature = "obj"))]
fn rest_mesh(
    _: &Path,
    _: &MeshAnimation,
    _: &mut dyn FnMut(&Path, &[u8]) -> Result<()>,
) -> Result<()> {
    Ok(())
}

/// `out/walk.obj` or `out/walk_0001.obj` → `out/walk` (frames are numbered from there).
fn sequence_base(path: &Path) -> PathBuf {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("frame");
    let trimmed = stem.trim_end_matches(|c: char| c.is_ascii_digit());
    let trimmed = if trimmed.len() < stem.len() {
        trimmed.trim_end_matches('_')
    } else {
        stem
    };
    path.with_file_name(trimmed)
}

#[cfg(test)]
mod tests {
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
