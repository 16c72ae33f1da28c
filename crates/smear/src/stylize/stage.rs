//! Composable preset stages: the paper's stylization functions S_E, S_M, S_L (SMEAR Eqs. 10–13) and
//! their Section 5 variants as a chain of small operations on one value.

use serde::{Deserialize, Serialize};

use super::error::StyleError;
use super::param::Param;
use super::voronoi::voronoi_f1;
use super::warp::warp_offset;
use crate::effects::{multiple_opacity, StyleBlock, StyleInput, STYLE_BLOCK};

/// One operation of a preset chain. The chain starts from x = δ and applies its stages in
/// order; e.g. `[past, speed, noise(κ = 18), scale(10)]` is Fig. 11d's
/// S_E^noise(δ−; v, 18, 10) = 10‖v‖F1(p(0), 18)δ−.
///
/// In TOML each stage is a table with an `op` key: `{ op = "scale", by = 2 }`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "op", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Stage {
    /// x ← 2·C_{s,p}((x + 1)/2) − 1: Hise's warp (Section 5.2, Fig. 12), s ∈ [0, 1) strength,
    /// p ∈ (0, 1) direction (p > 0.5 toward the past).
    Warp {
        /// Strength s ∈ [0, 1).
        s: Param,
        /// Pivot p ∈ (0, 1).
        p: Param,
    },
    /// x ← min(x, 0): past-only offsets δ− (Fig. 11d, 15).
    Past,
    /// x ← max(x, 0): future-only offsets δ+.
    Future,
    /// x ← k·x: β_max of S_E (SMEAR Eq. 10), τ_max of S_L (SMEAR Eq. 13), or any gain.
    Scale {
        /// The factor k.
        by: Param,
    },
    /// x ← ‖v‖·x: the speed weighting of S_E^speed (Fig. 11c); ‖v‖ in the style's units
    /// (size units per second by default, scene units per frame with
    /// `speed_units = "scene"`).
    Speed,
    /// x ← ω·x: painted weights ω ∈ [0, 1] (Fig. 15b).
    Weight,
    /// x ← F1(p(0), κ)·x: Voronoi noise at the rest position (Fig. 11d).
    Noise {
        /// Scale κ applied to the rest position (per size unit, per scene unit with
        /// `speed_units = "scene"`).
        kappa: Param,
        /// Seed of the feature-point jitter.
        #[serde(default)]
        seed: u64,
    },
    /// x ← H(‖v‖ − v_min)·x: zero below a speed (Fig. 1 multiples and lines).
    Threshold {
        /// Speed v_min in size units per second (scene units per frame with
        /// `speed_units = "scene"`).
        min_speed: Param,
    },
    /// x ← S_M(x, m; m_max) = H(x·m)·S((|x| − δ_m)/(1 − δ_m)), δ_m = (|m| − 1)/m_max (SMEAR Eq. 12,
    /// [`multiple_opacity`](crate::multiple_opacity)): past copies (m < 0) show trailing
    /// vertices only, future copies leading ones.
    Multiples {
        /// m_max of SMEAR Eq. 12 (> 0).
        m_max: Param,
    },
    /// x ← (1 − t)·x: fades along a motion line from its start to its end (Fig. 15e).
    Fade,
    /// x ← value: a constant (e.g. a line thickness), or a fresh start for later stages.
    Set {
        /// The value.
        value: Param,
    },
}

impl Stage {
    /// Checks parameter ranges. `i` is the stage index, used in error names.
    pub fn validate(&self, i: usize) -> Result<(), StyleError> {
        let name = |p: &str| format!("stages[{i}].{p}");
        match self {
            Stage::Warp { s, p } => {
                s.validate(&name("s"), (0.0, false), (1.0, true))?;
                p.validate(&name("p"), (0.0, true), (1.0, true))
            }
            Stage::Scale { by } => by.validate_finite(&name("by")),
            Stage::Noise { kappa, .. } => kappa.validate(&name("kappa"), (0.0, true), (1e9, false)),
            Stage::Threshold { min_speed } => min_speed.validate_finite(&name("min_speed")),
            Stage::Set { value } => value.validate_finite(&name("value")),
            Stage::Multiples { m_max } => m_max.validate(&name("m_max"), (0.0, true), (1e9, false)),
            Stage::Past | Stage::Future | Stage::Speed | Stage::Weight | Stage::Fade => Ok(()),
        }
    }

