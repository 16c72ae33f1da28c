//! USD export as ASCII layers (`.usda`), for Houdini, Maya, Blender and usdview pipelines.
//!
//! USD is write-only in toonkit: [`crate::load`] refuses `.usda` inputs with a one-line error.
//!
//! # Layout of a written layer
//!
//! ```text
//! #usda 1.0
//! (
//!     defaultPrim = "root"
//!     endTimeCode = 81            # F frames → time codes 1 … F
//!     framesPerSecond = 24
//!     metersPerUnit = 1           # glTF units are metres
//!     startTimeCode = 1
//!     timeCodesPerSecond = 24
//!     upAxis = "Y"
//! )
//!
//! def Xform "root"
//! {
//!     def Mesh "Robot"            # one Mesh prim per part, names sanitized and unique
//!     {
//!         uniform token orientation = "rightHanded"   # glTF triangles are counter-clockwise
//!         uniform token subdivisionScheme = "none"    # polygonal, not Catmull-Clark
//!         int[] faceVertexCounts = [3, 3, …]          # .timeSamples when topology changes
//!         int[] faceVertexIndices = [0, 1, 2, …]
//!         point3f[] points.timeSamples = { 1: [(x, y, z), …], 2: […], … }
//!         float3[] extent.timeSamples = { 1: [(min), (max)], … }
//!         color3f[] primvars:displayColor (interpolation = "vertex")   # optional, per frame
//!         float[] primvars:displayOpacity (interpolation = "vertex")
//!         token visibility.timeSamples = { 1: "inherited", 2: "invisible", … }  # when absent
//!     }
//! }
//! ```
//!
//! **Time codes.** Frame `k` (0-based) is written at time code `k + 1`
//! ([`DEFAULT_START_TIME_CODE`]), `startTimeCode = 1`, `endTimeCode = F`, and
//! `timeCodesPerSecond = framesPerSecond = fps`, so one time code is one frame: Blender's
//! and Houdini's default frame ranges start at frame 1, which is where the USD importers of
//! both put time code 1 (and the glTF flipbook nodes are numbered `_f0001` … the same way).
//! A one-frame animation is written without time samples, and so is any attribute whose value
//! is the same on every frame (fixed topology, still caches, constant colours). USD
//! interpolates `points` linearly between time codes when two samples have the same length;
//! motion lines change from frame to frame, so read them on whole frames.
//!
//! **Texture coordinates** of point caches are written as `primvars:st` (vertex
//! interpolation) with `v ← 1 − v`: toonkit's meshes use glTF's convention (v down from the
//! image top), USD's `st` has v up.
//!
//! **Not written:** normals (with `subdivisionScheme = "none"` every USD client computes
//! smooth vertex normals from the points of each frame), materials, skeletons.
//!
//! **Numbers.** Finite floats are written with Rust's shortest round-trip formatting, so
//! parsing the text gives back the exact `f32`. NaN and ±∞ are never written: they become 0
//! (and the extent is computed from the values as written).
//!
//! **Determinism.** The same stage always gives the same bytes (no time stamps, no hash-map
//! order). Callers put the text on disk with [`crate::write_atomic`].
//!
//! # Example
//! ```
//! use anim::glam::Vec3;
//! use anim::{Mesh, MeshAnimation};
//!
//! let tri = Mesh::new("my tri", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
//! let mut frames = tri.positions.clone();
//! frames.extend(tri.positions.iter().map(|p| *p + Vec3::Z));
//! let anim = MeshAnimation::new(tri, 24.0, frames).unwrap();
//! let text = tkio::usda::write_animation(&anim, None).unwrap();
//! assert!(text.starts_with("#usda 1.0\n"));
//! assert!(text.contains("def Mesh \"my_tri\""));
//! assert!(text.contains("2: [(0, 0, 1), (1, 0, 1), (0, 1, 1)],"));
//! ```

mod names;
pub(crate) mod source;
mod stage;
mod write;

pub use names::{sanitize_name, UniqueNames};
pub use stage::{
    UsdGeometry, UsdMesh, UsdStage, DEFAULT_METERS_PER_UNIT, DEFAULT_ROOT_NAME,
    DEFAULT_START_TIME_CODE,
};
pub use write::{write, write_animation, write_parts};
