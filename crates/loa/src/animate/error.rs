//! Errors of character motion synthesis. Every variant's documentation says how to fix the
//! input.

use thiserror::Error;

/// Any error of [`animate`](crate::animate::animate).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum AnimateError {
    /// The character has no joints. Use a skinned character or a BVH file.
    #[error("the character has no skeleton (no joints); use a skinned glTF or a BVH file")]
    EmptySkeleton,
    /// The initial pose does not have one transform per joint (an internal mismatch between
    /// the skeleton and the chosen clip); pick another clip or the rest pose.
    #[error("initial pose has {found} joint transforms, the skeleton {expected}")]
    PoseLength {
        /// Joints in the skeleton.
        expected: usize,
        /// Transforms given.
        found: usize,
    },
    /// A joint is listed before its parent. Re-export the skeleton parent-first.
    #[error("joint '{0}' comes before its parent; re-export the skeleton in parent-first order")]
    BadHierarchy(String),
    /// A joint of the initial pose is NaN or infinite. Pick another frame or the rest pose.
    #[error("joint '{0}' has a non-finite transform in the initial pose; pick another frame")]
    NonFinitePose(String),
    /// The bone-set name is not a preset and not a joint list.
    #[error(
        "unknown bone set '{0}'; use right-leg-spine-head, left-leg-spine-head, arm-spine, \
         left-arm-spine, arms, legs, full-body, right-leg-spine-arm, left-leg-spine-arm, \
         foot-head, spine-head, or a comma-separated list of joint names"
    )]
    UnknownPreset(String),
    /// A preset needs a joint the naming heuristics could not find; give the bone set as an
    /// explicit comma-separated joint list instead.
    #[error("no {role} joint found for the preset (joints: {joints}); list the joints explicitly")]
    PresetJoint {
        /// What was looked for.
        role: &'static str,
        /// The skeleton's joint names.
        joints: String,
    },
    /// A joint name is not in the skeleton; the message lists the valid names.
    #[error("no joint named '{name}' (joints: {joints})")]
    UnknownJoint {
        /// The requested name.
        name: String,
        /// The skeleton's joint names.
        joints: String,
    },
    /// A bone set resolves to fewer than two points. Name at least two joints.
    #[error("a bone set needs at least two joints (or a leaf with a tip)")]
    EmptyBoneSet,
    /// A bone set, contact or twist is keyed at a frame outside the line's frames, or a bone
    /// set is not at a keystroke frame. Key it at one of the keystroke frames.
    #[error("{what} keyed at frame {frame}, but {expected}")]
    BadFrame {
        /// What was keyed.
        what: &'static str,
        /// Its frame.
        frame: i64,
        /// What would be accepted.
        expected: String,
    },
    /// The action-plane normal is zero or not finite. Give a non-zero `x,y,z`.
    #[error("action plane normal {},{},{} is zero or not finite; give a non-zero x,y,z", .0[0], .0[1], .0[2])]
    PlaneNormal([f64; 3]),
    /// The line of action has no frame. Provide keystrokes.
    #[error("the line of action has no frames")]
    EmptyLine,
    /// The initial pose is not `rest` or `CLIP@FRAME` of an existing clip and frame.
    #[error("initial pose '{pose}': expected {expected}")]
    BadPose {
        /// The pose as given.
        pose: String,
        /// What would be accepted.
        expected: String,
    },
    /// No camera of that name; the message lists the scene's cameras.
    #[error("no camera named '{name}' (cameras: {cameras})")]
    UnknownCamera {
        /// The requested name.
        name: String,
        /// The scene's camera names.
        cameras: String,
    },
    /// The character's scene could not be sampled or turned into a skeletal animation.
    #[error("the character's scene: {source}")]
    Scene {
        /// The data-model error.
        #[source]
        source: anim::AnimError,
    },
    /// A numeric option is out of range.
    #[error("invalid {name} = {}: {expected}", anim::human_number(*.value))]
    InvalidParameter {
        /// Option name.
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// What would be accepted.
        expected: &'static str,
    },
    /// The space-time solve would be over its budget ([`anim::budget`]): fewer keystrokes or
    /// fewer bones in the bone sets.
    #[error(transparent)]
    OverBudget(#[from] anim::OverBudget),
}
