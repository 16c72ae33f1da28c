//! The whole library for a set of parts: size selection, method, print scale, results.

use std::time::Instant;

use anim::{Mesh, MeshAnimation};
use rayon::prelude::*;
use serde::Serialize;

use super::assembly::{piece_id, Assembly};
use super::error::{LibraryError, Result};
use super::fabricate::{scaled, solidify};
use super::metrics::{evaluate, ErrorSummary, FrameErrors};
use super::problem::{PartProblem, PartSetup};
use super::size::{budget_search, max_error_search, CurvePoint};
use super::solver::{PartSolution, SolveOptions};
use super::source::Source;
use super::subspace::SubspaceOptions;

/// How many pieces each part gets.
#[derive(Debug, Clone, PartialEq)]
pub enum LibrarySize {
    /// The same number of pieces for every part (fixed ones included).
    Pieces(usize),
    /// One size per part, in part order.
    PerPart(Vec<usize>),
    /// Smallest size whose worst frame error is at most this many model units (Fig. 16).
    MaxError(f64),
    /// A total number of pieces over all parts, allocated greedily.
    Budget(usize),
}

/// Which algorithm picks the pieces (Fig. 19 compares all three).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// StopShop Eq. 10 with the velocity term (λ from the options).
    StopShop,
    /// λ = 0: k-means (Lloyd), the paper's "velocity independent" variant.
    KMeans,
    /// Uniform temporal sampling, the naive baseline.
    Uniform,
}

/// Options of [`build_library`].
#[derive(Debug, Clone, PartialEq)]
pub struct LibraryOptions {
    /// Library size rule.
    pub size: LibrarySize,
    /// Algorithm.
    pub method: Method,
    /// Optimization parameters (λ, restarts, seed, …).
    pub solve: SolveOptions,
    /// Reduction of the frames.
    pub subspace: SubspaceOptions,
    /// Printed height (Y extent over all frames and parts) in millimetres.
    pub print_height_mm: f64,
}

impl Default for LibraryOptions {
    fn default() -> Self {
        LibraryOptions {
            size: LibrarySize::Pieces(20),
            method: Method::StopShop,
            solve: SolveOptions::default(),
            subspace: SubspaceOptions::default(),
            print_height_mm: super::fabricate::DEFAULT_PRINT_HEIGHT_MM,
        }
    }
}

/// One part to build a library for.
#[derive(Debug, Clone)]
pub struct PartInput<'a> {
    /// The part's animation (named after the part).
    pub animation: &'a MeshAnimation,
    /// Saliency, fixed pieces, cuts.
    pub setup: PartSetup,
}

/// The library of one part.
#[derive(Debug, Clone, PartialEq)]
pub struct PartResult {
    /// Part name.
    pub name: String,
    /// Pieces and labels.
    pub solution: PartSolution,
    /// Per-frame errors in model units.
    pub errors: FrameErrors,
    /// Error summary in millimetres.
    pub errors_mm: ErrorSummary,
    /// Sizes evaluated by a size search (empty for a given size).
    pub curve: Vec<CurvePoint>,
    /// Vertex count.
    pub vertices: usize,
}

/// Libraries of all parts.
#[derive(Debug, Clone, PartialEq)]
pub struct Library {
    /// Per part results, in input order.
    pub parts: Vec<PartResult>,
    /// Method used.
    pub method: Method,
    /// λ the energies are evaluated with.
    pub lambda: f64,
    /// Total StopShop Eq. 10 energy over parts (model units²).
    pub energy: f64,
    /// Millimetres per model unit.
    pub mm_per_unit: f64,
    /// Errors over all parts in millimetres (means weighted by vertex count).
    pub errors_mm: ErrorSummary,
    /// Wall time of the optimization in seconds.
    pub seconds: f64,
}

/// Millimetres per model unit so that the Y extent of all parts over all frames prints at
/// `height_mm` (falls back to the bounding-box diagonal for flat models, and to 1 for a
/// single point).
pub fn print_scale(anims: &[&MeshAnimation], height_mm: f64) -> f64 {
    scale_of(anims.iter().map(|a| a.bbox()), height_mm)
}

