//! 3D character motion that follows the dynamic line of action (Section 4 and 4.1).
//!
//! * [`Character`]: a skeleton (from a skinned glTF or a BVH) with an initial pose.
//! * [`ActionCamera`] / [`ActionPlane`] / [`ScreenMap`]: the view `P` the line is drawn
//!   through (default: orthographic front view fitted to the character), the plane the motion
//!   happens in (default normal: the view direction), and where the keystrokes' screen
//!   coordinates land on the image plane (default: one scale fitted so that every keystroke's
//!   length matches its bone set's length, the first keystroke's arc-length midpoint on its
//!   chain's midpoint).
//! * [`BoneSet`] / [`Preset`]: at each keystroke, an ordered chain of bones mapped onto the
//!   line by arc length; between keystrokes the common subset Ω(t) = Ω(t_k) ∩ Ω(t_k+1) is
//!   constrained (its arc-length positions blend linearly), the rest follows smoothly.
//! * [`animate`]: space-time matching over the whole clip — E_ẋ (LoA Eq. 3) + w_x E_x + w_∂ E_∂ —
//!   with per-bone angles about the plane normal and the root moving in the plane, on
//!   Hermite-reduced degrees of freedom (2N − 1 nodes), by Levenberg–Marquardt with analytic
//!   Jacobians; then, when twists or contacts are given, a second stage with full 3D bone
//!   orientations adds E_twist and E_⊥ (Section 4.1).
//!
//! Only rotations change (plus the root's translation), so bone lengths never change.
//!
//! ```
//! use anim::{Joint, Skeleton, Transform};
//! use glam::Vec3;
//! use loa::animate::{animate, AnimateOptions, BoneSetKey, Character};
//! use loa::{Keystrokes, LineOptions, Mode};
//!
//! // A 4-joint "spine" standing up along +Y.
//! let joint = |name: &str, parent, y| Joint {
//!     name: name.into(),
//!     parent,
//!     bind_local: Transform::from_translation(Vec3::new(0.0, y, 0.0)),
//! };
//! let skeleton = Skeleton { joints: vec![
//!     joint("hips", None, 0.0), joint("spine", Some(0), 1.0),
//!     joint("chest", Some(1), 1.0), joint("head", Some(2), 1.0),
//! ] };
//! let character = Character::rest(&skeleton)?;
//! // A bent line (screen y points down), held for 12 frames.
//! let keys = Keystrokes::from_json_str(r#"{"keystrokes": [
//!     {"frame": 0, "points": [[0, 0], [30, -40], [40, -90], [30, -140]]},
//!     {"frame": 12, "points": [[0, 0], [30, -40], [40, -90], [30, -140]]}]}"#)?;
//! let line = loa::line(&keys, &LineOptions { mode: Mode::Hermite, ..Default::default() })?;
//! let sets = [BoneSetKey { frame: 0, set: "hips,head".parse()? }];
//! let motion = animate(&character, &line.animation, &sets, &[], &[], &AnimateOptions::default())?;
//! assert_eq!(motion.frames(), 13 + 12); // and the default settle: one key interval
//! assert!(motion.report.line_distance_mean < 0.05); // within 5 % of the line's length
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod bones;
mod camera;
mod contacts;
mod error;
mod keys;
mod reduction;
mod release;
mod rig;
mod scene;
mod solver;
mod synthesis;
mod targets;
mod terms;

pub use bones::{BoneSet, Preset};
pub use camera::{ActionCamera, ActionPlane, ScreenMap, DEFAULT_CAMERA_MARGIN};
pub use error::AnimateError;
pub use keys::{BoneSetKey, ContactKey, TwistKey};
pub use reduction::Reduction;
pub use release::{CONTACT_RELEASE_MAX_TURN, MAX_CONTACT_RELEASE};
pub use rig::ATTACH_TOLERANCE;
pub use scene::{InitialPose, CLIP_NAME};
pub use solver::{StageReport, DEFAULT_INITIAL_DAMPING, DEFAULT_TOLERANCE, STAGING_TOLERANCE};

