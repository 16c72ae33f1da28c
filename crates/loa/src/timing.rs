//! How a simulated interval is laid onto the animator's frames (a toonkit decision; the paper
//! re-times `0..=t*` onto the whole interval, see the crate docs' "SPEC decisions").
//!
//! The keystrokes stay at their frames. Within an interval of `gap` frames:
//!
//! 1. **Approach** (output frames `0..t_a`): the simulated frames `0..=t*` (LoA Eq. 2), with
//!    the correction `Δγ = γ(t_k+1) − γ(t*)` blended in, played at the simulation's own speed
//!    (`t_a = t*`, so stiffer springs arrive sooner) — slowed down only as far as needed so
//!    that no chain point moves more than [`MAX_FRAME_MOTION`] of the line's length per frame,
//!    and sped up (as in the paper) only when `t*` is later than the next keystroke.
//! 2. **Follow-through** (`t_a..gap`): the line arrives on the next pose with the velocity it
//!    had and the same springs keep pulling it there, so it overshoots (more with less
//!    damping) and wobbles at the spring's frequency (higher with more stiffness); a second
//!    correction, blended over this phase, lands it exactly on the keystroke. A repeated
//!    keystroke is therefore a moving hold: the line swings through it and settles.
//! 3. **Settle** after the last keystroke: the same springs, faded out by a smoothstep window
//!    so the last frame is the last keystroke, at rest.

use crate::animation::{Animation, AnimationFrame};
use crate::hermite::HermiteLine;
use crate::keypose::KeyPose;
use crate::physics::{
    simulate, PhysicsAnimation, PhysicsOptions, Retarget, SimulatedFrames, Simulation,
};
use crate::retarget::{closest_frame, Blend};
use crate::{Chain, LoaError};

/// Largest per-frame motion of any chain point the approach is allowed, as a fraction of the
/// line's length (the promise is ≤ 15 %; the margin covers the follow-through phase).
pub const MAX_FRAME_MOTION: f64 = 0.1;

/// Physically-based interpolation of the key poses (Section 3.2). The result passes exactly
/// through every key pose at its frame; see the `timing` notes in the crate docs for how each
/// simulated interval is laid onto the keystrokes' frames, and [`PhysicsOptions::settle`] for
/// the frames added after the last keystroke.
pub fn interpolate_physics(
    keys: &[KeyPose],
    options: &PhysicsOptions,
) -> Result<PhysicsAnimation, LoaError> {
    options.validate()?;
    let Some(first) = keys.first() else {
        return Err(LoaError::NoKeystrokes);
    };
    let n = first.chain.elements();
    let line = HermiteLine::new(keys);
    let mut frames = vec![AnimationFrame {
        frame: first.frame,
        chain: first.chain.clone(),
    }];
    let mut retargets = Vec::with_capacity(keys.len().saturating_sub(1));
    let mut velocity = vec![0.0; n];
    for pair in keys.windows(2) {
        let (from, to) = (&pair[0], &pair[1]);
        let m = match options.simulated_frames {
            SimulatedFrames::Fixed(m) => m,
            SimulatedFrames::FrameGap => u32::try_from(to.frame - from.frame).unwrap_or(u32::MAX),
        };
        let sim = simulate(from, to.chain.angles(), &velocity, m, options)?;
        let whole: Vec<Vec<f64>> = (0..=sim.frames()).map(|i| sim.frame(i)).collect();
        let t_star = closest_frame(&whole, to.chain.angles());
        let delta = |t: usize| -> Vec<f64> {
            let at = sim.frame(t);
            to.chain
                .angles()
                .iter()
                .zip(&at)
                .map(|(a, b)| a - b)
                .collect()
        };
        let correction = delta(t_star);
        // The first pass: the first local minimum of LoA Eq. 2's distance (a later, closer swing
        // would force a sped-up replay of several swings, which strobes).
        let first = first_pass(&whole, to.chain.angles()).min(t_star);
        let applied = delta(first);
        let interval = Interval {
            from,
            to,
            line: &line,
            options,
        };
        let laid = interval.lay(&sim, first, &applied)?;
        for (f, chain) in (from.frame + 1..).zip(laid.chains) {
            frames.push(AnimationFrame { frame: f, chain });
        }
        velocity = laid.velocity;
        retargets.push(Retarget {
            from_frame: from.frame,
            to_frame: to.frame,
            simulated_frames: m,
            t_star,
            correction: correction.iter().map(|d| d * d).sum::<f64>().sqrt(),
            first_pass: first,
            arrival: laid.arrival,
        });
    }
    let last = &keys[keys.len() - 1];
    let key_frames: Vec<i64> = keys.iter().map(|k| k.frame).collect();
    let tail = options.settle.frames(&key_frames);
    for (f, chain) in (last.frame + 1..).zip(settle(last, &velocity, tail, options)?) {
        frames.push(AnimationFrame { frame: f, chain });
    }
    Ok(PhysicsAnimation {
        animation: Animation::new(options.fps, keys.iter().map(|k| k.frame).collect(), frames),
        retargets,
    })
}

