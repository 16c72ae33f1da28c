//! User stylization expressions (paper G3: "more experienced artists can freely create their
//! own" functions), compiled once with `exmex` and evaluated per vertex.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};

use exmex::{BinOp, Express, FlatEx, FloatOpsFactory, MakeOperators, Operator};

use super::error::StyleError;
use super::param::Param;
use super::units::{scaled, StyleUnits};
use super::voronoi::voronoi_f1;
use super::warp::warp_offset;
use crate::effects::StyleInput;

/// Most variables (inputs + parameters) one expression may use.
pub const MAX_EXPRESSION_VARIABLES: usize = 32;

/// Names of the inputs an expression may read, in the order of the expression slots that read them.
pub const EXPRESSION_INPUTS: [&str; 13] = [
    "delta", "speed", "weight", "noise", "frame", "m", "t", "vx", "vy", "vz", "x", "y", "z",
];

/// exmex's float operators plus `step(x)` (Heaviside, 1 for x ≥ 0), `smoothstep(x)` (on x
/// clamped to [0, 1]), `clamp01(x)`, `past(x)` = min(x, 0), `future(x)` = max(x, 0) and
/// `hise(δ, s)` (Hise's warp δ'(s, 0.5); other pivots: the `warp` stage). Binary operators are
/// written as functions: `min(a, b)`, `max(a, b)`, `atan2(y, x)`.
#[derive(Debug, Clone)]
pub struct StyleOps;

impl MakeOperators<f64> for StyleOps {
    fn make<'a>() -> Vec<Operator<'a, f64>> {
        let mut ops = FloatOpsFactory::<f64>::make();
        ops.push(Operator::make_unary("step", |a| {
            if a >= 0.0 {
                1.0
            } else {
                0.0
            }
        }));
        ops.push(Operator::make_unary("smoothstep", |a| {
            let x = a.clamp(0.0, 1.0);
            x * x * (3.0 - 2.0 * x)
        }));
        ops.push(Operator::make_unary("clamp01", |a| a.clamp(0.0, 1.0)));
        ops.push(Operator::make_unary("past", |a| a.min(0.0)));
        ops.push(Operator::make_unary("future", |a| a.max(0.0)));
        ops.push(Operator::make_bin(
            "hise",
            BinOp {
                // hise(δ, s): Hise's warp with pivot 0.5 (the paper's Fig. 1 δ'(0.8, 0.5)).
                apply: |d, s| warp_offset(d as f32, s as f32, 0.5) as f64,
                prio: 0,
                is_commutative: false,
            },
        ));
        ops
    }
}

/// Where each variable of a compiled expression takes its value from.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Slot {
    /// Index into [`EXPRESSION_INPUTS`].
    Input(usize),
    /// Index into the declared parameters.
    Param(usize),
}

/// A compiled user expression over [`EXPRESSION_INPUTS`] and declared keyframeable parameters.
///
/// ```
/// use smear::{Expression, StyleInput, Stylize};
/// let f = Expression::compile("beta * speed * min(delta, 0)", 1.0.into(), 0,
///     [("beta".to_string(), 15.0.into())].into_iter().collect())?;
/// let x = StyleInput { delta: -0.5, speed: 0.2, ..Default::default() };
/// assert!((f.eval(&x) + 1.5).abs() < 1e-6);
/// # Ok::<(), smear::StyleError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Expression {
    text: String,
    flat: FlatEx<f64, StyleOps>,
    slots: Vec<Slot>,
    params: Vec<Param>,
    kappa: Param,
    seed: u64,
    uses_noise: bool,
    /// Style units per scene unit of the inputs, and the output factor (all 1 in scene
    /// units): see [`Expression::in_units`].
    units: Option<InputUnits>,
    /// The first place the expression was not finite since the last
    /// [`Expression::take_non_finite`].
    non_finite: FirstNonFinite,
}

/// The smallest (frame, vertex) at which an expression evaluated to NaN or an infinity,
/// shared by the threads evaluating it. Keyed as `frame << 32 | vertex` and kept with
/// `fetch_min`, so the place reported does not depend on the threads' order.
#[derive(Debug)]
struct FirstNonFinite(AtomicU64);

impl FirstNonFinite {
    const NONE: u64 = u64::MAX;

    fn new() -> Self {
        FirstNonFinite(AtomicU64::new(Self::NONE))
    }