use anim::{Skeleton, Transform};
use glam::{DQuat, DVec2, DVec3, Mat4};

use crate::Animation;
use rig::Rig;

/// Default weight of E_x (projected positions on the line; distances relative to the longest
/// bone set's length).
pub const DEFAULT_POSITION_WEIGHT: f64 = 1.0;
/// Default weight of E_∂ (projected bone directions along the line's tangent). E_x is
/// measured in fractions of the line's length and E_∂ in radians (roughly): a bone a fraction
/// `ℓ` of the line long turned by `θ` moves its end by `ℓ θ`, so the two terms weigh alike
/// at `w_∂ ≈ ℓ²`; 0.05 is a bone of about a fifth of the line. Heavier tangents keep bones
/// parallel to the line at the cost of their positions (at 0.5, RobotExpressive's legs hung
/// 12 % of the line beside it).
pub const DEFAULT_TANGENT_WEIGHT: f64 = 0.05;
/// Default weight of LoA Eq. 3's rotation term for constrained bones (radians per frame).
pub const DEFAULT_SMOOTHNESS_WEIGHT: f64 = 1.0;
/// Fraction of the smoothness weight applied to unconstrained degrees of freedom, so that
/// bones leaving Ω(t) keep moving smoothly instead of being free.
pub const DEFAULT_FREE_SMOOTHNESS: f64 = 0.2;
/// Default weight of LoA Eq. 3's root velocity term (relative to the longest bone set's length).
pub const DEFAULT_ROOT_VELOCITY_WEIGHT: f64 = 0.2;
/// Default weight of contact positions (relative to body height).
pub const DEFAULT_CONTACT_POSITION_WEIGHT: f64 = 1e4;
/// Default weight of contact orientations (radians).
pub const DEFAULT_CONTACT_ORIENTATION_WEIGHT: f64 = 1.0;
/// Default weight of twist targets (radians).
pub const DEFAULT_TWIST_WEIGHT: f64 = 1.0;
/// Default weight pulling the accumulated increments toward the initial pose (keeps
/// redundant joints well-posed).
pub const DEFAULT_REGULARIZATION: f64 = 1e-2;
/// Default pull of the 3D stage (Section 4.1) toward the planar solution it starts from: the
/// 3D stage refines the planar motion for contacts and twists, so it bends the limbs they
/// concern instead of re-staging the whole body in depth, which the view cannot show.
pub const DEFAULT_SPATIAL_REGULARIZATION: f64 = 1e-2;
/// Default cap on accepted Levenberg–Marquardt iterations per stage: a safety net; the
/// solver stops earlier, when an accepted step lowers the energy by less than
/// [`DEFAULT_TOLERANCE`].
pub const DEFAULT_MAX_ITERATIONS: usize = 200;
/// Fewest frames over which the motion blends into a contact before its first key and out of
/// it after its last (in rotation space, along a smoothstep; see [`MAX_CONTACT_RELEASE`]).
pub const DEFAULT_CONTACT_RELEASE: usize = 6;

/// Weights of the energy terms.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Weights {
    /// `w_x` of E_x.
    pub position: f64,
    /// `w_∂` of E_∂.
    pub tangent: f64,
    /// LoA Eq. 3 rotation term, constrained bones.
    pub smoothness: f64,
    /// Factor on `smoothness` for unconstrained degrees of freedom.
    pub free_smoothness: f64,
    /// LoA Eq. 3 root velocity term.
    pub root_velocity: f64,
    /// `w_x` of E_⊥ (contact positions).
    pub contact_position: f64,
    /// `w_q` of E_⊥ (contact orientations).
    pub contact_orientation: f64,
    /// E_twist.
    pub twist: f64,
    /// Pull toward the initial pose.
    pub regularization: f64,
    /// Pull of the 3D stage's increments toward the planar solution.
    pub spatial_regularization: f64,
}