    /// Applies the stage to `x` with the inputs `i`.
    #[inline]
    pub fn apply(&self, x: f32, i: &StyleInput) -> f32 {
        match self {
            Stage::Warp { s, p } => warp_offset(x, s.at(i.frame), p.at(i.frame)),
            Stage::Past => x.min(0.0),
            Stage::Future => x.max(0.0),
            Stage::Scale { by } => x * by.at(i.frame),
            Stage::Speed => x * i.speed,
            Stage::Weight => x * i.weight,
            // F1 is finite, so a zero (a past-only stage's future, a still vertex) stays
            // the same zero without the 27 cell hashes.
            Stage::Noise { .. } if x == 0.0 => x,
            Stage::Noise { kappa, seed } => x * voronoi_f1(i.rest, kappa.at(i.frame), *seed),
            Stage::Threshold { min_speed } => {
                if i.speed >= min_speed.at(i.frame) {
                    x
                } else {
                    0.0
                }
            }
            Stage::Multiples { m_max } => multiple_opacity(x, i.m, m_max.at(i.frame)),
            Stage::Fade => x * (1.0 - i.t.clamp(0.0, 1.0)),
            Stage::Set { value } => value.at(i.frame),
        }
    }
}

/// Evaluates a chain: x = δ, then every stage in order. Non-finite results become 0.
#[inline]
pub fn apply_stages(stages: &[Stage], i: &StyleInput) -> f32 {
    let x = stages.iter().fold(i.delta, |x, s| s.apply(x, i));
    if x.is_finite() {
        x
    } else {
        0.0
    }
}

/// [`apply_stages`] at every point of a run (`out.len()` = `block.len()`), stage by stage over
/// the run: each stage's parameters are read once, the speeds computed only when a stage reads
/// them. Every point goes through the same operations in the same order as [`apply_stages`],
/// so the values are the same bit for bit.
pub fn apply_stages_block(stages: &[Stage], block: &StyleBlock<'_>, out: &mut [f32]) {
    assert_eq!(out.len(), block.len(), "one value per point of the run");
    let mut start = 0;
    for chunk in out.chunks_mut(STYLE_BLOCK) {
        let run = block.part(start, chunk.len());
        apply_run(stages, &run, chunk);
        start += chunk.len();
    }
}

/// [`apply_stages_block`] on a run of at most [`STYLE_BLOCK`] points.
fn apply_run(stages: &[Stage], run: &StyleBlock<'_>, x: &mut [f32]) {
    let frame = run.frame();
    x.copy_from_slice(run.deltas());
    let mut speeds = Speeds::new(x.len());
    for stage in stages {
        match stage {
            Stage::Warp { s, p } => {
                let (s, p) = (s.at(frame), p.at(frame));
                x.iter_mut().for_each(|x| *x = warp_offset(*x, s, p));
            }
            Stage::Past => x.iter_mut().for_each(|x| *x = x.min(0.0)),
            Stage::Future => x.iter_mut().for_each(|x| *x = x.max(0.0)),
            Stage::Scale { by } => {
                let by = by.at(frame);
                x.iter_mut().for_each(|x| *x *= by);
            }
            Stage::Speed => {
                for (x, v) in x.iter_mut().zip(speeds.of(run)) {
                    *x *= v;
                }
            }
            Stage::Weight => match run.weights() {
                Some(w) => x.iter_mut().zip(w).for_each(|(x, w)| *x *= w),
                None => x.iter_mut().for_each(|x| *x *= 1.0),
            },
            Stage::Noise { kappa, seed } => {
                let kappa = kappa.at(frame);
                for (x, rest) in x.iter_mut().zip(run.rest()) {
                    // As in `Stage::apply`: a zero stays the same zero.
                    if *x != 0.0 {
                        *x *= voronoi_f1(*rest, kappa, *seed);
                    }
                }
            }
            Stage::Threshold { min_speed } => {
                let min = min_speed.at(frame);
                for (x, v) in x.iter_mut().zip(speeds.of(run)) {
                    // As in `Stage::apply`: a NaN speed is below every threshold.
                    *x = if *v >= min { *x } else { 0.0 };
                }
            }
            Stage::Multiples { m_max } => {
                let (m, m_max) = (run.m(), m_max.at(frame));
                x.iter_mut()
                    .for_each(|x| *x = multiple_opacity(*x, m, m_max));
            }
            // A run's points are vertices, at t = 0 of no motion line: x·(1 − 0) is x.
            Stage::Fade => {}
            Stage::Set { value } => x.fill(value.at(frame)),
        }
    }
    for x in x.iter_mut() {
        if !x.is_finite() {
            *x = 0.0;
        }
    }
}

