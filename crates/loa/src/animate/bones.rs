//! Bone sets Ω(t_k): ordered chains of bones mapped onto the line by arc length, named
//! humanoid presets found from joint names, and explicit joint lists.
//!
//! A chain is a path in the kinematic tree (see [`super::rig`]) through its waypoints; its
//! points are the joint positions along the path plus, when the last joint is a leaf, its bone
//! tip. The stroke's first point maps onto the chain's first point: draw leg presets from the
//! foot up, arm presets from the hand in.

use std::fmt;
use std::str::FromStr;

use super::error::AnimateError;
use super::rig::Rig;

/// Named bone sets: humanoid ones found from joint names (RobotExpressive `FootR`, BVH `rFoot`
/// / `RightFoot`, Mixamo `mixamorig:RightFoot`, `foot.R`, `foot_r`, …), and two found from the
/// skeleton's hierarchy alone, for any joint names (the spine is followed through the
/// children that have no mirrored twin).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Preset {
    /// Right foot → right leg → spine → head.
    RightLegSpineHead,
    /// Left foot → left leg → spine → head.
    LeftLegSpineHead,
    /// Right hand → right arm → spine → hips.
    RightArmSpine,
    /// Left hand → left arm → spine → hips.
    LeftArmSpine,
    /// Left hand → arms and shoulders → right hand.
    Arms,
    /// Left foot → legs → right foot.
    Legs,
    /// Left foot → left leg → spine → right arm → right hand: the long diagonal.
    FullBody,
    /// Right foot → right leg → spine → right arm → right hand: a raised right arm.
    RightLegSpineArm,
    /// Left foot → left leg → spine → left arm → left hand: a raised left arm.
    LeftLegSpineArm,
    /// A foot → its leg → spine → head, found from the hierarchy (any joint names).
    FootHead,
    /// The root → spine → head, found from the hierarchy (any joint names).
    SpineHead,
}

impl Preset {
    /// Every preset with its command-line name.
    pub const ALL: [(Preset, &'static str); 11] = [
        (Preset::RightLegSpineHead, "right-leg-spine-head"),
        (Preset::LeftLegSpineHead, "left-leg-spine-head"),
        (Preset::RightArmSpine, "arm-spine"),
        (Preset::LeftArmSpine, "left-arm-spine"),
        (Preset::Arms, "arms"),
        (Preset::Legs, "legs"),
        (Preset::FullBody, "full-body"),
        (Preset::RightLegSpineArm, "right-leg-spine-arm"),
        (Preset::LeftLegSpineArm, "left-leg-spine-arm"),
        (Preset::FootHead, "foot-head"),
        (Preset::SpineHead, "spine-head"),
    ];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        Preset::ALL
            .iter()
            .find(|(p, _)| *p == self)
            .map_or("?", |(_, n)| n)
    }

    /// A short label for menus (the Blender panel, the studio).
    pub fn label(self) -> &'static str {
        self.text().0
    }

    /// What the chain runs through, in one sentence (menu tooltips).
    pub fn description(self) -> &'static str {
        self.text().1
    }

    fn text(self) -> (&'static str, &'static str) {
        match self {
            Preset::RightLegSpineHead => (
                "Right leg, spine, head",
                "Right foot → right leg → spine → head (joints found by name)",
            ),
            Preset::LeftLegSpineHead => (
                "Left leg, spine, head",
                "Left foot → left leg → spine → head (joints found by name)",
            ),
            Preset::RightArmSpine => (
                "Right arm, spine",
                "Right hand → right arm → spine → hips (joints found by name)",
            ),
            Preset::LeftArmSpine => (
                "Left arm, spine",
                "Left hand → left arm → spine → hips (joints found by name)",
            ),
            Preset::Arms => (
                "Arms",
                "Left hand → arms and shoulders → right hand (joints found by name)",
            ),
            Preset::Legs => (
                "Legs",
                "Left foot → legs → right foot (joints found by name)",
            ),
            Preset::FullBody => (
                "Full body",
                "Left foot → left leg → spine → right arm → right hand (joints found by name)",
            ),
            Preset::RightLegSpineArm => (
                "Right leg, spine, raised right arm",
                "Right foot → right leg → spine → right arm → right hand, for a raised arm \
                 (joints found by name)",
            ),
            Preset::LeftLegSpineArm => (
                "Left leg, spine, raised left arm",
                "Left foot → left leg → spine → left arm → left hand, for a raised arm \
                 (joints found by name)",
            ),
            Preset::FootHead => (
                "Foot to head (hierarchy)",
                "A foot → its leg → spine → head, found from the skeleton's hierarchy for any \
                 joint names (the head ends the spine, wherever the arms are)",
            ),
            Preset::SpineHead => (
                "Spine and head (hierarchy)",
                "Root → spine → head, found from the skeleton's hierarchy for any joint names",
            ),
        }
    }
}

