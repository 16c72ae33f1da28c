//! Options of the motion-offset computation and the crate's named tolerances.

use serde::{Deserialize, Serialize};

/// Default temporal smoothing half-window `N` of SMEAR Eq. 2 (the paper's "N = 2 in practice").
pub const DEFAULT_SMOOTH: usize = 2;

/// A velocity shorter than this fraction of the bounding-box diagonal counts as "still"
/// (SPEC.md): a still object gets offsets 0, a still joint takes its bone's other joint's
/// direction.
pub const DEFAULT_STILL_TOLERANCE: f32 = 1e-9;

/// Velocities below this multiple of the largest absolute coordinate (f32 rounding of the
/// positions) are still too, whatever [`DEFAULT_STILL_TOLERANCE`] says: an object followed by
/// the camera moves by rounding noise only, which must not pick a random separation plane.
pub const STILL_ROUNDING_FACTOR: f32 = 16.0 * f32::EPSILON;

/// Below this angle (radians) between root and tip directions, SMEAR Eq. 4's slerp falls back to a
/// renormalized linear interpolation (paper Section 3.2).
pub const DEFAULT_LERP_ANGLE: f32 = 0.1;

/// Bones shorter than this fraction of the bounding-box diagonal are zero-length and skipped.
pub const DEFAULT_ZERO_LENGTH: f32 = 1e-6;

/// Which scene camera to compute offsets relative to.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum CameraSelect {
    /// Index into `SampledScene::cameras`.
    Index(usize),
    /// Camera (node) name.
    Name(String),
}

/// How to compute motion offsets (missing fields take their defaults when deserialized).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default)]
pub struct OffsetOptions {
    /// Temporal smoothing half-window `N` of SMEAR Eq. 2; 0 turns smoothing off.
    pub smooth: usize,
    /// Treat every skinned character (its skinned meshes and the rigid props parented to its
    /// joints) as one simple object with a single separation plane (paper Fig. 14).
    pub whole_body: bool,
    /// Joints toggled off (paper Fig. 8d): their vertices follow the nearest kept ancestor.
    pub prune: Vec<String>,
    /// Compute offsets relative to this (possibly moving) camera instead of the world.
    pub camera: Option<CameraSelect>,
    /// Apply the collinear weight w_coll of SMEAR Eqs. 6/8 (paper Fig. 7); turning it off shows the
    /// shearing it prevents.
    pub collinear_weight: bool,
    /// Past-only mode (issue #22): velocities by backward differences, SMEAR Eq. 2 smoothing
    /// over past frames only, and trajectories that extrapolate instead of reading later
    /// frames — frame f's result uses frames ≤ f only (real-time previews, games).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub causal: bool,
    /// Objects (mesh names) that revolve about an axis (a wheel, a propeller): their offsets
    /// and trajectories follow arcs about the fitted axis instead of SMEAR Eq. 1's plane
    /// (issue #22; the paper's Fig. 19 limitation). `"auto"` detects them.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub revolve: Vec<String>,
}

impl Default for OffsetOptions {
    fn default() -> Self {
        OffsetOptions {
            smooth: DEFAULT_SMOOTH,
            whole_body: false,
            prune: Vec::new(),
            camera: None,
            collinear_weight: true,
            causal: false,
            revolve: Vec::new(),
        }
    }
}

impl OffsetOptions {
    /// Checks the sizes the options ask for against their budgets before anything is
    /// allocated: the smoothing window's weights ([`anim::budget::DEFAULT_MAX_SMOOTH`]).
    ///
    /// # Errors
    /// [`anim::OverBudget`] naming `--smooth`.
    pub fn check_budget(&self) -> Result<(), anim::OverBudget> {
        check_smooth(self.smooth)
    }
}

/// `--smooth N` against [`anim::budget::DEFAULT_MAX_SMOOTH`].
pub(crate) fn check_smooth(smooth: usize) -> Result<(), anim::OverBudget> {
    anim::check_budget(
        "--smooth",
        smooth as u64,
        anim::budget::DEFAULT_MAX_SMOOTH,
        "a window wider than the clip only repeats its end frames (N = 2 is the paper's)",
    )
}
