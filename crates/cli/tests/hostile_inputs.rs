//! A hostile but realistic user's clips and expressions: a clip keyed at 20,000 s (one key,
//! or keys at 0 and 20,000 s) on a skinned character with morph targets and on a morph-target
//! sphere, run through every command that samples a clip; an expression that is NaN or
//! infinite at some vertices only. Each command either works within the budgets of
//! `anim::budget` or exits 2 with one line naming the file and the limit, and the input keeps
//! every byte.

mod common;

use std::path::{Path, PathBuf};

use common::*;

/// The commands that sample a clip, writing into `out`.
fn sampling_commands(input: &Path, out: &Path) -> Vec<Vec<String>> {
    let i = s(input).to_string();
    let o = |name: &str| s(&out.join(name)).to_string();
    let style = out.join("style.toml");
    std::fs::write(
        &style,
        "[elongate]\n[multiples]\n[lines]\ncount = 20\nsamples = 4\n",
    )
    .unwrap();
    [
        vec!["info", &i],
        vec!["convert", &i, &o("c.pc2")],
        vec!["convert", &i, &o("c.glb")],
        vec!["smear", "offsets", &i, "-o", &o("d.npy")],
        vec!["smear", "elongate", &i, "-o", &o("e.glb")],
        vec!["smear", "multiples", &i, "-o", &o("m.glb")],
        vec!["smear", "lines", &i, "-o", &o("l.glb"), "--count", "20"],
        vec!["smear", &i, "--style", s(&style), "-o", &o("s.glb")],
        vec!["render", &i, "-o", &o("r.png")],
        vec!["render", &i, "-o", &o("r.gif"), "--size", "64x64"],
        vec!["stopmo", "segment", &i, "-o", &o("seg.glb")],
    ]
    .into_iter()
    .map(|c| c.into_iter().map(str::to_string).collect())
    .collect()
}

/// The robot (skins and morph targets in one clip) and the morph-target sphere, rekeyed to
/// `times` into `dir`.
fn late_clips(dir: &Path, times: &[f32], tag: &str) -> Vec<PathBuf> {
    [
        ("characters/RobotExpressive.glb", "robot"),
        (
            "morph/AnimatedMorphSphere/AnimatedMorphSphere.gltf",
            "sphere",
        ),
    ]
    .into_iter()
    .map(|(asset, name)| {
        let p = dir.join(format!("{name}_{tag}.glb"));
        rekeyed_glb(&data(asset), times, &p);
        p
    })
    .collect()
}

/// One key at t = 20,000 s is a one-frame clip starting there: every command works.
#[test]
fn a_clip_with_one_key_at_20000_seconds_is_one_frame() {
    let dir = tempfile::tempdir().unwrap();
    for input in late_clips(dir.path(), &[20_000.0], "one") {
        let before = std::fs::read(&input).unwrap();
        let info = json(&["info", s(&input)]);
        assert_eq!(info["clips"][0]["frames"], 1, "{info}");
        let out = tempfile::tempdir().unwrap();
        for args in sampling_commands(&input, out.path()) {
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let run = toonkit(&args);
            let err = String::from_utf8_lossy(&run.stderr);
            // Segmenting needs motion: a single frame is refused as input, in one line.
            if args[0] == "stopmo" {
                assert_eq!(run.status.code(), Some(2), "{args:?}: {err}");
                assert_eq!(err.trim_end().lines().count(), 1, "{err}");
                assert!(err.contains(s(&input)), "{err}");
                continue;
            }
            assert!(run.status.success(), "{args:?}: {err}");
        }
        let pc2 = read_pc2(&out.path().join("c.pc2"));
        assert_eq!(pc2.frame_count(), 1);
        assert!(pc2.positions().iter().all(|p| p.is_finite()));
        assert_eq!(std::fs::read(&input).unwrap(), before, "input unchanged");
    }
}

