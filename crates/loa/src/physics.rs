//! The elastic simulation of physically-based stroke interpolation (Section 3.2).
//!
//! From each keystroke the elastic chain ([`ElasticChain`]) is simulated for `M` frames with
//! its springs pulling toward the next keystroke's angles, starting with the angular velocity
//! the line arrived with ([`simulate`]). LoA Eq. 2 then picks the simulated frame `t*`
//! closest to the next keystroke and a correction `Δγ = γ(t_k+1) − γ(t*)` is blended in
//! ([`Blend`]); how the result is laid onto the keystrokes' frames (approach,
//! follow-through, settle) is [`interpolate_physics`](crate::interpolate_physics)'s job.
//! The root position and the element lengths are Hermite-interpolated.
//!
//! * **stiffness `k`** (per keystroke, 1/s²): the line turning rigidly about its root
//!   oscillates at `√k` rad/s and its bending modes scale with `√k`.
//! * **damping `ζ`** (per keystroke): `ζ ≥ 1` approaches the target without overshoot (every
//!   mode is at least critically damped); `ζ < 1` lets the slow modes overshoot by about
//!   `exp(−πζ/√(1−ζ²))` and wobble. Because the inertia couples joints, outboard joints lag
//!   and joints whose own target barely changes first swing the opposite way (anticipation).
//! * **simulated frames `M`**: the time window searched by LoA Eq. 2.
//! * **fps**: frame duration `1/fps` s of the simulated frames.
//! * **substeps**: accuracy only (the integrator is stable for any sub-step).

use crate::animation::Animation;
use crate::dynamics::ElasticChain;
use crate::keypose::KeyPose;
use crate::keystroke::{check_positive, DEFAULT_FPS};
use crate::retarget::Blend;
use crate::LoaError;

/// Simulated frames per interval used by the paper (`M = 40`).
pub const DEFAULT_SIMULATED_FRAMES: u32 = 40;
/// Default integration sub-steps per frame.
pub const DEFAULT_SUBSTEPS: u32 = 8;
/// Largest number of simulated sub-steps per interval (simulated frames × sub-steps), to keep
/// memory bounded.
pub const MAX_SIMULATED_STEPS: u64 = 2_000_000;

/// How many frames are simulated from each keystroke.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SimulatedFrames {
    /// A fixed count `M` (the paper uses 40): the window LoA Eq. 2 searches for the
    /// reported `t*`.
    Fixed(u32),
    /// As many frames as the interval has.
    FrameGap,
}

impl Default for SimulatedFrames {
    fn default() -> Self {
        SimulatedFrames::Fixed(DEFAULT_SIMULATED_FRAMES)
    }
}

/// Follow-through after the last keystroke ([`PhysicsOptions::settle`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Settle {
    /// This many frames (0 = the clip ends on the last keystroke).
    Frames(u32),
    /// One key interval: as many frames as between the last two keystrokes (none with a
    /// single keystroke). The default, so the line does not stop dead on the last key.
    #[default]
    KeyInterval,
}

impl Settle {
    /// Frames added after the last of the keystrokes at `key_frames` (increasing).
    pub fn frames(self, key_frames: &[i64]) -> u32 {
        match (self, key_frames) {
            (Settle::Frames(n), _) => n,
            (Settle::KeyInterval, [.., a, b]) => u32::try_from(b - a).unwrap_or(u32::MAX),
            (Settle::KeyInterval, _) => 0,
        }
    }
}

/// Options of the physically-based interpolation.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PhysicsOptions {
    /// Frames per second (simulated frame duration `1/fps` s).
    pub fps: f64,
    /// Integration sub-steps per frame (≥ 1).
    pub substeps: u32,
    /// Simulated frames per interval.
    pub simulated_frames: SimulatedFrames,
    /// Blend of the re-targeting correction.
    pub blend: Blend,
    /// Frames of follow-through added after the last keystroke (default one key interval;
    /// `Frames(0)` ends on it); they end on the last keystroke, at rest.
    pub settle: Settle,
}

impl Default for PhysicsOptions {
    fn default() -> Self {
        Self {
            fps: DEFAULT_FPS,
            substeps: DEFAULT_SUBSTEPS,
            simulated_frames: SimulatedFrames::default(),
            blend: Blend::default(),
            settle: Settle::default(),
        }
    }
}