impl fmt::Display for Preset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Preset {
    type Err = AnimateError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim().to_ascii_lowercase();
        let alias = match s.as_str() {
            "right-arm-spine" => "arm-spine",
            "right-leg" => "right-leg-spine-head",
            "left-leg" => "left-leg-spine-head",
            other => other,
        };
        Preset::ALL
            .iter()
            .find(|(_, n)| *n == alias)
            .map(|(p, _)| *p)
            .ok_or_else(|| AnimateError::UnknownPreset(s.clone()))
    }
}

/// What a bone set is made of.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(into = "String", try_from = "String")]
pub enum BoneSet {
    /// A named humanoid preset.
    Preset(Preset),
    /// Joint names; consecutive names are joined by their path in the skeleton.
    Joints(Vec<String>),
}

impl FromStr for BoneSet {
    type Err = AnimateError;
    /// A preset name, or a comma-separated list of joint names (waypoints).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.contains(',') {
            let names: Vec<String> = s
                .split(',')
                .map(|x| x.trim().to_string())
                .filter(|x| !x.is_empty())
                .collect();
            return Ok(BoneSet::Joints(names));
        }
        match s.parse::<Preset>() {
            Ok(p) => Ok(BoneSet::Preset(p)),
            Err(_) => Ok(BoneSet::Joints(vec![s.trim().to_string()])),
        }
    }
}

impl fmt::Display for BoneSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BoneSet::Preset(p) => write!(f, "{p}"),
            BoneSet::Joints(j) => write!(f, "{}", j.join(",")),
        }
    }
}

impl From<BoneSet> for String {
    fn from(set: BoneSet) -> String {
        set.to_string()
    }
}

impl TryFrom<String> for BoneSet {
    type Error = AnimateError;
    fn try_from(s: String) -> Result<Self, Self::Error> {
        s.parse()
    }
}

/// A bone set resolved on a rig: the chain's joints (kinematic path) and whether the last
/// point is the last joint's bone tip.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Chain3 {
    /// Joints along the chain.
    pub joints: Vec<usize>,
    /// The chain ends with the last joint's bone tip.
    pub tip: bool,
}

/// A point of a chain: a joint position or a leaf's tip.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) enum ChainPoint {
    Joint(usize),
    Tip(usize),
}

