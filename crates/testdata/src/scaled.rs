//! A character "exported in other units": its GLB with the root node scaled
//! (`docs/smear-units.md`), for tests that a style means the same at any scale.

use std::path::{Path, PathBuf};

/// The JSON chunk of a GLB and its length in bytes.
///
/// # Panics
/// If `bytes` is not a GLB whose first chunk is JSON.
pub fn glb_json(bytes: &[u8]) -> (serde_json::Value, usize) {
    let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    assert_eq!(&bytes[16..20], b"JSON", "not a GLB");
    (serde_json::from_slice(&bytes[20..20 + len]).unwrap(), len)
}

/// Writes the bundled GLB `rel` with its one root node scaled by `scale` (its `scale`, or
/// its `matrix` multiplied) into `dir`, the binary chunk kept; returns the new file's path.
///
/// # Panics
/// If the asset is not a GLB with one root node, or `dir` cannot be written.
pub fn scaled_glb(rel: &str, scale: f32, dir: &Path) -> PathBuf {
    let bytes = crate::bytes(rel);
    let (mut doc, len) = glb_json(&bytes);
    let roots = doc["scenes"][0]["nodes"].as_array().unwrap().clone();
    assert_eq!(roots.len(), 1, "one root node");
    let node = &mut doc["nodes"][roots[0].as_u64().unwrap() as usize];
    if let Some(m) = node.get_mut("matrix").and_then(|m| m.as_array_mut()) {
        // Column-major 4 × 4 (CesiumMan's Z_UP): scale × matrix scales its first three rows.
        for (k, v) in m.iter_mut().enumerate() {
            if k % 4 != 3 {
                *v = serde_json::json!(v.as_f64().unwrap() * scale as f64);
            }
        }
    } else {
        assert!(
            node.get("scale").is_none(),
            "the root node is scaled already"
        );
        node["scale"] = serde_json::json!([scale, scale, scale]);
    }
    let mut text = serde_json::to_vec(&doc).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let rest = &bytes[20 + len..];
    let total = 12 + 8 + text.len() + rest.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    out.extend_from_slice(rest);
    let stem = Path::new(rel).file_stem().unwrap().to_string_lossy();
    let path = dir.join(format!("{stem}_{scale}.glb"));
    std::fs::write(&path, out).unwrap();
    path
}
