//! The named presets of the elongation S_E (SMEAR Section 5.2, Fig. 11) and the defaults and
//! documented ranges of the parameters every front end shows. They are defined here once: the
//! CLI's flags take their defaults from these constants, the Python module exposes them
//! (`toonkit.smear.presets()`, `toonkit.smear.parameters()`), the Blender panel and the
//! studio's controls are built from that table, so one preset with the same parameters is the
//! same smear everywhere.

use serde::{Deserialize, Serialize};

use super::function::FunctionSpec;
use super::param::Param;
use super::stage::Stage;
use crate::{DEFAULT_LINE_COUNT, DEFAULT_SEED, DEFAULT_SMOOTH, DEFAULT_SPACING};

/// Default β_max of the elongation presets, in frames along the trajectory (SMEAR Eq. 10):
/// one frame, the CLI's since its first release (farm renders rely on it).
pub const DEFAULT_BETA_MAX: f32 = 1.0;

/// Default Voronoi scale κ of the `noise` preset (the value of SMEAR Fig. 11d).
pub const DEFAULT_KAPPA: f32 = 18.0;

/// Default τ_max of the motion lines, in frames along the trajectory (SMEAR Eq. 13).
pub const DEFAULT_LINE_LENGTH: f32 = 1.0;

/// Default number of copies in the past (m_p) and in the future (m_n) of the multiples.
pub const DEFAULT_COPIES: f32 = 1.0;

/// A named preset of the elongation S_E (SMEAR Section 5.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ElongatePreset {
    /// S_E(δ; β_max) = β_max·δ (SMEAR Eq. 10 example, Fig. 9b, 11b): the default, which
    /// needs no speed, so β is in frames in any units.
    #[default]
    Linear,
    /// S_E(δ; v, β_max) = β_max‖v‖δ (Fig. 11c): fast parts stretch, slow parts stay put.
    Speed,
    /// S_E(δ⁻; v, κ, β_max) = β_max‖v‖F1(p(0), κ)δ⁻ (Fig. 11d): a ragged trailing smear.
    Noise,
}

impl ElongatePreset {
    /// Every preset, in the order front ends list them.
    pub const ALL: [ElongatePreset; 3] = [
        ElongatePreset::Linear,
        ElongatePreset::Speed,
        ElongatePreset::Noise,
    ];

    /// The preset's name in styles, flags and the Python module.
    pub fn name(self) -> &'static str {
        match self {
            ElongatePreset::Linear => "linear",
            ElongatePreset::Speed => "speed",
            ElongatePreset::Noise => "noise",
        }
    }

    /// The preset of that name.
    pub fn from_name(name: &str) -> Option<ElongatePreset> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    /// One line for a menu or a tooltip.
    pub fn doc(self) -> &'static str {
        match self {
            ElongatePreset::Linear => "β = β max · δ (SMEAR Eq. 10, Fig. 11b)",
            ElongatePreset::Speed => "β = β max · |v| · δ: fast parts stretch (SMEAR Fig. 11c)",
            ElongatePreset::Noise => {
                "β = β max · |v| · F1(κ) · δ−: a ragged trailing smear (SMEAR Fig. 11d)"
            }
        }
    }

    /// The parameters (names of [`PARAMETERS`]) the preset reads.
    pub fn parameters(self) -> &'static [&'static str] {
        match self {
            ElongatePreset::Linear | ElongatePreset::Speed => &["beta_max"],
            ElongatePreset::Noise => &["beta_max", "kappa"],
        }
    }

    /// The preset's stage chain with these parameters (`kappa` is read by `noise` only).
    pub fn function(self, beta_max: impl Into<Param>, kappa: impl Into<Param>) -> FunctionSpec {
        match self {
            ElongatePreset::Linear => FunctionSpec::linear(beta_max),
            ElongatePreset::Speed => FunctionSpec::speed(beta_max),
            ElongatePreset::Noise => FunctionSpec::noise(kappa, beta_max),
        }
    }

    /// The preset's stage chain with the default parameters.
    pub fn default_function(self) -> FunctionSpec {
        self.function(DEFAULT_BETA_MAX, DEFAULT_KAPPA)
    }

    /// The stage chain of the preset without its own δ± restriction, for front ends that
    /// offer the restriction as a separate choice (the Blender panel's "Offsets").
    pub fn unsigned_stages(
        self,
        beta_max: impl Into<Param>,
        kappa: impl Into<Param>,
    ) -> Vec<Stage> {
        self.function(beta_max, kappa)
            .stages
            .into_iter()
            .filter(|s| !matches!(s, Stage::Past | Stage::Future))
            .collect()
    }
}

