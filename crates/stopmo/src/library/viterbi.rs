//! Exact label step: dynamic programming (Viterbi) along the frame chain.
//!
//! With the library fixed, StopShop Eq. 10 splits into unary terms (StopShop Eq. 15) and pairwise terms between
//! consecutive frames of one clip (StopShop Eq. 16). The frame graph is a set of chains (cuts split it),
//! so the minimum over all `dⁿ` labelings is found exactly by dynamic programming; this is
//! never worse than the α-expansion the paper uses.
//!
//! Everything comes from three Gram-type matrices (row-major): `P = X Rᵀ` (frames × pieces),
//! `G = R Rᵀ` (pieces × pieces) and the frame norms. With `D_f(k) = P(f,k) − P(f−1,k)`
//! (= `Δx_f · r_k`) and `c_f = ‖Δx_f‖²`, the pairwise cost of labels `a → b` at frame `f` is
//!
//! `(λ/2)‖Δx_f − (r_b − r_a)‖² = (λ/2)[c_f + G_bb − 2D_f(b)] + (λ/2)[G_aa + 2D_f(a)] − λ G_ab`,
//!
//! so the recursion `V_f(b) = U_f(b) + (λ/2)[c_f + G_bb − 2D_f(b)] + min_a (α_a − λ G_ab)` with
//! `α_a = V_{f−1}(a) + (λ/2)[G_aa + 2D_f(a)]` needs one `d × d` min-plus sweep per frame over
//! contiguous rows of `G` and nothing else.

use std::ops::Range;

/// Inputs of the label step; all matrices row-major.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LabelInputs<'a> {
    /// `n × d` inner products `x_f · r_k`.
    pub p: &'a [f64],
    /// Everything else, shared with the candidate steps.
    pub terms: ChainTerms<'a>,
}

/// What every label step takes besides the frames' inner products with the pieces.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ChainTerms<'a> {
    /// `d × d` Gram matrix `r_a · r_b`.
    pub g: &'a [f64],
    /// `‖x_f‖²` per frame.
    pub xx: &'a [f64],
    /// `‖x_f − x_{f−1}‖²` per frame (unused at chain starts).
    pub dxx: &'a [f64],
    /// Clips (consecutive frames linked by the velocity term).
    pub chains: &'a [Range<usize>],
    /// Velocity weight λ.
    pub lambda: f64,
    /// Number of pieces.
    pub d: usize,
}

impl ChainTerms<'_> {
    /// The diagonal `G_kk` into `gd` (contiguous, so that per-frame loops vectorize) and
    /// `λG` symmetrized into `lg`, so that a sweep along rows and a backtrack along columns
    /// agree exactly.
    pub(crate) fn gram_parts(&self, gd: &mut Vec<f64>, lg: &mut Vec<f64>) {
        let (d, g) = (self.d, self.g);
        gd.clear();
        gd.extend((0..d).map(|k| g[k * d + k]));
        lg.resize(d * d, 0.0);
        for a in 0..d {
            for b in 0..d {
                lg[a * d + b] = 0.5 * self.lambda * (g[a * d + b] + g[b * d + a]);
            }
        }
    }
}

impl LabelInputs<'_> {
    #[inline]
    fn unary(&self, f: usize, k: usize) -> f64 {
        self.terms.xx[f] - 2.0 * self.p[f * self.terms.d + k] + self.terms.g[k * self.terms.d + k]
    }

    #[cfg(test)]
    fn delta(&self, f: usize, k: usize) -> f64 {
        self.p[f * self.terms.d + k] - self.p[(f - 1) * self.terms.d + k]
    }

    /// Energy (StopShop Eq. 10) of a labeling, from the same Gram matrices.
    #[cfg(test)]
    pub(crate) fn energy(&self, labels: &[u32]) -> f64 {
        let mut e = 0.0;
        for ch in self.terms.chains {
            for f in ch.clone() {
                let b = labels[f] as usize;
                e += self.unary(f, b);
                if f > ch.start {
                    let a = labels[f - 1] as usize;
                    let (gaa, gbb, gab) = (
                        self.terms.g[a * self.terms.d + a],
                        self.terms.g[b * self.terms.d + b],
                        self.terms.g[a * self.terms.d + b],
                    );
                    let pair = self.terms.dxx[f] - 2.0 * self.delta(f, b)
                        + 2.0 * self.delta(f, a)
                        + gaa
                        + gbb
                        - 2.0 * gab;
                    e += 0.5 * self.terms.lambda * pair;
                }
            }
        }
        e
    }
}

