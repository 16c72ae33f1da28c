//! Smear frames from motion offsets — Basset, Bénard, Barla, "Smear: Stylized Motion Effects
//! for 3D Animation", SIGGRAPH 2024 (`SMEAR` below).
//!
//! Motion offsets δ_i(f) ∈ [−1, 1] say which parts of a moving object lead (δ > 0) and which
//! trail (δ < 0); elongated in-betweens, multiple in-betweens and motion lines are driven by
//! them (SMEAR Section 4).
//!
//! # The whole job
//! [`prepare`] takes a sampled scene and does everything that does not depend on the style,
//! once: the offset solve per object group (merged inside the crate when asked), the camera,
//! painted weights, velocities. [`stylize`] then applies a [`Style`] (the TOML format of
//! `examples/smear/`) and returns a [`Stylized`] flipbook plus a report; calling it again with
//! another style never solves offsets again (see [`offset_solves`]), which is what makes live
//! tuning possible. [`offsets`] alone is the `toonkit smear offsets` job. Options are serde
//! structs, so the same options come from CLI flags, TOML, Python keyword arguments or a web
//! form.
//!
//! ```
//! use anim::{Mesh, MeshAnimation, SampledScene};
//! use glam::Vec3;
//! use smear::{prepare, stylize, PrepareOptions, Style};
//!
//! // A unit tetrahedron translating along +X, one unit per frame.
//! let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
//! let mesh = Mesh::new("tet", p.clone(), vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]);
//! let frames: Vec<Vec3> = (0..6).flat_map(|f| p.iter().map(move |q| *q + Vec3::X * f as f32)).collect();
//! let scene = SampledScene::from_animation(MeshAnimation::new(mesh, 24.0, frames)?);
//!
//! let prepared = prepare(scene, &PrepareOptions::default())?;
//! let solves = smear::offset_solves();
//! let stretch = Style::from_toml_str("[elongate]\nfunction = { stages = [{ op = \"scale\", by = 2 }] }")?;
//! let copies = Style::from_toml_str("[multiples]\npast = 2\nfuture = 0")?;
//! let a = stylize(&prepared, &stretch)?; // the body, elongated
//! let b = stylize(&prepared, &copies)?; // the body and two past copies
//! assert_eq!((a.flipbook.parts.len(), b.flipbook.parts.len()), (1, 3));
//! assert_eq!(smear::offset_solves(), solves); // restyling reused the offsets
//! assert!(a.report.objects[0].elongation_max.unwrap() > 1.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Paper map
//! | SMEAR | item |
//! |---|---|
//! | SMEAR Eq. 1 (separation plane, simple objects) | [`surface_centroid`], [`mesh_offsets`], [`OffsetMode::Simple`] |
//! | SMEAR Eq. 2 (temporal smoothing) | [`smoothing_weights`], [`smooth_in_time`], [`MotionOffsets::smoothed`] |
//! | SMEAR Eqs. 3–5 (bone ribbons, slerped joint motion) | [`OffsetSolver`] with [`OffsetMode::Articulated`], [`smoothstep`] |
//! | SMEAR Eqs. 6–8 (collinear weight, skin-weighted sum) | [`OffsetOptions::collinear_weight`], [`OffsetSolver::surface_offsets`] |
//! | SMEAR Eq. 9 (joint-continuous normalization) | [`OffsetSolver::new`] (orientation fixed in SPEC.md) |
//! | SMEAR Eq. 10 (elongated in-betweens) | [`elongate`], [`elongate_frame`], [`ElongateStyle`] |
//! | SMEAR Eq. 11 (multiple in-betweens) | [`multiples`], [`multiples_frame`], [`MultiplesStyle`] |
//! | SMEAR Eq. 12 (multiples opacity) | [`multiple_opacity`], [`eq12_opacity`], [`overlap_spacing`] |
//! | SMEAR Eq. 13 (motion lines) | [`motion_lines`], [`motion_lines_frame`], [`LinesStyle`] |
//! | Section 5 (stylization functions) | [`FunctionSpec`], [`Stage`], [`Expression`], [`warp_offset`], [`voronoi_f1`] |
//!
//! # Beyond the paper (issue #22)
//! * **Adaptive subdivision** ([`Style::subdivide`], [`subdivide_frame`]): output edges longer
//!   than TOL × their rest length, or whose smear curves away from them by more than
//!   [`BEND`] × (TOL − 1) of it (a limb swinging through an arc), are split, crack-free; a new
//!   vertex is a blend of the input vertices of its triangle and follows the same blend of
//!   their trajectories, displaced by the blend of their β (Catmull-Rom is linear in its
//!   control points), so it lies on the smear and repeated splits refine toward its curve. Results then have one mesh per frame (`anim::FlipbookPart::Frames`).
//! * **Revolving parts** ([`OffsetOptions::revolve`], [`Arcs`], [`fit_screw`]): the paper's
//!   Fig. 19 limitation. Per frame interval the rigid motion is fitted as a screw; offsets are
//!   SMEAR Eq. 1 with the plane replaced by the half-plane through the axis (signed arc length
//!   ahead of each piece's angular centre) and trajectories follow the screw arcs, so
//!   elongated blades stay on their circles. The construction is documented in `revolve`.
//! * **Contact** ([`Style::contact`], [`ContactStyle`]): a displacement that would end below
//!   the ground plane stops where its trajectory reaches it ([`Trajectories::displaced`]);
//!   optional volume-preserving squash on impact ([`squash_frames`]). Collider meshes
//!   ([`Collider`], [`PrepareOptions::colliders`], [`Prepared::add_collider`]) stop
//!   displacements the same way and push out what is inside.
//! * **Causal mode** ([`OffsetOptions::causal`]) and **streaming** ([`Stream`]): backward
//!   velocity differences, the past half of SMEAR Eq. 2's window
//!   ([`causal_smoothing_weights`]) and trajectories that extrapolate past the current frame
//!   ([`Trajectories::seen_from`]): frame f's result reads frames ≤ f only. Visual
//!   difference from the offline mode: the smear lags (smoothed offsets by about N/3 frames,
//!   velocities by half a frame) and the leading half of an elongation is a straight
//!   extrapolation of the last motion, so it overshoots when the motion stops or turns.
//!   A stream keeps out of the ground plane and of collider meshes
//!   ([`Stream::add_collider`]) as the causal mode does.
//!
//! # Building blocks
//! * Simple objects (SMEAR Eq. 1): signed distance to the plane through the area-weighted
//!   surface centroid ([`surface_centroid`]) with the direction of motion as normal,
//!   normalized by the largest |δ̃|.
//! * Temporal smoothing (SMEAR Eq. 2): [`smoothing_weights`], [`smooth_in_time`].
//! * Articulated figures (SMEAR Eqs. 3–9): per-bone ribbons orthogonal to the bone and as
//!   aligned as possible with the slerped joint motion, collinear weights, skin-weighted sum,
//!   and the joint-continuous normalization of SMEAR Eq. 9 (orientation fixed in SPEC.md);
//!   optional skeleton pruning and whole-body mode.
//! * Camera space, several objects per scene, offsets at surface points ([`OffsetSolver`]).
//! * Velocities by central differences ([`vertex_velocities`]), used for speed.
//!
//! The crate is pure computation: it never touches files.
//!
//! ```
//! use anim::{Mesh, MeshAnimation};
//! use glam::Vec3;
//! use smear::{mesh_offsets, OffsetOptions};
//!
//! // A unit tetrahedron translating along +X, one unit per frame.
//! let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
//! let mesh = Mesh::new("tet", p.clone(), vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]);
//! let frames: Vec<Vec3> = (0..4).flat_map(|f| p.iter().map(move |q| *q + Vec3::X * f as f32)).collect();
//! let anim = MeshAnimation::new(mesh, 24.0, frames)?;
//! let delta = mesh_offsets(&anim, &OffsetOptions::default())?;
//! assert!((delta.get(2, 1).unwrap() - 1.0).abs() < 1e-6); // the vertex at +X leads
//! assert!(delta.get(2, 0).unwrap() < 0.0); // the others trail
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![warn(missing_docs, unreachable_pub)]

