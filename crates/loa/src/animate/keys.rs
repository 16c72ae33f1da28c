//! Keyed inputs of the synthesis: bone sets per keystroke, contacts and twists.

use std::str::FromStr;

use glam::DVec3;

use super::bones::BoneSet;
use super::error::AnimateError;

/// Ω(t_k): the bone set constrained at keystroke frame `frame`.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct BoneSetKey {
    /// A keystroke frame.
    pub frame: i64,
    /// The bone set.
    pub set: BoneSet,
}

impl FromStr for BoneSetKey {
    type Err = AnimateError;
    /// `SET@FRAME` (`right-leg-spine-head@0`, `FootR,Head@24`); without `@FRAME`, frame 0.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (set, frame) = match s.rsplit_once('@') {
            Some((a, f)) => (a, parse_frame("bone set", f)?),
            None => (s, 0),
        };
        Ok(BoneSetKey {
            frame,
            set: set.parse()?,
        })
    }
}

/// A contact key (Section 4.1, E_⊥): joint `joint` is held at a position and orientation.
///
/// Keys of one joint are interpolated linearly between them and the contact is active from
/// its first key to its last. Without an explicit `position`, the first key holds the joint
/// where the planar stage put it at that frame, and later keys hold the previous key's target
/// (so two keys plant the joint for the whole range). The orientation target is the planar
/// stage's orientation at the joint's first key.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactKey {
    /// Joint name.
    pub joint: String,
    /// Frame of the key.
    pub frame: i64,
    /// World position target; `None` = hold (see above).
    pub position: Option<DVec3>,
}

impl FromStr for ContactKey {
    type Err = AnimateError;
    /// `JOINT@FRAME`, `JOINT@FRAME:x,y,z`, or `JOINT@A..B` (shorthand for two holding keys;
    /// [`ContactKey::parse_all`] expands it).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let mut all = ContactKey::parse_all(s)?;
        Ok(all.remove(0))
    }
}

impl ContactKey {
    /// Parses one command-line contact into its keys (`JOINT@A..B` gives two).
    pub fn parse_all(s: &str) -> Result<Vec<ContactKey>, AnimateError> {
        let bad = || AnimateError::BadFrame {
            what: "contact",
            frame: 0,
            expected: format!("'{s}' should read JOINT@FRAME, JOINT@FRAME:x,y,z or JOINT@A..B"),
        };
        let (joint, rest) = s.rsplit_once('@').ok_or_else(bad)?;
        let (frames, pos) = match rest.split_once(':') {
            Some((f, p)) => (f, Some(p)),
            None => (rest, None),
        };
        let position = match pos {
            None => None,
            Some(p) => {
                let v: Vec<f64> = p
                    .split(',')
                    .map(|x| x.trim().parse::<f64>())
                    .collect::<Result<_, _>>()
                    .map_err(|_| bad())?;
                if v.len() != 3 || v.iter().any(|x| !x.is_finite()) {
                    return Err(bad());
                }
                Some(DVec3::new(v[0], v[1], v[2]))
            }
        };
        let joint = joint.trim().to_string();
        if let Some((a, b)) = frames.split_once("..") {
            let (a, b) = (parse_frame("contact", a)?, parse_frame("contact", b)?);
            return Ok(vec![
                ContactKey {
                    joint: joint.clone(),
                    frame: a,
                    position,
                },
                ContactKey {
                    joint,
                    frame: b,
                    position: None,
                },
            ]);
        }
        Ok(vec![ContactKey {
            joint,
            frame: parse_frame("contact", frames)?,
            position,
        }])
    }
}

/// A twist key (Section 4.1, E_twist): joint `joint` turned by `angle` radians about its own
/// bone axis relative to the planar solution. Angles interpolate linearly between a joint's
/// keys and hold before the first and after the last.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TwistKey {
    /// Joint name.
    pub joint: String,
    /// Frame of the key.
    pub frame: i64,
    /// Twist angle in radians.
    pub angle: f64,
}

impl FromStr for TwistKey {
    type Err = AnimateError;
    /// `JOINT@FRAME:DEGREES`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || AnimateError::BadFrame {
            what: "twist",
            frame: 0,
            expected: format!("'{s}' should read JOINT@FRAME:DEGREES"),
        };
        let (joint, rest) = s.rsplit_once('@').ok_or_else(bad)?;
        let (f, a) = rest.split_once(':').ok_or_else(bad)?;
        let angle: f64 = a.trim().parse().map_err(|_| bad())?;
        if !angle.is_finite() {
            return Err(bad());
        }
        Ok(TwistKey {
            joint: joint.trim().to_string(),
            frame: parse_frame("twist", f)?,
            angle: angle.to_radians(),
        })
    }
}

fn parse_frame(what: &'static str, s: &str) -> Result<i64, AnimateError> {
    s.trim().parse::<i64>().map_err(|_| AnimateError::BadFrame {
        what,
        frame: 0,
        expected: format!("'{s}' is not an integer frame"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_command_line_keys() {
        let b: BoneSetKey = "left-leg-spine-head@24".parse().unwrap();
        assert_eq!(b.frame, 24);
        let c = ContactKey::parse_all("FootR@0..20").unwrap();
        assert_eq!((c[0].frame, c[1].frame), (0, 20));
        let c: ContactKey = "FootR@5:0,0.1,2".parse().unwrap();
        assert_eq!(c.position, Some(DVec3::new(0.0, 0.1, 2.0)));
        let t: TwistKey = "Torso_1@12:90".parse().unwrap();
        assert!((t.angle - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert!("Torso_1@x:90".parse::<TwistKey>().is_err());
    }
}
