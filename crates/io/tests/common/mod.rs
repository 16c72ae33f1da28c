//! Helpers shared by the io integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

/// Path of a shared test asset; panics (fails loudly) if it is missing.
pub(crate) fn data(rel: &str) -> PathBuf {
    testdata::asset(rel)
}

/// Keeps `bytes` as `<name>.glb` for CI's Khronos validator run, like
/// `crates/cli/tests/common.rs`.
pub(crate) fn keep_for_validation(bytes: &[u8], name: &str) {
    let Ok(dest) = std::env::var("TOONKIT_VALIDATE_DIR") else {
        return;
    };
    let dest = PathBuf::from(dest);
    std::fs::create_dir_all(&dest).unwrap();
    std::fs::write(dest.join(format!("{name}.glb")), bytes).unwrap();
}