/// Keys at 0 and 20,000 s ask for 480,001 frames at 24 fps: every command that samples the
/// clip refuses it before allocating, naming the file, the frames and the limit.
#[test]
fn a_clip_keyed_at_0_and_20000_seconds_is_refused_by_the_frame_budget() {
    let dir = tempfile::tempdir().unwrap();
    for input in late_clips(dir.path(), &[0.0, 20_000.0], "two") {
        let before = std::fs::read(&input).unwrap();
        let info = json(&["info", s(&input)]);
        assert_eq!(info["clips"][0]["frames"], 480_001, "{info}");
        let out = tempfile::tempdir().unwrap();
        for args in sampling_commands(&input, out.path()).into_iter().skip(1) {
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            assert_bad_input(
                &args,
                "frames at 24 fps = 480001 is over the limit of 100000; the clip lasts 20000.0 s",
            );
            let err = String::from_utf8_lossy(&toonkit(&args).stderr).into_owned();
            assert!(err.contains(s(&input)), "names the file: {err}");
        }
        let left: Vec<String> = file_names(out.path())
            .into_iter()
            .filter(|n| n != "style.toml")
            .collect();
        assert!(left.is_empty(), "nothing written: {left:?}");
        assert_eq!(std::fs::read(&input).unwrap(), before, "input unchanged");
    }
}

/// Keys at 0 and 4,000 s on the robot: 96,001 frames are under the frame budget, but frames ×
/// vertices is not.
#[test]
fn a_long_clip_on_a_big_mesh_is_refused_by_the_point_budget() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("robot.glb");
    rekeyed_glb(
        &data("characters/RobotExpressive.glb"),
        &[0.0, 4_000.0],
        &input,
    );
    let out = dir.path().join("e.glb");
    assert_bad_input(
        &["smear", "elongate", s(&input), "-o", s(&out)],
        "frames × vertices = ",
    );
    let err =
        String::from_utf8_lossy(&toonkit(&["convert", s(&input), s(&out)]).stderr).into_owned();
    assert!(
        err.contains("is over the limit of 2.5e8; the clip lasts 4000.0 s: lower --fps"),
        "{err}"
    );
}

/// The index of the first vertex of CesiumMan whose x is negative in the first frame, read
/// independently of the smear (the sampled scene's frame-0 positions).
fn first_vertex_left_of_the_origin() -> usize {
    let scene = tkio::gltf::read(&data("characters/CesiumMan.glb")).unwrap();
    let sampled = anim::sample(&scene, &anim::SampleOptions::default()).unwrap();
    let frame0 = sampled.objects[0].animation.frame(0);
    frame0
        .iter()
        .position(|p| p.x < 0.0)
        .expect("a vertex left of x = 0")
}

/// `sqrt(x)` is finite right of the origin and NaN left of it: no longer drawn as zeros, it
/// is an error naming the expression, the first frame and the first vertex where it is NaN.
#[test]
fn an_expression_nan_at_some_vertices_names_the_frame_and_the_vertex() {
    let dir = tempfile::tempdir().unwrap();
    let input = data("characters/CesiumMan.glb");
    let vertex = first_vertex_left_of_the_origin();
    let out = dir.path().join("e.glb");
    let (i, o) = (s(&input), s(&out));
    let want = format!("expression 'sqrt(x)' is NaN or infinite at frame 0, vertex {vertex}");
    refused(
        &["smear", "elongate", i, "-o", o, "--expr", "sqrt(x)"],
        &[&want, "CesiumMan.glb", "keep it finite"],
        &input,
        dir.path(),
        &[],
    );
    // The same through a style file, on the multiples' opacity and the lines' length (the
    // index then counts motion lines).
    let style = dir.path().join("s.toml");
    let styled = ["smear", i, "--style", s(&style), "-o", o];
    std::fs::write(
        &style,
        "[multiples]\nopacity = { expr = \"0.5 / step(x)\" }\n",
    )
    .unwrap();
    refused(
        &styled,
        &[
            "expression '0.5 / step(x)' is NaN or infinite at frame ",
            ", vertex ",
        ],
        &input,
        dir.path(),
        &["s.toml"],
    );
    std::fs::write(
        &style,
        "[lines]\ncount = 50\nlength = { expr = \"2 / step(x)\" }\n",
    )
    .unwrap();
    refused(
        &styled,
        &[
            "expression '2 / step(x)' is NaN or infinite at frame ",
            ", motion line ",
        ],
        &input,
        dir.path(),
        &["s.toml"],
    );
    // Finite everywhere: works.
    ok(&[
        "smear",
        "elongate",
        i,
        "-o",
        o,
        "--expr",
        "sqrt(abs(x)) * delta",
    ]);
    assert_eq!(file_names(dir.path()), ["e.glb", "s.toml"]);
}

