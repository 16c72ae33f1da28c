//! A `.gltf` reads only what lies inside its own folder: buffer URIs that are absolute, lead
//! out through `..`, carry a scheme (`file:`), name a device or a symlink out of the folder
//! are refused in one line, and a buffer shorter than its `byteLength` is refused before it
//! is read. Images are never read at all (toonkit keeps geometry and animation only).

use std::path::{Path, PathBuf};

/// One triangle: 3 positions (36 bytes) then 3 u16 indices (6 bytes, padded to 8).
fn triangle_bin() -> Vec<u8> {
    let mut b = Vec::new();
    for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in p {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2, 0] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b
}

/// A `.gltf` in `dir` whose one buffer has `uri` (and an image with `image_uri`).
fn gltf_with(dir: &Path, uri: &str, image_uri: &str) -> PathBuf {
    let doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "buffers": [{"uri": uri, "byteLength": 44}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 6}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}
        ],
        "images": [{"uri": image_uri}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    let p = dir.join("tri.gltf");
    std::fs::write(&p, serde_json::to_vec(&doc).unwrap()).unwrap();
    p
}

fn load_error(path: &Path) -> String {
    tkio::load(path, &tkio::LoadOptions::default())
        .map(|_| ())
        .expect_err("must be refused")
        .to_string()
}

#[test]
fn a_buffer_beside_the_gltf_loads_and_is_recorded_as_read() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tri.bin"), triangle_bin()).unwrap();
    // The image names a system file: it is never opened.
    let p = gltf_with(dir.path(), "tri.bin", "/etc/passwd");
    let scope = tkio::ReadScope::open();
    let loaded = tkio::load(&p, &tkio::LoadOptions::default()).unwrap();
    assert!(matches!(loaded, tkio::Loaded::Scene(_)));
    // Reads on threads without a scope of their own (other tests running in parallel) are
    // charged to every open scope: keep this test's folder.
    let read: Vec<String> = scope
        .files()
        .iter()
        .filter(|f| f.starts_with(dir.path()))
        .map(|f| f.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        read,
        ["tri.gltf", "tri.bin"],
        "the file, its buffer; no image"
    );
}

#[test]
fn absolute_dotdot_and_scheme_uris_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let inner = dir.path().join("shot");
    std::fs::create_dir(&inner).unwrap();
    let outside = dir.path().join("secret.bin");
    std::fs::write(&outside, triangle_bin()).unwrap();
    let absolute = outside.display().to_string();
    let file_uri = format!("file://{absolute}");
    for uri in [
        absolute.as_str(),
        "../secret.bin",
        "sub/../../secret.bin",
        "%2E%2E/secret.bin",
        file_uri.as_str(),
        "http://example.invalid/tri.bin",
    ] {
        let p = gltf_with(&inner, uri, "x.png");
        let e = load_error(&p);
        assert!(e.starts_with(&p.display().to_string()), "{uri}: {e}");
        assert!(
            e.contains("outside the .gltf's folder") || e.contains("not a file beside the .gltf"),
            "{uri}: {e}"
        );
        assert!(!e.contains('\n'), "one line: {e}");
    }
}

#[cfg(unix)]
#[test]
fn a_symlink_out_of_the_folder_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let inner = dir.path().join("shot");
    std::fs::create_dir(&inner).unwrap();
    let outside = dir.path().join("secret.bin");
    std::fs::write(&outside, triangle_bin()).unwrap();
    std::os::unix::fs::symlink(&outside, inner.join("tri.bin")).unwrap();
    let e = load_error(&gltf_with(&inner, "tri.bin", "x.png"));
    assert!(e.contains("leads outside the .gltf's folder"), "{e}");
}

/// A device behind a buffer URI fails at once: `/dev/zero` read 4 GB before failing.
#[cfg(unix)]
#[test]
fn a_device_or_a_short_file_fails_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    // A link inside the folder to a device: still not a regular file.
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("zero.bin")).unwrap();
    let start = std::time::Instant::now();
    let e = load_error(&gltf_with(dir.path(), "zero.bin", "x.png"));
    assert!(
        e.contains("leads outside") || e.contains("not a regular file"),
        "{e}"
    );
    assert!(
        start.elapsed().as_secs_f64() < 5.0,
        "refused before reading"
    );
    // A buffer file shorter than the byteLength the document declares.
    std::fs::write(dir.path().join("short.bin"), [0u8; 10]).unwrap();
    let e = load_error(&gltf_with(dir.path(), "short.bin", "x.png"));
    assert!(
        e.contains("holds 10 bytes but the document declares byteLength 44"),
        "{e}"
    );
}
