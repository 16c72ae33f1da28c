//! The label step over a few candidate pieces per frame: the early iterations of block
//! coordinate descent with many pieces (docs/stopmo-scale.md, "Candidate label steps").
//!
//! The exact label step ([`super::viterbi`]) sweeps all `pieces²` transitions per frame. While
//! the library is still moving, most of that sweep only confirms what the unary term already
//! says, so these steps run the same dynamic programming over each frame's
//! [`CANDIDATES`] nearest pieces (StopShop Eq. 15) plus the current labels of the frame and its
//! two neighbours. The current labeling is one of the paths searched, so a step never raises
//! StopShop Eq. 10, and block coordinate descent keeps its monotone energy. Once these steps
//! stop improving, the solver goes on with exact steps until those stop too: a restart ends
//! where an exact label step finds nothing better, as before.

use std::ops::Range;

use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};

use super::viterbi::ChainTerms;

/// Nearest pieces (by unary cost) taken per frame, besides the current labels.
pub(crate) const CANDIDATES: usize = 8;
/// Library size from which the solver starts with candidate steps: below it the exact sweep
/// is cheap (and results stay those of exact steps only).
pub(crate) const MIN_PIECES: usize = 64;
/// Candidates per frame at most: the nearest ones and the labels of `f − 1`, `f`, `f + 1`.
const STRIDE: usize = CANDIDATES + 3;

/// Lanes of the dynamic programming's inner loop: [`STRIDE`] rounded up to whole registers.
const DP_LANES: usize = STRIDE.next_multiple_of(4);

/// Frames whose inner products with the pieces are computed at once (one small GEMM whose
/// result stays in cache while the frames' candidates are picked).
const BLOCK: usize = 64;

/// Inputs of [`candidate_label_step`]; all matrices row-major.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CandidateInputs<'a> {
    /// `n × q` frame coordinates.
    pub y: &'a [f64],
    /// `d × q` piece coordinates.
    pub r: &'a [f64],
    /// Coordinates per frame and piece.
    pub q: usize,
    /// Everything else, as the exact step takes it.
    pub terms: ChainTerms<'a>,
}

/// Reusable buffers of [`candidate_label_step`].
#[derive(Debug, Default, Clone)]
pub(crate) struct CandidateWork {
    /// Candidates of each frame, ascending (`STRIDE` slots per frame).
    pieces: Vec<u32>,
    /// How many slots of each frame are used.
    count: Vec<u8>,
    /// `x_f · r_b` per candidate `b` of frame `f`.
    here: Vec<f64>,
    /// `x_{f−1} · r_b` per candidate `b` of frame `f`.
    before: Vec<f64>,
    /// `x_f · r_a` per candidate `a` of frame `f − 1`.
    after: Vec<f64>,
    /// Value function `V_f` per candidate.
    v: Vec<f64>,
    /// Slot of the best predecessor per candidate.
    back: Vec<u8>,
    /// `α` of the previous frame's candidates.
    alpha: Vec<f64>,
    /// Diagonal `G_kk`, contiguous.
    gd: Vec<f64>,
    /// Symmetrized `λG`, as the exact step forms it.
    lg: Vec<f64>,
    /// A block of rows of `X Rᵀ`, and the row before it.
    rows: Vec<f64>,
    /// One frame's unary costs less `‖x_f‖²`.
    keys: Vec<f64>,
}

/// The label step restricted to each frame's candidates.
///
/// `labels` holds the current labeling on entry when `keep_current` is set (its labels join
/// the candidates, so the result's energy is at most the current one), and the new labeling
/// on return; `cost` receives each frame's unary cost as in [`super::viterbi::label_step`].
/// Returns the new labeling's energy (StopShop Eq. 10). With `CANDIDATES ≥ pieces` this is
/// the exact step.
///
/// # Performance
/// `O(n · q · pieces)` for the inner products, in blocks of frames that stay in cache (the
/// `n × pieces` matrix is never stored), `O(n · pieces)` to pick the candidates,
/// `O(n · STRIDE²)` for the dynamic programming; no allocation once `work` is warm.
pub(crate) fn candidate_label_step(
    inp: &CandidateInputs<'_>,
    labels: &mut [u32],
    keep_current: bool,
    cost: &mut [f64],
    work: &mut CandidateWork,
) -> f64 {
    // Compiled once per instruction set (AVX2 on x86-64): the per-frame loops over keys and
    // candidates vectorize; no sum changes order.
    pulp::Arch::new().dispatch(Step {
        inp,
        labels,
        keep_current,
        cost,
        work,
    })
}