/// One interval between two keystrokes.
struct Interval<'a> {
    pub from: &'a KeyPose,
    pub to: &'a KeyPose,
    pub line: &'a HermiteLine,
    pub options: &'a PhysicsOptions,
}

/// The frames of one interval (after its first keystroke, up to and including the second)
/// and what the re-timing did.
struct Laid {
    pub chains: Vec<Chain>,
    /// Output velocity (rad/s) leaving the second keystroke.
    pub velocity: Vec<f64>,
    /// Output frames from the first keystroke to the arrival on the next pose.
    pub arrival: f64,
}

impl Interval<'_> {
    fn gap(&self) -> f64 {
        (self.to.frame - self.from.frame) as f64
    }

    /// Lays the approach simulation `sim` (from the first keystroke, LoA Eq. 2's `t_star` and
    /// correction) onto the interval.
    pub(crate) fn lay(
        &self,
        sim: &Simulation,
        t_star: usize,
        correction: &[f64],
    ) -> Result<Laid, LoaError> {
        let gap = self.gap();
        let length = self
            .from
            .chain
            .total_length()
            .max(self.to.chain.total_length());
        // The approach at the simulation's own speed; slowed down (once, in proportion) when
        // one of its frames would move a chain point by more than the cap.
        let mut arrival = (t_star as f64).min(gap);
        let laid = self.lay_at(sim, t_star, correction, arrival)?;
        let approach = &laid.chains[..(arrival.floor() as usize).min(laid.chains.len())];
        let jump = max_jump(&self.from.chain, approach);
        if arrival >= gap || jump.is_nan() || jump <= MAX_FRAME_MOTION * length {
            return Ok(laid);
        }
        arrival = (arrival * jump / (MAX_FRAME_MOTION * length)).min(gap);
        self.lay_at(sim, t_star, correction, arrival)
    }

    fn lay_at(
        &self,
        sim: &Simulation,
        t_star: usize,
        correction: &[f64],
        arrival: f64,
    ) -> Result<Laid, LoaError> {
        let (gap, options) = (self.gap(), self.options);
        let frame_time = 1.0 / options.fps;
        let speed = t_star as f64 / arrival.max(1e-9);
        let blend = options.blend;
        let mut chains = Vec::with_capacity(gap as usize);
        // Velocity on arrival, in seconds of output time.
        let arrive_velocity: Vec<f64> = sim
            .state_velocity(t_star * options.substeps as usize)
            .iter()
            .zip(correction)
            .map(|(v, d)| v * speed + d * blend.slope(1.0) / (arrival * frame_time))
            .collect();
        let rest = gap - arrival;
        let follow = if rest > 1e-9 {
            let mut from = self.to.clone();
            from.stiffness = self.from.stiffness;
            from.damping = self.from.damping;
            let frames = rest.ceil() as u32 + 1;
            let sim2 = simulate(
                &from,
                self.to.chain.angles(),
                &arrive_velocity,
                frames,
                options,
            )?;
            let end = sim2.angles_at(rest);
            let landing: Vec<f64> = self
                .to
                .chain
                .angles()
                .iter()
                .zip(&end)
                .map(|(a, b)| a - b)
                .collect();
            Some((sim2, landing))
        } else {
            None
        };
        for f in 1..=gap as i64 {
            let t = f as f64;
            let angles: Vec<f64> = if f == gap as i64 {
                self.to.chain.angles().to_vec()
            } else if t <= arrival {
                let tau = t * speed;
                let w = blend.weight(tau / t_star as f64);
                add_scaled(&sim.angles_at(tau), correction, w)
            } else if let Some((sim2, landing)) = &follow {
                let s = t - arrival;
                add_scaled(&sim2.angles_at(s), landing, blend.weight(s / rest))
            } else {
                self.to.chain.angles().to_vec()
            };
            // Root and lengths follow the approach: their Hermite curves are replayed over
            // the approach and hold the next keystroke's during the follow-through.
            let time = self.from.frame as f64 + gap * (t / arrival).min(1.0);
            chains.push(Chain::new(
                self.line.root_at(time),
                angles,
                self.line.lengths_at(time),
            )?);
        }
        let velocity = match &follow {
            None => arrive_velocity,
            Some((sim2, landing)) => {
                let s = (rest * options.substeps as f64).round() as usize;
                sim2.state_velocity(s)
                    .iter()
                    .zip(landing)
                    .map(|(v, d)| v + d * blend.slope(1.0) / (rest * frame_time))
                    .collect()
            }
        };
        if let Some(last) = chains.last_mut() {
            *last = self.to.chain.clone();
        }
        Ok(Laid {
            chains,
            velocity,
            arrival,
        })
    }
}

