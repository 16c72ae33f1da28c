//! k-means++ seeding of a restart's library (Arthur & Vassilvitskii 2007) in the reduced
//! coordinates of the frames.

use faer::Par;
use rayon::prelude::*;

use super::problem::PartProblem;
use anim::SplitMix64;

/// k-means++ (Arthur & Vassilvitskii 2007) over frames, fixed pieces counted as centres.
/// Returns row-major `d × q` pieces. With `Par::Seq` (restarts already run in parallel) the
/// distance updates stay on the calling thread; the values are the same either way.
pub(super) fn kmeans_pp(
    p: &PartProblem<'_>,
    d: usize,
    rng: &mut SplitMix64,
    par: Par,
    yt: &[f64],
) -> Vec<f64> {
    let (n, q, nf) = (p.frames(), p.sub.dim, p.fixed);
    let y = p.frame_coords();
    let mut lib = Vec::with_capacity(d * q);
    lib.extend_from_slice(p.fixed_coords());
    let mut dist = vec![f64::INFINITY; n];
    let nearer = |(f, dv): (usize, &mut f64), c: &[f64]| {
        *dv = dv.min(squared_distance(&y[f * q..(f + 1) * q], c));
    };
    // On one thread, frames side by side over the transposed coordinates: each frame's sum
    // still adds its coordinates in order (the same value as `nearer`), several frames per
    // instruction; a block of frames that the new centre cannot come nearer to is skipped
    // (see `FAR_MARGIN`).
    let seq = matches!(par, Par::Seq);
    let mut owner = vec![NO_CENTRE; if seq { n } else { 0 }];
    let mut reach = Vec::with_capacity(if seq { d } else { 0 });
    let mut update = |dist: &mut [f64], lib: &[f64], c: &[f64]| {
        if !seq {
            dist.par_iter_mut().enumerate().for_each(|e| nearer(e, c));
            return;
        }
        // Squared distances from the new centre to the centres before it.
        reach.clear();
        reach.extend(lib.chunks_exact(q.max(1)).map(|r| squared_distance(r, c)));
        pulp::Arch::new().dispatch(Nearer {
            dist,
            owner: &mut owner,
            yt,
            c,
            reach: &reach,
            n,
        })
    };
    for k in 0..nf {
        let lib = &p.fixed_coords()[..k * q];
        update(&mut dist, lib, &p.fixed_coords()[k * q..(k + 1) * q]);
    }
    for _ in nf..d {
        let total: f64 = dist.iter().filter(|v| v.is_finite()).sum();
        let pick = if lib.is_empty() || total.is_nan() || total <= 0.0 || total.is_infinite() {
            rng.below(n)
        } else {
            let mut t = rng.next_f64() * total;
            let mut pick = n - 1;
            for (f, &dv) in dist.iter().enumerate() {
                if t < dv {
                    pick = f;
                    break;
                }
                t -= dv;
            }
            pick
        };
        let c = &y[pick * q..(pick + 1) * q];
        update(&mut dist, &lib, c);
        lib.extend_from_slice(c);
    }
    lib
}

/// `‖a − b‖²`, the coordinates added in order.
fn squared_distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| (a - b) * (a - b)).sum()
}

/// `owner` of a frame no centre has come nearest to yet.
const NO_CENTRE: u32 = u32::MAX;

/// Frames whose skip test is taken together (a block of consecutive frames: a clip's frames
/// near in time are near in shape, so they tend to be far from a new centre together).
const FAR_BLOCK: usize = 16;

/// Relative margin of the skip test. A frame `y` at squared distance `D` from its nearest
/// centre `a` cannot come nearer to a new centre `c` when `‖c − a‖ ≥ 2 √D` (triangle
/// inequality: `‖y − c‖ ≥ ‖c − a‖ − ‖y − a‖ ≥ √D`). Tested as `‖c − a‖² ≥ 4 D (1 + margin)`,
/// the true distance to `c` exceeds `√D` by far more than the rounding of the computed sums
/// (relative `q · 2⁻⁵³`), so the computed distance is larger too and `min` keeps `D`: a
/// skipped frame ends with the very value it would have had.
const FAR_MARGIN: f64 = 1e-6;

/// The distance update of one new centre on one thread, as a [`pulp::WithSimd`] operation:
/// compiled once per instruction set (AVX2 on x86-64), the same sums in the same order.
/// Blocks of [`FAR_BLOCK`] frames that all pass the skip test of [`FAR_MARGIN`] are left as
/// they are.
struct Nearer<'a> {
    dist: &'a mut [f64],
    /// Index of each frame's nearest centre so far ([`NO_CENTRE`] before the first).
    owner: &'a mut [u32],
    yt: &'a [f64],
    c: &'a [f64],
    /// Squared distance from `c` to every centre before it; `c` is centre `reach.len()`.
    reach: &'a [f64],
    n: usize,
}

impl pulp::WithSimd for Nearer<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let Nearer {
            dist,
            owner,
            yt,
            c,
            reach,
            n,
        } = self;
        let index = reach.len() as u32;
        let far = |dist: &[f64], owner: &[u32]| {
            dist.iter().zip(owner).all(|(&dv, &o)| {
                let o = o as usize;
                o < reach.len() && reach[o] >= 4.0 * dv * (1.0 + FAR_MARGIN)
            })
        };
        let mut b0 = 0;
        while b0 < n {
            let b1 = (b0 + FAR_BLOCK).min(n);
            if far(&dist[b0..b1], &owner[b0..b1]) {
                b0 = b1;
                continue;
            }
            let mut sums = [0.0f64; FAR_BLOCK];
            let sums = &mut sums[..b1 - b0];
            for (row, &cc) in yt.chunks_exact(n).zip(c) {
                for (s, &a) in sums.iter_mut().zip(&row[b0..b1]) {
                    *s += (a - cc) * (a - cc);
                }
            }
            for ((dv, o), &s) in dist[b0..b1]
                .iter_mut()
                .zip(&mut owner[b0..b1])
                .zip(sums.iter())
            {
                let nearest = dv.min(s);
                if nearest.to_bits() != dv.to_bits() {
                    *o = index;
                }
                *dv = nearest;
            }
            b0 = b1;
        }
    }
}
