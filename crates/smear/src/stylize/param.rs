//! Keyframeable numeric parameters (paper Section 5.1: "all stylization parameters may be
//! keyframed").

use serde::{Deserialize, Serialize};

use super::error::StyleError;

/// A numeric parameter: a constant, or a piecewise-linear curve over frames given as
/// `[[frame, value], ...]` (frames increasing), held constant before the first and after the
/// last key.
///
/// In TOML: `beta_max = 2` or `beta_max = [[0, 0.0], [12, 4.0]]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Param {
    /// The same value at every frame.
    Constant(f32),
    /// Keys `[frame, value]`, frames strictly increasing.
    Curve(Vec<[f32; 2]>),
}

impl Default for Param {
    fn default() -> Self {
        Param::Constant(0.0)
    }
}

impl From<f32> for Param {
    fn from(v: f32) -> Self {
        Param::Constant(v)
    }
}

impl Param {
    /// The value at `frame` (fractional frames interpolate; a NaN frame gives the first key).
    ///
    /// Performance: O(log keys), no allocation.
    #[inline]
    pub fn at(&self, frame: f32) -> f32 {
        match self {
            Param::Constant(v) => *v,
            Param::Curve(keys) => curve_at(keys, frame),
        }
    }

    /// Checks that every value is finite and in `[lo, hi]` (`lo_open`/`hi_open` exclude the
    /// bound) and that curve frames strictly increase.
    ///
    /// Arguments: `name` names the parameter in the error.
    pub fn validate(
        &self,
        name: &str,
        (lo, lo_open): (f32, bool),
        (hi, hi_open): (f32, bool),
    ) -> Result<(), StyleError> {
        let err = |problem: String| StyleError::Parameter {
            name: name.to_string(),
            problem,
        };
        let values: Vec<f32> = match self {
            Param::Constant(v) => vec![*v],
            Param::Curve(keys) => {
                if keys.is_empty() {
                    return Err(err("keyframe curve has no keys".into()));
                }
                for w in keys.windows(2) {
                    if w[1][0].partial_cmp(&w[0][0]) != Some(std::cmp::Ordering::Greater) {
                        return Err(err(format!(
                            "keyframe frames must increase ({} then {})",
                            w[0][0], w[1][0]
                        )));
                    }
                }
                if keys.iter().any(|k| !k[0].is_finite()) {
                    return Err(err("keyframe frame is not finite".into()));
                }
                keys.iter().map(|k| k[1]).collect()
            }
        };
        for v in values {
            if !v.is_finite() {
                return Err(err(format!("{v} is not a finite number")));
            }
            let below = if lo_open { v <= lo } else { v < lo };
            let above = if hi_open { v >= hi } else { v > hi };
            if below || above {
                return Err(err(format!(
                    "{} is {}",
                    anim::human_number(v),
                    describe_range((lo, lo_open), (hi, hi_open))
                )));
            }
        }
        Ok(())
    }

    /// The largest value the parameter takes (a curve's largest key).
    pub fn max_value(&self) -> f32 {
        match self {
            Param::Constant(v) => *v,
            Param::Curve(keys) => keys.iter().map(|k| k[1]).fold(f32::NEG_INFINITY, f32::max),
        }
    }

    /// Whether the parameter is a keyframed curve.
    pub fn is_keyframed(&self) -> bool {
        matches!(self, Param::Curve(_))
    }

    /// [`Param::validate`] for any finite value.
    pub fn validate_finite(&self, name: &str) -> Result<(), StyleError> {
        self.validate(name, (f32::MIN, false), (f32::MAX, false))
    }
}

/// Command-line form: a number (`2.5`) or keys `FRAME:VALUE` separated by commas
/// (`0:0,12:4,24:0`).
impl std::str::FromStr for Param {
    type Err = String;

    fn from_str(s: &str) -> Result<Param, String> {
        let number = |t: &str| match t.trim().parse::<f32>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(format!("'{}' is not a finite number", t.trim())),
            Err(_) => Err(format!("'{}' is not a number", t.trim())),
        };
        if !s.contains(':') {
            return number(s).map(Param::Constant);
        }
        let keys = s
            .split(',')
            .map(|key| match key.split_once(':') {
                Some((f, v)) => Ok([number(f)?, number(v)?]),
                None => Err(format!(
                    "'{}' is not a FRAME:VALUE key (write keys as 0:1.0,12:4.0)",
                    key.trim()
                )),
            })
            .collect::<Result<Vec<_>, String>>()
            .map_err(|e| format!("{e} (keyframes are FRAME:VALUE,FRAME:VALUE,...)"))?;
        let p = Param::Curve(keys);
        p.validate_finite("keyframes").map_err(|e| e.to_string())?;
        Ok(p)
    }
}

