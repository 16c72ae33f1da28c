//! Errors of the smear crate. Every variant's documentation says how to fix the input.

use thiserror::Error;

use crate::StyleError;

/// Any error of the `smear` crate.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SmearError {
    /// A bone named in [`OffsetOptions::prune`](crate::OffsetOptions::prune) or in a weight
    /// group is not a joint of the skeleton. Use one of the listed joint names (they are
    /// case-sensitive).
    #[error("no joint named '{name}'; joints are: {available}")]
    UnknownJoint {
        /// The name that was asked for.
        name: String,
        /// Comma-separated joint names.
        available: String,
    },
    /// A pruned joint has skinned vertices but no kept ancestor to take them over (it is a
    /// root, or all its ancestors are pruned too). Keep the root, or prune only descendants.
    #[error(
        "joint '{name}' is pruned but has no kept ancestor to drive its vertices; \
         keep it or one of its ancestors"
    )]
    PruneWithoutAncestor {
        /// Name of the pruned joint.
        name: String,
    },
    /// The vertex attribute holding painted weights is not on the mesh. Export it as a scalar
    /// glTF attribute whose name starts with `_` (e.g. `_SMEAR_WEIGHT`), or use one of the
    /// listed names.
    #[error("no vertex attribute '{name}'; the mesh has: {available}")]
    UnknownAttribute {
        /// The name that was asked for.
        name: String,
        /// Comma-separated attribute names.
        available: String,
    },
    /// The camera asked for is not in the scene. Use one of the listed camera names or an
    /// index below the number of cameras.
    #[error("no camera '{name}'; cameras are: {available}")]
    UnknownCamera {
        /// The name or index that was asked for.
        name: String,
        /// Comma-separated camera names (empty when the input has none).
        available: String,
    },
    /// An object named as a collider is not in the scene. Use one of the listed object names
    /// (case-sensitive).
    #[error("no object named '{name}' to use as a collider; objects are: {available}")]
    UnknownCollider {
        /// The name that was asked for.
        name: String,
        /// Comma-separated object names.
        available: String,
    },
    /// A style's `size_reference` (or `--size-reference`) names an object the scene does not
    /// have. Use one of the listed object names (case-sensitive), or give a length.
    #[error("no object named '{name}' to measure the size by; objects are: {available}")]
    UnknownSizeReference {
        /// The name that was asked for.
        name: String,
        /// Comma-separated object names.
        available: String,
    },
    /// A scene given as colliders has no mesh. Give a file with at least one mesh.
    #[error("the collider scene has no mesh")]
    NoColliderMesh,
    /// An object index is out of range. Use an index below the number of objects.
    #[error("object {index} does not exist; there are {count} objects")]
    UnknownObject {
        /// The index asked for.
        index: usize,
        /// Number of objects.
        count: usize,
    },
    /// A surface point refers to a missing triangle or has non-finite or all-zero barycentric
    /// coordinates. Sample points on existing triangles with finite, non-negative weights.
    #[error("surface point {index}: {reason}")]
    InvalidSurfacePoint {
        /// Index of the point in the input list.
        index: usize,
        /// What is wrong.
        reason: String,
    },
    /// Two offset fields to combine have different frame counts. Combine offsets of one clip.
    #[error("offsets have {found} frames, expected {expected}")]
    FrameMismatch {
        /// Frames of the first field.
        expected: usize,
        /// Frames of the offending field.
        found: usize,
    },
    /// A value buffer's length is not `frames × vertices`. Pass a buffer of that length.
    #[error("offset buffer has {found} values, expected {expected}")]
    LengthMismatch {
        /// `frames × vertices`.
        expected: usize,
        /// Actual length.
        found: usize,
    },
    /// An effect parameter is out of its range (a count, spacing, step or per-vertex buffer).
    /// Pass a value in the range the message names.
    #[error("invalid {name}: {reason}")]
    InvalidParameter {
        /// The parameter's name.
        name: &'static str,
        /// What is wrong and what is allowed.
        reason: String,
    },
    /// The sampled scene is inconsistent (skin slots, bone buffer). Re-sample it with
    /// `anim::sample`, which always produces consistent scenes.
    #[error("inconsistent scene: {0}")]
    InvalidScene(String),
    /// A style's function or parameter is invalid (see [`StyleError`] for how to fix it).
    #[error(transparent)]
    Style(#[from] StyleError),
    /// An option asks for more than its budget ([`anim::budget`]): lower it.
    #[error(transparent)]
    OverBudget(#[from] anim::OverBudget),
}

/// Result alias of the smear crate.
pub type Result<T, E = SmearError> = std::result::Result<T, E>;
