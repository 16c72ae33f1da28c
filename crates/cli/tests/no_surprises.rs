//! Issue #23: several frames never silently become one, shared options have one name, and
//! the malformed-input cases a new user hits get one readable line.

mod common;

use std::path::Path;

use common::*;

fn cesium() -> std::path::PathBuf {
    data("characters/CesiumMan.glb")
}

#[test]
fn several_frames_to_one_obj_are_refused_not_cut() {
    let dir = tempfile::tempdir().unwrap();
    for ext in ["obj", "stl"] {
        let out = dir.path().join(format!("out.{ext}"));
        assert_bad_input(
            &["convert", s(&cesium()), s(&out), "--fps", "24"],
            &format!(
                "out.{ext}: 48 frames do not fit in one .{ext}: use --layout sequence, or --frame N for one frame"
            ),
        );
    }
    assert!(file_names(dir.path()).is_empty(), "nothing written");
}

#[test]
fn layout_sequence_writes_every_frame_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    for (ext, flag) in [("obj", "--layout"), ("stl", "--as")] {
        let out = dir.path().join(ext).join(format!("walk.{ext}"));
        let text = ok(&["convert", s(&cesium()), s(&out), flag, "sequence"]);
        let names = file_names(out.parent().unwrap());
        assert_eq!(names.len(), 48, "{names:?}");
        assert_eq!(names[0], format!("walk_0001.{ext}"));
        assert_eq!(names[47], format!("walk_0048.{ext}"));
        // The summary names the files and the frame count it wrote.
        assert!(text.contains(&format!("walk_0001.{ext} …")), "{text}");
        assert!(
            text.contains(&format!("walk_0048.{ext} (48 files)")),
            "{text}"
        );
        assert!(text.contains("(48 frames ×"), "{text}");
    }
    let v = json(&[
        "convert",
        s(&cesium()),
        s(&dir.path().join("j/walk.obj")),
        "--layout",
        "sequence",
    ]);
    assert_eq!(v["outputs"].as_array().unwrap().len(), 48);
    assert_eq!(v["frames"], 48);
}

#[test]
fn frame_writes_that_frame_only() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("seq/walk.obj");
    ok(&["convert", s(&cesium()), s(&seq), "--layout", "sequence"]);
    let one = dir.path().join("one.obj");
    let text = ok(&["convert", s(&cesium()), s(&one), "--frame", "5"]);
    assert!(text.contains("frame 5 of 48"), "{text}");
    assert_eq!(file_names(dir.path()), ["one.obj", "seq"]);
    let read = |p: &Path| tkio::obj::read(&std::fs::read(p).unwrap()).unwrap();
    let frame5 = read(&dir.path().join("seq/walk_0006.obj"));
    let frame0 = read(&dir.path().join("seq/walk_0001.obj"));
    let got = read(&one);
    assert_eq!(
        got.positions, frame5.positions,
        "--frame 5 is the sixth file"
    );
    assert_ne!(got.positions, frame0.positions, "not the first frame");
    // --frame works for multi-frame formats too: a one-frame point cache.
    let pc2 = dir.path().join("f.pc2");
    let v = json(&["convert", s(&cesium()), s(&pc2), "--frame", "47"]);
    assert_eq!(read_pc2(&pc2).frame_count(), 1, "{v}");
    assert_bad_input(
        &["convert", s(&cesium()), s(&one), "--frame", "48"],
        "--frame 48 is past the last frame (47)",
    );
    assert_bad_input(
        &[
            "convert",
            s(&cesium()),
            s(&one),
            "--frame",
            "1",
            "--layout",
            "sequence",
        ],
        "--frame",
    );
}

#[test]
fn sequence_layout_to_a_format_that_holds_every_frame_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.glb");
    assert_bad_input(
        &["convert", s(&cesium()), s(&out), "--layout", "sequence"],
        "x.glb: the sequence layout writes one file per frame: name the output .obj or .stl",
    );
    assert!(!out.exists());
}

#[test]
fn smear_elongate_takes_the_same_layout_options() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("e.obj");
    assert_bad_input(
        &["smear", "elongate", s(&cesium()), "-o", s(&out)],
        "48 frames do not fit in one .obj",
    );
    let text = ok(&[
        "smear",
        "elongate",
        s(&cesium()),
        "-o",
        s(&out),
        "--frame",
        "10",
    ]);
    assert!(text.contains("frame 10 of 48"), "{text}");
    assert_eq!(file_names(dir.path()), ["e.obj"]);
}

