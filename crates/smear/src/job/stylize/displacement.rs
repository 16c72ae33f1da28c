//! The report's per-object displacement (`elongation_max`, `elongation_mean`): largest and
//! mean distance between the elongated in-betweens and the input (docs/smear-speed.md).

/// Largest and mean vertex displacement between two position lists of the same mesh.
///
/// The same values as `max` and mean of `a[i].distance(b[i])`: each distance is glam's
/// `(a − b).length()` (`(x² + y²) + z²`, then the square root), and the largest is taken on
/// the squared distances (a square root is correctly rounded and never decreasing, so the
/// square root of the largest square is the largest distance).
pub(super) fn displacement(a: &[glam::Vec3], b: &[glam::Vec3]) -> (f32, f64) {
    use rayon::prelude::*;
    // Chunks of whole cache lines; the f64 sums in a fixed order keep the mean independent of
    // the threads.
    const CHUNK: usize = 4096;
    let n = a.len().min(b.len());
    let (a, b): (&[f32], &[f32]) = (bytemuck::cast_slice(&a[..n]), bytemuck::cast_slice(&b[..n]));
    let (max_sq, sum) = a
        .par_chunks(3 * CHUNK)
        .zip(b.par_chunks(3 * CHUNK))
        .map(|(a, b)| displacement_chunk(a, b))
        .collect::<Vec<_>>()
        .into_iter()
        .fold((0.0f32, 0.0f64), |(m, s), (cm, cs)| (m.max(cm), s + cs));
    (max_sq.sqrt(), sum / n.max(1) as f64)
}

/// Points per lane run of [`displacement_chunk`].
const DISPLACEMENT_LANES: usize = 16;

/// The largest squared distance and the sum of distances of one chunk of points given as flat
/// xyz coordinates: a lane run of points at a time, each lane summed apart in f64, the lanes
/// added in order at the end.
///
/// # Performance
/// The coordinates are read as flat runs of f32, so the differences, squares and square
/// roots vectorize (a run of `Vec3`s does not). Compiled for baseline x86-64 and for AVX2,
/// picked at run time, with the same bits (only the register width differs).
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn displacement_chunk(a: &[f32], b: &[f32]) -> (f32, f64) {
    const L: usize = DISPLACEMENT_LANES;
    let (mut max, mut sum) = ([0.0f32; L], [0.0f64; L]);
    let run = |a: &[f32], b: &[f32], len: usize, max: &mut [f32; L], sum: &mut [f64; L]| {
        let mut sq = [0.0f32; 3 * L];
        for ((s, p), q) in sq.iter_mut().zip(a).zip(b) {
            let d = p - q;
            *s = d * d;
        }
        for l in 0..len {
            let s = (sq[3 * l] + sq[3 * l + 1]) + sq[3 * l + 2];
            max[l] = if s > max[l] { s } else { max[l] };
            sum[l] += s.sqrt() as f64;
        }
    };
    let (whole_a, whole_b) = (a.chunks_exact(3 * L), b.chunks_exact(3 * L));
    let (rest_a, rest_b) = (whole_a.remainder(), whole_b.remainder());
    for (a, b) in whole_a.zip(whole_b) {
        run(a, b, L, &mut max, &mut sum);
    }
    run(rest_a, rest_b, rest_a.len() / 3, &mut max, &mut sum);
    (
        max.into_iter().fold(0.0f32, f32::max),
        sum.into_iter().sum::<f64>(),
    )
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    #[test]
    fn displacement_is_the_largest_and_mean_distance() {
        // More points than one chunk and not a whole number of lane runs.
        let a = vec![Vec3::ONE; 5003];
        let b: Vec<Vec3> = (0..5003)
            .map(|k| Vec3::ONE + Vec3::new(0.0, k as f32, 0.0))
            .collect();
        let (max, mean) = super::displacement(&a, &b);
        assert_eq!(max, 5002.0);
        assert_eq!(mean, 2501.0);
        assert_eq!(super::displacement(&[], &[]), (0.0, 0.0));
    }

    #[test]
    fn displacement_is_glams_distance_bit_for_bit() {
        // Scattered points over two chunks and a partial lane run: the largest distance and
        // the mean equal those of `Vec3::distance` summed lane by lane in the same order.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 * 200.0 - 100.0
        };
        let a: Vec<Vec3> = (0..9001)
            .map(|_| Vec3::new(next(), next(), next()))
            .collect();
        let b: Vec<Vec3> = (0..9001)
            .map(|_| Vec3::new(next(), next(), next()))
            .collect();
        let (mut max, mut sum) = (0.0f32, 0.0f64);
        for (a, b) in a.chunks(4096).zip(b.chunks(4096)) {
            let mut lanes = [0.0f64; 16];
            for (k, (p, q)) in a.iter().zip(b).enumerate() {
                let d = p.distance(*q);
                max = max.max(d);
                lanes[k % 16] += d as f64;
            }
            sum += lanes.iter().sum::<f64>();
        }
        let (m, mean) = super::displacement(&a, &b);
        assert_eq!(m.to_bits(), max.to_bits());
        assert_eq!(mean.to_bits(), (sum / 9001.0).to_bits());
    }
}
