//! Options and measurements of the shared back surface.

use serde::{Deserialize, Serialize};

use crate::library::fabricate::{DEFAULT_PRINT_HEIGHT_MM, DEFAULT_THICKNESS_MM};

/// Width (Gaussian σ, millimetres along the surface) of [`DirectionField::Geodesic`] for a
/// model printed [`DEFAULT_PRINT_HEIGHT_MM`] high ([`DirectionField::Best`] scales it with
/// [`ShellOptions::model_height_mm`]). Narrower or wider, the directions fold the back behind
/// the nose on the ICT face (README seeds, `upper` part, crossing triangles left: 792 at 7 mm
/// and 8 pieces, 160 at 14 mm and 20 pieces, 240 at 21 mm and 8 pieces; none at 17.5 mm for
/// 8, 20 and 50 pieces).
pub const DEFAULT_NORMAL_SMOOTHING_MM: f64 = 17.5;
/// Radius (millimetres, in mean edge lengths) of [`DirectionField::EdgeRings`] for a model
/// printed [`DEFAULT_PRINT_HEIGHT_MM`] high (scaled like [`DEFAULT_NORMAL_SMOOTHING_MM`]).
pub const DEFAULT_EDGE_RING_RADIUS_MM: f64 = 14.0;

/// Radius of the column under a front vertex the back must stay behind
/// ([`ShellOptions::model_height_mm`] × this), and how far behind the vertex it reaches
/// ([`DEFAULT_ENVELOPE_REACH`]). They follow the face's features (the nostrils behind the
/// nose tip, the lips behind the mouth corners), so they scale with the print, not with the
/// wall: set in walls (2 and 3 walls of 1.5 mm at 60 mm), a 1 mm wall left 0.56 mm under the
/// nose and a 2.5 mm wall 816 crossing triangles, and prints of 100 and 150 mm left 0.87 and
/// 0.00 mm walls at the nose tip (ICT face, README seeds, 8 pieces; all clean with these).
pub const DEFAULT_ENVELOPE_LATERAL: f64 = 0.05;
/// How far behind a front vertex its column reaches, × [`ShellOptions::model_height_mm`]
/// (see [`DEFAULT_ENVELOPE_LATERAL`]).
pub const DEFAULT_ENVELOPE_REACH: f64 = 0.075;

/// How the inward direction field the back is offset along is smoothed.
///
/// Neither field is best on every cut of the ICT face (crossing triangles over 8 pieces per
/// part, bare shells): the geodesic disc is even in millimetres and unfolds the back behind
/// lips walled by a seam (two automatic parts: 5,043 → 2,506; seeds 0,15,8 / 0,−8,12:
/// 550 → 354), the edge rings smooth more where the mesh is coarse and keep other cuts clean
/// (seeds 30,0,0 / 0,−14,10: 0, geodesic 376; the README seeds plus 30,0,0: 0, geodesic
/// 216). [`DirectionField::Best`] builds a part's back with both and keeps the one that
/// crosses less.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DirectionField {
    /// Vertex normals diffused over `(radius_mm / mean edge)²` edge rings (at most 4,000):
    /// smooths less in millimetres where the mesh is finer than its mean.
    EdgeRings {
        /// Radius in millimetres (through the part's mean edge length).
        radius_mm: f64,
    },
    /// Area-weighted normals averaged over a geodesic disc of Gaussian width `sigma_mm`.
    Geodesic {
        /// Gaussian width in millimetres along the surface.
        sigma_mm: f64,
    },
    /// Both fields at their default widths scaled to the model's height
    /// ([`ShellOptions::model_height_mm`] / [`DEFAULT_PRINT_HEIGHT_MM`]: at 25 mm the
    /// unscaled widths left 572 crossing triangles on the README cut, none scaled); each part
    /// keeps the back with fewer crossing triangles (then one whose wall holds the minimum; a
    /// tie keeps the edge rings).
    Best,
}

