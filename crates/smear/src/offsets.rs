//! The per-frame, per-vertex motion offsets δ_i(f) container.

use rayon::prelude::*;

use crate::{smooth_in_time, Result, SmearError};

/// Values per job of [`MotionOffsets::range`]'s parallel pass.
const RANGE_CHUNK: usize = 1 << 16;

/// Motion offsets δ_i(f) of one object: `frames × vertices` values, frame-major and
/// contiguous (frame `f` is `values[f * vertices..(f + 1) * vertices]`).
///
/// Values lie in [−1, 1] for simple objects (SMEAR Eq. 1) and may slightly exceed it at joints of
/// articulated figures (paper Section 3.2, after SMEAR Eq. 9).
#[derive(Debug, Clone, PartialEq)]
pub struct MotionOffsets {
    frames: usize,
    vertices: usize,
    values: Vec<f32>,
}

impl MotionOffsets {
    /// Wraps a frame-major buffer.
    ///
    /// # Errors
    /// [`SmearError::LengthMismatch`] when `values.len() != frames * vertices`.
    pub fn new(frames: usize, vertices: usize, values: Vec<f32>) -> Result<MotionOffsets> {
        if values.len() != frames * vertices {
            return Err(SmearError::LengthMismatch {
                expected: frames * vertices,
                found: values.len(),
            });
        }
        Ok(MotionOffsets {
            frames,
            vertices,
            values,
        })
    }

    /// All-zero offsets.
    pub fn zeros(frames: usize, vertices: usize) -> MotionOffsets {
        MotionOffsets {
            frames,
            vertices,
            values: vec![0.0; frames * vertices],
        }
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.frames
    }

    /// Number of vertices (or surface points) per frame.
    pub fn vertex_count(&self) -> usize {
        self.vertices
    }

    /// Offsets of frame `f`.
    ///
    /// # Panics
    /// If `f >= frame_count()`.
    pub fn frame(&self, f: usize) -> &[f32] {
        &self.values[f * self.vertices..(f + 1) * self.vertices]
    }

    /// Offset of vertex `v` at frame `f`, `None` when out of range.
    pub fn get(&self, f: usize, v: usize) -> Option<f32> {
        (f < self.frames && v < self.vertices).then(|| self.values[f * self.vertices + v])
    }

    /// The whole frame-major buffer.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// Consumes the container, returning the frame-major buffer.
    pub fn into_values(self) -> Vec<f32> {
        self.values
    }

    /// Largest |δ| over all frames and vertices (0 when empty).
    pub fn max_abs(&self) -> f32 {
        self.values.iter().fold(0.0f32, |m, v| m.max(v.abs()))
    }

    /// Smallest and largest value, `(0, 0)` when empty.
    ///
    /// # Performance
    /// Parallel over blocks of values (one pass over a clip's offsets is serial time
    /// otherwise, at the end of every offsets job).
    pub fn range(&self) -> (f32, f32) {
        if self.values.is_empty() {
            return (0.0, 0.0);
        }
        let fold = |(lo, hi): (f32, f32), &v: &f32| (lo.min(v), hi.max(v));
        let empty = (f32::INFINITY, f32::NEG_INFINITY);
        self.values
            .par_chunks(RANGE_CHUNK)
            .map(|c| c.iter().fold(empty, fold))
            .reduce(|| empty, |(a, b), (c, d)| (a.min(c), b.max(d)))
    }

    /// Temporal smoothing of SMEAR Eq. 2 with half-window `n` (0 returns a copy).
    pub fn smoothed(&self, n: usize) -> MotionOffsets {
        MotionOffsets {
            frames: self.frames,
            vertices: self.vertices,
            values: smooth_in_time(&self.values, self.frames, self.vertices, n),
        }
    }

    /// Concatenates the vertices of several fields frame by frame (vertex order = order of
    /// `parts`), matching `anim::SampledScene::merged`.
    ///
    /// # Errors
    /// [`SmearError::FrameMismatch`] when the frame counts differ.
    pub fn concat(parts: &[MotionOffsets]) -> Result<MotionOffsets> {
        let frames = parts.first().map_or(0, |p| p.frames);
        if let Some(p) = parts.iter().find(|p| p.frames != frames) {
            return Err(SmearError::FrameMismatch {
                expected: frames,
                found: p.frames,
            });
        }
        let vertices = parts.iter().map(|p| p.vertices).sum();
        let mut values = Vec::with_capacity(frames * vertices);
        for f in 0..frames {
            for p in parts {
                values.extend_from_slice(p.frame(f));
            }
        }
        Ok(MotionOffsets {
            frames,
            vertices,
            values,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn concat_interleaves_frames() {
        let a = MotionOffsets::new(2, 1, vec![1.0, 2.0]).unwrap();
        let b = MotionOffsets::new(2, 2, vec![3.0, 4.0, 5.0, 6.0]).unwrap();
        let c = MotionOffsets::concat(&[a, b]).unwrap();
        assert_eq!(c.values(), &[1.0, 3.0, 4.0, 2.0, 5.0, 6.0]);
        assert_eq!(c.get(1, 2), Some(6.0));
        assert_eq!(c.range(), (1.0, 6.0));
        assert!(MotionOffsets::new(2, 2, vec![0.0; 3]).is_err());
    }

    /// The parallel range over several blocks finds extremes in any block and ignores NaN.
    #[test]
    fn range_over_blocks() {
        let n = 3 * RANGE_CHUNK + 7;
        let mut v: Vec<f32> = (0..n).map(|i| (i as f32 * 0.001).sin() * 0.5).collect();
        v[RANGE_CHUNK + 3] = -0.9;
        v[n - 1] = 0.8;
        v[5] = f32::NAN;
        let d = MotionOffsets::new(1, n, v).unwrap();
        assert_eq!(d.range(), (-0.9, 0.8));
        assert_eq!(MotionOffsets::zeros(0, 4).range(), (0.0, 0.0));
    }
}
