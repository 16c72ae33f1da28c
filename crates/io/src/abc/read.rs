//! Reading Alembic archives of polygon meshes back (the files toonkit writes, and files of the
//! same shape from other tools): every `PolyMesh` under the top object with its per-frame
//! points, faces and vertex colours.

use anim::glam::Vec3;

use super::ogawa::{malformed, Node, Reader};
use super::schema::{self, Kind, Pod, PropertyHeader};
use crate::Result;

/// An Alembic archive read back.
#[derive(Debug, Clone, PartialEq)]
pub struct AbcArchive {
    /// Seconds between two frames of the meshes' time sampling.
    pub frame_seconds: f64,
    /// Time of the first frame, in seconds.
    pub start_seconds: f64,
    /// The polygon meshes, in file order.
    pub meshes: Vec<AbcMesh>,
}

/// One `PolyMesh` object.
#[derive(Debug, Clone, PartialEq)]
pub struct AbcMesh {
    /// Object name.
    pub name: String,
    /// One entry per sample.
    pub frames: Vec<AbcFrame>,
}

/// One sample of a mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct AbcFrame {
    /// Vertex positions (`P`).
    pub points: Vec<Vec3>,
    /// Vertices per face (`.faceCounts`).
    pub face_counts: Vec<u32>,
    /// Face vertex indices, turned back to counter-clockwise order (glTF's and USD's).
    pub face_indices: Vec<u32>,
    /// Per-vertex RGBA (`.arbGeomParams/Cd`), when written.
    pub colors: Option<Vec<[f32; 4]>>,
    /// The object's `visible` property at this frame (true when absent).
    pub visible: bool,
}

/// Most bytes [`read`] decodes (points, faces, colours of every sample of every mesh).
/// Alembic stores a repeated sample once, so a file of a few hundred bytes can declare
/// millions of samples of the same data: past this budget the archive is refused rather than
/// expanded into gigabytes.
pub const MAX_DECODED_BYTES: usize = 512 << 20;

/// Reads an archive from its bytes.
///
/// # Errors
/// [`crate::IoError::Malformed`] for anything that is not a well-formed Ogawa archive of
/// polygon meshes (truncated, bad offsets, unexpected types), or one that decodes to more
/// than [`MAX_DECODED_BYTES`]. Never panics.
pub fn read(bytes: &[u8]) -> Result<AbcArchive> {
    read_with_limit(bytes, MAX_DECODED_BYTES)
}

/// [`read`] with another decoding budget: `max_decoded_bytes` replaces
/// [`MAX_DECODED_BYTES`] (a fuzzer or a server takes a few MiB so that every input stays
/// cheap; a farm job reading a long cache may take more).
///
/// # Errors
/// As [`read`], with `max_decoded_bytes` as the budget.
pub fn read_with_limit(bytes: &[u8], max_decoded_bytes: usize) -> Result<AbcArchive> {
    let (r, root) = Reader::open(bytes)?;
    let top = r.children(root)?;
    if top.len() < 6 {
        return Err(malformed(
            "the archive's root group has fewer than 6 children",
        ));
    }
    let samplings = time_samplings(r.data(top[4])?)?;
    let objects = r.children(top[2])?;
    let Some((&headers, children)) = objects.split_last() else {
        return Err(malformed("the top object is empty"));
    };
    let names = object_names(r.data(headers)?)?;
    let mut meshes = Vec::new();
    let mut sampling = None;
    let mut budget = max_decoded_bytes;
    for (name, object) in names.into_iter().zip(children.iter().skip(1)) {
        let (mesh, ts) = polymesh(&r, *object, name, &mut budget, max_decoded_bytes)?;
        sampling = sampling.or(Some(ts));
        meshes.push(mesh);
    }
    let (frame_seconds, start_seconds) = sampling
        .and_then(|ts| samplings.get(ts as usize).copied())
        .unwrap_or((1.0, 0.0));
    Ok(AbcArchive {
        frame_seconds,
        start_seconds,
        meshes,
    })
}

