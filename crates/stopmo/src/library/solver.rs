//! Block coordinate descent on StopShop Eq. 10 with k-means++ seeding and parallel restarts.

use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};
use glam::Vec3;
use rayon::prelude::*;

use super::candidates::{candidate_label_step, CandidateInputs, CandidateWork, MIN_PIECES};
use super::error::{LibraryError, Result};
use super::kmeans_pp::kmeans_pp;
use super::metrics::evaluate;
use super::problem::PartProblem;
use super::source::Source;
use super::update::{
    morph_right_hand_side, right_hand_side, solve_pieces, system_matrix, Dense, Positions,
};
use super::viterbi::{label_step, ChainTerms, LabelInputs, ViterbiWork};
use anim::SplitMix64;

/// Velocity weight λ of StopShop Eq. 10 (the paper's results use 2).
pub const DEFAULT_LAMBDA: f64 = 2.0;
/// Random restarts; the best energy is kept.
pub const DEFAULT_RESTARTS: usize = 8;
/// Most random restarts one optimization takes. Each restart is a whole block coordinate
/// descent (about a quarter of a CPU second at StopShop Table-1 scale), so this bounds a
/// solve's work, not its memory (only the best restart so far is kept).
pub const MAX_RESTARTS: usize = 1024;
/// Cap on block coordinate descent iterations (the paper reports 5–10).
pub const DEFAULT_MAX_ITERATIONS: usize = 50;
/// Stop when one iteration lowers the energy by less than this fraction.
pub const DEFAULT_TOLERANCE: f64 = 1e-5;
/// Default seed.
pub const DEFAULT_SEED: u64 = 0x5709_5409;

/// Parameters of one optimization.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct SolveOptions {
    /// Velocity weight λ ≥ 0 (0 = k-means / Lloyd).
    pub lambda: f64,
    /// Number of random restarts (≥ 1), run in parallel.
    pub restarts: usize,
    /// Seed of every random choice.
    pub seed: u64,
    /// Iteration cap per restart.
    pub max_iterations: usize,
    /// Relative energy decrease below which a restart stops.
    pub tolerance: f64,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            lambda: DEFAULT_LAMBDA,
            restarts: DEFAULT_RESTARTS,
            seed: DEFAULT_SEED,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            tolerance: DEFAULT_TOLERANCE,
        }
    }
}

impl SolveOptions {
    pub(crate) fn validate(&self) -> Result<()> {
        if !(self.lambda.is_finite() && self.lambda >= 0.0) {
            return Err(LibraryError::InvalidParameter(format!(
                "lambda must be finite and >= 0, got {}",
                self.lambda
            )));
        }
        if !(1..=MAX_RESTARTS).contains(&self.restarts) {
            return Err(LibraryError::InvalidParameter(format!(
                "restarts must be between 1 and {MAX_RESTARTS}, got {}",
                self.restarts
            )));
        }
        if !(self.tolerance.is_finite() && self.tolerance >= 0.0) {
            return Err(LibraryError::InvalidParameter(
                "tolerance must be finite and >= 0".into(),
            ));
        }
        Ok(())
    }
}

/// A library for one part and its per-frame labels.
#[derive(Debug, Clone, PartialEq)]
pub struct PartSolution {
    /// Pieces (model units): fixed ones first, one position per vertex.
    pub pieces: Vec<Vec<Vec3>>,
    /// Piece of each frame.
    pub labels: Vec<u32>,
    /// StopShop Eq. 10 evaluated exactly in full space (model units², saliency-weighted).
    pub energy: f64,
    /// Library steps of the best restart.
    pub iterations: usize,
    /// Restarts run.
    pub restarts: usize,
    /// Energy after each label step of the best restart (reduced space; Fig. 9).
    pub history: Vec<f64>,
    /// Fraction of the frame energy the reduction kept (1 = exact).
    pub captured: f64,
}