/// Arguments of [`candidate_label_step`], as a [`pulp::WithSimd`] operation.
struct Step<'a, 'b> {
    inp: &'a CandidateInputs<'b>,
    labels: &'a mut [u32],
    keep_current: bool,
    cost: &'a mut [f64],
    work: &'a mut CandidateWork,
}

impl pulp::WithSimd for Step<'_, '_> {
    type Output = f64;
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> f64 {
        let Step {
            inp,
            labels,
            keep_current,
            cost,
            work,
        } = self;
        let (d, n) = (inp.terms.d, inp.terms.xx.len());
        work.pieces.resize(n * STRIDE, 0);
        work.count.resize(n, 0);
        work.here.resize(n * STRIDE, 0.0);
        work.before.resize(n * STRIDE, 0.0);
        work.after.resize(n * STRIDE, 0.0);
        work.v.resize(n * STRIDE, 0.0);
        work.back.resize(n * STRIDE, 0);
        work.alpha.resize(STRIDE, 0.0);
        inp.terms.gram_parts(&mut work.gd, &mut work.lg);
        work.keys.resize(d, 0.0);
        work.rows.resize((BLOCK + 1) * d, 0.0);
        let mut total = 0.0;
        for ch in inp.terms.chains {
            if ch.is_empty() {
                continue;
            }
            pick_candidates(inp, ch, labels, keep_current, work);
            total += chain_dp(inp, ch, labels, cost, work);
        }
        total
    }
}

/// Picks every frame of chain `ch`'s candidates and the inner products the dynamic
/// programming needs, a block of frames at a time.
#[inline(always)]
fn pick_candidates(
    inp: &CandidateInputs<'_>,
    ch: &Range<usize>,
    labels: &[u32],
    keep_current: bool,
    work: &mut CandidateWork,
) {
    let (d, q) = (inp.terms.d, inp.q);
    let r = MatRef::from_row_major_slice(inp.r, d, q);
    let mut f0 = ch.start;
    while f0 < ch.end {
        let k = BLOCK.min(ch.end - f0);
        // Row 0 holds the frame before the block (the last row of the previous block).
        if f0 > ch.start {
            work.rows.copy_within(BLOCK * d..(BLOCK + 1) * d, 0);
        }
        matmul(
            MatMut::from_row_major_slice_mut(&mut work.rows[d..(k + 1) * d], k, d),
            Accum::Replace,
            MatRef::from_row_major_slice(&inp.y[f0 * q..(f0 + k) * q], k, q),
            r.transpose(),
            1.0,
            Par::Seq,
        );
        for f in f0..f0 + k {
            let row = f - f0 + 1;
            frame_candidates(inp, ch, f, row, labels, keep_current, work);
        }
        f0 += k;
    }
}

/// Frame `f`'s candidates, whose inner products are row `row` of `work.rows` (the previous
/// frame's are the row before).
#[inline(always)]
fn frame_candidates(
    inp: &CandidateInputs<'_>,
    ch: &Range<usize>,
    f: usize,
    row: usize,
    labels: &[u32],
    keep_current: bool,
    work: &mut CandidateWork,
) {
    let d = inp.terms.d;
    let pf = &work.rows[row * d..(row + 1) * d];
    // ‖x_f‖² is the same for every piece: the order is that of the unary cost.
    for ((k, &g), &p) in work.keys.iter_mut().zip(&work.gd).zip(pf) {
        *k = g - 2.0 * p;
    }
    let slots = &mut work.pieces[f * STRIDE..(f + 1) * STRIDE];
    // The previous step's candidates bound the new nearest ones: among any k distinct pieces,
    // the k-th smallest key is no smaller than the k-th smallest of all.
    let kept = if keep_current {
        work.count[f] as usize
    } else {
        0
    };
    let bound = kth_smallest(&work.keys, &slots[..kept], CANDIDATES.min(d));
    let mut c = nearest(&work.keys, bound, &mut slots[..CANDIDATES]);
    if keep_current {
        let around = f.saturating_sub(1).max(ch.start)..(f + 2).min(ch.end);
        for l in labels[around].iter().copied() {
            if !slots[..c].contains(&l) {
                slots[c] = l;
                c += 1;
            }
        }
    }
    slots[..c].sort_unstable();
    work.count[f] = c as u8;
    let at = f * STRIDE;
    for (j, &b) in slots[..c].iter().enumerate() {
        work.here[at + j] = pf[b as usize];
    }
    if f > ch.start {
        let pp = &work.rows[(row - 1) * d..row * d];
        for (j, &b) in slots[..c].iter().enumerate() {
            work.before[at + j] = pp[b as usize];
        }
        let prev = (f - 1) * STRIDE;
        for i in 0..work.count[f - 1] as usize {
            work.after[at + i] = pf[work.pieces[prev + i] as usize];
        }
    }
}

