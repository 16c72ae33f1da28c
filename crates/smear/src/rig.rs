//! Skin weights over kept bones and the joint neighbourhoods of SMEAR Eq. 9, after pruning.

use std::ops::Range;

use anim::{Skeleton, Skin};
use rayon::prelude::*;

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

/// Vertices per parallel job of [`Rig::new`].
const RIG_BLOCK: usize = 4096;

/// Rows and neighbourhood entries of a block of consecutive vertices (see [`Rig::new`]).
struct Block {
    /// End of each vertex's row in `row_joint` / `row_weight`.
    row_end: Vec<u32>,
    row_joint: Vec<u32>,
    row_weight: Vec<f32>,
    /// End of each vertex's entries in `entries`.
    entry_end: Vec<u32>,
    /// `(bone, membership flags, skin weight on the bone)` of each neighbourhood a vertex is in.
    entries: Vec<(u32, u8, f32)>,
    /// Entries per bone.
    count: Vec<u32>,
}

impl Block {
    /// The rows of the vertices in `range` (indices over the concatenated `parts`): their
    /// influences merged onto kept joints and normalized; then the neighbourhoods each vertex
    /// belongs to (`marks`, per joint), with merged flags and the vertex's weight on the bone.
    fn new(
        skeleton: &Skeleton,
        pruned: &Pruned,
        parts: &[&Skin],
        marks: &[Vec<(usize, u8)>],
        range: Range<usize>,
    ) -> Result<Block> {
        let len = range.len();
        let mut block = Block {
            row_end: Vec::with_capacity(len),
            // Two influences per vertex is typical of a skinned mesh: most rows fit.
            row_joint: Vec::with_capacity(2 * len),
            row_weight: Vec::with_capacity(2 * len),
            entry_end: Vec::with_capacity(len),
            entries: Vec::with_capacity(3 * len),
            count: vec![0; marks.len()],
        };
        let mut row: Vec<(u32, f32)> = Vec::with_capacity(8);
        let mut base = 0;
        for skin in parts {
            let count = skin.weights.vertex_count();
            for v in range.start.max(base)..range.end.min(base + count) {
                row.clear();
                let (slots, w) = skin.weights.influences(v - base);
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
                    block.row_joint.push(k);
                    block.row_weight.push(x / sum);
                }
                block.row_end.push(block.row_joint.len() as u32);
            }
            base += count;
        }
        let mut a = 0;
        for &end in &block.row_end {
            let (js, ws) = (
                &block.row_joint[a..end as usize],
                &block.row_weight[a..end as usize],
            );
            a = end as usize;
            let row = block.entries.len();
            for &m in js {
                for &(k, flag) in &marks[m as usize] {
                    let k = k as u32;
                    match block.entries[row..].iter_mut().find(|e| e.0 == k) {
                        Some(e) => e.1 |= flag,
                        None => {
                            let w = js.iter().zip(ws).find(|(j, _)| **j == k);
                            block.entries.push((k, flag, w.map_or(0.0, |(_, w)| *w)));
                            block.count[k as usize] += 1;
                        }
                    }
                }
            }
            block.entry_end.push(block.entries.len() as u32);
        }
        Ok(block)
    }
}

