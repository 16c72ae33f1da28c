//! Keystrokes: strokes drawn at given frames, with the elastic parameters of the line.

use std::ops::RangeInclusive;

use glam::DVec2;
use serde::Deserialize;

use crate::error::LoaError;
use crate::stroke::Stroke;

/// Default angular stiffness `k` in 1/s²: the line turning rigidly about its root would swing
/// at `ω = √k` rad/s (here ≈ 7.7 rad/s, a period of ≈ 0.8 s); its bends are springs of a
/// uniform elastic rod scaled by the same `k`.
pub const DEFAULT_STIFFNESS: f64 = 60.0;
/// Default damping ratio `ζ` (1 = critical; below 1 the line overshoots and wobbles).
pub const DEFAULT_DAMPING: f64 = 0.35;
/// The documented stiffness range (1/s²): across it a stiffer line arrives strictly earlier
/// and wobbles strictly faster, and no chain point moves more than 15 % of the line's length
/// in a frame. Values outside are rejected ([`LoaError::OutOfRange`]).
pub const STIFFNESS_RANGE: RangeInclusive<f64> = 5.0..=100.0;
/// The documented damping-ratio range: across it more damping strictly lowers the overshoot.
/// Values outside are rejected ([`LoaError::OutOfRange`]).
pub const DAMPING_RANGE: RangeInclusive<f64> = 0.05..=0.5;
/// Default frames per second when the input names none.
pub const DEFAULT_FPS: f64 = 24.0;
/// Largest frame span (last keystroke frame − first) accepted, to keep memory bounded.
pub const MAX_FRAME_SPAN: i64 = 1_000_000;
/// A keystroke shorter than this fraction of the longest keystroke is rejected as a stray
/// click ([`LoaError::TooShort`]).
pub const MIN_RELATIVE_STROKE_LENGTH: f64 = 0.01;

/// One sketched keystroke: a stroke, the frame it is drawn at, and how the line leaves it.
#[derive(Debug, Clone, PartialEq)]
pub struct Keystroke {
    /// Frame number of the keystroke.
    pub frame: i64,
    /// The drawn stroke, in screen coordinates.
    pub stroke: Stroke,
    /// Angular stiffness `k` (1/s², ≥ 0) of the springs pulling the line from this keystroke
    /// toward the next one. Larger is snappier: the line reaches the next pose sooner and
    /// wobbles faster.
    pub stiffness: f64,
    /// Damping ratio `ζ` (≥ 0) for the interval that starts at this keystroke: 1 is critical
    /// (no overshoot), below 1 gives follow-through and wobble, above 1 is sluggish.
    pub damping: f64,
}

impl Keystroke {
    /// A keystroke with the default stiffness and damping.
    pub fn new(frame: i64, stroke: Stroke) -> Self {
        Self {
            frame,
            stroke,
            stiffness: DEFAULT_STIFFNESS,
            damping: DEFAULT_DAMPING,
        }
    }
}

