//! `KHR_draco_mesh_compression`: every primitive whose geometry is a Draco bitstream is decoded
//! with `draco-core` (a pure-Rust port of Google's Draco decoder) into plain buffer views, and
//! its accessors are pointed at them. The decoded attribute keeps Draco's component type
//! (quantized positions come back as floats); the primitive becomes an ordinary one.

use std::borrow::Cow;

use draco_core::{DataType, DecoderBuffer, FaceIndex, Mesh, MeshDecoder, PointIndex};
use serde_json::{json, Map, Value};

use crate::{IoError, Result};

const NAME: &str = "KHR_draco_mesh_compression";

fn bad(mesh: usize, message: impl std::fmt::Display) -> IoError {
    IoError::malformed("glTF", format!("mesh {mesh} ({NAME}): {message}"))
}

fn get(v: &Value, key: &str) -> Option<usize> {
    v.get(key).and_then(Value::as_u64).map(|v| v as usize)
}

/// glTF component type and byte size of a Draco data type.
fn component(t: DataType) -> Option<(u32, usize)> {
    Some(match t {
        DataType::Int8 => (5120, 1),
        DataType::Uint8 => (5121, 1),
        DataType::Int16 => (5122, 2),
        DataType::Uint16 => (5123, 2),
        DataType::Uint32 => (5125, 4),
        DataType::Float32 => (5126, 4),
        _ => return None,
    })
}

/// The compressed bytes of buffer view `view`.
fn view_bytes<'a>(
    root: &Map<String, Value>,
    buffers: &'a [Cow<'_, [u8]>],
    view: usize,
) -> Option<&'a [u8]> {
    let v = root.get("bufferViews")?.as_array()?.get(view)?;
    let offset = get(v, "byteOffset").unwrap_or(0);
    let len = get(v, "byteLength")?;
    buffers
        .get(get(v, "buffer")?)?
        .get(offset..offset.checked_add(len)?)
}

/// Appends `bytes` (4-byte aligned) to `out` as a new buffer view of buffer `buffer`.
fn push_view(
    views: &mut Vec<Value>,
    out: &mut Vec<u8>,
    buffer: usize,
    bytes: &[u8],
    stride: Option<usize>,
) -> usize {
    while !out.len().is_multiple_of(4) {
        out.push(0);
    }
    let mut v = json!({"buffer": buffer, "byteOffset": out.len(), "byteLength": bytes.len()});
    if let Some(s) = stride {
        v["byteStride"] = json!(s);
    }
    out.extend_from_slice(bytes);
    views.push(v);
    views.len() - 1
}

/// Decodes every Draco-compressed primitive of `root` in place; the decoded data is appended
/// to `buffers` as one new buffer. Returns whether any primitive was decoded.
///
/// # Errors
/// When a bitstream lies outside its buffer or does not decode, or an attribute it names is
/// missing from it.
pub(crate) fn decode(
    root: &mut Map<String, Value>,
    buffers: &mut Vec<Cow<'_, [u8]>>,
) -> Result<bool> {
    let buffer = buffers.len();
    let mut out = Vec::new();
    let mut views: Vec<Value> = root
        .get("bufferViews")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    let mut accessors: Vec<Value> = root
        .get("accessors")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    let mut meshes: Vec<Value> = root
        .get("meshes")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    let mut any = false;
    for (m, mesh) in meshes.iter_mut().enumerate() {
        let Some(prims) = mesh.get_mut("primitives").and_then(Value::as_array_mut) else {
            continue;
        };
        for prim in prims {
            let Some(ext) = prim
                .get_mut("extensions")
                .and_then(Value::as_object_mut)
                .and_then(|e| e.remove(NAME))
            else {
                continue;
            };
            let view = get(&ext, "bufferView").ok_or_else(|| bad(m, "no bufferView"))?;
            let bytes = view_bytes(root, buffers, view)
                .ok_or_else(|| bad(m, "the bitstream lies outside its buffer"))?;
            let mut decoded = Mesh::new();
            MeshDecoder::new()
                .decode(&mut DecoderBuffer::new(bytes), &mut decoded)
                .map_err(|e| bad(m, format!("cannot decode: {e:?}")))?;
            let points = decoded.num_points();
            if let Some(idx) = get(prim, "indices") {
                let mut ib = Vec::with_capacity(decoded.num_faces() * 12);
                for f in 0..decoded.num_faces() {
                    for p in decoded.face(FaceIndex(f as u32)) {
                        ib.extend(p.0.to_le_bytes());
                    }
                }
                let v = push_view(&mut views, &mut out, buffer, &ib, None);
                let acc = accessors
                    .get_mut(idx)
                    .ok_or_else(|| bad(m, "missing indices accessor"))?;
                acc["bufferView"] = json!(v);
                acc["byteOffset"] = json!(0);
                acc["componentType"] = json!(5125);
                acc["count"] = json!(decoded.num_faces() * 3);
            }
            let attrs = ext
                .get("attributes")
                .and_then(Value::as_object)
                .cloned()
                .unwrap_or_default();
            for (name, id) in attrs {
                let Some(id) = id.as_u64() else { continue };
                let Some(acc_index) = prim
                    .get("attributes")
                    .and_then(|a| a.get(&name))
                    .and_then(Value::as_u64)
                else {
                    continue;
                };
                let att = decoded.attribute_by_unique_id(id as u32).ok_or_else(|| {
                    bad(
                        m,
                        format!("attribute {name} ({id}) is not in the bitstream"),
                    )
                })?;
                let (ctype, size) = component(att.data_type())
                    .ok_or_else(|| bad(m, format!("attribute {name} has an unsupported type")))?;
                let comps = att.num_components() as usize;
                let stride = att.byte_stride() as usize;
                let elem = comps * size;
                let padded = elem.div_ceil(4) * 4;
                let data = att.buffer().data();
                let mut ab = Vec::with_capacity(points * padded);
                for p in 0..points {
                    let value = att.mapped_index(PointIndex(p as u32)).0 as usize;
                    let start = value * stride;
                    let src = data
                        .get(start..start + elem)
                        .ok_or_else(|| bad(m, format!("attribute {name} is truncated")))?;
                    ab.extend_from_slice(src);
                    ab.resize(ab.len() + padded - elem, 0);
                }
                let v = push_view(
                    &mut views,
                    &mut out,
                    buffer,
                    &ab,
                    (padded != elem).then_some(padded),
                );
                let acc = accessors
                    .get_mut(acc_index as usize)
                    .ok_or_else(|| bad(m, format!("missing {name} accessor")))?;
                acc["bufferView"] = json!(v);
                acc["byteOffset"] = json!(0);
                acc["componentType"] = json!(ctype);
                acc["count"] = json!(points);
            }
            any = true;
        }
    }
    if !any {
        return Ok(false);
    }
    root.insert("bufferViews".into(), Value::Array(views));
    root.insert("accessors".into(), Value::Array(accessors));
    root.insert("meshes".into(), Value::Array(meshes));
    let list = root
        .entry("buffers")
        .or_insert_with(|| Value::Array(Vec::new()));
    if let Some(list) = list.as_array_mut() {
        list.push(json!({ "byteLength": out.len() }));
    }
    buffers.push(Cow::Owned(out));
    Ok(true)
}