impl Default for Weights {
    fn default() -> Self {
        Weights {
            position: DEFAULT_POSITION_WEIGHT,
            tangent: DEFAULT_TANGENT_WEIGHT,
            smoothness: DEFAULT_SMOOTHNESS_WEIGHT,
            free_smoothness: DEFAULT_FREE_SMOOTHNESS,
            root_velocity: DEFAULT_ROOT_VELOCITY_WEIGHT,
            contact_position: DEFAULT_CONTACT_POSITION_WEIGHT,
            contact_orientation: DEFAULT_CONTACT_ORIENTATION_WEIGHT,
            twist: DEFAULT_TWIST_WEIGHT,
            regularization: DEFAULT_REGULARIZATION,
            spatial_regularization: DEFAULT_SPATIAL_REGULARIZATION,
        }
    }
}

/// Options of [`crate::animate()`] (and [`animate()`]): keyed inputs, view and solver settings.
/// Serde-ready, so the same options come from CLI flags, a TOML/JSON file or Python keyword
/// arguments; bone sets are written as on the command line (`"arms"`, `"FootR,Head"`).
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AnimateOptions {
    /// Ω(t_k) per keystroke frame; a keystroke without one keeps the previous keystroke's
    /// set; the first defaults to [`Preset::RightLegSpineHead`].
    pub bone_sets: Vec<BoneSetKey>,
    /// Contact keys (Section 4.1, E_⊥); any contact or twist adds the 3D stage.
    pub contacts: Vec<ContactKey>,
    /// Twist keys (Section 4.1, E_twist).
    pub twists: Vec<TwistKey>,
    /// Camera; default [`ActionCamera::front_fitted`] to the initial pose.
    pub camera: Option<ActionCamera>,
    /// Action-plane normal; default the camera's viewing direction.
    pub plane_normal: Option<DVec3>,
    /// Screen → image map; default fitted (see the module docs).
    pub screen: Option<ScreenMap>,
    /// Energy weights.
    pub weights: Weights,
    /// Cap on accepted iterations per stage (0 = [`DEFAULT_MAX_ITERATIONS`]).
    pub max_iterations: usize,
    /// Keep the turn joints (pelvis, chest: where a bone set's path turns from climbing the
    /// tree to descending it) and their ancestors at their initial orientation in the planar
    /// stage, instead of freeing them after a first solve with them held (the default; see
    /// the crate docs' SPEC decisions).
    pub hold_pelvis: bool,
}

/// A character: skeleton plus initial pose.
#[derive(Debug, Clone)]
pub struct Character {
    rig: Rig,
}

impl Character {
    /// A character in the pose given by local transforms (one per joint, relative to the
    /// skeleton parent).
    pub fn new(skeleton: &Skeleton, pose: &[Transform]) -> Result<Character, AnimateError> {
        Ok(Character {
            rig: Rig::new(skeleton, pose)?,
        })
    }

    /// [`Character::new`] with explicit leaf bone axes (local directions; see
    /// [`Character::from_scene`]).
    fn with_axes(
        skeleton: &Skeleton,
        pose: &[Transform],
        axes: Vec<Option<DVec3>>,
    ) -> Result<Character, AnimateError> {
        Ok(Character {
            rig: Rig::with_axes(skeleton, pose, axes)?,
        })
    }

    /// A character in its rest (bind) pose.
    pub fn rest(skeleton: &Skeleton) -> Result<Character, AnimateError> {
        let pose: Vec<Transform> = skeleton.joints.iter().map(|j| j.bind_local).collect();
        Self::new(skeleton, &pose)
    }

    /// A character in the pose given by world matrices (e.g. a sampled clip frame).
    pub fn from_world(skeleton: &Skeleton, world: &[Mat4]) -> Result<Character, AnimateError> {
        Self::new(skeleton, &local_pose(skeleton, world)?)
    }

    /// Joint names.
    pub fn joint_names(&self) -> &[String] {
        &self.rig.names
    }

