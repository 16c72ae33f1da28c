//! Alembic export (`.abc`, Ogawa container), for Blender, Maya, Houdini and game engines:
//! point caches and sequences whose topology changes per frame (motion lines), with
//! per-vertex colour and alpha. Written from the same [`UsdStage`](crate::usda::UsdStage) as
//! `.usda`/`.usdc`, so all three hold the same meshes and frames. A minimal reader
//! ([`read`]) gives the meshes back for tests and tools.
//!
//! Only what toonkit needs is written, following the public layout of Alembic's
//! AbcCoreOgawa back end and the AbcGeom `PolyMesh` schema:
//!
//! ```text
//! root group: [file version 0 (i32), library version 10709 (i32), top object,
//!              archive metadata "_ai_Application=toonkit;…", time samplings, indexed metadata]
//! top object "ABC": [properties (empty), one PolyMesh object per mesh, child headers + hashes]
//! PolyMesh object "<name>" (schema AbcGeom_PolyMesh_v1):
//!     .geom      P (float32×3 array, interpretation=point), .faceIndices and .faceCounts
//!                (int32 arrays), .selfBnds (float64×6 scalar, interpretation=box),
//!                .arbGeomParams { Cd (float32×4, rgba, geoScope=vtx), alpha (float32,
//!                geoScope=vtx) } when the mesh has vertex colours
//!     visible    (int8 scalar) when some frames are absent (0 on those frames)
//! ```
//!
//! **Time.** Every property uses one uniform time sampling: frame `k` at
//! `(start_time_code + k) / fps` seconds, so at 24 fps frame 0 is at 1/24 s, which Blender's
//! importer shows as frame 1 (the same frame numbers as the USD time codes).
//!
//! **Samples.** A property whose value is the same on every frame is stored once (Alembic's
//! "constant" property); equal samples anywhere in the file are stored once and referenced.
//!
//! **Winding.** Alembic faces are clockwise seen from the front (Maya's convention), glTF's
//! and USD's counter-clockwise: each face's vertex indices are written in reverse (and
//! [`read`] turns them back).
//!
//! **Coordinates** are written as they are (Y-up, the file's units); NaN and ±∞ become 0.
//!
//! Callers put the bytes on disk with [`crate::write_atomic`] (or [`crate::save`]), so a
//! failed or interrupted write never leaves a partial archive.
//!
//! # Example
//! ```
//! use anim::glam::Vec3;
//! use anim::{Mesh, MeshAnimation};
//!
//! let tri = Mesh::new("tri", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
//! let mut frames = tri.positions.clone();
//! frames.extend(tri.positions.iter().map(|p| *p + Vec3::Z));
//! let anim = MeshAnimation::new(tri, 24.0, frames).unwrap();
//! let bytes = tkio::abc::write_animation(&anim, None).unwrap();
//! let back = tkio::abc::read(&bytes).unwrap();
//! assert_eq!(back.meshes[0].frames[1].points[1], Vec3::new(1.0, 0.0, 1.0));
//! assert_eq!(back.meshes[0].frames[0].face_indices, vec![0, 1, 2]);
//! ```

mod ogawa;
mod read;
mod schema;
mod write;

pub use read::{read, read_with_limit, AbcArchive, AbcFrame, AbcMesh, MAX_DECODED_BYTES};
pub use write::{write, write_animation, write_parts};

/// Whether `bytes` start like an Ogawa (Alembic) file.
pub(crate) fn is_ogawa(bytes: &[u8]) -> bool {
    bytes.starts_with(ogawa::MAGIC)
}
