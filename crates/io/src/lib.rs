//! # toonkit-io
//!
//! Reading and writing animation files: glTF 2.0 (`.gltf`/`.glb`, with the extensions
//! animators' files carry: quantized and meshopt-compressed geometry, lights, materials),
//! FBX (read, through ufbx), OBJ and OBJ sequences, PC2
//! and MDD point caches, binary STL, BVH motion capture, and NPY arrays; scene caches are
//! written only: USD layers (`.usda` text, `.usdc` binary, `.usdz` package) and Alembic
//! archives (`.abc`, with a reader for checking them). Formats are detected by content. Every reader returns [`IoError`] on bad
//! bytes, never panics; every writer produces bytes, and [`write_atomic`] puts them on disk.
//!
//! This crate does no algorithm work beyond format conversion.

#![warn(missing_docs, unreachable_pub)]

mod atomic;
mod error;
mod inputs;
mod layout;
mod save;
mod shapes;

pub mod abc;
pub mod bvh;
pub mod info;
pub mod mdd;
pub mod npy;
#[cfg(feature = "obj")]
pub mod obj;
pub mod pc2;
pub mod sampling;
#[cfg(feature = "stl")]
pub mod stl;
pub mod threemf;
pub mod usda;
pub mod usdc;

pub use atomic::{
    read_file, remove_stale_temps, write_atomic, write_atomic_all, write_atomic_with, SYNC_ENV,
};
pub use error::{describe_io, FilePath, IoError, Result};
pub use inputs::{check_not_input, note_read, same_file, ReadScope};
pub use layout::{save_files, FileData, OutputFile};
pub use save::{save, save_with, Layout, Output, SaveOptions};
pub use shapes::ShapeAnimation;

mod detect;
mod flipbook;

#[cfg(feature = "fbx")]
pub mod fbx;

pub mod gltf;

pub use detect::{detect, load, load_with_notes, Format, LoadOptions, Loaded};
pub use sampling::{open, open_frames, OpenError, OpenOptions};