    fn record(&self, frame: f32, vertex: u32) {
        let key = ((frame.max(0.0) as u64) << 32) | vertex as u64;
        self.0.fetch_min(key, Ordering::Relaxed);
    }

    fn take(&self) -> Option<(u32, u32)> {
        let key = self.0.swap(Self::NONE, Ordering::Relaxed);
        (key != Self::NONE).then_some(((key >> 32) as u32, key as u32))
    }
}

impl Clone for FirstNonFinite {
    /// A copy of a compiled expression has seen nothing yet.
    fn clone(&self) -> Self {
        Self::new()
    }
}

/// Factors applied to an expression's inputs and result (style units, `docs/smear-units.md`).
#[derive(Debug, Clone, Copy, PartialEq)]
struct InputUnits {
    /// Style speed per scene speed (`speed`, `vx, vy, vz`).
    speed: f64,
    /// Style length per scene length (`x, y, z`).
    length: f64,
    /// Scene units of the result per style unit.
    output: f64,
}

impl Expression {
    /// Parses and checks `text`.
    ///
    /// Arguments: `kappa` and `seed` define the `noise` input (Voronoi F1 at the rest position
    /// scaled by κ); `params` are named, keyframeable constants.
    ///
    /// Returns [`StyleError::Expression`] on a syntax error, [`StyleError::UnknownVariable`]
    /// for a name that is neither an input nor a parameter, [`StyleError::Parameter`] for a
    /// parameter that shadows an input or is not finite.
    pub fn compile(
        text: &str,
        kappa: Param,
        seed: u64,
        params: BTreeMap<String, Param>,
    ) -> Result<Self, StyleError> {
        if let Err(over) = anim::check_budget(
            "expression length (bytes)",
            text.len() as u64,
            anim::budget::DEFAULT_MAX_EXPRESSION_LEN,
            "write a shorter expression, or name its constants under params",
        ) {
            let head: String = text.chars().take(40).collect();
            return Err(StyleError::Expression {
                expr: format!("{head}…"),
                problem: over.to_string(),
            });
        }
        let problem = |p: String| StyleError::Expression {
            expr: text.to_string(),
            problem: p,
        };
        if text.trim().is_empty() {
            return Err(problem("empty expression".into()));
        }
        kappa.validate("kappa", (0.0, true), (1e9, false))?;
        for (name, p) in &params {
            if EXPRESSION_INPUTS.contains(&name.as_str()) {
                return Err(StyleError::Parameter {
                    name: name.clone(),
                    problem: "has the name of an input; rename it".into(),
                });
            }
            p.validate_finite(name)?;
        }
        let flat = FlatEx::<f64, StyleOps>::parse(&expand_exponents(text))
            .map_err(|e| problem(e.to_string()))?;
        let names: Vec<&String> = params.keys().collect();
        let mut slots = Vec::new();
        for v in flat.var_names() {
            let slot = if let Some(i) = EXPRESSION_INPUTS.iter().position(|n| n == v) {
                Slot::Input(i)
            } else if let Some(i) = names.iter().position(|n| *n == v) {
                Slot::Param(i)
            } else {
                let mut known: Vec<&str> = EXPRESSION_INPUTS.to_vec();
                known.extend(names.iter().map(|s| s.as_str()));
                return Err(StyleError::UnknownVariable {
                    expr: text.to_string(),
                    name: v.clone(),
                    known: known.join(", "),
                });
            };
            slots.push(slot);
        }
        if slots.len() > MAX_EXPRESSION_VARIABLES {
            return Err(problem(format!(
                "uses {} variables, at most {MAX_EXPRESSION_VARIABLES} are supported",
                slots.len()
            )));
        }
        if slots.is_empty() {
            // A constant: NaN or infinity here would be NaN or infinity at every vertex of
            // every frame (silently drawn as 0): say so now.
            match flat.eval(&[]) {
                Ok(x) if !x.is_finite() => {
                    return Err(problem(format!(
                        "is {} at every frame and vertex (a division by zero, or log/sqrt of \
                         a negative number): write a finite value",
                        if x.is_nan() { "NaN" } else { "infinite" }
                    )))
                }
                _ => {}
            }
        }
        let uses_noise = slots.contains(&Slot::Input(3));
        Ok(Expression {
            text: text.to_string(),
            flat,
            slots,
            params: params.into_values().collect(),
            kappa,
            seed,
            uses_noise,
            units: None,
            non_finite: FirstNonFinite::new(),
        })
    }

