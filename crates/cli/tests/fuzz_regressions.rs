//! Replays every fuzz seed and every saved crasher (`fuzz/seeds/<target>/`,
//! `fuzz/regressions/<target>/`) through the fuzz targets' own code (`fuzz/targets.rs`), so
//! a reader that panics again on a once-crashing input fails `cargo test` on stable Rust.

#[path = "../../../fuzz/targets.rs"]
mod targets;

use std::path::Path;

/// A fuzz target's body: takes libFuzzer's input, panics on a finding.
type Target = fn(&[u8]);

/// Each fuzz target by name.
const TARGETS: [(&str, Target); 13] = [
    ("abc", targets::abc),
    ("bvh", targets::bvh),
    ("expr", targets::expr),
    ("gltf", targets::gltf),
    ("gltf_uri", targets::gltf_uri),
    ("keystrokes", targets::keystrokes),
    ("mdd", targets::mdd),
    ("npy", targets::npy),
    ("obj", targets::obj),
    ("pc2", targets::pc2),
    ("sizes", targets::sizes),
    ("stl", targets::stl),
    ("style", targets::style),
];

fn files(dir: &Path) -> Vec<std::path::PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut v: Vec<_> = entries.flatten().map(|e| e.path()).collect();
    v.sort();
    v
}

#[test]
fn seeds_and_crashers_replay_without_panic() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz");
    let mut seeds = 0;
    let mut crashers = 0;
    for (name, target) in TARGETS {
        let s = files(&root.join("seeds").join(name));
        assert!(!s.is_empty(), "fuzz/seeds/{name} is empty");
        for p in s.iter().chain(&files(&root.join("regressions").join(name))) {
            let bytes = std::fs::read(p).unwrap();
            let run = std::panic::catch_unwind(|| target(&bytes));
            assert!(run.is_ok(), "{name}: {} panics", p.display());
        }
        seeds += s.len();
        crashers += files(&root.join("regressions").join(name)).len();
    }
    assert!(
        seeds >= 13 && crashers >= 5,
        "{seeds} seeds, {crashers} crashers"
    );
}
