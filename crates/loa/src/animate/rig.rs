//! The character as a kinematic tree in double precision: the skeleton's hierarchy, an initial
//! pose, and forward kinematics of per-frame local rotations plus a root offset.
//!
//! **Attachments.** Game rigs exported with baked IK (RobotExpressive) parent the feet to the
//! armature root instead of the shin. For solving, such a joint is *attached* to the leaf joint
//! whose bone axis it lies on (see [`ATTACH_TOLERANCE`]): it becomes a kinematic child of the
//! leaf, so the foot follows the leg. Output world matrices are
//! converted back to the real hierarchy, so the file's skeleton is unchanged.
//!
//! Scales: positions use `x_c = x_p + R_p (S_p ⊙ t_c)` with `S` the product of the local
//! scales, exact for uniform scales (the usual case, e.g. RobotExpressive's 100×); rotations
//! never change lengths, so bone lengths are preserved exactly for any scale.

use anim::{Skeleton, Transform};
use glam::{DQuat, DVec3};

use super::error::AnimateError;

/// A leaf joint parented to a root and lying on another leaf bone's axis (distance from the axis below this fraction of its
/// distance along it, and at most three bone lengths out) is attached to that leaf for
/// solving (see the module docs).
pub const ATTACH_TOLERANCE: f64 = 0.35;

/// The character's kinematic tree with its initial pose.
#[derive(Debug, Clone)]
pub(crate) struct Rig {
    /// Joint names (skeleton order).
    pub names: Vec<String>,
    /// Parent in the skeleton file.
    pub skeleton_parent: Vec<Option<usize>>,
    /// Parent used for solving (skeleton parent, or the leaf a joint is attached to).
    pub parent: Vec<Option<usize>>,
    /// Joints in parent-first order of the kinematic tree.
    pub order: Vec<usize>,
    /// Kinematic children.
    pub children: Vec<Vec<usize>>,
    /// Initial local translation relative to the kinematic parent (world for roots).
    pub translation: Vec<DVec3>,
    /// Initial local rotation relative to the kinematic parent.
    pub rotation: Vec<DQuat>,
    /// Local scale.
    pub scale: Vec<DVec3>,
    /// Leaf joints: tip offset along the bone axis (SPEC bone rule), in local units.
    pub leaf_tip: Vec<Option<DVec3>>,
    /// Bone axis of a joint without a rest orientation, from its `End Site` (local units);
    /// `None`: the local +Y (see [`Rig::with_axes`]).
    pub axis: Vec<Option<DVec3>>,
}

/// World state of every joint in one pose.
#[derive(Debug, Clone, Default)]
pub(crate) struct WorldPose {
    /// Joint positions.
    pub position: Vec<DVec3>,
    /// Joint rotations (scale removed).
    pub rotation: Vec<DQuat>,
    /// Accumulated scale.
    pub scale: Vec<DVec3>,
}

impl WorldPose {
    /// Tip of a leaf joint's bone, or the joint position for joints without a tip.
    pub(super) fn tip(&self, rig: &Rig, j: usize) -> DVec3 {
        match rig.leaf_tip[j] {
            Some(t) => self.position[j] + self.rotation[j] * (self.scale[j] * t),
            None => self.position[j],
        }
    }
}

fn dquat(q: glam::Quat) -> DQuat {
    DQuat::from_xyzw(q.x as f64, q.y as f64, q.z as f64, q.w as f64).normalize()
}

impl Rig {
    /// Builds the rig from a skeleton and the local transforms of the initial pose (one per
    /// joint, relative to the skeleton parent).
    pub(super) fn new(skeleton: &Skeleton, pose: &[Transform]) -> Result<Rig, AnimateError> {
        Rig::with_axes(skeleton, pose, Vec::new())
    }