/// A validated, frame-ordered set of keystrokes.
#[derive(Debug, Clone, PartialEq)]
pub struct Keystrokes {
    keys: Vec<Keystroke>,
    fps: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonFile {
    #[serde(default)]
    fps: Option<f64>,
    #[serde(default)]
    stiffness: Option<f64>,
    #[serde(default)]
    damping: Option<f64>,
    keystrokes: Vec<JsonKey>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonKey {
    frame: f64,
    points: Vec<[f64; 2]>,
    #[serde(default)]
    stiffness: Option<f64>,
    #[serde(default)]
    damping: Option<f64>,
}

impl Keystrokes {
    /// Validates keystrokes: at least one, frames strictly increasing, valid parameters, and
    /// no stroke shorter than [`MIN_RELATIVE_STROKE_LENGTH`] of the longest.
    pub fn new(keys: Vec<Keystroke>, fps: Option<f64>) -> Result<Self, LoaError> {
        if keys.is_empty() {
            return Err(LoaError::NoKeystrokes);
        }
        anim::check_budget(
            "keystrokes",
            keys.len() as u64,
            anim::budget::DEFAULT_MAX_KEYSTROKES,
            "split the shot into several lines",
        )?;
        if let Some(f) = fps {
            check_positive("fps", f)?;
        }
        for (i, k) in keys.iter().enumerate() {
            if i > 0 && k.frame <= keys[i - 1].frame {
                return Err(LoaError::FrameOrder {
                    keystroke: i,
                    frame: k.frame,
                    previous: keys[i - 1].frame,
                });
            }
            check_range("stiffness", k.stiffness, &STIFFNESS_RANGE, i, k.frame)?;
            check_range("damping", k.damping, &DAMPING_RANGE, i, k.frame)?;
        }
        let span = keys[keys.len() - 1].frame.saturating_sub(keys[0].frame);
        if span > MAX_FRAME_SPAN {
            return Err(LoaError::InvalidParameter {
                name: "frame span",
                value: span as f64,
                expected: "keystrokes at most 1,000,000 frames apart in total",
            });
        }
        let longest = keys.iter().map(|k| k.stroke.length()).fold(0.0, f64::max);
        for (i, k) in keys.iter().enumerate() {
            if k.stroke.length() < MIN_RELATIVE_STROKE_LENGTH * longest {
                return Err(LoaError::TooShort {
                    keystroke: i,
                    frame: k.frame,
                    length: k.stroke.length(),
                    longest,
                });
            }
        }
        Ok(Self { keys, fps })
    }

    /// Parses the keystroke JSON layout:
    ///
    /// ```json
    /// { "fps": 24, "stiffness": 60, "damping": 0.35,
    ///   "keystrokes": [ { "frame": 0, "points": [[0, 0], [10, 5]], "stiffness": 80, "damping": 0.2 } ] }
    /// ```
    ///
    /// `fps`, the file-wide `stiffness`/`damping` defaults and the per-keystroke overrides are
    /// optional. Frames must be integers in strictly increasing order.
    pub fn from_json_str(text: &str) -> Result<Self, LoaError> {
        let file: JsonFile =
            serde_json::from_str(text).map_err(|e| LoaError::Json(e.to_string()))?;
        let default_k = file.stiffness.unwrap_or(DEFAULT_STIFFNESS);
        let default_c = file.damping.unwrap_or(DEFAULT_DAMPING);
        let mut keys = Vec::with_capacity(file.keystrokes.len());
        for (i, k) in file.keystrokes.into_iter().enumerate() {
            let frame = integral_frame(k.frame)?;
            let stroke =
                Stroke::new(k.points.iter().map(|p| DVec2::new(p[0], p[1]))).map_err(|source| {
                    LoaError::Stroke {
                        keystroke: i,
                        frame,
                        source,
                    }
                })?;
            keys.push(Keystroke {
                frame,
                stroke,
                stiffness: k.stiffness.unwrap_or(default_k),
                damping: k.damping.unwrap_or(default_c),
            });
        }
        Self::new(keys, file.fps)
    }

    /// The keystrokes in frame order.
    pub fn keys(&self) -> &[Keystroke] {
        &self.keys
    }

    /// Frames per second named by the input, if any.
    pub fn fps(&self) -> Option<f64> {
        self.fps
    }

    /// Frame numbers of the keystrokes.
    pub fn frames(&self) -> Vec<i64> {
        self.keys.iter().map(|k| k.frame).collect()
    }
}

pub(crate) fn integral_frame(f: f64) -> Result<i64, LoaError> {
    if !f.is_finite() || f.fract() != 0.0 || f.abs() > 1e15 {
        return Err(LoaError::InvalidParameter {
            name: "frame",
            value: f,
            expected: "an integer frame number",
        });
    }
    Ok(f as i64)
}

/// `value` of keystroke `keystroke` (at `frame`) inside the documented `range`.
fn check_range(
    name: &'static str,
    value: f64,
    range: &RangeInclusive<f64>,
    keystroke: usize,
    frame: i64,
) -> Result<(), LoaError> {
    if range.contains(&value) {
        return Ok(());
    }
    Err(LoaError::OutOfRange {
        name,
        value,
        min: *range.start(),
        max: *range.end(),
        keystroke,
        frame,
    })
}

pub(crate) fn check_non_negative(name: &'static str, v: f64) -> Result<(), LoaError> {
    if !(v.is_finite() && v >= 0.0) {
        return Err(LoaError::InvalidParameter {
            name,
            value: v,
            expected: "a finite value >= 0",
        });
    }
    Ok(())
}

pub(crate) fn check_positive(name: &'static str, v: f64) -> Result<(), LoaError> {
    if !(v.is_finite() && v > 0.0) {
        return Err(LoaError::InvalidParameter {
            name,
            value: v,
            expected: "a finite value > 0",
        });
    }
    Ok(())
}