/// `(time per cycle, first time)` of every time sampling.
fn time_samplings(bytes: &[u8]) -> Result<Vec<(f64, f64)>> {
    let mut c = Cursor { bytes, at: 0 };
    let mut out = Vec::new();
    while c.at < bytes.len() {
        let _max_samples = c.u32()?;
        let per_cycle = f64::from_le_bytes(c.take(8)?.try_into().unwrap_or_default());
        let count = c.u32()? as usize;
        let times = c.take(
            count
                .checked_mul(8)
                .ok_or_else(|| malformed("time sampling"))?,
        )?;
        let first = times.get(..8).map_or(0.0, |t| {
            f64::from_le_bytes(t.try_into().unwrap_or_default())
        });
        out.push((per_cycle, first));
    }
    Ok(out)
}

/// Names of the objects listed in an object-headers block (the last 32 bytes are hashes).
fn object_names(bytes: &[u8]) -> Result<Vec<String>> {
    let body = &bytes[..bytes.len().saturating_sub(32)];
    let mut c = Cursor { bytes: body, at: 0 };
    let mut names = Vec::new();
    while c.at < body.len() {
        let n = c.u32()? as usize;
        names.push(String::from_utf8_lossy(c.take(n)?).into_owned());
        let index = c.take(1)?[0];
        if u32::from(index) == schema::INLINE_METADATA {
            let m = c.u32()? as usize;
            c.take(m)?;
        }
    }
    Ok(names)
}

/// Headers of a compound property and the nodes of its children.
fn compound(r: &Reader, node: Node) -> Result<Vec<(PropertyHeader, Node)>> {
    let kids = r.children(node)?;
    let Some((&headers, groups)) = kids.split_last() else {
        return Ok(Vec::new());
    };
    let headers = property_headers(r.data(headers)?)?;
    if headers.len() > groups.len() {
        return Err(malformed("more property headers than properties"));
    }
    Ok(headers.into_iter().zip(groups.iter().copied()).collect())
}

fn property_headers(bytes: &[u8]) -> Result<Vec<PropertyHeader>> {
    use schema::info;
    let mut c = Cursor { bytes, at: 0 };
    let mut out = Vec::new();
    while c.at < bytes.len() {
        let word = c.u32()?;
        let hint = (word & info::SIZE_HINT) >> 2;
        let kind = match word & info::KIND {
            0 => Kind::Compound,
            1 => Kind::Scalar,
            _ => Kind::Array,
        };
        let mut h = PropertyHeader {
            name: String::new(),
            kind,
            pod: (word & info::POD) >> 4,
            extent: (word & info::EXTENT) >> 12,
            samples: 0,
            first_changed: 0,
            last_changed: 0,
            time_sampling: 0,
            homogenous: word & info::HOMOGENOUS != 0,
            metadata: String::new(),
        };
        if kind != Kind::Compound {
            h.samples = c.sized(hint)?;
            if word & info::FIRST_LAST != 0 {
                h.first_changed = c.sized(hint)?;
                h.last_changed = c.sized(hint)?;
            } else if word & info::CONSTANT == 0 {
                h.first_changed = 1;
                h.last_changed = h.samples.saturating_sub(1);
            }
            if word & info::HAS_TIME_SAMPLING != 0 {
                h.time_sampling = c.sized(hint)?;
            }
        }
        let n = c.sized(hint)? as usize;
        h.name = String::from_utf8_lossy(c.take(n)?).into_owned();
        if (word & info::METADATA) >> 20 == schema::INLINE_METADATA {
            let m = c.sized(hint)? as usize;
            h.metadata = String::from_utf8_lossy(c.take(m)?).into_owned();
        }
        out.push(h);
    }
    Ok(out)
}

