//! A sketched 2D stroke `x_stroke(s)` with a constant-length (arc-length) parametrization.

use glam::DVec2;

use crate::error::StrokeError;

/// Relative tolerance under which a stroke's extent counts as a single point.
const COLLAPSE_TOLERANCE: f64 = 1e-9;

/// Samples of a smoothed stroke ([`Stroke::smoothed`]).
pub const SMOOTHING_SAMPLES: usize = 101;

/// Default smoothing of keystrokes before fitting: a Gaussian of σ = 2 % of the stroke's
/// length along the arc ([`Stroke::smoothed`]).
pub const DEFAULT_STROKE_SMOOTHING: f64 = 0.02;

/// A polyline of screen-space samples, parametrized by arc length (Section 3.1).
///
/// Consecutive duplicate samples are dropped on construction, so every segment has a
/// positive length.
#[derive(Debug, Clone, PartialEq)]
pub struct Stroke {
    points: Vec<DVec2>,
    /// Cumulative arc length at each point; `cumulative[0] == 0`.
    cumulative: Vec<f64>,
}

impl Stroke {
    /// Builds a stroke from its samples.
    ///
    /// Errors when there are fewer than two samples, a coordinate is not finite, or all
    /// samples coincide (the stroke overlaps itself into a point).
    pub fn new(samples: impl IntoIterator<Item = DVec2>) -> Result<Self, StrokeError> {
        let raw: Vec<DVec2> = samples.into_iter().collect();
        if raw.len() < 2 {
            return Err(StrokeError::TooFewPoints { points: raw.len() });
        }
        if let Some(sample) = raw.iter().position(|p| !p.is_finite()) {
            return Err(StrokeError::NonFinite { sample });
        }
        let (lo, hi) = raw.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let extent = (hi - lo).length();
        let magnitude = lo.abs().max(hi.abs()).max_element().max(1.0);
        if extent <= COLLAPSE_TOLERANCE * magnitude {
            return Err(StrokeError::Collapsed { extent });
        }
        let mut points: Vec<DVec2> = Vec::with_capacity(raw.len());
        for p in raw {
            if points.last().is_none_or(|q| *q != p) {
                points.push(p);
            }
        }
        let mut cumulative = Vec::with_capacity(points.len());
        let mut total = 0.0;
        cumulative.push(0.0);
        for w in points.windows(2) {
            total += (w[1] - w[0]).length();
            cumulative.push(total);
        }
        Ok(Self { points, cumulative })
    }

    /// The (deduplicated) samples.
    pub fn points(&self) -> &[DVec2] {
        &self.points
    }

    /// Total arc length.
    pub fn length(&self) -> f64 {
        *self.cumulative.last().unwrap_or(&0.0)
    }

    /// The point at arc length `s` from the start, clamped to `[0, length]`.
    pub fn point_at_length(&self, s: f64) -> DVec2 {
        let s = if s.is_nan() {
            0.0
        } else {
            s.clamp(0.0, self.length())
        };
        // First index whose cumulative length is >= s.
        let i = self.cumulative.partition_point(|&c| c < s);
        if i == 0 {
            return self.points[0];
        }
        let (c0, c1) = (self.cumulative[i - 1], self.cumulative[i]);
        let t = if c1 > c0 { (s - c0) / (c1 - c0) } else { 0.0 };
        self.points[i - 1].lerp(self.points[i], t)
    }

    /// The point at normalized arc length `u ∈ [0, 1]` (`x_stroke(u)` of the paper).
    pub fn point_at(&self, u: f64) -> DVec2 {
        self.point_at_length(u * self.length())
    }

    /// `count + 1` points equally spaced in arc length, from the start to the end.
    pub fn resample(&self, count: usize) -> Vec<DVec2> {
        let count = count.max(1);
        let step = self.length() / count as f64;
        (0..=count)
            .map(|j| self.point_at_length(step * j as f64))
            .collect()
    }

    /// The stroke drawn the other way round.
    pub fn reversed(&self) -> Stroke {
        let total = self.length();
        Stroke {
            points: self.points.iter().rev().copied().collect(),
            cumulative: self.cumulative.iter().rev().map(|c| total - c).collect(),
        }
    }

