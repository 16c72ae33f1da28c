//! 3D Voronoi (Worley) noise F1 (paper Section 5.2, Fig. 11d; definition fixed in SPEC.md).

use anim::mix;
use glam::Vec3;

/// Voronoi F1 at `position · kappa`: the distance to the nearest feature point, one feature
/// point jittered uniformly inside every cell of the unit grid (Worley 1996), searched over the
/// 27 cells around the sample. The jitter is a hash of the cell and `seed`, so the value is a
/// pure function of its arguments.
///
/// Returns a value in [0, √3) (in practice mostly in [0, 1]); 0 for non-finite input.
///
/// # Performance
/// No allocation. The sample's own cell first, then only the neighbours that could hold a
/// nearer feature point (a neighbour's feature is at least as far as the cell's face, edge or
/// corner): ~8 of the 27 hashes on average, the same value as searching all 27 bit for bit
/// (the bound leaves a margin for rounding; tested against the full search).
pub fn voronoi_f1(position: Vec3, kappa: f32, seed: u64) -> f32 {
    let q = position * kappa;
    if !q.is_finite() {
        return 0.0;
    }
    let cell = q.floor();
    let (cx, cy, cz) = (cell.x as i64, cell.y as i64, cell.z as i64);
    let distance = |dx: i64, dy: i64, dz: i64| {
        let (i, j, k) = (cx + dx, cy + dy, cz + dz);
        let feature = Vec3::new(i as f32, j as f32, k as f32) + jitter(i, j, k, seed);
        feature.distance_squared(q)
    };
    // How far the sample is from each side of its cell, less the rounding of coordinates
    // this far from the origin (a feature's coordinate rounds by up to half an ulp of it).
    let frac = q - cell;
    let margin = (q.abs().max_element() + 1.0) * 4.0 * f32::EPSILON;
    let gaps = |f: f32| [(f - margin).max(0.0), 0.0, (1.0 - f - margin).max(0.0)];
    let (gx, gy, gz) = (gaps(frac.x), gaps(frac.y), gaps(frac.z));
    let mut best = distance(0, 0, 0);
    for dz in -1..=1i64 {
        for dy in -1..=1i64 {
            for dx in -1..=1i64 {
                if (dx, dy, dz) == (0, 0, 0) {
                    continue;
                }
                let [x, y, z] = [
                    gx[(dx + 1) as usize],
                    gy[(dy + 1) as usize],
                    gz[(dz + 1) as usize],
                ];
                // Every feature of that cell is at least this far (squared); the factor
                // covers the rounding of the squares and sums on both sides.
                if (x * x + y * y + z * z) * (1.0 - 1e-5) > best {
                    continue;
                }
                best = best.min(distance(dx, dy, dz));
            }
        }
    }
    best.sqrt()
}

/// Three uniform numbers in [0, 1) from a cell and a seed (splitmix64 finalizer).
#[inline]
fn jitter(i: i64, j: i64, k: i64, seed: u64) -> Vec3 {
    let mut h = seed ^ 0x9E37_79B9_7F4A_7C15;
    for c in [i, j, k] {
        h = mix(h ^ (c as u64).wrapping_mul(0xD6E8_FEB8_6659_FD93));
    }
    let unit = |bits: u64| (bits >> 40) as f32 / (1u64 << 24) as f32;
    Vec3::new(unit(h), unit(mix(h ^ 1)), unit(mix(h ^ 2)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The full search over all 27 cells (the definition).
    fn f1_all_cells(position: Vec3, kappa: f32, seed: u64) -> f32 {
        let q = position * kappa;
        if !q.is_finite() {
            return 0.0;
        }
        let cell = q.floor();
        let (cx, cy, cz) = (cell.x as i64, cell.y as i64, cell.z as i64);
        let mut best = f32::INFINITY;
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let (i, j, k) = (cx + dx, cy + dy, cz + dz);
                    let feature = Vec3::new(i as f32, j as f32, k as f32) + jitter(i, j, k, seed);
                    best = best.min(feature.distance_squared(q));
                }
            }
        }
        best.sqrt()
    }

    #[test]
    fn skipping_far_cells_keeps_every_bit_of_the_full_search() {
        // Samples near and far from the origin, on both signs, on cell faces and corners.
        let mut h = 0x1234_5678_9ABC_DEF0u64;
        let mut next = || {
            h = mix(h);
            (h >> 40) as f32 / (1u64 << 24) as f32
        };
        for n in 0..200_000 {
            let scale = [1.0, 10.0, 1e3, 1e5, 3e6][n % 5];
            let p = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * scale;
            let kappa = [1.0, 18.0, 0.37][n % 3];
            let (a, b) = (voronoi_f1(p, kappa, 7), f1_all_cells(p, kappa, 7));
            assert_eq!(a.to_bits(), b.to_bits(), "{p} × {kappa}: {a} vs {b}");
        }
        for p in [
            Vec3::ZERO,
            Vec3::ONE,
            Vec3::splat(-1.0),
            Vec3::new(2.0, -3.0, 0.5),
        ] {
            assert_eq!(
                voronoi_f1(p, 1.0, 3).to_bits(),
                f1_all_cells(p, 1.0, 3).to_bits()
            );
        }
    }

    #[test]
    fn fig11d_noise_is_deterministic_and_in_range() {
        let mut sum = 0.0;
        let n = 2000;
        let (mut lo, mut hi) = (f32::MAX, f32::MIN);
        for i in 0..n {
            let p = Vec3::new(
                i as f32 * 0.137,
                (i % 17) as f32 * 0.31,
                (i % 5) as f32 * -0.7,
            );
            let a = voronoi_f1(p, 18.0, 7);
            assert_eq!(a.to_bits(), voronoi_f1(p, 18.0, 7).to_bits());
            assert!((0.0..3f32.sqrt()).contains(&a), "{a}");
            lo = lo.min(a);
            hi = hi.max(a);
            sum += a;
        }
        let mean = sum / n as f32;
        // F1 of a jittered grid has mean ≈ 0.5 and spreads over most of [0, 1].
        assert!((0.35..0.65).contains(&mean), "mean {mean}");
        assert!(lo < 0.15 && hi > 0.8, "range [{lo}, {hi}]");
        // Another seed gives another pattern.
        let p = Vec3::new(0.3, 0.2, 0.1);
        let diff: f32 = (0..50)
            .map(|i| {
                let q = p + Vec3::X * i as f32 * 0.21;
                (voronoi_f1(q, 3.0, 1) - voronoi_f1(q, 3.0, 2)).abs()
            })
            .sum();
        assert!(diff > 1.0, "{diff}");
        assert_eq!(voronoi_f1(Vec3::NAN, 1.0, 0), 0.0);
    }

    #[test]
    fn a_feature_point_has_zero_distance() {
        let f = Vec3::new(2.0, -1.0, 5.0) + jitter(2, -1, 5, 3);
        assert!(voronoi_f1(f, 1.0, 3) < 1e-6);
        // Scaling by κ: the same feature point seen from position f / κ.
        assert!(voronoi_f1(f / 4.0, 4.0, 3) < 1e-5);
    }
}
