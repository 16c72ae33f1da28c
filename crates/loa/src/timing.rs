//! How each keyframe interval is laid onto the animator's frames (a toonkit decision; the
//! paper re-times `0..=t*` onto the whole interval; why and what instead:
//! `docs/loa-timing.md`).
//!
//! The keystrokes stay at their frames. Within an interval from pose `γ_A` to `γ_B`
//! (change `Δ = γ_B − γ_A`) the angles are
//!
//! `γ(t) = γ_A + p(t) Δ + d(t)`
//!
//! * `p(t)` — the **progress** along the change, the dominant mode's step response
//!   ([`Progress`]): stiffness sets when the line arrives, damping how far it swings past
//!   the next pose before landing on it at its frame.
//! * `d(t)` — the **shape**: the elastic chain simulated from `γ_A` toward `γ_B` (LoA §3.2,
//!   [`simulate`]) on the progress's time scale, with its component along `Δ` removed (the
//!   progress carries that) — the overlap, anticipation and follow-through of the joints —
//!   and LoA Eq. 2's correction blended in so that it vanishes on the keystroke.
//!
//! The line leaves a keystroke with the shape's velocity, made orthogonal to the next
//! change, so every interval starts where the previous one left it (C1 with the smoothstep
//! blend) and its progress does not depend on how the previous interval ended. The root and
//! the element lengths follow their Hermite curves in real time (LoA §3.2: "for the root
//! position, we simply interpolate the position between keyframes"). After the last
//! keystroke the line settles: the dominant mode's free response to the velocity it arrived
//! with, faded out by a smoothstep window so the last frame is the last keystroke, at rest.

use crate::animation::{Animation, AnimationFrame};
use crate::dynamics::change_frequency;
use crate::hermite::HermiteLine;
use crate::keypose::KeyPose;
use crate::mode::free_response;
use crate::physics::{simulate, PhysicsAnimation, PhysicsOptions, Retarget, SimulatedFrames};
use crate::progress::Progress;
use crate::retarget::{closest_frame, Blend};
use crate::{Chain, LoaError};

/// Changes (radians, Euclidean norm of the angle change) below this are holds: no progress
/// direction.
const HOLD: f64 = 1e-9;
/// Modes of the shape around the frames' Nyquist rate (π radians per output frame) and above
/// would alias into jitter: each mode is weighted by `1 / (1 + (ω/SHAPE_CUTOFF)⁴)` (ω in
/// radians per output frame): ½ at 2.5, 0.28 at π, 0.03 at 2π.
const SHAPE_CUTOFF: f64 = 2.5;
/// Most frames over which the velocity of faded modes is let out after a keystroke.
const RELEASE_FRAMES: f64 = 6.0;
/// Per-frame motion of any chain point the shape is scaled down to keep (fraction of the
/// line's length; the promise is 15 %).
const MAX_JUMP: f64 = 0.145;
/// Bisection steps of the shape's scale.
const SCALE_STEPS: usize = 12;
/// Most simulated frames per output frame for the shape (a near-zero stiffness would
/// otherwise ask for an unbounded simulation).
const MAX_TIME_SCALE: f64 = 64.0;

