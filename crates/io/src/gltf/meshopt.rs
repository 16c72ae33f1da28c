//! `EXT_meshopt_compression` (and its `KHR_meshopt_compression` successor with the same
//! layout): every buffer view whose data is meshopt-encoded is decoded with the
//! `meshoptimizer-rs` codec (a Rust port of meshoptimizer's decoders, filters included) into a
//! new plain buffer, and the view is pointed at it. What remains is an ordinary glTF document.

use std::borrow::Cow;

use meshoptimizer_rs::codec::{BufferView, Filter, Mode};
use meshoptimizer_rs::Workspace;
use serde_json::{json, Map, Value};

use crate::{IoError, Result};

const NAMES: [&str; 2] = ["EXT_meshopt_compression", "KHR_meshopt_compression"];

fn bad(view: usize, message: impl std::fmt::Display) -> IoError {
    IoError::malformed(
        "glTF",
        format!("buffer view {view} (EXT_meshopt_compression): {message}"),
    )
}

fn field(ext: &Value, key: &str) -> Option<usize> {
    ext.get(key).and_then(Value::as_u64).map(|v| v as usize)
}

/// Decodes every meshopt-compressed buffer view of `root` in place; decoded data is
/// appended to `buffers` (and to `root`'s buffer list).
///
/// # Errors
/// When a view's compressed range lies outside its buffer, its mode or filter is unknown,
/// or the data does not decode.
pub(crate) fn decode(
    root: &mut Map<String, Value>,
    buffers: &mut Vec<Cow<'_, [u8]>>,
) -> Result<()> {
    let mut workspace = Workspace::default();
    let mut new_buffers = Vec::new();
    let first_new = buffers.len();
    if let Some(views) = root.get_mut("bufferViews").and_then(Value::as_array_mut) {
        for (v, view) in views.iter_mut().enumerate() {
            let Some(obj) = view.as_object_mut() else {
                continue;
            };
            let Some((name, ext)) =
                obj.get("extensions")
                    .and_then(Value::as_object)
                    .and_then(|e| {
                        NAMES
                            .iter()
                            .find_map(|n| e.get(*n).map(|x| (*n, x.clone())))
                    })
            else {
                continue;
            };
            let (Some(buffer), Some(length), Some(stride), Some(count)) = (
                field(&ext, "buffer"),
                field(&ext, "byteLength"),
                field(&ext, "byteStride"),
                field(&ext, "count"),
            ) else {
                return Err(bad(
                    v,
                    "buffer, byteLength, byteStride and count are required",
                ));
            };
            let offset = field(&ext, "byteOffset").unwrap_or(0);
            let mode = ext.get("mode").and_then(Value::as_str).unwrap_or_default();
            let filter = ext.get("filter").and_then(Value::as_str).unwrap_or("NONE");
            let mode = Mode::parse(mode).map_err(|_| bad(v, format!("unknown mode {mode:?}")))?;
            let filter =
                Filter::parse(filter).map_err(|_| bad(v, format!("unknown filter {filter:?}")))?;
            let source = buffers
                .get(buffer)
                .and_then(|b| b.get(offset..offset.checked_add(length)?))
                .ok_or_else(|| bad(v, "compressed data lies outside its buffer"))?;
            let layout = BufferView::new(mode, filter, count, stride)
                .map_err(|e| bad(v, format!("{e:?}")))?;
            let decoded = layout
                .decode(source, &mut workspace)
                .map_err(|e| bad(v, format!("cannot decode: {e:?}")))?;
            let index = first_new + new_buffers.len();
            obj.insert("buffer".into(), json!(index));
            obj.insert("byteOffset".into(), json!(0));
            obj.insert("byteLength".into(), json!(decoded.len()));
            if let Some(exts) = obj.get_mut("extensions").and_then(Value::as_object_mut) {
                exts.remove(name);
            }
            new_buffers.push(decoded);
        }
    }
    if new_buffers.is_empty() {
        return Ok(());
    }
    let list = root
        .entry("buffers")
        .or_insert_with(|| Value::Array(Vec::new()));
    if let Some(list) = list.as_array_mut() {
        for b in &new_buffers {
            list.push(json!({ "byteLength": b.len() }));
        }
    }
    buffers.extend(new_buffers.into_iter().map(Cow::Owned));
    Ok(())
}