    /// Skeleton parent of every joint.
    pub fn parents(&self) -> &[Option<usize>] {
        &self.rig.skeleton_parent
    }

    /// Joints re-parented for solving: `(joint, leaf it is attached to)`.
    pub fn attachments(&self) -> Vec<(usize, usize)> {
        (0..self.rig.len())
            .filter_map(
                |j| match (self.rig.parent[j], self.rig.skeleton_parent[j]) {
                    (Some(p), q) if Some(p) != q => Some((j, p)),
                    _ => None,
                },
            )
            .collect()
    }

    /// World joint positions of the initial pose.
    pub fn initial_positions(&self) -> Vec<DVec3> {
        self.rig.world(&self.rig.rotation, DVec3::ZERO).position
    }

    /// Body height: extent of the initial pose's joints and bone tips along +Y (at least
    /// 1e-9).
    pub fn height(&self) -> f64 {
        let (min, max) = self.bounds();
        (max.y - min.y).max(1e-9)
    }

    /// Bounding box of the initial pose's joints and bone tips.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let w = self.rig.world(&self.rig.rotation, DVec3::ZERO);
        let mut min = DVec3::splat(f64::INFINITY);
        let mut max = DVec3::splat(f64::NEG_INFINITY);
        for j in 0..self.rig.len() {
            for p in [w.position[j], w.tip(&self.rig, j)] {
                min = min.min(p);
                max = max.max(p);
            }
        }
        (min, max)
    }

    /// Resolves a bone set to its chain of joint indices (kinematic path through the
    /// waypoints).
    pub fn bone_chain(&self, set: &BoneSet) -> Result<Vec<usize>, AnimateError> {
        Ok(bones::resolve(&self.rig, set)?.joints)
    }
}

/// Local transforms (relative to the skeleton parent) of a pose given by world matrices.
fn local_pose(skeleton: &Skeleton, world: &[Mat4]) -> Result<Vec<Transform>, AnimateError> {
    if world.len() != skeleton.len() {
        return Err(AnimateError::PoseLength {
            expected: skeleton.len(),
            found: world.len(),
        });
    }
    Ok(skeleton
        .local_from_world(world)
        .into_iter()
        .map(Transform::from_matrix)
        .collect())
}

/// Measurements of a synthesized motion.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AnimateReport {
    /// Planar stage (Section 4).
    pub planar: StageReport,
    /// 3D stage (Section 4.1), when twists or contacts were given.
    pub spatial: Option<StageReport>,
    /// Mean 2D distance between the character and the line: over every constrained chain
    /// point ([`measured_joints`](Self::measured_joints)) of every frame that has one, each
    /// as a fraction of the line's length at its frame. Frames without constrained points
    /// ([`unmeasured_frames`](Self::unmeasured_frames)) cannot be measured and are listed
    /// instead of counted.
    pub line_distance_mean: f64,
    /// 95th percentile of the same distances (nearest rank).
    pub line_distance_p95: f64,
    /// The single point farthest from the line, over every frame.
    pub line_distance_worst: WorstPoint,
    /// Names of the measured points' joints (a leaf's tip is `NAME (tip)`), in joint order:
    /// every point of the bone sets' chains except the lower end of a branch connector —
    /// where a chain turns from going up the skeleton to going down (the pelvis on a foot-to-
    /// head chain), the joint below the turn (RobotExpressive's `UpperLegR`, the hip beside
    /// the pelvis) hangs off the line by the pelvis's width and is neither constrained nor
    /// measured.
    pub measured_joints: Vec<String>,
    /// Frames with no constrained point (no bone set in force there), left out of the
    /// distance figures.
    pub unmeasured_frames: Vec<i64>,
    /// Largest rotation (radians) of any joint's local orientation between consecutive
    /// frames.
    pub max_rotation_step: f64,
    /// Largest contact position error, as a fraction of the body height (0 without
    /// contacts).
    pub contact_error_max: f64,
    /// Body height used for contacts.
    pub height: f64,
}