/// One restart's state in reduced coordinates.
struct Run {
    labels: Vec<u32>,
    /// The library of the last label step (reduced coordinates).
    #[cfg_attr(not(test), allow(dead_code))]
    lib: Vec<f64>,
    energy: f64,
    iterations: usize,
    history: Vec<f64>,
}

/// Gives every unused free piece the worst-fitting frame (largest unary cost) among frames
/// whose piece is fixed or used more than once, so that `A` stays positive definite.
pub(crate) fn repair_empty(labels: &mut [u32], cost: &[f64], fixed: usize, d: usize) {
    let mut count = vec![0usize; d];
    labels.iter().for_each(|&l| count[l as usize] += 1);
    if (fixed..d).all(|k| count[k] > 0) {
        return;
    }
    let mut order: Vec<usize> = (0..labels.len()).collect();
    order.sort_by(|&a, &b| cost[b].total_cmp(&cost[a]).then(a.cmp(&b)));
    let mut it = order.into_iter();
    for k in fixed..d {
        if count[k] > 0 {
            continue;
        }
        for f in it.by_ref() {
            let l = labels[f] as usize;
            if l < fixed || count[l] > 1 {
                count[l] -= 1;
                count[k] += 1;
                labels[f] = k as u32;
                break;
            }
        }
    }
}

#[derive(Default)]
struct LabelBuffers {
    p: Vec<f64>,
    g: Vec<f64>,
    cost: Vec<f64>,
    work: ViterbiWork,
    candidates: CandidateWork,
}

/// Which label step an iteration runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Step {
    /// Over each frame's candidate pieces (`keep`: the current labels among them).
    Candidates { keep: bool },
    /// The exact dynamic programming over all pieces.
    Exact,
}

#[allow(clippy::too_many_arguments)]
fn label(
    prob: &PartProblem<'_>,
    lib: &[f64],
    d: usize,
    lambda: f64,
    par: Par,
    buf: &mut LabelBuffers,
    labels: &mut [u32],
    step: Step,
) -> f64 {
    let (n, q) = (prob.frames(), prob.sub.dim);
    let y = MatRef::from_row_major_slice(prob.frame_coords(), n, q);
    let r = MatRef::from_row_major_slice(lib, d, q);
    buf.g.resize(d * d, 0.0);
    matmul(
        MatMut::from_row_major_slice_mut(&mut buf.g, d, d),
        Accum::Replace,
        r,
        r.transpose(),
        1.0,
        par,
    );
    buf.cost.resize(n, 0.0);
    let terms = ChainTerms {
        g: &buf.g,
        xx: &prob.xx,
        dxx: &prob.dxx,
        chains: &prob.chains,
        lambda,
        d,
    };
    if let Step::Candidates { keep } = step {
        let inp = CandidateInputs {
            y: prob.frame_coords(),
            r: lib,
            q,
            terms,
        };
        return candidate_label_step(&inp, labels, keep, &mut buf.cost, &mut buf.candidates);
    }
    buf.p.resize(n * d, 0.0);
    // One GEMM per iteration: X Rᵀ gives both ‖x − r‖² and Δx·r.
    matmul(
        MatMut::from_row_major_slice_mut(&mut buf.p, n, d),
        Accum::Replace,
        y,
        r.transpose(),
        1.0,
        par,
    );
    let inp = LabelInputs { p: &buf.p, terms };
    label_step(&inp, labels, &mut buf.cost, &mut buf.work)
}

