//! Errors of the segmentation and homogenization stage.

use thiserror::Error;

/// Why a segmentation or homogenization could not be computed.
///
/// Every variant's documentation says how to fix the input.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SegmentError {
    /// The animation has no triangle. Export the mesh with its faces (not as a point cloud).
    #[error("the mesh has no triangles")]
    NoTriangles,
    /// Fewer than two parts were requested. Give at least two parts, each with a seed.
    #[error("at least 2 parts are needed, got {0}")]
    TooFewParts(usize),
    /// A part has no seed. Give every part at least one seed triangle or point.
    #[error("part '{0}' has no seed")]
    EmptyPart(String),
    /// A seed triangle id is out of range. Triangle ids run from 0 to `triangles - 1`
    /// (`toonkit info` prints the count).
    #[error("seed triangle {index} of part '{part}' is out of range (mesh has {triangles})")]
    SeedOutOfRange {
        /// Part name.
        part: String,
        /// Offending triangle id.
        index: u32,
        /// Triangle count.
        triangles: usize,
    },
    /// A seed point is NaN or infinite. Give finite coordinates.
    #[error("seed point of part '{0}' is not finite")]
    NonFiniteSeed(String),
    /// The same triangle is a seed of two parts. Move one of the seeds.
    #[error("triangle {triangle} is a seed of both '{first}' and '{second}'")]
    ConflictingSeeds {
        /// Triangle id.
        triangle: u32,
        /// First part.
        first: String,
        /// Second part.
        second: String,
    },
    /// A triangle label is not a valid part index. Labels must lie in `0..parts`.
    #[error("triangle {triangle} has part {part}, but there are only {parts} parts")]
    BadLabel {
        /// Triangle id.
        triangle: usize,
        /// Its label.
        part: u32,
        /// Number of parts.
        parts: usize,
    },
    /// A per-triangle array has the wrong length. Pass one entry per triangle.
    #[error("expected {expected} per-triangle labels, found {found}")]
    LabelCount {
        /// Triangle count.
        expected: usize,
        /// Given length.
        found: usize,
    },
    /// The animation data is invalid (bad indices, non-finite positions). Re-export the file.
    #[error("invalid animation: {0}")]
    Invalid(String),
    /// A parameter is out of range (the message says which). Use the documented range.
    #[error("invalid parameter: {0}")]
    Parameter(String),
    /// The sparse solver failed (out of memory, or a numerically singular system on a
    /// degenerate mesh). Remove zero-area triangles or weld duplicate vertices.
    #[error("sparse solver failed: {0}")]
    Solver(String),
}

/// Result alias of this module.
pub type Result<T, E = SegmentError> = std::result::Result<T, E>;