/// The dynamic programming over chain `ch`'s candidates; writes its labels and unary costs
/// and returns its energy.
#[inline(always)]
fn chain_dp(
    inp: &CandidateInputs<'_>,
    ch: &Range<usize>,
    labels: &mut [u32],
    cost: &mut [f64],
    work: &mut CandidateWork,
) -> f64 {
    let d = inp.terms.d;
    let half = 0.5 * inp.terms.lambda;
    let gd = &work.gd[..];
    for f in ch.clone() {
        let (xf, at) = (inp.terms.xx[f], f * STRIDE);
        let cf = work.count[f] as usize;
        if f == ch.start {
            for j in 0..cf {
                let b = work.pieces[at + j] as usize;
                work.v[at + j] = xf - 2.0 * work.here[at + j] + gd[b];
            }
            continue;
        }
        let prev = (f - 1) * STRIDE;
        let cp = work.count[f - 1] as usize;
        // α of the previous frame's candidates, as the exact step forms it.
        for i in 0..cp {
            let a = work.pieces[prev + i] as usize;
            work.alpha[i] = work.v[prev + i]
                + half * (gd[a] + 2.0 * (work.after[at + i] - work.here[prev + i]));
        }
        let df = inp.terms.dxx[f];
        // Every candidate `b` of frame f runs its own chain `if v < best` over the previous
        // frame's candidates in order (the first minimum, as the exact step takes it); the
        // chains go side by side, one lane per `b`. λG is symmetrized: row `a` holds column `a`.
        // Lanes past the frame's candidates read piece 0 and are never used.
        let mut idx = [0usize; DP_LANES];
        for (o, &b) in idx.iter_mut().zip(&work.pieces[at..at + cf]) {
            *o = b as usize;
        }
        let (mut best, mut arg) = ([f64::INFINITY; DP_LANES], [0u64; DP_LANES]);
        for i in 0..cp {
            let a = work.pieces[prev + i] as usize;
            let (al, lg) = (work.alpha[i], &work.lg[a * d..(a + 1) * d]);
            let v: [f64; DP_LANES] = std::array::from_fn(|j| al - lg[idx[j]]);
            for j in 0..DP_LANES {
                let lower = v[j] < best[j];
                best[j] = if lower { v[j] } else { best[j] };
                arg[j] = if lower { i as u64 } else { arg[j] };
            }
        }
        for j in 0..cf {
            let b = idx[j];
            let (gb, pb) = (gd[b], work.here[at + j]);
            work.v[at + j] = (xf - 2.0 * pb + gb)
                + half * (df + gb - 2.0 * (pb - work.before[at + j]))
                + best[j];
            work.back[at + j] = arg[j] as u8;
        }
    }
    let last = ch.end - 1;
    let (mut best, mut slot) = (f64::INFINITY, 0);
    for j in 0..work.count[last] as usize {
        let v = work.v[last * STRIDE + j];
        if v < best {
            (best, slot) = (v, j);
        }
    }
    for f in ch.clone().rev() {
        let at = f * STRIDE + slot;
        let b = work.pieces[at];
        labels[f] = b;
        cost[f] = inp.terms.xx[f] - 2.0 * work.here[at] + gd[b as usize];
        slot = work.back[at] as usize;
    }
    best
}