/// Runs `args`, which must fail with exit 2 and one line holding every `needles`, and checks
/// that `input` kept every byte and nothing but `keep` is left in `dir`.
fn refused(args: &[&str], needles: &[&str], input: &Path, dir: &Path, keep: &[&str]) {
    let before = std::fs::read(input).unwrap();
    assert_bad_input(args, needles[0]);
    let err = String::from_utf8_lossy(&toonkit(args).stderr).into_owned();
    for n in needles {
        assert!(err.contains(n), "{args:?}: {err:?} lacks {n:?}");
    }
    assert_eq!(
        std::fs::read(input).unwrap(),
        before,
        "{args:?}: input changed"
    );
    assert_eq!(file_names(dir), keep, "{args:?}: nothing written");
}

/// Options whose sizes are over their budgets: refused before allocating, naming the option
/// and the limit (`--smooth 1e9`, `--count 1e7`, a GIF of 8192², keystrokes nested 20,000
/// deep in an SVG, 10,000 keystrokes, keystrokes 500,000 frames apart).
#[test]
fn options_over_their_budgets_name_the_option_and_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("walk.glb");
    std::fs::copy(data("characters/CesiumMan.glb"), &input).unwrap();
    let o = |n: &str| s(&dir.path().join(n)).to_string();
    let i = s(&input);
    let keep = ["walk.glb"];
    refused(
        &[
            "smear",
            "offsets",
            i,
            "-o",
            &o("d.npy"),
            "--smooth",
            "1000000000",
        ],
        &["--smooth = 1e9 is over the limit of 100000", "walk.glb"],
        &input,
        dir.path(),
        &keep,
    );
    refused(
        &[
            "smear",
            "lines",
            i,
            "-o",
            &o("l.glb"),
            "--count",
            "10000000",
        ],
        &[
            "lines count × clip frames = 4.8e8 is over the limit of 2.5e8",
            "--count",
        ],
        &input,
        dir.path(),
        &keep,
    );
    refused(
        &["render", i, "-o", &o("r.gif"), "--size", "8192x8192"],
        &[
            "width × height × frames = ",
            "is over the limit of 1.2e9",
            "--size",
        ],
        &input,
        dir.path(),
        &keep,
    );
    // A supersampled size names the size asked for, not the internal one.
    refused(
        &["render", i, "-o", &o("r.png"), "--size", "16384x16384"],
        &["16384x16384"],
        &input,
        dir.path(),
        &keep,
    );
    let err = String::from_utf8_lossy(
        &toonkit(&["render", i, "-o", &o("r.png"), "--size", "16384x16384"]).stderr,
    )
    .into_owned();
    assert!(!err.contains("32768"), "{err}");

    let svg = dir.path().join("deep.svg");
    let nested = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\">{}<path data-frame=\"0\" d=\"M0 0 L10 10\"/>{}</svg>",
        "<g>".repeat(20_000),
        "</g>".repeat(20_000)
    );
    std::fs::write(&svg, nested).unwrap();
    refused(
        &["loa", "line", s(&svg), "-o", &o("line.json")],
        &["deep.svg", "is over the limit of 256"],
        &svg,
        dir.path(),
        &["deep.svg", "walk.glb"],
    );
    let keys = dir.path().join("keys.json");
    let strokes: Vec<serde_json::Value> = (0..10_000)
        .map(|k| serde_json::json!({"frame": k, "points": [[10.0, 10.0], [20.0, 40.0]]}))
        .collect();
    std::fs::write(
        &keys,
        serde_json::json!({ "keystrokes": strokes }).to_string(),
    )
    .unwrap();
    refused(
        &["loa", "line", s(&keys), "-o", &o("line.json")],
        &["keys.json", "keystrokes = 10000 is over the limit of 1000"],
        &keys,
        dir.path(),
        &["deep.svg", "keys.json", "walk.glb"],
    );
    // Two keystrokes 500,000 frames apart: every frame between them would be a pose.
    let far = dir.path().join("far.json");
    let stroke = [[10.0, 10.0], [20.0, 40.0], [30.0, 80.0]];
    std::fs::write(
        &far,
        serde_json::json!({ "keystrokes": [
            {"frame": 0, "points": stroke},
            {"frame": 500_000i64, "points": stroke},
        ] })
        .to_string(),
    )
    .unwrap();
    refused(
        &["loa", "line", s(&far), "-o", &o("line.json")],
        &[
            "far.json",
            "line frames (first keystroke to last, then the settle frames) = 1000001 is over the limit of 100000",
        ],
        &far,
        dir.path(),
        &["deep.svg", "far.json", "keys.json", "walk.glb"],
    );
}

