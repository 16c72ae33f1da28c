//! Replacement library optimization and fabrication (StopShop Sections 3.3–3.4, 5).
//!
//! Given one animation per part, [`build_library`] finds for every part a small library of
//! pieces `R` and a piece label per frame `ℓ` minimizing StopShop Eq. 10,
//! `‖X − R S(ℓ)‖²_W + (λ/2)‖X G − R S(ℓ) G‖²_W` (positions plus velocities), by block
//! coordinate descent: the library step solves the normal equations of StopShop Eq. 10 (derived in
//! the `update` module; the printed StopShop Eq. 13 has typos) and the label step is solved *exactly*
//! by dynamic programming along the frame chain (cuts split it), never worse than the paper's
//! α-expansion (with 64 pieces or more the first steps search each frame's nearest pieces
//! only, and a restart ends only where an exact step finds nothing better:
//! docs/stopmo-scale.md, "Candidate label steps"). k-means++ seeding, random restarts in parallel, fixed or partially fixed
//! libraries, saliency weights, empty-piece repair. Library sizes are given per part, found
//! for a maximum frame error (Fig. 16), or distributed from a total budget; baselines
//! ([`Method::KMeans`] = λ 0, [`Method::Uniform`] temporal sampling) report the same errors
//! (Fig. 19). [`solidify`] turns a piece into a watertight printable solid, [`Assembly`] and
//! [`shooting_order`] tell the animator what to put on each frame and in which order to shoot.
//!
//! The frames are first reduced to coordinates of their span (exact for low-rank data such as
//! blendshape faces, a randomized sketch otherwise, see [`SubspaceOptions`]), so an iteration
//! costs one small GEMM and one Viterbi sweep; the final library step and all reported errors
//! use the full-resolution frames.
//!
//! ```
//! use anim::{Mesh, MeshAnimation};
//! use glam::Vec3;
//! use stopmo::library::{build_library, LibraryOptions, LibrarySize, PartInput, shooting_order};
//!
//! // A triangle whose tip rises slowly then snaps back, 40 frames.
//! let mesh = Mesh::new("mouth", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
//! let positions = (0..40)
//!     .flat_map(|f| {
//!         let h = if f < 30 { f as f32 / 30.0 } else { 0.0 };
//!         [Vec3::ZERO, Vec3::X, Vec3::new(0.0, 1.0 + h, 0.0)]
//!     })
//!     .collect();
//! let anim = MeshAnimation::new(mesh, 24.0, positions).unwrap();
//! let opts = LibraryOptions { size: LibrarySize::Pieces(4), ..LibraryOptions::default() };
//! let lib = build_library(&[PartInput { animation: &anim, setup: Default::default() }], &opts)
//!     .unwrap();
//! assert_eq!(lib.parts[0].solution.pieces.len(), 4);
//! assert_eq!(lib.parts[0].solution.labels.len(), 40);
//! assert!(lib.errors_mm.position_mean < 4.8); // millimetres at a 60 mm print height
//! let order = shooting_order(&lib.assembly());
//! assert!(order.swaps <= order.sequential_swaps);
//! ```

mod assembly;
mod back_surface;
mod borders;
mod build;
mod candidates;
mod error;
mod fabricate;
mod input_errors;
mod intersect;
mod kmeans_pp;
mod magnet;
mod metrics;
mod nearest;
mod piece_id;
mod plugs;
mod problem;
mod regularize;
mod size;
mod solver;
mod source;
mod subspace;
#[cfg(test)]
mod test_shapes;
mod update;
mod viterbi;

pub use assembly::{
    piece_id, shooting_order, Assembly, ShootingOrder, Shot, DEFAULT_TWO_OPT_LIMIT,
    DEFAULT_TWO_OPT_PASSES,
};
pub use back_surface::{
    build_shells, first_thinnest, Boss, DirectionField, PartShell, Pocket, PocketMiss, PocketSpec,
    ShellInput, ShellOptions, ShellStats, ThinnestWall, DEFAULT_BACK_SMOOTHING_ITERATIONS,
    DEFAULT_CAP_FRACTION, DEFAULT_EDGE_RING_RADIUS_MM, DEFAULT_ENVELOPE_LATERAL,
    DEFAULT_ENVELOPE_REACH, DEFAULT_NORMAL_SMOOTHING_MM, DEFAULT_REPAIR_ROUNDS,
    DEFAULT_RESOLVE_ROUNDS,
};
pub use borders::BORDER_RINGS;
pub use build::{
    build_library, print_scale, Library, LibraryOptions, LibrarySize, Method, PartInput, PartResult,
};
pub(crate) use build::{build_sources, print_scale_of};
pub use error::{LibraryError, Result};
pub use fabricate::{
    check_solid, material, scaled, solidify, volume, MaterialEstimate, SolidCheck,
    DEFAULT_PRINT_HEIGHT_MM, DEFAULT_THICKNESS_MM, PLA_DENSITY_G_PER_MM3,
};
pub use input_errors::compare_frames;
pub use intersect::{intersecting_pairs, self_intersecting_triangles, MAX_EXACT_COORDINATE};
pub(crate) use magnet::{cut_pocket, cylinder, turned_cylinder};
pub use magnet::{MagnetOptions, DEFAULT_POCKET_SEGMENTS, MIN_MAGNET_WALL_MM};
pub use metrics::{ErrorSummary, FrameErrors};
pub use nearest::{closest_point_on_triangle, TriangleGrid};
pub use piece_id::{
    Bitmap, Key, KeyOptions, DEFAULT_ID_RELIEF_MM, DEFAULT_KEYS_PER_SEAM, DEFAULT_KEY_COUNT,
    KEY_HEIGHT_PER_RADIUS, KEY_RADIUS_PER_HEIGHT,
};
pub use plugs::{
    add_plugs, components, plan_plugs, Plug, PlugOptions, DEFAULT_PLUG_CLEARANCE_MM,
    DEFAULT_PLUG_LENGTH_MM, DEFAULT_PLUG_RADIUS_MM, DEFAULT_PLUG_SEGMENTS, DEFAULT_PLUG_WALL_MM,
};
pub use problem::{PartProblem, PartSetup};
pub(crate) use regularize::exact_difference;
pub use regularize::{regularize, Regularized};
pub use size::{allocate_budget, CurvePoint};
pub use solver::{
    PartSolution, SolveOptions, DEFAULT_LAMBDA, DEFAULT_MAX_ITERATIONS, DEFAULT_RESTARTS,
    DEFAULT_SEED, DEFAULT_TOLERANCE, MAX_RESTARTS,
};
pub(crate) use source::Source;
pub use subspace::{
    SubspaceOptions, DEFAULT_INITIAL_RANK, DEFAULT_MAX_RANK, DEFAULT_SUBSPACE_TOLERANCE,
};