mod collider;
mod effects;
mod error;
mod field;
mod job;
mod offsets;
mod options;
mod plane;
mod revolve;
mod ribbon;
mod rig;
mod smooth;
mod solver;
mod stream;
mod stylize;
mod surface;
mod velocity;

pub use collider::Collider;
pub use effects::{
    attribute_weights, elongate, elongate_frame, eq12_opacity, group_weights, held_frame,
    motion_lines, motion_lines_frame, multiple_opacity, multiples, multiples_frame,
    overlap_spacing, sample_surface, squash_frames, subdivide_frame, subdivide_moving_frame,
    surface_point_weights, trajectory_velocities, AroundFrame, ContactStyle, EffectInputs,
    ElongateOptions, LineFrame, LineOptions, LineStyle, MultipleCopy, MultiplesOptions, Spacing,
    Squash, StyleBlock, StyleInput, Stylize, SubdivisionStats, Trajectories, BEND,
    DEFAULT_FRAME_STEP, DEFAULT_LINE_SAMPLES, DEFAULT_LINE_SIDES, DEFAULT_SEED, DEFAULT_SPACING,
    DEFAULT_SQUASH_FRAMES, DEVIATION_SHARE, MAX_SQUASH, MAX_SUBDIVISION_LEVELS, STYLE_BLOCK,
};
pub use error::{Result, SmearError};
pub use job::{
    offsets, prepare, stylize, stylize_frames, stylize_memory, CopyReport, ObjectOffsets,
    ObjectParts, ObjectReport, PrepareOptions, PrepareReport, Prepared, SceneOffsets,
    StylizeReport, StylizeTimings, Stylized,
};
pub use offsets::MotionOffsets;
pub use options::{
    CameraSelect, OffsetOptions, DEFAULT_LERP_ANGLE, DEFAULT_SMOOTH, DEFAULT_STILL_TOLERANCE,
    DEFAULT_ZERO_LENGTH, STILL_ROUNDING_FACTOR,
};
pub use plane::surface_centroid;
pub use revolve::{fit_screw, object_screws, revolving_offsets, Arcs, Screw, REVOLVE_AUTO};
pub use ribbon::smoothstep;
pub use smooth::{
    causal_smoothing_weights, smooth_in_time, smooth_in_time_causal, smoothing_weights,
};
pub use solver::{mesh_offsets, offset_solves, scene_offsets, OffsetMode, OffsetSolver};
pub use stream::{Stream, StreamOptions, DEFAULT_STREAM_HISTORY};
pub use stylize::{
    apply_stages, apply_stages_block, hise_curve, parameter, voronoi_f1, warp_offset,
    CompiledEffects, CompiledLines, ElongatePreset, ElongateStyle, Expression, FunctionSpec,
    LinesStyle, MultiplesStyle, ObjectEffects, ObjectStyle, Param, Parameter, SizeReference,
    SpeedUnits, Stage, Style, StyleError, StyleFunction, StyleOps, StyleUnits, WeightAttribute,
    WeightGroup, WeightSource, DEFAULT_BETA_MAX, DEFAULT_COPIES, DEFAULT_KAPPA, DEFAULT_LINE_COUNT,
    DEFAULT_LINE_LENGTH, DEFAULT_LINE_THICKNESS, DEFAULT_MULTIPLE_COLOR, EXPRESSION_INPUTS,
    MAX_EXPRESSION_VARIABLES, PARAMETERS,
};
pub use surface::SurfacePoint;
pub use velocity::{camera_vertex_velocities, causal_vertex_velocities, speeds, vertex_velocities};