/// Physically-based interpolation of the key poses (Section 3.2). The result passes exactly
/// through every key pose at its frame; see the module documentation for how each interval
/// is laid out, and [`PhysicsOptions::settle`] for the frames added after the last keystroke.
pub fn interpolate_physics(
    keys: &[KeyPose],
    options: &PhysicsOptions,
) -> Result<PhysicsAnimation, LoaError> {
    options.validate()?;
    let Some(first) = keys.first() else {
        return Err(LoaError::NoKeystrokes);
    };
    let line = HermiteLine::new(keys);
    let mut frames = vec![AnimationFrame {
        frame: first.frame,
        chain: first.chain.clone(),
    }];
    let mut retargets = Vec::with_capacity(keys.len().saturating_sub(1));
    // Angular velocity (radians per frame) leaving the last laid keystroke.
    let mut velocity = vec![0.0; first.chain.elements()];
    for (i, pair) in keys.windows(2).enumerate() {
        let interval = Interval {
            from: &pair[0],
            to: &pair[1],
            next: keys.get(i + 2),
            line: &line,
            options,
        };
        let laid = interval.lay(&velocity)?;
        for (f, chain) in (pair[0].frame + 1..).zip(laid.chains) {
            frames.push(AnimationFrame { frame: f, chain });
        }
        velocity = laid.velocity;
        retargets.push(laid.retarget);
    }
    let last = &keys[keys.len() - 1];
    let key_frames: Vec<i64> = keys.iter().map(|k| k.frame).collect();
    let tail = options.settle.frames(&key_frames);
    let omega = match keys {
        [.., before, last] => {
            let change = difference(last.chain.angles(), before.chain.angles());
            change_frequency(&last.chain, last.stiffness, &change)
        }
        _ => last.stiffness.max(0.0).sqrt(),
    };
    for (f, chain) in (last.frame + 1..).zip(settle(last, omega, &velocity, tail, options.fps)?) {
        frames.push(AnimationFrame { frame: f, chain });
    }
    Ok(PhysicsAnimation {
        animation: Animation::new(options.fps, key_frames, frames),
        retargets,
    })
}

/// One interval between two keystrokes (and the keystroke after it, if any).
struct Interval<'a> {
    from: &'a KeyPose,
    to: &'a KeyPose,
    next: Option<&'a KeyPose>,
    line: &'a HermiteLine,
    options: &'a PhysicsOptions,
}

/// The frames of one interval (after its first keystroke, up to and including the second).
struct Laid {
    chains: Vec<Chain>,
    /// Angular velocity (radians per frame) leaving the second keystroke.
    velocity: Vec<f64>,
    retarget: Retarget,
}

