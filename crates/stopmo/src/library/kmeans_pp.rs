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
        let s: f64 = y[f * q..(f + 1) * q]
            .iter()
            .zip(c)
            .map(|(a, b)| (a - b) * (a - b))
            .sum();
        *dv = dv.min(s);
    };
    // On one thread, frames side by side over the transposed coordinates: each frame's sum
    // still adds its coordinates in order (the same value as `nearer`), several frames per
    // instruction.
    let mut sums = vec![0.0; if matches!(par, Par::Seq) { n } else { 0 }];
    let mut update = |dist: &mut [f64], c: &[f64]| match par {
        Par::Seq => pulp::Arch::new().dispatch(Nearer {
            dist,
            sums: &mut sums,
            yt,
            c,
            n,
        }),
        _ => dist.par_iter_mut().enumerate().for_each(|e| nearer(e, c)),
    };
    for k in 0..nf {
        update(&mut dist, &p.fixed_coords()[k * q..(k + 1) * q]);
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
        update(&mut dist, c);
        lib.extend_from_slice(c);
    }
    lib
}

/// The distance update of one new centre on one thread, as a [`pulp::WithSimd`] operation:
/// compiled once per instruction set (AVX2 on x86-64), the same sums in the same order.
struct Nearer<'a> {
    dist: &'a mut [f64],
    sums: &'a mut [f64],
    yt: &'a [f64],
    c: &'a [f64],
    n: usize,
}

impl pulp::WithSimd for Nearer<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let Nearer {
            dist,
            sums,
            yt,
            c,
            n,
        } = self;
        sums.fill(0.0);
        for (row, &cc) in yt.chunks_exact(n).zip(c) {
            for (s, &a) in sums.iter_mut().zip(row) {
                *s += (a - cc) * (a - cc);
            }
        }
        for (dv, &s) in dist.iter_mut().zip(sums.iter()) {
            *dv = dv.min(s);
        }
    }
}
