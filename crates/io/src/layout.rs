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

/// Writes every file of a layout under `dir` (in parallel) and returns the files written, in
/// the layout's order.
///
/// The largest files start first: a point cache of a long clip can take longer to write than
/// all the other files together, and started last it would be written while the other
/// threads wait.
///
/// # Errors
/// [`IoError::WouldOverwriteInput`](crate::IoError::WouldOverwriteInput) before anything
/// is written when a target is a file the job read; else the first
/// [`IoError`](crate::IoError), naming its file.
pub fn save_files(dir: &Path, files: &[OutputFile<'_>]) -> crate::Result<Vec<PathBuf>> {
    use rayon::prelude::*;
    // Every target is checked before any is written: a layout that would write over an
    // input of the job writes nothing.
    for f in files {
        crate::inputs::check_not_input(&dir.join(&f.path))?;
    }
    let mut written: Vec<(usize, Vec<PathBuf>)> = largest_first(files)
        .into_par_iter()
        .map(|i| {
            files[i]
                .data
                .save(&dir.join(&files[i].path))
                .map(|w| (i, w))
        })
        .collect::<crate::Result<_>>()?;
    written.sort_unstable_by_key(|(i, _)| *i);
    Ok(written.into_iter().flat_map(|(_, w)| w).collect())
}

/// The indices of `files` by [`FileData::size_hint`], largest first (equal sizes in the
/// layout's order).
fn largest_first(files: &[OutputFile<'_>]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..files.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(files[i].data.size_hint(&files[i].path)));
    order
}

impl FileData<'_> {
    /// About how many bytes the file at `path` will hold (its extension says the format):
    /// only the order in which [`save_files`] starts the files depends on it.
    fn size_hint(&self, path: &str) -> u64 {
        let ext = path.rsplit('.').next().unwrap_or("").to_ascii_lowercase();
        // Text formats: about 36 bytes per vertex and 24 per triangle (OBJ); binary STL: 50
        // per triangle; float32 positions elsewhere.
        let mesh = |m: &Mesh| -> u64 {
            let (v, t) = (m.vertex_count() as u64, m.triangles.len() as u64);
            match ext.as_str() {
                "stl" => 50 * t,
                _ => 36 * v + 24 * t,
            }
        };
        let cache = |a: &MeshAnimation| 12 * a.positions().len() as u64;
        match self {
            FileData::Text(t) => t.len() as u64,
            FileData::Bytes(b) => b.len() as u64,
            FileData::Mesh(m) => mesh(m),
            FileData::OwnedMesh(m) => mesh(m),
            FileData::Parts(parts) => parts.iter().map(|a| cache(a)).sum(),
            FileData::PointCache(a) => cache(a),
            FileData::Shapes { parts, .. } => parts
                .iter()
                .map(|p| {
                    // A point cache holds every frame; a glTF each shape once.
                    let held = if ext == "pc2" || ext == "mdd" {
                        p.shown.len()
                    } else {
                        p.shapes.len()
                    };
                    12 * (held * p.mesh.vertex_count()) as u64
                })
                .sum(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn mesh(vertices: usize) -> Mesh {
        Mesh::new(
            "m",
            vec![Vec3::ZERO; vertices],
            vec![[0, 0, 0]; vertices / 2],
        )
    }

    /// A stop-motion library's layout: the point cache of every frame starts before the
    /// pieces and the sheets, then the rest by size, equal sizes in the layout's order.
    #[test]
    fn the_point_cache_of_a_long_clip_is_written_first() {
        let (piece, rest) = (mesh(100), mesh(100));
        let shapes = vec![vec![Vec3::ZERO; 100]; 3];
        let shown = vec![0u32; 5_000];
        let part = crate::ShapeAnimation {
            mesh: &piece,
            shapes: &shapes,
            shown: &shown,
            fps: 24.0,
            start_time: 0.0,
        };
        let file = |path: &str, data| OutputFile {
            path: path.into(),
            data,
        };
        let files = vec![
            file("pieces/a.obj", FileData::Mesh(&piece)),
            file("pieces/b.obj", FileData::Mesh(&piece)),
            file("report.json", FileData::Text("{}".into())),
            file(
                "reconstruction.glb",
                FileData::Shapes {
                    parts: vec![part],
                    rest: rest.clone(),
                },
            ),
            file(
                "reconstruction.pc2",
                FileData::Shapes {
                    parts: vec![part],
                    rest,
                },
            ),
        ];
        assert_eq!(largest_first(&files), vec![4, 0, 1, 3, 2]);
        assert_eq!(files[4].data.size_hint(&files[4].path), 12 * 5_000 * 100);
        assert_eq!(files[3].data.size_hint(&files[3].path), 12 * 3 * 100);

        // Written in that order, listed in the layout's (every file written, the streamed
        // point cache too).
        let dir = tempfile::tempdir().unwrap();
        let written = save_files(dir.path(), &files).unwrap();
        let names: Vec<String> = written
            .iter()
            .map(|p| p.strip_prefix(dir.path()).unwrap().display().to_string())
            .collect();
        // The point cache's rest mesh is written beside it, listed after it.
        assert_eq!(
            names,
            [
                "pieces/a.obj",
                "pieces/b.obj",
                "report.json",
                "reconstruction.glb",
                "reconstruction.pc2",
                "reconstruction.obj",
            ]
        );
        let pc2 = std::fs::metadata(dir.path().join("reconstruction.pc2")).unwrap();
        assert_eq!(pc2.len(), 32 + 12 * 5_000 * 100);
    }

    /// A library written into its input's folder, where one of its files has the input's
    /// name: refused before any file of the layout is written (no half-written folder).
    #[test]
    fn a_layout_over_its_input_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("reconstruction.glb");
        std::fs::write(&input, b"glTF").unwrap();
        let scope = crate::inputs::ReadScope::open();
        crate::inputs::note_read(&input);
        let piece = mesh(10);
        let files = vec![
            OutputFile {
                path: "pieces/a.obj".into(),
                data: FileData::Mesh(&piece),
            },
            OutputFile {
                path: "reconstruction.glb".into(),
                data: FileData::Text("x".into()),
            },
        ];
        let e = save_files(dir.path(), &files).unwrap_err().to_string();
        assert!(e.contains("reconstruction.glb"), "{e}");
        assert_eq!(std::fs::read(&input).unwrap(), b"glTF");
        assert!(!dir.path().join("pieces").exists(), "nothing written");
        drop(scope);
    }
}