/// `settle` frames after the last keystroke `key`, entered with `velocity` (rad/s): the
/// springs of `key` pull the line back onto it and a smoothstep window fades the offset out,
/// so the last frame is `key` at rest.
fn settle(
    key: &KeyPose,
    velocity: &[f64],
    settle: u32,
    options: &PhysicsOptions,
) -> Result<Vec<Chain>, LoaError> {
    if settle == 0 {
        return Ok(Vec::new());
    }
    let sim = simulate(key, key.chain.angles(), velocity, settle, options)?;
    let target = key.chain.angles();
    (1..=settle)
        .map(|f| {
            let u = f as f64 / settle as f64;
            let keep = 1.0 - Blend::Smoothstep.weight(u);
            let angles = sim
                .frame(f as usize)
                .iter()
                .zip(target)
                .map(|(a, t)| t + keep * (a - t))
                .collect();
            Chain::new(key.chain.root(), angles, key.chain.lengths().to_vec())
        })
        .collect()
}

/// The first simulated frame `i ≥ 1` whose distance to `target` is not larger than the next
/// frame's (the first local minimum of LoA Eq. 2's objective).
fn first_pass(frames: &[Vec<f64>], target: &[f64]) -> usize {
    let dist = |a: &[f64]| -> f64 { a.iter().zip(target).map(|(x, y)| (x - y) * (x - y)).sum() };
    (1..frames.len())
        .find(|&i| i + 1 >= frames.len() || dist(&frames[i]) <= dist(&frames[i + 1]))
        .unwrap_or(1)
}

fn add_scaled(a: &[f64], d: &[f64], w: f64) -> Vec<f64> {
    a.iter().zip(d).map(|(x, y)| x + w * y).collect()
}

/// Largest distance any chain point moves between consecutive chains (`first` precedes
/// `chains`).
pub(crate) fn max_jump(first: &Chain, chains: &[Chain]) -> f64 {
    let mut prev = first.joints();
    let mut worst: f64 = 0.0;
    for c in chains {
        let joints = c.joints();
        for (a, b) in joints.iter().zip(&prev) {
            worst = worst.max((*a - *b).length());
        }
        prev = joints;
    }
    worst
}
