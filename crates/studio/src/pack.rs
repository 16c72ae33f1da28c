//! Binary responses: geometry goes to the page as little-endian float32 (and uint32 index)
//! buffers after a JSON header.
//!
//! Layout: `u32` header length `H`, `H` bytes of JSON (space-padded to a multiple of 4),
//! then the buffers back to back. The header is the caller's JSON object plus
//! `"buffers": [{"name", "type": "f32"|"u32"|"i16"|"u8", "offset", "count"}]` (offset in bytes from the
//! start of the data, count in elements), so the page can view each one as a typed array
//! without copying.
//!
//! The response body goes out as chunks (the header, then the buffers as written), so a
//! clip of a few hundred megabytes is neither copied into one more buffer at the end nor,
//! for buffers [`Pack::shared`] hands over, copied at all: the server's peak memory stays
//! near what it holds anyway.

use std::convert::Infallible;

use axum::body::{Body, Bytes};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use serde_json::{json, Map, Value};

/// A chunk holding this many bytes is ended before a buffer written value by value: that
/// buffer grows by doubling its chunk, and a grown chunk of earlier buffers would be copied
/// and held twice (a 23 MB whole-clip answer reached 31 MB of blocks).
const CHUNK_BYTES: usize = 1 << 20;

/// Buffers collected for one binary response.
#[derive(Debug, Default)]
pub struct Pack {
    entries: Vec<Value>,
    /// Finished chunks of the data, in order.
    chunks: Vec<Bytes>,
    /// The chunk being written.
    data: Vec<u8>,
    /// Bytes in `chunks`.
    written: usize,
    /// Values dropped once the response is sent ([`Pack::keep`]).
    kept: Kept,
}

/// What a response keeps until it is sent (a memory reservation).
#[derive(Default)]
struct Kept(Vec<Box<dyn std::any::Any + Send>>);

impl std::fmt::Debug for Kept {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Kept({})", self.0.len())
    }
}

impl Pack {
    /// An empty pack.
    pub fn new() -> Pack {
        Pack::default()
    }

    /// The offset of the next buffer from the start of the data.
    fn offset(&self) -> usize {
        self.written + self.data.len()
    }

    /// Adds a float32 buffer.
    pub fn f32(&mut self, name: &str, values: impl IntoIterator<Item = f32>) -> &mut Pack {
        let values = values.into_iter();
        self.start_buffer(values.size_hint().0 * size_of::<f32>());
        let offset = self.offset();
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
        let offset = self.offset();
        let slices: Vec<&[f32]> = slices.into_iter().collect();
        // Reserved exactly: a growing buffer would hold its old and new block at once.
        self.end_large_chunk();
        self.data
            .reserve_exact(4 * slices.iter().map(|s| s.len()).sum::<usize>());
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

    /// Adds a float32 buffer without copying it: `owner` keeps the values alive until the
    /// response is sent (e.g. a clip the server holds anyway, behind an `Arc`), `values`
    /// reads them.
    pub fn shared<T: Send + 'static>(
        &mut self,
        name: &str,
        owner: T,
        values: fn(&T) -> &[f32],
    ) -> &mut Pack {
        let offset = self.offset();
        let count = values(&owner).len();
        if cfg!(target_endian = "little") {
            self.flush();
            self.written += 4 * count;
            self.chunks
                .push(Bytes::from_owner(F32Bytes { owner, values }));
        } else {
            let v = values(&owner);
            self.data.extend(v.iter().flat_map(|v| v.to_le_bytes()));
        }
        self.entry(name, "f32", offset, count)
    }

