//! Skin weights over kept bones and the joint neighbourhoods of Eq. 9, after pruning.

use anim::{Skeleton, Skin};

use crate::{Result, SmearError};

/// Membership flag: the vertex is in V_k,r (root-side neighbourhood of bone k).
pub(crate) const IN_ROOT: u8 = 1;
/// Membership flag: the vertex is in V_k,t (tip-side neighbourhood of bone k).
pub(crate) const IN_TIP: u8 = 2;

/// Per-vertex influences on kept skeleton joints and per-bone neighbourhoods, in compressed
/// rows.
#[derive(Debug, Clone, Default)]
pub(crate) struct Rig {
    row_start: Vec<u32>,
    row_joint: Vec<u32>,
    row_weight: Vec<f32>,
    hood_start: Vec<u32>,
    hood: Vec<HoodEntry>,
}

/// One vertex of a bone's neighbourhood V_k,r ∪ V_k,t.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct HoodEntry {
    /// Vertex index.
    pub(crate) vertex: u32,
    /// The vertex's (normalized) skin weight on the bone; 0 when it is only a neighbour.
    pub(crate) weight: f32,
    /// [`IN_ROOT`] | [`IN_TIP`] membership.
    pub(crate) flags: u8,
}

/// Joint hierarchy after pruning (paper Fig. 8d).
#[derive(Debug, Clone)]
pub(crate) struct Pruned {
    /// Nearest kept ancestor-or-self of every joint.
    pub(crate) drive: Vec<Option<usize>>,
    /// Kept parent of every kept joint.
    pub(crate) parent: Vec<Option<usize>>,
    /// Kept children of every kept joint.
    pub(crate) children: Vec<Vec<usize>>,
    /// Kept joints without a kept parent.
    pub(crate) roots: Vec<usize>,
}

impl Pruned {
    /// Resolves the pruned joint names.
    ///
    /// # Errors
    /// [`SmearError::UnknownJoint`] for a name that is not a joint.
    pub(crate) fn new(skeleton: &Skeleton, prune: &[String]) -> Result<Pruned> {
        let n = skeleton.len();
        let mut kept = vec![true; n];
        for name in prune {
            let k = skeleton.find(name).map_err(|_| SmearError::UnknownJoint {
                name: name.clone(),
                available: skeleton
                    .joints
                    .iter()
                    .map(|j| j.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            })?;
            kept[k] = false;
        }
        let mut drive = vec![None; n];
        let mut parent = vec![None; n];
        let mut children = vec![Vec::new(); n];
        let mut roots = Vec::new();
        for (k, j) in skeleton.joints.iter().enumerate() {
            // Parent-first order: the parent's drive is final.
            let up = j.parent.and_then(|p| drive.get(p).copied().flatten());
            if kept[k] {
                drive[k] = Some(k);
                parent[k] = up;
                match up {
                    Some(p) => children[p].push(k),
                    None => roots.push(k),
                }
            } else {
                drive[k] = up;
            }
        }
        Ok(Pruned {
            drive,
            parent,
            children,
            roots,
        })
    }
}

impl Rig {
    /// Builds the rig of a group of skinned meshes (vertex order = order of `parts`).
    ///
    /// # Errors
    /// [`SmearError::PruneWithoutAncestor`] when a vertex is weighted on a pruned joint that has
    /// no kept ancestor.
    pub(crate) fn new(skeleton: &Skeleton, pruned: &Pruned, parts: &[&Skin]) -> Result<Rig> {
        let n = skeleton.len();
        let mut rig = Rig {
            row_start: vec![0],
            ..Rig::default()
        };
        let mut row: Vec<(u32, f32)> = Vec::with_capacity(8);
        for skin in parts {
            for v in 0..skin.weights.vertex_count() {
                row.clear();
                let (slots, w) = skin.weights.influences(v);
                for (&s, &x) in slots.iter().zip(w) {
                    let j = skin.joints[s as usize];
                    let Some(k) = pruned.drive[j] else {
                        return Err(SmearError::PruneWithoutAncestor {
                            name: skeleton.joints[j].name.clone(),
                        });
                    };
                    match row.iter_mut().find(|e| e.0 == k as u32) {
                        Some(e) => e.1 += x,
                        None => row.push((k as u32, x)),
                    }
                }
                let sum: f32 = row.iter().map(|e| e.1).sum();
                for &(k, x) in &row {
                    rig.row_joint.push(k);
                    rig.row_weight.push(x / sum);
                }
                rig.row_start.push(rig.row_joint.len() as u32);
            }
        }

        // Neighbourhoods (SPEC.md): V_k,t ∋ vertices on k or its children; V_k,r ∋ vertices on
        // k, its parent or the parent's other children (for a root: on any root bone).
        let mut hoods: Vec<Vec<HoodEntry>> = vec![Vec::new(); n];
        let mut local: Vec<(usize, u8)> = Vec::with_capacity(32);
        for v in 0..rig.vertex_count() {
            local.clear();
            let mut mark = |k: usize, flag: u8| match local.iter_mut().find(|e| e.0 == k) {
                Some(e) => e.1 |= flag,
                None => local.push((k, flag)),
            };
            for &m in rig.influences(v).0 {
                let m = m as usize;
                mark(m, IN_ROOT | IN_TIP);
                if let Some(p) = pruned.parent[m] {
                    mark(p, IN_TIP);
                    for &s in &pruned.children[p] {
                        mark(s, IN_ROOT);
                    }
                } else {
                    for &r in &pruned.roots {
                        mark(r, IN_ROOT);
                    }
                }
                for &c in &pruned.children[m] {
                    mark(c, IN_ROOT);
                }
            }
            let (js, ws) = rig.influences(v);
            for &(k, flags) in &local {
                let weight = js
                    .iter()
                    .zip(ws)
                    .find(|(j, _)| **j as usize == k)
                    .map_or(0.0, |(_, w)| *w);
                hoods[k].push(HoodEntry {
                    vertex: v as u32,
                    weight,
                    flags,
                });
            }
        }
        rig.hood_start.push(0);

        for h in hoods {
            rig.hood.extend_from_slice(&h);
            rig.hood_start.push(rig.hood.len() as u32);
        }
        Ok(rig)
    }