/// Reusable buffers of the label step.
#[derive(Debug, Default, Clone)]
pub(crate) struct ViterbiWork {
    /// Per frame: `α_{f+1}` once the next frame is reached (what the backtrack needs), the
    /// value function `V_f` on a chain's last frame.
    v: Vec<f64>,
    m: Vec<f64>,
    lg: Vec<f64>,
    /// Diagonal `G_kk`, contiguous so that the per-frame loops vectorize.
    gd: Vec<f64>,
}

/// Lanes of the register-blocked min-plus sweep (4 AVX2 or 2 AVX-512 registers of f64).
const LANES: usize = 16;

/// `m[b] = min_a (alpha[a] − lg[a·d + b])` for all `b`, register-blocked: a block of output
/// columns stays in registers while the sweep streams contiguous pieces of the rows of the
/// symmetric `λG`, so each Gram entry is loaded once and nothing is stored in the inner loop.
///
/// On CPUs with AVX-512 the hand-written kernel ([`avx512::min_plus`]) runs; elsewhere the
/// portable sweep, compiled once per instruction set by [`pulp::Arch`] (AVX2 on x86-64).
/// Both compute every column as the same sequence `acc = if v < acc { v } else { acc }` over
/// `a` in order (only `−` and `min`, no reassociation), so the result is bit-identical.
fn min_plus(m: &mut [f64], alpha: &[f64], lg: &[f64], d: usize) {
    #[cfg(target_arch = "x86_64")]
    if d >= avx512::LANES && avx512::available() {
        avx512::min_plus_checked(m, alpha, lg, d);
        return;
    }
    min_plus_portable(m, alpha, lg, d);
}

/// The portable sweep of [`min_plus`] (`LANES` columns per block, 4-wide and scalar tails).
fn min_plus_portable(m: &mut [f64], alpha: &[f64], lg: &[f64], d: usize) {
    pulp::Arch::new().dispatch(MinPlus { m, alpha, lg, d });
}

/// Arguments of [`min_plus`], as a [`pulp::WithSimd`] operation.
struct MinPlus<'a> {
    m: &'a mut [f64],
    alpha: &'a [f64],
    lg: &'a [f64],
    d: usize,
}

impl pulp::WithSimd for MinPlus<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> Self::Output {
        let MinPlus { m, alpha, lg, d } = self;
        let mut b0 = 0;
        while b0 + LANES <= d {
            min_plus_block::<LANES>(m, alpha, lg, d, b0);
            b0 += LANES;
        }
        while b0 + 4 <= d {
            min_plus_block::<4>(m, alpha, lg, d, b0);
            b0 += 4;
        }
        while b0 < d {
            min_plus_block::<1>(m, alpha, lg, d, b0);
            b0 += 1;
        }
    }
}

/// Columns `b0..b0 + W` of the min-plus product, `W` accumulators in registers.
#[inline(always)]
fn min_plus_block<const W: usize>(m: &mut [f64], alpha: &[f64], lg: &[f64], d: usize, b0: usize) {
    let mut acc = [f64::INFINITY; W];
    for (a, &al) in alpha.iter().enumerate() {
        let row: &[f64; W] = lg[a * d + b0..a * d + b0 + W]
            .try_into()
            .expect("W-wide row block");
        for l in 0..W {
            let v = al - row[l];
            acc[l] = if v < acc[l] { v } else { acc[l] };
        }
    }
    m[b0..b0 + W].copy_from_slice(&acc);
}

