//! The numbers of `report.json` (SPEC "Output layouts").

use serde::Serialize;

use super::printability::PrintabilityReport;
use crate::library::{
    ErrorSummary, Key, Library, MagnetOptions, MaterialEstimate, Method, Plug, Pocket, ShellStats,
    ShootingOrder,
};

/// One plug in the report (millimetres, print coordinates).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlugReport {
    /// Part carrying the pin.
    pub male: String,
    /// Part carrying the socket.
    pub female: String,
    /// Anchor on the seam.
    pub anchor_mm: [f32; 3],
    /// Outward surface normal at the anchor.
    pub normal: [f32; 3],
    /// Plug axis, from the male into the female part.
    pub axis: [f32; 3],
    /// Axis point below the anchor.
    pub center_mm: [f32; 3],
    /// Pin radius.
    pub radius_mm: f32,
    /// Socket bore radius.
    pub socket_radius_mm: f32,
    /// Outer radius of boss and socket.
    pub outer_radius_mm: f32,
    /// Boss plus pin length.
    pub length_mm: f32,
    /// Seam vertices shared by the two parts.
    pub seam_vertices: usize,
}

/// One part in the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PartReport {
    /// Part name.
    pub name: String,
    /// Library size.
    pub pieces: usize,
    /// Vertices.
    pub vertices: usize,
    /// StopShop Eq. 10 energy of the part (model units²).
    pub energy: f64,
    /// Block-coordinate-descent iterations of the best restart.
    pub iterations: usize,
    /// Restarts run.
    pub restarts: usize,
    /// Errors in millimetres at the print height, against the artist's animation (before
    /// homogenization) when it is known ([`run`](crate::run())).
    pub errors_mm: ErrorSummary,
    /// Errors against the animation the library was built from (homogenized seams).
    pub library_errors_mm: ErrorSummary,
}

/// The shooting order in the report.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OrderReport {
    /// Distinct assemblies to shoot.
    pub shots: usize,
    /// Piece swaps along the proposed order.
    pub swaps: usize,
    /// Piece swaps when shooting in frame order.
    pub sequential_swaps: usize,
}

/// `report.json`: energy, λ, pieces, per-part and total mean/max position and velocity errors
/// in millimetres, timing, iterations, restarts, plugs, shooting order.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LibraryReport {
    /// The input file, when a front end sets it (not serialized when `None`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub input: Option<String>,
    /// Method used.
    pub method: Method,
    /// Total StopShop Eq. 10 energy (model units²).
    pub energy: f64,
    /// λ of StopShop Eq. 10.
    pub lambda: f64,
    /// Total pieces.
    pub pieces: usize,
    /// Frames.
    pub frames: usize,
    /// Frames per second of the animation.
    pub fps: f32,
    /// Millimetres per model unit.
    pub mm_per_unit: f64,
    /// Printed height of the model.
    pub print_height_mm: f64,
    /// Wall thickness of the pieces.
    pub thickness_mm: f64,
    /// Plugs across the seams.
    pub plugs: Vec<PlugReport>,
    /// Errors over all parts in millimetres, against the artist's animation (before
    /// homogenization) when it is known ([`run`](crate::run())).
    pub errors_mm: ErrorSummary,
    /// Errors against the animation the library was built from.
    pub library_errors_mm: ErrorSummary,
    /// What homogenization alone changed (homogenized parts against the input), when the
    /// input is known.
    pub homogenization_errors_mm: Option<ErrorSummary>,
    /// Back surfaces, keys, IDs, resolution check, material and print time (`null` when the
    /// job did not print: [`LibraryJobOptions::print`](crate::LibraryJobOptions::print)).
    pub printing: Option<PrintReport>,
    /// Printing warnings (e.g. pieces below the printer resolution).
    pub warnings: Vec<String>,
    /// The assembly sheets with thumbnails (`assembly_shotNN.png`).
    pub assembly_sheets: Vec<String>,
    /// Per part.
    pub parts: Vec<PartReport>,
    /// Iterations summed over parts.
    pub iterations: usize,
    /// Restarts per solve.
    pub restarts: usize,
    /// Shooting order summary.
    pub shooting_order: OrderReport,
    /// Wall time of the optimization in seconds.
    pub seconds: f64,
    /// Wall time of the whole job in seconds.
    pub total_seconds: f64,
    /// Peak resident memory of the process up to the end of the job, in MiB (the `VmHWM` of
    /// `/proc/self/status`; `null` where the system does not tell).
    pub peak_memory_mib: Option<f64>,
    /// How the parts' frames reached the solver: positions, or morph weights expanded only
    /// where needed (`docs/stopmo-scale.md`).
    pub frames_form: FramesForm,
}

