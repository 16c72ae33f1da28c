//! Contact trajectories of the 3D stage (LoA §4.1, E_⊥): the keyed positions interpolated
//! between keys, and the eases before the first key and after the last.
//!
//! **Easing.** A contact does not switch on or off in one frame: before its first key the
//! target slides from the planar stage's pose onto the contact, and after its last key back.
//! The slide turns about the limb's root (the contact joint's kinematic grandparent: the hip
//! for a foot, the shoulder for a hand) rather than moving in a straight line, so the limb
//! keeps its reach instead of folding up as the target passes near its root; and it lasts
//! long enough that the limb turns at most [`CONTACT_RELEASE_MAX_TURN`] per frame about that
//! root (at least [`super::DEFAULT_CONTACT_RELEASE`] frames, at most
//! [`MAX_CONTACT_RELEASE`]).

use std::collections::BTreeMap;

use glam::{DQuat, DVec3};

use super::error::AnimateError;
use super::keys::ContactKey;
use super::rig::{Rig, WorldPose};
use super::targets::ContactTarget;
use super::DEFAULT_CONTACT_RELEASE;
use crate::retarget::Blend;

/// Largest turn (radians, 8°) of a released limb about its root in one frame of an ease.
pub const CONTACT_RELEASE_MAX_TURN: f64 = 8.0 * std::f64::consts::PI / 180.0;
/// Longest ease (frames) before a contact's first key or after its last.
pub const MAX_CONTACT_RELEASE: usize = 24;

/// Keyed contact targets per frame and the eases around them (both per frame).
pub(crate) struct ContactTrajectories {
    /// Targets on and between keys.
    pub held: Vec<Vec<ContactTarget>>,
    /// Targets of the ease-in and ease-out frames.
    pub easing: Vec<Vec<ContactTarget>>,
    /// Per frame, the joints of every limb held or easing (contact joint up to its root), for
    /// LoA Eq. 3's smoothness of constrained bones.
    pub limbs: Vec<Vec<usize>>,
}

/// Resolves `contacts` (frames already checked to lie in `0..worlds.len()` after
/// `frame_index`) against the planar stage's poses `worlds`.
pub(crate) fn contact_trajectories(
    rig: &Rig,
    worlds: &[WorldPose],
    contacts: &[ContactKey],
    joint_index: impl Fn(&str) -> Result<usize, AnimateError>,
    frame_index: impl Fn(i64) -> Result<usize, AnimateError>,
) -> Result<ContactTrajectories, AnimateError> {
    let frames = worlds.len();
    let mut out = ContactTrajectories {
        held: vec![Vec::new(); frames],
        easing: vec![Vec::new(); frames],
        limbs: vec![Vec::new(); frames],
    };
    let mut by_joint: BTreeMap<usize, Vec<(usize, Option<DVec3>)>> = BTreeMap::new();
    for c in contacts {
        let j = joint_index(&c.joint)?;
        by_joint
            .entry(j)
            .or_default()
            .push((frame_index(c.frame)?, c.position));
    }
    for (j, mut ks) in by_joint {
        ks.sort_by_key(|k| k.0);
        let rotation = worlds[ks[0].0].rotation[j];
        let mut resolved: Vec<(usize, DVec3)> = Vec::with_capacity(ks.len());
        for (f, p) in ks {
            let p = p.unwrap_or_else(|| {
                resolved
                    .last()
                    .map_or(worlds[f].position[j], |&(_, prev)| prev)
            });
            resolved.push((f, p));
        }
        for w in 0..resolved.len() {
            let (f0, p0) = resolved[w];
            let (f1, p1) = resolved.get(w + 1).copied().unwrap_or((f0, p0));
            for f in f0..=f1 {
                let t = if f1 > f0 {
                    (f - f0) as f64 / (f1 - f0) as f64
                } else {
                    0.0
                };
                let t_ = &mut out.held[f];
                t_.retain(|c| c.joint != j);
                t_.push(ContactTarget {
                    joint: j,
                    position: p0.lerp(p1, t),
                    rotation,
                });
            }
        }
        let limb = limb(rig, j);
        let pivot = *limb.last().unwrap_or(&j);
        let (first_key, last_key) = (resolved[0], resolved[resolved.len() - 1]);
        let mut touched: Vec<usize> = (first_key.0..=last_key.0).collect();
        for (key, before) in [(first_key, true), (last_key, false)] {
            // Frame of the i-th ease frame away from the key (None outside the clip).
            let frame = |i: usize| -> Option<usize> {
                if before {
                    key.0.checked_sub(i)
                } else {
                    Some(key.0 + i).filter(|&f| f < frames)
                }
            };
            let n = ease_length(worlds, j, pivot, key.1, &frame);
            for i in 1..=n {
                let Some(f) = frame(i) else { break };
                if out.held[f].iter().any(|c| c.joint == j) {
                    continue;
                }
                let w = 1.0 - Blend::Smoothstep.weight(i as f64 / (n + 1) as f64);
                let free = &worlds[f];
                out.easing[f].push(ContactTarget {
                    joint: j,
                    position: turn_about(free.position[pivot], key.1, free.position[j], w),
                    rotation: free.rotation[j].slerp(rotation, w),
                });
                touched.push(f);
            }
        }
        for f in touched {
            for &k in &limb {
                if !out.limbs[f].contains(&k) {
                    out.limbs[f].push(k);
                }
            }
        }
    }
    Ok(out)
}

