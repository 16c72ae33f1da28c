//! The render error type.

use thiserror::Error;

/// Everything that can go wrong while rendering or encoding a preview.
#[derive(Debug, Error)]
pub enum RenderError {
    /// The image size is zero or too large. Fix: ask for a size between 1×1 and
    /// [`MAX_IMAGE_SIZE`](crate::MAX_IMAGE_SIZE) on each side.
    #[error("invalid image size {width}x{height} (each side must be 1..={max})")]
    InvalidSize {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
        /// Largest allowed side.
        max: u32,
    },
    /// A triangle refers to a vertex that does not exist. Fix: validate the mesh
    /// (`Mesh::validate`) before drawing it.
    #[error("mesh '{mesh}': triangle {triangle} uses vertex {index} but there are {vertices}")]
    IndexOutOfRange {
        /// Mesh label.
        mesh: String,
        /// Triangle index.
        triangle: usize,
        /// Offending vertex index.
        index: u32,
        /// Number of vertices.
        vertices: usize,
    },
    /// A per-vertex or per-triangle attribute has the wrong length. Fix: give one value per
    /// vertex (or per triangle for per-triangle colours).
    #[error("mesh '{mesh}': {what} has {found} entries, expected {expected}")]
    AttributeLength {
        /// Mesh label.
        mesh: String,
        /// Which attribute.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Actual length.
        found: usize,
    },
    /// Images given together (GIF frames, comparisons) differ in size. Fix: render every frame
    /// with the same renderer size.
    #[error("image {index} is {found_w}x{found_h}, expected {width}x{height}")]
    SizeMismatch {
        /// Index of the offending image.
        index: usize,
        /// Expected width.
        width: u32,
        /// Expected height.
        height: u32,
        /// Actual width.
        found_w: u32,
        /// Actual height.
        found_h: u32,
    },
    /// Nothing to encode. Fix: pass at least one frame.
    #[error("no frames to encode")]
    NoFrames,
    /// The camera frame rate is not positive. Fix: pass a positive, finite fps.
    #[error("frame rate must be positive and finite, got {}", anim::human_number(*.0))]
    InvalidFps(f32),
    /// The requested frame does not exist. Fix: pick a frame below the frame count.
    #[error("frame {frame} is out of range (the clip has {frames} frames)")]
    FrameOutOfRange {
        /// Requested frame.
        frame: usize,
        /// Frame count.
        frames: usize,
    },
    /// No scene camera has this name. Fix: use one of the listed cameras, or a direction view.
    #[error("no camera named '{name}' (available: {available})")]
    CameraNotFound {
        /// Requested name.
        name: String,
        /// Names of the scene's cameras.
        available: String,
    },
    /// PNG encoding or decoding failed. Fix: for decoding, pass an 8- or 16-bit PNG file.
    #[error("png: {0}")]
    Png(String),
    /// GIF encoding failed (an internal limit of the format, e.g. a side over 65535 pixels).
    #[error("gif: {0}")]
    Gif(String),
    /// The pictures asked for are over the pixel budget ([`anim::budget::DEFAULT_MAX_PIXELS`]):
    /// ask for a smaller `--size` or fewer frames.
    #[error(transparent)]
    OverBudget(#[from] anim::OverBudget),
}

/// Result alias of this crate.
pub type Result<T, E = RenderError> = std::result::Result<T, E>;
