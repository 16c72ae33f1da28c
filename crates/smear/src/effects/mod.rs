//! Smear effects driven by motion offsets (Section 4): trajectories, elongated in-betweens,
//! multiple in-betweens and motion lines.

mod elongate;
mod inputs;
mod lines;
mod multiples;
mod seeds;
mod stylization;
#[cfg(test)]
mod test_util;
mod trajectory;
mod tube;
mod weights;

pub use elongate::{elongate, elongate_frame, ElongateOptions};
pub use inputs::{held_frame, EffectInputs, DEFAULT_FRAME_STEP};
pub use lines::{
    motion_lines, motion_lines_frame, LineFrame, LineOptions, LineStyle, DEFAULT_LINE_SAMPLES,
    DEFAULT_LINE_SIDES,
};
pub use multiples::{
    eq12_opacity, multiple_opacity, multiples, multiples_frame, overlap_spacing, MultipleCopy,
    MultiplesOptions, Spacing, DEFAULT_SPACING,
};
pub use seeds::{sample_surface, DEFAULT_SEED};
pub use stylization::{StyleInput, Stylize};
pub use trajectory::Trajectories;
pub use weights::{attribute_weights, group_weights, surface_point_weights};