/// Writes the pieces of the `out.len()` smallest `keys` into `out`, smallest first (ties to
/// the lower piece), and returns how many there are (`min(out.len(), pieces)`, fewer when
/// keys are NaN, at least 1). With a `bound` no smaller than the `out.len()`-th smallest key,
/// only the keys up to it are looked at; the result is the same.
#[inline(always)]
fn nearest(keys: &[f64], bound: Option<f64>, out: &mut [u32]) -> usize {
    if let Some(t) = bound {
        let c = smallest(keys, t, out);
        if c == out.len() {
            return c;
        }
    }
    let c = smallest(keys, f64::INFINITY, out);
    if c == 0 {
        out[0] = 0;
        return 1;
    }
    c
}

/// The `k`-th smallest of the keys of `pieces` (distinct; the first [`STRIDE`] of them), NaN
/// keys left out; `None` when fewer than `k` are left.
#[inline(always)]
fn kth_smallest(keys: &[f64], pieces: &[u32], k: usize) -> Option<f64> {
    let mut known = [0.0f64; STRIDE];
    let mut c = 0;
    for &b in pieces.iter().take(STRIDE) {
        let key = keys[b as usize];
        if !key.is_nan() {
            known[c] = key;
            c += 1;
        }
    }
    if k == 0 || c < k {
        return None;
    }
    let known = &mut known[..c];
    known.sort_unstable_by(f64::total_cmp);
    Some(known[k - 1])
}

