//! A layout of output files: paths relative to an output folder and their data, written in
//! parallel by [`save_files`] through [`save`](crate::save) (a job such as a stop-motion
//! library lists its files this way and does no file work itself).

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use anim::{Mesh, MeshAnimation};

/// What one output file holds; the path's extension says which format it is written in.
#[derive(Debug, Clone)]
pub enum FileData<'a> {
    /// Text written as is (CSV, JSON, Markdown).
    Text(String),
    /// Bytes written as is (an encoded PNG).
    Bytes(Vec<u8>),
    /// One static mesh (`.obj` surface or `.stl` solid).
    Mesh(&'a Mesh),
    /// Several animations with the same frames, one node per part (`.glb`, morph targets).
    Parts(Vec<&'a MeshAnimation>),
    /// One point cache (`.pc2`).
    PointCache(Cow<'a, MeshAnimation>),
    /// Parts showing one of their pieces per frame (`.glb` with the pieces as morph
    /// targets, or `.pc2` merged in part order and streamed, `rest` beside it as `.obj`).
    Shapes {
        /// The parts.
        parts: Vec<crate::ShapeAnimation<'a>>,
        /// The merged rest mesh.
        rest: Mesh,
    },
    /// A rest mesh that is not borrowed from the result (`.obj`).
    OwnedMesh(Mesh),
}

/// One file of the layout: a path relative to the output directory and its data.
#[derive(Debug, Clone)]
pub struct OutputFile<'a> {
    /// Relative path with `/` separators (`pieces/upper_03.stl`, `report.json`, …).
    pub path: String,
    /// The data.
    pub data: FileData<'a>,
}

impl FileData<'_> {
    /// Writes the data to `path` with [`save`](crate::save) (the format follows the extension;
    /// parts as one morph-target glTF) and returns every file written.
    ///
    /// # Errors
    /// [`IoError`](crate::IoError) naming the file.
    pub fn save(&self, path: &Path) -> crate::Result<Vec<PathBuf>> {
        let layers: Vec<(&MeshAnimation, Option<&[[f32; 4]]>)>;
        let output = match self {
            FileData::Text(t) => crate::Output::Text(t),
            FileData::Bytes(b) => crate::Output::Bytes(b),
            FileData::Mesh(m) => crate::Output::Mesh(m),
            FileData::OwnedMesh(m) => crate::Output::Mesh(m),
            FileData::PointCache(a) => crate::Output::Animation {
                animation: a,
                layout: crate::Layout::default(),
                colors: None,
            },
            FileData::Shapes { parts, rest } => crate::Output::Shapes { parts, rest },
            FileData::Parts(parts) => {
                layers = parts.iter().map(|a| (*a, None)).collect();
                crate::Output::Parts {
                    parts: &layers,
                    layout: crate::Layout::Morph,
                }
            }
        };
        crate::save(path, &output)
    }
}

/// Writes every file of a layout under `dir` (in parallel) and returns the files written.
///
/// # Errors
/// The first [`IoError`](crate::IoError), naming its file.
pub fn save_files(dir: &Path, files: &[OutputFile<'_>]) -> crate::Result<Vec<PathBuf>> {
    use rayon::prelude::*;
    let written: Vec<Vec<PathBuf>> = files
        .par_iter()
        .map(|f| f.data.save(&dir.join(&f.path)))
        .collect::<crate::Result<_>>()?;
    Ok(written.into_iter().flatten().collect())
}
