//! Dynamic lines of action from sketched keystrokes — Guay, Ronfard, Gleicher, Cani,
//! "Adding dynamics to sketch-based character animations", SBIM 2015, Section 3.
//!
//! * [`Stroke`] / [`Keystrokes`]: screen-space strokes with a frame each, read from JSON
//!   ([`Keystrokes::from_json_str`]) or SVG ([`Keystrokes::from_svg_str`]).
//! * [`fit_chain`] (Eq. 1): a chain of `N` equal rigid elements, root at the arc-length
//!   midpoint, two chains outward, angles by least squares.
//! * [`interpolate_hermite`]: geometric interpolation of angles, lengths and root with Hermite
//!   cubics, then forward kinematics.
//! * [`interpolate_physics`] (Section 3.2, Eq. 2): the line as an elastic articulated chain
//!   ([`ElasticChain`]) shooting for the next keystroke, re-targeted to land on it exactly.
//! * [`wobble()`]: an impulse on a point of the line, left to settle.
//!
//! The crate is pure computation: it never touches files.
//!
//! ```
//! use loa::{line_of_action, Keystrokes, LineOptions, Mode};
//!
//! let keys = Keystrokes::from_json_str(r#"{"keystrokes": [
//!     {"frame": 0,  "points": [[0, 0], [50, -30], [100, 0]]},
//!     {"frame": 24, "points": [[0, 0], [50, 30], [100, 0]], "damping": 0.2}
//! ]}"#)?;
//! let line = line_of_action(&keys, &LineOptions::default())?;
//! assert_eq!(line.animation.frames.len(), 25);
//! // The line lands on the second keystroke exactly.
//! let last = line.animation.chain_at(24).unwrap().joints();
//! let key = line.keys[1].chain.joints();
//! assert!(last.iter().zip(&key).all(|(a, b)| (*a - *b).length() < 1e-9));
//!
//! let hermite = line_of_action(&keys, &LineOptions { mode: Mode::Hermite, ..Default::default() })?;
//! assert!(hermite.retargets.is_empty());
//! # Ok::<(), loa::LoaError>(())
//! ```

pub mod animate;
mod animation;
mod chain;
mod dynamics;
mod error;
mod fit;
mod hermite;
mod keypose;
mod keystroke;
mod linalg;
mod onion;
mod physics;
mod retarget;
mod stroke;
pub mod svg;
mod wobble;

pub use animation::{Animation, AnimationFrame};
pub use chain::Chain;
pub use dynamics::ElasticChain;
pub use error::{LoaError, StrokeError};
pub use fit::{fit_chain, ChainFit, FitResidual, DEFAULT_ELEMENTS};
pub use hermite::{interpolate_hermite, HermiteLine, HermiteTrack};
pub use keypose::{fit_keystrokes, KeyPose};
pub use keystroke::{
    Keystroke, Keystrokes, DEFAULT_DAMPING, DEFAULT_FPS, DEFAULT_STIFFNESS, MAX_FRAME_SPAN,
    MIN_RELATIVE_STROKE_LENGTH,
};
pub use onion::{to_svg_string, DEFAULT_SVG_WIDTH};
pub use physics::{
    interpolate_physics, simulate, PhysicsAnimation, PhysicsOptions, Retarget, SimulatedFrames,
    Simulation, DEFAULT_SIMULATED_FRAMES, DEFAULT_SUBSTEPS, MAX_SIMULATED_STEPS,
};
pub use retarget::{closest_frame, Blend};
pub use stroke::Stroke;
pub use wobble::{wobble, Wobble, MAX_SETTLE_SECONDS, SETTLE_TOLERANCE};

/// Which interpolation between keystrokes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mode {
    /// Physically-based interpolation (Section 3.2).
    #[default]
    Physics,
    /// Geometric Hermite interpolation (end of Section 3.1).
    Hermite,
}

/// Options of [`line_of_action`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineOptions {
    /// Interpolation mode.
    pub mode: Mode,
    /// Rigid elements per chain (even, ≥ 2).
    pub elements: usize,
    /// Physics options; `physics.fps` is also the output's fps in Hermite mode.
    pub physics: PhysicsOptions,
}

impl Default for LineOptions {
    fn default() -> Self {
        Self {
            mode: Mode::default(),
            elements: DEFAULT_ELEMENTS,
            physics: PhysicsOptions::default(),
        }
    }
}

/// A computed dynamic line of action.
#[derive(Debug, Clone, PartialEq)]
pub struct LineOfAction {
    /// The animated line, one chain per frame.
    pub animation: Animation,
    /// The fitted keystrokes (with their Eq. 1 residuals).
    pub keys: Vec<KeyPose>,
    /// Re-targeting per interval (physics mode only; empty for Hermite).
    pub retargets: Vec<Retarget>,
}

/// Fits the keystrokes (Eq. 1) and interpolates them with the chosen mode.
pub fn line_of_action(keys: &Keystrokes, options: &LineOptions) -> Result<LineOfAction, LoaError> {
    let poses = fit_keystrokes(keys, options.elements)?;
    match options.mode {
        Mode::Hermite => {
            keystroke::check_positive("fps", options.physics.fps)?;
            Ok(LineOfAction {
                animation: interpolate_hermite(&poses, options.physics.fps),
                keys: poses,
                retargets: Vec::new(),
            })
        }
        Mode::Physics => {
            let result = interpolate_physics(&poses, &options.physics)?;
            Ok(LineOfAction {
                animation: result.animation,
                keys: poses,
                retargets: result.retargets,
            })
        }
    }
}
