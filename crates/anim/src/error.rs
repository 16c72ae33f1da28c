use thiserror::Error;

/// Errors raised while building or evaluating animation data.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum AnimError {
    /// A buffer length does not match the topology. Re-export the data; the vertex count
    /// must be the same in every frame.
    #[error("{what}: expected {expected} values, found {found}")]
    LengthMismatch {
        /// What was being checked.
        what: String,
        /// Expected count.
        expected: usize,
        /// Found count.
        found: usize,
    },
    /// A triangle refers to a vertex that does not exist. The file's index buffer is corrupt.
    #[error(
        "triangle {triangle} refers to vertex {index}, but there are only {vertices} vertices"
    )]
    IndexOutOfRange {
        /// Triangle number.
        triangle: usize,
        /// Offending index.
        index: u32,
        /// Vertex count.
        vertices: usize,
    },
    /// A position, time or weight is NaN or infinite. Clean the source file.
    #[error("{what} contains a non-finite value (NaN or infinity)")]
    NonFinite {
        /// Which data.
        what: String,
    },
    /// A named clip, mesh, node or joint was not found. `toonkit info FILE` lists the names.
    #[error("no {kind} named '{name}' (available: {available})")]
    NotFound {
        /// What kind of thing (clip, mesh, node, joint).
        kind: &'static str,
        /// The requested name.
        name: String,
        /// Comma separated list of what exists.
        available: String,
    },
    /// The data is not usable for the requested operation.
    #[error("{0}")]
    Invalid(String),
    /// A size derived from the input (frames sampled from a clip, frames × vertices) is over
    /// its budget ([`crate::budget`]). Lower the frame rate or pick a shorter clip.
    #[error(transparent)]
    OverBudget(#[from] crate::OverBudget),
}

/// Result alias for this crate.
pub type Result<T, E = AnimError> = std::result::Result<T, E>;
