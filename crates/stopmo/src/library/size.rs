//! Library size selection: max-error search (Fig. 16), budget allocation, size/error curve
//! (Fig. 8), and the uniform-sampling baseline (Fig. 19).

use serde::Serialize;

use super::error::{LibraryError, Result};
use super::problem::PartProblem;
use super::solver::{PartSolution, SolveOptions};

/// One point of the library size versus error curve (model units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CurvePoint {
    /// Library size (fixed pieces included).
    pub pieces: usize,
    /// StopShop Eq. 10 energy.
    pub energy: f64,
    /// Largest per-frame mean position error.
    pub worst_frame_error: f64,
    /// Mean position error over frames.
    pub mean_error: f64,
}

fn point(p: &PartProblem<'_>, s: &PartSolution, lambda: f64) -> CurvePoint {
    let (_, e) = super::metrics::evaluate(p, &s.pieces, &s.labels, lambda);
    CurvePoint {
        pieces: s.pieces.len(),
        energy: s.energy,
        worst_frame_error: e.worst_frame(),
        mean_error: e.summary(1.0).position_mean,
    }
}

impl PartProblem<'_> {
    /// Smallest library whose worst frame error ([`FrameErrors::worst_frame`], model units)
    /// is at most `max_error`: sizes grow by doubling from the fixed pieces (or 1), then the
    /// bracket is bisected. The error is not exactly monotone in the size (local minima), so
    /// the answer is the smallest size *tried* that meets the bound.
    ///
    /// # Returns
    /// The chosen solution and every evaluated size, sorted by size.
    ///
    /// [`FrameErrors::worst_frame`]: super::FrameErrors::worst_frame
    pub fn solve_max_error(
        &self,
        max_error: f64,
        opts: &SolveOptions,
    ) -> Result<(PartSolution, Vec<CurvePoint>)> {
        max_error_search(self, max_error, opts.lambda, &|d| self.solve(d, opts))
    }

    /// The naive baseline of Section 5: the timeline is cut into `pieces` equal segments,
    /// each segment's middle frame is printed and shown for the whole segment. Fixed pieces
    /// are ignored.
    pub fn uniform(&self, pieces: usize, lambda: f64) -> Result<PartSolution> {
        let n = self.frames();
        if pieces == 0 {
            return Err(LibraryError::ZeroPieces);
        }
        if pieces > n {
            return Err(LibraryError::TooManyPieces {
                part: self.name.clone(),
                pieces,
                frames: n,
            });
        }
        let labels: Vec<u32> = (0..n).map(|f| (f * pieces / n) as u32).collect();
        let lib = (0..pieces)
            .map(|k| {
                let (a, b) = ((k * n).div_ceil(pieces), ((k + 1) * n).div_ceil(pieces));
                self.src.frame((a + b - 1) / 2).into_owned()
            })
            .collect::<Vec<_>>();
        let (energy, _) = super::metrics::evaluate(self, &lib, &labels, lambda);
        Ok(PartSolution {
            pieces: lib,
            labels,
            energy,
            iterations: 0,
            restarts: 0,
            history: vec![energy],
            captured: 1.0,
        })
    }
}

/// Size search behind [`PartProblem::solve_max_error`], for any solver.
pub(crate) fn max_error_search(
    p: &PartProblem<'_>,
    max_error: f64,
    lambda: f64,
    solve: &(dyn Fn(usize) -> Result<PartSolution> + Sync),
) -> Result<(PartSolution, Vec<CurvePoint>)> {
    if !(max_error.is_finite() && max_error >= 0.0) {
        return Err(LibraryError::InvalidParameter(format!(
            "max error must be finite and >= 0, got {max_error}"
        )));
    }
    let cap = p.fixed + p.frames();
    let mut curve = Vec::new();
    let eval = |d: usize, curve: &mut Vec<CurvePoint>| -> Result<(bool, PartSolution)> {
        let s = solve(d)?;
        let pt = point(p, &s, lambda);
        curve.push(pt);
        Ok((pt.worst_frame_error <= max_error, s))
    };
    let mut lo = 0; // largest size known to fail
    let mut d = p.fixed.max(1);
    let (mut hi, mut best) = loop {
        let (ok, s) = eval(d, &mut curve)?;
        if ok || d == cap {
            break (d, s);
        }
        lo = d;
        d = (d * 2).min(cap);
    };
    while hi - lo > 1 && lo > 0 {
        let mid = lo + (hi - lo) / 2;
        let (ok, s) = eval(mid, &mut curve)?;
        if ok {
            (hi, best) = (mid, s);
        } else {
            lo = mid;
        }
    }
    curve.sort_by_key(|p| p.pieces);
    Ok((best, curve))
}

/// Distributes a total budget of pieces over parts by greedy marginal allocation: every part
/// starts at max(fixed, 1) pieces; each further piece goes to the part whose StopShop Eq. 10 energy
/// drops the most by it.
///
/// # Returns
/// Per part: the final solution and every evaluated size.
///
/// # Performance
/// About `budget + parts` solves.
pub fn allocate_budget(
    parts: &[PartProblem<'_>],
    budget: usize,
    opts: &SolveOptions,
) -> Result<Vec<(PartSolution, Vec<CurvePoint>)>> {
    budget_search(parts, budget, opts.lambda, &|i, d| parts[i].solve(d, opts))
}

/// Greedy allocation behind [`allocate_budget`], for any solver (`solve(part, size)`).
pub(crate) fn budget_search(
    parts: &[PartProblem<'_>],
    budget: usize,
    lambda: f64,
    solve: &(dyn Fn(usize, usize) -> Result<PartSolution> + Sync),
) -> Result<Vec<(PartSolution, Vec<CurvePoint>)>> {
    if parts.is_empty() {
        return Err(LibraryError::NoParts);
    }
    let base: Vec<usize> = parts.iter().map(|p| p.fixed.max(1)).collect();
    let minimum: usize = base.iter().sum();
    if budget < minimum {
        return Err(LibraryError::BudgetTooSmall { budget, minimum });
    }
    let mut curves: Vec<Vec<CurvePoint>> = vec![Vec::new(); parts.len()];
    let mut cur = Vec::with_capacity(parts.len());
    let mut next: Vec<Option<PartSolution>> = Vec::with_capacity(parts.len());
    let try_solve = |i: usize, d: usize| -> Result<Option<PartSolution>> {
        if d - parts[i].fixed > parts[i].frames() {
            Ok(None)
        } else {
            solve(i, d).map(Some)
        }
    };
    for (i, p) in parts.iter().enumerate() {
        let s = solve(i, base[i])?;
        curves[i].push(point(p, &s, lambda));
        cur.push(s);
        next.push(try_solve(i, base[i] + 1)?);
    }
    let mut left = budget - minimum;
    while left > 0 {
        let pick = (0..parts.len())
            .filter_map(|i| next[i].as_ref().map(|s| (i, cur[i].energy - s.energy)))
            .fold(None, |b: Option<(usize, f64)>, (i, g)| match b {
                Some((_, bg)) if bg >= g => b,
                _ => Some((i, g)),
            });
        let Some((i, _)) = pick else { break };
        let s = next[i].take().expect("picked part has a next size");
        curves[i].push(point(&parts[i], &s, lambda));
        let d = s.pieces.len();
        cur[i] = s;
        next[i] = try_solve(i, d + 1)?;
        left -= 1;
    }
    Ok(cur.into_iter().zip(curves).collect())
}
