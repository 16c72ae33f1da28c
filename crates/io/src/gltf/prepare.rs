//! Turns the glTF files animators have into what the `gltf` crate validates: required
//! extensions that do not change geometry or animation are accepted (and noted),
//! `EXT_meshopt_compression` buffer views are decoded into plain buffers,
//! `KHR_draco_mesh_compression` primitives are decoded (`draco`), `KHR_mesh_quantization`
//! integer attributes are left for `values` to read as floats, and what cannot be read
//! (an unknown extension that replaces the geometry) is refused in one line naming the
//! extension and how to convert the file.
//!
//! The rule for an extension toonkit does not know is general: if every primitive's
//! `POSITION` (and its indices) still lies in a buffer view or a sparse accessor, the
//! geometry is present and the extension is ignored with a note; otherwise the file is
//! refused naming the extension.

use std::borrow::Cow;
use std::path::Path;

use serde_json::{json, Map, Value};

use crate::{IoError, Result};

/// A document ready for the `gltf` crate, its buffers, and what was accepted on the way.
pub(crate) struct Prepared<'a> {
    /// The JSON root, without materials, textures and the extension lists.
    pub root: gltf_json::Root,
    /// The bytes of every buffer of `root` (decoded meshopt buffers appended); the GLB binary
    /// chunk is borrowed from the file's bytes, not copied.
    pub buffers: Vec<Cow<'a, [u8]>>,
    /// One line per extension the file uses and what toonkit did with it.
    pub notes: Vec<String>,
}

fn bad(message: impl Into<String>) -> IoError {
    IoError::malformed("glTF", message)
}

/// Extensions whose data is decoded here or read by the accessor readers.
const DECODED: &[(&str, &str)] = &[
    (
        "KHR_mesh_quantization",
        "quantized vertex data read as floats",
    ),
    ("EXT_meshopt_compression", "compressed buffer views decoded"),
    ("KHR_meshopt_compression", "compressed buffer views decoded"),
    (
        "KHR_draco_mesh_compression",
        "Draco-compressed geometry decoded",
    ),
];

/// Prefixes of extensions that only touch shading, lights or metadata.
const HARMLESS_PREFIXES: &[&str] = &[
    "KHR_materials_",
    "KHR_texture_",
    "EXT_texture_",
    "MSFT_texture_",
    "KHR_lights_",
    "EXT_lights_",
    "KHR_xmp",
    "EXT_materials_",
    "ADOBE_materials_",
];

/// How to get a file toonkit reads when `ext` replaces its geometry.
fn how_to_convert(ext: &str) -> String {
    format!(
        "toonkit cannot decode it; re-export the file without {ext} (e.g. Blender's glTF \
         export, or `gltfpack -i IN -o OUT`, whose meshopt compression toonkit reads)"
    )
}

/// The JSON and (GLB) binary chunk of a glTF file, borrowed from its bytes.
type Chunks<'a> = (Cow<'a, [u8]>, Option<Cow<'a, [u8]>>);

/// Splits `.glb` bytes into JSON and binary chunk; `.gltf` is all JSON.
fn split(bytes: &[u8]) -> Result<Chunks<'_>> {
    if bytes.starts_with(b"glTF") {
        // gltf 1.4 subtracts the 12-byte header from the declared length unchecked.
        let declared = bytes
            .get(8..12)
            .map_or(0, |l| u32::from_le_bytes([l[0], l[1], l[2], l[3]]));
        if declared < 12 {
            return Err(bad(format!(
                "the GLB header declares {declared} bytes, less than the header itself"
            )));
        }
        let glb = gltf::binary::Glb::from_slice(bytes).map_err(|e| bad(e.to_string()))?;
        Ok((glb.json, glb.bin))
    } else {
        Ok((Cow::Borrowed(bytes), None))
    }
}

fn names(v: &Value, key: &str) -> Vec<String> {
    v.get(key)
        .and_then(Value::as_array)
        .map(|a| {
            a.iter()
                .filter_map(Value::as_str)
                .map(str::to_string)
                .collect()
        })
        .unwrap_or_default()
}