/// How a library job was given its parts' frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FramesForm {
    /// Positions of every frame.
    Positions,
    /// Morph weights on still nodes (every part).
    MorphWeights,
    /// Some parts as positions, some as morph weights.
    Mixed,
}

impl FramesForm {
    /// The form of `parts`.
    pub(crate) fn of(parts: &[anim::MeshFrames]) -> FramesForm {
        let morph = parts
            .iter()
            .filter(|p| matches!(p, anim::MeshFrames::Morph(_)))
            .count();
        match morph {
            0 => FramesForm::Positions,
            m if m == parts.len() => FramesForm::MorphWeights,
            _ => FramesForm::Mixed,
        }
    }
}

/// Peak resident memory of this process so far in MiB (`VmHWM`, Linux); `None` elsewhere.
pub(crate) fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kb: f64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))?
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    Some(kb / 1024.0)
}

/// Inputs of [`LibraryReport::new`] beyond the library.
pub(crate) struct ReportInputs<'a> {
    pub(crate) names: &'a [String],
    pub(crate) plugs: &'a [Plug],
    pub(crate) order: &'a ShootingOrder,
    pub(crate) frames: usize,
    pub(crate) fps: f32,
    pub(crate) print_height_mm: f64,
    pub(crate) thickness_mm: f64,
    pub(crate) restarts: usize,
    pub(crate) errors: InputErrors,
    pub(crate) printing: Option<PrintReport>,
    pub(crate) warnings: Vec<String>,
    pub(crate) sheets: Vec<String>,
}

/// Errors against the artist's animation, in millimetres.
pub(crate) struct InputErrors {
    /// All parts.
    pub(crate) total: ErrorSummary,
    /// Per part.
    pub(crate) parts: Vec<ErrorSummary>,
    /// What homogenization alone changed, when the input is known.
    pub(crate) homogenization: Option<ErrorSummary>,
}

impl LibraryReport {
    /// The report of `lib` (`total_seconds` 0 and no peak memory until the job sets them).
    pub(crate) fn new(lib: &Library, x: ReportInputs<'_>) -> LibraryReport {
        LibraryReport {
            input: None,
            frames_form: FramesForm::Positions,
            method: lib.method,
            energy: lib.energy,
            lambda: lib.lambda,
            pieces: lib.total_pieces(),
            frames: x.frames,
            fps: x.fps,
            mm_per_unit: lib.mm_per_unit,
            print_height_mm: x.print_height_mm,
            thickness_mm: x.thickness_mm,
            plugs: x.plugs.iter().map(|p| plug_report(p, x.names)).collect(),
            errors_mm: x.errors.total,
            library_errors_mm: lib.errors_mm,
            homogenization_errors_mm: x.errors.homogenization,
            printing: x.printing,
            warnings: x.warnings,
            assembly_sheets: x.sheets,
            parts: lib
                .parts
                .iter()
                .enumerate()
                .map(|(i, p)| PartReport {
                    name: p.name.clone(),
                    pieces: p.solution.pieces.len(),
                    vertices: p.vertices,
                    energy: p.solution.energy,
                    iterations: p.solution.iterations,
                    restarts: p.solution.restarts,
                    errors_mm: x.errors.parts[i],
                    library_errors_mm: p.errors_mm,
                })
                .collect(),
            iterations: lib.parts.iter().map(|p| p.solution.iterations).sum(),
            restarts: x.restarts,
            shooting_order: OrderReport {
                shots: x.order.shots.len(),
                swaps: x.order.swaps,
                sequential_swaps: x.order.sequential_swaps,
            },
            seconds: lib.seconds,
            total_seconds: 0.0,
            peak_memory_mib: None,
        }
    }

    /// Pretty-printed JSON (`report.json`).
    pub fn to_json(&self) -> String {
        super::segment_job::to_pretty_json(self)
    }
}

fn plug_report(p: &Plug, names: &[String]) -> PlugReport {
    PlugReport {
        male: names[p.male].clone(),
        female: names[p.female].clone(),
        anchor_mm: p.anchor,
        normal: p.normal,
        axis: p.axis,
        center_mm: p.center,
        radius_mm: p.radius_mm,
        socket_radius_mm: p.socket_radius_mm,
        outer_radius_mm: p.outer_radius_mm,
        length_mm: p.length_mm,
        seam_vertices: p.seam_vertices,
    }
}

