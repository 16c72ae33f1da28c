//! What a library job holds, counted against the job budget before the solver allocates
//! (`docs/stopmo-scale.md`, "Memory").

use std::borrow::Borrow;

use anim::{MeshAnimation, MeshFrames};

use super::error::Result;

/// Copies of a part's positions a library build holds: the parts, and at most the solver's
/// reduced coordinates (f64, twice an f32 copy, when a part is too small to be sketched).
/// The frames are streamed into the sketch, the reconstruction is kept and written as pieces
/// and labels (`reconstruction.pc2` streams frame by frame).
pub(crate) const LIBRARY_COPIES: u64 = 3;

/// What to lower when a library job is over the memory budget.
pub(crate) const MEMORY_HINT: &str = "lower --fps or pick a shorter clip";

/// What building a library of `parts` will hold ([`super::library()`] checks it before the solver
/// allocates; a server reserves it): [`LIBRARY_COPIES`] copies of the parts' frames.
pub fn library_memory<A: Borrow<MeshAnimation>>(parts: &[A]) -> anim::budget::JobMemory {
    let frames = parts.first().map_or(0, |a| a.borrow().frame_count());
    let vertices = parts.iter().map(|a| a.borrow().vertex_count()).sum();
    memory(frames, vertices, LIBRARY_COPIES)
}

/// `copies` copies of `frames` frames of parts of `vertices` vertices in all.
fn memory(frames: usize, vertices: usize, copies: u64) -> anim::budget::JobMemory {
    anim::budget::JobMemory::new().positions(
        "copies of the clip (parts, solver)",
        frames,
        vertices,
        copies,
    )
}

/// Checks what building a library of parts of `vertices` vertices in all will hold (`copies`
/// copies of their `frames` frames) against [`anim::budget::DEFAULT_MAX_JOB_BYTES`] before
/// the solver allocates.
pub(crate) fn check_memory(frames: usize, vertices: usize, copies: u64) -> Result<()> {
    memory(frames, vertices, copies)
        .check(MEMORY_HINT)
        .map_err(anim::AnimError::from)?;
    Ok(())
}

/// What [`super::library_frames()`] holds: [`LIBRARY_COPIES`] copies of the parts given as positions,
/// and for a morph clip its weights and targets (f32, twice again for the solver's f64
/// copies) plus one expanded block and the reduced coordinates.
pub fn frames_memory(parts: &[MeshFrames]) -> anim::budget::JobMemory {
    let frames = parts.first().map_or(0, MeshFrames::frame_count);
    let dense: usize = parts
        .iter()
        .filter(|p| matches!(p, MeshFrames::Positions(_)))
        .map(MeshFrames::vertex_count)
        .sum();
    let floats: u64 = parts
        .iter()
        .filter_map(|p| match p {
            MeshFrames::Morph(m) => {
                let k = m.target_count() as u64 + 1;
                Some(3 * k * (m.frame_count() as u64 + 3 * m.vertex_count() as u64))
            }
            MeshFrames::Positions(_) => None,
        })
        .sum();
    memory(frames, dense, LIBRARY_COPIES)
        .bytes("morph weights, targets and coordinates", 4 * floats)
}
