//! Errors of style files and stylization functions. Every variant says how to fix the input.

use thiserror::Error;

/// An invalid style or stylization function.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StyleError {
    /// A user expression does not parse. Check the syntax: operators `+ - * / ^`, functions
    /// written `f(x)` (`min(a, b)`, `max(a, b)`, `abs`, `step`, `smoothstep`, `sqrt`, ...).
    #[error("expression '{expr}': {problem}")]
    Expression {
        /// The expression text.
        expr: String,
        /// What the parser reported.
        problem: String,
    },
    /// A user expression reads a variable that is neither an input nor a declared parameter.
    /// Use one of the listed names, or declare it under `params`.
    #[error("expression '{expr}': unknown variable '{name}'; known: {known}")]
    UnknownVariable {
        /// The expression text.
        expr: String,
        /// The unknown name.
        name: String,
        /// Comma-separated names that may be used.
        known: String,
    },
    /// A parameter is out of its range, not finite, or a keyframe curve is empty or its frames
    /// do not increase. Give finite values in range and keyframes sorted by frame.
    #[error("parameter '{name}': {problem}")]
    Parameter {
        /// Which parameter (e.g. `warp.s`).
        name: String,
        /// What is wrong.
        problem: String,
    },
    /// A user expression is NaN or infinite at some vertices (a division by zero, the log or
    /// square root of a negative number there). Keep it finite over the inputs it reads, e.g.
    /// `1 / max(x, 0.001)` or `log(max(speed, 0.001))`.
    #[error(
        "expression '{expr}' is NaN or infinite at frame {frame}, {item} {index} (a division \
         by zero, or log/sqrt of a negative number): keep it finite there, e.g. max(..., 0.001)"
    )]
    NotFinite {
        /// The expression text.
        expr: String,
        /// First frame where it is not finite.
        frame: u32,
        /// What `index` counts: `vertex` or `motion line`.
        item: &'static str,
        /// The vertex (or motion line) at that frame.
        index: u32,
    },
    /// A function gives both `expr` and `stages`. Give one of them.
    #[error("a stylization function takes either 'expr' or 'stages', not both")]
    ExprAndStages,
    /// The style text is not valid TOML for a style. The message names the line and key.
    #[error("style: {0}")]
    Syntax(String),
}
