//! Hise's warping curve C_{s,p} applied to motion offsets (paper Section 5.2, Fig. 12).

/// Hise's curve C_{s,p}(y) on y ∈ [0, 1] (SPEC.md): with c = 2/(1 − s) − 1,
/// C(y) = y^c / p^(c−1) for y ≤ p, else 1 − (1 − y)^c / (1 − p)^(c−1).
///
/// Arguments: `s` ∈ [0, 1) strength (0 = identity), `p` ∈ (0, 1) pivot (C(p) = p). Out-of-range
/// arguments are clamped (s to [0, 0.999], p to [0.001, 0.999], y to [0, 1]).
#[inline]
pub fn hise_curve(y: f32, s: f32, p: f32) -> f32 {
    let y = if y.is_nan() { 0.5 } else { y.clamp(0.0, 1.0) };
    let s = if s.is_nan() { 0.0 } else { s.clamp(0.0, 0.999) };
    let p = if p.is_nan() {
        0.5
    } else {
        p.clamp(0.001, 0.999)
    };
    let c = 2.0 / (1.0 - s) - 1.0;
    if y <= p {
        y.powf(c) / p.powf(c - 1.0)
    } else {
        1.0 - (1.0 - y).powf(c) / (1.0 - p).powf(c - 1.0)
    }
}

/// Warped motion offset δ'(s, p) = 2·C_{s,p}((δ + 1)/2) − 1 ∈ [−1, 1] (paper Section 5.2).
/// p > 0.5 shifts offsets toward the past (more trailing), p < 0.5 toward the future.
#[inline]
pub fn warp_offset(delta: f32, s: f32, p: f32) -> f32 {
    2.0 * hise_curve((delta + 1.0) * 0.5, s, p) - 1.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fig12_warp_endpoints_pivot_and_midpoint() {
        // Fig. 12: δ'(0.5, 0.8). c = 2/(1 − 0.5) − 1 = 3.
        for (s, p) in [(0.5, 0.8), (0.8, 0.5), (0.3, 0.2)] {
            assert!((warp_offset(-1.0, s, p) + 1.0).abs() < 1e-6);
            assert!((warp_offset(1.0, s, p) - 1.0).abs() < 1e-6);
            assert!((hise_curve(p, s, p) - p).abs() < 1e-6);
        }
        // C(0.5) = 0.5³ / 0.8² = 0.1953125, δ' = 2·0.1953125 − 1 = −0.609375 (toward the past).
        assert!((warp_offset(0.0, 0.5, 0.8) + 0.609375).abs() < 1e-6);
        // p = 0.5, s = 0.8: c = 9; δ = 0.5 → y = 0.75 > p: 1 − 0.25⁹/0.5⁸ = 0.9990234375.
        assert!((warp_offset(0.5, 0.8, 0.5) - 0.998_046_9).abs() < 1e-6);
        // s = 0 is the identity.
        assert!((warp_offset(0.3, 0.0, 0.7) - 0.3).abs() < 1e-6);
    }

    #[test]
    fn warp_is_monotonic_and_bounded() {
        let mut prev = -1.0f32;
        for i in 0..=200 {
            let d = -1.0 + i as f32 / 100.0;
            let w = warp_offset(d, 0.6, 0.3);
            assert!((-1.0..=1.0).contains(&w) && w >= prev - 1e-6);
            prev = w;
        }
        assert!(warp_offset(f32::NAN, 0.5, 0.5).is_finite());
    }
}
