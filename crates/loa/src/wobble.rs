//! Drag-to-wobble: an impulse applied to a point of the line at one frame, left to settle.
//!
//! The users of the paper asked to "grab the line in order to wobble it as an elastic"
//! (Section 5). Because the elastic model is linear within an interval, the wobble is an
//! offset `e(t)` solving `M ë + D ė + K e = 0` with `e(0) = 0` and `ė(0) = M⁻¹ Jᵀ P` (the
//! impulse `P` at the grabbed point, `J` its Jacobian), added on top of the animation from the
//! grabbed frame on. The animation is extended with the last pose held until the wobble has
//! settled.

use glam::DVec2;

use crate::animation::{Animation, AnimationFrame};
use crate::dynamics::ElasticChain;
use crate::keystroke::{check_positive, DEFAULT_DAMPING, DEFAULT_STIFFNESS};
use crate::{Chain, LoaError};

/// Longest settling tail added after the animation's end, in seconds.
pub const MAX_SETTLE_SECONDS: f64 = 10.0;
/// The wobble counts as settled once every angle offset is below this (radians) and the
/// energy is below this fraction of the initial energy.
pub const SETTLE_TOLERANCE: f64 = 1e-4;

/// An impulse applied to the line.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Wobble {
    /// Frame at which the line is hit.
    pub frame: i64,
    /// Where along the line, as a fraction of its length (0 = first point, 1 = last).
    pub at: f64,
    /// The impulse (screen units per second for the line's unit mass): the velocity a free
    /// point of that mass would get.
    pub impulse: DVec2,
    /// Angular stiffness `k` (1/s²) of the wobble.
    pub stiffness: f64,
    /// Damping ratio `ζ` of the wobble (must be > 0 to settle).
    pub damping: f64,
}

impl Wobble {
    /// A wobble with the default stiffness and damping.
    pub fn new(frame: i64, at: f64, impulse: DVec2) -> Self {
        Self {
            frame,
            at,
            impulse,
            stiffness: DEFAULT_STIFFNESS,
            damping: DEFAULT_DAMPING,
        }
    }
}

impl std::str::FromStr for Wobble {
    type Err = LoaError;
    /// `FRAME:S:DX,DY`: hit frame, arc-length position `S ∈ [0, 1]` along the line, and the
    /// impulse in screen units per second (default stiffness and damping).
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let bad = || LoaError::Wobble(text.to_string());
        let parts: Vec<&str> = text.split(':').collect();
        let [frame, at, impulse] = parts[..] else {
            return Err(bad());
        };
        let number = |x: &str| x.trim().parse::<f64>().ok().filter(|v| v.is_finite());
        let frame = number(frame)
            .filter(|f| f.fract() == 0.0 && f.abs() < 1e15)
            .ok_or_else(bad)? as i64;
        let at = number(at)
            .filter(|u| (0.0..=1.0).contains(u))
            .ok_or_else(bad)?;
        let (dx, dy) = impulse.split_once(',').ok_or_else(bad)?;
        let impulse = DVec2::new(number(dx).ok_or_else(bad)?, number(dy).ok_or_else(bad)?);
        Ok(Wobble::new(frame, at, impulse))
    }
}

/// Adds the wobble to `animation` (see the module documentation), integrating with
/// `substeps` sub-steps per frame.
pub fn wobble(
    animation: &Animation,
    wobble: &Wobble,
    substeps: u32,
) -> Result<Animation, LoaError> {
    check_positive("damping", wobble.damping)?;
    check_positive("stiffness", wobble.stiffness)?;
    check_positive("fps", animation.fps)?;
    if substeps == 0 {
        return Err(LoaError::InvalidParameter {
            name: "substeps",
            value: 0.0,
            expected: "at least 1 sub-step per frame",
        });
    }
    let pose = animation
        .chain_at(wobble.frame)
        .ok_or(LoaError::InvalidParameter {
            name: "wobble frame",
            value: wobble.frame as f64,
            expected: "a frame inside the animation",
        })?
        .clone();
    let n = pose.elements();
    let mut sim = ElasticChain::new(&pose, wobble.stiffness, wobble.damping)?;
    let zeros = vec![0.0; n];
    sim.set_target(&zeros);
    sim.set_state(&zeros, &zeros);
    sim.apply_impulse(&pose, wobble.at, wobble.impulse);
    let initial_energy = sim.energy();
    let h = 1.0 / (animation.fps * substeps as f64);
    let mut out = animation.clone();
    let start = out
        .frames
        .iter()
        .position(|f| f.frame == wobble.frame)
        .unwrap_or(out.frames.len());
    let offset = |chain: &Chain, e: &[f64]| -> Result<Chain, LoaError> {
        let angles = chain.angles().iter().zip(e).map(|(a, d)| a + d).collect();
        Chain::new(chain.root(), angles, chain.lengths().to_vec())
    };
    for frame in out.frames.iter_mut().skip(start + 1) {
        for _ in 0..substeps {
            sim.step(h);
        }
        frame.chain = offset(&frame.chain, &sim.angles())?;
    }
    let settled = |s: &ElasticChain| {
        s.angles().iter().all(|e| e.abs() < SETTLE_TOLERANCE)
            && s.energy() <= SETTLE_TOLERANCE * initial_energy
    };
    let (Some(last), max_tail) = (
        animation.frames.last().cloned(),
        ((MAX_SETTLE_SECONDS * animation.fps).ceil() as i64).min(100_000),
    ) else {
        return Ok(out);
    };
    let mut frame = last.frame;
    while !settled(&sim) && frame - last.frame < max_tail {
        for _ in 0..substeps {
            sim.step(h);
        }
        frame += 1;
        out.frames.push(AnimationFrame {
            frame,
            chain: offset(&last.chain, &sim.angles())?,
        });
    }
    Ok(out)
}