    /// [`Rig::new`] with the bone axes of leaves the file gives explicitly: `axes[k]` is joint
    /// k's bone direction in its local frame. A BVH joint has no rest orientation, so the SPEC
    /// rule's local +Y means nothing there (it is world up); its `End Site` is where the bone
    /// points. The tip stays at the parent bone's length along that axis (the SPEC rule), so
    /// a skeleton handed over as BVH gets the same tips as the file it came from.
    pub(super) fn with_axes(
        skeleton: &Skeleton,
        pose: &[Transform],
        axes: Vec<Option<DVec3>>,
    ) -> Result<Rig, AnimateError> {
        let n = skeleton.len();
        if n == 0 {
            return Err(AnimateError::EmptySkeleton);
        }
        if pose.len() != n {
            return Err(AnimateError::PoseLength {
                expected: n,
                found: pose.len(),
            });
        }
        for (k, j) in skeleton.joints.iter().enumerate() {
            if j.parent.is_some_and(|p| p >= k) {
                return Err(AnimateError::BadHierarchy(j.name.clone()));
            }
        }
        let ok = |t: &Transform| {
            t.translation.is_finite() && t.rotation.is_finite() && t.scale.is_finite()
        };
        if let Some(k) = pose.iter().position(|t| !ok(t)) {
            return Err(AnimateError::NonFinitePose(skeleton.joints[k].name.clone()));
        }
        let skeleton_parent: Vec<Option<usize>> =
            skeleton.joints.iter().map(|j| j.parent).collect();
        let mut rig = Rig {
            names: skeleton.joints.iter().map(|j| j.name.clone()).collect(),
            skeleton_parent: skeleton_parent.clone(),
            parent: skeleton_parent,
            order: (0..n).collect(),
            children: Vec::new(),
            translation: pose.iter().map(|t| t.translation.as_dvec3()).collect(),
            rotation: pose.iter().map(|t| dquat(t.rotation)).collect(),
            scale: pose.iter().map(|t| t.scale.as_dvec3()).collect(),
            leaf_tip: vec![None; n],
            axis: (0..n)
                .map(|k| {
                    axes.get(k)
                        .copied()
                        .flatten()
                        .and_then(DVec3::try_normalize)
                })
                .collect(),
        };
        rig.rebuild_tree();
        rig.attach_detached_effectors();
        Ok(rig)
    }

    /// Number of joints.
    pub(super) fn len(&self) -> usize {
        self.names.len()
    }

    fn rebuild_tree(&mut self) {
        let n = self.len();
        self.children = vec![Vec::new(); n];
        for k in 0..n {
            if let Some(p) = self.parent[k] {
                self.children[p].push(k);
            }
        }
        // Parent-first order by depth-first traversal from the roots.
        let mut order = Vec::with_capacity(n);
        let mut stack: Vec<usize> = (0..n).filter(|&k| self.parent[k].is_none()).rev().collect();
        while let Some(k) = stack.pop() {
            order.push(k);
            stack.extend(self.children[k].iter().rev());
        }
        self.order = order;
        self.update_leaf_tips();
    }

    /// SPEC bone tips of leaves: the bone axis (local +Y, or the file's `End Site` axis for a
    /// joint without rest orientation) scaled to the parent bone's length (in the leaf's local
    /// units).
    fn update_leaf_tips(&mut self) {
        let world = self.world(&self.rotation, DVec3::ZERO);
        let n = self.len();
        for k in 0..n {
            self.leaf_tip[k] = None;
            if !self.children[k].is_empty() {
                continue;
            }
            let Some(p) = self.parent[k] else { continue };
            let kids = &self.children[p];
            let tip = kids.iter().map(|&c| world.position[c]).sum::<DVec3>() / kids.len() as f64;
            let len = (tip - world.position[p]).length();
            let s = world.scale[k];
            self.leaf_tip[k] = match self.axis[k] {
                // The local step whose world length (through the accumulated scale) is `len`.
                Some(axis) => {
                    let unit = (s * axis).length();
                    (len > 0.0 && unit > 0.0).then(|| axis * (len / unit))
                }
                None => (len > 0.0 && s.y.abs() > 0.0).then(|| DVec3::new(0.0, len / s.y, 0.0)),
            };
        }
    }

    /// Re-parents joints sitting on a leaf bone's tip under that leaf (see the module docs).
    fn attach_detached_effectors(&mut self) {
        let world = self.world(&self.rotation, DVec3::ZERO);
        let n = self.len();
        let mut changed = false;
        for j in 0..n {
            // Only leaf joints hanging from a root (IK effectors) are candidates.
            let Some(pj) = self.parent[j] else { continue };
            if !self.children[j].is_empty() || self.parent[pj].is_some() {
                continue;
            }
            let mut best: Option<(f64, usize)> = None;
            for leaf in 0..n {
                if leaf == j || !self.children[leaf].is_empty() || self.is_ancestor(j, leaf) {
                    continue;
                }
                let Some(p_leaf) = self.parent[leaf] else {
                    continue;
                };
                let len = (world.position[leaf] - world.position[p_leaf]).length();
                if len <= 0.0 || !self.is_ancestor(pj, leaf) || pj == p_leaf {
                    continue;
                }
                // The joint must sit on the leaf's bone axis, beyond its root and within a
                // few bone lengths: its distance from the axis, relative to how far along it
                // is, below ATTACH_TOLERANCE.
                let axis = world.tip(self, leaf) - world.position[leaf];
                let Some(dir) = axis.try_normalize() else {
                    continue;
                };
                let v = world.position[j] - world.position[leaf];
                let along = v.dot(dir);
                let off = (v - dir * along).length();
                if along <= 0.0 || along > 3.0 * axis.length() {
                    continue;
                }
                let d = off / along;
                if d <= ATTACH_TOLERANCE && best.is_none_or(|(b, _)| d < b) {
                    best = Some((d, leaf));
                }
            }
            if let Some((_, leaf)) = best {
                // Local transform relative to the leaf in the initial pose.
                let (ql, xl, sl) = (
                    world.rotation[leaf],
                    world.position[leaf],
                    world.scale[leaf],
                );
                self.parent[j] = Some(leaf);
                self.translation[j] = (ql.inverse() * (world.position[j] - xl)) / sl;
                self.rotation[j] = (ql.inverse() * world.rotation[j]).normalize();
                self.scale[j] = world.scale[j] / sl;
                self.children = vec![Vec::new(); n];
                for k in 0..n {
                    if let Some(p) = self.parent[k] {
                        self.children[p].push(k);
                    }
                }
                changed = true;
            }
        }
        if changed {
            self.rebuild_tree();
        }
    }

