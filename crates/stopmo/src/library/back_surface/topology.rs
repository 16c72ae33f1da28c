//! The shell's own topology, built once per part from its input triangles: the average
//! surface welded where glTF splits it at UV seams, bow-tie vertices split per fan, the
//! directed boundary edges, and the small openings (eyes, mouth) capped by a fan.

use std::collections::HashMap;
use std::sync::Arc;

use anim::Mesh;
use glam::Vec3;
use rayon::prelude::*;

use super::{caps, front_positions, position_key, untangle};
use crate::library::error::{LibraryError, Result};
use crate::library::fabricate::split_fans;

/// What [`weld`] builds (shell vertices: welded copies, fan-split copies, one per cap).
pub(super) struct ShellTopology {
    /// For every shell vertex but the caps' centroids, the input vertex it copies.
    pub source: Vec<u32>,
    /// Average front position of every shell vertex (caps' centroids last).
    pub front: Vec<Vec3>,
    /// Front triangles, the caps' fans last (outward oriented, like the input).
    pub triangles: Vec<[u32; 3]>,
    /// Directed boundary edges `a → b` left after capping (sorted).
    pub boundary: Vec<(u32, u32)>,
    /// Capped boundary loops; cap `i` adds the shell vertex `source.len() + i`.
    pub caps: Vec<Vec<u32>>,
}

/// Welds `topology`'s triangles over the positions `average` (exact duplicates, compacted to
/// the used vertices), splits bow-tie fans and caps the boundary loops shorter than
/// `cap_fraction` of the longest one.
///
/// # Errors
/// [`LibraryError::BadSurface`] for an index out of range or an edge used twice in the same
/// direction (not an oriented 2-manifold).
pub(super) fn weld(topology: &Mesh, average: &[Vec3], cap_fraction: f64) -> Result<ShellTopology> {
    let bad = |reason: String| LibraryError::BadSurface {
        mesh: topology.name.clone(),
        reason,
    };
    let nv = average.len();
    // Weld exact duplicates of the average (glTF UV seams), compact to used vertices.
    let mut by_bits: HashMap<[u32; 3], u32> = HashMap::new();
    let mut class = vec![u32::MAX; nv];
    let mut source: Vec<u32> = Vec::new();
    let mut tris = Vec::with_capacity(topology.triangles.len());
    for t in &topology.triangles {
        let mut out = [0u32; 3];
        for (o, &i) in out.iter_mut().zip(t) {
            let i = i as usize;
            if i >= nv {
                return Err(bad(format!("index {i} out of range ({nv} vertices)")));
            }
            if class[i] == u32::MAX {
                let key = position_key(average[i]);
                class[i] = *by_bits.entry(key).or_insert_with(|| {
                    source.push(i as u32);
                    (source.len() - 1) as u32
                });
            }
            *o = class[i];
        }
        if out[0] != out[1] && out[1] != out[2] && out[0] != out[2] {
            tris.push(out);
        }
    }
    let front: Vec<Vec3> = source.iter().map(|&s| average[s as usize]).collect();
    let (mut front, mut tris) = split_fans(front, tris);
    // Copies made by the fan split come after the welded vertices: find their source.
    let mut src = source.clone();
    if front.len() > src.len() {
        let at: HashMap<[u32; 3], u32> = source
            .iter()
            .enumerate()
            .map(|(i, &s)| (position_key(front[i]), s))
            .collect();
        for p in &front[source.len()..] {
            src.push(at.get(&position_key(*p)).copied().unwrap_or(0));
        }
    }
    let mut directed: HashMap<(u32, u32), ()> = HashMap::with_capacity(tris.len() * 3);
    for t in &tris {
        for k in 0..3 {
            let e = (t[k], t[(k + 1) % 3]);
            if directed.insert(e, ()).is_some() {
                return Err(bad(format!(
                    "edge {}–{} used twice in the same direction",
                    e.0, e.1
                )));
            }
        }
    }
    let mut boundary: Vec<(u32, u32)> = tris
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .filter(|&(a, b)| !directed.contains_key(&(b, a)))
        .collect();
    boundary.sort_unstable();
    // Cap the small boundary loops (eye and mouth openings): a fan from the loop's
    // centroid, so only the outer boundary (seams, neck, scalp) needs a wall.
    let caps = caps::cap_loops(&front, &mut boundary, cap_fraction);
    let regular = front.len();
    for (i, lp) in caps.iter().enumerate() {
        let c = (regular + i) as u32;
        front.push(lp.iter().map(|&v| front[v as usize]).sum::<Vec3>() / lp.len() as f32);
        for k in 0..lp.len() {
            let (a, b) = (lp[k], lp[(k + 1) % lp.len()]);
            tris.push([b, a, c]);
        }
    }
    Ok(ShellTopology {
        source: src,
        front,
        triangles: tris,
        boundary,
        caps,
    })
}