/// The min-plus sweep with AVX-512 intrinsics. AVX-512 doubles the f64 lanes per
/// register and has 32 registers: up to 64 output columns share each broadcast `α_a`, which
/// is what makes it faster than the AVX2 sweep on the same core (not a wider FP port).
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx512 {
    use std::arch::x86_64::{
        __m512d, _mm512_loadu_pd, _mm512_min_pd, _mm512_set1_pd, _mm512_storeu_pd, _mm512_sub_pd,
    };

    /// f64 lanes of one register.
    pub(super) const LANES: usize = 8;
    /// Accumulator registers per block at most (of 32; the rest hold `α_a` and the loads).
    const MAX_REGS: usize = 8;

    /// Whether this CPU runs the kernel (checked once, then a cached flag).
    pub(super) fn available() -> bool {
        std::arch::is_x86_feature_detected!("avx512f")
    }

    /// [`super::min_plus`] on AVX-512; `d ≥ LANES` and the slices hold `d`, `d`, `d²` values.
    ///
    /// # Panics
    /// If the CPU lacks AVX-512F (callers check [`available`]) or a slice is too short.
    pub(super) fn min_plus_checked(m: &mut [f64], alpha: &[f64], lg: &[f64], d: usize) {
        assert!(available(), "AVX-512F kernel on a CPU without it");
        // SAFETY: the CPU supports AVX-512F (asserted just above), the only requirement of
        // a `#[target_feature(enable = "avx512f")]` function.
        unsafe { min_plus(m, alpha, lg, d) }
    }

    /// Columns are covered by registers of 8 starting at `8j`, the last one at `d − 8` when
    /// `d` is not a multiple of 8 (its overlap recomputes equal values); registers are split
    /// into as few blocks of at most [`MAX_REGS`] as possible, of nearly equal sizes, so
    /// that every block has enough independent `min` chains to hide their latency.
    #[target_feature(enable = "avx512f")]
    fn min_plus(m: &mut [f64], alpha: &[f64], lg: &[f64], d: usize) {
        assert!(d >= LANES && m.len() >= d && alpha.len() >= d && lg.len() >= d * d);
        let regs = d.div_ceil(LANES);
        let blocks = regs.div_ceil(MAX_REGS);
        let (base, extra) = (regs / blocks, regs % blocks);
        let mut r0 = 0;
        for k in 0..blocks {
            let k_regs = base + usize::from(k < extra);
            match k_regs {
                1 => block::<1>(m, alpha, lg, d, r0),
                2 => block::<2>(m, alpha, lg, d, r0),
                3 => block::<3>(m, alpha, lg, d, r0),
                4 => block::<4>(m, alpha, lg, d, r0),
                5 => block::<5>(m, alpha, lg, d, r0),
                6 => block::<6>(m, alpha, lg, d, r0),
                7 => block::<7>(m, alpha, lg, d, r0),
                _ => block::<MAX_REGS>(m, alpha, lg, d, r0),
            }
            r0 += k_regs;
        }
    }

    /// Registers `r0..r0 + K` of the sweep: `K` accumulators of 8 columns each.
    #[target_feature(enable = "avx512f")]
    #[inline]
    fn block<const K: usize>(m: &mut [f64], alpha: &[f64], lg: &[f64], d: usize, r0: usize) {
        let col: [usize; K] = std::array::from_fn(|l| (LANES * (r0 + l)).min(d - LANES));
        let mut acc: [__m512d; K] = [_mm512_set1_pd(f64::INFINITY); K];
        for (row, &al) in lg.chunks_exact(d).zip(&alpha[..d]) {
            let al = _mm512_set1_pd(al);
            for l in 0..K {
                // SAFETY: `col[l] + LANES ≤ d = row.len()`: the 8 loaded values are in `row`.
                let g = unsafe { _mm512_loadu_pd(row.as_ptr().add(col[l])) };
                // min(v, acc) is `if v < acc { v } else { acc }`, as in the portable sweep.
                acc[l] = _mm512_min_pd(_mm512_sub_pd(al, g), acc[l]);
            }
        }
        let out = &mut m[..d];
        for l in 0..K {
            // SAFETY: `col[l] + LANES ≤ d = out.len()`: the 8 stored values are in `out`.
            unsafe { _mm512_storeu_pd(out.as_mut_ptr().add(col[l]), acc[l]) };
        }
    }
}

