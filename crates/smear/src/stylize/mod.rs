//! Stylization functions (paper G3; S_E, S_M, S_L of SMEAR Eqs. 10–13 and the variants of Section 5)
//! and styles: which effects to apply with which functions and parameters.
//!
//! * [`Stage`] chains compose the paper's presets: linear (`scale`), speed-weighted, Voronoi
//!   noise, past-/future-only offsets, Hise-warped offsets, painted weights, speed threshold,
//!   the multiples opacity of SMEAR Eq. 12, line fading.
//! * [`Expression`]: user expressions (exmex) over `delta, speed, weight, noise, frame, m, t,
//!   vx, vy, vz, x, y, z` and declared parameters.
//! * [`Param`]: every numeric parameter is a constant or a keyframed curve.
//! * [`Style`]: several effects with their functions and per-object overrides, read from TOML.
//! * [`SpeedUnits`], [`SizeReference`], [`StyleUnits`]: a style's speeds and lengths are in
//!   the character's own size by default (`docs/smear-units.md`).

mod compiled;
mod error;
mod expr;
mod function;
mod param;
mod preset;
mod stage;
mod style;
#[cfg(test)]
mod style_tests;
mod units;
mod voronoi;
mod warp;
mod weights;

pub use compiled::{CompiledEffects, CompiledLines};
pub use error::StyleError;
pub use expr::{Expression, StyleOps, EXPRESSION_INPUTS, MAX_EXPRESSION_VARIABLES};
pub use function::{FunctionSpec, StyleFunction};
pub use param::Param;
pub use preset::{
    parameter, ElongatePreset, Parameter, DEFAULT_BETA_MAX, DEFAULT_COPIES, DEFAULT_KAPPA,
    DEFAULT_LINE_LENGTH, PARAMETERS,
};
pub use stage::{apply_stages, apply_stages_block, Stage};
pub use style::{
    ElongateStyle, LinesStyle, MultiplesStyle, ObjectEffects, ObjectStyle, Style,
    DEFAULT_LINE_COUNT, DEFAULT_LINE_THICKNESS, DEFAULT_MULTIPLE_COLOR,
};
pub use units::{SizeReference, SpeedUnits, StyleUnits};
pub use voronoi::voronoi_f1;
pub use warp::{hise_curve, warp_offset};
pub use weights::{WeightAttribute, WeightGroup, WeightSource};
