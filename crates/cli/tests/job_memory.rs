//! The job memory budget (`anim::budget::JobMemory`, `TOONKIT_MAX_JOB_BYTES`): every command
//! that samples a clip estimates what it will hold (the samples and each copy it makes) before
//! allocating it, and a job over the budget exits 2 with one line naming the copies, the limit
//! and what to lower — under an address-space limit (`ulimit -v`), where an allocation made
//! without that check would abort the process (exit 134) instead.

mod common;

use std::process::Output;

use common::*;

/// Address space each run may map (KiB for `ulimit -v`): the runtime, the character and a
/// small job, not the job asked for.
#[cfg(target_os = "linux")]
const LIMIT_KIB: u64 = 1_500_000;

/// The job budget of these runs (bytes): CesiumMan at 120 fps is ~240 frames × 3,273
/// vertices, 9.4 MB of samples, so every job that copies them more than once is over it.
#[cfg(target_os = "linux")]
const BUDGET: &str = "20e6";

/// `toonkit ARGS` under `ulimit -v` [`LIMIT_KIB`] with the job budget [`BUDGET`].
#[cfg(target_os = "linux")]
fn limited(args: &[&str]) -> Output {
    let quoted: Vec<String> = args.iter().map(|a| format!("'{a}'")).collect();
    let script = format!(
        "ulimit -v {LIMIT_KIB} && exec '{}' {}",
        env!("CARGO_BIN_EXE_toonkit"),
        quoted.join(" ")
    );
    std::process::Command::new("sh")
        .args(["-c", &script])
        .env("TOONKIT_MAX_JOB_BYTES", BUDGET)
        .output()
        .unwrap()
}

/// Every command that samples a clip, over the job budget: exit 2, one line naming the limit
/// and what to lower, no abort, nothing written and the input unchanged.
#[cfg(target_os = "linux")]
#[test]
fn every_command_over_the_job_budget_is_one_line_under_a_memory_limit() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let input = dir.path().join("walk.glb");
    std::fs::copy(data("characters/CesiumMan.glb"), &input).unwrap();
    let before = std::fs::read(&input).unwrap();
    let i = s(&input);
    let o = |name: &str| s(&out.join(name)).to_string();
    let style = dir.path().join("style.toml");
    std::fs::write(&style, "[elongate]\n[multiples]\n[lines]\ncount = 20\n").unwrap();
    let fps = ["--fps", "120"];
    let commands: Vec<Vec<String>> = [
        vec!["convert", i, &o("c.pc2")],
        vec!["convert", i, &o("c.glb")],
        vec!["smear", "offsets", i, "-o", &o("d.npy")],
        vec!["smear", "elongate", i, "-o", &o("e.glb")],
        vec!["smear", "multiples", i, "-o", &o("m.glb")],
        vec!["smear", "lines", i, "-o", &o("l.glb"), "--count", "20"],
        vec!["smear", i, "--style", s(&style), "-o", &o("s.glb")],
        vec!["stopmo", "segment", i, "-o", &o("seg.glb")],
        vec!["stopmo", "library", i, "-o", &o("lib")],
        vec!["stopmo", "run", i, "-o", &o("run")],
        vec!["render", i, "-o", &o("r.gif"), "--size", "512x512"],
    ]
    .into_iter()
    .map(|c| c.into_iter().chain(fps).map(str::to_string).collect())
    .collect();
    for args in &commands {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let run = limited(&args);
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains("is over the limit of"), "{args:?}: {err}");
        let named = err.contains("TOONKIT_MAX_JOB_BYTES") || err.contains("--size");
        assert!(named && err.contains("walk.glb"), "{args:?}: {err}");
        assert_readable(&err);
        assert_eq!(std::fs::read(&input).unwrap(), before, "{args:?}");
        assert!(
            file_names(&out).is_empty(),
            "{args:?}: {:?}",
            file_names(&out)
        );
    }
    // Within the budget the same limit changes nothing.
    let run = limited(&["convert", i, &o("c.pc2")]);
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

/// The job budget set by the environment: CesiumMan's 48 frames × 3,273 vertices (1.9 MB of
/// samples) fit 4 MB, its three copies in `convert` do not; the message names the variable.
#[test]
fn the_job_budget_names_its_variable() {
    let dir = tempfile::tempdir().unwrap();
    let input = data("characters/CesiumMan.glb");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_toonkit"))
        .args(["convert", s(&input), s(&dir.path().join("c.pc2"))])
        .env("TOONKIT_MAX_JOB_BYTES", "4e6")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert!(
        err.contains("memory of the job (3 copies of the clip (sampled, merged, written)")
            && err.contains("over the limit of 4000000")
            && err.contains("(or raise TOONKIT_MAX_JOB_BYTES)"),
        "{err}"
    );
    assert!(file_names(dir.path()).is_empty());
}

/// Under an address-space limit (`ulimit -v`) and no budget set, the budget is half that
/// limit: CesiumMan at 5,000 fps (~10,000 frames, three copies of ~0.4 GB in `convert`) is
/// under the default 6 GB but over half of 1.5 GB, and is refused in one line instead of
/// aborting on an allocation the limit denies.
#[cfg(target_os = "linux")]
#[test]
fn the_job_budget_is_half_the_address_space_limit() {
    let dir = tempfile::tempdir().unwrap();
    let input = data("characters/CesiumMan.glb");
    let target = dir.path().join("c.pc2");
    let script = format!(
        "ulimit -v {LIMIT_KIB} && exec '{}' convert '{}' '{}' --fps 5000",
        env!("CARGO_BIN_EXE_toonkit"),
        s(&input),
        s(&target)
    );
    let run = std::process::Command::new("sh")
        .args(["-c", &script])
        .env_remove("TOONKIT_MAX_JOB_BYTES")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    // The limit named is the address space's half (in bytes, or as points of 12 bytes taken
    // twice), far under the default budget's.
    let limit: f64 = err
        .split("over the limit of ")
        .nth(1)
        .and_then(|t| t.split(';').next())
        .and_then(|t| t.trim().parse().ok())
        .unwrap_or_else(|| panic!("no limit in: {err}"));
    let half = (LIMIT_KIB * 1024 / 2) as f64;
    assert!(limit == half || limit == (half / 24.0).floor(), "{err}");
    assert!(err.contains("lower --fps"), "{err}");
    assert!(file_names(dir.path()).is_empty());
}