/// The speeds of a run, computed the first time a stage reads them.
struct Speeds {
    values: [f32; STYLE_BLOCK],
    len: usize,
    ready: bool,
}

impl Speeds {
    fn new(len: usize) -> Self {
        Speeds {
            values: [0.0; STYLE_BLOCK],
            len,
            ready: false,
        }
    }

    fn of(&mut self, run: &StyleBlock<'_>) -> &[f32] {
        let values = &mut self.values[..self.len];
        if !self.ready {
            run.speeds(values);
            self.ready = true;
        }
        values
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn input(delta: f32, speed: f32) -> StyleInput {
        StyleInput {
            delta,
            speed,
            weight: 1.0,
            ..Default::default()
        }
    }

    #[test]
    fn eq12_multiples_stage() {
        // m_max = 2: δ_1 = 0, δ_2 = 0.5.
        let st = [Stage::Multiples { m_max: 2.0.into() }];
        let at = |delta: f32, m: f32| {
            let i = StyleInput {
                delta,
                m,
                ..Default::default()
            };
            apply_stages(&st, &i)
        };
        assert_eq!(at(-0.5, -1.0), 0.5); // S(0.5) = 0.5
        assert_eq!(at(0.5, -1.0), 0.0); // leading vertex, past copy
        assert_eq!(at(-0.5, 1.0), 0.0); // trailing vertex, future copy
                                        // m = 2, δ = 0.75: S((0.75 − 0.5)/0.5) = S(0.5) = 0.5; δ = 0.4 < δ_2 → 0.
        assert_eq!(at(0.75, 2.0), 0.5);
        assert_eq!(at(0.4, 2.0), 0.0);
    }

    #[test]
    fn fig11_presets_by_hand() {
        let i = StyleInput {
            rest: Vec3::new(0.1, 0.2, 0.3),
            ..input(-0.5, 0.2)
        };
        let linear = [Stage::Scale { by: 2.0.into() }];
        assert_eq!(apply_stages(&linear, &i), -1.0); // Fig. 11b: S_E(δ; 2)
        let speed = [Stage::Speed, Stage::Scale { by: 6.0.into() }];
        assert!((apply_stages(&speed, &i) + 0.6).abs() < 1e-6); // Fig. 11c: 6·0.2·(−0.5)
        let noise = [
            Stage::Past,
            Stage::Speed,
            Stage::Noise {
                kappa: 18.0.into(),
                seed: 0,
            },
            Stage::Scale { by: 10.0.into() },
        ];
        let f1 = voronoi_f1(i.rest, 18.0, 0);
        assert!((apply_stages(&noise, &i) - 10.0 * 0.2 * f1 * -0.5).abs() < 1e-6);
        // δ− removes leading offsets.
        assert_eq!(apply_stages(&noise, &input(0.7, 1.0)), 0.0);
        let future = [Stage::Future];
        assert_eq!(apply_stages(&future, &input(-0.7, 1.0)), 0.0);
        assert_eq!(apply_stages(&future, &input(0.7, 1.0)), 0.7);
    }

    #[test]
    fn threshold_weight_fade_and_keyframes() {
        let st = [
            Stage::Threshold {
                min_speed: 0.1.into(),
            },
            Stage::Weight,
            Stage::Scale {
                by: Param::Curve(vec![[0.0, 0.0], [10.0, 10.0]]),
            },
        ];
        let mut i = input(0.5, 0.05);
        i.weight = 0.5;
        i.frame = 4.0;
        assert_eq!(apply_stages(&st, &i), 0.0); // below v_min
        i.speed = 0.1;
        assert!((apply_stages(&st, &i) - 0.5 * 0.5 * 4.0).abs() < 1e-6);
        i.t = 0.25;
        assert!((apply_stages(&[Stage::Fade], &i) - 0.375).abs() < 1e-6);
    }

    #[test]
    fn validation_names_the_stage() {
        let bad = Stage::Warp {
            s: 1.0.into(),
            p: 0.5.into(),
        };
        let e = bad.validate(3).unwrap_err().to_string();
        assert!(e.contains("stages[3].s"), "{e}");
        let bad = Stage::Multiples { m_max: 0.0.into() };
        assert!(bad.validate(0).is_err());
    }
}