impl Interval<'_> {
    fn lay(&self, velocity: &[f64]) -> Result<Laid, LoaError> {
        let (from, to, options) = (self.from, self.to, self.options);
        let gap = (to.frame - from.frame) as f64;
        let start = from.chain.angles();
        let change = difference(to.chain.angles(), start);
        let axis = unit(&change, HOLD);
        let length = from.chain.total_length().max(to.chain.total_length());
        let reach = if length > 0.0 {
            reach(&from.chain, &change, to.chain.root() - from.chain.root()) / length
        } else {
            0.0
        };
        let omega = change_frequency(&from.chain, from.stiffness, &change);
        let progress = Progress::new(omega, from.damping, gap, options.fps, reach);
        let (t_star, correction, m) = self.closest_frame(velocity)?;

        // The shape: the chain simulated on the progress's time scale, `Δ` removed.
        let rate = progress.time_scale().min(MAX_TIME_SCALE);
        let mut pose = from.clone();
        pose.damping = progress.damping();
        let sim_velocity: Vec<f64> = velocity.iter().map(|v| v * options.fps / rate).collect();
        let sim_frames = (gap * rate).ceil() as u32 + 2;
        let sim = simulate(&pose, to.chain.angles(), &sim_velocity, sim_frames, options)?;
        // Modes faster than the frames can show would strobe: they are faded out.
        let weights: Vec<f64> = sim
            .modal_frequencies()
            .iter()
            .map(|w| 1.0 / (1.0 + (w * rate / options.fps / SHAPE_CUTOFF).powi(4)))
            .collect();
        let shape = |t: f64| -> Vec<f64> {
            let mut d = sim.weighted_motion(t * rate, &weights);
            if let Some(a) = &axis {
                remove(&mut d, a);
            }
            d
        };
        // The part of the arriving velocity those faded modes carried, let out over the
        // first frames so the line leaves the keystroke as it arrived.
        let h = 1e-3;
        let carried = shape(h);
        let lost: Vec<f64> = velocity
            .iter()
            .zip(&carried)
            .map(|(v, c)| v - c / h)
            .collect();
        let release = (0.5 * gap).min(RELEASE_FRAMES);
        // LoA Eq. 2's correction of the shape, blended in so it vanishes on the keystroke.
        let blend = options.blend;
        let landing = shape(gap);
        let mut leave: Vec<f64> = difference(&shape(gap + h), &shape(gap - h))
            .iter()
            .zip(&landing)
            .map(|(v, d)| v / (2.0 * h) - d * blend.slope(1.0) / gap)
            .collect();
        // Leave the keystroke orthogonal to the next change too (a kick that fades in over
        // the interval's end and is orthogonal to this change).
        let kick = self.next.and_then(|n| {
            let mut e = difference(n.chain.angles(), to.chain.angles());
            if let Some(a) = &axis {
                remove(&mut e, a);
            }
            let e = unit(&e, HOLD)?;
            let along = dot(&leave, &e);
            for (v, x) in leave.iter_mut().zip(&e) {
                *v -= along * x;
            }
            Some((e, along))
        });

        // Per inner frame: the progress (and the released velocity), and the shape.
        let (mut base, mut part) = (Vec::new(), Vec::new());
        for f in 1..to.frame - from.frame {
            let t = f as f64;
            let p = progress.at(t);
            let g = if t < release {
                t * (1.0 - t / release) * (1.0 - t / release)
            } else {
                0.0
            };
            base.push(
                (0..start.len())
                    .map(|j| start[j] + p * change[j] + g * lost[j])
                    .collect::<Vec<f64>>(),
            );
            let w = blend.weight(t / gap);
            let mut d: Vec<f64> = shape(t)
                .iter()
                .zip(&landing)
                .map(|(d, l)| d - w * l)
                .collect();
            if let Some((e, along)) = &kick {
                // β(t) = −(gap − t)(t/gap)²: 0 with zero slope at the start, slope 1 at the end.
                let beta = -(gap - t) * (t / gap) * (t / gap);
                for (x, y) in d.iter_mut().zip(e) {
                    *x -= beta * along * y;
                }
            }
            part.push(d);
        }
        let frames = Frames {
            interval: self,
            base: &base,
            shape: &part,
        };
        let scale = frames.shape_scale(length)?;
        let chains = frames.chains(scale)?;
        let leave: Vec<f64> = leave.iter().map(|v| v * scale).collect();
        Ok(Laid {
            chains,
            velocity: leave,
            retarget: Retarget {
                from_frame: from.frame,
                to_frame: to.frame,
                simulated_frames: m,
                t_star,
                correction,
                arrival: progress.arrival(),
                overshoot: progress.overshoot(),
                damping: progress.damping(),
                time_scale: progress.time_scale(),
            },
        })
    }

    /// LoA Eq. 2 on the paper's simulation (`M` frames from the keystroke at the spring's own
    /// speed, with the velocity the line arrives with): `t*`, the norm of its correction, `M`.
    fn closest_frame(&self, velocity: &[f64]) -> Result<(usize, f64, u32), LoaError> {
        let (from, to, options) = (self.from, self.to, self.options);
        let m = match options.simulated_frames {
            SimulatedFrames::Fixed(m) => m,
            SimulatedFrames::FrameGap => u32::try_from(to.frame - from.frame).unwrap_or(u32::MAX),
        };
        let per_second: Vec<f64> = velocity.iter().map(|v| v * options.fps).collect();
        let sim = simulate(from, to.chain.angles(), &per_second, m, options)?;
        let whole: Vec<Vec<f64>> = (0..=sim.frames()).map(|i| sim.frame(i)).collect();
        let t_star = closest_frame(&whole, to.chain.angles());
        let offset = difference(to.chain.angles(), &sim.frame(t_star));
        Ok((t_star, dot(&offset, &offset).sqrt(), m))
    }
}

/// An interval's inner frames as progress plus a shape that can be scaled down.
struct Frames<'a, 'b> {
    interval: &'a Interval<'b>,
    base: &'a [Vec<f64>],
    shape: &'a [Vec<f64>],
}

impl Frames<'_, '_> {
    /// The chains of the inner frames and the second keystroke, with the shape scaled by
    /// `scale`.
    fn chains(&self, scale: f64) -> Result<Vec<Chain>, LoaError> {
        let (from, line) = (self.interval.from, self.interval.line);
        let mut chains = Vec::with_capacity(self.base.len() + 1);
        for (f, (b, d)) in self.base.iter().zip(self.shape).enumerate() {
            let time = (from.frame + 1 + f as i64) as f64;
            let angles = b.iter().zip(d).map(|(x, y)| x + scale * y).collect();
            chains.push(Chain::new(
                line.root_at(time),
                angles,
                line.lengths_at(time),
            )?);
        }
        chains.push(self.interval.to.chain.clone());
        Ok(chains)
    }

