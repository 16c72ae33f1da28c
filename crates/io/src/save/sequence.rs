//! Numbered one-frame files (`name_0001.obj`, …): an animation or a flipbook written to a
//! format that holds one frame, each file that frame's own mesh.

use std::path::{Path, PathBuf};

use anim::{Mesh, MeshAnimation};

use super::{output_format, write_animation, Layout};
use crate::{Format, IoError, Result};

/// Every frame as its own file, `name_0001.obj`, … (numbered from 1, as Blender's OBJ
/// sequences are).
pub(super) fn write_sequence(
    path: &Path,
    format: Format,
    anim: &MeshAnimation,
    put: &mut dyn FnMut(&Path, Vec<u8>) -> Result<()>,
) -> Result<()> {
    let base = sequence_base(path);
    match format {
        #[cfg(feature = "obj")]
        Format::Obj => {
            for (p, text) in crate::obj::write_sequence(anim, &base) {
                put(&p, text.into_bytes())?;
            }
        }
        _ => {
            for f in 0..anim.frame_count() {
                let p = frame_path(&base, f, format);
                write_animation(
                    &p,
                    &MeshAnimation::still(anim.mesh_at(f)),
                    Layout::Flipbook,
                    None,
                    crate::gltf::GlbOptions::default(),
                    put,
                )?;
            }
        }
    }
    Ok(())
}

/// A flipbook in a one-frame format (`.obj`, `.stl`): one file per frame holding that
/// frame's own meshes (their topology may change from frame to frame), `name_0001.obj`, …;
/// a one-frame flipbook is the named file itself. OBJ keeps each mesh as its own `o`
/// object; STL holds one solid, so the meshes are joined.
pub(super) fn write_frames(
    path: &Path,
    frames: usize,
    frame: &dyn Fn(usize) -> Vec<Mesh>,
    put: &mut dyn FnMut(&Path, Vec<u8>) -> Result<()>,
) -> Result<()> {
    let format = output_format(path)?;
    let base = sequence_base(path);
    for f in 0..frames {
        let p = if frames == 1 {
            path.to_path_buf()
        } else {
            frame_path(&base, f, format)
        };
        let meshes = frame(f);
        let bytes = match format {
            #[cfg(feature = "obj")]
            Format::Obj => crate::obj::write_objects(&meshes).into_bytes(),
            #[cfg(feature = "stl")]
            Format::Stl => crate::stl::write_binary(&joined(&meshes)),
            _ => {
                return Err(
                    IoError::unsupported("this build of toonkit cannot write that format").at(&p),
                )
            }
        };
        put(&p, bytes)?;
    }
    Ok(())
}

/// Meshes joined into one (positions and triangles only), for formats with one solid.
#[cfg(feature = "stl")]
fn joined(meshes: &[Mesh]) -> Mesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for m in meshes {
        let first = positions.len() as u32;
        positions.extend_from_slice(&m.positions);
        triangles.extend(m.triangles.iter().map(|t| t.map(|i| i + first)));
    }
    Mesh::new("frame", positions, triangles)
}

/// `out/walk.obj` or `out/walk_0001.obj` → `out/walk` (frames are numbered from there).
pub(super) fn sequence_base(path: &Path) -> PathBuf {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("frame");
    let trimmed = stem.trim_end_matches(|c: char| c.is_ascii_digit());
    let trimmed = if trimmed.len() < stem.len() {
        trimmed.trim_end_matches('_')
    } else {
        stem
    };
    path.with_file_name(trimmed)
}

/// Frame `f`'s file of the sequence based at `base`: `out/walk` → `out/walk_0001.obj` (numbered
/// from 1, as Blender's OBJ sequences are).
fn frame_path(base: &Path, f: usize, format: Format) -> PathBuf {
    let stem = base.file_name().map(|s| s.to_string_lossy().into_owned());
    let stem = stem.unwrap_or_else(|| "frame".into());
    base.with_file_name(format!("{stem}_{:04}.{}", f + 1, format.extension()))
}
