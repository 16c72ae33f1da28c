//! PC2 point caches (3ds Max / Blender "Mesh Cache" modifier format).
//!
//! Layout, little-endian:
//!
//! | bytes | field |
//! |---|---|
//! | 12 | magic `POINTCACHE2\0` |
//! | 4 | `i32` version = 1 |
//! | 4 | `i32` number of points |
//! | 4 | `f32` start frame |
//! | 4 | `f32` sample rate (frames between two samples) |
//! | 4 | `i32` number of samples |
//! | 12 × points × samples | `f32` x, y, z, sample-major |
//!
//! The file stores *frame numbers*, not seconds, so the scene frame rate `fps` is an argument
//! of [`read`]: sample `k` is at frame `start + k × rate`, i.e. at time
//! `(start + k × rate) / fps` seconds. The resulting [`MeshAnimation`] therefore has
//! `fps / rate` samples per second and `start_time = start / fps`. [`write()`] writes
//! `rate = 1` and `start = start_time × fps` (what Blender writes), so
//! `read(&write(a), mesh, a.fps)` reproduces `a`.

use anim::{Mesh, MeshAnimation};
use glam::Vec3;

use crate::{IoError, Result};

/// The 12-byte magic at the start of every PC2 file.
pub const MAGIC: &[u8; 12] = b"POINTCACHE2\0";
/// Size of the fixed header in bytes.
pub const HEADER_LEN: usize = 32;
const FORMAT: &str = "PC2";
/// Frames per sample a cache may have: wide for real caches (Blender writes 1), narrow enough
/// that the frame rate derived from it stays an ordinary number.
pub const SAMPLE_RATES: std::ops::RangeInclusive<f32> = 1e-4..=1e4;

/// The fixed header of a PC2 file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pc2Header {
    /// Vertices per sample.
    pub points: usize,
    /// Frame number of the first sample.
    pub start_frame: f32,
    /// Frames between two samples (1 = one sample per frame).
    pub sample_rate: f32,
    /// Number of samples.
    pub samples: usize,
}

/// Reads and checks the header: magic, version, non-negative counts, finite positive rate,
/// and a file length of exactly `32 + 12 × points × samples` bytes.
///
/// # Errors
/// [`IoError::Malformed`] naming the first inconsistency.
pub fn read_header(bytes: &[u8]) -> Result<Pc2Header> {
    if bytes.len() < HEADER_LEN {
        return Err(IoError::malformed(
            FORMAT,
            format!(
                "file is {} bytes, shorter than the 32-byte header",
                bytes.len()
            ),
        ));
    }
    if &bytes[..12] != MAGIC {
        return Err(IoError::malformed(FORMAT, "missing POINTCACHE2 magic"));
    }
    let i32_at =
        |o: usize| i32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
    let f32_at = |o: usize| f32::from_bits(i32_at(o) as u32);
    let version = i32_at(12);
    if version != 1 {
        return Err(IoError::malformed(
            FORMAT,
            format!("version {version}, expected 1"),
        ));
    }
    let count = |v: i32, what: &str| {
        usize::try_from(v)
            .map_err(|_| IoError::malformed(FORMAT, format!("negative {what} count {v}")))
    };
    let points = count(i32_at(16), "point")?;
    let start_frame = f32_at(20);
    let sample_rate = f32_at(24);
    let samples = count(i32_at(28), "sample")?;
    if !(SAMPLE_RATES.contains(&sample_rate)) {
        return Err(IoError::malformed(
            FORMAT,
            format!(
                "sample rate {sample_rate} (frames per sample) is outside {}..{}",
                SAMPLE_RATES.start(),
                SAMPLE_RATES.end()
            ),
        ));
    }
    // The start in samples is what a re-write stores (at one sample per frame): it must stay
    // finite too.
    if !(start_frame.is_finite() && (start_frame / sample_rate).is_finite()) {
        return Err(IoError::malformed(
            FORMAT,
            format!("start frame {start_frame} at sample rate {sample_rate} is not finite"),
        ));
    }
    let need = points
        .checked_mul(samples)
        .and_then(|n| n.checked_mul(12))
        .and_then(|n| n.checked_add(HEADER_LEN));
    if need != Some(bytes.len()) {
        return Err(IoError::malformed(
            FORMAT,
            format!(
                "header says {points} points × {samples} samples, which needs {} bytes, but the \
                 file has {} bytes",
                need.map_or_else(|| "more than 2^64".to_string(), |n| n.to_string()),
                bytes.len()
            ),
        ));
    }
    Ok(Pc2Header {
        points,
        start_frame,
        sample_rate,
        samples,
    })
}

/// Reads a PC2 cache onto the topology of `rest`.
///
/// # Arguments
/// * `bytes` – the whole file.
/// * `rest` – the mesh the cache deforms (e.g. the OBJ the cache was exported with); its
///   vertex count must equal the file's point count. It is stored unchanged as
///   [`MeshAnimation::mesh`].
/// * `fps` – the scene frame rate the file's frame numbers refer to (see the module docs).
///
/// # Returns
/// A cache with `samples` frames at `fps / sample_rate` frames per second, starting at
/// `start_frame / fps` seconds.
///
/// # Errors
/// Malformed header or length, a point count different from `rest`, no sample, a
/// non-finite position, or a non-positive `fps`.
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
    if h.samples == 0 || h.points == 0 {
        return Err(IoError::malformed(FORMAT, "cache holds no sample"));
    }
    if !(fps.is_finite() && fps > 0.0) {
        return Err(IoError::unsupported(format!(
            "frame rate must be positive, got {fps}"
        )));
    }
    let positions = decode_le_vec3(&bytes[HEADER_LEN..])
        .ok_or_else(|| IoError::malformed(FORMAT, "a position is NaN or infinite"))?;
    let mut anim = MeshAnimation::new(rest, fps / h.sample_rate, positions)?;
    anim.start_time = h.start_frame / fps;
    Ok(anim)
}