/// The command-line form read by [`FromStr`](std::str::FromStr) (`2.5` or `0:0,12:4`).
impl std::fmt::Display for Param {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Param::Constant(v) => write!(f, "{v}"),
            Param::Curve(keys) => {
                for (i, [frame, value]) in keys.iter().enumerate() {
                    write!(f, "{}{frame}:{value}", if i > 0 { "," } else { "" })?;
                }
                Ok(())
            }
        }
    }
}

/// "not in [0, 1]", "not > 0", "not ≤ 1e9": a range without bounds that mean "any finite
/// number" (`f32::MIN`, `f32::MAX`).
fn describe_range((lo, lo_open): (f32, bool), (hi, hi_open): (f32, bool)) -> String {
    let (has_lo, has_hi) = (lo > f32::MIN, hi < f32::MAX);
    let lower = format!(
        "{} {}",
        if lo_open { ">" } else { "≥" },
        anim::human_number(lo)
    );
    let upper = format!(
        "{} {}",
        if hi_open { "<" } else { "≤" },
        anim::human_number(hi)
    );
    match (has_lo, has_hi) {
        (true, true) => format!(
            "not in {}{}, {}{}",
            if lo_open { '(' } else { '[' },
            anim::human_number(lo),
            anim::human_number(hi),
            if hi_open { ')' } else { ']' }
        ),
        (true, false) => format!("not {lower}"),
        (false, true) => format!("not {upper}"),
        (false, false) => "not a finite number".into(),
    }
}

fn curve_at(keys: &[[f32; 2]], frame: f32) -> f32 {
    let (Some(first), Some(last)) = (keys.first(), keys.last()) else {
        return 0.0;
    };
    if frame.is_nan() || frame <= first[0] {
        return first[1];
    }
    if frame >= last[0] {
        return last[1];
    }
    // First key with a frame > `frame`; 1 ≤ i < len here.
    let i = keys.partition_point(|k| k[0] <= frame);
    let (a, b) = (keys[i - 1], keys[i]);
    let u = (frame - a[0]) / (b[0] - a[0]);
    a[1] + (b[1] - a[1]) * u
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keyframes_interpolate_linearly_and_clamp() {
        let p = Param::Curve(vec![[0.0, 1.0], [10.0, 3.0], [20.0, -1.0]]);
        assert_eq!(p.at(-5.0), 1.0);
        assert_eq!(p.at(0.0), 1.0);
        assert!((p.at(5.0) - 2.0).abs() < 1e-6);
        assert!((p.at(10.0) - 3.0).abs() < 1e-6);
        assert!((p.at(15.0) - 1.0).abs() < 1e-6);
        assert_eq!(p.at(25.0), -1.0);
        assert_eq!(p.at(f32::NAN), 1.0);
        assert_eq!(Param::Constant(4.5).at(100.0), 4.5);
    }

    #[test]
    fn command_line_keyframes_parse() {
        assert_eq!("2.5".parse::<Param>(), Ok(Param::Constant(2.5)));
        let p: Param = "0:0, 12:4,24:0".parse().unwrap();
        assert_eq!(p, Param::Curve(vec![[0.0, 0.0], [12.0, 4.0], [24.0, 0.0]]));
        assert_eq!(p.max_value(), 4.0);
        assert_eq!(p.to_string().parse::<Param>(), Ok(p.clone()));
        assert_eq!(Param::Constant(0.5).to_string(), "0.5");
        assert!(p.is_keyframed());
        assert!("0:1,x:2".parse::<Param>().is_err());
        assert!("3:1,1:2".parse::<Param>().unwrap_err().contains("increase"));
        assert!("1e-3".parse::<Param>().is_ok());
    }

    #[test]
    fn bad_curves_are_rejected() {
        let any = ((f32::MIN, false), (f32::MAX, false));
        assert!(Param::Curve(vec![]).validate("k", any.0, any.1).is_err());
        let back = Param::Curve(vec![[3.0, 0.0], [1.0, 1.0]]);
        assert!(back.validate("k", any.0, any.1).is_err());
        let s = Param::Constant(1.0);
        let e = s.validate("warp.s", (0.0, false), (1.0, true)).unwrap_err();
        assert!(e.to_string().contains("warp.s"), "{e}");
        assert!(Param::Constant(0.5)
            .validate("s", (0.0, false), (1.0, true))
            .is_ok());
    }
}
