//! The library size versus reconstruction error curve (StopShop Fig. 8) as a job, and the
//! whole library of one of its points built from the solve the curve already made.
//!
//! An artist picks the library size from this curve: [`size_curve`] solves StopShop Eq. 10
//! once per size and keeps the solved libraries, so [`library_of`] only prints and plans
//! the chosen one (the second half of [`library`](crate::library())), never solving again.

use std::borrow::Borrow;
use std::time::Instant;

use anim::MeshAnimation;
use serde::Serialize;

use super::error::{Error, Result};
use super::library_job::{finish, solve};
use super::options::{LibraryJobOptions, PieceCount};
use super::result::LibraryResult;
use crate::library::Library;

/// One point of the size-versus-error curve (StopShop Fig. 8).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SizePoint {
    /// Pieces per part.
    pub pieces: usize,
    /// Pieces over all parts (the curve's x axis).
    pub total_pieces: usize,
    /// StopShop Eq. 10 energy over all parts (model units²).
    pub energy: f64,
    /// Mean over frames of the mean vertex position error, millimetres at the print height
    /// (the curve's y axis).
    pub mean_error_mm: f64,
    /// Largest vertex position error over all frames, millimetres.
    pub max_error_mm: f64,
}

/// The curve and the library solved at each of its points.
#[derive(Debug, Clone)]
pub struct SizeCurve {
    /// The points, by increasing size.
    pub points: Vec<SizePoint>,
    /// The solved library of every point, in the same order.
    pub libraries: Vec<Library>,
}

impl SizeCurve {
    /// The solved library with `pieces` pieces per part, if the curve has that point.
    pub fn library(&self, pieces: usize) -> Option<&Library> {
        self.points
            .iter()
            .position(|p| p.pieces == pieces)
            .and_then(|i| self.libraries.get(i))
    }
}

/// Solves the library of `parts` (one animation per part, named by its mesh name, as for
/// [`library`](crate::library())) at every size of `sizes` (pieces per part; sorted and
/// deduplicated), with `opts`' method, λ, restarts and seed (`opts.pieces` is ignored).
/// `on_point(done, total)` is called before each solve and after the last; when it returns
/// `false` the curve stops and the points solved so far are returned (cancel).
///
/// # Errors
/// [`Error::Option`] for no size or a size of 0; the options' and the optimization's
/// errors as for [`library`](crate::library()) (e.g. more pieces than frames).
pub fn size_curve<A: Borrow<MeshAnimation>>(
    parts: &[A],
    opts: &LibraryJobOptions,
    sizes: &[usize],
    on_point: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<SizeCurve> {
    let mut sizes = sizes.to_vec();
    sizes.sort_unstable();
    sizes.dedup();
    if sizes.is_empty() || sizes[0] == 0 {
        return Err(Error::option_error(
            "sizes",
            "give one or more library sizes of at least 1 piece per part",
        ));
    }
    let anims: Vec<&MeshAnimation> = parts.iter().map(Borrow::borrow).collect();
    let names: Vec<String> = anims.iter().map(|a| a.mesh.name.clone()).collect();
    let mut curve = SizeCurve {
        points: Vec::new(),
        libraries: Vec::new(),
    };
    for (i, &d) in sizes.iter().enumerate() {
        if !on_point(i, sizes.len()) {
            return Ok(curve);
        }
        let at = LibraryJobOptions {
            pieces: PieceCount::Each(d),
            ..opts.clone()
        };
        let lib = solve(&anims, &names, &at)?;
        curve.points.push(SizePoint {
            pieces: d,
            total_pieces: lib.total_pieces(),
            energy: lib.energy,
            mean_error_mm: lib.errors_mm.position_mean,
            max_error_mm: lib.errors_mm.position_max,
        });
        curve.libraries.push(lib);
    }
    on_point(sizes.len(), sizes.len());
    Ok(curve)
}

/// The whole library job's result for `solved`, a library [`size_curve`] solved for the
/// same `parts` and `opts`: the pieces, assembly, shooting order, reconstruction and report
/// of [`library`](crate::library()) at that size, without solving StopShop Eq. 10 again.
/// The report's total time counts only this call.
///
/// # Errors
/// [`Error::Option`] when `solved` is not a library of `parts` (other part names, vertex
/// or frame counts); fabrication errors as for [`library`](crate::library()).
pub fn library_of<A: Borrow<MeshAnimation>>(
    parts: &[A],
    opts: &LibraryJobOptions,
    solved: &Library,
) -> Result<LibraryResult> {
    let start = Instant::now();
    let anims: Vec<&MeshAnimation> = parts.iter().map(Borrow::borrow).collect();
    let names: Vec<String> = anims.iter().map(|a| a.mesh.name.clone()).collect();
    let matches = solved.parts.len() == anims.len()
        && solved.parts.iter().zip(&anims).all(|(p, a)| {
            p.name == a.mesh.name
                && p.vertices == a.vertex_count()
                && p.solution.labels.len() == a.frame_count()
        });
    if !matches {
        return Err(Error::option_error(
            "parts",
            "the solved library is not of these parts: build the size curve of these parts again",
        ));
    }
    finish(solved.clone(), &anims, &names, opts, None, start)
}
