//! Errors of the line-of-action crate. Every variant's documentation says how to fix the input.

use thiserror::Error;

/// A problem with one sketched stroke, independent of the other keystrokes.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StrokeError {
    /// The stroke has fewer than two samples. Draw (or export) at least two distinct points.
    #[error("stroke has {points} sample(s); at least 2 distinct points are needed")]
    TooFewPoints {
        /// Number of samples found.
        points: usize,
    },
    /// A coordinate is NaN or infinite. Re-export the stroke with finite coordinates.
    #[error("stroke sample {sample} has a non-finite coordinate")]
    NonFinite {
        /// Index of the offending sample.
        sample: usize,
    },
    /// All samples lie on (almost) the same spot: the stroke overlaps itself into a point and
    /// has no direction to fit. Draw an actual line.
    #[error("stroke collapses to a point (extent {extent:.3e}); draw a visible line")]
    Collapsed {
        /// Bounding-box diagonal of the samples.
        extent: f64,
    },
}

/// Any error of the `loa` crate.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LoaError {
    /// One keystroke's stroke is unusable; see the inner [`StrokeError`] for the fix.
    #[error("keystroke {keystroke} (frame {frame}): {source}")]
    Stroke {
        /// Index of the keystroke in input order.
        keystroke: usize,
        /// Its frame number.
        frame: i64,
        /// What is wrong with the stroke.
        source: StrokeError,
    },
    /// A stroke is much shorter than the longest keystroke (below
    /// [`MIN_RELATIVE_STROKE_LENGTH`](crate::MIN_RELATIVE_STROKE_LENGTH) of it): usually a stray
    /// click. Remove it or redraw it at the scale of the other keystrokes.
    #[error(
        "keystroke {keystroke} (frame {frame}) is too short: length {length:.4} vs. longest {longest:.4}; \
         redraw it at the scale of the other keystrokes"
    )]
    TooShort {
        /// Index of the keystroke in input order.
        keystroke: usize,
        /// Its frame number.
        frame: i64,
        /// Its arc length.
        length: f64,
        /// Arc length of the longest keystroke.
        longest: f64,
    },
    /// Keystroke frames must strictly increase in input order. Sort the keystrokes by frame
    /// and remove duplicates.
    #[error(
        "keystroke {keystroke} has frame {frame}, not after the previous keystroke's frame \
         {previous}; list keystrokes in strictly increasing frame order"
    )]
    FrameOrder {
        /// Index of the keystroke in input order.
        keystroke: usize,
        /// Its frame number.
        frame: i64,
        /// Frame of the keystroke before it.
        previous: i64,
    },
    /// The input holds no keystroke. Provide at least one (two for an animation).
    #[error("no keystrokes found; provide at least one stroke with a frame number")]
    NoKeystrokes,
    /// A numeric parameter is out of its valid range; the message names the range.
    #[error("invalid {name} = {}: {expected}", anim::human_number(*.value))]
    InvalidParameter {
        /// Parameter name as in the input format or options.
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// What would be accepted.
        expected: &'static str,
    },
    /// A keystroke's stiffness or damping lies outside its documented range
    /// ([`STIFFNESS_RANGE`](crate::STIFFNESS_RANGE), [`DAMPING_RANGE`](crate::DAMPING_RANGE)),
    /// where the sliders no longer act monotonically. Pick a value inside the range.
    #[error(
        "keystroke {keystroke} (frame {frame}): {name} = {} is outside the documented range \
         [{}, {}]; pick a value inside it",
        anim::human_number(*.value), anim::human_number(*.min), anim::human_number(*.max)
    )]
    OutOfRange {
        /// `stiffness` or `damping`.
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// Smallest accepted value.
        min: f64,
        /// Largest accepted value.
        max: f64,
        /// Index of the keystroke in input order.
        keystroke: usize,
        /// Its frame number.
        frame: i64,
    },
    /// The keystroke JSON does not parse or does not follow the layout documented in
    /// [`Keystrokes::from_json_str`](crate::Keystrokes::from_json_str).
    #[error("keystroke JSON: {0}")]
    Json(String),
    /// The SVG is not well-formed XML. Fix or re-export the file.
    #[error("keystroke SVG: {0}")]
    Xml(String),
    /// A `<path>`/`<polyline>` could not be read; the message says which element and why
    /// (only M/L/H/V/C/S/Q/T/Z path commands are understood; arcs must be converted to curves).
    #[error("keystroke SVG element {element} (<{tag}>): {message}")]
    SvgElement {
        /// Index of the stroke element in document order.
        element: usize,
        /// Its tag name.
        tag: String,
        /// What is wrong.
        message: String,
    },
    /// A wobble is not written `FRAME:S:DX,DY` (e.g. `20:1:0,-800`), with `S` in `[0, 1]`.
    #[error("wobble '{0}': expected FRAME:S:DX,DY with S in [0, 1] (e.g. 20:1:0,-800)")]
    Wobble(String),
    /// The keystrokes ask for more than a budget allows ([`anim::budget`]): fewer keystrokes,
    /// a flatter SVG, a shorter span.
    #[error(transparent)]
    OverBudget(#[from] anim::OverBudget),
}
