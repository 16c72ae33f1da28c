//! The whole 2D job: keystrokes in, the dynamic line of action out ([`line()`]).

use glam::DVec2;
use serde::{Deserialize, Serialize};

use crate::animation::AnimationFrame;
use crate::error::LoaError;
use crate::fit::DEFAULT_ELEMENTS;
use crate::hermite::interpolate_hermite;
use crate::keypose::{fit_keystrokes, KeyPose};
use crate::keystroke::{check_positive, Keystroke, Keystrokes};
use crate::physics::{PhysicsOptions, Retarget};
use crate::stroke::{Stroke, DEFAULT_STROKE_SMOOTHING};
use crate::timing::interpolate_physics;
use crate::wobble::{wobble, Wobble};
use crate::Animation;

/// Which interpolation between keystrokes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Physically-based interpolation (Section 3.2).
    #[default]
    Physics,
    /// Geometric Hermite interpolation (end of Section 3.1).
    Hermite,
}

/// Options of [`line()`]. Serde-ready: every field is optional in a TOML/JSON file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LineOptions {
    /// Interpolation mode.
    pub mode: Mode,
    /// Rigid elements per chain (even, ≥ 2).
    pub elements: usize,
    /// Physics options; `physics.fps` is also the output's fps and `physics.settle` the
    /// number of frames added after the last keystroke in Hermite mode too (held there).
    pub physics: PhysicsOptions,
    /// Stroke smoothing before the fit: σ of [`Stroke::smoothed`] as a fraction of each
    /// stroke's length (0 = fit the raw samples).
    pub smoothing: f64,
    /// Orient every keystroke like the previous one (see [`line()`]); a reversed keystroke is
    /// reported in [`Line::warnings`].
    pub orient: bool,
    /// Drag-to-wobble impulses applied to the finished line, in order.
    pub wobbles: Vec<Wobble>,
}

impl Default for LineOptions {
    fn default() -> Self {
        Self {
            mode: Mode::default(),
            elements: DEFAULT_ELEMENTS,
            physics: PhysicsOptions::default(),
            smoothing: DEFAULT_STROKE_SMOOTHING,
            orient: true,
            wobbles: Vec::new(),
        }
    }
}

/// A computed dynamic line of action and what was done to get it.
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    /// The animated line, one chain per frame.
    pub animation: Animation,
    /// The fitted keystrokes (with their LoA Eq. 1 residuals).
    pub keys: Vec<KeyPose>,
    /// Re-targeting per interval (physics mode only; empty for Hermite).
    pub retargets: Vec<Retarget>,
    /// Frames of keystrokes that were drawn the other way round and reversed.
    pub reversed: Vec<i64>,
    /// Human-readable warnings (one line each), e.g. about reversed keystrokes.
    pub warnings: Vec<String>,
}

/// Every frame from the first keystroke to the last, then the settle frames, is a pose of
/// the line (and of the character that follows it): keystrokes at frames 0 and 10^9 are
/// refused before the poses are made, however few they are.
fn check_line_frames(keys: &Keystrokes, options: &LineOptions) -> Result<(), LoaError> {
    let frames = keys.frames();
    let span = match (frames.first(), frames.last()) {
        (Some(&a), Some(&b)) => {
            u64::try_from(i128::from(b) - i128::from(a) + 1).unwrap_or(u64::MAX)
        }
        _ => 0,
    };
    let settle = u64::from(options.physics.settle.frames(&frames));
    anim::check_budget(
        "line frames (first keystroke to last, then the settle frames)",
        span.saturating_add(settle),
        anim::budget::DEFAULT_MAX_FRAMES,
        "put the keystrokes' frames closer together, lower the settle frames or split the shot",
    )?;
    Ok(())
}