/// [`print_scale`] of parts given as positions or morph weights (the latter expanded in
/// streamed blocks).
pub(crate) fn print_scale_of(parts: &[Source<'_>], height_mm: f64) -> f64 {
    scale_of(parts.iter().map(Source::bbox), height_mm)
}

/// [`print_scale`] of the parts' bounding boxes.
fn scale_of(boxes: impl Iterator<Item = anim::Aabb>, height_mm: f64) -> f64 {
    let bbox = boxes.fold(anim::Aabb::EMPTY, anim::Aabb::union);
    let h = f64::from(bbox.max.y - bbox.min.y);
    let extent = if h > 0.0 && h.is_finite() {
        h
    } else {
        f64::from(bbox.diagonal())
    };
    if extent > 0.0 && extent.is_finite() {
        height_mm / extent
    } else {
        1.0
    }
}

/// Builds the replacement library of every part (Sections 3.3 and 5).
///
/// # Errors
/// Invalid inputs or options (see [`LibraryError`]).
///
/// # Performance
/// Parts are reduced once each; every solve is parallel over restarts.
pub fn build_library(parts: &[PartInput<'_>], opts: &LibraryOptions) -> Result<Library> {
    let sources: Vec<(Source<'_>, &PartSetup)> = parts
        .iter()
        .map(|p| (Source::Positions(p.animation), &p.setup))
        .collect();
    build_sources(&sources, opts)
}

/// [`build_library`] of parts given as positions or morph weights.
pub(crate) fn build_sources(
    parts: &[(Source<'_>, &PartSetup)],
    opts: &LibraryOptions,
) -> Result<Library> {
    let start = Instant::now();
    let first = parts.first().ok_or(LibraryError::NoParts)?;
    let n = first.0.frame_count();
    for (p, _) in parts {
        if p.frame_count() != n {
            return Err(LibraryError::FrameCountMismatch {
                part: p.mesh().name.clone(),
                expected: n,
                found: p.frame_count(),
            });
        }
    }
    if !(opts.print_height_mm.is_finite() && opts.print_height_mm > 0.0) {
        return Err(LibraryError::InvalidParameter(format!(
            "print height must be > 0 mm, got {}",
            opts.print_height_mm
        )));
    }
    opts.solve.validate()?;
    let lambda = opts.solve.lambda;
    let problems = parts
        .iter()
        .enumerate()
        .map(|(i, (src, setup))| {
            PartProblem::of(*src, setup, &opts.subspace, opts.solve.seed ^ i as u64)
        })
        .collect::<Result<Vec<_>>>()?;
    let method_opts = match opts.method {
        Method::KMeans => SolveOptions {
            lambda: 0.0,
            ..opts.solve
        },
        _ => opts.solve,
    };
    let confine = opts.method == Method::StopShop && lambda > 0.0;
    // Where each part ends (once per part: the searches below solve many sizes).
    let borders: Vec<Vec<(usize, f32)>> = problems
        .iter()
        .map(|p| {
            if confine {
                p.border_weights()
            } else {
                Vec::new()
            }
        })
        .collect();
    // The solution and, when its energy was evaluated here, its per-frame errors (kept, so
    // that a given size passes over the frames once for both).
    let solve_full = |i: usize, d: usize| -> Result<(PartSolution, Option<FrameErrors>)> {
        let p = &problems[i];
        // Evaluated once, after the pieces are final.
        let reevaluate = confine || opts.method == Method::KMeans;
        let mut s = match opts.method {
            Method::Uniform => p.uniform(d, lambda)?,
            _ => p.solve_with(d, &method_opts, !reevaluate)?,
        };
        if confine {
            // The velocity term lets pieces leave the input's range; not where a part ends.
            p.confine_borders(&mut s, &borders[i]);
        }
        let errors = reevaluate.then(|| {
            let (energy, errors) = evaluate(p, &s.pieces, &s.labels, lambda);
            s.energy = energy;
            errors
        });
        Ok((s, errors))
    };
    let solve_one = |i: usize, d: usize| solve_full(i, d).map(|(s, _)| s);
    let given = |(s, e): (PartSolution, Option<FrameErrors>)| (s, Vec::new(), e);
    let solved: Vec<(PartSolution, Vec<CurvePoint>, Option<FrameErrors>)> = match &opts.size {
        LibrarySize::Pieces(d) => (0..problems.len())
            .map(|i| solve_full(i, *d).map(given))
            .collect::<Result<_>>()?,
        LibrarySize::PerPart(ds) => {
            if ds.len() != problems.len() {
                return Err(LibraryError::InvalidParameter(format!(
                    "{} sizes given for {} parts",
                    ds.len(),
                    problems.len()
                )));
            }
            (0..problems.len())
                .map(|i| solve_full(i, ds[i]).map(given))
                .collect::<Result<_>>()?
        }
        LibrarySize::MaxError(e) => (0..problems.len())
            .map(|i| {
                max_error_search(&problems[i], *e, lambda, &|d| solve_one(i, d))
                    .map(|(s, c)| (s, c, None))
            })
            .collect::<Result<_>>()?,
        LibrarySize::Budget(b) => budget_search(&problems, *b, lambda, &solve_one)?
            .into_iter()
            .map(|(s, c)| (s, c, None))
            .collect(),
    };
    // Errors first: their pass over the frames also gives the bounding boxes of the scale.
    let solved: Vec<(PartSolution, Vec<CurvePoint>, FrameErrors)> = solved
        .into_par_iter()
        .zip(problems.par_iter())
        .map(|((solution, curve, errors), p)| {
            let errors =
                errors.unwrap_or_else(|| evaluate(p, &solution.pieces, &solution.labels, lambda).1);
            (solution, curve, errors)
        })
        .collect();
    let mm = scale_of(problems.iter().map(PartProblem::bbox), opts.print_height_mm);
    let results: Vec<PartResult> = solved
        .into_par_iter()
        .zip(problems.par_iter())
        .map(|((solution, curve, errors), p)| PartResult {
            name: p.name.clone(),
            errors_mm: errors.summary(mm),
            errors,
            solution,
            curve,
            vertices: p.vertices(),
        })
        .collect();
    let summary: Vec<(ErrorSummary, usize)> =
        results.iter().map(|r| (r.errors_mm, r.vertices)).collect();
    Ok(Library {
        energy: results.iter().map(|r| r.solution.energy).sum(),
        errors_mm: ErrorSummary::combine(&summary),
        parts: results,
        method: opts.method,
        lambda,
        mm_per_unit: mm,
        seconds: start.elapsed().as_secs_f64(),
    })
}

impl Library {
    /// The assembly table (piece of every part on every frame).
    pub fn assembly(&self) -> Assembly {
        let labels: Vec<&[u32]> = self
            .parts
            .iter()
            .map(|p| p.solution.labels.as_slice())
            .collect();
        Assembly::new(
            self.parts.iter().map(|p| p.name.clone()).collect(),
            self.parts.iter().map(|p| p.solution.pieces.len()).collect(),
            &labels,
        )
    }

    /// Total number of pieces.
    pub fn total_pieces(&self) -> usize {
        self.parts.iter().map(|p| p.solution.pieces.len()).sum()
    }

    /// The stop-motion reconstruction of part `part` (model units): frame `f` shows the piece
    /// of its label. `source` is the part's input animation (for topology and timing).
    pub fn reconstruction(&self, part: usize, source: &MeshAnimation) -> Option<MeshAnimation> {
        let sol = &self.parts.get(part)?.solution;
        let positions = sol
            .labels
            .iter()
            .flat_map(|&l| sol.pieces[l as usize].iter().copied())
            .collect();
        let mut out = MeshAnimation::new(source.mesh.clone(), source.fps, positions).ok()?;
        out.start_time = source.start_time;
        Some(out)
    }

    /// Piece `k` of part `part` as a surface in model units, named `<part>_<NN>`.
    pub fn piece_surface(&self, part: usize, k: usize, topology: &Mesh) -> Option<Mesh> {
        let p = self.parts.get(part)?;
        let pos = p.solution.pieces.get(k)?;
        let mut m = Mesh::new(
            piece_id(&p.name, k, p.solution.pieces.len()),
            pos.clone(),
            topology.triangles.clone(),
        );
        m.uvs = topology.uvs.clone();
        Some(m)
    }

    /// Piece `k` of part `part` as a printable solid in millimetres (see
    /// [`solidify`](super::solidify)), `thickness_mm` thick.
    pub fn printable_piece(
        &self,
        part: usize,
        k: usize,
        topology: &Mesh,
        thickness_mm: f64,
    ) -> Result<Mesh> {
        let surface = self.piece_surface(part, k, topology).ok_or_else(|| {
            LibraryError::InvalidParameter(format!("no piece {k} of part {part}"))
        })?;
        solidify(
            &scaled(&surface, self.mm_per_unit as f32),
            thickness_mm as f32,
        )
    }
}
