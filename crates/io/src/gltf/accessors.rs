//! The buffer and accessor half of the glTF writer: typed arrays packed into one 4-byte
//! aligned binary chunk, one buffer view per accessor, correct `min`/`max` bounds, and
//! identical data stored once.
//!
//! Deduplication: every accessor is keyed by its element type, component type, normalization,
//! usage, bounds flag and the bytes themselves (a deterministic hash, then a byte comparison);
//! a repeat returns the first accessor. Flipbooks repeat their triangles, UVs, painted
//! attributes, still frames and animation timelines in every frame, so this shrinks them a lot
//! while the output stays byte-identical for identical input.

use std::borrow::Cow;
use std::collections::HashMap;
use std::hash::{DefaultHasher, Hasher};

use anim::glam::Vec3;
use gltf_json as json;
use json::accessor::{ComponentType, Type};
use json::validation::Checked::Valid;
use json::validation::USize64;
use serde_json::json as js;

use crate::{IoError, Result};

/// Largest index written as UNSIGNED_SHORT: glTF 2.0 §3.7.2.1 forbids the type's maximum
/// (65535, a primitive-restart value) in index data.
pub(crate) const MAX_U16_INDEX: u32 = 65534;

/// What an accessor is used for. It decides the buffer view's target, and accessors of
/// different usages are never shared (the Khronos validator rejects an accessor or buffer
/// view whose usage changes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Usage {
    /// A vertex attribute (`ARRAY_BUFFER`).
    Vertex,
    /// Triangle indices (`ELEMENT_ARRAY_BUFFER`).
    Index,
    /// Key times of an animation sampler.
    AnimationInput,
    /// Values of an animation sampler.
    AnimationOutput,
    /// Inverse bind matrices of a skin.
    InverseBind,
}

/// Everything but the bytes that must match for two accessors to be one.
#[derive(Clone, Copy, PartialEq, Eq)]
struct Key {
    ty: Type,
    component: ComponentType,
    normalized: bool,
    usage: Usage,
    bounds: bool,
    count: usize,
    /// Byte stride of the buffer view (padded vertex attributes), `None` when tight.
    stride: Option<usize>,
}

/// A stored accessor: its key, where its bytes are in the chunk, its index.
struct Stored {
    key: Key,
    offset: usize,
    len: usize,
    index: json::Index<json::Accessor>,
}

/// Accumulates a glTF document and its binary chunk.
pub(crate) struct Builder {
    /// The document being built.
    pub root: json::Root,
    bin: Vec<u8>,
    /// Accessors by hash of their bytes.
    stored: HashMap<u64, Vec<Stored>>,
    /// The shared opaque material, once created.
    pub opaque: Option<json::Index<json::Material>>,
    /// The shared alpha-blended material, once created.
    pub blend: Option<json::Index<json::Material>>,
}

impl Builder {
    pub(crate) fn new() -> Builder {
        let mut root = json::Root::default();
        root.asset.generator = Some(format!("toonkit {}", env!("CARGO_PKG_VERSION")));
        root.buffers.push(json::Buffer {
            byte_length: USize64(0),
            name: None,
            uri: None,
            extensions: None,
            extras: Default::default(),
        });
        Builder {
            root,
            bin: Vec::new(),
            stored: HashMap::new(),
            opaque: None,
            blend: None,
        }
    }

