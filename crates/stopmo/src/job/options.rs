//! Options of the whole jobs: plain data with serde, so the same options come from CLI flags,
//! a TOML/JSON file, Python keyword arguments or a web form. Every field has a default.

use std::collections::BTreeMap;
use std::ops::RangeInclusive;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::library::{
    MagnetOptions, Method, PlugOptions, SolveOptions, DEFAULT_PRINT_HEIGHT_MM, DEFAULT_THICKNESS_MM,
};
use crate::segment::{PartSpec, SavedSegmentation, SegmentOptions};

/// Clearance of printed fits per millimetre of printer resolution: 0.15 mm at the default
/// 0.05 mm, the tight fit a resin printer holds (±0.15 mm; ≥ 0.3 mm gives a loose fit).
pub const CLEARANCE_PER_RESOLUTION: f64 = 3.0;

/// Largest clearance derived from the printer resolution (mm): a fit looser than this holds
/// nothing, whatever resolution is given (a huge one flags every piece as too close).
pub const MAX_DEFAULT_CLEARANCE_MM: f64 = 1.0;

/// The clearance used when none is given: [`CLEARANCE_PER_RESOLUTION`] times the printer
/// resolution, from 0.1 mm to [`MAX_DEFAULT_CLEARANCE_MM`].
pub fn default_clearance_mm(resolution_mm: f64) -> f64 {
    let c = resolution_mm * CLEARANCE_PER_RESOLUTION;
    if c.is_finite() {
        c.clamp(0.1, MAX_DEFAULT_CLEARANCE_MM)
    } else {
        0.1
    }
}

/// Clearances of printed fits a printer can use (mm): beyond 5 mm a fit holds nothing.
pub const CLEARANCE_RANGE_MM: RangeInclusive<f64> = 0.0..=5.0;

/// The printer minimums (thinnest wall, smallest feature) a printer can have (mm).
pub const PRINTER_MINIMUM_RANGE_MM: RangeInclusive<f64> = 0.0..=10.0;

/// Each side of a build plate (mm), from a toy printer to a large-format one.
pub const PLATE_SIDE_RANGE_MM: RangeInclusive<f64> = 10.0..=2000.0;

/// Build plate of a small resin printer (mm): where `library.3mf` lays the pieces out and
/// what the print-time estimate assumes when no plate is given.
pub const DEFAULT_PLATE_MM: [f64; 2] = [120.0, 68.0];

/// Which files hold the printable solids.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum PrintFormat {
    /// One STL per piece (`pieces/<part>_<NN>.stl`).
    #[default]
    #[serde(rename = "stl")]
    Stl,
    /// One `library.3mf` with every piece as a named object, laid out on build plates.
    #[serde(rename = "3mf")]
    ThreeMf,
    /// Both.
    #[serde(rename = "stl,3mf")]
    Both,
}

impl PrintFormat {
    /// Parses `stl`, `3mf` or `stl,3mf` (either order).
    pub fn parse(text: &str) -> Option<PrintFormat> {
        let mut stl = false;
        let mut three = false;
        for f in text.split(',') {
            match f.trim().to_ascii_lowercase().as_str() {
                "stl" => stl = true,
                "3mf" => three = true,
                _ => return None,
            }
        }
        Some(match (stl, three) {
            (true, true) => PrintFormat::Both,
            (false, true) => PrintFormat::ThreeMf,
            _ => PrintFormat::Stl,
        })
    }

    /// Whether one STL per piece is written.
    pub fn stl(self) -> bool {
        self != PrintFormat::ThreeMf
    }

    /// Whether `library.3mf` is written.
    pub fn three_mf(self) -> bool {
        self != PrintFormat::Stl
    }
}

/// Pieces per part when no size is given.
pub const DEFAULT_PIECES: usize = 20;

