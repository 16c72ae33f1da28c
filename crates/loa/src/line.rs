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

/// The whole 2D job: prepares the keystrokes (orientation, smoothing), fits them (LoA
/// Eq. 1), interpolates them with the chosen mode (physics: LoA Section 3.2 and LoA Eq. 2),
/// adds the settle frames and applies the wobbles.
///
/// Orientation: a keystroke's start is the end that pairs better with the previous
/// keystroke's ends (smaller sum of start–start and end–end distances than start–end and
/// end–start); a keystroke drawn the other way round is reversed and reported, because the
/// line would otherwise spin 180° about its root.
///
/// # Errors
/// Invalid options (fps, sub-steps, element count, wobble frame) or a keystroke the fit
/// rejects.
pub fn line(keys: &Keystrokes, options: &LineOptions) -> Result<Line, LoaError> {
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
    let warnings = reversed
        .iter()
        .map(|f| {
            format!(
                "keystroke at frame {f} is drawn the other way round from the previous one; \
                 reversed it (its start is the end nearer the previous keystroke's start)"
            )
        })
        .collect();
    Ok(Line {
        animation,
        keys: poses,
        retargets,
        reversed,
        warnings,
    })
}

/// Orients and smooths the keystrokes; returns them with the frames of reversed ones.
fn prepare(keys: &Keystrokes, options: &LineOptions) -> Result<(Keystrokes, Vec<i64>), LoaError> {
    let mut out: Vec<Keystroke> = Vec::with_capacity(keys.keys().len());
    let mut reversed = Vec::new();
    for k in keys.keys() {
        let mut k = k.clone();
        if let (true, Some(prev)) = (options.orient, out.last()) {
            let (p0, p1) = ends(&prev.stroke);
            let (a, b) = ends(&k.stroke);
            if (a - p1).length() + (b - p0).length() < (a - p0).length() + (b - p1).length() {
                k.stroke = k.stroke.reversed();
                reversed.push(k.frame);
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
