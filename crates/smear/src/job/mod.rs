//! The whole smear job on in-memory data: [`prepare`] once (offsets, camera, weights,
//! velocities), then [`stylize`] with any number of styles; [`offsets`] alone for
//! `toonkit smear offsets`.

mod frames;
mod prepare;
mod stylize;

pub use prepare::{
    offsets, prepare, ObjectOffsets, PrepareOptions, PrepareReport, Prepared, SceneOffsets,
};
pub use stylize::{
    stylize, stylize_frames, stylize_memory, CopyReport, ObjectParts, ObjectReport, StylizeReport,
    StylizeTimings, Stylized,
};
