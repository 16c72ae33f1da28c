//! The units a style's speeds and lengths are measured in (`docs/smear-units.md`).
//!
//! By default a style means the same on any character: one *size* unit is the character's
//! bounding-box diagonal (or a length the user gives), speeds are in size units per second.
//! `speed_units = "scene"` keeps the paper's scene units per frame (SPEC: velocities are
//! central differences per frame). The conversion happens once, when a style is compiled
//! against a prepared scene: preset chains get their numbers rewritten into scene units
//! (so the per-vertex work is the paper's), expressions get their inputs converted.

use serde::{Deserialize, Serialize};

use super::param::Param;
use super::stage::Stage;

/// What a style's speeds (`speed`, `vx, vy, vz`, `threshold`, `lines.min_speed`) and
/// lengths (`x, y, z`, noise κ, `lines.thickness`, `contact.ground`) are measured in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SpeedUnits {
    /// The character's own size: lengths in size units (one unit = the rest-pose
    /// bounding-box diagonal, or --size-reference), speeds in size units per second. The
    /// same style looks the same on a character modelled in centimetres or in metres.
    #[default]
    Size,
    /// The scene's units: lengths in scene units, speeds in scene units per frame (the
    /// paper's convention: the numbers of SMEAR Figs. 11–16 are tuned on one scale).
    Scene,
}

impl SpeedUnits {
    /// Whether this is the default (size units), for serde's `skip_serializing_if`.
    pub fn is_size(&self) -> bool {
        *self == SpeedUnits::Size
    }
}

/// What one size unit is when a style is in [`SpeedUnits::Size`].
///
/// TOML: `size_reference = 1.8` (a length in scene units) or `size_reference = "Body"` (the
/// bounding-box diagonal of that object at its rest pose). Without it: the bounding-box
/// diagonal of every object of the scene at the rest pose (`anim::SampledScene::rest_diagonal`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum SizeReference {
    /// A length in scene units (> 0).
    Length(f32),
    /// An object (mesh) of the scene: its bounding-box diagonal at its rest pose.
    Node(String),
}

/// Command-line form: a number is a length, anything else names an object.
impl std::str::FromStr for SizeReference {
    type Err = String;

    fn from_str(s: &str) -> Result<SizeReference, String> {
        match s.trim().parse::<f32>() {
            Ok(v) if v.is_finite() && v > 0.0 => Ok(SizeReference::Length(v)),
            Ok(v) => Err(format!("a size reference length must be > 0, got {v}")),
            Err(_) if s.trim().is_empty() => Err("give a length or an object name".into()),
            Err(_) => Ok(SizeReference::Node(s.trim().to_string())),
        }
    }
}

/// The conversion of a style's numbers into the scene's units for one prepared scene.
///
/// `speed` multiplies a speed in scene units per frame into the style's speed unit,
/// `length` is the scene length of one of the style's length units. Both are 1 in
/// [`SpeedUnits::Scene`], where nothing is converted at all.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StyleUnits {
    /// Style speed per scene speed: fps / size for size units per second.
    pub speed: f64,
    /// Scene units per style length unit: the size.
    pub length: f64,
}

impl Default for StyleUnits {
    fn default() -> Self {
        StyleUnits::SCENE
    }
}

impl StyleUnits {
    /// Scene units per frame: no conversion.
    pub const SCENE: StyleUnits = StyleUnits {
        speed: 1.0,
        length: 1.0,
    };

    /// Size units per second for a character of `size` scene units sampled at `fps`.
    /// A degenerate size (zero, not finite) counts as 1 scene unit so that results stay
    /// defined; a degenerate frame rate as 1.
    pub fn size(size: f64, fps: f64) -> StyleUnits {
        let size = if size.is_finite() && size > 0.0 {
            size
        } else {
            1.0
        };
        let fps = if fps.is_finite() && fps > 0.0 {
            fps
        } else {
            1.0
        };
        StyleUnits {
            speed: fps / size,
            length: size,
        }
    }

    /// Whether nothing is converted.
    pub fn is_scene(&self) -> bool {
        *self == StyleUnits::SCENE
    }

    /// A style speed in scene units per frame.
    pub fn speed_to_scene(&self, p: &Param) -> Param {
        scaled(p, 1.0 / self.speed)
    }

    /// A style length in scene units.
    pub fn length_to_scene(&self, v: f32) -> f32 {
        (v as f64 * self.length) as f32
    }

    /// A keyframeable style length in scene units.
    pub fn length_param_to_scene(&self, p: &Param) -> Param {
        scaled(p, self.length)
    }

