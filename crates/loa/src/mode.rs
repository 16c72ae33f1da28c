//! The dominant mode of the elastic line: a single damped oscillator whose natural
//! frequency is `√k` (the line turning rigidly about its root, LoA §3.2's elastic chain) and
//! whose damping ratio is the keystroke's `ζ`. Its responses give the timing every interval
//! and the settle are built on (`docs/loa-timing.md`).
//!
//! Time is the oscillator's natural time `x = √k · t` (radians); every function here is for
//! a unit natural frequency.

use std::f64::consts::PI;

/// Damping ratios this close to 1 use the critically damped formulas.
const CRITICAL_BAND: f64 = 1e-6;

/// Step response from rest: the progress `r(x)` of a unit oscillator released at 0 toward 1
/// (`r(0) = 0`, `r'(0) = 0`). Under-damped (`ζ < 1`) it first reaches 1 at
/// [`first_arrival`] and overshoots by [`overshoot`].
pub(crate) fn step_response(x: f64, zeta: f64) -> f64 {
    let x = x.max(0.0);
    if (zeta - 1.0).abs() < CRITICAL_BAND {
        return 1.0 - (-x).exp() * (1.0 + x);
    }
    if zeta < 1.0 {
        let wd = (1.0 - zeta * zeta).sqrt();
        return 1.0 - (-zeta * x).exp() * ((wd * x).cos() + zeta / wd * (wd * x).sin());
    }
    let root = (zeta * zeta - 1.0).sqrt();
    let (l1, l2) = (-zeta + root, -zeta - root);
    1.0 + (l2 * (l1 * x).exp() - l1 * (l2 * x).exp()) / (l1 - l2)
}

/// Free response `h(x)` released at 0 with unit velocity (`h(0) = 0`, `h'(0) = 1`); it is
/// also the derivative of [`step_response`].
pub(crate) fn free_response(x: f64, zeta: f64) -> f64 {
    let x = x.max(0.0);
    if (zeta - 1.0).abs() < CRITICAL_BAND {
        return x * (-x).exp();
    }
    if zeta < 1.0 {
        let wd = (1.0 - zeta * zeta).sqrt();
        return (-zeta * x).exp() * (wd * x).sin() / wd;
    }
    let root = (zeta * zeta - 1.0).sqrt();
    let (l1, l2) = (-zeta + root, -zeta - root);
    ((l1 * x).exp() - (l2 * x).exp()) / (l1 - l2)
}

/// Natural time at which the step response first reaches 1 (`∞` when `ζ ≥ 1`).
pub(crate) fn first_arrival(zeta: f64) -> f64 {
    if zeta >= 1.0 {
        return f64::INFINITY;
    }
    let wd = (1.0 - zeta * zeta).sqrt();
    (PI - wd.atan2(zeta)) / wd
}

/// Overshoot of the step response past 1, as a fraction of the step:
/// `exp(−πζ/√(1−ζ²))`, 0 from critical damping on. Strictly decreasing in `ζ` below 1.
#[cfg(test)]
pub(crate) fn overshoot(zeta: f64) -> f64 {
    if zeta >= 1.0 {
        return 0.0;
    }
    (-PI * zeta / (1.0 - zeta * zeta).sqrt()).exp()
}

/// The damping ratio whose [`overshoot`] is `fraction` (0 for a fraction ≥ 1).
pub(crate) fn damping_for_overshoot(fraction: f64) -> f64 {
    if fraction >= 1.0 {
        return 0.0;
    }
    if fraction <= 0.0 {
        return 1.0;
    }
    let l = fraction.ln();
    -l / (PI * PI + l * l).sqrt()
}

/// Largest speed of the step response, `max_x r'(x)` (1 when undamped).
pub(crate) fn peak_speed(zeta: f64) -> f64 {
    if zeta <= 0.0 {
        return 1.0;
    }
    if zeta >= 1.0 - CRITICAL_BAND {
        // Critical and over-damped responses peak below the critical one's 1/e.
        return (-1.0f64).exp();
    }
    let wd = (1.0 - zeta * zeta).sqrt();
    free_response(wd.atan2(zeta) / wd, zeta)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn responses_start_at_rest_and_match_their_derivatives() {
        for zeta in [0.0, 0.05, 0.3, 0.5, 0.9, 1.0, 1.5] {
            assert!(step_response(0.0, zeta).abs() < 1e-12);
            assert!(free_response(0.0, zeta).abs() < 1e-12);
            for x in [0.3, 1.0, 2.5, 7.0] {
                let h = 1e-5;
                let d = (step_response(x + h, zeta) - step_response(x - h, zeta)) / (2.0 * h);
                assert!((d - free_response(x, zeta)).abs() < 1e-7, "ζ={zeta} x={x}");
            }
        }
    }

    #[test]
    fn overshoot_and_first_arrival_are_the_step_responses() {
        for zeta in [0.05, 0.2, 0.5, 0.8] {
            let x1 = first_arrival(zeta);
            assert!((step_response(x1, zeta) - 1.0).abs() < 1e-12);
            let peak = PI / (1.0 - zeta * zeta).sqrt();
            assert!((step_response(peak, zeta) - 1.0 - overshoot(zeta)).abs() < 1e-12);
            assert!((damping_for_overshoot(overshoot(zeta)) - zeta).abs() < 1e-12);
            let fastest = (0..4000)
                .map(|i| free_response(i as f64 * 1e-3, zeta))
                .fold(0.0, f64::max);
            assert!((fastest - peak_speed(zeta)).abs() < 1e-5);
        }
    }

    /// The property the overshoot's monotonicity rests on (`docs/loa-timing.md`): up to the
    /// first peak of the less damped response, the more damped one is never ahead of it.
    #[test]
    fn more_damping_is_never_ahead_before_the_first_peak() {
        let dampings: Vec<f64> = (0..=40).map(|i| 0.02 * i as f64).collect();
        for w in dampings.windows(2) {
            let peak = PI / (1.0 - w[0] * w[0]).sqrt();
            for i in 1..=400 {
                let x = peak * i as f64 / 400.0;
                assert!(
                    step_response(x, w[1]) < step_response(x, w[0]),
                    "ζ {} vs {} at x = {x}",
                    w[0],
                    w[1]
                );
            }
        }
    }
}