/// The pieces of the `out.len()` smallest keys up to `limit` (NaN never), smallest first, ties
/// to the lower piece; returns how many there are. Each new key is inserted after the equal
/// ones already kept, which is a stable sort's order. One comparison per key with the current
/// limit (the k-th key kept so far, once there are k) passes over most keys: with the
/// previous candidates' bound, about 9 of 200 keys are looked at further on Table-1's case.
#[inline(always)]
fn smallest(keys: &[f64], limit: f64, out: &mut [u32]) -> usize {
    let k = out.len();
    let mut best = [f64::INFINITY; CANDIDATES];
    let best = &mut best[..k];
    let mut c = 0;
    let mut lim = limit;
    for (b, &key) in keys.iter().enumerate() {
        // NaN keys are never candidates, nor are keys no better than the k-th (a key equal
        // to it comes after it).
        let within = key <= lim;
        if !within || (c == k && key >= best[k - 1]) {
            continue;
        }
        let mut i = c.min(k - 1);
        while i > 0 && key < best[i - 1] {
            best[i] = best[i - 1];
            out[i] = out[i - 1];
            i -= 1;
        }
        best[i] = key;
        out[i] = b as u32;
        c = (c + 1).min(k);
        if c == k {
            lim = lim.min(best[k - 1]);
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::super::viterbi::tests::{case, Case};
    use super::super::viterbi::{label_step, LabelInputs, ViterbiWork};
    use super::*;

    fn inputs<'a>(
        c: &'a Case,
        chains: &'a [Range<usize>],
        d: usize,
        lambda: f64,
    ) -> (LabelInputs<'a>, CandidateInputs<'a>) {
        let terms = ChainTerms {
            g: &c.g,
            xx: &c.xx,
            dxx: &c.dxx,
            chains,
            lambda,
            d,
        };
        let exact = LabelInputs { p: &c.p, terms };
        let ours = CandidateInputs {
            y: &c.x,
            r: &c.r,
            q: c.dim,
            terms,
        };
        (exact, ours)
    }

    /// With at least as many candidates as pieces the step is the exact one, over chains
    /// longer than a block of frames.
    #[test]
    fn all_pieces_as_candidates_is_the_exact_step() {
        for (seed, (n, d, lambda)) in [(140, 3, 2.0), (200, 8, 0.7), (70, 5, 10.0)]
            .into_iter()
            .enumerate()
        {
            let c = case(n, d, 4, seed as u64);
            for chains in [
                std::iter::once(0..n).collect::<Vec<_>>(),
                vec![0..7, 7..n - 1, n - 1..n],
            ] {
                let (exact_inp, inp) = inputs(&c, &chains, d, lambda);
                let (mut exact, mut ours) = (vec![0u32; n], vec![0u32; n]);
                let (mut ce, mut co) = (vec![0.0; n], vec![0.0; n]);
                let e = label_step(&exact_inp, &mut exact, &mut ce, &mut ViterbiWork::default());
                let mut work = CandidateWork::default();
                let o = candidate_label_step(&inp, &mut ours, false, &mut co, &mut work);
                assert!((e - o).abs() <= 1e-9 * e.abs(), "seed {seed}: {e} vs {o}");
                assert_eq!(exact, ours, "seed {seed}");
                // Searched again from its own labels (the bounded pick), the same.
                let again = candidate_label_step(&inp, &mut ours, true, &mut co, &mut work);
                assert_eq!(exact, ours, "seed {seed}");
                assert!((e - again).abs() <= 1e-9 * e.abs());
            }
        }
    }

    /// Many pieces: the step's energy is its labeling's, never above the current labeling's
    /// (which it searches), and never below the exact optimum.
    #[test]
    fn candidate_steps_never_raise_the_energy() {
        let (n, d, lambda) = (300, 90, 2.0);
        let c = case(n, d, 6, 7);
        let chains = vec![0..120, 120..n];
        let (exact_inp, inp) = inputs(&c, &chains, d, lambda);
        let mut exact = vec![0u32; n];
        let optimum = label_step(
            &exact_inp,
            &mut exact,
            &mut vec![0.0; n],
            &mut ViterbiWork::default(),
        );
        let mut rng = anim::SplitMix64::new(3, 1);
        let mut labels: Vec<u32> = (0..n).map(|_| rng.below(d) as u32).collect();
        let mut work = CandidateWork::default();
        let mut before = exact_inp.energy(&labels);
        for step in 0..3 {
            let e = candidate_label_step(&inp, &mut labels, step > 0, &mut vec![0.0; n], &mut work);
            let again = exact_inp.energy(&labels);
            assert!((again - e).abs() <= 1e-9 * e.abs(), "{again} vs {e}");
            if step > 0 {
                assert!(e <= before * (1.0 + 1e-12), "{e} after {before}");
            }
            assert!(
                e >= optimum * (1.0 - 1e-12),
                "{e} below the optimum {optimum}"
            );
            before = e;
        }
        // The exact optimum is a fixed point: searched again with its own labels, kept.
        let mut kept = exact.clone();
        let e = candidate_label_step(&inp, &mut kept, true, &mut vec![0.0; n], &mut work);
        assert!((e - optimum).abs() <= 1e-9 * optimum.abs());
        assert_eq!(kept, exact);
    }

    /// The nearest pieces of [`nearest`] are those of a stable sort of the keys whatever the
    /// bound (a valid one, a larger one, one too small, none), with ties, signed zeros and NaN
    /// keys; [`kth_smallest`] gives a valid bound from any distinct pieces.
    #[test]
    fn nearest_pieces_are_those_of_a_stable_sort() {
        let mut rng = anim::SplitMix64::new(11, 4);
        for trial in 0..300 {
            let d = 1 + rng.below(70);
            let keys: Vec<f64> = (0..d)
                .map(|_| match rng.below(12) {
                    0 => f64::NAN,
                    1 => -0.0,
                    2 => 0.0,
                    _ => (rng.below(9) as f64 - 4.0) * 0.5,
                })
                .collect();
            let mut sorted: Vec<(f64, u32)> = keys
                .iter()
                .enumerate()
                .filter(|(_, k)| !k.is_nan())
                .map(|(b, &k)| (k, b as u32))
                .collect();
            sorted.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
            let mut want: Vec<u32> = sorted.iter().take(CANDIDATES).map(|p| p.1).collect();
            if want.is_empty() {
                want.push(0);
            }
            let pieces: Vec<u32> = (0..d as u32).filter(|b| b % 3 != trial % 3).collect();
            let bounds = [
                None,
                sorted.get(CANDIDATES - 1).map(|p| p.0),
                sorted.last().map(|p| p.0 + 1.0),
                sorted.first().map(|p| p.0 - 1.0),
                kth_smallest(&keys, &pieces, CANDIDATES.min(d)),
            ];
            for bound in bounds {
                let mut out = [u32::MAX; CANDIDATES];
                let c = nearest(&keys, bound, &mut out);
                assert_eq!(
                    &out[..c],
                    &want[..],
                    "trial {trial}, bound {bound:?}: {keys:?}"
                );
            }
            if let Some(t) = kth_smallest(&keys, &pieces, CANDIDATES.min(d)) {
                let kth = sorted[CANDIDATES.min(d) - 1].0;
                assert!(
                    t >= kth,
                    "trial {trial}: bound {t} below the k-th key {kth}"
                );
            }
        }
    }
}
