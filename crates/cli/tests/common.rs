//! Helpers shared by the CLI integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Path of a shared test asset; panics (fails loudly) if it is missing.
pub(crate) fn data(rel: &str) -> PathBuf {
    testdata::asset(rel)
}

/// A path as a command-line argument.
pub(crate) fn s(p: &Path) -> &str {
    p.to_str().expect("test paths are UTF-8")
}

/// Reads a `.pc2` written by toonkit with its rest `.obj` beside it (24 fps).
pub(crate) fn read_pc2(path: &Path) -> anim::MeshAnimation {
    let rest = tkio::obj::read(&std::fs::read(path.with_extension("obj")).unwrap()).unwrap();
    tkio::pc2::read(&std::fs::read(path).unwrap(), rest, 24.0).unwrap()
}

/// Runs `toonkit` with arguments.
pub(crate) fn toonkit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_toonkit"))
        .args(args)
        .output()
        .expect("run toonkit")
}

/// Runs `toonkit`, asserting success; returns stdout.
pub(crate) fn ok(args: &[&str]) -> String {
    let out = toonkit(args);
    assert!(
        out.status.success(),
        "toonkit {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8 stdout")
}

/// Runs `toonkit --json ...` and parses stdout.
pub(crate) fn json(args: &[&str]) -> serde_json::Value {
    let mut a = vec!["--json"];
    a.extend_from_slice(args);
    serde_json::from_str(&ok(&a)).expect("json stdout")
}

/// Keeps a copy of every glTF in `dir` for CI's Khronos validation run
/// (`TOONKIT_VALIDATE_DIR`), under a name prefixed by `tag`; CI runs the Khronos validator
/// on the glTF files and Pixar's USD (`.ci/validate_usd.py`) on the `.usda` files.
pub(crate) fn keep_for_validation(dir: &Path, tag: &str) {
    let Ok(dest) = std::env::var("TOONKIT_VALIDATE_DIR") else {
        return;
    };
    let dest = PathBuf::from(dest);
    std::fs::create_dir_all(&dest).unwrap();
    for e in walk(dir) {
        if e.extension()
            .is_some_and(|x| x == "glb" || x == "gltf" || x == "usda")
        {
            let name = format!("{tag}_{}", e.file_name().unwrap().to_string_lossy());
            std::fs::copy(&e, dest.join(name)).unwrap();
        }
    }
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

/// Asserts a failed run: exit code 2, one line on stderr mentioning `needle`, no panic.
pub(crate) fn assert_bad_input(args: &[&str], needle: &str) {
    let out = toonkit(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(2),
        "toonkit {args:?}: expected exit 2, stderr: {err}"
    );
    assert!(!err.contains("panicked"), "panic on {args:?}: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "expected one line, got: {err}"
    );
    assert!(
        err.contains(needle),
        "stderr {err:?} does not mention {needle:?}"
    );
    assert_readable(&err);
}

/// The rules of every error message (issue #23): no `Debug` output, no OS error codes, no
/// text said twice, numbers written for people.
pub(crate) fn assert_readable(message: &str) {
    let m = message.trim_end();
    for leak in [
        "Constant(",
        "Curve(",
        "Some(",
        "None",
        "Error {",
        "kind: ",
        "os error",
    ] {
        assert!(!m.contains(leak), "{m:?} leaks {leak:?}");
    }
    let digits = m
        .split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0);
    assert!(digits <= 12, "{m:?} spells out a {digits}-digit number");
    let parts: Vec<&str> = m.split(": ").map(str::trim).collect();
    for w in parts.windows(2) {
        assert!(!w[0].eq_ignore_ascii_case(w[1]), "{m:?} repeats {:?}", w[0]);
    }
}

/// Every file name in `dir`, sorted (temporary files included: they start with '.').
pub(crate) fn file_names(dir: &Path) -> Vec<String> {
    testdata::file_names(dir)
}