/// The point of the character farthest from the line ([`AnimateReport::line_distance_worst`]).
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct WorstPoint {
    /// Its distance to the line, as a fraction of the line's length at that frame.
    pub distance: f64,
    /// The joint (`NAME (tip)` for the end of a leaf bone).
    pub joint: String,
    /// The frame.
    pub frame: i64,
}

/// A synthesized motion: world transforms of every joint per frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// Frames per second (the line's).
    pub fps: f64,
    /// Frame number of the first frame (the first keystroke).
    pub first_frame: i64,
    /// Joints per frame.
    pub joints: usize,
    /// World positions, frames × joints.
    pub positions: Vec<DVec3>,
    /// World rotations (scale removed), frames × joints.
    pub rotations: Vec<DQuat>,
    /// World scales, frames × joints.
    pub scales: Vec<DVec3>,
    /// The camera used.
    pub camera: ActionCamera,
    /// The action plane used.
    pub plane: ActionPlane,
    /// The screen → image map used.
    pub screen: ScreenMap,
    /// The line in image coordinates, per frame.
    pub line: Vec<Vec<DVec2>>,
    /// Constrained chain joints per frame (joint indices; the tips' joints are included).
    pub constrained: Vec<Vec<usize>>,
    /// Measurements.
    pub report: AnimateReport,
}

impl Motion {
    /// Number of frames.
    pub fn frames(&self) -> usize {
        self.positions.len().checked_div(self.joints).unwrap_or(0)
    }

    /// World positions of frame `f`.
    pub fn positions_at(&self, f: usize) -> &[DVec3] {
        &self.positions[f * self.joints..(f + 1) * self.joints]
    }

    /// World matrices (single precision, frames × joints) in the skeleton's joint order, ready
    /// for `anim::SkeletalAnimation::new`.
    pub fn world_matrices(&self) -> Vec<Mat4> {
        self.positions
            .iter()
            .zip(&self.rotations)
            .zip(&self.scales)
            .map(|((p, q), s)| {
                Mat4::from_scale_rotation_translation(s.as_vec3(), q.as_quat(), p.as_vec3())
            })
            .collect()
    }

    /// The line of frame `f` as world points on the camera's focal plane.
    pub fn line_world(&self, f: usize) -> Vec<DVec3> {
        self.line
            .get(f)
            .map(|l| l.iter().map(|&p| self.camera.unproject(p)).collect())
            .unwrap_or_default()
    }
}

/// Synthesizes the character motion following `line` (Sections 4 and 4.1).
///
/// # Arguments
/// * `character` – skeleton and initial pose (every frame starts from it).
/// * `line` – the dynamic line of action (e.g. [`crate::line()`]'s animation); one frame per
///   output frame, keystrokes at `line.keystroke_frames`.
/// * `bone_sets`, `contacts`, `twists` – keyed inputs in addition to those in `options` (see
///   [`AnimateOptions::bone_sets`], [`ContactKey`], [`TwistKey`]); when any contact or twist
///   is given a second, 3D stage runs.
///
/// # Errors
/// Unknown joints or presets, keys outside the line's frames, a zero plane normal.
///
/// # Performance
/// Linear in frames × constrained joints per iteration; a 120-frame, 5-keystroke,
/// 43-joint clip takes a few milliseconds per iteration on two cores.
pub fn animate(
    character: &Character,
    line: &Animation,
    bone_sets: &[BoneSetKey],
    contacts: &[ContactKey],
    twists: &[TwistKey],
    options: &AnimateOptions,
) -> Result<Motion, AnimateError> {
    let bone_sets = [options.bone_sets.as_slice(), bone_sets].concat();
    let contacts = [options.contacts.as_slice(), contacts].concat();
    let twists = [options.twists.as_slice(), twists].concat();
    synthesis::run(character, line, &bone_sets, &contacts, &twists, options)
}
