//! The progress of one keyframe interval along its key-to-key change: the dominant mode's
//! step response ([`crate::mode`]), laid onto the interval so that what the sliders mean
//! holds by construction (`docs/loa-timing.md`):
//!
//! * **stiffness** sets the time scale `s` (natural radians per frame): `ω / fps`, with `ω` the
//!   elastic chain's natural frequency along the change (`∝ √k`), combined
//!   with smooth, strictly monotone maxima and minima so that the approach still arrives
//!   inside a short interval and no chain point outruns [`MAX_FRAME_MOTION`]. More stiffness
//!   → larger `s` → the line is further along at every frame of the approach.
//! * **damping** sets the swing: the response overshoots the next pose by
//!   `exp(−πζ/√(1−ζ²))`, and a landing window (`1 − smoothstep`, opened once the most damped
//!   documented response has arrived) brings the swing back onto the keystroke at its frame,
//!   at rest along the change. The window and the time scale do not depend on `ζ`, so a
//!   larger `ζ` never swings further.
//!
//! `p(t) = 1 + (r(s·t; ζ) − 1)·c(t)`: `p(0) = 0`, `p(gap) = 1`, `p'(0) = p'(gap) = 0`.

use crate::keystroke::DAMPING_RANGE;
use crate::mode::{damping_for_overshoot, first_arrival, peak_speed, step_response};

/// Per-frame motion the approach is allowed (fastest chain point, as a fraction of the
/// line's length); with the landing's [`LANDING_MOTION`] and the shape's own follow-through
/// the line stays under the promised 15 %.
pub const MAX_FRAME_MOTION: f64 = 0.075;
/// Per-frame motion the landing window may add while it takes the swing back.
const LANDING_MOTION: f64 = 0.04;
/// Share of the interval by which the most damped documented response has arrived (when the
/// motion cap allows).
const ARRIVAL_SHARE: f64 = 0.6;
/// Most extra damping a short interval may add to fit its swing into the motion cap.
const MAX_EXTRA_DAMPING: f64 = 0.6;
/// Frames (at most half the interval) left for the swing after the latest arrival.
const SWING_FRAMES: f64 = 2.0;

/// One interval's progress `p(t)` from its first keystroke (0) to the second (1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Progress {
    gap: f64,
    natural: f64,
    speed: f64,
    damping: f64,
    window: f64,
}

impl Progress {
    /// The progress over `gap` frames (> 0) for the natural frequency `omega` (rad/s, the
    /// chain's along the change, `∝ √k`), damping `ζ` and `fps`, where `reach` is the fastest
    /// chain point's motion per unit of progress over the line's length.
    pub(crate) fn new(omega: f64, damping: f64, gap: f64, fps: f64, reach: f64) -> Self {
        let natural = omega.max(0.0) / fps;
        // A swing that the landing cannot take back within its budget is damped more.
        let extra = if reach > 0.0 {
            let room = LANDING_MOTION * (1.0 - ARRIVAL_SHARE) * gap / (1.5 * reach);
            damping_for_overshoot(room).min(MAX_EXTRA_DAMPING)
        } else {
            0.0
        };
        // The smallest raise that lands the swing: a smooth maximum with the extra damping.
        // The speed and the window use it at the documented range's ends only.
        let smooth = |z: f64| (z.max(0.0).powi(4) + extra.powi(4)).powf(0.25);
        // The damping used is the chord of `smooth` over the documented range (above it, the
        // range's ends shared): a smooth maximum flattens the slider's low end onto the extra
        // damping, the chord keeps every step of the slider visible in the swing.
        let top = *DAMPING_RANGE.end();
        let effective = |z: f64| (extra + (smooth(top) - extra) * z.max(0.0) / top).max(smooth(z));
        // Natural time by which the most damped documented response has arrived.
        let latest = first_arrival(effective(top));
        let arrive = latest / (ARRIVAL_SHARE * gap);
        // (`smooth` is below `effective`: its peak speed bounds the fastest response's.)
        let cap = if reach > 0.0 {
            MAX_FRAME_MOTION / (reach * peak_speed(smooth(*DAMPING_RANGE.start())))
        } else {
            f64::INFINITY
        };
        let swing = latest / (gap - (0.5 * gap).min(SWING_FRAMES));
        // Smooth maxima and minimum: strictly increasing in the natural speed.
        let s = natural.hypot(arrive);
        let s = if cap.is_finite() {
            (s.powi(-4) + cap.powi(-4)).powf(-0.25)
        } else {
            s
        };
        let speed = (s.powi(4) + swing.powi(4)).powf(0.25);
        Self {
            gap,
            natural,
            speed,
            damping: effective(damping),
            window: latest / speed,
        }
    }

