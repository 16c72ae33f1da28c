//! Errors of the replacement-library optimization and fabrication.

use thiserror::Error;

/// Why a library could not be computed; every variant says how to fix the input.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LibraryError {
    /// No part was given. Pass at least one part animation (a whole, unsegmented mesh is one
    /// part).
    #[error("no part to build a library for: pass at least one part animation")]
    NoParts,
    /// A part has no vertex. Remove the empty part or fix the segmentation that produced it.
    #[error("part '{part}' has no vertex: remove it or fix the segmentation")]
    EmptyPart {
        /// Name of the part.
        part: String,
    },
    /// Parts have different frame counts. Sample every part from the same clip range.
    #[error("part '{part}' has {found} frames but the first part has {expected}: sample all parts over the same frames")]
    FrameCountMismatch {
        /// Name of the part.
        part: String,
        /// Frame count of the first part.
        expected: usize,
        /// Frame count of this part.
        found: usize,
    },
    /// A library of zero pieces was asked for. Ask for at least one piece per part.
    #[error("a library needs at least one piece per part")]
    ZeroPieces,
    /// More free pieces than frames were asked for. Ask for at most as many pieces as frames.
    #[error("part '{part}': {pieces} free pieces for {frames} frames; ask for at most {frames}")]
    TooManyPieces {
        /// Name of the part.
        part: String,
        /// Free pieces asked for.
        pieces: usize,
        /// Frames available.
        frames: usize,
    },
    /// A piece budget smaller than the number of parts (or than the fixed pieces). Raise the
    /// budget to at least one free piece per part.
    #[error("budget of {budget} pieces is below the minimum of {minimum} (one per part plus fixed pieces)")]
    BudgetTooSmall {
        /// Requested budget.
        budget: usize,
        /// Smallest feasible budget.
        minimum: usize,
    },
    /// A printed back surface (`pieces/<part>_back.obj` of an earlier run) does not fit its
    /// part. Give the back printed for this part of this mesh and segmentation.
    #[error("part '{part}': {reason}")]
    PrintedBack {
        /// Name of the part.
        part: String,
        /// What is wrong.
        reason: String,
    },
    /// A solid could not be regularized (`regularize`): it is not
    /// closed and orientable, has a non-finite coordinate or encloses no material. Build it
    /// closed and outward oriented (every piece toonkit writes is).
    #[error("solid '{mesh}' cannot be regularized: {reason}")]
    Regularization {
        /// Name of the mesh.
        mesh: String,
        /// What is wrong.
        reason: String,
    },
    /// A parameter is out of range (negative or non-finite λ, zero restarts, non-positive print
    /// height or thickness, …). The message names the parameter and its valid range.
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
    /// Saliency weights do not match the part. Give one finite, non-negative weight per vertex,
    /// not all zero.
    #[error("part '{part}': saliency weights invalid ({reason}); give one finite weight >= 0 per vertex, not all zero")]
    BadSaliency {
        /// Name of the part.
        part: String,
        /// What is wrong.
        reason: String,
    },
    /// A fixed (pre-defined) piece does not match the part. Give fixed pieces with the part's
    /// vertex count and finite positions.
    #[error("part '{part}': fixed piece {piece} invalid ({reason}); it must have the part's vertex count and finite positions")]
    BadFixedPiece {
        /// Name of the part.
        part: String,
        /// Index of the fixed piece.
        piece: usize,
        /// What is wrong.
        reason: String,
    },
    /// A cut index lies outside the animation. Give cut frames in `0..frames`.
    #[error("cut at frame {cut} is outside the animation of {frames} frames")]
    BadCut {
        /// The offending cut.
        cut: usize,
        /// Frame count.
        frames: usize,
    },
    /// The surface to fabricate is unusable (no triangle, bad index, an edge shared by more
    /// than two triangles). Repair the mesh (make it an edge-manifold surface) first.
    #[error("cannot fabricate '{mesh}': {reason}; repair it into an edge-manifold surface")]
    BadSurface {
        /// Mesh name.
        mesh: String,
        /// What is wrong.
        reason: String,
    },
    /// A linear algebra step failed (should not happen for valid input; please report it).
    #[error("numerical failure in {0}; please report this input")]
    Numerical(String),
}

/// Result alias of this module.
pub type Result<T> = std::result::Result<T, LibraryError>;
