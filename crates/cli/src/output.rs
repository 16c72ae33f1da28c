//! Writing results: a thin layer over [`tkio::save`], which picks the format by extension and
//! writes atomically.

use std::path::{Path, PathBuf};

use anim::MeshAnimation;
use anyhow::Result;
use clap::ValueEnum;
use tkio::Output;

/// How an animation is laid out in the output (the CLI face of [`tkio::Layout`]).
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

impl From<Layout> for tkio::Layout {
    fn from(l: Layout) -> tkio::Layout {
        match l {
            Layout::Flipbook => tkio::Layout::Flipbook,
            Layout::Morph => tkio::Layout::Morph,
            Layout::Sequence => tkio::Layout::Sequence,
        }
    }
}

/// Writes a point cache to `path` in the format its extension names. Returns every file
/// written.
pub fn write_animation(
    path: &Path,
    anim: &MeshAnimation,
    layout: Layout,
    colors: Option<&[[f32; 4]]>,
    options: tkio::SaveOptions,
) -> Result<Vec<PathBuf>> {
    Ok(tkio::save_with(
        path,
        &Output::Animation {
            animation: anim,
            layout: layout.into(),
            colors,
        },
        options,
    )?)
}

/// The lower-case extension of `path` ("" when it has none).
pub fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default()
}

/// Writes a scalar field per frame and vertex as `.npy` (float32, frames × vertices).
pub fn write_npy_field(path: &Path, frames: usize, vertices: usize, values: &[f32]) -> Result<()> {
    tkio::save(
        path,
        &Output::Field {
            frames,
            vertices,
            values,
        },
    )?;
    Ok(())
}