/// Options of [`segment`](crate::segment()).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct SegmentJobOptions {
    /// Named parts with their seeds (at least two), unless `auto_parts` is given.
    pub parts: Vec<PartSpec>,
    /// Choose this many parts automatically instead (named `part1`, `part2`, …).
    pub auto_parts: Option<usize>,
    /// Also draw StopShop Fig. 5 (parts beside the mean displacement) as a PNG.
    pub figure: bool,
    /// Reuse the cut and seam targets of an earlier segmentation of the same mesh (the
    /// `"reuse"` section of its `segmentation.json`) instead of `parts`: parts of both clips
    /// assemble together.
    pub reuse: Option<SavedSegmentation>,
    /// γ (StopShop Eq. 1), boundary smoothing, snapping, homogenization, welding.
    #[serde(flatten)]
    pub segment: SegmentOptions,
}

/// How many pieces each part gets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PieceCount {
    /// The same number of pieces for every part (fixed pieces included).
    Each(usize),
    /// A number per part, by part name; every part is named exactly once.
    PerPart(BTreeMap<String, usize>),
    /// The smallest library per part whose worst frame's mean position error is at most this
    /// many millimetres at the print height (StopShop Fig. 16).
    MaxErrorMm(f64),
    /// A total number of pieces over all parts, allocated greedily.
    Budget(usize),
}

impl Default for PieceCount {
    fn default() -> Self {
        PieceCount::Each(DEFAULT_PIECES)
    }
}

/// Options of [`library`](crate::library()).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct LibraryJobOptions {
    /// Library size rule.
    pub pieces: PieceCount,
    /// Which algorithm picks the pieces (StopShop Eq. 10, k-means or uniform sampling).
    pub method: Method,
    /// λ of StopShop Eq. 10, restarts, seed, iteration cap, tolerance.
    #[serde(flatten)]
    pub solve: SolveOptions,
    /// Printed height of the whole model in millimetres (scales the solids and the errors).
    pub print_height_mm: f64,
    /// Wall thickness of the printed pieces in millimetres.
    pub thickness_mm: f64,
    /// Male/female plugs across every seam shared by two parts (StopShop Fig. 13); their
    /// `thickness_mm` is taken from [`LibraryJobOptions::thickness_mm`].
    pub plugs: Option<PlugOptions>,
    /// Per-vertex saliency weights in the merged vertex order of the parts (parts one after
    /// the other); in [`run`](crate::run()), in the vertex order of the input animation
    /// (checked before segmenting, then carried through the cut to the parts).
    pub saliency: Option<Vec<f32>>,
    /// Frames that start a new, unrelated shot (no velocity term across them, StopShop
    /// Eq. 12).
    pub cuts: Vec<usize>,
    /// Pre-made pieces per part name (model units, one position per vertex of the part):
    /// they are kept and new pieces are added up to the library size.
    pub fixed: BTreeMap<String, Vec<Vec<Vec3>>>,
    /// Printed back surfaces per part name (millimetres, in the shell's vertex order: the
    /// `pieces/<part>_back.obj` of an earlier run): the new pieces seat on them instead of
    /// a back surface made for this clip, so they fit the printed library's head.
    pub backs: BTreeMap<String, Vec<Vec3>>,
    /// Printer resolution in millimetres: pieces that differ from a sibling by less are
    /// reported (a warning and `printing.parts[].below_resolution`).
    pub resolution_mm: f64,
    /// Registration keys (domes on the shared back surface that fix all six degrees of
    /// freedom on the armature/head).
    pub keys: bool,
    /// Piece ID (`P-NN`) embossed on the back of every piece.
    pub ids: bool,
    /// A disc magnet (millimetres): every piece gets a pocket for it at one place of its
    /// part's back that all pieces share, and the part's mount (`pieces/<part>_back.stl`)
    /// the matching pocket.
    pub magnets: Option<MagnetOptions>,
    /// Clearance of printed fits (millimetres): magnet pockets and the mount's key sockets
    /// are this much wider; `None`: [`default_clearance_mm`] of the printer resolution.
    /// Plugs keep their own `plugs.clearance_mm` (the CLI fills it from `--clearance`).
    pub clearance_mm: Option<f64>,
    /// Which files hold the printable solids: one STL per piece, `library.3mf`, or both.
    pub print_format: PrintFormat,
    /// Build plate width and depth (millimetres) where `library.3mf` lays the pieces out.
    pub plate_mm: [f64; 2],
    /// The printer's thinnest wall (millimetres): thinner walls of a piece or mount are
    /// reported (a warning and `printing.printability`), and magnet pockets keep at least
    /// this much material around them.
    pub min_wall_mm: f64,
    /// The printer's smallest free-standing feature (millimetres): smaller IDs, keys or plug
    /// pins are reported.
    pub min_feature_mm: f64,
    /// Build the printable solids (`pieces/*.stl`, the back surfaces, keys, IDs and the
    /// report's `"printing"`). Off, the job stops at the pieces' surfaces, the labels and the
    /// errors — a quick look at a library size before printing it (on the face, the solids
    /// are ~95 % of the job's time).
    pub print: bool,
}