    /// Number of vertices.
    pub(crate) fn vertex_count(&self) -> usize {
        self.row_start.len() - 1
    }

    /// Number of joints.
    pub(crate) fn joint_count(&self) -> usize {
        self.hood_start.len().saturating_sub(1)
    }

    /// Kept joints and normalized weights of vertex `v`.
    #[inline]
    pub(crate) fn influences(&self, v: usize) -> (&[u32], &[f32]) {
        let (a, b) = (self.row_start[v] as usize, self.row_start[v + 1] as usize);
        (&self.row_joint[a..b], &self.row_weight[a..b])
    }

    /// Vertices of V_k,r ∪ V_k,t, ascending, with their weights and membership flags.
    #[inline]
    pub(crate) fn hood(&self, k: usize) -> &[HoodEntry] {
        &self.hood[self.hood_start[k] as usize..self.hood_start[k + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim::{Joint, Transform, VertexWeights};
    use glam::Mat4;

    fn chain(names: &[&str]) -> Skeleton {
        Skeleton {
            joints: names
                .iter()
                .enumerate()
                .map(|(k, n)| Joint {
                    name: n.to_string(),
                    parent: k.checked_sub(1),
                    bind_local: Transform::IDENTITY,
                })
                .collect(),
        }
    }

    #[test]
    fn pruned_hand_follows_the_forearm() {
        let s = chain(&["arm", "forearm", "hand"]);
        let p = Pruned::new(&s, &["hand".into()]).unwrap();
        assert_eq!(p.drive, vec![Some(0), Some(1), Some(1)]);
        assert!(p.children[1].is_empty());
        let skin = Skin {
            joints: vec![0, 1, 2],
            inverse_bind: vec![Mat4::IDENTITY; 3],
            weights: VertexWeights::from_influences(vec![
                vec![(0, 1.0)],
                vec![(1, 0.5), (2, 0.5)],
                vec![(2, 1.0)],
            ]),
        };
        let rig = Rig::new(&s, &p, &[&skin]).unwrap();
        assert_eq!(rig.influences(1), (&[1u32][..], &[1.0f32][..]));
        assert_eq!(rig.influences(2).0, &[1]);
        // V_forearm,t = vertices on the forearm (and no kept child); V_forearm,r adds the arm's.
        let hood = rig.hood(1);
        assert_eq!(hood.iter().map(|e| e.vertex).collect::<Vec<_>>(), [0, 1, 2]);
        assert_eq!(
            hood.iter().map(|e| e.flags).collect::<Vec<_>>(),
            [IN_ROOT, IN_ROOT | IN_TIP, IN_ROOT | IN_TIP]
        );
        assert_eq!(
            hood.iter().map(|e| e.weight).collect::<Vec<_>>(),
            [0.0, 1.0, 1.0]
        );
        assert!(rig.hood(2).is_empty());
        assert!(matches!(
            Pruned::new(&s, &["wrist".into()]),
            Err(SmearError::UnknownJoint { .. })
        ));
        let root_pruned = Pruned::new(&s, &["arm".into()]).unwrap();
        assert!(matches!(
            Rig::new(&s, &root_pruned, &[&skin]),
            Err(SmearError::PruneWithoutAncestor { .. })
        ));
    }
}
