//! Temporal smoothing of motion offsets (paper SMEAR Eq. 2).

use rayon::prelude::*;

/// The normalized weights w_n, n = −N..=N, of SMEAR Eq. 2: w_n = (1 − (n/(N+1))²)² / Σ w.
///
/// # Arguments
/// * `n` — half-window N; 0 gives `[1.0]` (no smoothing).
///
/// # Returns
/// `2N + 1` weights summing to 1, index `n + N` holding w_n.
pub fn smoothing_weights(n: usize) -> Vec<f32> {
    let denom = (n + 1) as f64;
    let raw: Vec<f64> = (-(n as i64)..=n as i64)
        .map(|k| {
            let x = k as f64 / denom;
            (1.0 - x * x).powi(2)
        })
        .collect();
    let sum: f64 = raw.iter().sum();
    raw.iter().map(|w| (w / sum) as f32).collect()
}

/// The past half of SMEAR Eq. 2's window for the causal mode (issue #22): w_n for
/// n = −N..=0, renormalized to sum 1 (index `n + N` holds w_n). Frame f then reads no frame
/// after f; the smoothed offsets lag the offline ones by about N/3 frames.
pub fn causal_smoothing_weights(n: usize) -> Vec<f32> {
    let w = smoothing_weights(n);
    let past = &w[..=n];
    let sum: f32 = past.iter().sum();
    past.iter().map(|x| x / sum).collect()
}

/// [`smooth_in_time`] with the past-only window of [`causal_smoothing_weights`] (frames
/// before the first clamp to it).
pub fn smooth_in_time_causal(values: &[f32], frames: usize, vertices: usize, n: usize) -> Vec<f32> {
    smooth_columns(values, frames, vertices, 0..vertices, n, true)
}

/// Smooths a frame-major `frames × vertices` buffer in time with SMEAR Eq. 2; frames outside the
/// animation are clamped to the first/last frame (SPEC.md).
///
/// # Performance
/// Parallel over frames; `(2N + 1) × frames × vertices` multiply-adds.
pub fn smooth_in_time(values: &[f32], frames: usize, vertices: usize, n: usize) -> Vec<f32> {
    smooth_columns(values, frames, vertices, 0..vertices, n, false)
}

/// SMEAR Eq. 2 on the columns `cols` of a frame-major `frames × stride` buffer (one object's
/// vertices inside a group), into a new frame-major `frames × cols.len()` buffer; with
/// `causal`, only the past half of the window ([`causal_smoothing_weights`]).
///
/// # Panics
/// If `values` is shorter than `frames × stride` or `cols` is not inside `0..stride`.
///
/// # Performance
/// Parallel over frames. Each output frame is written before it is read, so the fresh
/// (zeroed, not yet mapped) output pages fault once, not twice.
pub(crate) fn smooth_columns(
    values: &[f32],
    frames: usize,
    stride: usize,
    cols: std::ops::Range<usize>,
    n: usize,
    causal: bool,
) -> Vec<f32> {
    let width = cols.len();
    let w = if causal {
        causal_smoothing_weights(n)
    } else {
        smoothing_weights(n)
    };
    let column = |g: usize| &values[g * stride + cols.start..g * stride + cols.end];
    if n == 0 || frames <= 1 || width == 0 {
        let mut out = Vec::with_capacity(frames * width);
        for f in 0..frames {
            out.extend_from_slice(column(f));
        }
        return out;
    }
    let mut out = vec![0.0f32; frames * width];
    out.par_chunks_mut(width).enumerate().for_each(|(f, dst)| {
        for (k, &wk) in w.iter().enumerate() {
            let g = (f as i64 + k as i64 - n as i64).clamp(0, frames as i64 - 1) as usize;
            let src = column(g);
            if k == 0 {
                for (d, s) in dst.iter_mut().zip(src) {
                    *d = wk * s;
                }
            } else {
                for (d, s) in dst.iter_mut().zip(src) {
                    *d += wk * s;
                }
            }
        }
    });
    out
}

/// [`smooth_columns`] over every column of a frame-major `frames × width` buffer, in place:
/// the same values bit for bit, without a second `frames × width` buffer (whose fresh pages
/// the kernel would clear first).
///
/// # Performance
/// Parallel over contiguous runs of frames, one per worker. Each run keeps the originals it
/// still needs once they are overwritten — its last N frames in a ring — and, copied before
/// any run starts, the N frames before it and after it that its neighbours overwrite.
pub(crate) fn smooth_in_place(
    values: &mut [f32],
    frames: usize,
    width: usize,
    n: usize,
    causal: bool,
) {
    let per_run = frames.div_ceil(rayon::current_num_threads().max(1));
    smooth_runs(values, frames, width, n, causal, per_run);
}

