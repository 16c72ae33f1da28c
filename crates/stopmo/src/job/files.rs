//! The output layout of a library (SPEC "Output layouts"), as relative paths and data
//! ([`OutputFile`]); [`tkio::save_files`] writes them (stopmo does no file work itself).

use anim::{Mesh, MeshAnimation};
use tkio::{FileData, OutputFile};

use super::error::{Error, Result};
use super::result::LibraryResult;

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

fn file(path: impl Into<String>, data: FileData<'_>) -> OutputFile<'_> {
    OutputFile {
        path: path.into(),
        data,
    }
}