/// One restart; `yt` holds the frames' reduced coordinates transposed (`q × n`) for the
/// seeding on one thread (empty otherwise).
fn run(
    prob: &PartProblem<'_>,
    d: usize,
    opts: &SolveOptions,
    restart: usize,
    par: Par,
    yt: &[f64],
) -> Result<Run> {
    let (n, q, nf) = (prob.frames(), prob.sub.dim, prob.fixed);
    let mut rng = SplitMix64::new(opts.seed, restart as u64 + 1);
    let mut lib = kmeans_pp(prob, d, &mut rng, par, yt);
    let mut buf = LabelBuffers::default();
    let mut labels = vec![0u32; n];
    let mut prev = vec![0u32; n];
    // Many pieces: candidate label steps while they improve, then exact ones
    // (docs/stopmo-scale.md, "Candidate label steps").
    let mut candidates = d >= MIN_PIECES && opts.lambda > 0.0;
    let first = if candidates {
        Step::Candidates { keep: false }
    } else {
        Step::Exact
    };
    let mut energy = label(
        prob,
        &lib,
        d,
        opts.lambda,
        par,
        &mut buf,
        &mut labels,
        first,
    );
    let mut history = vec![energy];
    let mut iterations = 0;
    while d > nf && iterations < opts.max_iterations {
        repair_empty(&mut labels, &buf.cost, nf, d);
        let a = system_matrix(&labels, &prob.chains, opts.lambda, d);
        let b = right_hand_side(
            &Dense {
                data: prob.frame_coords(),
                cols: q,
            },
            &labels,
            &prob.chains,
            opts.lambda,
            d,
        );
        lib = solve_pieces(&a, b, d, q, nf, prob.fixed_coords())?;
        iterations += 1;
        let mut step = if candidates {
            Step::Candidates { keep: true }
        } else {
            Step::Exact
        };
        loop {
            prev.copy_from_slice(&labels);
            let e = label(prob, &lib, d, opts.lambda, par, &mut buf, &mut labels, step);
            history.push(e);
            let stalled = energy - e <= opts.tolerance * energy.abs();
            energy = e;
            if !(prev == labels || stalled) {
                break;
            }
            if step == Step::Exact {
                return Ok(Run {
                    labels,
                    lib,
                    energy,
                    iterations,
                    history,
                });
            }
            // The candidate steps have settled: the same library, the exact step next.
            candidates = false;
            step = Step::Exact;
        }
    }
    Ok(Run {
        labels,
        lib,
        energy,
        iterations,
        history,
    })
}

fn finish(
    prob: &PartProblem<'_>,
    d: usize,
    lambda: f64,
    mut labels: Vec<u32>,
) -> Result<(Vec<Vec<Vec3>>, Vec<u32>)> {
    let (m, nf) = (prob.vertices(), prob.fixed);
    // The last label step may leave a free piece unused: repair before the full-space step.
    if d > nf {
        let mut count = vec![0usize; d];
        labels.iter().for_each(|&l| count[l as usize] += 1);
        if (nf..d).any(|k| count[k] == 0) {
            let q = prob.sub.dim;
            let y = prob.frame_coords();
            // Cost of a frame: squared distance to the mean of its label's frames.
            let mut mean = vec![0.0; d * q];
            for (f, &l) in labels.iter().enumerate() {
                for c in 0..q {
                    mean[l as usize * q + c] += y[f * q + c] / count[l as usize].max(1) as f64;
                }
            }
            let cost: Vec<f64> = (0..labels.len())
                .map(|f| {
                    let l = labels[f] as usize;
                    (0..q)
                        .map(|c| (y[f * q + c] - mean[l * q + c]).powi(2))
                        .sum()
                })
                .collect();
            repair_empty(&mut labels, &cost, nf, d);
        }
    }
    let a = system_matrix(&labels, &prob.chains, lambda, d);
    let b = match prob.src {
        Source::Positions(anim) => {
            let positions = Positions {
                data: anim.positions(),
                vertices: m,
            };
            right_hand_side(&positions, &labels, &prob.chains, lambda, d)
        }
        Source::Morph(anim) => morph_right_hand_side(anim, &labels, &prob.chains, lambda, d),
    };
    let flat = solve_pieces(&a, b, d, 3 * m, nf, &prob.fixed_rows)?;
    let pieces = flat
        .par_chunks_exact((3 * m).max(1))
        .map(|r| {
            r.chunks_exact(3)
                .map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32))
                .collect()
        })
        .collect();
    Ok((pieces, labels))
}

