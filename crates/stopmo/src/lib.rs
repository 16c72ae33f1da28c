//! Replacement libraries for 3D-printed stop-motion (StopShop, Abdrashitov et al.): cut a
//! face animation into parts, make the seams identical in every frame, find for every part a
//! small library of printable pieces and the piece to show on every frame.
//!
//! # Whole jobs
//! Each job is one call on in-memory data, with serde options (the same options come from
//! CLI flags, a TOML/JSON file, Python keyword arguments or a web form) and a result that
//! carries its report:
//! * [`segment()`] → [`Segmented`]: parts, labels, seams, homogenization, the SPEC report and
//!   optionally StopShop Fig. 5;
//! * [`library()`] → [`LibraryResult`]: libraries and labels, printable pieces (surface +
//!   solid), assembly, shooting order, reconstruction, size-versus-error curve, report;
//! * [`run()`] → [`LibraryResult`]: both, the segmentation kept in
//!   [`LibraryResult::segmented`];
//! * [`size_curve()`] → [`SizeCurve`]: library size versus reconstruction error (StopShop
//!   Fig. 8), one solve per size, and [`library_of()`]: the whole library job at one of its
//!   points without solving again.
//!
//! [`LibraryResult::files`] lists the output layout (SPEC "Output layouts") as relative paths
//! and data, so a front end only writes them. The stages are also available one by one in
//! [`mod@segment`] (Sections 3.1–3.2) and [`mod@library`] (Sections 3.3–3.4, 5).
//!
//! # Paper map (StopShop equation → item)
//! | equation | what | item |
//! |---|---|---|
//! | StopShop Eq. 1 | segmentation energy: unary + γ · seam term (Potts) | [`segment::SegmentationProblem::label`], [`segment::SegmentOptions::gamma`] |
//! | StopShop Eq. 2 | unary term: geodesic distance to the seeds | [`segment::SegmentationProblem`] |
//! | StopShop Eq. 3 | seam term: edge length × (1 + displacement), averaged over frames | [`segment::SegmentationProblem`] |
//! | StopShop Eqs. 4–9 | seam homogenization: squared cotangent Laplacian of the displacement, seams pinned | [`segment::Homogenizer`], [`segment::homogenize`] |
//! | StopShop Eq. 10 | library energy `‖X − R S(ℓ)‖²_W + (λ/2)‖X G − R S(ℓ) G‖²_W` | [`library::build_library`], [`library::PartSolution::energy`], [`library::SolveOptions::lambda`] |
//! | StopShop Eq. 11 | selection matrix `S(ℓ)` (one piece per frame) | [`library::PartSolution::labels`] |
//! | StopShop Eq. 12 | velocity operator `G` with cuts | [`library::PartSetup::cuts`] |
//! | StopShop Eq. 13 | library step: normal equations (derived from StopShop Eq. 10; the printed one has typos) | [`library::PartProblem::solve`] |
//! | StopShop Eqs. 14–16 | label step: unary and pairwise terms, solved exactly by dynamic programming | [`library::PartProblem::solve`] |
//!
//! # Example
//! A 6 × 6 grid whose lower half moves like a jaw: segment into two parts, then build a
//! library of 3 pieces per part.
//!
//! ```
//! use anim::{Mesh, MeshAnimation};
//! use glam::Vec3;
//! use stopmo::segment::{PartSpec, Seed};
//! use stopmo::{LibraryJobOptions, PieceCount, SegmentJobOptions};
//!
//! let n = 6;
//! let mut rest = Vec::new();
//! let mut triangles = Vec::new();
//! for y in 0..n {
//!     for x in 0..n {
//!         rest.push(Vec3::new(x as f32, y as f32, 0.0));
//!     }
//! }
//! for y in 0..n - 1 {
//!     for x in 0..n - 1 {
//!         let i = (y * n + x) as u32;
//!         triangles.push([i, i + 1, i + n as u32 + 1]);
//!         triangles.push([i, i + n as u32 + 1, i + n as u32]);
//!     }
//! }
//! let frames: Vec<Vec3> = (0..12)
//!     .flat_map(|f| {
//!         let open = (f as f32 * 0.7).sin().abs();
//!         rest.iter()
//!             .map(move |p| *p + Vec3::Z * (open * (2.5 - p.y).max(0.0)))
//!             .collect::<Vec<_>>()
//!     })
//!     .collect();
//! let anim = MeshAnimation::new(Mesh::new("grid", rest, triangles), 24.0, frames).unwrap();
//!
//! let seg = stopmo::segment(
//!     &anim,
//!     &SegmentJobOptions {
//!         parts: vec![
//!             PartSpec::new("upper", vec![Seed::Point(Vec3::new(2.5, 5.0, 0.0))]),
//!             PartSpec::new("lower", vec![Seed::Point(Vec3::new(2.5, 0.0, 0.0))]),
//!         ],
//!         ..Default::default()
//!     },
//! )
//! .unwrap();
//! assert_eq!(seg.parts.len(), 2);
//!
//! let parts: Vec<MeshAnimation> = seg.parts.iter().map(|p| p.animation.clone()).collect();
//! let lib = stopmo::library(
//!     &parts,
//!     &LibraryJobOptions { pieces: PieceCount::Each(3), ..Default::default() },
//! )
//! .unwrap();
//! assert_eq!(lib.pieces.len(), 6);
//! assert_eq!(lib.assembly.frames.len(), 12);
//! assert!(lib.assembly_csv().starts_with("frame,upper,lower\n"));
//! let files = lib.files().unwrap();
//! assert!(files.iter().any(|f| f.path == "pieces/lower_02.stl"));
//! ```

#![warn(missing_docs, unreachable_pub)]

mod job;
pub mod library;
pub mod segment;

pub use job::{
    check_positive_mm, check_segment_memory, file_safe_name, frames_memory, is_library_piece,
    library, library_frames, library_memory, library_of, library_pieces, piece_label, run,
    saved_segmentation, segment, segment_into_parts, segment_memory, segment_owned, size_curve,
    Error, FileData, FramesForm, LibraryJobOptions, LibraryReport, LibraryResult, OrderReport,
    OutputFile, PartPrintReport, PartReport, PartSummary, Piece, PieceCount, PiecesFolder,
    PlugReport, PrintReport, PrintTime, Reconstruction, Result, RunOptions, SegmentJobOptions,
    SegmentSummary, Segmented, SizeCurve, SizePoint, DEFAULT_PIECES, DEFAULT_RESOLUTION_MM,
};
pub use job::{
    default_clearance_mm, PieceReport, Plate, PrintFormat, CLEARANCE_PER_RESOLUTION,
    CLEARANCE_RANGE_MM, DEFAULT_PLATE_MM, MAX_DEFAULT_CLEARANCE_MM, PLATE_SIDE_RANGE_MM,
    PRINTER_MINIMUM_RANGE_MM,
};
pub use job::{
    PrintabilityReport, SolidPrintability, Thin, ThinSpot, DEFAULT_MIN_FEATURE_MM,
    DEFAULT_MIN_WALL_MM,
};
