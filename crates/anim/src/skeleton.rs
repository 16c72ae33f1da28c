//! Skeletons, skeletal clips and bones (SPEC.md: bone k is joint k).

use glam::{Mat4, Vec3};

use crate::{AnimError, Result, Transform};

/// One joint of a skeleton.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Joint name.
    pub name: String,
    /// Parent joint index; parents always come before their children.
    pub parent: Option<usize>,
    /// Local transform relative to the parent in the bind (rest) pose.
    pub bind_local: Transform,
}

/// Named joints in parent-first order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Skeleton {
    /// Joints; `joints[k].parent < k`.
    pub joints: Vec<Joint>,
}

impl Skeleton {
    /// Checks parent-first ordering.
    pub fn validate(&self) -> Result<()> {
        for (k, j) in self.joints.iter().enumerate() {
            if let Some(p) = j.parent {
                if p >= k {
                    return Err(AnimError::Invalid(format!(
                        "joint '{}' comes before its parent",
                        j.name
                    )));
                }
            }
        }
        Ok(())
    }

    /// Number of joints.
    pub fn len(&self) -> usize {
        self.joints.len()
    }

    /// True when there is no joint.
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// Index of the joint named `name`.
    pub fn find(&self, name: &str) -> Result<usize> {
        self.joints
            .iter()
            .position(|j| j.name == name)
            .ok_or_else(|| AnimError::NotFound {
                kind: "joint",
                name: name.to_string(),
                available: self
                    .joints
                    .iter()
                    .map(|j| j.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    /// Children of every joint.
    pub fn children(&self) -> Vec<Vec<usize>> {
        let mut c = vec![Vec::new(); self.joints.len()];
        for (k, j) in self.joints.iter().enumerate() {
            if let Some(p) = j.parent {
                c[p].push(k);
            }
        }
        c
    }

    /// World transforms of the bind pose.
    pub fn bind_world(&self) -> Vec<Mat4> {
        let locals: Vec<Mat4> = self.joints.iter().map(|j| j.bind_local.matrix()).collect();
        self.world_from_local(&locals)
    }

    /// World matrices from local matrices (parent-first accumulation).
    pub fn world_from_local(&self, local: &[Mat4]) -> Vec<Mat4> {
        let mut w = Vec::with_capacity(local.len());
        for (k, j) in self.joints.iter().enumerate() {
            let m = match j.parent {
                Some(p) => w[p] * local[k],
                None => local[k],
            };
            w.push(m);
        }
        w
    }

    /// Local matrices from world matrices.
    pub fn local_from_world(&self, world: &[Mat4]) -> Vec<Mat4> {
        self.joints
            .iter()
            .enumerate()
            .map(|(k, j)| match j.parent {
                Some(p) => world[p].inverse() * world[k],
                None => world[k],
            })
            .collect()
    }
}

/// A bone: segment from the joint's world position (root) to its tip (SPEC.md).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bone {
    /// World position of the joint.
    pub root: Vec3,
    /// Average of the children's positions; for a leaf, root + the joint's +Y axis scaled by
    /// the parent bone's length.
    pub tip: Vec3,
}

impl Bone {
    /// Bone length.
    pub fn length(&self) -> f32 {
        // In f64: the squared length of a valid f32 vector beyond ~1e19 overflows f32.
        (self.tip.as_dvec3() - self.root.as_dvec3()).length() as f32
    }
}

/// Bones of one pose, given the joints' world matrices.
///
/// A leaf whose parent bone has zero length, or a lone root, is a zero-length bone
/// (tip = root); users of bones skip those.
pub fn bones(skeleton: &Skeleton, children: &[Vec<usize>], world: &[Mat4], out: &mut Vec<Bone>) {
    out.clear();
    let root = |k: usize| world[k].w_axis.truncate();
    for k in 0..skeleton.joints.len() {
        let r = root(k);
        let tip = if children[k].is_empty() {
            r
        } else {
            children[k].iter().map(|&c| root(c)).sum::<Vec3>() / children[k].len() as f32
        };
        out.push(Bone { root: r, tip });
    }
    // Leaves: parent-first order means parents' bones are final when we reach a leaf.
    for k in 0..skeleton.joints.len() {
        if !children[k].is_empty() {
            continue;
        }
        let len = skeleton.joints[k]
            .parent
            .map(|p| out[p].length())
            .unwrap_or(0.0);
        let axis = world[k]
            .y_axis
            .truncate()
            .try_normalize()
            .unwrap_or(Vec3::ZERO);
        out[k].tip = out[k].root + axis * len;
    }
}

/// A skeletal clip sampled at a fixed rate: world matrix of every joint in every frame,
/// frame-major.
#[derive(Debug, Clone, PartialEq)]
pub struct SkeletalAnimation {
    /// Frames per second.
    pub fps: f32,
    /// Time of frame 0.
    pub start_time: f32,
    joint_count: usize,
    world: Vec<Mat4>,
}

impl SkeletalAnimation {
    /// From a frame-major buffer of world matrices.
    pub fn new(fps: f32, joint_count: usize, world: Vec<Mat4>) -> Result<SkeletalAnimation> {
        if joint_count == 0 || !world.len().is_multiple_of(joint_count) || world.is_empty() {
            return Err(AnimError::LengthMismatch {
                what: "skeletal animation".into(),
                expected: joint_count,
                found: world.len(),
            });
        }
        if !world.iter().all(|m| m.is_finite()) {
            return Err(AnimError::NonFinite {
                what: "joint transforms".into(),
            });
        }
        Ok(SkeletalAnimation {
            fps,
            start_time: 0.0,
            joint_count,
            world,
        })
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.world.len() / self.joint_count
    }

    /// Number of joints.
    pub fn joint_count(&self) -> usize {
        self.joint_count
    }

    /// World matrices of frame `f`.
    pub fn frame(&self, f: usize) -> &[Mat4] {
        &self.world[f * self.joint_count..(f + 1) * self.joint_count]
    }

    /// Every frame's bones, frame-major (`frames × joints`).
    pub fn bones(&self, skeleton: &Skeleton) -> Vec<Bone> {
        let children = skeleton.children();
        let mut all = Vec::with_capacity(self.world.len());
        let mut tmp = Vec::new();
        for f in 0..self.frame_count() {
            bones(skeleton, &children, self.frame(f), &mut tmp);
            all.extend_from_slice(&tmp);
        }
        all
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chain() -> Skeleton {
        let j = |name: &str, parent, y| Joint {
            name: name.into(),
            parent,
            bind_local: Transform::from_translation(Vec3::new(0.0, y, 0.0)),
        };
        Skeleton {
            joints: vec![
                j("hip", None, 0.0),
                j("spine", Some(0), 1.0),
                j("head", Some(1), 2.0),
            ],
        }
    }

    #[test]
    fn leaf_tip_uses_parent_length() {
        let s = chain();
        let w = s.bind_world();
        let mut b = Vec::new();
        bones(&s, &s.children(), &w, &mut b);
        assert_eq!(b[0].tip, Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(b[1].tip, Vec3::new(0.0, 3.0, 0.0));
        // head: root (0,3,0) + Y * |spine| = 2
        assert!(b[2].tip.abs_diff_eq(Vec3::new(0.0, 5.0, 0.0), 1e-6));
    }

    #[test]
    fn local_world_round_trip() {
        let s = chain();
        let w = s.bind_world();
        let l = s.local_from_world(&w);
        let w2 = s.world_from_local(&l);
        for (a, b) in w.iter().zip(&w2) {
            assert!(a.abs_diff_eq(*b, 1e-6));
        }
    }
}