    /// Appends `bytes` as a new buffer view at a 4-byte aligned offset.
    fn view(
        &mut self,
        bytes: &[u8],
        usage: Usage,
        stride: Option<usize>,
    ) -> (json::Index<json::buffer::View>, usize) {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        let target = match usage {
            Usage::Vertex => Some(Valid(json::buffer::Target::ArrayBuffer)),
            Usage::Index => Some(Valid(json::buffer::Target::ElementArrayBuffer)),
            _ => None,
        };
        let view = self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64(bytes.len() as u64),
            byte_offset: Some(USize64(offset as u64)),
            byte_stride: stride.map(json::buffer::Stride),
            name: None,
            target,
            extensions: None,
            extras: Default::default(),
        });
        (view, offset)
    }

    /// An accessor over `bytes`, or the earlier identical one.
    ///
    /// # Arguments
    /// * `bounds` — computes `[min, max]` per component when the data is new; called only then.
    ///
    /// # Performance
    /// One hash pass over `bytes`; a byte comparison on a hash hit.
    fn accessor(
        &mut self,
        bytes: &[u8],
        key: Key,
        bounds: impl FnOnce() -> (Vec<f32>, Vec<f32>),
    ) -> json::Index<json::Accessor> {
        let mut h = DefaultHasher::new(); // fixed keys: deterministic
        h.write(bytes);
        let hash = h.finish();
        if let Some(list) = self.stored.get(&hash) {
            let bin = &self.bin;
            if let Some(s) = list.iter().find(|s| {
                s.key == key && s.len == bytes.len() && bin[s.offset..][..s.len] == *bytes
            }) {
                return s.index;
            }
        }
        let (view, offset) = self.view(bytes, key.usage, key.stride);
        let (min, max) = if key.bounds {
            let (a, b) = bounds();
            (Some(js!(a)), Some(js!(b)))
        } else {
            (None, None)
        };
        let index = self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64(key.count as u64),
            component_type: Valid(json::accessor::GenericComponentType(key.component)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(key.ty),
            min,
            max,
            name: None,
            normalized: key.normalized,
            sparse: None,
        });
        self.stored.entry(hash).or_default().push(Stored {
            key,
            offset,
            len: bytes.len(),
            index,
        });
        index
    }

    /// Float accessor of `n`-component items (1–4, or 16 for matrices), with min/max bounds
    /// when asked. Non-finite values are written as 0 (the validator rejects NaN/∞).
    pub(crate) fn floats(
        &mut self,
        data: &[f32],
        n: usize,
        usage: Usage,
        bounds: bool,
    ) -> json::Index<json::Accessor> {
        let ty = match n {
            1 => Type::Scalar,
            2 => Type::Vec2,
            3 => Type::Vec3,
            4 => Type::Vec4,
            _ => Type::Mat4,
        };
        let finite = |x: f32| if x.is_finite() { x } else { 0.0 };
        let bytes: Vec<u8> = data.iter().flat_map(|&f| finite(f).to_le_bytes()).collect();
        let key = Key {
            ty,
            component: ComponentType::F32,
            normalized: false,
            usage,
            bounds,
            count: data.len() / n,
            stride: None,
        };
        self.accessor(&bytes, key, || {
            let mut lo = vec![f32::INFINITY; n];
            let mut hi = vec![f32::NEG_INFINITY; n];
            for item in data.chunks_exact(n) {
                for k in 0..n {
                    lo[k] = lo[k].min(finite(item[k]));
                    hi[k] = hi[k].max(finite(item[k]));
                }
            }
            (lo, hi)
        })
    }

    /// VEC3 float vertex attribute.
    pub(crate) fn vec3s(&mut self, data: &[Vec3], bounds: bool) -> json::Index<json::Accessor> {
        let flat: Vec<f32> = data.iter().flat_map(|v| v.to_array()).collect();
        self.floats(&flat, 3, Usage::Vertex, bounds)
    }

    /// Triangle indices: UNSIGNED_SHORT when every index is at most [`MAX_U16_INDEX`]
    /// (half the bytes), else UNSIGNED_INT.
    pub(crate) fn indices(&mut self, tris: &[[u32; 3]]) -> json::Index<json::Accessor> {
        let flat = tris.iter().flatten();
        let short = flat.clone().all(|&i| i <= MAX_U16_INDEX);
        let bytes: Vec<u8> = if short {
            flat.flat_map(|&i| (i as u16).to_le_bytes()).collect()
        } else {
            flat.flat_map(|i| i.to_le_bytes()).collect()
        };
        let key = Key {
            ty: Type::Scalar,
            component: if short {
                ComponentType::U16
            } else {
                ComponentType::U32
            },
            normalized: false,
            usage: Usage::Index,
            bounds: false,
            count: tris.len() * 3,
            stride: None,
        };
        self.accessor(&bytes, key, no_bounds)
    }

    /// VEC4 UNSIGNED_SHORT joint indices.
    pub(crate) fn joints(&mut self, data: &[[u16; 4]]) -> json::Index<json::Accessor> {
        let bytes: Vec<u8> = data
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let key = Key {
            ty: Type::Vec4,
            component: ComponentType::U16,
            normalized: false,
            usage: Usage::Vertex,
            bounds: false,
            count: data.len(),
            stride: None,
        };
        self.accessor(&bytes, key, no_bounds)
    }

    /// RGBA colours as VEC4 normalized UNSIGNED_SHORT (`round(c · 65535)`, clamped to
    /// [0, 1], NaN → 0): half the bytes of floats, round-trip error ≤ 1/131070.
    pub(crate) fn colors(&mut self, data: &[[f32; 4]]) -> json::Index<json::Accessor> {
        let bytes: Vec<u8> = data
            .iter()
            .flatten()
            .flat_map(|&c| quantize_u16(c).to_le_bytes())
            .collect();
        let key = Key {
            ty: Type::Vec4,
            component: ComponentType::U16,
            normalized: true,
            usage: Usage::Vertex,
            bounds: false,
            count: data.len(),
            stride: None,
        };
        self.accessor(&bytes, key, no_bounds)
    }

    /// VEC3 of normalized signed integers (`KHR_mesh_quantization`): SHORT (`short`) or BYTE
    /// from values in [−1, 1] (`round(x · max)`, clamped; non-finite → 0), each element
    /// padded to four components (stride 8 or 4) as glTF requires of vertex attributes.
    /// Bounds, when asked, are the integer values (glTF 2.0 §3.6.2: in the component type).
    pub(crate) fn snorm_vec3s(
        &mut self,
        data: &[Vec3],
        short: bool,
        bounds: bool,
    ) -> json::Index<json::Accessor> {
        let max = if short { 32767.0 } else { 127.0 };
        let q = |x: f32| {
            if x.is_finite() {
                (x * max).round().clamp(-max, max) as i32
            } else {
                0
            }
        };
        let ints: Vec<[i32; 3]> = data.iter().map(|v| [q(v.x), q(v.y), q(v.z)]).collect();
        let mut bytes = Vec::with_capacity(data.len() * if short { 8 } else { 4 });
        for v in &ints {
            for &c in v.iter().chain([0].iter()) {
                if short {
                    bytes.extend((c as i16).to_le_bytes());
                } else {
                    bytes.push(c as i8 as u8);
                }
            }
        }
        let key = Key {
            ty: Type::Vec3,
            component: if short {
                ComponentType::I16
            } else {
                ComponentType::I8
            },
            normalized: true,
            usage: Usage::Vertex,
            bounds,
            count: data.len(),
            stride: Some(if short { 8 } else { 4 }),
        };
        self.accessor(&bytes, key, || {
            let mut lo = vec![f32::INFINITY; 3];
            let mut hi = vec![f32::NEG_INFINITY; 3];
            for v in &ints {
                for k in 0..3 {
                    lo[k] = lo[k].min(v[k] as f32);
                    hi[k] = hi[k].max(v[k] as f32);
                }
            }
            (lo, hi)
        })
    }

    /// Serializes to GLB bytes.
    pub(crate) fn finish(mut self) -> Result<Vec<u8>> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        if self.bin.is_empty() {
            self.root.buffers.clear();
        } else {
            self.root.buffers[0].byte_length = USize64(self.bin.len() as u64);
        }
        let json = json::serialize::to_vec(&self.root)
            .map_err(|e| IoError::unsupported(format!("cannot serialize glTF: {e}")))?;
        if self.bin.len() + json.len() > u32::MAX as usize - 64 {
            return Err(IoError::unsupported(
                "the result exceeds the 4 GiB limit of a .glb file",
            ));
        }
        let glb = gltf::binary::Glb {
            header: gltf::binary::Header {
                magic: *b"glTF",
                version: 2,
                length: 0,
            },
            json: Cow::Owned(json),
            bin: (!self.bin.is_empty()).then_some(Cow::Owned(self.bin)),
        };
        glb.to_vec()
            .map_err(|e| IoError::unsupported(format!("cannot write GLB: {e}")))
    }
}

