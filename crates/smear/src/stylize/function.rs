//! Stylization functions as written in a style: a preset chain or a user expression.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::error::StyleError;
use super::expr::Expression;
use super::param::Param;
use super::stage::{apply_stages, apply_stages_block, Stage};
use super::units::StyleUnits;
use crate::effects::{StyleBlock, StyleInput, Stylize};

/// A stylization function as written in a style file: either `stages` (a preset chain, see
/// [`Stage`]) or `expr` (a user expression over the inputs of
/// [`EXPRESSION_INPUTS`](super::expr::EXPRESSION_INPUTS) and the declared `params`). Compile
/// it once with [`FunctionSpec::compile`].
///
/// TOML: `function = { stages = [{ op = "speed" }, { op = "scale", by = 6 }] }` or
/// `function = { expr = "beta * speed * delta", params = { beta = 6 } }`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FunctionSpec {
    /// Preset chain applied to δ; empty with no `expr` = the identity S(δ) = δ.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub stages: Vec<Stage>,
    /// A user expression (exclusive with `stages`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub expr: Option<String>,
    /// κ of the `noise` input of `expr` (default 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kappa: Option<Param>,
    /// Seed of the `noise` input of `expr`.
    #[serde(skip_serializing_if = "is_zero")]
    pub seed: u64,
    /// Named keyframeable constants usable in `expr`.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub params: BTreeMap<String, Param>,
}

fn is_zero(x: &u64) -> bool {
    *x == 0
}

impl FunctionSpec {
    /// A preset chain.
    pub fn stages(stages: Vec<Stage>) -> Self {
        FunctionSpec {
            stages,
            ..Default::default()
        }
    }

    /// A user expression with named (possibly keyframed) parameters.
    pub fn expr(text: &str, params: &[(&str, Param)]) -> Self {
        FunctionSpec {
            expr: Some(text.to_string()),
            params: params
                .iter()
                .map(|(k, v)| (k.to_string(), v.clone()))
                .collect(),
            ..Default::default()
        }
    }

    /// S_E(δ; β_max) = β_max·δ (SMEAR Eq. 10; also S_L(δ; τ_max) = τ_max·δ, SMEAR Eq. 13).
    pub fn linear(beta_max: impl Into<Param>) -> Self {
        Self::stages(vec![Stage::Scale {
            by: beta_max.into(),
        }])
    }

    /// S_E^speed(δ; v, β_max) = β_max‖v‖δ (Fig. 11c).
    pub fn speed(beta_max: impl Into<Param>) -> Self {
        Self::stages(vec![
            Stage::Speed,
            Stage::Scale {
                by: beta_max.into(),
            },
        ])
    }

    /// S_E^noise(δ−; v, κ, β_max) = β_max‖v‖F1(p(0), κ)δ− (Fig. 11d).
    pub fn noise(kappa: impl Into<Param>, beta_max: impl Into<Param>) -> Self {
        Self::stages(vec![
            Stage::Past,
            Stage::Speed,
            Stage::Noise {
                kappa: kappa.into(),
                seed: 0,
            },
            Stage::Scale {
                by: beta_max.into(),
            },
        ])
    }

    /// S_M(δ, m; m_max) of SMEAR Eq. 12.
    pub fn multiples(m_max: impl Into<Param>) -> Self {
        Self::stages(vec![Stage::Multiples {
            m_max: m_max.into(),
        }])
    }

    /// Checks and compiles the function.
    ///
    /// Returns [`StyleError::ExprAndStages`] when both forms are given, the stage or
    /// expression errors otherwise.
    pub fn compile(&self) -> Result<StyleFunction, StyleError> {
        match &self.expr {
            Some(_) if !self.stages.is_empty() => Err(StyleError::ExprAndStages),
            Some(text) => Ok(StyleFunction::Expr(Box::new(Expression::compile(
                text,
                self.kappa.clone().unwrap_or(Param::Constant(1.0)),
                self.seed,
                self.params.clone(),
            )?))),
            None => {
                for (i, s) in self.stages.iter().enumerate() {
                    s.validate(i)?;
                }
                Ok(StyleFunction::Stages(self.stages.clone()))
            }
        }
    }
}

impl FunctionSpec {
    /// [`FunctionSpec::compile`] for a style in `units` (see [`StyleUnits`]): preset chains
    /// are rewritten in scene units, expressions convert their inputs; the result is
    /// multiplied by `output` (the scene length of a style length for a thickness, else 1).
    /// In [`StyleUnits::SCENE`] with `output` 1 this is [`FunctionSpec::compile`], bit for bit.
    ///
    /// # Errors
    /// As [`FunctionSpec::compile`].
    pub fn compile_in(&self, units: &StyleUnits, output: f64) -> Result<StyleFunction, StyleError> {
        Ok(match self.compile()? {
            StyleFunction::Stages(s) => StyleFunction::Stages(units.stages_to_scene(&s, output)),
            StyleFunction::Expr(e) => StyleFunction::Expr(Box::new(e.in_units(units, output))),
        })
    }
}

/// A compiled stylization function, ready for per-vertex evaluation from many threads.
#[derive(Debug, Clone)]
pub enum StyleFunction {
    /// A preset chain.
    Stages(Vec<Stage>),
    /// A compiled user expression.
    Expr(Box<Expression>),
}

