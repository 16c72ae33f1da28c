//! Paths of toonkit's bundled assets for tests, benches and examples.
//!
//! The repository carries every file its tests read in `assets/` at the workspace root (with
//! their licences in `assets/README.md`); names are relative to that folder, e.g.
//! `characters/RobotExpressive.glb` or `face/ict-face-talk.glb`. A missing file fails loudly,
//! naming the full path.
//!
//! ```
//! let robot = testdata::asset("characters/RobotExpressive.glb");
//! assert!(robot.is_file());
//! ```

#![warn(missing_docs)]

use std::path::{Path, PathBuf};

mod scaled;
pub use scaled::{glb_json, scaled_glb};

/// The `assets/` folder at the workspace root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets")
}

/// Path of the bundled asset `rel` (relative to `assets/`).
///
/// # Panics
/// If the file does not exist: the message names the full path, so a broken checkout is obvious.
pub fn asset(rel: &str) -> PathBuf {
    let p = root().join(rel);
    assert!(p.is_file(), "missing test asset {}", p.display());
    p
}

/// Bytes of the bundled asset `rel`.
///
/// # Panics
/// If the file cannot be read (the message names the full path).
pub fn bytes(rel: &str) -> Vec<u8> {
    let p = asset(rel);
    std::fs::read(&p).unwrap_or_else(|e| panic!("cannot read test asset {}: {e}", p.display()))
}

/// Every file name in `dir`, sorted (temporary files included: they start with '.'), to
/// check what a job left behind.
pub fn file_names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Writes `escape.gltf` into `dir`: one triangle whose 36-byte buffer is read from `uri` (a
/// hostile file's absolute path, `../…`, `file:` URL or device), and returns its path.
pub fn gltf_with_buffer_uri(dir: &Path, uri: &str) -> PathBuf {
    let path = dir.join("escape.gltf");
    let text = format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":"{}","byteLength":36}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
        "min":[0,0,0],"max":[1,1,0]}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#,
        uri.replace('\\', "\\\\").replace('"', "\\\"")
    );
    std::fs::write(&path, text).unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
    path
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_bundled_asset_is_there() {
        for rel in [
            "characters/RobotExpressive.glb",
            "characters/CesiumMan.glb",
            "characters/SimpleSkin.gltf",
            "face/ict-face-talk.glb",
            "meshes/spot.obj",
            "mocap/02_02.bvh",
            "mocap/12_03.bvh",
            "morph/MorphStressTest/MorphStressTest.gltf",
            "morph/AnimatedMorphSphere/AnimatedMorphSphere.gltf",
        ] {
            assert!(!super::bytes(rel).is_empty(), "{rel}");
        }
    }

    #[test]
    #[should_panic(expected = "missing test asset")]
    fn a_missing_asset_names_its_path() {
        super::asset("nope/missing.glb");
    }
}