impl PhysicsOptions {
    pub(crate) fn validate(&self) -> Result<(), LoaError> {
        check_positive("fps", self.fps)?;
        if self.substeps == 0 {
            return Err(LoaError::InvalidParameter {
                name: "substeps",
                value: 0.0,
                expected: "at least 1 sub-step per frame",
            });
        }
        if self.simulated_frames == SimulatedFrames::Fixed(0) {
            return Err(LoaError::InvalidParameter {
                name: "simulated_frames",
                value: 0.0,
                expected: "at least 1 simulated frame",
            });
        }
        Ok(())
    }
}

/// A forward simulation sampled at every sub-step. States are kept in the modal coordinates
/// of the [`ElasticChain`] and turned into angles on demand.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    elements: usize,
    substeps: u32,
    step: f64,
    target: Vec<f64>,
    to_angles: Vec<f64>,
    /// Undamped frequency (rad/s) of each modal coordinate.
    omega: Vec<f64>,
    z: Vec<f64>,
    zdot: Vec<f64>,
}

impl Simulation {
    /// Sub-steps per frame.
    pub fn substeps(&self) -> u32 {
        self.substeps
    }

    /// Sub-step duration in seconds.
    pub fn step(&self) -> f64 {
        self.step
    }

    /// Number of stored states (`frames × substeps + 1`).
    pub fn states(&self) -> usize {
        self.z.len() / self.elements.max(1)
    }

    fn to_angles(&self, z: &[f64], offset: bool) -> Vec<f64> {
        let mut out = vec![0.0; self.elements];
        crate::dynamics::apply(&self.to_angles, self.elements, z, &mut out);
        if offset {
            for (o, t) in out.iter_mut().zip(&self.target) {
                *o += t;
            }
        }
        out
    }

    fn modal<'a>(&self, data: &'a [f64], s: usize) -> &'a [f64] {
        let n = self.elements;
        let s = s.min(self.states().saturating_sub(1));
        &data[s * n..(s + 1) * n]
    }

    /// Angles at sub-step state `s`.
    pub fn state(&self, s: usize) -> Vec<f64> {
        self.to_angles(self.modal(&self.z, s), true)
    }

    /// Angular velocities (rad/s) at sub-step state `s`.
    pub fn state_velocity(&self, s: usize) -> Vec<f64> {
        self.to_angles(self.modal(&self.zdot, s), false)
    }

    /// Angles at whole simulated frame `i`.
    pub fn frame(&self, i: usize) -> Vec<f64> {
        self.state(i * self.substeps as usize)
    }

    /// Number of whole simulated frames after the start.
    pub fn frames(&self) -> usize {
        (self.states() - 1) / self.substeps as usize
    }

    /// Angles at fractional simulated frame `tau` (cubic Hermite between sub-steps, using the
    /// simulated velocities).
    pub fn angles_at(&self, tau: f64) -> Vec<f64> {
        self.to_angles(&self.modal_at(tau), true)
    }

    /// Undamped frequencies (rad/s) of the modal coordinates, in the simulation's order.
    pub(crate) fn modal_frequencies(&self) -> &[f64] {
        &self.omega
    }

    /// The motion of the angles from the start to fractional frame `tau`, each mode `i`
    /// weighted by `weights[i]` (1 keeps it, 0 leaves it out).
    pub(crate) fn weighted_motion(&self, tau: f64, weights: &[f64]) -> Vec<f64> {
        let (now, start) = (self.modal_at(tau), self.modal(&self.z, 0));
        let z: Vec<f64> = (0..self.elements)
            .map(|j| weights[j] * (now[j] - start[j]))
            .collect();
        self.to_angles(&z, false)
    }

    /// Modal state at fractional simulated frame `tau` (cubic Hermite between sub-steps).
    fn modal_at(&self, tau: f64) -> Vec<f64> {
        let last = self.states() - 1;
        let s = (tau * self.substeps as f64).clamp(0.0, last as f64);
        let i = (s.floor() as usize).min(last.saturating_sub(1));
        let u = s - i as f64;
        if last == 0 || u == 0.0 {
            return self.modal(&self.z, i).to_vec();
        }
        let h = self.step;
        let (u2, u3) = (u * u, u * u * u);
        let (h00, h10, h01, h11) = (
            2.0 * u3 - 3.0 * u2 + 1.0,
            u3 - 2.0 * u2 + u,
            -2.0 * u3 + 3.0 * u2,
            u3 - u2,
        );
        let (a0, a1) = (self.modal(&self.z, i), self.modal(&self.z, i + 1));
        let (v0, v1) = (self.modal(&self.zdot, i), self.modal(&self.zdot, i + 1));
        (0..self.elements)
            .map(|j| h00 * a0[j] + h10 * h * v0[j] + h01 * a1[j] + h11 * h * v1[j])
            .collect()
    }
}