    /// Progress at `t` frames after the first keystroke.
    pub(crate) fn at(&self, t: f64) -> f64 {
        if t <= 0.0 {
            return 0.0;
        }
        if t >= self.gap {
            return 1.0;
        }
        let open = if t <= self.window {
            1.0
        } else {
            let u = (t - self.window) / (self.gap - self.window);
            1.0 - u * u * (3.0 - 2.0 * u)
        };
        1.0 + (step_response(self.speed * t, self.damping) - 1.0) * open
    }

    /// The damping ratio actually used (the keystroke's, raised when the interval is too
    /// short for its swing).
    pub(crate) fn damping(&self) -> f64 {
        self.damping
    }

    /// Natural radians per frame.
    #[cfg(test)]
    pub(crate) fn speed(&self) -> f64 {
        self.speed
    }

    /// The time scale over the spring's own (`> 1`: sped up to arrive within the interval,
    /// `< 1`: slowed down by the motion cap); 1 without springs.
    pub(crate) fn time_scale(&self) -> f64 {
        if self.natural > 0.0 {
            self.speed / self.natural
        } else {
            1.0
        }
    }

    /// Frames until the line first reaches the next pose (the interval when it only gets
    /// there at the keystroke).
    pub(crate) fn arrival(&self) -> f64 {
        (first_arrival(self.damping) / self.speed).min(self.gap)
    }

    /// Largest swing past the next pose on the interval's frames, as a fraction of the change.
    pub(crate) fn overshoot(&self) -> f64 {
        (1..self.gap.ceil() as i64)
            .map(|f| self.at(f as f64) - 1.0)
            .fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64))
            .collect()
    }

    #[test]
    fn lands_at_rest_on_the_keystroke() {
        for gap in [1.0, 3.0, 10.0, 30.0] {
            for reach in [0.0, 0.01, 0.5] {
                let p = Progress::new(60f64.sqrt(), 0.2, gap, 24.0, reach);
                assert_eq!(p.at(0.0), 0.0);
                assert_eq!(p.at(gap), 1.0);
                let h = 1e-6;
                assert!((p.at(gap - h) - 1.0).abs() < 1e-9, "gap {gap}");
                assert!(p.at(h).abs() < 1e-9);
            }
        }
    }

    /// Asserts that `f` over the 6-value grid of `lo..=hi` strictly rises (`sign` 1) or
    /// falls (`sign` −1).
    fn assert_strict(lo: f64, hi: f64, sign: f64, f: impl Fn(f64) -> f64, what: &str) {
        let v: Vec<f64> = grid(lo, hi, 6).into_iter().map(f).collect();
        assert!(
            v.windows(2).all(|w| sign * (w[1] - w[0]) > 0.0),
            "{what}: {v:?}"
        );
    }

    #[test]
    fn damping_lowers_and_stiffness_advances_every_interval() {
        for gap in [5.0, 10.0, 17.0, 30.0, 90.0] {
            for reach in [0.0, 0.02, 0.1, 0.3, 0.6, 1.5] {
                let at = |k: f64, z: f64| Progress::new(k.sqrt(), z, gap, 24.0, reach);
                let what = format!("gap {gap} reach {reach}");
                for k in grid(5.0, 100.0, 6) {
                    assert_strict(0.05, 0.5, -1.0, |z| at(k, z).overshoot(), &what);
                }
                for z in grid(0.05, 0.5, 6) {
                    assert_strict(5.0, 100.0, 1.0, |k| at(k, z).speed(), &what);
                }
            }
        }
    }
}