impl Default for LibraryJobOptions {
    fn default() -> Self {
        LibraryJobOptions {
            pieces: PieceCount::default(),
            method: Method::StopShop,
            solve: SolveOptions::default(),
            print_height_mm: DEFAULT_PRINT_HEIGHT_MM,
            thickness_mm: DEFAULT_THICKNESS_MM,
            plugs: None,
            saliency: None,
            cuts: Vec::new(),
            fixed: BTreeMap::new(),
            backs: BTreeMap::new(),
            resolution_mm: DEFAULT_RESOLUTION_MM,
            keys: true,
            ids: true,
            magnets: None,
            clearance_mm: None,
            print_format: PrintFormat::Stl,
            plate_mm: DEFAULT_PLATE_MM,
            min_wall_mm: DEFAULT_MIN_WALL_MM,
            min_feature_mm: DEFAULT_MIN_FEATURE_MM,
            print: true,
        }
    }
}

impl LibraryJobOptions {
    /// The clearance of fits: [`LibraryJobOptions::clearance_mm`] or the default from the
    /// printer resolution.
    pub fn clearance(&self) -> f64 {
        self.clearance_mm
            .unwrap_or_else(|| default_clearance_mm(self.resolution_mm))
    }
}

/// Options of [`run`](crate::run()): segmentation, then the library of the parts.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct RunOptions {
    /// How to segment.
    pub segment: SegmentJobOptions,
    /// How to build the library of the segmented parts.
    pub library: LibraryJobOptions,
}

/// Printer resolution assumed when none is given (mm).
pub const DEFAULT_RESOLUTION_MM: f64 = 0.05;

/// Thinnest wall a resin or PolyJet printer holds (mm): 0.8–1 mm, the lower end.
pub const DEFAULT_MIN_WALL_MM: f64 = 0.8;

/// Smallest free-standing feature a resin or PolyJet printer forms (mm): 0.25–0.3 mm, the
/// upper end.
pub const DEFAULT_MIN_FEATURE_MM: f64 = 0.3;

/// How the pieces are printed.
pub(crate) struct PrintSettings<'a> {
    pub(crate) thickness_mm: f64,
    pub(crate) print_height_mm: f64,
    pub(crate) resolution_mm: f64,
    pub(crate) keys: bool,
    pub(crate) ids: bool,
    pub(crate) plugs: &'a [crate::library::Plug],
    pub(crate) plug_segments: usize,
    /// Disc magnet whose pocket every piece and mount gets.
    pub(crate) magnet: Option<MagnetOptions>,
    /// Clearance of fits (key sockets, magnet pockets; mm).
    pub(crate) clearance_mm: f64,
    /// Build plate (mm): the print-time estimate's.
    pub(crate) plate_mm: [f64; 2],
    /// Files of the solids.
    pub(crate) print_format: PrintFormat,
    /// The printer's thinnest wall (mm).
    pub(crate) min_wall_mm: f64,
    /// The printer's smallest free-standing feature (mm).
    pub(crate) min_feature_mm: f64,
    /// Printed back surfaces by part name (see [`crate::LibraryJobOptions::backs`]).
    pub(crate) backs: &'a BTreeMap<String, Vec<Vec3>>,
}