    /// The expression reading its inputs in a style's units: `speed` and `vx, vy, vz`
    /// multiplied by `units.speed`, `x, y, z` divided by `units.length`, the `noise` κ
    /// per style length; the result is multiplied by `output` (e.g. `units.length` for a
    /// thickness). [`StyleUnits::SCENE`] with `output` 1 changes nothing.
    pub fn in_units(mut self, units: &StyleUnits, output: f64) -> Self {
        if units.is_scene() && output == 1.0 {
            return self;
        }
        // κ per style length as κ per scene length (the noise reads scene positions).
        self.kappa = scaled(&self.kappa, 1.0 / units.length);
        self.units = Some(InputUnits {
            speed: units.speed,
            length: 1.0 / units.length,
            output,
        });
        self
    }

    /// The expression text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// Evaluates at one vertex. A result that is not finite (a division by zero, the log of a
    /// negative number at some vertices) gives 0, so the geometry stays defined, and its frame
    /// and vertex are kept: the job reports the first of them
    /// ([`Expression::take_non_finite`]) instead of drawing those zeros silently.
    ///
    /// Performance: no allocation; ~100 ns plus 50 ns when `noise` is used.
    pub fn evaluate(&self, i: &StyleInput) -> f32 {
        let noise = if self.uses_noise {
            voronoi_f1(i.rest, self.kappa.at(i.frame), self.seed)
        } else {
            0.0
        };
        let inputs = [
            i.delta,
            i.speed,
            i.weight,
            noise,
            i.frame,
            i.m,
            i.t,
            i.velocity.x,
            i.velocity.y,
            i.velocity.z,
            i.rest.x,
            i.rest.y,
            i.rest.z,
        ];
        let mut vars = [0.0f64; MAX_EXPRESSION_VARIABLES];
        for (v, s) in vars.iter_mut().zip(&self.slots) {
            *v = match *s {
                Slot::Input(k) => inputs[k] as f64,
                Slot::Param(k) => self.params[k].at(i.frame) as f64,
            };
        }
        let mut output = 1.0;
        if let Some(u) = &self.units {
            for (v, s) in vars.iter_mut().zip(&self.slots) {
                match *s {
                    // speed, vx, vy, vz
                    Slot::Input(1 | 7..=9) => *v *= u.speed,
                    // x, y, z
                    Slot::Input(10..=12) => *v *= u.length,
                    _ => {}
                }
            }
            output = u.output;
        }
        match self.flat.eval(&vars[..self.slots.len()]) {
            Ok(x) if (x * output).is_finite() => (x * output) as f32,
            _ => {
                self.non_finite.record(i.frame, i.vertex);
                0.0
            }
        }
    }

    /// The first (frame, vertex) — smallest frame, then vertex — at which the expression was
    /// not finite since the last call, and forgets it.
    pub fn take_non_finite(&self) -> Option<(u32, u32)> {
        self.non_finite.take()
    }

    /// `Err` naming the expression, the frame and the `item` (`"vertex"`, `"motion line"`)
    /// where it was first not finite since the last check.
    ///
    /// # Errors
    /// [`StyleError::NotFinite`].
    pub fn check_finite(&self, item: &'static str) -> Result<(), StyleError> {
        match self.take_non_finite() {
            None => Ok(()),
            Some((frame, index)) => Err(StyleError::NotFinite {
                expr: self.text.clone(),
                frame,
                item,
                index,
            }),
        }
    }
}

impl crate::effects::Stylize for Expression {
    fn eval(&self, x: &StyleInput) -> f32 {
        self.evaluate(x)
    }
}

