//! Part segmentation and seam homogenization (StopShop Sections 3.1–3.2).
//!
//! Pipeline ([`segment`]):
//! 1. **Weld** coincident vertices of the average mesh ([`Weld`]; glTF duplicates vertices
//!    along UV seams) — connectivity, geodesics and Laplacians use the welded mesh, outputs
//!    keep the input vertex order.
//! 2. **Label triangles** (StopShop Eqs. 1–3, [`SegmentationProblem::label`]): unary = geodesic
//!    distance to the part's seeds on the average mesh (Dijkstra on the dual graph), binary =
//!    Σ_f edge length × (1 + displacement of the edge's ends) for every pair of adjacent
//!    triangles in different parts, γ = 100 after scaling to a unit bounding box. Seed
//!    triangles are hard constraints. Exact min-cut for two parts, α-expansion beyond, on
//!    our own Boykov–Kolmogorov max-flow ([`solver::MaxFlow`]).
//! 3. **Smooth boundaries** (Fig. 5): area-weighted per-vertex votes, Laplacian smoothing,
//!    then triangles are cut along the level sets where the winning vote changes
//!    ([`CutMesh`]). New vertices sit at fixed barycentric coordinates, evaluated
//!    identically in every frame, so the surface geometry is unchanged.
//! 4. **Homogenize seams** (StopShop Eqs. 4–9, [`Homogenizer`]): per frame the squared cotangent
//!    Laplacian energy of the displacement is minimized with the seam and its one-ring
//!    pinned to their average positions; one sparse Cholesky factorization, all frames
//!    solved in parallel.
//!
//! ```
//! use anim::{Mesh, MeshAnimation};
//! use glam::Vec3;
//! use stopmo::segment::{segment, PartSpec, Seed, SegmentOptions};
//!
//! // A 6×6 grid whose lower half moves with a "jaw".
//! let n = 6;
//! let mut pos = Vec::new();
//! let mut tris = Vec::new();
//! for y in 0..n {
//!     for x in 0..n {
//!         pos.push(Vec3::new(x as f32, y as f32, 0.0));
//!     }
//! }
//! for y in 0..n - 1 {
//!     for x in 0..n - 1 {
//!         let i = (y * n + x) as u32;
//!         tris.push([i, i + 1, i + n as u32 + 1]);
//!         tris.push([i, i + n as u32 + 1, i + n as u32]);
//!     }
//! }
//! let mesh = Mesh::new("grid", pos.clone(), tris);
//! let frames: Vec<Vec3> = (0..4)
//!     .flat_map(|f| {
//!         pos.iter()
//!             .map(move |p| *p + Vec3::Z * (f as f32 * 0.3 * (2.5 - p.y).max(0.0)))
//!             .collect::<Vec<_>>()
//!     })
//!     .collect();
//! let anim = MeshAnimation::new(mesh, 24.0, frames).unwrap();
//! let parts = [
//!     PartSpec::new("upper", vec![Seed::Point(Vec3::new(2.5, 5.0, 0.0))]),
//!     PartSpec::new("lower", vec![Seed::Point(Vec3::new(2.5, 0.0, 0.0))]),
//! ];
//! let seg = segment(&anim, &parts, &SegmentOptions::default()).unwrap();
//! assert_eq!(seg.part_count(), 2);
//! // Seam vertices are identical in every frame after homogenization.
//! let v = seg.seam_vertices[0] as usize;
//! assert_eq!(seg.animation.frame(0)[v], seg.animation.frame(3)[v]);
//! ```

mod cut;
mod cut_animation;
mod error;
mod geodesic;
mod graphcut;
mod homogenize;
mod laplacian;
mod maxflow;
mod pipeline;
mod problem;
mod reuse;
mod seeds;
mod smooth;
mod topology;
mod transfer;
mod weld;

pub use cut::{CutMesh, VertexSource, DEFAULT_SNAP};
pub use error::{Result, SegmentError};
pub use homogenize::{HomogenizeStats, Homogenizer, DEFAULT_CHUNK_FRAMES};
pub use laplacian::DEFAULT_MAX_COT;
pub(crate) use pipeline::segment_input;
pub use pipeline::{
    auto_parts, homogenize, segment, segment_with, Part, SegmentOptions, SegmentReport,
    Segmentation,
};
pub use problem::{SegmentationProblem, DEFAULT_GAMMA};
pub(crate) use reuse::reuse_input;
pub use reuse::{segment_reusing, SavedSegmentation};
pub use seeds::{
    auto_seeds, resolve_seeds, PartSpec, Seed, DEFAULT_AUTO_CENTERING_ITERATIONS,
    DEFAULT_AUTO_SAMPLES, DEFAULT_AUTO_SEED_RADIUS,
};
pub use smooth::{DEFAULT_SMOOTH_ITERATIONS, DEFAULT_SMOOTH_STEP};
pub(crate) use topology::{open_border, Topology};
pub use transfer::DEFAULT_MIN_PART_FRACTION;
pub use weld::{Weld, DEFAULT_WELD_EPSILON};

/// The graph-cut solvers behind StopShop Eq. 1: public for tests and benchmarks (and for
/// anyone with another Potts problem), not part of the segmentation interface.
pub mod solver {
    pub use super::graphcut::{
        minimize_potts, solve_two_labels, PottsProblem, DEFAULT_MAX_EXPANSION_CYCLES,
    };
    pub use super::maxflow::MaxFlow;
}