/// Solves the label step exactly.
///
/// # Arguments
/// * `inp` — Gram matrices, chains and λ;
/// * `labels` — output, one label per frame;
/// * `cost` — output, the unary cost (StopShop Eq. 15) of each frame's chosen label (for empty-piece
///   repair);
/// * `work` — reusable buffers.
///
/// # Returns
/// The energy E(R, ℓ) of StopShop Eq. 10 (with the optimal ℓ).
///
/// # Performance
/// `O(n · d²)` flops in a vectorized min-plus sweep (one pass over `λG` per frame) (`O(n · d)` when λ = 0), `O(n · d)`
/// memory; no allocation once `work` is warm.
pub(crate) fn label_step(
    inp: &LabelInputs<'_>,
    labels: &mut [u32],
    cost: &mut [f64],
    work: &mut ViterbiWork,
) -> f64 {
    let d = inp.terms.d;
    let n = inp.terms.xx.len();
    let half = 0.5 * inp.terms.lambda;
    work.v.resize(n * d, 0.0);
    work.m.resize(d, 0.0);
    inp.terms.gram_parts(&mut work.gd, &mut work.lg);
    let gd = &work.gd[..];
    let mut total = 0.0;
    for ch in inp.terms.chains {
        if ch.is_empty() {
            continue;
        }
        let (xs, ps) = (
            inp.terms.xx[ch.start],
            &inp.p[ch.start * d..(ch.start + 1) * d],
        );
        for ((v, &p), &g) in work.v[ch.start * d..(ch.start + 1) * d]
            .iter_mut()
            .zip(ps)
            .zip(gd)
        {
            *v = xs - 2.0 * p + g;
        }
        for f in ch.start + 1..ch.end {
            let (prev, cur) = work.v.split_at_mut(f * d);
            // V_{f−1} becomes α_f in place: the backtrack reads it back bit for bit.
            let alpha = &mut prev[(f - 1) * d..];
            let cur = &mut cur[..d];
            let (pp, pf) = (&inp.p[(f - 1) * d..f * d], &inp.p[f * d..(f + 1) * d]);
            for (((al, &g), &a1), &a0) in alpha.iter_mut().zip(gd).zip(pf).zip(pp) {
                *al += half * (g + 2.0 * (a1 - a0));
            }
            // m(b) = min_a (α_a − λ G_ab), swept row by row of λG (λ = 0: one minimum).
            if inp.terms.lambda == 0.0 {
                let flat = alpha.iter().copied().fold(f64::INFINITY, f64::min);
                work.m.fill(flat);
            } else {
                min_plus(&mut work.m, alpha, &work.lg, d);
            }
            let (xf, df) = (inp.terms.xx[f], inp.terms.dxx[f]);
            for ((((c, &g), &b1), &b0), &mb) in cur.iter_mut().zip(gd).zip(pf).zip(pp).zip(&work.m)
            {
                *c = (xf - 2.0 * b1 + g) + half * (df + g - 2.0 * (b1 - b0)) + mb;
            }
        }
        // Backtrack: the last label minimizes V, each earlier one re-derives its argmin.
        let last = ch.end - 1;
        let (best, arg) = arg_min(&work.v[last * d..(last + 1) * d]);
        total += best;
        labels[last] = arg as u32;
        for f in (ch.start + 1..ch.end).rev() {
            let b = labels[f] as usize;
            let alpha = &work.v[(f - 1) * d..f * d];
            for ((m, &al), &l) in work
                .m
                .iter_mut()
                .zip(alpha)
                .zip(&work.lg[b * d..(b + 1) * d])
            {
                *m = al - l;
            }
            labels[f - 1] = arg_min(&work.m).1 as u32;
        }
        for f in ch.clone() {
            cost[f] = inp.unary(f, labels[f] as usize);
        }
    }
    total
}