impl StyleFunction {
    /// `Err` when this is a user expression that was NaN or infinite somewhere since the last
    /// check, naming it with the frame and the `item` (`"vertex"`, `"motion line"`).
    ///
    /// # Errors
    /// [`StyleError::NotFinite`].
    pub fn check_finite(&self, item: &'static str) -> Result<(), StyleError> {
        match self {
            StyleFunction::Stages(_) => Ok(()),
            StyleFunction::Expr(e) => e.check_finite(item),
        }
    }
}

impl Stylize for StyleFunction {
    #[inline]
    fn eval(&self, x: &StyleInput) -> f32 {
        match self {
            StyleFunction::Stages(s) => apply_stages(s, x),
            StyleFunction::Expr(e) => e.evaluate(x),
        }
    }

    fn eval_block(&self, block: &StyleBlock<'_>, out: &mut [f32]) {
        match self {
            StyleFunction::Stages(s) => apply_stages_block(s, block, out),
            StyleFunction::Expr(e) => {
                for (k, o) in out.iter_mut().enumerate() {
                    *o = e.evaluate(&block.input(k));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use rayon::prelude::*;

    fn samples() -> Vec<StyleInput> {
        (0..500)
            .map(|k| {
                let f = k as f32;
                StyleInput {
                    delta: ((f * 0.37).sin()).clamp(-1.0, 1.0),
                    speed: (f * 0.11).cos().abs() * 0.3,
                    velocity: Vec3::new(0.1, 0.0, 0.2),
                    weight: (k % 7) as f32 / 6.0,
                    rest: Vec3::new(f * 0.013, (f * 0.7).sin(), 0.2),
                    frame: (k % 40) as f32,
                    m: [-2.0, -1.0, 1.0, 2.0][k % 4],
                    vertex: k as u32,
                    t: (k % 11) as f32 / 10.0,
                }
            })
            .collect()
    }

    fn assert_same(a: &FunctionSpec, b: &FunctionSpec) {
        let (fa, fb) = (a.compile().unwrap(), b.compile().unwrap());
        let xs = samples();
        let va: Vec<f32> = xs.par_iter().map(|x| fa.eval(x)).collect();
        let vb: Vec<f32> = xs.par_iter().map(|x| fb.eval(x)).collect();
        let nonzero = va.iter().filter(|v| v.abs() > 1e-4).count();
        assert!(nonzero > 25, "only {nonzero} non-zero values");
        for (k, (x, y)) in va.iter().zip(&vb).enumerate() {
            assert!(
                (x - y).abs() < 1e-4 * (1.0 + x.abs()),
                "sample {k}: {x} vs {y}"
            );
        }
    }

    #[test]
    fn expressions_match_presets() {
        assert_same(
            &FunctionSpec::linear(2.0),
            &FunctionSpec::expr("2 * delta", &[]),
        );
        assert_same(
            &FunctionSpec::speed(6.0),
            &FunctionSpec::expr("b * speed * delta", &[("b", 6.0.into())]),
        );
        let mut noise = FunctionSpec::expr("10 * speed * noise * min(delta, 0)", &[]);
        noise.kappa = Some(18.0.into());
        assert_same(&FunctionSpec::noise(18.0, 10.0), &noise);
        // Fig. 15's multiples S_M(10‖v‖ω δ−, m; m_max), here with m_max = 2 (no degenerate δ_m).
        let fig15 = FunctionSpec::stages(vec![
            Stage::Past,
            Stage::Weight,
            Stage::Speed,
            Stage::Scale { by: 10.0.into() },
            Stage::Multiples { m_max: 2.0.into() },
        ]);
        let x = "min(10 * speed * weight * delta, 0)";
        // SMEAR Eq. 12 written out with δ_m = (|m| − 1)/2; H(0) = 0.
        let sm = format!(
            "step(m * {x}) * step(abs({x}) - 0.000001) \
             * smoothstep((abs({x}) - (abs(m) - 1) / 2) / (1 - (abs(m) - 1) / 2))"
        );
        let sm_spec = FunctionSpec::expr(&sm, &[]);
        assert_same(&fig15, &sm_spec);
        // Fig. 12: S_E^speed on warped offsets δ'(0.5, 0.8), against the warp formula
        // written out (c = 3, p = 0.8).
        let warp = FunctionSpec::stages(vec![
            Stage::Warp {
                s: 0.5.into(),
                p: 0.8.into(),
            },
            Stage::Speed,
            Stage::Scale { by: 3.0.into() },
        ]);
        let y = "((delta + 1) / 2)";
        let c = format!(
            "step(0.8 - {y}) * {y}^3 / 0.8^2 + step({y} - 0.8) * (1 - (1 - {y})^3 / 0.2^2)"
        );
        let e = format!("3 * speed * (2 * ({c}) - 1)");
        assert_same(&warp, &FunctionSpec::expr(&e, &[]));
    }

    #[test]
    fn both_forms_is_an_error() {
        let mut f = FunctionSpec::linear(1.0);
        f.expr = Some("delta".into());
        assert_eq!(f.compile().unwrap_err(), StyleError::ExprAndStages);
        assert_eq!(
            FunctionSpec::default()
                .compile()
                .unwrap()
                .eval(&samples()[3]),
            samples()[3].delta
        );
    }
}
