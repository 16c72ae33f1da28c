//! MDD point caches (LightWave / Blender "Mesh Cache" modifier format).
//!
//! Layout, big-endian:
//!
//! | bytes | field |
//! |---|---|
//! | 4 | `i32` number of frames |
//! | 4 | `i32` number of points |
//! | 4 × frames | `f32` time of every frame in seconds |
//! | 12 × points × frames | `f32` x, y, z, frame-major |
//!
//! Blender's exporter writes the times `k / fps` starting at 0 and its importer ignores
//! them. [`read`] takes the frame rate and start time from the times when they are evenly
//! spaced and increasing (within 0.1 %), and otherwise falls back to the `fps` argument and
//! a start time of 0. [`write()`] writes `start_time + k / fps`.

use anim::{Mesh, MeshAnimation};
use glam::Vec3;

use crate::pc2::clamp_i32;
use crate::{IoError, Result};

const FORMAT: &str = "MDD";
/// Relative tolerance on the spacing of the frame times for them to define a frame rate.
pub const DEFAULT_TIME_SPACING_TOLERANCE: f32 = 1e-3;

/// The counts at the start of an MDD file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MddHeader {
    /// Number of frames.
    pub frames: usize,
    /// Vertices per frame.
    pub points: usize,
}

/// Reads the two counts and checks that the file length is exactly
/// `8 + 4 × frames + 12 × points × frames` bytes.
///
/// # Errors
/// [`IoError::Malformed`] when the file is shorter than 8 bytes, a count is negative, or the
/// length does not match.
pub fn read_header(bytes: &[u8]) -> Result<MddHeader> {
    if bytes.len() < 8 {
        return Err(IoError::malformed(
            FORMAT,
            format!(
                "file is {} bytes, shorter than the 8-byte header",
                bytes.len()
            ),
        ));
    }
    let i32_at =
        |o: usize| i32::from_be_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
    let count = |v: i32, what: &str| {
        usize::try_from(v)
            .map_err(|_| IoError::malformed(FORMAT, format!("negative {what} count {v}")))
    };
    let frames = count(i32_at(0), "frame")?;
    let points = count(i32_at(4), "point")?;
    let need = points
        .checked_mul(12)
        .and_then(|n| n.checked_add(4))
        .and_then(|n| n.checked_mul(frames))
        .and_then(|n| n.checked_add(8));
    if need != Some(bytes.len()) {
        return Err(IoError::malformed(
            FORMAT,
            format!(
                "header says {frames} frames × {points} points, which needs {} bytes, but the \
                 file has {} bytes",
                need.map_or_else(|| "more than 2^64".to_string(), |n| n.to_string()),
                bytes.len()
            ),
        ));
    }
    Ok(MddHeader { frames, points })
}

/// Reads an MDD cache onto the topology of `rest`.
///
/// # Arguments
/// * `bytes` – the whole file.
/// * `rest` – the mesh the cache deforms; its vertex count must equal the file's point count.
///   It is stored unchanged as [`MeshAnimation::mesh`].
/// * `fps` – frame rate used when the file's times do not define one (a single frame, or
///   times that are not evenly spaced and increasing).
///
/// # Errors
/// Malformed header or length, a point count different from `rest`, no frame, or a
/// non-finite time or position.
pub fn read(bytes: &[u8], rest: Mesh, fps: f32) -> Result<MeshAnimation> {
    let h = read_header(bytes)?;
    if h.points != rest.vertex_count() {
        return Err(IoError::malformed(
            FORMAT,
            format!(
                "cache has {} points but the mesh '{}' has {} vertices",
                h.points,
                rest.name,
                rest.vertex_count()
            ),
        ));
    }
    if h.frames == 0 || h.points == 0 {
        return Err(IoError::malformed(FORMAT, "cache holds no frame"));
    }
    let be = |c: &[u8], o: usize| f32::from_be_bytes([c[o], c[o + 1], c[o + 2], c[o + 3]]);
    let times_end = 8 + 4 * h.frames;
    let times: Vec<f32> = bytes[8..times_end]
        .chunks_exact(4)
        .map(|c| be(c, 0))
        .collect();
    if !times.iter().all(|t| t.is_finite()) {
        return Err(IoError::malformed(
            FORMAT,
            "a frame time is NaN or infinite",
        ));
    }
    let positions: Option<Vec<Vec3>> = bytes[times_end..]
        .chunks_exact(12)
        .map(|c| {
            let v = Vec3::new(be(c, 0), be(c, 4), be(c, 8));
            v.is_finite().then_some(v)
        })
        .collect();
    let positions =
        positions.ok_or_else(|| IoError::malformed(FORMAT, "a position is NaN or infinite"))?;
    let (rate, start) = match times_rate(&times) {
        Some(r) => (r, times[0]),
        None => (fps, 0.0),
    };
    if !(rate.is_finite() && rate > 0.0) {
        return Err(IoError::unsupported(format!(
            "frame rate must be positive, got {rate}"
        )));
    }
    let mut anim = MeshAnimation::new(rest, rate, positions)?;
    anim.start_time = start;
    Ok(anim)
}