/// Per joint m, the neighbourhoods a vertex on m belongs to, with merged flags (SPEC.md):
/// V_k,t ∋ vertices on k or its children; V_k,r ∋ vertices on k, its parent or the parent's
/// other children (for a root: on any root bone).
fn neighbourhood_marks(n: usize, pruned: &Pruned) -> Vec<Vec<(usize, u8)>> {
    (0..n)
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
        .collect()
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
    ///
    /// # Performance
    /// Each vertex's row and neighbourhood entries are built in blocks of [`RIG_BLOCK`]
    /// vertices in parallel (the rig is built on the critical path, between the sampling and
    /// the ribbons), then concatenated, and every entry written into its bone's neighbourhood
    /// in one pass over the vertices.
    pub(crate) fn new(skeleton: &Skeleton, pruned: &Pruned, parts: &[&Skin]) -> Result<Rig> {
        let n = skeleton.len();
        let nv: usize = parts.iter().map(|s| s.weights.vertex_count()).sum();
        let marks = neighbourhood_marks(n, pruned);
        let blocks: Vec<Result<Block>> = (0..nv.div_ceil(RIG_BLOCK))
            .into_par_iter()
            .map(|b| {
                let range = b * RIG_BLOCK..((b + 1) * RIG_BLOCK).min(nv);
                Block::new(skeleton, pruned, parts, &marks, range)
            })
            .collect();
        // The first failing vertex's error (blocks in order), as a serial pass reports it.
        let blocks = blocks.into_iter().collect::<Result<Vec<Block>>>()?;
        let mut rig = Rig {
            row_start: Vec::with_capacity(nv + 1),
            ..Rig::default()
        };
        rig.row_start.push(0);
        let rows: usize = blocks.iter().map(|b| b.row_joint.len()).sum();
        rig.row_joint.reserve(rows);
        rig.row_weight.reserve(rows);
        let mut count = vec![0u32; n];
        for b in &blocks {
            let base = rig.row_joint.len() as u32;
            rig.row_start.extend(b.row_end.iter().map(|e| base + e));
            rig.row_joint.extend_from_slice(&b.row_joint);
            rig.row_weight.extend_from_slice(&b.row_weight);
            for (c, &x) in count.iter_mut().zip(&b.count) {
                *c += x;
            }
        }
        let total: usize = count.iter().map(|&c| c as usize).sum();
        rig.hood_start = Vec::with_capacity(n + 1);
        rig.hood_start.push(0);
        for &c in &count {
            let last = *rig.hood_start.last().expect("starts at 0");
            rig.hood_start.push(last + c);
        }
        let mut fill: Vec<u32> = rig.hood_start[..n].to_vec();
        rig.hood_vertex = vec![0; total];
        rig.hood_flags = vec![0; total];
        let mut weight = vec![0.0f32; total];
        for (b, block) in blocks.iter().enumerate() {
            let mut a = 0;
            for (i, &end) in block.entry_end.iter().enumerate() {
                let v = (b * RIG_BLOCK + i) as u32;
                for &(k, flags, w) in &block.entries[a..end as usize] {
                    let at = fill[k as usize] as usize;
                    fill[k as usize] += 1;
                    rig.hood_vertex[at] = v;
                    rig.hood_flags[at] = flags;
                    weight[at] = w;
                }
                a = end as usize;
            }
        }
        let mask = |f: u8| move |&flags: &u8| if flags & f != 0 { 1.0 } else { 0.0 };
        rig.hood_in_root = rig.hood_flags.iter().map(mask(IN_ROOT)).collect();
        rig.hood_in_tip = rig.hood_flags.iter().map(mask(IN_TIP)).collect();
        rig.skinned_start.push(0);
        rig.run_start.push(0);
        let mut runs: Vec<(u32, u32)> = Vec::new();
        for k in 0..n {
            let (a, b) = (rig.hood_start[k] as usize, rig.hood_start[k + 1] as usize);
            let hood = &rig.hood_vertex[a..b];
            runs.clear();
            for &v in hood {
                match runs.last_mut() {
                    Some((first, len)) if *first + *len == v => *len += 1,
                    _ => runs.push((v, 1)),
                }
            }
            if hood.len() >= MIN_MEAN_RUN * runs.len() {
                rig.runs.extend_from_slice(&runs);
            }
            rig.run_start.push(rig.runs.len() as u32);
            rig.max_hood = rig.max_hood.max(hood.len());
            for (i, &w) in weight[a..b].iter().enumerate() {
                if w > 0.0 {
                    rig.skinned_at.push(i as u32);
                    rig.skinned_weight.push(w);
                }
            }
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

    /// Two skins of several blocks each: every row, neighbourhood, flag and skinned weight is
    /// what a vertex-by-vertex reading of SPEC.md's neighbourhoods gives, vertices ascending,
    /// and the first failing vertex is reported, whichever block fails first.
    #[test]
    fn blocks_join_like_one_pass_over_the_vertices() {
        let s = chain(&["hips", "spine", "chest", "neck"]);
        let p = Pruned::new(&s, &["neck".into()]).unwrap();
        let skin = |n: usize, shift: usize| Skin {
            joints: vec![0, 1, 2, 3],
            inverse_bind: vec![Mat4::IDENTITY; 4],
            weights: VertexWeights::from_influences((0..n).map(|v| {
                let j = ((v + shift) / 700 % 4) as u32;
                let w = (v % 5) as f32 * 0.2;
                if w == 0.0 {
                    vec![(j, 1.0)]
                } else {
                    vec![(j, 1.0 - w), ((j + 1) % 4, w)]
                }
            })),
        };
        let (a, b) = (skin(RIG_BLOCK + 1234, 0), skin(2 * RIG_BLOCK + 17, 300));
        let rig = Rig::new(&s, &p, &[&a, &b]).unwrap();
        let n = a.weights.vertex_count() + b.weights.vertex_count();
        assert_eq!(rig.vertex_count(), n);
        // Vertex by vertex: kept joints (neck → chest) with merged, normalized weights.
        let rows: Vec<Vec<(u32, f32)>> = [
            (&a, a.weights.vertex_count()),
            (&b, b.weights.vertex_count()),
        ]
        .iter()
        .flat_map(|(sk, len)| {
            (0..*len).map(|v| {
                let mut row: Vec<(u32, f32)> = Vec::new();
                let (slots, w) = sk.weights.influences(v);
                for (&j, &x) in slots.iter().zip(w) {
                    let k = p.drive[j as usize].unwrap() as u32;
                    match row.iter_mut().find(|e| e.0 == k) {
                        Some(e) => e.1 += x,
                        None => row.push((k, x)),
                    }
                }
                let sum: f32 = row.iter().map(|e| e.1).sum();
                row.iter().map(|&(k, x)| (k, x / sum)).collect()
            })
        })
        .collect();
        for (v, row) in rows.iter().enumerate() {
            let (js, ws) = rig.influences(v);
            assert_eq!(
                js,
                row.iter().map(|e| e.0).collect::<Vec<_>>(),
                "vertex {v}"
            );
            assert_eq!(
                ws,
                row.iter().map(|e| e.1).collect::<Vec<_>>(),
                "vertex {v}"
            );
        }
        let marks = neighbourhood_marks(s.len(), &p);
        for k in 0..s.len() {
            let hood = rig.hood(k);
            let mut want = (Vec::new(), Vec::new(), Vec::new());
            for (v, row) in rows.iter().enumerate() {
                let flags = row
                    .iter()
                    .flat_map(|&(m, _)| &marks[m as usize])
                    .filter(|e| e.0 == k)
                    .fold(0u8, |f, e| f | e.1);
                if flags != 0 {
                    if let Some(&(_, w)) = row.iter().find(|e| e.0 == k as u32) {
                        want.2.push((want.0.len() as u32, w));
                    }
                    want.0.push(v as u32);
                    want.1.push(flags);
                }
            }
            assert_eq!(hood.vertex, want.0, "bone {k}");
            assert_eq!(hood.flags, want.1, "bone {k}");
            let skinned: Vec<(u32, f32)> = hood
                .skinned_at
                .iter()
                .copied()
                .zip(hood.skinned_weight.iter().copied())
                .collect();
            assert_eq!(skinned, want.2, "bone {k}");
        }
        assert!(rig.hood(0).vertex.len() > RIG_BLOCK, "a bone spans blocks");
        // Two roots pruned: the first failing vertex (block 1, on "prop") is reported, not a
        // later block's (block 2, on "hips").
        let mut two = chain(&["hips", "spine", "prop"]);
        two.joints[2].parent = None;
        let bad = Pruned::new(&two, &["hips".into(), "prop".into()]).unwrap();
        let c = Skin {
            joints: vec![0, 1, 2],
            inverse_bind: vec![Mat4::IDENTITY; 3],
            weights: VertexWeights::from_influences((0..3 * RIG_BLOCK).map(|v| match v {
                v if v == RIG_BLOCK + 5 => vec![(2, 1.0)],
                v if v == 2 * RIG_BLOCK + 9 => vec![(0, 1.0)],
                _ => vec![(1, 1.0)],
            })),
        };
        match Rig::new(&two, &bad, &[&c]) {
            Err(SmearError::PruneWithoutAncestor { name }) => assert_eq!(name, "prop"),
            other => panic!("expected PruneWithoutAncestor, got {other:?}"),
        }
    }
}