/// The contact joint and its kinematic ancestors up to its grandparent (the limb's root).
fn limb(rig: &Rig, j: usize) -> Vec<usize> {
    let mut v = vec![j];
    let mut a = rig.parent[j];
    while let (Some(k), true) = (a, v.len() < 3) {
        v.push(k);
        a = rig.parent[k];
    }
    v
}

/// The point `w` of the way from `free` back to `held` (`w = 1`: `held`), turning about
/// `pivot`: the direction from the pivot turns along the great circle, the distance from it
/// changes linearly.
fn turn_about(pivot: DVec3, held: DVec3, free: DVec3, w: f64) -> DVec3 {
    let (a, b) = (held - pivot, free - pivot);
    let (la, lb) = (a.length(), b.length());
    let (Some(da), Some(db)) = (a.try_normalize(), b.try_normalize()) else {
        return free.lerp(held, w);
    };
    if da.dot(db) < -0.999 {
        return free.lerp(held, w);
    }
    let turn = DQuat::IDENTITY.slerp(DQuat::from_rotation_arc(db, da), w);
    pivot + turn * db * (lb + (la - lb) * w)
}

/// The shortest ease (frames) in which the limb turns at most [`CONTACT_RELEASE_MAX_TURN`]
/// per frame about its pivot, within [`DEFAULT_CONTACT_RELEASE`]..=[`MAX_CONTACT_RELEASE`].
fn ease_length(
    worlds: &[WorldPose],
    j: usize,
    pivot: usize,
    held: DVec3,
    frame: &dyn Fn(usize) -> Option<usize>,
) -> usize {
    let direction = |i: usize, n: usize| -> Option<DVec3> {
        let f = frame(i)?;
        let w = if i == 0 {
            1.0
        } else {
            1.0 - Blend::Smoothstep.weight(i as f64 / (n + 1) as f64)
        };
        let p = worlds[f].position[pivot];
        (turn_about(p, held, worlds[f].position[j], w) - p).try_normalize()
    };
    for n in DEFAULT_CONTACT_RELEASE..=MAX_CONTACT_RELEASE {
        let worst = (0..=n)
            .filter_map(|i| Some(direction(i, n)?.angle_between(direction(i + 1, n)?)))
            .fold(0.0, f64::max);
        if worst <= CONTACT_RELEASE_MAX_TURN {
            return n;
        }
    }
    MAX_CONTACT_RELEASE
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ease_turns_about_the_limb_root_keeping_its_reach() {
        let pivot = DVec3::new(0.0, 1.0, 0.0);
        let held = DVec3::new(0.0, -1.0, 0.0); // 2 below the pivot
        let free = DVec3::new(2.0, 1.0, 0.0); // 2 beside it
        assert!((turn_about(pivot, held, free, 1.0) - held).length() < 1e-12);
        assert!((turn_about(pivot, held, free, 0.0) - free).length() < 1e-12);
        let mid = turn_about(pivot, held, free, 0.5);
        // A straight slide would pass 1.41 from the pivot; the turn keeps the reach of 2.
        assert!(((mid - pivot).length() - 2.0).abs() < 1e-12);
        let d = (mid - pivot).normalize();
        assert!((d.angle_between(DVec3::NEG_Y) - std::f64::consts::FRAC_PI_4).abs() < 1e-9);
    }
}