/// `mask` grown by `rings` rings of the adjacency `adj` (a vertex joins when a neighbour is
/// in).
pub(super) fn grow_mask(mut mask: Vec<bool>, adj: &[Vec<u32>], rings: usize) -> Vec<bool> {
    for _ in 0..rings {
        mask = (0..mask.len())
            .map(|v| mask[v] || adj[v].iter().any(|&w| mask[w as usize]))
            .collect();
    }
    mask
}

/// Vertex adjacency (sorted, deduplicated) of a triangle list.
pub(super) fn neighbours(n: usize, tris: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let mut adj = vec![Vec::new(); n];
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            adj[a as usize].push(b);
            adj[b as usize].push(a);
        }
    }
    for a in &mut adj {
        a.sort_unstable();
        a.dedup();
    }
    adj
}

/// Every piece's front laid over the shell vertices, as the piece gives it and untangled where
/// it crosses itself: built once per part and shared (behind an `Arc`) by the shells of both
/// direction fields, so that measuring, repairing and writing a piece never untangles it again
/// (the untangling's exact crossing tests were ~20 % of `stopmo run` on the README cut).
#[derive(Debug)]
pub(super) struct Fronts {
    /// Bits of every piece's front before untangling: the key a piece is found by.
    laid: Vec<Vec<[u32; 3]>>,
    /// Every piece's front, untangled.
    pub untangled: Vec<Vec<Vec3>>,
}

impl Fronts {
    /// The untangled front whose laid-out positions are exactly `laid` (bit for bit).
    pub(super) fn find(&self, laid: &[Vec3]) -> Option<&[Vec3]> {
        let k = self.laid.iter().position(|l| {
            l.len() == laid.len() && l.iter().zip(laid).all(|(a, &b)| *a == position_key(b))
        })?;
        Some(&self.untangled[k])
    }
}

/// What a part's back surfaces share whatever their direction field: the shell topology,
/// its adjacency and boundary, and every piece's (untangled) front over it.
pub(super) struct PartFrame {
    /// The welded, capped shell topology and average front.
    pub topo: ShellTopology,
    /// Vertex adjacency of the front triangles.
    pub adj: Vec<Vec<u32>>,
    /// Whether a shell vertex lies on the (uncapped) boundary.
    pub on_boundary: Vec<bool>,
    /// Every piece's front over the shell vertices, untangled where it crosses itself.
    pub fronts: Arc<Fronts>,
    /// The retraction per round those fronts were untangled with (mm).
    pub untangle_step_mm: f32,
}

impl PartFrame {
    /// [`weld`]s the part and lays every piece's front over it.
    ///
    /// # Errors
    /// As [`weld`].
    pub(super) fn new(
        topology: &Mesh,
        average: &[Vec3],
        pieces: &[&[Vec3]],
        cap_fraction: f64,
        untangle_step_mm: f32,
    ) -> Result<PartFrame> {
        let topo = weld(topology, average, cap_fraction)?;
        let n = topo.front.len();
        let adj = neighbours(n, &topo.triangles);
        let mut on_boundary = vec![false; n];
        for &(a, b) in &topo.boundary {
            on_boundary[a as usize] = true;
            on_boundary[b as usize] = true;
        }
        let (laid, untangled) = pieces
            .par_iter()
            .map(|p| {
                let laid = front_positions(&topo.source, &topo.caps, p);
                let mut f = laid.clone();
                untangle::untangle(
                    &mut f,
                    &topo.triangles,
                    &adj,
                    &on_boundary,
                    untangle_step_mm,
                );
                (laid.into_iter().map(position_key).collect(), f)
            })
            .unzip();
        Ok(PartFrame {
            topo,
            adj,
            on_boundary,
            fronts: Arc::new(Fronts { laid, untangled }),
            untangle_step_mm,
        })
    }
}