/// Whether every triangle primitive's POSITION and indices are readable without `ext`.
fn geometry_present(root: &Value, ext: &str) -> bool {
    let accessors = root.get("accessors").and_then(Value::as_array);
    let readable = |i: &Value| {
        i.as_u64()
            .and_then(|i| accessors.and_then(|a| a.get(i as usize)))
            .is_some_and(|a| a.get("bufferView").is_some() || a.get("sparse").is_some())
    };
    let meshes = root.get("meshes").and_then(Value::as_array);
    meshes.into_iter().flatten().all(|m| {
        let prims = m.get("primitives").and_then(Value::as_array);
        prims.into_iter().flatten().all(|p| {
            let uses = p.get("extensions").and_then(|e| e.get(ext)).is_some();
            let pos = p.get("attributes").and_then(|a| a.get("POSITION"));
            let idx_ok = p.get("indices").is_none_or(readable);
            !uses && pos.is_none_or(readable) && idx_ok
        })
    })
}

/// What toonkit does with extension `ext` (required or not), or the one-line refusal.
fn classify(root: &Value, ext: &str, required: bool) -> Result<String> {
    if let Some((_, what)) = DECODED.iter().find(|(n, _)| *n == ext) {
        return Ok(format!("{ext}: {what}"));
    }
    if HARMLESS_PREFIXES.iter().any(|p| ext.starts_with(p)) {
        return Ok(format!(
            "{ext}: ignored (shading, lights or metadata; geometry and animation unchanged)"
        ));
    }
    if geometry_present(root, ext) {
        let kind = if required { "required" } else { "used" };
        return Ok(format!(
            "{ext}: {kind} but not read by toonkit; geometry and animation read without it"
        ));
    }
    Err(IoError::unsupported(format!(
        "the file needs glTF extension {ext} for its geometry: {}",
        how_to_convert(ext)
    )))
}

/// Removes what toonkit never reads (materials, textures, images, samplers, the
/// extension lists, animation channels that target a JSON pointer) so that their
/// extensions cannot make the `gltf` crate refuse the file.
fn strip(root: &mut Map<String, Value>, notes: &mut Vec<String>) {
    for key in [
        "materials",
        "textures",
        "images",
        "samplers",
        "extensionsRequired",
        "extensionsUsed",
        "extensions",
    ] {
        root.remove(key);
    }
    if let Some(meshes) = root.get_mut("meshes").and_then(Value::as_array_mut) {
        for m in meshes {
            if let Some(prims) = m.get_mut("primitives").and_then(Value::as_array_mut) {
                for p in prims.iter_mut().filter_map(Value::as_object_mut) {
                    p.remove("material");
                }
            }
        }
    }
    let mut dropped = 0;
    if let Some(anims) = root.get_mut("animations").and_then(Value::as_array_mut) {
        for a in anims {
            if let Some(ch) = a.get_mut("channels").and_then(Value::as_array_mut) {
                let before = ch.len();
                ch.retain(|c| {
                    c.get("target")
                        .and_then(|t| t.get("path"))
                        .and_then(Value::as_str)
                        != Some("pointer")
                });
                dropped += before - ch.len();
            }
        }
    }
    if dropped > 0 {
        notes.push(format!(
            "KHR_animation_pointer: {dropped} channel(s) animating material or camera \
             properties ignored"
        ));
    }
}

/// Reads buffer `i`'s bytes: the GLB chunk, a `data:` URI, or a file inside the document's
/// folder ([`external_buffer`]). A meshopt fallback buffer (no URI, no data) is empty.
fn load_buffer<'a>(
    i: usize,
    buffer: &Value,
    bin: &mut Option<Cow<'a, [u8]>>,
    base: Option<&Path>,
) -> Result<Cow<'a, [u8]>> {
    if let Some(uri) = buffer.get("uri").and_then(Value::as_str) {
        if !uri.starts_with("data:") {
            let byte_length = buffer
                .get("byteLength")
                .and_then(Value::as_u64)
                .unwrap_or(0);
            return external_buffer(i, uri, byte_length, base).map(Cow::Owned);
        }
        let data = gltf::buffer::Data::from_source(gltf::buffer::Source::Uri(uri), base)
            .map_err(|e| bad(format!("buffer {i}: {e}")))?;
        return Ok(Cow::Owned(data.0));
    }
    let fallback = buffer
        .get("extensions")
        .and_then(|e| e.get("EXT_meshopt_compression"))
        .and_then(|m| m.get("fallback"))
        .and_then(Value::as_bool)
        .unwrap_or(false);
    if fallback {
        return Ok(Cow::Borrowed(&[]));
    }
    match (i, bin.take()) {
        (0, Some(b)) => Ok(b),
        _ => Err(bad(format!(
            "buffer {i} has no uri and is not the GLB binary chunk"
        ))),
    }
}

