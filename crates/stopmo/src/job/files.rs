//! The output layout of a library (SPEC "Output layouts"), as relative paths and data, and
//! [`save_files`], the one mapping of that data to [`tkio::save`] every front end uses.

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use anim::{Mesh, MeshAnimation};

use super::error::{Error, Result};
use super::result::LibraryResult;

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
        parts: Vec<tkio::ShapeAnimation<'a>>,
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

impl LibraryResult {
    /// Every file of the output layout: `pieces/<part>_<NN>.obj` and `.stl` (no `.stl` when
    /// the job did not print),
    /// (none either with `print_format` `3mf`), `pieces/<part>_back.obj` (the shared back
    /// surface, mm), `pieces/<part>_back.stl` (the mount, with magnets), `library.3mf` (with
    /// the 3MF print format), `assembly.csv`,
    /// `assembly.md`, `catalogue.png`, `assembly_shotNN.png` (one per shot),
    /// `shooting_order.csv`, `report.json`, `reconstruction.glb`,
    /// `reconstruction.pc2` + `rest.obj`, `error_curve.csv` / `.png` after a size search and,
    /// for [`run`](crate::run()), `segmentation.glb`, `segmentation.json` and
    /// `segmentation.png` (when the figure was asked for).
    ///
    /// # Errors
    /// When the reconstruction cannot be merged or the curve chart cannot be drawn.
    pub fn files(&self) -> Result<Vec<OutputFile<'_>>> {
        let mut out = Vec::new();
        if let Some(seg) = &self.segmented {
            out.push(file(
                "segmentation.glb",
                FileData::Parts(seg.part_animations()),
            ));
            out.push(file("segmentation.json", FileData::Text(seg.report_json())));
            if let Some(png) = &seg.figure {
                out.push(file("segmentation.png", FileData::Bytes(png.clone())));
            }
        }
        for p in &self.pieces {
            out.push(file(
                format!("pieces/{}.obj", p.id),
                FileData::Mesh(&p.surface),
            ));
            if let Some(solid) = p.solid.as_ref().filter(|_| self.writes_stl()) {
                out.push(file(format!("pieces/{}.stl", p.id), FileData::Mesh(solid)));
            }
        }
        for b in &self.backs {
            out.push(file(format!("pieces/{}.obj", b.name), FileData::Mesh(b)));
        }
        for m in &self.mounts {
            out.push(file(format!("pieces/{}.stl", m.name), FileData::Mesh(m)));
        }
        if let Some(bytes) = &self.library_3mf {
            out.push(file("library.3mf", FileData::Bytes(bytes.clone())));
        }
        out.push(file("assembly.csv", FileData::Text(self.assembly_csv())));
        out.push(file(
            "assembly.md",
            FileData::Text(self.assembly_markdown()),
        ));
        out.push(file(
            "catalogue.png",
            FileData::Bytes(self.catalogue.clone()),
        ));
        for (name, png) in &self.sheets {
            out.push(file(name.clone(), FileData::Bytes(png.clone())));
        }
        out.push(file(
            "shooting_order.csv",
            FileData::Text(self.shooting_order_csv()),
        ));
        let rest = self.merged_rest()?;
        out.push(file(
            "reconstruction.glb",
            FileData::Shapes {
                parts: self.shape_animations(),
                rest: rest.clone(),
            },
        ));
        out.push(file("rest.obj", FileData::OwnedMesh(rest.clone())));
        out.push(file(
            "reconstruction.pc2",
            FileData::Shapes {
                parts: self.shape_animations(),
                rest,
            },
        ));
        if let Some(csv) = self.error_curve_csv() {
            out.push(file("error_curve.csv", FileData::Text(csv)));
        }
        if let Some(png) = self.error_curve_png()? {
            out.push(file("error_curve.png", FileData::Bytes(png)));
        }
        out.push(file("report.json", FileData::Text(self.report.to_json())));
        Ok(out)
    }

    /// Whether the pieces' solids are written as STL files (the print format says so).
    fn writes_stl(&self) -> bool {
        self.report
            .printing
            .as_ref()
            .is_none_or(|p| p.print_format.stl())
    }

    /// All parts' reconstructions merged into one point cache, in part order (the vertex
    /// order of `reconstruction.pc2` and `rest.obj`).
    ///
    /// # Errors
    /// When the parts' frames differ (they never do for a library's own reconstruction).
    pub fn merged_reconstruction(&self) -> Result<MeshAnimation> {
        let parts = (0..self.reconstruction.len())
            .map(|i| {
                self.reconstruction_of(i).ok_or_else(|| {
                    Error::option_error("parts", format!("no reconstruction of part {i}"))
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(match parts.len() {
            1 => parts.into_iter().next().expect("one part"),
            _ => MeshAnimation::concat("reconstruction", &parts)?,
        })
    }

    /// The rest mesh of [`LibraryResult::merged_reconstruction`] (`rest.obj`), without
    /// expanding the frames.
    ///
    /// # Errors
    /// As [`LibraryResult::merged_reconstruction`].
    pub fn merged_rest(&self) -> Result<Mesh> {
        Ok(match self.reconstruction.as_slice() {
            [one] => one.mesh.clone(),
            all => {
                let stills: Vec<MeshAnimation> = all
                    .iter()
                    .map(|r| {
                        let mut a = MeshAnimation::still(r.mesh.clone());
                        a.fps = r.fps;
                        a
                    })
                    .collect();
                MeshAnimation::concat("reconstruction", &stills)?.mesh
            }
        })
    }
}

impl FileData<'_> {
    /// Writes the data to `path` with [`tkio::save`] (the format follows the extension;
    /// parts as one morph-target glTF) and returns every file written.
    ///
    /// # Errors
    /// [`tkio::IoError`] naming the file.
    pub fn save(&self, path: &Path) -> tkio::Result<Vec<PathBuf>> {
        let layers: Vec<(&MeshAnimation, Option<&[[f32; 4]]>)>;
        let output = match self {
            FileData::Text(t) => tkio::Output::Text(t),
            FileData::Bytes(b) => tkio::Output::Bytes(b),
            FileData::Mesh(m) => tkio::Output::Mesh(m),
            FileData::OwnedMesh(m) => tkio::Output::Mesh(m),
            FileData::PointCache(a) => tkio::Output::Animation {
                animation: a,
                layout: tkio::Layout::default(),
                colors: None,
            },
            FileData::Shapes { parts, rest } => tkio::Output::Shapes { parts, rest },
            FileData::Parts(parts) => {
                layers = parts.iter().map(|a| (*a, None)).collect();
                tkio::Output::Parts {
                    parts: &layers,
                    layout: tkio::Layout::Morph,
                }
            }
        };
        tkio::save(path, &output)
    }
}

/// Writes every file of a layout under `dir` (in parallel) and returns the files written.
///
/// # Errors
/// The first [`tkio::IoError`], naming its file.
pub fn save_files(dir: &Path, files: &[OutputFile<'_>]) -> tkio::Result<Vec<PathBuf>> {
    use rayon::prelude::*;
    let written: Vec<Vec<PathBuf>> = files
        .par_iter()
        .map(|f| f.data.save(&dir.join(&f.path)))
        .collect::<tkio::Result<_>>()?;
    Ok(written.into_iter().flatten().collect())
}

fn file(path: impl Into<String>, data: FileData<'_>) -> OutputFile<'_> {
    OutputFile {
        path: path.into(),
        data,
    }
}