/// The frame rate of evenly spaced increasing times, if they are.
fn times_rate(times: &[f32]) -> Option<f32> {
    let n = times.len();
    if n < 2 {
        return None;
    }
    let dt = (times[n - 1] as f64 - times[0] as f64) / (n - 1) as f64;
    if !(dt > 0.0 && dt.is_finite()) {
        return None;
    }
    let tol = DEFAULT_TIME_SPACING_TOLERANCE as f64 * dt;
    let even = times
        .windows(2)
        .all(|w| ((w[1] as f64 - w[0] as f64) - dt).abs() <= tol);
    let rate = (1.0 / dt) as f32;
    (even && rate.is_finite()).then_some(rate)
}

/// Writes a cache as MDD with times `start_time + k / fps` in seconds.
///
/// # Returns
/// The file bytes (`8 + 4 × frames + 12 × vertices × frames`).
pub fn write(anim: &MeshAnimation) -> Vec<u8> {
    let positions = anim.positions();
    let frames = positions.len() / anim.vertex_count().max(1);
    let mut out = Vec::with_capacity(8 + 4 * frames + 12 * positions.len());
    out.extend_from_slice(&clamp_i32(frames).to_be_bytes());
    out.extend_from_slice(&clamp_i32(anim.vertex_count()).to_be_bytes());
    for k in 0..frames {
        out.extend_from_slice(&anim.time_of(k).to_be_bytes());
    }
    for p in positions {
        for c in p.to_array() {
            out.extend_from_slice(&c.to_be_bytes());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> Mesh {
        Mesh::new("tri", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]])
    }

    fn cache(fps: f32) -> MeshAnimation {
        let pos = (0..5)
            .flat_map(|f| (0..3).map(move |v| Vec3::new(v as f32, f as f32 * 0.25, 3.0)))
            .collect();
        MeshAnimation::new(tri(), fps, pos).unwrap()
    }

    #[test]
    fn write_then_read_recovers_rate_from_times() {
        let a = cache(25.0);
        let bytes = write(&a);
        assert_eq!(bytes.len(), 8 + 4 * 5 + 12 * 15);
        assert_eq!(
            read_header(&bytes).unwrap(),
            MddHeader {
                frames: 5,
                points: 3
            }
        );
        // The fallback rate is ignored: the times say 25 fps.
        let b = read(&bytes, tri(), 60.0).unwrap();
        assert_eq!(b.positions(), a.positions());
        assert!((b.fps - 25.0).abs() < 1e-3, "{}", b.fps);
        assert_eq!(b.start_time, 0.0);
    }

    #[test]
    fn uneven_times_fall_back_to_argument() {
        let mut bytes = write(&cache(25.0));
        bytes[12..16].copy_from_slice(&0.5f32.to_be_bytes());
        let b = read(&bytes, tri(), 60.0).unwrap();
        assert_eq!(b.fps, 60.0);
    }

    #[test]
    fn corrupt_inputs_are_errors() {
        let bytes = write(&cache(24.0));
        assert!(read(&bytes[..bytes.len() - 4], tri(), 24.0).is_err());
        assert!(read(&bytes[..3], tri(), 24.0).is_err());
        let mut huge = bytes.clone();
        huge[0..4].copy_from_slice(&i32::MAX.to_be_bytes());
        huge[4..8].copy_from_slice(&i32::MAX.to_be_bytes());
        assert!(read(&huge, tri(), 24.0)
            .unwrap_err()
            .to_string()
            .contains("needs"));
        let mut neg = bytes.clone();
        neg[0..4].copy_from_slice(&(-1i32).to_be_bytes());
        assert!(read(&neg, tri(), 24.0)
            .unwrap_err()
            .to_string()
            .contains("negative"));
        let mut nan = bytes.clone();
        let last = nan.len() - 4;
        nan[last..].copy_from_slice(&f32::INFINITY.to_be_bytes());
        assert!(read(&nan, tri(), 24.0)
            .unwrap_err()
            .to_string()
            .contains("NaN or infinite"));
    }
}