/// Bounds of an accessor written without them (never called: its key has `bounds: false`).
fn no_bounds() -> (Vec<f32>, Vec<f32>) {
    (Vec::new(), Vec::new())
}

/// A colour channel in [0, 1] as a normalized UNSIGNED_SHORT; NaN → 0.
fn quantize_u16(c: f32) -> u16 {
    // `as` saturates and maps NaN to 0.
    (c.clamp(0.0, 1.0) * 65535.0).round() as u16
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_data_is_one_accessor_and_other_usage_is_not() {
        let mut b = Builder::new();
        let a = b.floats(&[1.0, 2.0, 3.0], 1, Usage::Vertex, false);
        let again = b.floats(&[1.0, 2.0, 3.0], 1, Usage::Vertex, false);
        let input = b.floats(&[1.0, 2.0, 3.0], 1, Usage::AnimationInput, true);
        let other = b.floats(&[1.0, 2.0, 4.0], 1, Usage::Vertex, false);
        assert_eq!(a, again);
        assert_ne!(a, input);
        assert_ne!(a, other);
        assert_eq!(b.root.accessors.len(), 3);
        assert_eq!(b.root.buffer_views.len(), 3);
        assert_eq!(b.bin.len(), 3 * 12);
    }

    #[test]
    fn indices_are_short_below_65535_vertices() {
        let mut b = Builder::new();
        b.indices(&[[0, 1, MAX_U16_INDEX]]);
        b.indices(&[[0, 1, MAX_U16_INDEX + 1]]);
        let types: Vec<_> = b
            .root
            .accessors
            .iter()
            .map(|a| match a.component_type {
                Valid(json::accessor::GenericComponentType(c)) => Some(c),
                _ => None,
            })
            .collect();
        assert_eq!(types, [Some(ComponentType::U16), Some(ComponentType::U32)]);
        assert_eq!(b.bin.len(), 8 + 12, "6 bytes padded to 8, then 12");
    }

    #[test]
    fn colors_quantize_to_nearest_u16_and_nan_to_zero() {
        assert_eq!(quantize_u16(1.0), 65535);
        assert_eq!(quantize_u16(2.0), 65535);
        assert_eq!(quantize_u16(-1.0), 0);
        assert_eq!(quantize_u16(f32::NAN), 0);
        assert_eq!(quantize_u16(0.5), 32768);
    }
}