    /// The "spatially smooth stroke" the paper fits (LoA Section 3.1): the stroke resampled at
    /// [`SMOOTHING_SAMPLES`] points equally spaced in arc length, each averaged with a
    /// Gaussian of standard deviation `sigma × length` along the arc (window ±3σ, shrinking
    /// symmetrically near the ends so that both end points stay exactly where they were
    /// drawn). Jitter shorter than σ is removed; a stroke that is already smooth at that scale
    /// moves by much less than σ (a circular arc of angle θ shrinks by about σ²θ²/2 of its
    /// length). `sigma ≤ 0` returns the stroke unchanged.
    pub fn smoothed(&self, sigma: f64) -> Stroke {
        if !(sigma > 0.0 && sigma.is_finite()) {
            return self.clone();
        }
        let count = SMOOTHING_SAMPLES;
        let samples = self.resample(count - 1);
        let step = 1.0 / (count - 1) as f64;
        let radius = ((3.0 * sigma / step).ceil() as usize).max(1);
        let smooth: Vec<DVec2> = (0..count)
            .map(|i| {
                let k = radius.min(i).min(count - 1 - i);
                let (mut sum, mut weight) = (DVec2::ZERO, 0.0);
                for j in i - k..=i + k {
                    let d = (j as f64 - i as f64) * step / sigma;
                    let w = (-0.5 * d * d).exp();
                    sum += w * samples[j];
                    weight += w;
                }
                sum / weight
            })
            .collect();
        Stroke::new(smooth).unwrap_or_else(|_| self.clone())
    }

    /// Axis-aligned bounds `(min, max)` of the samples.
    pub fn bounds(&self) -> (DVec2, DVec2) {
        self.points.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arc_length_parametrization_is_uniform() {
        let s = Stroke::new([DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(1.0, 3.0)]).unwrap();
        assert_eq!(s.length(), 4.0);
        let r = s.resample(4);
        assert_eq!(r.len(), 5);
        assert!((r[1] - DVec2::new(1.0, 0.0)).length() < 1e-12);
        assert!((r[2] - DVec2::new(1.0, 1.0)).length() < 1e-12);
        assert!((s.point_at(1.0) - DVec2::new(1.0, 3.0)).length() < 1e-12);
    }

    #[test]
    fn smoothing_removes_jitter_and_keeps_the_ends() {
        // A straight stroke with ±1 % zig-zag jitter every sample.
        let raw: Vec<DVec2> = (0..=200)
            .map(|i| DVec2::new(i as f64, if i % 2 == 0 { 2.0 } else { -2.0 }))
            .collect();
        let s = Stroke::new(raw).unwrap();
        let smooth = s.smoothed(DEFAULT_STROKE_SMOOTHING);
        assert_eq!(smooth.points()[0], s.points()[0]);
        assert_eq!(smooth.points().last(), s.points().last());
        let interior = &smooth.points()[10..smooth.points().len() - 10];
        let worst = interior.iter().map(|p| p.y.abs()).fold(0.0, f64::max);
        assert!(worst < 0.2, "jitter left: {worst}");
        // Reversal swaps the ends and keeps the length.
        let r = s.reversed();
        assert_eq!(r.points()[0], *s.points().last().unwrap());
        assert!((r.length() - s.length()).abs() < 1e-9);
        assert!((r.point_at(0.25) - s.point_at(0.75)).length() < 1e-9);
    }

    #[test]
    fn degenerate_strokes_are_errors() {
        assert_eq!(
            Stroke::new([DVec2::ONE]),
            Err(StrokeError::TooFewPoints { points: 1 })
        );
        assert!(matches!(
            Stroke::new([DVec2::ONE, DVec2::ONE, DVec2::ONE]),
            Err(StrokeError::Collapsed { .. })
        ));
        assert_eq!(
            Stroke::new([DVec2::ONE, DVec2::new(f64::NAN, 0.0)]),
            Err(StrokeError::NonFinite { sample: 1 })
        );
    }
}
