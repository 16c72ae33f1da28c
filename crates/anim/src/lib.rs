//! # toonkit-anim
//!
//! The animation data model shared by every toonkit tool: [`Mesh`], [`MeshAnimation`]
//! (frames × vertices point caches, frame-major and contiguous), [`Skeleton`], [`Skin`],
//! [`SkeletalAnimation`], [`Bone`]s as SPEC.md defines them, [`Camera`]s, and a glTF-like
//! [`Scene`] with keyframed [`Clip`]s. [`sample`] evaluates a clip (node TRS animation, morph
//! weights, linear blend skinning) at a fixed frame rate, in parallel over frames.
//!
//! This crate never touches files; `toonkit-io` reads and writes them.
//!
//! ```
//! use anim::{Mesh, MeshAnimation};
//! use glam::Vec3;
//! let tri = Mesh::new("tri", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
//! let frames: Vec<Vec3> = (0..3).flat_map(|f| tri.positions.iter().map(move |p| *p + Vec3::X * f as f32)).collect();
//! let anim = MeshAnimation::new(tri, 24.0, frames).unwrap();
//! assert_eq!(anim.frame_count(), 3);
//! assert_eq!(anim.frame(2)[0], Vec3::new(2.0, 0.0, 0.0));
//! ```

#![warn(missing_docs, unreachable_pub)]

pub mod budget;
mod camera;
mod clip;
mod curves;
mod error;
mod flipbook;
mod human;
mod mesh;
mod mesh_animation;
mod morph_animation;
mod rest;
mod rng;
mod sample;
mod scene;
mod skeleton;
mod skin;
mod transform;
mod twins;

pub use budget::{check_budget, OverBudget};
pub use camera::{Camera, Projection};
pub use clip::{frame_count, Channel, Clip, Interpolation, Property, MAX_FRAMES};
pub use curves::Curves;
pub use error::{AnimError, Result};
pub use flipbook::{Flipbook, FlipbookPart};
pub use human::human_number;
pub use mesh::{area_normals, triangulate_polygon, vertex_normals, Aabb, Mesh};
pub use mesh_animation::{MeshAnimation, DEFAULT_FPS};
pub use morph_animation::{MeshFrames, MorphAnimation};
pub use rng::{mix, SplitMix64};
pub use sample::{
    rest_transform, sample, sample_morph, sample_node_world, sample_owned, MeshObject,
    SampleOptions, SampledScene,
};
pub use scene::{MorphTarget, Node, Scene, SceneCamera, SceneMesh, SkinDef};
pub use skeleton::{bones, Bone, Joint, SkeletalAnimation, Skeleton};
pub use skin::{skin_frames, skin_positions, Skin, VertexWeights};
pub use transform::Transform;

pub use glam;