    /// Keeps `value` until the response is sent or dropped (the memory reservation of the
    /// job whose results the buffers copy).
    pub fn keep<T: Send + 'static>(&mut self, value: T) -> &mut Pack {
        self.kept.0.push(Box::new(value));
        self
    }

    /// Before a buffer of at least `bytes`: ends a large chunk (its growth would copy the
    /// buffers before), then reserves them.
    fn start_buffer(&mut self, bytes: usize) {
        self.end_large_chunk();
        self.data.reserve(bytes);
    }

    /// Ends the chunk being written when it holds [`CHUNK_BYTES`] or more.
    fn end_large_chunk(&mut self) {
        if self.data.len() >= CHUNK_BYTES {
            self.flush();
        }
    }

    /// Ends the chunk being written.
    fn flush(&mut self) {
        if !self.data.is_empty() {
            let data = std::mem::take(&mut self.data);
            self.written += data.len();
            self.chunks.push(Bytes::from(data));
        }
    }

    /// Adds a uint32 buffer.
    pub fn u32(&mut self, name: &str, values: impl IntoIterator<Item = u32>) -> &mut Pack {
        let values = values.into_iter();
        self.start_buffer(values.size_hint().0 * size_of::<u32>());
        let offset = self.offset();
        let mut count = 0usize;
        for v in values {
            self.data.extend_from_slice(&v.to_le_bytes());
            count += 1;
        }
        self.entry(name, "u32", offset, count)
    }

    /// Adds a uint8 buffer made of `parts` one after the other (a frame each), copied into one
    /// chunk and zero-padded to a multiple of 4 bytes (the buffers after it stay aligned for
    /// the page's typed arrays).
    pub fn u8_parts(&mut self, name: &str, parts: Vec<Vec<u8>>) -> &mut Pack {
        let offset = self.offset();
        let count: usize = parts.iter().map(Vec::len).sum();
        self.end_large_chunk();
        self.data.reserve_exact(count + 3);
        for part in parts {
            self.data.extend_from_slice(&part);
        }
        self.data.resize(self.data.len() + (4 - count % 4) % 4, 0);
        self.entry(name, "u8", offset, count)
    }

    /// Adds a uint32 buffer handed over without copying (copied as [`Pack::u32`] on a
    /// big-endian machine).
    pub fn u32_vec(&mut self, name: &str, values: Vec<u32>) -> &mut Pack {
        if cfg!(target_endian = "big") || values.is_empty() {
            return self.u32(name, values);
        }
        let offset = self.offset();
        let count = values.len();
        self.flush();
        self.written += 4 * count;
        self.chunks.push(Bytes::from_owner(PodBytes(values)));
        self.entry(name, "u32", offset, count)
    }

    /// Adds an int16 buffer (zero-padded to a multiple of 4 bytes, so the buffers after it
    /// stay aligned for the page's typed arrays).
    pub fn i16(&mut self, name: &str, values: impl IntoIterator<Item = i16>) -> &mut Pack {
        let values = values.into_iter();
        self.start_buffer(values.size_hint().0 * size_of::<i16>());
        let offset = self.offset();
        let mut count = 0usize;
        for v in values {
            self.data.extend_from_slice(&v.to_le_bytes());
            count += 1;
        }
        if count % 2 == 1 {
            self.data.extend_from_slice(&[0, 0]);
        }
        self.entry(name, "i16", offset, count)
    }

    fn entry(&mut self, name: &str, kind: &str, offset: usize, count: usize) -> &mut Pack {
        self.entries.push(json!({
            "name": name, "type": kind, "offset": offset, "count": count
        }));
        self
    }

    /// The header chunk (length and JSON) and the data chunks: `header` (a JSON object) gains
    /// `"buffers"`.
    fn chunks(mut self, header: Value) -> Vec<Bytes> {
        self.flush();
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
        let mut head = Vec::with_capacity(4 + text.len());
        head.extend_from_slice(&(text.len() as u32).to_le_bytes());
        head.extend_from_slice(&text);
        let mut out = Vec::with_capacity(1 + self.chunks.len());
        out.push(Bytes::from(head));
        out.extend(self.chunks);
        out
    }

    /// The bytes in one buffer (tests and tools; a response sends the chunks as they are).
    pub fn finish(self, header: Value) -> Vec<u8> {
        self.chunks(header).concat()
    }

    /// The bytes as an `application/octet-stream` response, sent chunk by chunk.
    pub fn response(mut self, header: Value) -> Response {
        let kept = std::mem::take(&mut self.kept);
        let chunks = self.chunks(header);
        let length: usize = chunks.iter().map(Bytes::len).sum();
        // The stream owns what was kept: dropped with the body, once sent or abandoned.
        let stream = futures_util::stream::iter(chunks.into_iter().map(move |c| {
            let _kept = &kept;
            Ok::<_, Infallible>(c)
        }));
        (
            [
                (header::CONTENT_TYPE, "application/octet-stream".to_string()),
                (header::CONTENT_LENGTH, length.to_string()),
            ],
            Body::from_stream(stream),
        )
            .into_response()
    }
}