impl PartProblem<'_> {
    /// Optimizes a library of `pieces` pieces (fixed ones included) and the labels (StopShop Eqs. 10–16).
    ///
    /// Block coordinate descent in the reduced coordinates: k-means++ seeding, exact label
    /// steps (Viterbi, the `viterbi` module), library steps from the normal
    /// equations with empty-piece repair; `opts.restarts` restarts run in parallel and the
    /// lowest energy wins (ties: lowest restart index). A final library step in full space
    /// gives the pieces, and the energy is evaluated exactly.
    ///
    /// # Errors
    /// [`LibraryError::ZeroPieces`], [`LibraryError::TooManyPieces`] (more free pieces than
    /// frames), [`LibraryError::InvalidParameter`].
    ///
    /// # Performance
    /// Per iteration: one `frames × dim × pieces` GEMM, an `O(frames · pieces²)` Viterbi sweep
    /// and an `O(frames · dim)` pass; then one streaming pass over the full frames.
    pub fn solve(&self, pieces: usize, opts: &SolveOptions) -> Result<PartSolution> {
        self.solve_with(pieces, opts, true)
    }

    /// [`PartProblem::solve`]; without `evaluate` the energy is left NaN for a caller that
    /// changes the pieces and evaluates them itself (one pass over the frames less).
    pub(crate) fn solve_with(
        &self,
        pieces: usize,
        opts: &SolveOptions,
        evaluate_energy: bool,
    ) -> Result<PartSolution> {
        opts.validate()?;
        let d = pieces;
        if d == 0 {
            return Err(LibraryError::ZeroPieces);
        }
        if d < self.fixed {
            return Err(LibraryError::InvalidParameter(format!(
                "part '{}': {} pieces requested but {} are fixed",
                self.name, d, self.fixed
            )));
        }
        if d - self.fixed > self.frames() {
            return Err(LibraryError::TooManyPieces {
                part: self.name.clone(),
                pieces: d - self.fixed,
                frames: self.frames(),
            });
        }
        let par = if opts.restarts > 1 {
            Par::Seq
        } else {
            Par::rayon(rayon::current_num_threads().max(1))
        };
        let yt = match par {
            Par::Seq => self.frame_coords_transposed(),
            _ => Vec::new(),
        };
        // Only the best restart so far is kept (memory for two runs per thread, however
        // many restarts): the lowest energy, the first restart among equal ones, the first
        // restart's error in restart order.
        let best = (0..opts.restarts)
            .into_par_iter()
            .map(|r| run(self, d, opts, r, par, &yt))
            .reduce_with(|a, b| match (a, b) {
                (Ok(a), Ok(b)) => Ok(if b.energy < a.energy { b } else { a }),
                (Err(e), _) | (Ok(_), Err(e)) => Err(e),
            })
            .expect("restarts >= 1")?;
        let (pieces, labels) = finish(self, d, opts.lambda, best.labels)?;
        let energy = if evaluate_energy {
            evaluate(self, &pieces, &labels, opts.lambda).0
        } else {
            f64::NAN
        };
        Ok(PartSolution {
            pieces,
            labels,
            energy,
            iterations: best.iterations,
            restarts: opts.restarts,
            history: best.history,
            captured: self.sub.captured,
        })
    }

    /// Labels every frame with a fully given library (exact Viterbi, no library update):
    /// the "pre-defined library" workflow when every piece is fixed.
    pub fn label_fixed(&self, lambda: f64) -> Result<PartSolution> {
        let opts = SolveOptions {
            lambda,
            restarts: 1,
            ..SolveOptions::default()
        };
        self.solve(self.fixed, &opts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::library::{PartSetup, SubspaceOptions};
    use anim::{Mesh, MeshAnimation};

    /// A wobbling strip: `frames` frames of a smooth random motion (cuts at `cuts`).
    fn strip(frames: usize, seed: u64) -> MeshAnimation {
        let m = 12;
        let mesh = Mesh::new(
            "strip",
            (0..m).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect(),
            (0..m as u32 - 2).map(|i| [i, i + 1, i + 2]).collect(),
        );
        let mut rng = SplitMix64::new(seed, 5);
        let phase: Vec<f32> = (0..3 * m).map(|_| 6.0 * rng.next_f64() as f32).collect();
        let positions = (0..frames)
            .flat_map(|f| {
                let t = f as f32 * 0.05;
                let phase = &phase;
                (0..m).map(move |i| {
                    let w = |k: usize| (t * (1.0 + k as f32 * 0.37) + phase[3 * i + k]).sin();
                    Vec3::new(i as f32 + 0.3 * w(0), w(1), 0.5 * w(2))
                })
            })
            .collect();
        MeshAnimation::new(mesh, 24.0, positions).expect("strip")
    }

    /// k-means++ on one thread skips blocks of frames the new centre cannot come nearer to
    /// (triangle inequality, `kmeans_pp::FAR_MARGIN`): the centres are those of the full
    /// update on the pool, bit for bit, for every restart's seed.
    #[test]
    fn kmeans_pp_skipping_far_frames_picks_the_same_centres() {
        let anim = strip(900, 7);
        let prob = PartProblem::new(&anim, &PartSetup::default(), &SubspaceOptions::default(), 1)
            .expect("part");
        let yt = prob.frame_coords_transposed();
        for (d, restart) in [(5, 1u64), (70, 2), (200, 3)] {
            let mut a = SplitMix64::new(DEFAULT_SEED, restart);
            let mut b = SplitMix64::new(DEFAULT_SEED, restart);
            let skipped = kmeans_pp(&prob, d, &mut a, Par::Seq, &yt);
            let full = kmeans_pp(&prob, d, &mut b, Par::rayon(2), &[]);
            assert_eq!(skipped.len(), d * prob.sub.dim);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&skipped), bits(&full), "{d} pieces, restart {restart}");
        }
    }

    /// With many pieces the restarts start with candidate label steps; each ends where an
    /// exact label step over its last library finds nothing better, with an energy that
    /// never rose from step to step.
    #[test]
    fn candidate_steps_end_at_an_exact_label_step() {
        let anim = strip(600, 3);
        let setup = PartSetup {
            cuts: vec![250],
            ..PartSetup::default()
        };
        let prob = PartProblem::new(&anim, &setup, &SubspaceOptions::default(), 1).expect("part");
        let d = MIN_PIECES + 6;
        let opts = SolveOptions::default();
        for restart in 0..3 {
            let yt = prob.frame_coords_transposed();
            let run = run(&prob, d, &opts, restart, Par::Seq, &yt).expect("run");
            for w in run.history.windows(2) {
                assert!(
                    w[1] <= w[0] * (1.0 + 1e-12),
                    "energy rose: {:?}",
                    run.history
                );
            }
            let mut buf = LabelBuffers::default();
            let mut labels = vec![0u32; prob.frames()];
            let exact = label(
                &prob,
                &run.lib,
                d,
                opts.lambda,
                Par::Seq,
                &mut buf,
                &mut labels,
                Step::Exact,
            );
            assert!(
                exact >= run.energy * (1.0 - 1e-9) && exact <= run.energy * (1.0 + 1e-9),
                "restart {restart}: exact step {exact}, run ended at {}",
                run.energy
            );
        }
    }

    #[test]
    fn repair_fills_every_free_piece() {
        let mut labels = vec![0, 0, 0, 1, 1];
        let cost = [0.1, 5.0, 0.2, 3.0, 0.0];
        repair_empty(&mut labels, &cost, 0, 4);
        let mut used: Vec<u32> = labels.clone();
        used.sort();
        used.dedup();
        assert_eq!(used, vec![0, 1, 2, 3], "{labels:?}");
        // The worst frames moved: frame 1 (cost 5) and frame 3 (cost 3).
        assert_eq!((labels[1], labels[3]), (2, 3));
    }
}
