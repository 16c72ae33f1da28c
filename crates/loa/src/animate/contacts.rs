//! Contact trajectories of the 3D stage (LoA §4.1, E_⊥): the keyed positions interpolated
//! between a contact's first and last key, the frames each contact holds, and the limbs it
//! holds. How the motion blends into and out of a contact is [`super::release`].

use std::collections::BTreeMap;

use glam::DVec3;

use super::error::AnimateError;
use super::keys::ContactKey;
use super::rig::{Rig, WorldPose};
use super::targets::ContactTarget;

/// Keyed contact targets per frame, the held windows and the held limbs.
pub(crate) struct ContactTrajectories {
    /// Targets on and between keys.
    pub held: Vec<Vec<ContactTarget>>,
    /// Per frame, the joints of every held limb (contact joint up to its root), for LoA
    /// Eq. 3's smoothness of constrained bones.
    pub limbs: Vec<Vec<usize>>,
    /// Every contact's held frames `(first key, last key)`.
    pub windows: Vec<(usize, usize)>,
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
        limbs: vec![Vec::new(); frames],
        windows: Vec::new(),
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
        let (first_key, last_key) = (resolved[0].0, resolved[resolved.len() - 1].0);
        out.windows.push((first_key, last_key));
        let touched = first_key..=last_key;
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