/// The smallest value and its first index (+∞ and index 0 when every value is NaN or +∞),
/// as a scan keeping the first strictly smaller value would give; the minimum is taken in
/// lanes so that it vectorizes.
fn arg_min(values: &[f64]) -> (f64, usize) {
    const W: usize = 8;
    let mut acc = [f64::INFINITY; W];
    let chunks = values.chunks_exact(W);
    let rest = chunks.remainder();
    for c in chunks {
        for l in 0..W {
            acc[l] = if c[l] < acc[l] { c[l] } else { acc[l] };
        }
    }
    let mut best = f64::INFINITY;
    for &v in acc.iter().chain(rest) {
        best = if v < best { v } else { best };
    }
    let arg = if best < f64::INFINITY {
        values.iter().position(|&v| v == best).unwrap_or(0)
    } else {
        0
    };
    (best, arg)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use anim::SplitMix64;

    /// Gram matrices of random frames and pieces.
    pub(crate) struct Case {
        /// Frames, `n × dim`.
        pub(crate) x: Vec<f64>,
        /// Pieces, `d × dim`.
        pub(crate) r: Vec<f64>,
        pub(crate) dim: usize,
        pub(crate) p: Vec<f64>,
        pub(crate) g: Vec<f64>,
        pub(crate) xx: Vec<f64>,
        pub(crate) dxx: Vec<f64>,
    }

    /// Random frames and pieces in `dim` dimensions, with their Gram matrices.
    pub(crate) fn case(n: usize, d: usize, dim: usize, seed: u64) -> Case {
        let mut rng = SplitMix64::new(seed, 9);
        let x: Vec<f64> = (0..n * dim).map(|_| rng.normal()).collect();
        let r: Vec<f64> = (0..d * dim).map(|_| rng.normal()).collect();
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| a * b).sum::<f64>();
        let row = |m: &[f64], i: usize| m[i * dim..(i + 1) * dim].to_vec();
        let mut p = vec![0.0; n * d];
        for f in 0..n {
            for k in 0..d {
                p[f * d + k] = dot(&row(&x, f), &row(&r, k));
            }
        }
        let mut g = vec![0.0; d * d];
        for a in 0..d {
            for b in 0..d {
                g[a * d + b] = dot(&row(&r, a), &row(&r, b));
            }
        }
        let xx = (0..n).map(|f| dot(&row(&x, f), &row(&x, f))).collect();
        let dxx = (0..n)
            .map(|f| {
                if f == 0 {
                    return 0.0;
                }
                let dv: Vec<f64> = row(&x, f)
                    .iter()
                    .zip(row(&x, f - 1))
                    .map(|(a, b)| a - b)
                    .collect();
                dot(&dv, &dv)
            })
            .collect();
        Case {
            x,
            r,
            dim,
            p,
            g,
            xx,
            dxx,
        }
    }

    fn brute_force(inp: &LabelInputs<'_>, n: usize) -> f64 {
        let total = inp.terms.d.pow(n as u32);
        let mut labels = vec![0u32; n];
        let mut best = f64::INFINITY;
        for code in 0..total {
            let mut c = code;
            for l in labels.iter_mut() {
                *l = (c % inp.terms.d) as u32;
                c /= inp.terms.d;
            }
            best = best.min(inp.energy(&labels));
        }
        best
    }

    /// A min-plus sweep: `m`, `alpha`, `lg`, `d` as [`min_plus`] takes them.
    type Sweep = fn(&mut [f64], &[f64], &[f64], usize);

    /// The naive double loop, with the sweep's `min` (the first of equal values is kept).
    fn naive_min_plus(alpha: &[f64], lg: &[f64], d: usize, b: usize) -> f64 {
        (0..d)
            .map(|a| alpha[a] - lg[a * d + b])
            .fold(f64::INFINITY, |acc, v| if v < acc { v } else { acc })
    }

    /// The blocked sweeps equal the naive double loop bit for bit for every block split
    /// (the portable sweep's 16-wide, 4-wide and scalar tails; the AVX-512 kernel's blocks
    /// of 1–8 registers and its overlapping last register), including Table 1's 200 labels,
    /// on random values and on ties of signed zeros, infinities and NaNs. The AVX-512 kernel
    /// is called directly wherever the CPU has it (and `min_plus` dispatches to it).
    #[test]
    fn min_plus_matches_naive_sweep() {
        let mut rng = SplitMix64::new(11, 3);
        let sizes = [
            1, 3, 4, 7, 8, 9, 15, 16, 17, 37, 63, 64, 65, 127, 129, 199, 200, 201,
        ];
        for (d, special) in sizes.iter().flat_map(|&d| [(d, false), (d, true)]) {
            let mut value = || {
                if !special {
                    return rng.normal();
                }
                match rng.below(8) {
                    0 => 0.0,
                    1 => -0.0,
                    2 => f64::INFINITY,
                    3 => f64::NEG_INFINITY,
                    4 => f64::NAN,
                    _ => (rng.below(3) as f64) - 1.0,
                }
            };
            let alpha: Vec<f64> = (0..d).map(|_| value()).collect();
            let lg: Vec<f64> = (0..d * d).map(|_| value()).collect();
            let mut paths: Vec<(&str, Sweep)> =
                vec![("dispatched", min_plus), ("portable", min_plus_portable)];
            #[cfg(target_arch = "x86_64")]
            if d >= avx512::LANES && avx512::available() {
                paths.push(("avx512", avx512::min_plus_checked));
            }
            for (name, path) in paths {
                let mut m = vec![0.0; d];
                path(&mut m, &alpha, &lg, d);
                for b in 0..d {
                    let naive = naive_min_plus(&alpha, &lg, d, b);
                    assert_eq!(
                        m[b].to_bits(),
                        naive.to_bits(),
                        "{name}: d {d}, special {special}, column {b}"
                    );
                }
            }
        }
    }

    #[test]
    fn viterbi_matches_brute_force() {
        for (seed, (n, d, lambda)) in [
            (6, 3, 2.0),
            (5, 4, 0.7),
            (7, 2, 10.0),
            (6, 3, 0.0),
            (4, 5, 3.0),
            (3, 9, 2.0),
            (4, 11, 1.0),
        ]
        .into_iter()
        .enumerate()
        {
            let c = case(n, d, 4, seed as u64);
            for chains in [std::iter::once(0..n).collect::<Vec<_>>(), vec![0..2, 2..n]] {
                let inp = LabelInputs {
                    p: &c.p,
                    terms: ChainTerms {
                        g: &c.g,
                        xx: &c.xx,
                        dxx: &c.dxx,
                        chains: &chains,
                        lambda,
                        d,
                    },
                };
                let mut labels = vec![0u32; n];
                let mut cost = vec![0.0; n];
                let e = label_step(&inp, &mut labels, &mut cost, &mut ViterbiWork::default());
                let brute = brute_force(&inp, n);
                assert!(
                    (e - brute).abs() < 1e-9 * brute.abs().max(1.0),
                    "dp {e} vs brute {brute}"
                );
                let again = inp.energy(&labels);
                assert!(
                    (again - e).abs() < 1e-9 * e.abs().max(1.0),
                    "labels give {again}, dp {e}"
                );
            }
        }
    }
}