/// A parameter a front end shows: its default and the range its control offers.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Parameter {
    /// The name in styles, Python keyword arguments and (with `-` for `_`) CLI flags.
    pub name: &'static str,
    /// The default every front end starts from.
    pub default: f64,
    /// The smallest value a control offers.
    pub min: f64,
    /// The largest value a slider offers (larger values may be typed where the core accepts
    /// them).
    pub max: f64,
    /// Whether the value is a whole number.
    pub integer: bool,
    /// One line for a tooltip.
    pub doc: &'static str,
}

/// The style parameters every front end shows, with their defaults and documented ranges.
pub const PARAMETERS: &[Parameter] = &[
    Parameter {
        name: "smooth",
        default: DEFAULT_SMOOTH as f64,
        min: 0.0,
        max: 10.0,
        integer: true,
        doc: "Temporal smoothing half-window N of the offsets (SMEAR Eq. 2; 0 = off)",
    },
    Parameter {
        name: "beta_max",
        default: DEFAULT_BETA_MAX as f64,
        min: 0.0,
        max: 30.0,
        integer: false,
        doc: "Largest elongation β max, in frames along the trajectory (SMEAR Eq. 10); the speed and noise presets multiply it by the speed in character sizes (bounding-box diagonals) per second",
    },
    Parameter {
        name: "kappa",
        default: DEFAULT_KAPPA as f64,
        min: 0.01,
        max: 100.0,
        integer: false,
        doc: "Noise frequency κ of the noise preset: Voronoi F1 cells per character size (bounding-box diagonal; SMEAR Fig. 11d)",
    },
    Parameter {
        name: "past",
        default: DEFAULT_COPIES as f64,
        min: 0.0,
        max: 16.0,
        integer: true,
        doc: "Copies in the past m_p of the multiples (SMEAR Eq. 11)",
    },
    Parameter {
        name: "future",
        default: DEFAULT_COPIES as f64,
        min: 0.0,
        max: 16.0,
        integer: true,
        doc: "Copies in the future m_n of the multiples (SMEAR Eq. 11)",
    },
    Parameter {
        name: "spacing",
        default: DEFAULT_SPACING as f64,
        min: 0.01,
        max: 4.0,
        integer: false,
        doc: "Temporal spacing Δf between copies, in frames (SMEAR Eq. 11)",
    },
    Parameter {
        name: "count",
        default: DEFAULT_LINE_COUNT as f64,
        min: 0.0,
        max: 2000.0,
        integer: true,
        doc: "Number of motion lines K (random surface points, area-weighted)",
    },
    Parameter {
        name: "length_max",
        default: DEFAULT_LINE_LENGTH as f64,
        min: 0.0,
        max: 50.0,
        integer: false,
        doc: "Longest motion line τ max, in frames along the trajectory (SMEAR Eq. 13)",
    },
    Parameter {
        name: "seed",
        default: DEFAULT_SEED as f64,
        min: 0.0,
        // The largest seed every front end holds (Blender's properties are 32-bit signed).
        max: i32::MAX as f64,
        integer: true,
        doc: "Seed of every random choice (same seed, same lines)",
    },
];

/// The parameter of that name in [`PARAMETERS`].
pub fn parameter(name: &str) -> Option<&'static Parameter> {
    PARAMETERS.iter().find(|p| p.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_reads_only_listed_parameters_and_defaults_lie_in_their_ranges() {
        for p in ElongatePreset::ALL {
            assert_eq!(ElongatePreset::from_name(p.name()), Some(p));
            for name in p.parameters() {
                assert!(parameter(name).is_some(), "{name}");
            }
            p.default_function().compile().unwrap();
        }
        for p in PARAMETERS {
            assert!(p.min <= p.default && p.default <= p.max, "{}", p.name);
            assert!(!p.integer || p.default.fract() == 0.0, "{}", p.name);
        }
    }

    #[test]
    fn fig11d_noise_preset_trails_and_the_unsigned_chain_drops_only_the_restriction() {
        let full = ElongatePreset::Noise.function(10.0, 18.0).stages;
        assert_eq!(full[0], Stage::Past);
        let unsigned = ElongatePreset::Noise.unsigned_stages(10.0, 18.0);
        assert_eq!(unsigned, full[1..].to_vec());
    }
}
