//! Smear effects driven by motion offsets (Section 4): trajectories, elongated in-betweens,
//! multiple in-betweens and motion lines.

mod contact;
mod elongate;
mod inputs;
mod lines;
mod multiples;
mod seeds;
mod style_block;
mod stylization;
mod subdivide;
#[cfg(test)]
pub(crate) mod test_util;
mod trajectory;
mod tube;
mod weights;

pub use contact::{squash_frames, ContactStyle, Squash, DEFAULT_SQUASH_FRAMES, MAX_SQUASH};
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
pub use style_block::{StyleBlock, STYLE_BLOCK};
pub use stylization::{StyleInput, Stylize};
pub use subdivide::{
    subdivide_frame, subdivide_moving_frame, trajectory_velocities, AroundFrame, SubdivisionStats,
    BEND, DEVIATION_SHARE, MAX_SUBDIVISION_LEVELS,
};
pub use trajectory::Trajectories;
pub use weights::{attribute_weights, group_weights, surface_point_weights};
