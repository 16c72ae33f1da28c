//! Motion-line seeds (Section 4.3): random surface points, area-weighted, deterministic.

use anim::SplitMix64;
use glam::Vec3;

use crate::SurfacePoint;

/// Default seed of the random generator.
pub const DEFAULT_SEED: u64 = 0x5EED;

/// `count` points uniformly distributed over the surface (triangles picked with probability
/// proportional to their area in `positions`, then a uniform point inside), from toonkit's one
/// generator ([`anim::SplitMix64`]) seeded with `seed`: same inputs, same points on every platform.
///
/// The paper picks random vertices "for simplicity"; surface samples spread lines evenly
/// whatever the tessellation.
///
/// # Arguments
/// * `positions` — vertex positions the areas are measured on (typically the first frame).
///
/// # Returns
/// `count` points, or none when the surface has no area (or a triangle index is out of
/// range, which [`anim::Mesh::validate`] rules out).
///
/// # Performance
/// O(triangles + count · log triangles).
pub fn sample_surface(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    count: usize,
    seed: u64,
) -> Vec<SurfacePoint> {
    let mut cdf = Vec::with_capacity(triangles.len());
    let mut total = 0.0f64;
    for t in triangles {
        let area = match t.map(|v| positions.get(v as usize)) {
            [Some(a), Some(b), Some(c)] => 0.5 * (*b - *a).cross(*c - *a).length() as f64,
            _ => return Vec::new(),
        };
        if area.is_finite() {
            total += area;
        }
        cdf.push(total);
    }
    if total.is_nan() || total <= 0.0 {
        return Vec::new();
    }
    let mut rng = SplitMix64::new(seed, 0);
    (0..count)
        .map(|_| {
            let r = rng.next_f64() * total;
            let tri = cdf.partition_point(|&c| c <= r).min(cdf.len() - 1);
            let (mut u, mut v) = (rng.next_f32(), rng.next_f32());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            SurfacePoint {
                triangle: tri as u32,
                barycentric: [1.0 - u - v, u, v],
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_are_deterministic_and_area_weighted() {
        // Two triangles, the second with 3× the area.
        let p = [
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(13.0, 0.0, 0.0),
            Vec3::new(10.0, 1.0, 0.0),
        ];
        let t = [[0, 1, 2], [3, 4, 5]];
        let a = sample_surface(&p, &t, 4000, 7);
        assert_eq!(a, sample_surface(&p, &t, 4000, 7));
        assert_ne!(a, sample_surface(&p, &t, 4000, 8));
        let big = a.iter().filter(|s| s.triangle == 1).count() as f32 / 4000.0;
        assert!((big - 0.75).abs() < 0.03, "share on the big triangle {big}");
        assert!(a
            .iter()
            .all(|s| s.barycentric.iter().all(|b| (0.0..=1.0).contains(b))
                && (s.barycentric.iter().sum::<f32>() - 1.0).abs() < 1e-5));
        assert!(sample_surface(&p[..3], &[[0, 0, 1]], 5, 1).is_empty());
        assert!(sample_surface(&p, &[[0, 1, 9]], 5, 1).is_empty());
    }
}
