//! What [`library`](crate::library()) and [`run`](crate::run()) return.

use anim::{Mesh, MeshAnimation};

use super::print::Piece;
use super::report::LibraryReport;
use super::segment_job::Segmented;
use crate::library::{Assembly, Library, Plug, ShootingOrder};

/// The replacement library of every part and everything needed to print and shoot it.
#[derive(Debug, Clone)]
pub struct LibraryResult {
    /// The segmentation the parts came from ([`run`](crate::run()) only).
    pub segmented: Option<Segmented>,
    /// Part names (file-safe), in part order.
    pub part_names: Vec<String>,
    /// Libraries, labels, per-frame errors and size curves of every part.
    pub library: Library,
    /// Every piece, part by part.
    pub pieces: Vec<Piece>,
    /// The back surface every piece of a part seats on (millimetres, before keys and IDs;
    /// `pieces/<part>_back.obj`, read back by `--fixed`).
    pub backs: Vec<anim::Mesh>,
    /// With magnets, every part's mount: the back thickened towards the head with the pocket
    /// matching the pieces', key sockets and an ID recess (`pieces/<part>_back.stl`).
    pub mounts: Vec<anim::Mesh>,
    /// `library.3mf` (every piece a named object, laid out on build plates) when the print
    /// format asks for it.
    pub library_3mf: Option<Vec<u8>>,
    /// Which piece of each part goes on each frame.
    pub assembly: Assembly,
    /// A proposed order to shoot the frames with few piece swaps.
    pub shooting_order: ShootingOrder,
    /// Plugs across the seams (empty unless asked for).
    pub plugs: Vec<Plug>,
    /// The stop-motion reconstruction of every part (model units, input timing), kept as
    /// pieces and labels: [`LibraryResult::reconstruction_of`] expands one to every frame.
    pub reconstruction: Vec<Reconstruction>,
    /// `catalogue.png`: every piece with its embossed ID.
    pub catalogue: Vec<u8>,
    /// `assembly_shotNN.png` per shot: (file name, PNG bytes).
    pub sheets: Vec<(String, Vec<u8>)>,
    /// The numbers of `report.json`.
    pub report: LibraryReport,
}

/// The stop-motion reconstruction of one part: frame `f` shows piece `labels[f]` of the
/// part's library, on the input's topology and timing. Held this way (not expanded to every
/// frame), a feature-length reconstruction costs no more memory than its pieces.
#[derive(Debug, Clone, PartialEq)]
pub struct Reconstruction {
    /// The part's topology, attributes and rest positions, named after the part.
    pub mesh: Mesh,
    /// Frames per second of the input.
    pub fps: f32,
    /// Time of frame 0 in seconds.
    pub start_time: f32,
}

impl LibraryResult {
    /// The reconstruction of every part as shapes (its pieces) and the shape of each frame,
    /// for [`tkio::Output::Shapes`].
    pub fn shape_animations(&self) -> Vec<tkio::ShapeAnimation<'_>> {
        self.reconstruction
            .iter()
            .zip(&self.library.parts)
            .map(|(r, p)| tkio::ShapeAnimation {
                mesh: &r.mesh,
                shapes: &p.solution.pieces,
                shown: &p.solution.labels,
                fps: r.fps,
                start_time: r.start_time,
            })
            .collect()
    }

    /// The reconstruction of part `part` expanded to every frame (model units, input timing);
    /// `None` when there is no such part.
    pub fn reconstruction_of(&self, part: usize) -> Option<MeshAnimation> {
        let r = self.reconstruction.get(part)?;
        // A one-frame source for the topology and timing.
        let mut source = MeshAnimation::still(r.mesh.clone());
        source.fps = r.fps;
        source.start_time = r.start_time;
        self.library.reconstruction(part, &source)
    }

    /// Piece label of every frame, per part.
    pub fn labels(&self) -> Vec<&[u32]> {
        self.library
            .parts
            .iter()
            .map(|p| p.solution.labels.as_slice())
            .collect()
    }

    /// Whether a size search ran (then there is a size-versus-error curve).
    pub fn has_curve(&self) -> bool {
        self.library.parts.iter().any(|p| !p.curve.is_empty())
    }

    /// Piece identifiers of every frame (rows of the assembly sheet).
    pub fn frame_ids(&self) -> Vec<Vec<String>> {
        (0..self.assembly.frames.len())
            .map(|f| self.assembly.frame_ids(f))
            .collect()
    }
}