/// Forward-simulates `frames` frames of the elastic chain starting at `from` (with angular
/// velocities `velocities`, rad/s) and pulled toward `target` angles, using the stiffness and
/// damping of `from`.
pub fn simulate(
    from: &KeyPose,
    target: &[f64],
    velocities: &[f64],
    frames: u32,
    options: &PhysicsOptions,
) -> Result<Simulation, LoaError> {
    options.validate()?;
    if frames as u64 * options.substeps as u64 > MAX_SIMULATED_STEPS {
        return Err(LoaError::InvalidParameter {
            name: "simulated frames × substeps",
            value: frames as f64 * options.substeps as f64,
            expected: "at most 2,000,000 sub-steps per interval",
        });
    }
    let mut chain = ElasticChain::new(&from.chain, from.stiffness, from.damping)?;
    chain.set_target(target);
    chain.set_state(from.chain.angles(), velocities);
    let step = 1.0 / (options.fps * options.substeps as f64);
    let count = frames as usize * options.substeps as usize;
    let n = chain.elements();
    let mut z = Vec::with_capacity((count + 1) * n);
    let mut zdot = Vec::with_capacity((count + 1) * n);
    let record = |chain: &ElasticChain, z: &mut Vec<f64>, zdot: &mut Vec<f64>| {
        let (a, v) = chain.modal_state();
        z.extend_from_slice(a);
        zdot.extend_from_slice(v);
    };
    record(&chain, &mut z, &mut zdot);
    for _ in 0..count {
        chain.step(step);
        record(&chain, &mut z, &mut zdot);
    }
    Ok(Simulation {
        elements: n,
        substeps: options.substeps,
        step,
        target: chain.target().to_vec(),
        to_angles: chain.modal_to_angles().to_vec(),
        omega: chain.modal_frequencies().to_vec(),
        z,
        zdot,
    })
}

/// What the re-targeting did on one keyframe interval.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Retarget {
    /// Frame of the interval's first keystroke.
    pub from_frame: i64,
    /// Frame of the interval's second keystroke.
    pub to_frame: i64,
    /// Simulated frames `M`.
    pub simulated_frames: u32,
    /// The closest simulated frame `t*` of LoA Eq. 2.
    pub t_star: usize,
    /// Euclidean norm of the correction `Δγ` (radians).
    pub correction: f64,
    /// Output frames after `from_frame` until the line first reaches the next pose (the
    /// dominant mode's first arrival; the whole interval when it only gets there on the
    /// keystroke). Earlier with more stiffness.
    pub arrival: f64,
    /// Largest swing past the next pose on the interval's frames, as a fraction of the
    /// key-to-key change (the dominant mode's, before landing). Smaller with more damping.
    pub overshoot: f64,
    /// Damping ratio used: the keystroke's, raised when the interval is too short for its
    /// swing to land within the per-frame motion cap.
    pub damping: f64,
    /// Time scale over the spring's own: above 1 the approach was sped up to arrive inside
    /// the interval, below 1 slowed down by the per-frame motion cap.
    pub time_scale: f64,
}

/// The physically interpolated line and what the re-targeting did per interval.
#[derive(Debug, Clone, PartialEq)]
pub struct PhysicsAnimation {
    /// One chain per frame from the first keystroke to the last.
    pub animation: Animation,
    /// One entry per keyframe interval.
    pub retargets: Vec<Retarget>,
}