/// The clumsy cases: a negative --fps, a constant expression that is NaN, a two-vertex OBJ
/// face, random bytes named .obj, a BVH frame time of 1e-30 s — each one line with the fix.
#[test]
fn clumsy_inputs_get_one_line_with_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("walk.glb");
    std::fs::copy(data("characters/CesiumMan.glb"), &input).unwrap();
    let o = |n: &str| s(&dir.path().join(n)).to_string();
    let i = s(&input);
    refused(
        &["convert", i, &o("c.pc2"), "--fps", "-1"],
        &["--fps", "-1"],
        &input,
        dir.path(),
        &["walk.glb"],
    );
    let out = toonkit(&["convert", i, &o("c.pc2"), "--fps", "-1"]);
    assert!(
        !String::from_utf8_lossy(&out.stderr).contains("unexpected argument"),
        "a negative number is read as a number"
    );
    refused(
        &[
            "smear",
            "elongate",
            i,
            "-o",
            &o("e.glb"),
            "--expr",
            "1/0 + log(-1)",
        ],
        &["--expr", "1/0 + log(-1)", "every frame and vertex"],
        &input,
        dir.path(),
        &["walk.glb"],
    );
    let edge = dir.path().join("edge.obj");
    std::fs::write(&edge, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n").unwrap();
    refused(
        &["convert", s(&edge), &o("e.glb")],
        &[
            "edge.obj",
            "a face needs at least 3 vertices, this one has 2",
        ],
        &edge,
        dir.path(),
        &["edge.obj", "walk.glb"],
    );
    let noise = dir.path().join("noise.obj");
    let bytes: Vec<u8> = (0..4096u32)
        .map(|k| (k.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    std::fs::write(&noise, bytes).unwrap();
    refused(
        &["info", s(&noise)],
        &["noise.obj", "not an OBJ file"],
        &noise,
        dir.path(),
        &["edge.obj", "noise.obj", "walk.glb"],
    );
    let bvh = dir.path().join("fast.bvh");
    std::fs::write(
        &bvh,
        "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xposition Yposition Zposition\n  \
         End Site\n  {\n    OFFSET 0 1 0\n  }\n}\nMOTION\nFrames: 10\nFrame Time: 1e-30\n"
            .to_string()
            + &"0 0 0\n".repeat(10),
    )
    .unwrap();
    refused(
        &["convert", s(&bvh), &o("b.glb")],
        &["fast.bvh", "frame time 1e-30 s is below"],
        &bvh,
        dir.path(),
        &["edge.obj", "fast.bvh", "noise.obj", "walk.glb"],
    );
}

/// A `.gltf` whose buffer points outside its folder (absolute, `..`, `file:`, a device) is
/// refused by every command before anything is read from there.
#[test]
fn a_gltf_buffer_outside_its_folder_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    for uri in ["/etc/hostname", "../x.bin", "file:///dev/zero", "/dev/zero"] {
        let path = testdata::gltf_with_buffer_uri(dir.path(), uri);
        refused(
            &["convert", s(&path), s(&dir.path().join("x.obj"))],
            &["escape.gltf", uri],
            &path,
            dir.path(),
            &["escape.gltf"],
        );
    }
}

/// Keys at 0 and 2,000 s on CesiumMan: 48,001 frames × 3,273 vertices are within the default
/// point budget, but 1.9 GB do not fit a 2 GB address space. That allocation failing was the
/// "panic in bytemuck" (exit 101); under `ulimit -v` the budget is half the address space, so
/// it is now refused before allocating, in one line naming the file and what to lower.
#[cfg(target_os = "linux")]
#[test]
fn a_clip_within_budget_that_does_not_fit_in_memory_is_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("walk.glb");
    rekeyed_glb(&data("characters/CesiumMan.glb"), &[0.0, 2_000.0], &input);
    let script = format!(
        "ulimit -v 2000000 && exec '{}' convert '{}' '{}'",
        env!("CARGO_BIN_EXE_toonkit"),
        s(&input),
        s(&dir.path().join("walk.pc2"))
    );
    let out = std::process::Command::new("sh")
        .args(["-c", &script])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("walk.glb: frames × vertices = 1.5710727e8 is over the limit of"),
        "{err}"
    );
    assert!(err.contains("lower --fps or pick a shorter clip"), "{err}");
    assert_eq!(file_names(dir.path()), ["walk.glb"]);
}