#[test]
fn messages_of_the_issue_are_one_readable_line() {
    let dir = tempfile::tempdir().unwrap();
    // A folder instead of a file: said once, in words, with the fix.
    assert_bad_input(&["info", s(dir.path())], "is a directory: name a file");
    // A missing file: the path first, said once.
    let missing = dir.path().join("nope.glb");
    assert_bad_input(
        &["info", s(&missing)],
        &format!("{}: no such file or directory", missing.display()),
    );
    let out = dir.path().join("l.glb");
    assert_bad_input(
        &[
            "smear",
            "lines",
            s(&cesium()),
            "-o",
            s(&out),
            "--count",
            "100000000",
        ],
        "--count 100000000: give a number of lines from 0 to 10000000",
    );
    assert_bad_input(
        &[
            "smear",
            "elongate",
            s(&cesium()),
            "-o",
            s(&out),
            "--beta-max",
            "nan",
        ],
        "--beta-max",
    );
    assert_bad_input(&["convert", s(&cesium()), s(&out), "--fps", "0"], "--fps");
}

/// Copies `asset` into `dir` and returns the copy and its bytes.
fn copy_in(dir: &Path, asset: &str, name: &str) -> (std::path::PathBuf, Vec<u8>) {
    let p = dir.join(name);
    std::fs::copy(data(asset), &p).unwrap();
    let bytes = std::fs::read(&p).unwrap();
    (p, bytes)
}

/// `toonkit convert fox.glb fox.glb` replaced a three-clip character with a flipbook: now
/// refused naming both paths and the fix, the input byte for byte as it was.
#[test]
fn converting_a_file_onto_itself_is_refused_and_keeps_every_byte() {
    let dir = tempfile::tempdir().unwrap();
    let (fox, before) = copy_in(dir.path(), "characters/CesiumMan.glb", "fox.glb");
    assert_bad_input(
        &["convert", s(&fox), s(&fox)],
        "refusing to write over it; name another output file",
    );
    let err = String::from_utf8_lossy(&toonkit(&["convert", s(&fox), s(&fox)]).stderr).into_owned();
    assert_eq!(err.matches("fox.glb").count(), 2, "both paths named: {err}");
    assert_eq!(std::fs::read(&fox).unwrap(), before);
    assert_eq!(file_names(dir.path()), vec!["fox.glb"], "no temporary left");
}

/// A symlink to the output, and another spelling of the output's path, are the same file.
#[cfg(unix)]
#[test]
fn a_symlink_or_an_alias_of_the_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let o2 = dir.path().join("o2");
    std::fs::create_dir(&o2).unwrap();
    let (fox, before) = copy_in(&o2, "characters/CesiumMan.glb", "fox.glb");
    let link = dir.path().join("link.glb");
    std::os::unix::fs::symlink(&fox, &link).unwrap();
    assert_bad_input(
        &["smear", "elongate", s(&link), "-o", s(&fox)],
        "is the input",
    );
    // `./fox.glb` from inside o2 against `../o2/fox.glb`.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_toonkit"))
        .current_dir(&o2)
        .args(["convert", "./fox.glb", "../o2/fox.glb"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("../o2/fox.glb: is the input ./fox.glb"),
        "{err}"
    );
    assert_eq!(std::fs::read(&fox).unwrap(), before);
}

/// `convert spot.obj spot.pc2` wrote the rest mesh over `spot.obj` (its uv and normal lines
/// gone): the implicit rest `.obj` of a cache is an output too, and nothing is written.
#[test]
fn a_point_cache_whose_rest_obj_is_the_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (spot, before) = copy_in(dir.path(), "meshes/spot.obj", "spot.obj");
    assert_bad_input(
        &["convert", s(&spot), s(&dir.path().join("spot.pc2"))],
        "spot.obj: is the input",
    );
    assert_eq!(std::fs::read(&spot).unwrap(), before);
    assert_eq!(file_names(dir.path()), vec!["spot.obj"], "the .pc2 neither");
}

/// A point cache read with its implicit rest `.obj`, written back as a `.mdd` beside it,
/// would replace that rest mesh: refused too (the load recorded it).
#[test]
fn the_implicit_rest_obj_of_an_input_cache_is_kept() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("walk.pc2");
    ok(&["convert", s(&cesium()), s(&cache)]);
    let rest = std::fs::read(dir.path().join("walk.obj")).unwrap();
    assert_bad_input(
        &["convert", s(&cache), s(&dir.path().join("walk.mdd"))],
        "walk.obj: is the input",
    );
    assert_eq!(std::fs::read(dir.path().join("walk.obj")).unwrap(), rest);
}