    /// A preset chain in scene units whose result is multiplied by `output` (the scene
    /// length of one size unit for a thickness, 1 for dimensionless results).
    ///
    /// The speed factor of every `speed` stage travels down the chain through the stages
    /// that commute with a positive factor (past, future, weight, noise, threshold, fade,
    /// more speed) and is multiplied into the next `scale` — so `[speed, scale 1.85]` on a
    /// character whose factor is 3.24 runs as the paper's `[speed, scale 6]`; before a
    /// stage that does not commute (warp, multiples) it becomes a `scale` of its own.
    /// Thresholds compare the scene speed against the converted v_min, noise reads the
    /// scene position with κ converted.
    pub fn stages_to_scene(&self, stages: &[Stage], output: f64) -> Vec<Stage> {
        let mut out = Vec::with_capacity(stages.len() + 1);
        let mut pending = 1.0f64;
        let flush = |out: &mut Vec<Stage>, pending: &mut f64| {
            if *pending != 1.0 {
                out.push(Stage::Scale {
                    by: Param::Constant(*pending as f32),
                });
                *pending = 1.0;
            }
        };
        for s in stages {
            match s {
                Stage::Speed => {
                    pending *= self.speed;
                    out.push(Stage::Speed);
                }
                Stage::Scale { by } => {
                    out.push(Stage::Scale {
                        by: scaled(by, pending),
                    });
                    pending = 1.0;
                }
                Stage::Set { value } => {
                    // The running value is dropped: so is its pending factor.
                    pending = 1.0;
                    out.push(Stage::Set {
                        value: value.clone(),
                    });
                }
                Stage::Threshold { min_speed } => out.push(Stage::Threshold {
                    min_speed: self.speed_to_scene(min_speed),
                }),
                Stage::Noise { kappa, seed } => out.push(Stage::Noise {
                    kappa: scaled(kappa, 1.0 / self.length),
                    seed: *seed,
                }),
                Stage::Past | Stage::Future | Stage::Weight | Stage::Fade => out.push(s.clone()),
                Stage::Warp { .. } | Stage::Multiples { .. } => {
                    flush(&mut out, &mut pending);
                    out.push(s.clone());
                }
            }
        }
        pending *= output;
        if pending != 1.0 {
            let folded = match out.last_mut() {
                Some(Stage::Scale { by: p }) | Some(Stage::Set { value: p }) => {
                    *p = scaled(p, pending);
                    true
                }
                _ => false,
            };
            if !folded {
                flush(&mut out, &mut pending);
            }
        }
        out
    }
}

/// `p × k`, computed in f64 and rounded once (a factor of 1 leaves every bit as it was).
pub(super) fn scaled(p: &Param, k: f64) -> Param {
    if k == 1.0 {
        return p.clone();
    }
    let f = |v: f32| (v as f64 * k) as f32;
    match p {
        Param::Constant(v) => Param::Constant(f(*v)),
        Param::Curve(keys) => Param::Curve(keys.iter().map(|&[t, v]| [t, f(v)]).collect()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::StyleInput;
    use crate::stylize::stage::apply_stages;

    #[test]
    fn fig11c_speed_folds_into_beta() {
        let u = StyleUnits::size(7.5, 24.0);
        let size = [Stage::Speed, Stage::Scale { by: 2.0.into() }];
        let scene = u.stages_to_scene(&size, 1.0);
        assert_eq!(scene.len(), 2);
        let x = StyleInput {
            delta: 0.5,
            speed: 0.1,
            ..Default::default()
        };
        // β = 2 frames per (diagonal per second) = 2·24/7.5 = 6.4 per (unit per frame).
        assert!((apply_stages(&scene, &x) - 6.4 * 0.1 * 0.5).abs() < 1e-6);
        assert_eq!(StyleUnits::SCENE.stages_to_scene(&size, 1.0), size.to_vec());
    }

    #[test]
    fn non_commuting_stages_take_the_factor_first() {
        let u = StyleUnits::size(2.0, 10.0);
        let st = [
            Stage::Speed,
            Stage::Multiples { m_max: 1.0.into() },
            Stage::Threshold {
                min_speed: 1.0.into(),
            },
        ];
        let scene = u.stages_to_scene(&st, 1.0);
        assert_eq!(scene[1], Stage::Scale { by: 5.0.into() });
        assert_eq!(
            scene[3],
            Stage::Threshold {
                min_speed: 0.2.into()
            }
        );
        // A thickness of 0.01 diagonals on a character of 2 units is 0.02 units.
        let t = u.stages_to_scene(&[Stage::Set { value: 0.01.into() }], u.length);
        assert_eq!(t, vec![Stage::Set { value: 0.02.into() }]);
    }

    #[test]
    fn size_references_parse_and_degenerate_sizes_stay_defined() {
        assert_eq!("2.5".parse(), Ok(SizeReference::Length(2.5)));
        assert_eq!("Body".parse(), Ok(SizeReference::Node("Body".into())));
        assert!("-1".parse::<SizeReference>().is_err());
        assert!(" ".parse::<SizeReference>().is_err());
        assert_eq!(StyleUnits::size(0.0, 24.0).length, 1.0);
        assert!(StyleUnits::size(f64::NAN, f64::INFINITY).speed.is_finite());
    }
}
