//! The segmentation energy of StopShop Eqs. 1–3 on one animation, precomputed once so that seeds and
//! γ can be changed cheaply.

use anim::MeshAnimation;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::error::{Result, SegmentError};
use super::geodesic::DualGraph;
use super::graphcut::{minimize_potts, PottsProblem, DEFAULT_MAX_EXPANSION_CYCLES};
use super::topology::Topology;
use super::weld::{Weld, DEFAULT_WELD_EPSILON};

/// Frames per parallel task when summing StopShop Eq. 3 over the animation.
const FRAMES_PER_TASK: usize = 32;

/// Default weight γ of the binary term (StopShop Eq. 1), for models scaled to a unit bounding box.
pub const DEFAULT_GAMMA: f64 = 100.0;

/// The precomputed terms of StopShop Eqs. 1–3 for one animation.
///
/// Everything is measured after scaling the model so that the largest side of the bounding
/// box of the average mesh is 1 ("unit bounding box"), which is what makes
/// [`DEFAULT_GAMMA`] meaningful.
#[derive(Debug, Clone)]
pub struct SegmentationProblem {
    pub(crate) weld: Weld,
    pub(crate) topology: Topology,
    /// Average positions of the welded vertices (model units).
    pub(crate) average: Vec<DVec3>,
    /// Average positions of the input vertices (model units).
    pub(crate) average_input: Vec<Vec3>,
    pub(crate) scale: f64,
    pub(crate) dual: DualGraph,
    /// StopShop Eq. 3 per dual edge, averaged over frames, in unit-box units (γ not applied).
    pub(crate) motion: Vec<f64>,
    /// Animation-average triangle areas (model units²).
    pub(crate) areas: Vec<f64>,
    pub(crate) triangles: usize,
}

impl SegmentationProblem {
    /// Welds the mesh, builds the dual graph and evaluates the motion term of StopShop Eq. 3 over all
    /// frames.
    ///
    /// # Arguments
    /// * `anim` — the input animation X (fixed topology).
    /// * `weld_epsilon` — welding tolerance relative to the bounding-box diagonal of the
    ///   average mesh ([`DEFAULT_WELD_EPSILON`]); 0 welds bit-identical positions only.
    ///
    /// # Errors
    /// [`SegmentError::NoTriangles`], [`SegmentError::Invalid`] on bad indices.
    ///
    /// # Performance
    /// One parallel pass over all frames: O(frames × triangles).
    pub fn new(anim: &MeshAnimation, weld_epsilon: f32) -> Result<SegmentationProblem> {
        anim.mesh
            .validate()
            .map_err(|e| SegmentError::Invalid(e.to_string()))?;
        let k = anim.mesh.triangle_count();
        if k == 0 {
            return Err(SegmentError::NoTriangles);
        }
        let average_input = anim.average_positions();
        let bbox = anim::Aabb::from_points(&average_input);
        let eps = if weld_epsilon > 0.0 {
            weld_epsilon * bbox.diagonal()
        } else {
            0.0
        };
        let weld = Weld::new(&average_input, eps);
        let welded_triangles = weld.triangles(&anim.mesh.triangles);
        let topology = Topology::new(weld.len(), &welded_triangles);
        let average: Vec<DVec3> = weld
            .representative
            .iter()
            .map(|&r| average_input[r as usize].as_dvec3())
            .collect();
        let extent = (bbox.max - bbox.min).max_element() as f64;
        let scale = if extent > 0.0 && extent.is_finite() {
            1.0 / extent
        } else {
            1.0
        };
        let scaled: Vec<DVec3> = average.iter().map(|p| *p * scale).collect();
        let dual = DualGraph::new(&scaled, &welded_triangles, &topology.dual);

        // StopShop Eq. 3 (without γ) and average areas, in one pass over the frames.
        let rep = &weld.representative;
        let edges: Vec<[usize; 2]> = topology
            .dual
            .iter()
            .map(|e| e.v.map(|v| rep[v as usize] as usize))
            .collect();
        let avg_rep: Vec<[DVec3; 2]> = topology
            .dual
            .iter()
            .map(|e| e.v.map(|v| average[v as usize]))
            .collect();
        let tris = &anim.mesh.triangles;
        let n = anim.vertex_count();
        // Fixed chunks of frames summed in order: the result does not depend on how rayon
        // schedules the work (ties in the graph cut must break the same way every run).
        let partials: Vec<(Vec<f64>, Vec<f64>)> = anim
            .positions()
            .par_chunks(n.max(1) * FRAMES_PER_TASK)
            .map(|chunk| {
                let mut mo = vec![0.0f64; edges.len()];
                let mut ar = vec![0.0f64; k];
                for x in chunk.chunks_exact(n.max(1)) {
                    for (e, (ends, avg)) in edges.iter().zip(&avg_rep).enumerate() {
                        let (a, b) = (x[ends[0]].as_dvec3(), x[ends[1]].as_dvec3());
                        let len = a.distance(b) * scale;
                        let disp = (a.distance(avg[0]) + b.distance(avg[1])) * scale;
                        mo[e] += len * (1.0 + disp);
                    }
                    for (t, tri) in tris.iter().enumerate() {
                        let p = tri.map(|i| x[i as usize].as_dvec3());
                        ar[t] += 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
                    }
                }
                (mo, ar)
            })
            .collect();
        let mut motion = vec![0.0f64; edges.len()];
        let mut areas = vec![0.0f64; k];
        for (mo, ar) in &partials {
            motion.iter_mut().zip(mo).for_each(|(x, y)| *x += y);
            areas.iter_mut().zip(ar).for_each(|(x, y)| *x += y);
        }
        let frames = anim.frame_count().max(1) as f64;
        let areas = areas.into_iter().map(|a| a / frames).collect();
        let motion = motion.into_iter().map(|m| m / frames).collect();
        Ok(SegmentationProblem {
            weld,
            topology,
            average,
            average_input,
            scale,
            dual,
            motion,
            areas,
            triangles: k,
        })
    }