/// The relative path an external URI names inside the document's folder, or why it may not
/// be read: toonkit reads only the files named and what they reference inside their own
/// folder (no absolute path, no `..`, no scheme such as `file:`).
///
/// # Errors
/// The one-line reason an external URI is refused (the caller adds the buffer and file).
pub fn confined_uri(uri: &str) -> std::result::Result<std::path::PathBuf, String> {
    let shown = format!("{:.80}", uri.escape_default().to_string());
    if uri.contains(':') {
        return Err(format!(
            "{shown} is not a file beside the .gltf (a URI with a scheme or a drive is not read): \
             keep the file in the .gltf's folder and name it relatively, or export a .glb"
        ));
    }
    let decoded = urlencoding::decode(uri)
        .map_err(|_| format!("its uri is not percent-encoded UTF-8: {shown}"))?;
    let rel = Path::new(decoded.as_ref());
    let inside = !decoded.is_empty()
        && !decoded.starts_with('\\')
        && rel.components().all(|c| {
            matches!(
                c,
                std::path::Component::Normal(_) | std::path::Component::CurDir
            )
        });
    if !inside {
        return Err(format!(
            "{shown} lies outside the .gltf's folder (absolute, or through ..): toonkit reads only \
             files inside it; copy the file next to the .gltf, or export a .glb"
        ));
    }
    Ok(rel.to_path_buf())
}

/// Reads the external buffer `uri` of `byte_length` bytes from inside `base`: a regular file
/// there (a symlink leading out of the folder, or a device such as `/dev/zero`, is refused),
/// at least `byte_length` long (checked before reading, so a huge file is never read past
/// what the document declares); its first `byte_length` bytes are read.
fn external_buffer(i: usize, uri: &str, byte_length: u64, base: Option<&Path>) -> Result<Vec<u8>> {
    let rel = confined_uri(uri).map_err(|m| bad(format!("buffer {i}: {m}")))?;
    let base = base.ok_or_else(|| {
        bad(format!(
            "buffer {i}: {uri} is an external file, and glTF bytes without a folder have none: \
             export a .glb"
        ))
    })?;
    let path = base.join(&rel);
    let missing = || {
        bad(format!(
            "buffer {i}: {uri} is missing beside the file: copy it next to the .gltf, or export a .glb"
        ))
    };
    let real = std::fs::canonicalize(&path).map_err(|_| missing())?;
    let folder = std::fs::canonicalize(base).map_err(|e| IoError::io(base, e))?;
    if !real.starts_with(&folder) {
        return Err(bad(format!(
            "buffer {i}: {uri} leads outside the .gltf's folder (a symlink to {}): copy the \
             file next to the .gltf, or export a .glb",
            real.display()
        )));
    }
    let meta = std::fs::metadata(&real).map_err(|e| IoError::io(&path, e))?;
    if !meta.is_file() {
        return Err(bad(format!(
            "buffer {i}: {uri} is not a regular file (a device, pipe or folder): name a data file"
        )));
    }
    if meta.len() < byte_length {
        return Err(bad(format!(
            "buffer {i}: {uri} holds {} bytes but the document declares byteLength {byte_length} \
             (a truncated or wrong file)",
            meta.len()
        )));
    }
    let mut bytes = Vec::new();
    let file = std::fs::File::open(&real).map_err(|e| IoError::io(&path, e))?;
    use std::io::Read;
    file.take(byte_length)
        .read_to_end(&mut bytes)
        .map_err(|e| {
            bad(format!(
                "buffer {i}: cannot read {uri}: {}",
                crate::describe_io(&e)
            ))
        })?;
    crate::note_read(&path);
    Ok(bytes)
}

