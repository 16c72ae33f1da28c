//! Skin weights over kept bones and the joint neighbourhoods of SMEAR Eq. 9, after pruning.

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
    /// Per bone: start of its neighbourhood in `hood_vertex` / `hood_flags`.
    hood_start: Vec<u32>,
    hood_vertex: Vec<u32>,
    hood_flags: Vec<u8>,
    /// 1.0 where the entry is in V_k,r (resp. V_k,t), else 0.0: masks for vectorized maxima.
    hood_in_root: Vec<f32>,
    hood_in_tip: Vec<f32>,
    /// Per bone: start of its skinned entries in `skinned_at` / `skinned_weight`.
    skinned_start: Vec<u32>,
    skinned_at: Vec<u32>,
    skinned_weight: Vec<f32>,
    /// Per bone: start of its runs in `runs`.
    run_start: Vec<u32>,
    /// `(first vertex, length)` of the runs of consecutive vertices of each neighbourhood
    /// whose runs are long enough (see [`MIN_MEAN_RUN`]); none for fragmented ones.
    runs: Vec<(u32, u32)>,
    max_hood: usize,
}

/// A neighbourhood whose runs of consecutive vertex indices are at least this long on
/// average is evaluated run by run straight from struct-of-arrays positions, without a
/// gather (vertices of one bone are often stored together).
pub(crate) const MIN_MEAN_RUN: usize = 32;

/// Bone k's neighbourhood V_k,r ∪ V_k,t in struct-of-arrays form (vertices ascending), as the
/// batched ribbon evaluation reads it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Hood<'a> {
    /// Vertex indices.
    pub(crate) vertex: &'a [u32],
    /// [`IN_ROOT`] | [`IN_TIP`] membership of each vertex.
    pub(crate) flags: &'a [u8],
    /// `flags` as multiplicative masks: 1.0 for entries in V_k,r, else 0.0.
    pub(crate) in_root: &'a [f32],
    /// 1.0 for entries in V_k,t, else 0.0.
    pub(crate) in_tip: &'a [f32],
    /// Positions in `vertex` of the vertices skinned to the bone (non-zero weight).
    pub(crate) skinned_at: &'a [u32],
    /// Their (normalized) skin weights on the bone.
    pub(crate) skinned_weight: &'a [f32],
    /// `(first vertex, length)` of the runs of consecutive vertices covering `vertex` in
    /// order, or empty when the neighbourhood is too fragmented (then gather `vertex`).
    pub(crate) runs: &'a [(u32, u32)],
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
        // Per joint m, the neighbourhoods a vertex on m belongs to (merged flags), once.
        let marks: Vec<Vec<(usize, u8)>> = (0..n)
            .map(|m| {
                let mut l: Vec<(usize, u8)> = Vec::new();
                let mut mark = |k: usize, flag: u8| match l.iter_mut().find(|e| e.0 == k) {
                    Some(e) => e.1 |= flag,
                    None => l.push((k, flag)),
                };
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
                l
            })
            .collect();
        let mut hoods: Vec<Vec<(u32, f32, u8)>> = vec![Vec::new(); n];
        let mut local: Vec<(usize, u8)> = Vec::with_capacity(32);
        for v in 0..rig.vertex_count() {
            let (js, ws) = rig.influences(v);
            let local: &[(usize, u8)] = if let [m] = js {
                &marks[*m as usize]
            } else {
                local.clear();
                for &m in js {
                    for &(k, flag) in &marks[m as usize] {
                        match local.iter_mut().find(|e| e.0 == k) {
                            Some(e) => e.1 |= flag,
                            None => local.push((k, flag)),
                        }
                    }
                }
                &local
            };
            for &(k, flags) in local {
                let weight = js
                    .iter()
                    .zip(ws)
                    .find(|(j, _)| **j as usize == k)
                    .map_or(0.0, |(_, w)| *w);
                hoods[k].push((v as u32, weight, flags));
            }
        }
        rig.hood_start.push(0);
        rig.skinned_start.push(0);
        rig.run_start.push(0);
        let mut runs: Vec<(u32, u32)> = Vec::new();
        for h in hoods {
            runs.clear();
            for &(v, _, _) in &h {
                match runs.last_mut() {
                    Some((first, len)) if *first + *len == v => *len += 1,
                    _ => runs.push((v, 1)),
                }
            }
            if h.len() >= MIN_MEAN_RUN * runs.len() {
                rig.runs.extend_from_slice(&runs);
            }
            rig.run_start.push(rig.runs.len() as u32);
            rig.max_hood = rig.max_hood.max(h.len());
            for (i, &(v, w, flags)) in h.iter().enumerate() {
                if w > 0.0 {
                    rig.skinned_at.push(i as u32);
                    rig.skinned_weight.push(w);
                }
                rig.hood_vertex.push(v);
                rig.hood_flags.push(flags);
                let mask = |f: u8| if flags & f != 0 { 1.0 } else { 0.0 };
                rig.hood_in_root.push(mask(IN_ROOT));
                rig.hood_in_tip.push(mask(IN_TIP));
            }
            rig.hood_start.push(rig.hood_vertex.len() as u32);
            rig.skinned_start.push(rig.skinned_at.len() as u32);
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

    /// Vertices of V_k,r ∪ V_k,t, ascending, with their membership flags and skin weights.
    #[inline]
    pub(crate) fn hood(&self, k: usize) -> Hood<'_> {
        let (a, b) = (self.hood_start[k] as usize, self.hood_start[k + 1] as usize);
        let (c, d) = (
            self.skinned_start[k] as usize,
            self.skinned_start[k + 1] as usize,
        );
        let (e, f) = (self.run_start[k] as usize, self.run_start[k + 1] as usize);
        Hood {
            runs: &self.runs[e..f],
            vertex: &self.hood_vertex[a..b],
            flags: &self.hood_flags[a..b],
            in_root: &self.hood_in_root[a..b],
            in_tip: &self.hood_in_tip[a..b],
            skinned_at: &self.skinned_at[c..d],
            skinned_weight: &self.skinned_weight[c..d],
        }
    }

    /// Whether some neighbourhood is evaluated by runs (see [`Hood::runs`]).
    pub(crate) fn has_runs(&self) -> bool {
        !self.runs.is_empty()
    }

    /// Size of the largest neighbourhood (scratch size of the batched evaluation).
    pub(crate) fn max_hood_len(&self) -> usize {
        self.max_hood
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
        assert_eq!(hood.vertex, [0, 1, 2]);
        assert_eq!(hood.flags, [IN_ROOT, IN_ROOT | IN_TIP, IN_ROOT | IN_TIP]);
        assert_eq!(
            (hood.in_root, hood.in_tip),
            (&[1.0; 3][..], &[0.0, 1.0, 1.0][..])
        );
        assert_eq!(hood.skinned_at, [1, 2]);
        assert_eq!(hood.skinned_weight, [1.0, 1.0]);
        assert!(rig.hood(2).vertex.is_empty());
        assert_eq!(rig.max_hood_len(), 3);
        // Three consecutive vertices: one run, but too short to be worth it.
        assert!(hood.runs.is_empty() && !rig.has_runs());
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
