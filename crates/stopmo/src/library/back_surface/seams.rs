//! Where a part's back surface meets other parts and other shots: the seam vertices and
//! walls shared with neighbouring parts, and a printed back surface reused by new pieces
//! (`--fixed`).

use std::collections::{HashMap, HashSet};

use anim::Mesh;
use glam::Vec3;

use super::resolve::resolve_crossings;
use super::topology::grow_mask;
use super::{centroid, position_key, PartShell, ShellOptions};
use crate::library::error::{LibraryError, Result};

/// One part's input to [`build_shells`] (millimetres).
#[derive(Debug, Clone)]
pub struct ShellInput<'a> {
    /// The part's triangles (outward oriented, edge-manifold after welding).
    pub topology: &'a Mesh,
    /// The part's average surface.
    pub average: &'a [Vec3],
    /// Every piece of the part (same vertex count).
    pub pieces: Vec<&'a [Vec3]>,
    /// A printed back surface to reuse ([`PartShell::use_back`]); its seam points stay as
    /// printed.
    pub printed_back: Option<&'a [Vec3]>,
}

/// Rings of back vertices around a moved seam point that follow it.
const SEAM_RELAX_RINGS: usize = 10;
/// Relaxation steps after seam points moved.
const SEAM_RELAX_STEPS: usize = 60;