/// One part in [`PrintReport`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PartPrintReport {
    /// Part name.
    pub name: String,
    /// Measurements of the part's shared back surface.
    pub shell: ShellStats,
    /// Registration keys on the back surface (empty without keys).
    pub keys: Vec<Key>,
    /// Pieces closer to a sibling than the printer resolution.
    pub below_resolution: Vec<String>,
    /// Smallest largest-vertex-distance between two pieces of the part (mm; `null` for one
    /// piece).
    pub min_sibling_distance_mm: f64,
    /// Triangles of the pieces' animated surfaces (the library pieces alone, before the back
    /// is added) that cross that same surface, summed over the pieces whose solid crosses:
    /// where the input presses into itself inside one part (lips or lids on a face) or has
    /// degenerate triangles. No back can undo these (the regularized solid merges the touching
    /// surfaces); a seam between them (one in each part) or a mended input keeps them apart.
    pub surface_self_intersecting_triangles: usize,
    /// Triangles of the solids as built (front, back, walls, keys, ID) that cross the same
    /// solid, summed over the pieces; those pieces were regularized
    /// ([`regularize`](crate::library::regularize)) and `shell.self_intersecting_triangles`
    /// counts what is left in the written solids.
    pub built_self_intersecting_triangles: usize,
    /// Pieces whose solid crossed itself as built and was regularized: the printed shape
    /// differs from the animated surface where it crossed.
    pub regularized_pieces: Vec<String>,
    /// Volume of what regularizing dropped (mm³): chips of material apart from a piece and
    /// sealed cavities inside it (filled).
    pub dropped_volume_mm3: f64,
    /// The magnet pocket every piece of the part has, and the mount has at the same place
    /// (`null` without magnets).
    pub magnet_pocket: Option<Pocket>,
}

/// The print-time estimate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PrintTime {
    /// Estimated hours.
    pub hours: f64,
    /// Build plates needed.
    pub plates: f64,
    /// Layers per plate.
    pub layers_per_plate: f64,
    /// Layer height (mm).
    pub layer_mm: f64,
    /// Seconds per layer.
    pub seconds_per_layer: f64,
    /// Build plate (mm).
    pub plate_mm: [f64; 2],
    /// What the estimate assumes.
    pub assumes: String,
}

/// One printed piece in [`PrintReport::pieces`]: what a print shop and an animator look up.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PieceReport {
    /// Identifier `<part>_<NN>` (file stem, 3MF object name).
    pub id: String,
    /// The ID embossed on its back (`P-NN`).
    pub label: String,
    /// Part name.
    pub part: String,
    /// Frames (0-based) the piece is on, in frame order.
    pub frames: Vec<usize>,
    /// Volume of its solid (mm³).
    pub volume_mm3: f64,
    /// Whether it has a magnet pocket (at its part's `magnet_pocket`).
    pub magnet: bool,
    /// Build plate of `library.3mf` it is on (1-based; `null` without a 3MF).
    pub plate: Option<usize>,
}

/// `report.json` `"printing"`: material, print time, resolution check, keys and IDs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PrintReport {
    /// Material of all solids.
    pub material: MaterialEstimate,
    /// Print-time estimate.
    pub print_time: PrintTime,
    /// Printer resolution checked against (mm).
    pub resolution_mm: f64,
    /// Whether registration keys were added.
    pub keys: bool,
    /// Whether IDs were embossed.
    pub ids: bool,
    /// Clearance of the fits (mm): magnet pockets are this much wider (radius) and deeper
    /// than the magnet, the mount's key sockets and ID recess wider and deeper than the key
    /// or ID; from `--clearance`, else 3 × the printer resolution.
    pub clearance_mm: f64,
    /// The disc magnet every piece holds (`null` without magnets).
    pub magnet: Option<MagnetOptions>,
    /// Files of the solids: `"stl"`, `"3mf"` or `"stl,3mf"`.
    pub print_format: super::options::PrintFormat,
    /// Build plates of `library.3mf` (empty without a 3MF): several plates are laid side by
    /// side along x in its one build, each listed here with its origin and pieces.
    pub plates: Vec<super::plates::Plate>,
    /// Per part.
    pub parts: Vec<PartPrintReport>,
    /// Per piece: ID, part, frames used, volume, magnet, plate.
    pub pieces: Vec<PieceReport>,
    /// Thinnest wall and smallest feature of every piece and mount against the printer's
    /// minimums.
    pub printability: PrintabilityReport,
}