/// Decodes little-endian `f32` triples; `None` when a value is not finite.
pub(crate) fn decode_le_vec3(bytes: &[u8]) -> Option<Vec<Vec3>> {
    bytes
        .chunks_exact(12)
        .map(|c| {
            let f = |o: usize| f32::from_le_bytes([c[o], c[o + 1], c[o + 2], c[o + 3]]);
            let v = Vec3::new(f(0), f(4), f(8));
            v.is_finite().then_some(v)
        })
        .collect()
}

/// Writes a cache as PC2 with `sample_rate = 1` and `start_frame = start_time × fps`.
///
/// # Returns
/// The file bytes (`32 + 12 × vertices × frames`). Counts beyond `i32::MAX` cannot be
/// stored by the format; such caches (over 25 GB) are not supported.
pub fn write(anim: &MeshAnimation) -> Vec<u8> {
    let positions = anim.positions();
    let mut out = Vec::with_capacity(HEADER_LEN + positions.len() * 12);
    out.extend_from_slice(&header_bytes(
        anim.vertex_count(),
        positions.len() / anim.vertex_count().max(1),
        anim.start_time,
        anim.fps,
    ));
    for p in positions {
        for c in p.to_array() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    out
}

/// The header of a cache of `frames` frames of `vertices` vertices starting at
/// `start_time` seconds (one sample per frame).
pub(crate) fn header_bytes(vertices: usize, frames: usize, start_time: f32, fps: f32) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_LEN);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&1i32.to_le_bytes());
    out.extend_from_slice(&clamp_i32(vertices).to_le_bytes());
    // In f64 and clamped: the product of two valid f32 can overflow f32.
    let start = (start_time as f64 * fps as f64).clamp(f32::MIN as f64, f32::MAX as f64);
    out.extend_from_slice(&(start as f32).to_le_bytes());
    out.extend_from_slice(&1.0f32.to_le_bytes());
    out.extend_from_slice(&clamp_i32(frames).to_le_bytes());
    out
}

pub(crate) fn clamp_i32(n: usize) -> i32 {
    i32::try_from(n).unwrap_or(i32::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> Mesh {
        Mesh::new("tri", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]])
    }

    fn cache() -> MeshAnimation {
        let pos = (0..4)
            .flat_map(|f| (0..3).map(move |v| Vec3::new(f as f32 * 0.1, v as f32, -1.5)))
            .collect();
        let mut a = MeshAnimation::new(tri(), 30.0, pos).unwrap();
        a.start_time = 2.0 / 30.0;
        a
    }

    #[test]
    fn write_then_read_is_exact() {
        let a = cache();
        let bytes = write(&a);
        assert_eq!(bytes.len(), 32 + 12 * 3 * 4);
        let h = read_header(&bytes).unwrap();
        assert_eq!((h.points, h.samples, h.sample_rate), (3, 4, 1.0));
        assert!((h.start_frame - 2.0).abs() < 1e-5);
        let b = read(&bytes, tri(), 30.0).unwrap();
        assert_eq!(b.positions(), a.positions());
        assert_eq!(b.fps, 30.0);
        assert!((b.start_time - a.start_time).abs() < 1e-6);
    }

    #[test]
    fn sample_rate_divides_fps() {
        let mut bytes = write(&cache());
        bytes[24..28].copy_from_slice(&2.0f32.to_le_bytes());
        let b = read(&bytes, tri(), 24.0).unwrap();
        assert_eq!(b.fps, 12.0);
    }

    #[test]
    fn huge_header_is_an_error_not_an_allocation() {
        let mut bytes = write(&cache());
        bytes[16..20].copy_from_slice(&i32::MAX.to_le_bytes());
        bytes[28..32].copy_from_slice(&i32::MAX.to_le_bytes());
        let e = read(&bytes, tri(), 24.0).unwrap_err().to_string();
        assert!(e.contains("needs"), "{e}");
    }

    #[test]
    fn truncated_nan_and_wrong_mesh_are_errors() {
        let bytes = write(&cache());
        assert!(read(&bytes[..bytes.len() - 1], tri(), 24.0).is_err());
        assert!(read(&bytes[..10], tri(), 24.0).is_err());
        let mut nan = bytes.clone();
        nan[40..44].copy_from_slice(&f32::NAN.to_le_bytes());
        let e = read(&nan, tri(), 24.0).unwrap_err().to_string();
        assert!(e.contains("NaN"), "{e}");
        let quad = Mesh::new("q", vec![Vec3::ZERO; 4], vec![]);
        assert!(read(&bytes, quad, 24.0).is_err());
        assert!(read(&bytes, tri(), 0.0).is_err());
    }
}