/// Back surfaces of all parts of a segmentation, with their seam walls shared.
///
/// Parts are built in order; a part's boundary vertices on a seam with an earlier part take
/// that part's back points ([`PartShell::new_sharing`]), so that the walls of both parts
/// along the seam are one surface. Where such a point lies within the wall of the later
/// part's pieces (its surface is deeper there), the later part moves it deeper along its
/// direction field and the earlier parts' back points there follow: taking the earlier
/// point as is left 0.9 mm walls under a 1.5 mm wall (ICT face, `--auto-parts 3`). A
/// printed back's points stay as printed (the later part's wall may then be thinner; the
/// measurements say so).
///
/// # Errors
/// As [`PartShell::new`]; [`LibraryError::PrintedBack`] when a printed back does not fit its
/// part.
///
/// # Performance
/// One shell construction per part; a part whose seam points moved is measured again.
pub fn build_shells(inputs: &[ShellInput<'_>], opts: &ShellOptions) -> Result<Vec<PartShell>> {
    // Seam points decided so far (average, back), where each key sits, which are printed.
    let mut shared: Vec<(Vec3, Vec3)> = Vec::new();
    let mut printed_keys: HashSet<[u32; 3]> = HashSet::new();
    let mut at: HashMap<[u32; 3], usize> = HashMap::new();
    let mut out: Vec<PartShell> = Vec::with_capacity(inputs.len());
    for input in inputs {
        let mut shell =
            PartShell::new_sharing(input.topology, input.average, &input.pieces, opts, &shared)?;
        if let Some(back) = input.printed_back {
            shell
                .use_back(back, &input.pieces)
                .map_err(|e| LibraryError::PrintedBack {
                    part: input.topology.name.clone(),
                    reason: match e {
                        LibraryError::InvalidParameter(r) => r,
                        other => other.to_string(),
                    },
                })?;
        }
        // Points this part moved deeper: a printed back's go back (it is printed), the
        // others move in the earlier parts too.
        let mut moved: HashMap<[u32; 3], Vec3> = HashMap::new();
        let mut restore: HashMap<[u32; 3], Vec3> = HashMap::new();
        for (average, back) in shell.boundary_pairs(input.average) {
            let k = position_key(average);
            match at.get(&k) {
                Some(&i) if shared[i].1 != back => {
                    if printed_keys.contains(&k) {
                        restore.insert(k, shared[i].1);
                    } else {
                        shared[i].1 = back;
                        moved.insert(k, back);
                    }
                }
                Some(_) => {}
                None => {
                    at.insert(k, shared.len());
                    shared.push((average, back));
                    if input.printed_back.is_some() {
                        printed_keys.insert(k);
                    }
                }
            }
        }
        if !restore.is_empty() && shell.set_seam_backs(input.average, &restore) {
            shell.measure(&input.pieces);
        }
        if !moved.is_empty() {
            for (earlier, earlier_input) in out.iter_mut().zip(inputs) {
                if earlier.set_seam_backs(earlier_input.average, &moved) {
                    earlier.measure(&earlier_input.pieces);
                }
            }
        }
        out.push(shell);
    }
    // Last, the search that moves single back vertices where solids still cross (a seam's
    // point in both parts); a printed back stays whole.
    if out.iter().any(|s| s.stats.self_intersecting_triangles > 0) {
        let averages: Vec<&[Vec3]> = inputs.iter().map(|i| i.average).collect();
        let pieces: Vec<Vec<&[Vec3]>> = inputs.iter().map(|i| i.pieces.clone()).collect();
        let frozen: Vec<bool> = inputs.iter().map(|i| i.printed_back.is_some()).collect();
        resolve_crossings(
            &mut out,
            &averages,
            &pieces,
            &frozen,
            opts.wall_mm,
            opts.resolve_rounds,
        );
    }
    // Then the wall, wherever a front point came closer to the back than it (a printed
    // back stays as printed; the measurements say where).
    for (shell, input) in out.iter_mut().zip(inputs) {
        if input.printed_back.is_none() && shell.stats.min_wall_mm < opts.wall_mm {
            shell.stats.thickened_back_points = shell.thicken(&input.pieces, opts.wall_mm);
            if shell.stats.thickened_back_points > 0 {
                shell.measure(&input.pieces);
            }
        }
    }
    Ok(out)
}

/// Back points of a part's shared seam vertices (`shared[v]`, the earlier part's point),
/// each moved deeper along the direction field where it lies within this part's wall
/// (`point · normals[v] > limit[v]`), its neighbours along the seam (`along`, the boundary
/// loops' previous and next vertex) following by a tent that falls to zero over `spread` mm,
/// so the seam's back curve stays smooth. [`build_shells`] moves them in the earlier parts
/// too.
pub(super) fn deepen_shared(
    shared: &[Option<Vec3>],
    front: &[Vec3],
    normals: &[Vec3],
    limit: &[f32],
    along: &[[u32; 2]],
    spread: f32,
) -> Vec<Option<Vec3>> {
    let mut deeper = vec![0.0f32; shared.len()];
    for (v, p) in shared.iter().enumerate() {
        let Some(p) = p else { continue };
        let excess = p.dot(normals[v]) - limit[v];
        if excess <= 0.0 {
            continue;
        }
        deeper[v] = deeper[v].max(excess);
        for side in 0..2 {
            let (mut u, mut walked) = (v, 0.0f32);
            loop {
                let w = along[u][side] as usize;
                if w == u32::MAX as usize || w == v || shared[w].is_none() {
                    break;
                }
                walked += front[u].distance(front[w]);
                if walked >= spread {
                    break;
                }
                u = w;
                deeper[u] = deeper[u].max(excess * (1.0 - walked / spread));
            }
        }
    }
    shared
        .iter()
        .zip(normals.iter().zip(&deeper))
        .map(|(p, (n, d))| p.map(|p| p - *n * *d))
        .collect()
}

impl PartShell {
    /// `(average front position, back position)` of every boundary vertex, to share the seam
    /// walls with the next part ([`PartShell::new_sharing`]).
    pub fn boundary_pairs(&self, average: &[Vec3]) -> Vec<(Vec3, Vec3)> {
        let mut out: Vec<(Vec3, Vec3)> = (0..self.back.len())
            .filter(|&v| self.on_boundary[v])
            .filter_map(|v| {
                average
                    .get(self.source[v] as usize)
                    .map(|a| (*a, self.back[v]))
            })
            .collect();
        out.dedup();
        out
    }

    /// Sets the back point of every boundary vertex whose average front position
    /// (`average`, this part's) is a key of `points`; whether any changed.
    fn set_seam_backs(&mut self, average: &[Vec3], points: &HashMap<[u32; 3], Vec3>) -> bool {
        let mut changed = Vec::new();
        for v in 0..self.back.len() {
            if !self.on_boundary[v] {
                continue;
            }
            let Some(a) = average.get(self.source[v] as usize) else {
                continue;
            };
            if let Some(&p) = points.get(&position_key(*a)) {
                if self.back[v] != p {
                    changed.push(v as u32);
                }
                self.back[v] = p;
            }
        }
        self.relax_around(&changed, SEAM_RELAX_RINGS, SEAM_RELAX_STEPS);
        !changed.is_empty()
    }

    /// Relaxes the back's interior vertices within `rings` of `moved` (boundary vertices
    /// that were set) towards their neighbours, keeping the wall behind every piece, so the
    /// back follows the moved points without a kink.
    fn relax_around(&mut self, moved: &[u32], rings: usize, steps: usize) {
        let n = self.back.len();
        let mut mask = vec![false; n];
        for &v in moved {
            mask[v as usize] = true;
        }
        let mask = grow_mask(mask, &self.adjacency, rings);
        for _ in 0..steps {
            let back = &self.back;
            let next: Vec<Vec3> = (0..n)
                .map(|v| {
                    let adj = &self.adjacency[v];
                    if !mask[v] || self.on_boundary[v] || adj.is_empty() {
                        return back[v];
                    }
                    let c = centroid(back, adj);
                    let p = back[v] + (c - back[v]) * 0.5;
                    let (d, h) = (self.normals[v], p.dot(self.normals[v]));
                    p - d * (h - self.limits[v]).max(0.0)
                })
                .collect();
            self.back = next;
        }
    }

    /// Measures the wall and the crossings again after the back changed.
    pub(super) fn measure(&mut self, pieces: &[&[Vec3]]) {
        self.stats.min_wall_mm = self.min_wall_of(pieces);
        self.stats.self_intersecting_triangles = self.crossings(pieces).1;
    }

    /// Boundary shell vertices on the seam with another part: those whose average front
    /// position (`average`, this part's) is the first element of a pair in `other` (that
    /// part's [`PartShell::boundary_pairs`]).
    pub fn seam_vertices(&self, average: &[Vec3], other: &[(Vec3, Vec3)]) -> Vec<u32> {
        let theirs: HashSet<[u32; 3]> = other.iter().map(|(a, _)| position_key(*a)).collect();
        (0..self.back.len())
            .filter(|&v| self.on_boundary[v])
            .filter(|&v| {
                average
                    .get(self.source[v] as usize)
                    .is_some_and(|a| theirs.contains(&position_key(*a)))
            })
            .map(|v| v as u32)
            .collect()
    }

    /// The seams this part (`part`, in part order) shares with every other part:
    /// [`PartShell::seam_vertices`] against each other part's boundary pairs in
    /// `boundaries` (indexed by part), empty seams left out.
    pub fn shared_seams(
        &self,
        average: &[Vec3],
        boundaries: &[Vec<(Vec3, Vec3)>],
        part: usize,
    ) -> Vec<Vec<u32>> {
        boundaries
            .iter()
            .enumerate()
            .filter(|(q, _)| *q != part)
            .map(|(_, other)| self.seam_vertices(average, other))
            .filter(|v| !v.is_empty())
            .collect()
    }

    /// Replaces the back surface by a printed one (shell vertex order, millimetres, before
    /// keys and IDs: [`PartShell::back`] of an earlier run, `pieces/<part>_back.obj`), so
    /// new pieces seat on the same head as the printed ones; `pieces` are the part's pieces
    /// (millimetres) to measure the wall against.
    ///
    /// # Errors
    /// [`LibraryError::InvalidParameter`] when the vertex count differs (another mesh or
    /// segmentation) or a position is not finite.
    pub fn use_back(&mut self, back: &[Vec3], pieces: &[&[Vec3]]) -> Result<()> {
        if back.len() != self.back.len() || back.iter().any(|p| !p.is_finite()) {
            return Err(LibraryError::InvalidParameter(format!(
                "the printed back surface has {} vertices, this part's has {}: it belongs to another mesh or segmentation",
                back.len(),
                self.back.len()
            )));
        }
        self.back = back.to_vec();
        self.measure(pieces);
        Ok(())
    }

    /// The back surface as a mesh (millimetres, outward = away from the front), named `name`.
    pub fn back_mesh(&self, name: &str) -> anim::Mesh {
        anim::Mesh::new(
            name,
            self.back.clone(),
            self.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect(),
        )
    }
}