impl Chain3 {
    pub(super) fn points(&self) -> Vec<ChainPoint> {
        let mut v: Vec<ChainPoint> = self.joints.iter().map(|&j| ChainPoint::Joint(j)).collect();
        if self.tip {
            if let Some(&l) = self.joints.last() {
                v.push(ChainPoint::Tip(l));
            }
        }
        v
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Side {
    Left,
    Right,
}

/// Lower-case alphanumerics of the name after any namespace (`mixamorig:`, `Armature|`).
fn normalize(name: &str) -> String {
    let base = name.rsplit([':', '|']).next().unwrap_or(name);
    base.chars()
        .filter(|c| c.is_ascii_alphanumeric())
        .map(|c| c.to_ascii_lowercase())
        .collect()
}

/// Side and core of a name: `FootR`, `rFoot`, `RightFoot`, `foot.r`, `Left_Foot` …
fn side_variants(name: &str) -> Vec<(Option<Side>, String)> {
    let n = normalize(name);
    let mut v = vec![(None, n.clone())];
    for (side, word, letter) in [(Side::Left, "left", 'l'), (Side::Right, "right", 'r')] {
        if let Some(c) = n.strip_prefix(word) {
            v.push((Some(side), c.to_string()));
        }
        if let Some(c) = n.strip_suffix(word) {
            v.push((Some(side), c.to_string()));
        }
        if let Some(c) = n.strip_prefix(letter) {
            v.push((Some(side), c.to_string()));
        }
        if let Some(c) = n.strip_suffix(letter) {
            v.push((Some(side), c.to_string()));
        }
    }
    v
}

/// The first joint (in skeleton order) whose core name is one of `cores`, on `side`.
fn find_role(rig: &Rig, side: Option<Side>, cores: &[&str]) -> Option<usize> {
    for core in cores {
        for (k, name) in rig.names.iter().enumerate() {
            if side_variants(name)
                .iter()
                .any(|(s, c)| *s == side && c == core)
            {
                return Some(k);
            }
        }
    }
    None
}

const FOOT: &[&str] = &["foot", "ankle", "shin", "lowerleg", "calf", "leg", "knee"];
const HAND: &[&str] = &["hand", "wrist", "forearm", "lowerarm", "elbow"];
const HEAD: &[&str] = &["head", "neck1", "neck"];

fn role(
    rig: &Rig,
    side: Option<Side>,
    cores: &[&str],
    what: &'static str,
) -> Result<usize, AnimateError> {
    find_role(rig, side, cores).ok_or_else(|| AnimateError::PresetJoint {
        role: what,
        joints: rig.names.join(", "),
    })
}

/// Lowest common ancestor of `a` and `b` in the kinematic tree.
fn lca(rig: &Rig, a: usize, b: usize) -> usize {
    let path = rig.path(a, b);
    // The path goes up from `a` then down to `b`: its highest joint is the LCA.
    let depth = |mut k: usize| {
        let mut d = 0;
        while let Some(p) = rig.parent[k] {
            d += 1;
            k = p;
        }
        d
    };
    path.into_iter().min_by_key(|&k| depth(k)).unwrap_or(a)
}

/// Joints in each joint's kinematic subtree and that subtree's depth (a leaf: `(1, 0)`).
fn shapes(rig: &Rig) -> Vec<(usize, usize)> {
    let mut shape = vec![(1, 0); rig.len()];
    for &k in rig.order.iter().rev() {
        for &c in &rig.children[k] {
            shape[k].0 += shape[c].0;
            shape[k].1 = shape[k].1.max(shape[c].1 + 1);
        }
    }
    shape
}

/// Children of `k` whose subtree has a twin among its siblings (the same joint count and
/// depth: a left/right pair of limbs), and those without one.
fn twins(rig: &Rig, shape: &[(usize, usize)], k: usize) -> (Vec<usize>, Vec<usize>) {
    let kids = &rig.children[k];
    kids.iter()
        .copied()
        .partition(|&c| kids.iter().any(|&d| d != c && shape[d] == shape[c]))
}

/// The spine, root first, found from the hierarchy alone (no names, no pose, so raised arms
/// and any up axis are fine): from the root with the largest subtree, down through the
/// child that has no twin among its siblings (legs and arms come in mirrored pairs, the
/// spine, neck and head do not), the largest such child when there are several; it ends
/// where every child has a twin or there is none (the head, or the joint the eyes hang from).
pub(crate) fn spine(rig: &Rig) -> Vec<usize> {
    let shape = shapes(rig);
    let Some(root) = (0..rig.len())
        .filter(|&k| rig.parent[k].is_none())
        .max_by_key(|&k| (shape[k].0, std::cmp::Reverse(k)))
    else {
        return Vec::new();
    };
    let mut path = vec![root];
    loop {
        let k = path[path.len() - 1];
        let (_, single) = twins(rig, &shape, k);
        match single
            .into_iter()
            .max_by_key(|&c| (shape[c].0, std::cmp::Reverse(c)))
        {
            Some(c) => path.push(c),
            None => return path,
        }
    }
}

/// The foot of the hierarchy's leg: along the spine from the root, the first pair of twin
/// subtrees of two or more joints (the legs, branching at the hips below the arms; single
/// IK targets hanging from the root are no legs); of the pair, the right one when its first
/// joint's name says so, else the first; its deepest leaf.
fn hierarchy_foot(rig: &Rig, spine: &[usize]) -> Option<usize> {
    let shape = shapes(rig);
    let right = |c: usize| {
        side_variants(&rig.names[c])
            .iter()
            .any(|(s, _)| *s == Some(Side::Right))
    };
    let legs = spine.iter().find_map(|&k| {
        let (paired, _) = twins(rig, &shape, k);
        let legs: Vec<usize> = paired.into_iter().filter(|&c| shape[c].0 >= 2).collect();
        (legs.len() >= 2).then_some(legs)
    })?;
    let mut k = legs.iter().copied().find(|&c| right(c)).unwrap_or(legs[0]);
    // Down the deepest branch to its leaf.
    while let Some(&c) = rig.children[k]
        .iter()
        .max_by_key(|&&c| (shape[c].1, std::cmp::Reverse(c)))
    {
        k = c;
    }
    Some(k)
}

/// Resolves a bone set into a chain on the rig.
pub(crate) fn resolve(rig: &Rig, set: &BoneSet) -> Result<Chain3, AnimateError> {
    let waypoints: Vec<usize> = match set {
        BoneSet::Joints(names) => {
            if names.is_empty() {
                return Err(AnimateError::EmptyBoneSet);
            }
            names
                .iter()
                .map(|n| {
                    rig.names.iter().position(|x| x == n).ok_or_else(|| {
                        AnimateError::UnknownJoint {
                            name: n.clone(),
                            joints: rig.names.join(", "),
                        }
                    })
                })
                .collect::<Result<_, _>>()?
        }
        BoneSet::Preset(p) => {
            let foot = |s| role(rig, Some(s), FOOT, "foot");
            let hand = |s| role(rig, Some(s), HAND, "hand");
            let head = || role(rig, None, HEAD, "head");
            match p {
                Preset::RightLegSpineHead => vec![foot(Side::Right)?, head()?],
                Preset::LeftLegSpineHead => vec![foot(Side::Left)?, head()?],
                Preset::RightArmSpine | Preset::LeftArmSpine => {
                    let s = if *p == Preset::RightArmSpine {
                        Side::Right
                    } else {
                        Side::Left
                    };
                    let hips = lca(rig, foot(Side::Left)?, foot(Side::Right)?);
                    vec![hand(s)?, hips]
                }
                Preset::Arms => vec![hand(Side::Left)?, hand(Side::Right)?],
                Preset::Legs => vec![foot(Side::Left)?, foot(Side::Right)?],
                Preset::FullBody => vec![foot(Side::Left)?, hand(Side::Right)?],
                Preset::RightLegSpineArm => vec![foot(Side::Right)?, hand(Side::Right)?],
                Preset::LeftLegSpineArm => vec![foot(Side::Left)?, hand(Side::Left)?],
                Preset::FootHead | Preset::SpineHead => {
                    let spine = spine(rig);
                    let (Some(&root), Some(&head)) = (spine.first(), spine.last()) else {
                        return Err(AnimateError::EmptySkeleton);
                    };
                    let start = if *p == Preset::FootHead {
                        hierarchy_foot(rig, &spine).ok_or_else(|| AnimateError::PresetJoint {
                            role: "leg",
                            joints: rig.names.join(", "),
                        })?
                    } else {
                        root
                    };
                    if start == head {
                        return Err(AnimateError::EmptyBoneSet);
                    }
                    vec![start, head]
                }
            }
        }
    };
    let mut joints = vec![waypoints[0]];
    for w in waypoints.windows(2) {
        let path = rig.path(w[0], w[1]);
        joints.extend_from_slice(&path[1..]);
    }
    joints.dedup();
    let last = *joints.last().unwrap_or(&waypoints[0]);
    let tip = rig.children[last].is_empty() && rig.leaf_tip[last].is_some();
    if joints.len() < 2 && !tip {
        return Err(AnimateError::EmptyBoneSet);
    }
    Ok(Chain3 { joints, tip })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_and_core_of_common_naming_schemes() {
        for (name, side) in [
            ("FootR", Side::Right),
            ("rFoot", Side::Right),
            ("RightFoot", Side::Right),
            ("mixamorig:LeftFoot", Side::Left),
            ("foot.L", Side::Left),
            ("Foot_r", Side::Right),
        ] {
            assert!(
                side_variants(name)
                    .iter()
                    .any(|(s, c)| *s == Some(side) && c == "foot"),
                "{name}"
            );
        }
        // "LowerBack" is not a left "owerback".
        assert!(!side_variants("LowerBack")
            .iter()
            .any(|(s, c)| s.is_some() && FOOT.contains(&c.as_str())));
    }

    #[test]
    fn parses_presets_and_lists() {
        assert_eq!(
            "right-leg-spine-head".parse::<BoneSet>().unwrap(),
            BoneSet::Preset(Preset::RightLegSpineHead)
        );
        assert_eq!(
            "FootR,Head".parse::<BoneSet>().unwrap(),
            BoneSet::Joints(vec!["FootR".into(), "Head".into()])
        );
    }
}