    /// Whether `a` is `b` or an ancestor of `b` in the kinematic tree.
    pub(super) fn is_ancestor(&self, a: usize, b: usize) -> bool {
        let mut k = Some(b);
        while let Some(x) = k {
            if x == a {
                return true;
            }
            k = self.parent[x];
        }
        false
    }

    /// Path in the kinematic tree from `a` to `b` (both included).
    pub(super) fn path(&self, a: usize, b: usize) -> Vec<usize> {
        let up = |mut k: usize| {
            let mut v = vec![k];
            while let Some(p) = self.parent[k] {
                v.push(p);
                k = p;
            }
            v
        };
        let (pa, pb) = (up(a), up(b));
        let Some(common) = pa.iter().position(|x| pb.contains(x)) else {
            return vec![a, b];
        };
        let lca = pa[common];
        let mut path: Vec<usize> = pa[..=common].to_vec();
        let down = pb.iter().position(|&x| x == lca).unwrap_or(0);
        path.extend(pb[..down].iter().rev());
        path
    }

    /// Forward kinematics of local `rotations` (one per joint) with `offset` added to every
    /// root's translation.
    pub(super) fn world(&self, rotations: &[DQuat], offset: DVec3) -> WorldPose {
        let mut w = WorldPose::default();
        self.world_into(rotations, offset, &mut w);
        w
    }

    /// [`Rig::world`] into reusable buffers.
    pub(super) fn world_into(&self, rotations: &[DQuat], offset: DVec3, w: &mut WorldPose) {
        let n = self.len();
        w.position.resize(n, DVec3::ZERO);
        w.rotation.resize(n, DQuat::IDENTITY);
        w.scale.resize(n, DVec3::ONE);
        for &k in &self.order {
            match self.parent[k] {
                None => {
                    w.position[k] = self.translation[k] + offset;
                    w.rotation[k] = rotations[k];
                    w.scale[k] = self.scale[k];
                }
                Some(p) => {
                    w.position[k] =
                        w.position[p] + w.rotation[p] * (w.scale[p] * self.translation[k]);
                    w.rotation[k] = w.rotation[p] * rotations[k];
                    w.scale[k] = w.scale[p] * self.scale[k];
                }
            }
        }
    }

    /// Rotation of the kinematic parent (identity for roots).
    pub(super) fn parent_rotation(&self, w: &WorldPose, k: usize) -> DQuat {
        self.parent[k].map_or(DQuat::IDENTITY, |p| w.rotation[p])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim::Joint;
    use glam::Vec3;

    fn joint(name: &str, parent: Option<usize>, t: Vec3) -> Joint {
        Joint {
            name: name.into(),
            parent,
            bind_local: Transform::from_translation(t),
        }
    }

    #[test]
    fn detached_foot_is_attached_to_the_shin() {
        // root → hips → thigh → shin (leaf), and a foot parented to the root at the shin tip.
        let s = Skeleton {
            joints: vec![
                joint("root", None, Vec3::ZERO),
                joint("hips", Some(0), Vec3::new(0.0, 2.0, 0.0)),
                joint("thigh", Some(1), Vec3::new(0.0, -1.0, 0.0)),
                joint("shin", Some(2), Vec3::new(0.0, -1.0, 0.0)),
                joint("foot", Some(0), Vec3::new(0.0, 1.0, 0.0)),
            ],
        };
        let pose: Vec<Transform> = s.joints.iter().map(|j| j.bind_local).collect();
        // The shin (root at y = 0, a leaf) has its +Y tip one thigh length out, at y = 1,
        // where the foot sits.
        let rig = Rig::new(&s, &pose).unwrap();
        assert_eq!(rig.parent[4], Some(3));
        let w = rig.world(&rig.rotation, DVec3::ZERO);
        assert!((w.position[4] - DVec3::new(0.0, 1.0, 0.0)).length() < 1e-12);
        assert_eq!(rig.path(4, 1), vec![4, 3, 2, 1]);
    }
}
