//! Whole jobs on in-memory data: [`segment`], [`library`], [`run`], with serde options and
//! results that carry their reports and list their output files.

mod checks;
mod error;
mod figure;
mod files;
mod fixed_pieces;
mod library_job;
mod library_memory;
mod magnets;
mod options;
mod piece;
mod plates;
mod print;
mod printability;
mod report;
mod resolution;
mod result;
mod segment_job;
mod sheets;
mod size_curve;
mod text;

pub use checks::check_positive_mm;
pub use error::{Error, Result};
pub use fixed_pieces::{is_library_piece, library_pieces, PiecesFolder};
pub use library_job::{file_safe_name, library, library_frames, run};
pub use library_memory::{frames_memory, library_memory};
pub use options::{
    default_clearance_mm, LibraryJobOptions, PieceCount, PrintFormat, RunOptions,
    SegmentJobOptions, CLEARANCE_PER_RESOLUTION, CLEARANCE_RANGE_MM, DEFAULT_MIN_FEATURE_MM,
    DEFAULT_MIN_WALL_MM, DEFAULT_PIECES, DEFAULT_PLATE_MM, MAX_DEFAULT_CLEARANCE_MM,
    PLATE_SIDE_RANGE_MM, PRINTER_MINIMUM_RANGE_MM,
};
pub use plates::Plate;
pub use print::{piece_label, Piece, DEFAULT_RESOLUTION_MM};
pub use printability::{PrintabilityReport, SolidPrintability, Thin, ThinSpot};
pub use report::{
    FramesForm, LibraryReport, OrderReport, PartPrintReport, PartReport, PieceReport, PlugReport,
    PrintReport, PrintTime,
};
pub use result::{LibraryResult, Reconstruction};
pub use segment_job::{
    check_segment_memory, saved_segmentation, segment, segment_into_parts, segment_memory,
    segment_owned, PartSummary, SegmentSummary, Segmented,
};
pub use size_curve::{library_of, size_curve, SizeCurve, SizePoint};
pub use tkio::{FileData, OutputFile};
