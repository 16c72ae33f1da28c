//! Writing results by file extension, always atomically (temporary file + rename).

use std::path::{Path, PathBuf};

use anim::MeshAnimation;
use anyhow::{bail, Result};
use clap::ValueEnum;
use tkio::{write_atomic, Format};

/// How an animation is laid out in the output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum Layout {
    /// glTF: one node per frame, visibility keyed (vertex colours per frame).
    #[default]
    Flipbook,
    /// glTF: one morph target per frame, STEP weights.
    Morph,
    /// OBJ: one file per frame, `name_0001.obj`, ….
    Sequence,
}

/// Writes a point cache to `path` in the format its extension names. PC2 and MDD caches get
/// their rest mesh as a same-name `.obj` beside them. Returns every file written.
///
/// `colors`: optional per-frame RGBA vertex colours (frame-major), used by glTF flipbooks and
/// USD (`primvars:displayColor`/`displayOpacity`).
pub fn write_animation(
    path: &Path,
    anim: &MeshAnimation,
    layout: Layout,
    colors: Option<&[[f32; 4]]>,
) -> Result<Vec<PathBuf>> {
    let format = Format::from_extension(path).ok_or_else(|| {
        anyhow::anyhow!(
            "{}: unknown output extension (use .glb, .usda, .pc2, .mdd, .obj, .stl or .npy)",
            path.display()
        )
    })?;
    let mut written = Vec::new();
    let mut put = |p: &Path, bytes: &[u8]| -> Result<()> {
        write_atomic(p, bytes)?;
        written.push(p.to_path_buf());
        Ok(())
    };
    match format {
        Format::Glb => {
            let l = match layout {
                Layout::Morph => tkio::gltf::AnimationLayout::Morph,
                _ => tkio::gltf::AnimationLayout::Flipbook,
            };
            let bytes = tkio::gltf::write_animation(anim, l, colors).map_err(|e| e.at(path))?;
            put(path, &bytes)?;
        }
        Format::Gltf => bail!(
            "{}: toonkit writes binary glTF: name the output .glb",
            path.display()
        ),
        Format::Pc2 | Format::Mdd => {
            let bytes = if format == Format::Pc2 {
                tkio::pc2::write(anim)
            } else {
                tkio::mdd::write(anim)
            };
            put(path, &bytes)?;
            put(
                &path.with_extension("obj"),
                tkio::obj::write(&anim.mesh).as_bytes(),
            )?;
        }
        Format::Obj => {
            if layout == Layout::Sequence && anim.frame_count() > 1 {
                let base = sequence_base(path);
                for (p, text) in tkio::obj::write_sequence(anim, &base) {
                    put(&p, text.as_bytes())?;
                }
            } else {
                put(path, tkio::obj::write(&anim.mesh_at(0)).as_bytes())?;
            }
        }
        Format::Stl => put(path, &tkio::stl::write_binary(&anim.mesh_at(0)))?,
        Format::Npy => {
            let flat: Vec<f32> = anim.positions().iter().flat_map(|p| p.to_array()).collect();
            let shape = [anim.frame_count(), anim.vertex_count(), 3];
            put(
                path,
                &tkio::npy::write_f32(&shape, &flat).map_err(|e| e.at(path))?,
            )?;
        }
        Format::Bvh => bail!("{}: BVH output holds skeletons, not meshes", path.display()),
        Format::Usda => {
            let text = tkio::usda::write_animation(anim, colors).map_err(|e| e.at(path))?;
            put(path, text.as_bytes())?;
        }
    }
    Ok(written)
}

/// The lower-case extension of `path` ("" when it has none).
pub fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default()
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

/// Writes a scalar field per frame and vertex as `.npy` (float32, frames × vertices).
pub fn write_npy_field(path: &Path, frames: usize, vertices: usize, values: &[f32]) -> Result<()> {
    let bytes = tkio::npy::write_f32(&[frames, vertices], values).map_err(|e| e.at(path))?;
    write_atomic(path, &bytes)?;
    Ok(())
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
}