/// One `PolyMesh` object; also returns the time sampling index of its points. Every decoded
/// sample is charged to `budget`, the bytes left of the archive's whole budget `limit`.
fn polymesh(
    r: &Reader,
    object: Node,
    name: String,
    budget: &mut usize,
    limit: usize,
) -> Result<(AbcMesh, u32)> {
    let kids = r.children(object)?;
    let props = compound(r, *kids.first().ok_or_else(|| malformed("empty object"))?)?;
    let find = |props: &[(PropertyHeader, Node)], n: &str| {
        props.iter().find(|(h, _)| h.name == n).cloned()
    };
    let (_, geom) = find(&props, ".geom")
        .ok_or_else(|| malformed(format!("object '{name}' is not a PolyMesh (no .geom)")))?;
    let geom = compound(r, geom)?;
    let need =
        |n: &str| find(&geom, n).ok_or_else(|| malformed(format!("PolyMesh '{name}' has no {n}")));
    let p = need("P")?;
    let indices = need(".faceIndices")?;
    let counts = need(".faceCounts")?;
    let colors = match find(&geom, ".arbGeomParams") {
        Some((_, node)) => find(&compound(r, node)?, "Cd"),
        None => None,
    };
    let visible = find(&props, "visible");
    let too_big = || {
        malformed(format!(
            "the samples decode to more than {} MiB (PolyMesh '{name}' declares {} samples)",
            limit as f64 / f64::from(1u32 << 20),
            p.0.samples
        ))
    };
    // Every sample costs at least its frame record: refuse absurd counts before decoding.
    if (p.0.samples as usize).saturating_mul(std::mem::size_of::<AbcFrame>()) > *budget {
        return Err(too_big());
    }
    let frames = (0..p.0.samples)
        .map(|f| {
            let points = floats(&sample(r, &p, f, Pod::Float32)?);
            let counts: Vec<u32> = ints(&sample(r, &counts, f, Pod::Int32)?);
            let mut indices: Vec<u32> = ints(&sample(r, &indices, f, Pod::Int32)?);
            let mut at = 0usize;
            for &c in &counts {
                let end = at.saturating_add(c as usize);
                let face = indices
                    .get_mut(at..end)
                    .ok_or_else(|| malformed("face counts exceed the face indices"))?;
                face.reverse();
                at = end;
            }
            let colors = match &colors {
                Some(c) => Some(
                    floats(&sample(r, c, f, Pod::Float32)?)
                        .chunks_exact(4)
                        .map(|c| [c[0], c[1], c[2], c[3]])
                        .collect(),
                ),
                None => None,
            };
            let visible = match &visible {
                Some(v) => sample(r, v, f, Pod::Int8)?.first().is_none_or(|&b| b != 0),
                None => true,
            };
            let size = std::mem::size_of::<AbcFrame>()
                + 4 * (points.len() + counts.len() + indices.len())
                + colors.as_ref().map_or(0, |c: &Vec<[f32; 4]>| 16 * c.len());
            *budget = budget.checked_sub(size).ok_or_else(too_big)?;
            Ok(AbcFrame {
                points: points
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2]))
                    .collect(),
                face_counts: counts,
                face_indices: indices,
                colors,
                visible,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((AbcMesh { name, frames }, p.0.time_sampling))
}

/// The values of frame `f` of a property, without the 16-byte key; checks the data type.
fn sample(r: &Reader, (h, node): &(PropertyHeader, Node), f: u32, pod: Pod) -> Result<Vec<u8>> {
    if Pod::from_code(h.pod) != Some(pod) {
        return Err(malformed(format!(
            "property {} has data type {}",
            h.name, h.pod
        )));
    }
    let stride = if h.kind == Kind::Array { 2 } else { 1 };
    let kids = r.children(*node)?;
    let at = h.stored_index(f) as usize * stride;
    let data = r.data(*kids.get(at).ok_or_else(|| malformed("missing sample"))?)?;
    let values = data.get(16..).unwrap_or_default();
    if values.len() % (pod.size() * h.extent.max(1) as usize) != 0 {
        return Err(malformed(format!(
            "property {} has a partial value",
            h.name
        )));
    }
    Ok(values.to_vec())
}

fn floats(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

fn ints(bytes: &[u8]) -> Vec<u32> {
    bytes
        .chunks_exact(4)
        .map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]).max(0) as u32)
        .collect()
}

/// A bounds-checked reader of little-endian fields.
struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&e| e <= self.bytes.len())
            .ok_or_else(|| malformed("a header runs past its block"))?;
        let out = &self.bytes[self.at..end];
        self.at = end;
        Ok(out)
    }

    fn u32(&mut self) -> Result<u32> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    /// A size written with a size hint: 0 → 1 byte, 1 → 2 bytes, else 4 bytes.
    fn sized(&mut self, hint: u32) -> Result<u32> {
        Ok(match hint {
            0 => u32::from(self.take(1)?[0]),
            1 => {
                let b = self.take(2)?;
                u32::from(u16::from_le_bytes([b[0], b[1]]))
            }
            _ => self.u32()?,
        })
    }
}
