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

/// What a write produced, for the summary line: "out.obj", or "out_0001.obj … out_0048.obj
/// (48 files)" for a sequence.
pub(crate) fn files(written: &[PathBuf]) -> String {
    match written {
        [] => "nothing".into(),
        [one] => one.display().to_string(),
        [first, .., last] if is_sequence(written) => format!(
            "{} … {} ({} files)",
            first.display(),
            last.display(),
            written.len()
        ),
        many => many
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
    }
}

/// The frames a write holds, for the summary line: "48 frames" or "frame 5 of 48".
pub(crate) fn frames_written(layout: tkio::Layout, frames: usize) -> String {
    match layout {
        tkio::Layout::Frame(f) => format!("frame {f} of {frames}"),
        _ if frames == 1 => "1 frame".into(),
        _ => format!("{frames} frames"),
    }
}

fn is_sequence(written: &[PathBuf]) -> bool {
    let ext = |p: &PathBuf| p.extension().map(|e| e.to_ascii_lowercase());
    written.len() > 2 && written.iter().all(|p| ext(p) == ext(&written[0]))
}

/// Refuses an output whose format cannot hold scenes (one mesh per part, a topology that
/// changes per frame): those of [`tkio::Format::SCENES`] can; `why` says what needs one.
///
/// # Errors
/// `PATH: why` for any other extension.
pub(crate) fn require_scenes(path: &Path, why: &str) -> Result<()> {
    if !tkio::Format::from_extension(path).is_some_and(tkio::Format::holds_scenes) {
        anyhow::bail!("{}: {why}", path.display());
    }
    Ok(())
}