/// Laplacian smoothing steps of the back surface.
pub const DEFAULT_BACK_SMOOTHING_ITERATIONS: usize = 300;
/// Boundary loops shorter than this fraction of the longest one are capped.
pub const DEFAULT_CAP_FRACTION: f64 = 0.5;

/// Rounds of local repair where the exact test still finds crossings. Each round re-runs the
/// exact test over every piece (and the wall measure), so one by default: it straightens the
/// crossing wall rungs, which does most of the gain (ICT face, README seeds, 8 pieces per
/// part: 308 crossing triangles of 311,968 without repair, 247 with 1 round, 247 with 8;
/// 20 pieces: 833 → 816 with 1 round; 50: 2,363 → 2,235; 8 rounds cost twice the time). Raise it in
/// `ShellOptions::repair_rounds` for more.
pub const DEFAULT_REPAIR_ROUNDS: usize = 1;

/// Rounds of the last search of [`build_shells`](super::build_shells) that moves single
/// points where the exact test still finds crossings after the repair: each round runs the
/// exact test on every piece, then tries every crossing point once (ICT face, README seeds,
/// 8 / 20 / 50 pieces per part: 247 / 816 / 2,235 crossing triangles → 20 / 40 / 95; 2–3
/// rounds end it there, a round without a move ends it; `stopmo run` 8 pieces 13.2 → 14.1 s,
/// 50 pieces 51 → 66 s, release).
pub const DEFAULT_RESOLVE_ROUNDS: usize = 8;

/// Options of the shared back surface (millimetres, like the printable pieces).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ShellOptions {
    /// Minimum wall between any piece's front and the back surface.
    pub wall_mm: f64,
    /// Printed height of the whole model: the direction field ([`DirectionField::Best`]) and
    /// the envelope's column scale with it.
    pub model_height_mm: f64,
    /// How the inward direction field is smoothed.
    pub direction: DirectionField,
    /// Laplacian smoothing steps of the back surface.
    pub smoothing_iterations: usize,
    /// Rounds of local repair driven by the exact intersection test.
    pub repair_rounds: usize,
    /// Rounds of the search that moves single back vertices where crossings are left
    /// (0: none).
    pub resolve_rounds: usize,
    /// Boundary loops shorter than this fraction of the longest loop (eye and mouth
    /// openings) are capped instead of walled.
    pub cap_fraction: f64,
    /// Smooth the back surface's boundary too (walls may lean inward).
    pub smooth_boundary: bool,
}

impl Default for ShellOptions {
    fn default() -> Self {
        ShellOptions {
            wall_mm: DEFAULT_THICKNESS_MM,
            model_height_mm: DEFAULT_PRINT_HEIGHT_MM,
            direction: DirectionField::Best,
            smoothing_iterations: DEFAULT_BACK_SMOOTHING_ITERATIONS,
            repair_rounds: DEFAULT_REPAIR_ROUNDS,
            resolve_rounds: DEFAULT_RESOLVE_ROUNDS,
            cap_fraction: DEFAULT_CAP_FRACTION,
            smooth_boundary: false,
        }
    }
}

/// Measurements of a [`PartShell`](super::PartShell).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct ShellStats {
    /// Repair rounds used.
    pub repair_rounds: usize,
    /// Rounds of the last search (moving single back vertices) used.
    pub resolve_rounds: usize,
    /// Front points shifted (by at most the printer resolution, 0.05 mm, in every piece)
    /// where the front folds over a wall.
    pub front_nudged_points: usize,
    /// Back points pushed deeper at the end where some piece's front still came closer to
    /// the back than the wall.
    pub thickened_back_points: usize,
    /// Self-intersecting triangles over all pieces' solids, summed (0 when printable): after
    /// the repair for a bare shell; of the written solids (keys and IDs included) in a
    /// library job's report.
    pub self_intersecting_triangles: usize,
    /// Smallest distance from a front vertex of any piece to the back surface (mm).
    pub min_wall_mm: f64,
}