/// The whole 2D job: prepares the keystrokes (orientation, smoothing), fits them (LoA
/// Eq. 1), interpolates them with the chosen mode (physics: LoA Section 3.2 and LoA Eq. 2),
/// adds the settle frames and applies the wobbles.
///
/// Orientation: a keystroke is reversed (and reported, with the distances compared) when it
/// is drawn the other way round from the previous keystroke — its chord (start → end) turns
/// more than 90° from the previous one's *and* its ends pair better crossed (start–previous
/// end plus end–previous start shorter than start–previous start plus end–previous end) —
/// because the line would otherwise spin about its root. A keystroke that continues the
/// previous one's direction (chords less than 90° apart) is never reversed.
///
/// # Errors
/// Invalid options (fps, sub-steps, element count, wobble frame) or a keystroke the fit
/// rejects; [`LoaError::OverBudget`] when the keystrokes and the settle frames span more
/// than [`anim::budget::DEFAULT_MAX_FRAMES`] frames.
pub fn line(keys: &Keystrokes, options: &LineOptions) -> Result<Line, LoaError> {
    check_line_frames(keys, options)?;
    let (prepared, reversed) = prepare(keys, options)?;
    let poses = fit_keystrokes(&prepared, options.elements)?;
    let (mut animation, retargets) = match options.mode {
        Mode::Hermite => {
            check_positive("fps", options.physics.fps)?;
            let mut a = interpolate_hermite(&poses, options.physics.fps);
            if let Some(last) = a.frames.last().cloned() {
                let tail = options.physics.settle.frames(&keys.frames());
                for k in 1..=i64::from(tail) {
                    a.frames.push(AnimationFrame {
                        frame: last.frame + k,
                        chain: last.chain.clone(),
                    });
                }
            }
            (a, Vec::new())
        }
        Mode::Physics => {
            let result = interpolate_physics(&poses, &options.physics)?;
            (result.animation, result.retargets)
        }
    };
    for w in &options.wobbles {
        animation = wobble(&animation, w, options.physics.substeps)?;
    }
    let warnings = reversed.iter().map(Reversal::warning).collect();
    let reversed = reversed.iter().map(|r| r.frame).collect();
    Ok(Line {
        animation,
        keys: poses,
        retargets,
        reversed,
        warnings,
    })
}

/// A keystroke drawn the other way round from the previous one, and why it was reversed.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Reversal {
    frame: i64,
    /// Start–previous start plus end–previous end, as drawn.
    straight: f64,
    /// Start–previous end plus end–previous start.
    crossed: f64,
    /// Angle (degrees) between the chord as drawn and the previous keystroke's chord.
    turn: f64,
}

impl Reversal {
    /// The reversal of the keystroke at `frame` with ends `(a, b)` after a keystroke with ends
    /// `(p0, p1)`, if the orientation rule of [`line()`] asks for one.
    fn of(frame: i64, (a, b): (DVec2, DVec2), (p0, p1): (DVec2, DVec2)) -> Option<Reversal> {
        let (chord, previous) = (b - a, p1 - p0);
        let straight = (a - p0).length() + (b - p1).length();
        let crossed = (a - p1).length() + (b - p0).length();
        // Continuing the previous direction (or a degenerate chord) never reverses.
        let opposed = chord.dot(previous) < 0.0;
        (opposed && crossed < straight).then(|| Reversal {
            frame,
            straight,
            crossed,
            turn: previous.angle_to(chord).abs().to_degrees(),
        })
    }

    fn warning(&self) -> String {
        format!(
            "keystroke at frame {} is drawn the other way round from the previous one (its \
             direction turns {:.0}° from the previous one's, more than 90°, and its ends are \
             nearer the previous keystroke's opposite ends: {:.1} crossed against {:.1} as drawn, \
             start-to-start plus end-to-end); reversed it so the line does not spin about its \
             root",
            self.frame, self.turn, self.crossed, self.straight,
        )
    }
}

/// Orients and smooths the keystrokes; returns them with the reversed ones.
fn prepare(
    keys: &Keystrokes,
    options: &LineOptions,
) -> Result<(Keystrokes, Vec<Reversal>), LoaError> {
    let mut out: Vec<Keystroke> = Vec::with_capacity(keys.keys().len());
    let mut reversed = Vec::new();
    for k in keys.keys() {
        let mut k = k.clone();
        if let (true, Some(prev)) = (options.orient, out.last()) {
            if let Some(r) = Reversal::of(k.frame, ends(&k.stroke), ends(&prev.stroke)) {
                k.stroke = k.stroke.reversed();
                reversed.push(r);
            }
        }
        out.push(k);
    }
    for k in &mut out {
        k.stroke = k.stroke.smoothed(options.smoothing);
    }
    Ok((Keystrokes::new(out, keys.fps())?, reversed))
}

fn ends(s: &Stroke) -> (DVec2, DVec2) {
    let p = s.points();
    (p[0], p[p.len() - 1])
}