/// A float32 buffer's bytes borrowed from the value that holds it ([`Pack::shared`]).
struct F32Bytes<T> {
    owner: T,
    values: fn(&T) -> &[f32],
}

impl<T> AsRef<[u8]> for F32Bytes<T> {
    fn as_ref(&self) -> &[u8] {
        bytemuck::cast_slice((self.values)(&self.owner))
    }
}

/// A vector's values as the bytes of a response chunk ([`Pack::u32_vec`]).
struct PodBytes<T>(Vec<T>);

impl<T: bytemuck::Pod> AsRef<[u8]> for PodBytes<T> {
    fn as_ref(&self) -> &[u8] {
        bytemuck::cast_slice(&self.0)
    }
}

/// Points as their x, y, z coordinates, without copying.
pub fn coordinates(points: &[anim::glam::Vec3]) -> &[f32] {
    bytemuck::cast_slice(points)
}

/// The header and the bytes of the buffer `name` of type `ty` (`size` bytes per value).
fn read_raw<'a>(bytes: &'a [u8], name: &str, ty: &str, size: usize) -> Option<(Value, &'a [u8])> {
    let (header, data) = split(bytes)?;
    let entry = header["buffers"]
        .as_array()?
        .iter()
        .find(|b| b["name"] == name && b["type"] == ty)?;
    let offset = entry["offset"].as_u64()? as usize;
    let count = entry["count"].as_u64()? as usize;
    let raw = data.get(offset..offset + count * size)?;
    Some((header, raw))
}

/// Reads a pack back: the header and the named float32 buffer (for tests and tools).
pub fn read_f32(bytes: &[u8], name: &str) -> Option<(Value, Vec<f32>)> {
    let (header, raw) = read_raw(bytes, name, "f32", 4)?;
    let values = raw
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    Some((header, values))
}

/// Reads a pack back: the named uint32 buffer (for tests and tools).
pub fn read_u32(bytes: &[u8], name: &str) -> Option<Vec<u32>> {
    let (_, raw) = read_raw(bytes, name, "u32", 4)?;
    Some(
        raw.chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect(),
    )
}

/// Reads a pack back: the named uint8 buffer (for tests and tools).
pub fn read_u8(bytes: &[u8], name: &str) -> Option<Vec<u8>> {
    read_raw(bytes, name, "u8", 1).map(|(_, raw)| raw.to_vec())
}

/// Appends `value` as a zigzag LEB128 integer (a `u8` buffer's values such as
/// `body.varints`): `2|v|` or `2|v| − 1` for a negative `v`, 7 bits a byte from the lowest,
/// the high bit set on every byte but the last — 1 byte below 64 in size, 2 below 8,192, 3
/// below 2²⁰.
#[inline]
pub(crate) fn push_zigzag_varint(out: &mut Vec<u8>, value: i32) {
    let mut z = ((value << 1) ^ (value >> 31)) as u32;
    while z >= 0x80 {
        out.push((z as u8) | 0x80);
        z >>= 7;
    }
    out.push(z as u8);
}