    /// [`SegmentationProblem::new`] with [`DEFAULT_WELD_EPSILON`].
    pub fn with_defaults(anim: &MeshAnimation) -> Result<SegmentationProblem> {
        SegmentationProblem::new(anim, DEFAULT_WELD_EPSILON)
    }

    /// Number of input triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles
    }

    /// The welding of the input vertices.
    pub fn weld(&self) -> &Weld {
        &self.weld
    }

    /// Scale factor to the unit bounding box (1 / largest side of the average mesh's box).
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// Average positions of the input vertices.
    pub fn average_positions(&self) -> &[Vec3] {
        &self.average_input
    }

    /// Pairs of adjacent triangles and their StopShop Eq. 3 cost divided by the frame count (γ not
    /// applied, unit-box units, each unordered pair once).
    pub fn motion_costs(&self) -> impl Iterator<Item = (u32, u32, f64)> + '_ {
        self.topology
            .dual
            .iter()
            .zip(&self.motion)
            .map(|(e, &w)| (e.a, e.b, w))
    }

    /// Geodesic distances (unit-box units) of every triangle to the nearest of `seeds`.
    pub fn geodesic_distances(&self, seeds: &[u32]) -> Vec<f64> {
        self.dual.distances(seeds)
    }

    /// Per-triangle part labels minimizing StopShop Eq. 1 with unary StopShop Eq. 2 and binary StopShop Eq. 3.
    ///
    /// Decisions where the paper is ambiguous:
    /// * StopShop Eq. 3's sum over frames is divided by the frame count (a mean over frames). Summed
    ///   literally, the binary term grows with the clip length, so one default γ could not
    ///   serve the paper's clips of 260 to 5,177 frames: with hundreds of frames the cheapest
    ///   cut simply encircles a seed triangle. With the mean, the default γ = 100 (SPEC.md)
    ///   already moves the face cut below the eyes, where motion is low, but the cut still
    ///   follows the seeds; around γ = 1,000 it no longer depends on them (Fig. 4); far beyond
    ///   (γ ≈ 10,000 on the face) the shrinking bias of graph cuts wins and the cut encircles
    ///   a seed (measured in `tests/segment_face.rs`).
    /// * Seed triangles are hard constraints (a seed always belongs to its part).
    /// * The double sum of StopShop Eq. 1 runs over ordered pairs, so every adjacent pair contributes
    ///   `2 γ b(α, β)` (as printed).
    ///
    /// # Arguments
    /// * `seeds` — seed triangles of every part (at least 2 parts, none empty; checked by
    ///   the caller, see [`super::resolve_seeds`]).
    /// * `gamma` — weight of the binary term ([`DEFAULT_GAMMA`]).
    ///
    /// # Returns
    /// One label per input triangle: exact minimum for 2 parts, α-expansion beyond.
    pub fn label(&self, seeds: &[Vec<u32>], gamma: f64) -> Vec<u32> {
        let s = seeds.len();
        let k = self.triangles;
        let mut unary = vec![0.0f64; k * s];
        for (j, part) in seeds.iter().enumerate() {
            let d = self.dual.distances(part);
            for t in 0..k {
                unary[t * s + j] = d[t];
            }
        }
        for (j, part) in seeds.iter().enumerate() {
            for &t in part {
                for l in 0..s {
                    if l != j {
                        unary[t as usize * s + l] = f64::INFINITY;
                    }
                }
            }
        }
        let gamma = if gamma.is_finite() {
            gamma.max(0.0)
        } else {
            DEFAULT_GAMMA
        };
        let edges: Vec<(u32, u32, f64)> = self
            .motion_costs()
            .map(|(a, b, w)| (a, b, 2.0 * gamma * w))
            .collect();
        let problem = PottsProblem {
            labels: s,
            unary: &unary,
            edges: &edges,
        };
        minimize_potts(&problem, DEFAULT_MAX_EXPANSION_CYCLES)
    }

    /// Length of the boundary between differently labeled triangles on the average mesh
    /// (model units).
    pub fn boundary_length(&self, labels: &[u32]) -> f64 {
        self.topology
            .dual
            .iter()
            .filter(|e| labels[e.a as usize] != labels[e.b as usize])
            .map(|e| self.average[e.v[0] as usize].distance(self.average[e.v[1] as usize]))
            .sum()
    }
}