/// Accessors without a buffer view or sparse values are zeros (glTF 2.0 §3.6.2.1; exporters
/// write all-zero morph targets so): they get a zero-filled view, which the `gltf` crate needs.
fn zero_views(root: &mut Map<String, Value>, buffers: &mut Vec<Cow<'_, [u8]>>) {
    let mut zeros: Vec<u8> = Vec::new();
    let buffer = buffers.len();
    let mut new_views = Vec::new();
    let first_view = root
        .get("bufferViews")
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    if let Some(accessors) = root.get_mut("accessors").and_then(Value::as_array_mut) {
        for acc in accessors.iter_mut().filter_map(Value::as_object_mut) {
            if acc.contains_key("bufferView") || acc.contains_key("sparse") {
                continue;
            }
            let comps = match acc.get("type").and_then(Value::as_str) {
                Some("SCALAR") => 1,
                Some("VEC2") => 2,
                Some("VEC3") => 3,
                Some("VEC4") | Some("MAT2") => 4,
                Some("MAT3") => 12,
                Some("MAT4") => 16,
                _ => continue,
            };
            let size = match acc.get("componentType").and_then(Value::as_u64) {
                Some(5120 | 5121) => 1,
                Some(5122 | 5123) => 2,
                _ => 4,
            };
            let count = acc.get("count").and_then(Value::as_u64).unwrap_or(0) as usize;
            let len = (count * comps * size).div_ceil(4) * 4;
            acc.insert("bufferView".into(), json!(first_view + new_views.len()));
            acc.insert("byteOffset".into(), json!(0));
            new_views.push(json!({"buffer": buffer, "byteOffset": zeros.len(), "byteLength": len}));
            zeros.resize(zeros.len() + len, 0);
        }
    }
    if new_views.is_empty() {
        return;
    }
    if let Some(views) = root
        .entry("bufferViews")
        .or_insert_with(|| Value::Array(Vec::new()))
        .as_array_mut()
    {
        views.extend(new_views);
    }
    if let Some(list) = root
        .entry("buffers")
        .or_insert_with(|| Value::Array(Vec::new()))
        .as_array_mut()
    {
        list.push(json!({ "byteLength": zeros.len() }));
    }
    buffers.push(Cow::Owned(zeros));
}

/// Prepares `bytes` (a `.glb`, or `.gltf` whose external buffers are found in `base`).
pub(crate) fn prepare<'a>(bytes: &'a [u8], base: Option<&Path>) -> Result<Prepared<'a>> {
    let (json, mut bin) = split(bytes)?;
    let mut value: Value = serde_json::from_slice(&json).map_err(|e| bad(e.to_string()))?;
    if !value.is_object() {
        return Err(bad("the document is not a JSON object"));
    }
    let required = names(&value, "extensionsRequired");
    let mut notes = Vec::new();
    let mut listed = required.clone();
    for used in names(&value, "extensionsUsed") {
        if !listed.contains(&used) {
            listed.push(used);
        }
    }
    for ext in &listed {
        let note = classify(&value, ext, required.contains(ext))?;
        notes.push(note);
    }
    let mut buffers = Vec::new();
    if let Some(list) = value.get("buffers").and_then(Value::as_array) {
        for (i, b) in list.iter().enumerate() {
            buffers.push(load_buffer(i, b, &mut bin, base)?);
        }
    }
    let Value::Object(map) = &mut value else {
        unreachable!("checked above")
    };
    strip(map, &mut notes);
    crate::gltf::meshopt::decode(map, &mut buffers)?;
    crate::gltf::draco::decode(map, &mut buffers)?;
    zero_views(map, &mut buffers);
    let root: gltf_json::Root = serde_json::from_value(value).map_err(|e| bad(e.to_string()))?;
    Ok(Prepared {
        root,
        buffers,
        notes,
    })
}