    /// The most of the shape (a scale in `[0, 1]`) for which no chain point moves more than
    /// [`MAX_JUMP`] of the line's `length` per frame. The shape is orthogonal to the change,
    /// so this never alters the progress.
    fn shape_scale(&self, length: f64) -> Result<f64, LoaError> {
        let limit = MAX_JUMP * length;
        if limit.is_nan() || limit <= 0.0 {
            return Ok(1.0);
        }
        largest(|scale| Ok(max_jump(&self.interval.from.chain, &self.chains(scale)?) <= limit))
    }
}

/// The largest `x` in `[0, 1]` (bisected) for which `fits(x)` holds; 0 when none does.
fn largest(fits: impl Fn(f64) -> Result<bool, LoaError>) -> Result<f64, LoaError> {
    if fits(1.0)? {
        return Ok(1.0);
    }
    if !fits(0.0)? {
        return Ok(0.0);
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..SCALE_STEPS {
        let mid = 0.5 * (lo + hi);
        if fits(mid)? {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(lo)
}

/// Largest distance any chain point moves between consecutive chains (`first` precedes
/// `chains`).
fn max_jump(first: &Chain, chains: &[Chain]) -> f64 {
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

/// `settle` frames after the last keystroke `key`, entered with `velocity` (radians per
/// frame): the dominant mode's free response (natural frequency `omega` rad/s — the chain's
/// along the last change — damping ratio `ζ`), faded out
/// by a smoothstep window so the last frame is `key` at rest.
fn settle(
    key: &KeyPose,
    omega: f64,
    velocity: &[f64],
    settle: u32,
    fps: f64,
) -> Result<Vec<Chain>, LoaError> {
    let natural = omega / fps;
    (1..=settle)
        .map(|f| {
            let t = f as f64;
            let keep = 1.0 - Blend::Smoothstep.weight(t / settle as f64);
            let swing = if natural > 0.0 {
                free_response(natural * t, key.damping) / natural
            } else {
                t
            };
            let angles = key
                .chain
                .angles()
                .iter()
                .zip(velocity)
                .map(|(a, v)| a + keep * swing * v)
                .collect();
            Chain::new(key.chain.root(), angles, key.chain.lengths().to_vec())
        })
        .collect()
}

/// Fastest chain point's motion per unit of progress along `change` from `chain`, over
/// progress −0.25..=2 (the approach and its swing), counting the root's key-to-key `shift`
/// as if it moved with the progress (it follows its curve in real time, but its motion adds
/// to every point's).
fn reach(chain: &Chain, change: &[f64], shift: glam::DVec2) -> f64 {
    let at = |u: f64| -> Vec<glam::DVec2> {
        let angles = chain
            .angles()
            .iter()
            .zip(change)
            .map(|(a, c)| a + u * c)
            .collect();
        Chain::new(chain.root() + u * shift, angles, chain.lengths().to_vec())
            .map(|c| c.joints())
            .unwrap_or_default()
    };
    let du = 0.01;
    (0..=9)
        .map(|i| {
            let u = -0.25 + 0.25 * i as f64;
            let (a, b) = (at(u), at(u + du));
            a.iter()
                .zip(&b)
                .map(|(p, q)| (*q - *p).length() / du)
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max)
}

fn difference(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x - y).collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `v / |v|`, or `None` when `|v|` is below `floor`.
fn unit(v: &[f64], floor: f64) -> Option<Vec<f64>> {
    let n = dot(v, v).sqrt();
    (n > floor && n.is_finite()).then(|| v.iter().map(|x| x / n).collect())
}

/// Removes the component of `v` along the unit vector `axis`.
fn remove(v: &mut [f64], axis: &[f64]) {
    let along = dot(v, axis);
    for (x, a) in v.iter_mut().zip(axis) {
        *x -= along * a;
    }
}