/// [`smooth_in_place`] in runs of `per_run` frames.
fn smooth_runs(
    values: &mut [f32],
    frames: usize,
    width: usize,
    n: usize,
    causal: bool,
    per_run: usize,
) {
    if n == 0 || frames <= 1 || width == 0 || per_run == 0 || values.len() < frames * width {
        return;
    }
    let w = if causal {
        causal_smoothing_weights(n)
    } else {
        smoothing_weights(n)
    };
    let frame = |v: &[f32], g: usize| v[g * width..(g + 1) * width].to_vec();
    // Per run starting at frame a: the originals of frames a − N..a (the ring's first
    // contents) and of the N frames after it, taken before any run writes.
    let halos: Vec<(Vec<f32>, Vec<f32>)> = (0..frames)
        .step_by(per_run)
        .map(|a| {
            let b = (a + per_run).min(frames);
            let mut ring = vec![0.0f32; (n + 1) * width];
            for g in a.saturating_sub(n)..a {
                let slot = g % (n + 1);
                ring[slot * width..(slot + 1) * width].copy_from_slice(&frame(values, g));
            }
            let ahead: Vec<f32> = (b..(b + n).min(frames))
                .flat_map(|g| frame(values, g))
                .collect();
            (ring, ahead)
        })
        .collect();
    values[..frames * width]
        .par_chunks_mut(per_run * width)
        .zip(halos)
        .enumerate()
        .for_each(|(r, (run, (mut ring, ahead)))| {
            let a = r * per_run;
            let b = a + run.len() / width;
            for f in a..b {
                // Frame f's original joins the ring (the slot of frame f − N − 1, no longer
                // read), then frame f is overwritten by its smoothed values.
                let slot = f % (n + 1);
                let local = (f - a) * width;
                ring[slot * width..(slot + 1) * width].copy_from_slice(&run[local..local + width]);
                let (_, rest) = run.split_at_mut(local);
                let (dst, after) = rest.split_at_mut(width);
                for (k, &wk) in w.iter().enumerate() {
                    let g = (f as i64 + k as i64 - n as i64).clamp(0, frames as i64 - 1) as usize;
                    let src: &[f32] = if g <= f {
                        let s = g % (n + 1);
                        &ring[s * width..(s + 1) * width]
                    } else if g < b {
                        let o = (g - f - 1) * width;
                        &after[o..o + width]
                    } else {
                        let o = (g - b) * width;
                        &ahead[o..o + width]
                    };
                    if k == 0 {
                        for (d, s) in dst.iter_mut().zip(src) {
                            *d = wk * s;
                        }
                    } else {
                        for (d, s) in dst.iter_mut().zip(src) {
                            *d += wk * s;
                        }
                    }
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smoothing_weights_sum_to_one() {
        for n in 0..6 {
            let w = smoothing_weights(n);
            assert_eq!(w.len(), 2 * n + 1);
            let s: f32 = w.iter().sum();
            assert!((s - 1.0).abs() < 1e-6, "N = {n}: sum {s}");
            // Symmetric and peaked at the centre.
            for k in 0..n {
                assert_eq!(w[k], w[2 * n - k]);
                assert!(w[k] < w[k + 1]);
            }
        }
        // N = 2: raw weights (1 − (n/3)²)² = 25/81, 64/81, 1, 64/81, 25/81.
        let w = smoothing_weights(2);
        let total = (2.0 * 25.0 + 2.0 * 64.0 + 81.0) / 81.0;
        assert!((w[2] - 1.0 / total).abs() < 1e-6);
        assert!((w[0] - 25.0 / 81.0 / total).abs() < 1e-6);
    }

    #[test]
    fn smoothing_is_identity_for_n0_and_constant_signals() {
        let v: Vec<f32> = (0..12).map(|i| (i as f32).sin()).collect();
        assert_eq!(smooth_in_time(&v, 4, 3, 0), v);
        let c = vec![0.7f32; 15];
        for x in smooth_in_time(&c, 5, 3, 2) {
            assert!((x - 0.7).abs() < 1e-6);
        }
    }

    #[test]
    fn causal_smoothing_reads_only_the_past() {
        let w = causal_smoothing_weights(2);
        assert_eq!(w.len(), 3);
        assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        // A step at frame 3: frames 0..=2 stay 0 in causal mode (offline, frame 2 sees it).
        let v = [0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
        let c = smooth_in_time_causal(&v, 6, 1, 2);
        assert_eq!(&c[..3], &[0.0, 0.0, 0.0]);
        assert!((c[3] - w[2]).abs() < 1e-6 && (c[5] - 1.0).abs() < 1e-6);
        assert!(smooth_in_time(&v, 6, 1, 2)[2] > 0.0);
        assert_eq!(smooth_in_time_causal(&v, 6, 1, 0), v);
    }

    /// In place, in runs of frames with rings and halos, gives the bits of the buffer-to-buffer
    /// smoothing, offline and causal, for runs shorter and longer than the window.
    #[test]
    fn smoothing_in_place_equals_smoothing_into_a_new_buffer() {
        let (width, n) = (5, 2);
        for frames in [2, 3, 7, 40] {
            let v: Vec<f32> = (0..frames * width)
                .map(|i| ((i * 7919) % 101) as f32 / 50.0 - 1.0)
                .collect();
            for causal in [false, true] {
                let want = smooth_columns(&v, frames, width, 0..width, n, causal);
                let mut got = v.clone();
                smooth_in_place(&mut got, frames, width, n, causal);
                assert_eq!(got, want, "{frames} frames, causal {causal}");
                for per_run in [1, 2, 3, 16] {
                    let mut got = v.clone();
                    smooth_runs(&mut got, frames, width, n, causal, per_run);
                    assert_eq!(
                        got, want,
                        "{frames} frames, runs of {per_run}, causal {causal}"
                    );
                }
            }
        }
        let mut single = vec![1.0, 2.0];
        smooth_in_place(&mut single, 1, 2, n, false);
        assert_eq!(single, [1.0, 2.0]);
    }

    #[test]
    fn smoothing_clamps_at_the_ends() {
        // A step at the last frame: frame 0 sees only clamped copies of frames 0..=2.
        let v = [0.0, 0.0, 0.0, 1.0];
        let s = smooth_in_time(&v, 4, 1, 2);
        let w = smoothing_weights(2);
        assert_eq!(s[0], 0.0);
        assert!((s[3] - (w[2] + w[3] + w[4])).abs() < 1e-6);
        assert!((s[1] - w[4]).abs() < 1e-6);
    }
}
