//! Binary responses: geometry goes to the page as little-endian float32 (and uint32 index)
//! buffers after a JSON header.
//!
//! Layout: `u32` header length `H`, `H` bytes of JSON (space-padded to a multiple of 4),
//! then the buffers back to back. The header is the caller's JSON object plus
//! `"buffers": [{"name", "type": "f32"|"u32", "offset", "count"}]` (offset in bytes from the
//! start of the data, count in elements), so the page can view each one as a typed array
//! without copying.

use axum::http::header;
use axum::response::{IntoResponse, Response};
use serde_json::{json, Map, Value};

/// Buffers collected for one binary response.
#[derive(Debug, Default)]
pub struct Pack {
    entries: Vec<Value>,
    data: Vec<u8>,
}

impl Pack {
    /// An empty pack.
    pub fn new() -> Pack {
        Pack::default()
    }

    /// Adds a float32 buffer.
    pub fn f32(&mut self, name: &str, values: impl IntoIterator<Item = f32>) -> &mut Pack {
        let offset = self.data.len();
        let mut count = 0usize;
        for v in values {
            self.data.extend_from_slice(&v.to_le_bytes());
            count += 1;
        }
        self.entry(name, "f32", offset, count)
    }

    /// Adds a float32 buffer from contiguous slices (frame-major geometry): copied as bytes,
    /// not value by value.
    pub fn f32_slices<'a>(
        &mut self,
        name: &str,
        slices: impl IntoIterator<Item = &'a [f32]>,
    ) -> &mut Pack {
        let offset = self.data.len();
        let mut count = 0usize;
        for s in slices {
            if cfg!(target_endian = "little") {
                self.data.extend_from_slice(bytemuck::cast_slice(s));
            } else {
                self.data.extend(s.iter().flat_map(|v| v.to_le_bytes()));
            }
            count += s.len();
        }
        self.entry(name, "f32", offset, count)
    }

    /// Adds a uint32 buffer.
    pub fn u32(&mut self, name: &str, values: impl IntoIterator<Item = u32>) -> &mut Pack {
        let offset = self.data.len();
        let mut count = 0usize;
        for v in values {
            self.data.extend_from_slice(&v.to_le_bytes());
            count += 1;
        }
        self.entry(name, "u32", offset, count)
    }

    fn entry(&mut self, name: &str, kind: &str, offset: usize, count: usize) -> &mut Pack {
        self.entries.push(json!({
            "name": name, "type": kind, "offset": offset, "count": count
        }));
        self
    }

    /// The bytes: `header` (a JSON object) gains `"buffers"`.
    pub fn finish(self, header: Value) -> Vec<u8> {
        let mut object = match header {
            Value::Object(m) => m,
            other => {
                let mut m = Map::new();
                m.insert("value".into(), other);
                m
            }
        };
        object.insert("buffers".into(), Value::Array(self.entries));
        let mut text = Value::Object(object).to_string().into_bytes();
        while !text.len().is_multiple_of(4) {
            text.push(b' ');
        }
        let mut out = Vec::with_capacity(4 + text.len() + self.data.len());
        out.extend_from_slice(&(text.len() as u32).to_le_bytes());
        out.extend_from_slice(&text);
        out.extend_from_slice(&self.data);
        out
    }

    /// The bytes as an `application/octet-stream` response.
    pub fn response(self, header: Value) -> Response {
        (
            [(header::CONTENT_TYPE, "application/octet-stream")],
            self.finish(header),
        )
            .into_response()
    }
}

/// Points as their x, y, z coordinates, without copying.
pub fn coordinates(points: &[anim::glam::Vec3]) -> &[f32] {
    bytemuck::cast_slice(points)
}

/// Reads a pack back: the header and the named float32 buffer (for tests and tools).
pub fn read_f32(bytes: &[u8], name: &str) -> Option<(Value, Vec<f32>)> {
    let (header, data) = split(bytes)?;
    let entry = header["buffers"]
        .as_array()?
        .iter()
        .find(|b| b["name"] == name && b["type"] == "f32")?;
    let offset = entry["offset"].as_u64()? as usize;
    let count = entry["count"].as_u64()? as usize;
    let raw = data.get(offset..offset + count * 4)?;
    let values = raw
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    Some((header, values))
}

/// Splits a pack into its header and data.
pub fn split(bytes: &[u8]) -> Option<(Value, &[u8])> {
    let len = u32::from_le_bytes(bytes.get(..4)?.try_into().ok()?) as usize;
    let header: Value = serde_json::from_slice(bytes.get(4..4 + len)?).ok()?;
    Some((header, bytes.get(4 + len..)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pack_reads_back() {
        let mut p = Pack::new();
        p.u32("tri", [0, 1, 2]).f32("pos", [1.5, -2.0]);
        p.f32_slices("frames", [&[0.25f32, 3.0][..], &[-7.5][..]]);
        let bytes = p.finish(json!({"frames": 3}));
        let (header, pos) = read_f32(&bytes, "pos").unwrap();
        assert_eq!(pos, vec![1.5, -2.0]);
        assert_eq!(read_f32(&bytes, "frames").unwrap().1, vec![0.25, 3.0, -7.5]);
        assert_eq!(header["frames"], 3);
        assert_eq!(header["buffers"][1]["offset"], 12);
        let len = u32::from_le_bytes(bytes[..4].try_into().unwrap()) as usize;
        assert_eq!(len % 4, 0);
    }
}