/// Rewrites scientific literals (`1e-3`, `2.5E4`) as plain decimals, which the expression
/// parser reads (it would take the `e` for a variable). Identifiers such as `x1e3` are kept.
fn expand_exponents(text: &str) -> String {
    let b = text.as_bytes();
    let ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        let starts_number = (b[i].is_ascii_digit() || b[i] == b'.')
            && (i == 0 || !(ident(b[i - 1]) || b[i - 1] == b'.'));
        if !starts_number {
            let c = text[i..].chars().next().unwrap_or(' ');
            out.push(c);
            i += c.len_utf8();
            continue;
        }
        let mut j = i;
        while j < b.len() && (b[j].is_ascii_digit() || b[j] == b'.') {
            j += 1;
        }
        let mut k = j;
        if k < b.len() && (b[k] == b'e' || b[k] == b'E') {
            k += 1;
            if k < b.len() && (b[k] == b'+' || b[k] == b'-') {
                k += 1;
            }
            let digits = k;
            while k < b.len() && b[k].is_ascii_digit() {
                k += 1;
            }
            let whole = k > digits && (k == b.len() || !ident(b[k]));
            if let (true, Ok(v)) = (whole, text[i..k].parse::<f64>()) {
                out.push_str(&format!("{v}"));
                i = k;
                continue;
            }
        }
        out.push_str(&text[i..j]);
        i = j;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn compile(text: &str) -> Result<Expression, StyleError> {
        Expression::compile(text, 1.0.into(), 0, BTreeMap::new())
    }

    #[test]
    fn scientific_literals_are_numbers() {
        assert_eq!(
            expand_exponents("1e-3 * x1e3 + 2.5E2"),
            "0.001 * x1e3 + 250"
        );
        assert_eq!(expand_exponents("delta*1e+2-.5e1"), "delta*100-5");
        assert_eq!(expand_exponents("3e + 1"), "3e + 1");
        let e = compile("delta * 1e-3").unwrap();
        let x = StyleInput {
            delta: 2.0,
            ..Default::default()
        };
        assert!((e.evaluate(&x) - 0.002).abs() < 1e-9);
    }

    #[test]
    fn every_input_is_readable() {
        let i = StyleInput {
            delta: 0.5,
            speed: 2.0,
            velocity: Vec3::new(1.0, 2.0, 3.0),
            weight: 0.25,
            rest: Vec3::new(4.0, 5.0, 6.0),
            frame: 7.0,
            m: -2.0,
            t: 0.75,
            vertex: 0,
        };
        for (name, want) in [
            ("delta", 0.5),
            ("speed", 2.0),
            ("weight", 0.25),
            ("frame", 7.0),
            ("m", -2.0),
            ("t", 0.75),
            ("vx + 10*vy + 100*vz", 321.0),
            ("x + 10*y + 100*z", 654.0),
            (
                "step(delta) + smoothstep(0.5) + past(-delta) + future(-delta)",
                1.0,
            ),
            ("min(delta, 0) + max(delta, 1) + abs(m)", 3.0),
        ] {
            let got = compile(name).unwrap().evaluate(&i);
            assert!((got - want).abs() < 1e-5, "{name}: {got} != {want}");
        }
        let n = compile("noise").unwrap().evaluate(&i);
        assert_eq!(n, voronoi_f1(i.rest, 1.0, 0));
        let pole = compile("1 / (delta - 0.5)").unwrap();
        assert_eq!(pole.evaluate(&i), 0.0);
        assert_eq!(pole.take_non_finite(), Some((7, 0)));
        assert_eq!(pole.take_non_finite(), None, "taken once");
    }

    #[test]
    fn bad_expressions_are_errors_not_panics() {
        let e = compile("delta * (speed").unwrap_err();
        assert!(matches!(e, StyleError::Expression { .. }), "{e}");
        assert!(e.to_string().contains("delta * (speed"), "{e}");
        let e = compile("delta * velocity").unwrap_err();
        match &e {
            StyleError::UnknownVariable { name, .. } => assert_eq!(name, "velocity"),
            other => panic!("wrong error {other}"),
        }
        assert!(compile("").is_err());
        assert!(compile("delta +* 2").is_err());
        let shadow: BTreeMap<_, _> = [("speed".to_string(), Param::Constant(1.0))].into();
        assert!(Expression::compile("speed", 1.0.into(), 0, shadow).is_err());
    }

    #[test]
    fn keyframed_expression_parameters() {
        let params = [("b".to_string(), Param::Curve(vec![[0.0, 0.0], [10.0, 5.0]]))].into();
        let f = Expression::compile("b * delta", 1.0.into(), 0, params).unwrap();
        let i = StyleInput {
            delta: 2.0,
            frame: 4.0,
            ..Default::default()
        };
        assert!((f.evaluate(&i) - 4.0).abs() < 1e-6);
    }
}
