//! Writing results: a thin layer over [`tkio::save`], which picks the format by extension and
//! writes atomically.

use std::path::{Path, PathBuf};

use anim::MeshAnimation;
use anyhow::Result;
use tkio::Output;

/// Writes a point cache to `path` in the format its extension names. Returns every file
/// written.
pub(crate) fn write_animation(
    path: &Path,
    anim: &MeshAnimation,
    layout: tkio::Layout,
    colors: Option<&[[f32; 4]]>,
    options: tkio::SaveOptions,
) -> Result<Vec<PathBuf>> {
    Ok(tkio::save_with(
        path,
        &Output::Animation {
            animation: anim,
            layout,
            colors,
        },
        options,
    )?)
}

/// The lower-case extension of `path` ("" when it has none).
pub(crate) fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default()
}
