//! glTF 2.0: read `.gltf`/`.glb` into a scene, write scenes and point caches as `.glb`.
//!
//! One concept per file: `read` maps a document onto the data model after `prepare` has
//! decoded compressed primitives (`draco`, `meshopt`) and `precheck` has checked what the
//! `gltf` crate assumes; `values` and `attributes` read accessors; `write`, `scenes`,
//! `accessors` and `quantize` build `.glb` files, `flipbook` writes point caches and
//! varying topology.

pub(crate) mod accessors;
pub(crate) mod attributes;
pub(crate) mod draco;
pub(crate) mod flipbook;
pub(crate) mod meshopt;
pub(crate) mod precheck;
pub(crate) mod prepare;
pub(crate) mod quantize;
pub(crate) mod read;
pub(crate) mod scenes;
pub(crate) mod values;
pub(crate) mod write;

pub use flipbook::{write_animation, write_animations, write_animations_with, AnimationLayout};
pub use prepare::confined_uri;
pub use quantize::{GlbOptions, MAX_ERROR};
pub use read::{read, read_bytes};
pub use write::{write_glb, write_glb_with};