/// A copy of the glTF `src` (`.glb`, or `.gltf` with buffers beside it) whose every animation
/// sampler has the keys `times` (seconds), written as a `.glb` at `dst`: each sampler keeps
/// its first `times.len()` output values (linear), so skins, node transforms and morph weights
/// stay valid. A clip with one key at 20,000 s, or keys at 0 and 20,000 s, asks the samplers
/// for what a hostile file would.
pub(crate) fn rekeyed_glb(src: &Path, times: &[f32], dst: &Path) {
    let bytes = std::fs::read(src).unwrap();
    let (mut gltf, mut bin): (serde_json::Value, Vec<u8>) = if bytes.starts_with(b"glTF") {
        let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        let json = serde_json::from_slice(&bytes[20..20 + len]).unwrap();
        (json, bytes[28 + len..].to_vec())
    } else {
        let json: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
        let uri = json["buffers"][0]["uri"].as_str().unwrap();
        let bin = std::fs::read(src.with_file_name(uri)).unwrap();
        (json, bin)
    };
    assert_eq!(gltf["buffers"].as_array().unwrap().len(), 1, "one buffer");
    gltf["buffers"][0] = serde_json::json!({"byteLength": bin.len()});
    let offset = |g: &serde_json::Value, a: usize| {
        let acc = &g["accessors"][a];
        let view = &g["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
        (view["byteOffset"].as_u64().unwrap_or(0) + acc["byteOffset"].as_u64().unwrap_or(0))
            as usize
    };
    let n = times.len() as u64;
    // Values per key of every sampler, before any shared input accessor is rewritten.
    let count = |g: &serde_json::Value, a: usize| g["accessors"][a]["count"].as_u64().unwrap();
    let mut samplers = Vec::new();
    for a in gltf["animations"].as_array().unwrap() {
        for s in a["samplers"].as_array().unwrap() {
            let input = s["input"].as_u64().unwrap() as usize;
            let output = s["output"].as_u64().unwrap() as usize;
            samplers.push((input, output, count(&gltf, output) / count(&gltf, input)));
        }
    }
    for &(input, output, per_key) in &samplers {
        let at = offset(&gltf, input);
        for (k, t) in times.iter().enumerate() {
            bin[at + 4 * k..at + 4 * k + 4].copy_from_slice(&t.to_le_bytes());
        }
        let lo = times.iter().copied().fold(f32::INFINITY, f32::min);
        let hi = times.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        let acc = &mut gltf["accessors"][input];
        acc["count"] = n.into();
        acc["min"] = serde_json::json!([lo]);
        acc["max"] = serde_json::json!([hi]);
        let out = &mut gltf["accessors"][output];
        out["count"] = (per_key * n).into();
        if let Some(o) = out.as_object_mut() {
            o.remove("min");
            o.remove("max");
        }
    }
    for a in gltf["animations"].as_array_mut().unwrap() {
        for s in a["samplers"].as_array_mut().unwrap() {
            s["interpolation"] = "LINEAR".into();
        }
    }
    let mut json = serde_json::to_vec(&gltf).unwrap();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let mut glb = Vec::new();
    glb.extend_from_slice(b"glTF");
    glb.extend_from_slice(&2u32.to_le_bytes());
    glb.extend_from_slice(&((28 + json.len() + bin.len()) as u32).to_le_bytes());
    glb.extend_from_slice(&(json.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"JSON");
    glb.extend_from_slice(&json);
    glb.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"BIN\0");
    glb.extend_from_slice(&bin);
    std::fs::write(dst, glb).unwrap();
}

/// The `.timeSamples` of `decl` inside `text` (file order), as the text of each value; one
/// entry for a static (default) value.
pub(crate) fn samples<'a>(text: &'a str, decl: &str) -> Vec<&'a str> {
    let head = format!("{decl}.timeSamples = {{\n");
    if let Some(start) = text.find(&head) {
        let body = &text[start + head.len()..];
        let end = body.find("\n        }").unwrap();
        return body[..end]
            .lines()
            .map(|l| l.split_once(": ").unwrap().1.trim_end_matches(','))
            .collect();
    }
    let head = format!("{decl} = ");
    let start = text.find(&head).unwrap_or_else(|| panic!("no {decl}")) + head.len();
    vec![text[start..].lines().next().unwrap()]
}

/// Parses `[(x, y, z), ...]`.
pub(crate) fn vec3s(v: &str) -> Vec<[f32; 3]> {
    let inner = v.trim().trim_start_matches('[').trim_end_matches(']');
    if inner.is_empty() {
        return Vec::new();
    }
    inner
        .trim_start_matches('(')
        .trim_end_matches(')')
        .split("), (")
        .map(|t| {
            let c: Vec<f32> = t.split(", ").map(|x| x.parse().unwrap()).collect();
            [c[0], c[1], c[2]]
        })
        .collect()
}