/// The zigzag LEB128 integers of a `u8` buffer such as `body.varints`
/// ([`push_zigzag_varint`]), for tests and tools. A last integer cut short reads as what it
/// holds.
pub fn zigzag_varints(bytes: &[u8]) -> Vec<i32> {
    let (mut out, mut z, mut shift) = (Vec::new(), 0u32, 0);
    for &b in bytes {
        z |= u32::from(b & 0x7f).checked_shl(shift).unwrap_or(0);
        shift += 7;
        if b & 0x80 == 0 {
            out.push((z >> 1) as i32 ^ -((z & 1) as i32));
            (z, shift) = (0, 0);
        }
    }
    out
}

/// Reads a pack back: the named int16 buffer (for tests and tools).
pub fn read_i16(bytes: &[u8], name: &str) -> Option<Vec<i16>> {
    let (_, raw) = read_raw(bytes, name, "i16", 2)?;
    Some(
        raw.chunks_exact(2)
            .map(|c| i16::from_le_bytes([c[0], c[1]]))
            .collect(),
    )
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
    fn varints_hold_every_step_count_in_as_few_bytes_as_its_size_needs() {
        let values = [0, 1, -1, 63, -64, 64, -65, 8191, -8192, 8192];
        let values = [&values[..], &[(1 << 20) - 1, -(1 << 22), 1 << 22]].concat();
        let mut bytes = Vec::new();
        let mut sizes = Vec::new();
        for &v in &values {
            let before = bytes.len();
            push_zigzag_varint(&mut bytes, v);
            sizes.push(bytes.len() - before);
        }
        assert_eq!(zigzag_varints(&bytes), values);
        assert_eq!(sizes, [1, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 4, 4]);
    }

    #[test]
    fn a_pack_reads_back() {
        let mut p = Pack::new();
        p.u32("tri", [0, 1, 2]).f32("pos", [1.5, -2.0]);
        p.f32_slices("frames", [&[0.25f32, 3.0][..], &[-7.5][..]]);
        let held = std::sync::Arc::new(vec![4.0f32, 5.0, 6.0]);
        p.shared("held", held.clone(), |v| &v[..]);
        p.u32("after", [9]);
        p.i16("small", [-3, 7, 1]).u32("aligned", [5]);
        p.u8_parts("parts", vec![vec![1, 254], vec![], vec![3]])
            .u32_vec("words", vec![6, 7]);
        let bytes = p.finish(json!({"frames": 3}));
        let (header, pos) = read_f32(&bytes, "pos").unwrap();
        assert_eq!(pos, vec![1.5, -2.0]);
        assert_eq!(read_f32(&bytes, "frames").unwrap().1, vec![0.25, 3.0, -7.5]);
        assert_eq!(read_f32(&bytes, "held").unwrap().1, *held);
        assert_eq!(header["buffers"][3]["offset"], 32);
        assert_eq!(header["buffers"][4]["offset"], 44);
        assert_eq!(header["frames"], 3);
        assert_eq!(header["buffers"][5]["type"], "i16");
        assert_eq!(header["buffers"][6]["offset"], 56);
        assert_eq!(read_u32(&bytes, "aligned").unwrap(), vec![5]);
        assert_eq!(read_i16(&bytes, "small").unwrap(), vec![-3, 7, 1]);
        assert_eq!(read_u8(&bytes, "parts").unwrap(), vec![1, 254, 3]);
        // Three bytes and one of padding: the next buffer is aligned.
        assert_eq!(header["buffers"][8]["offset"], 64);
        assert_eq!(read_u32(&bytes, "words").unwrap(), vec![6, 7]);
        assert_eq!(header["buffers"][1]["offset"], 12);
        let len = u32::from_le_bytes(bytes[..4].try_into().unwrap()) as usize;
        assert_eq!(len % 4, 0);
    }
}
