//! `toonkit batch`: shots from a manifest in parallel, skip/resume by stamp (a killed batch
//! re-run finishes without redoing a completed shot), failing shots reported with the exit
//! code, Open Job Description templates.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant, SystemTime};

use common::{data, s, toonkit};

/// A manifest of `shots` (TOML tables without the `[[shot]]` line) written in `dir`.
fn manifest(dir: &Path, shots: &[String]) -> PathBuf {
    let text: String = shots.iter().map(|t| format!("[[shot]]\n{t}\n\n")).collect();
    let p = dir.join("shots.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn shot(name: &str, tool: &str, input: &Path, clip: &str, outputs: &[&str]) -> String {
    format!(
        "name = \"{name}\"\ntool = \"{tool}\"\ninput = \"{}\"\nclip = \"{clip}\"\noutputs = {outputs:?}",
        s(input)
    )
}

/// Stamps present in `out`, with their modification times.
fn stamps(out: &Path) -> Vec<(String, SystemTime)> {
    let Ok(dir) = std::fs::read_dir(out.join(".toonkit-batch")) else {
        return Vec::new();
    };
    let mut v: Vec<_> = dir
        .flatten()
        .filter(|e| e.path().extension().is_some_and(|x| x == "json"))
        .map(|e| {
            let name = e.path().file_stem().unwrap().to_string_lossy().into_owned();
            (name, e.metadata().unwrap().modified().unwrap())
        })
        .collect();
    v.sort();
    v
}

fn mtime(p: &Path) -> SystemTime {
    std::fs::metadata(p).unwrap().modified().unwrap()
}

/// Every output is a valid file of its format.
fn assert_valid(path: &Path) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    match path.extension().unwrap().to_str().unwrap() {
        "abc" => {
            let a = tkio::abc::read(&bytes).unwrap();
            assert!(!a.meshes[0].frames.is_empty(), "{}", path.display());
        }
        "usdc" => assert_eq!(tkio::detect(&bytes, path), Some(tkio::Format::Usdc)),
        "pc2" => {
            let c = common::read_pc2(path);
            assert!(c.frame_count() > 1, "{}", path.display());
        }
        other => panic!("unexpected output .{other}"),
    }
}

#[test]
fn killed_batch_resumes_without_redoing_completed_shots() {
    let dir = tempfile::tempdir().unwrap();
    let robot = data("characters/RobotExpressive.glb");
    let shots = vec![
        shot(
            "a_punch",
            "convert",
            &robot,
            "Punch",
            &["a/punch.pc2", "a/punch.abc"],
        ),
        shot(
            "b_dance",
            "smear elongate",
            &robot,
            "Dance",
            &["b/dance.usdc", "b/dance.pc2"],
        ),
        shot(
            "c_punch",
            "smear elongate",
            &robot,
            "Punch",
            &["c/punch.abc", "c/punch.pc2"],
        ),
        shot(
            "d_dance",
            "convert",
            &robot,
            "Dance",
            &["d/dance.abc", "d/dance.usdc"],
        ),
    ];
    let m = manifest(dir.path(), &shots);
    let out = dir.path().join("out");
    // One shot at a time; kill the batch as soon as the first shot is stamped.
    let mut child = Command::new(env!("CARGO_BIN_EXE_toonkit"))
        .args(["batch", s(&m), "-o", s(&out), "--jobs", "1"])
        .spawn()
        .unwrap();
    let t = Instant::now();
    while stamps(&out).is_empty() && t.elapsed() < Duration::from_secs(120) {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let _ = child.kill();
    let _ = child.wait();
    let before = stamps(&out);
    assert!(!before.is_empty(), "no shot finished before the kill");
    assert!(
        before.len() < 4,
        "every shot finished before the kill: {before:?}"
    );
    let kept: Vec<(PathBuf, SystemTime)> = ["a/punch.pc2", "a/punch.abc"]
        .iter()
        .map(|o| (out.join(o), mtime(&out.join(o))))
        .collect();

    let summary = common::json(&["batch", s(&m), "-o", s(&out), "--jobs", "2"]);
    let status: Vec<(&str, &str)> = summary["shots"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| (r["name"].as_str().unwrap(), r["status"].as_str().unwrap()))
        .collect();
    for (name, st) in &status {
        let was_done = before.iter().any(|(n, _)| n == name);
        let want = if was_done { "skipped" } else { "done" };
        assert_eq!(*st, want, "shot {name}: {summary}");
    }
    assert_eq!(summary["failed"], 0);
    // Completed shots were not redone: stamps and outputs untouched.
    let after = stamps(&out);
    for (name, time) in &before {
        assert!(
            after.contains(&(name.clone(), *time)),
            "stamp of {name} rewritten"
        );
    }
    for (p, time) in &kept {
        assert_eq!(mtime(p), *time, "{} rewritten", p.display());
    }
    for o in [
        "a/punch.pc2",
        "a/punch.abc",
        "b/dance.usdc",
        "b/dance.pc2",
        "c/punch.abc",
        "c/punch.pc2",
        "d/dance.abc",
        "d/dance.usdc",
    ] {
        assert_valid(&out.join(o));
    }
    assert_eq!(after.len(), 4);
    // No temporary file of the killed writer is left behind.
    for sub in ["a", "b", "c", "d"] {
        for e in std::fs::read_dir(out.join(sub)).unwrap().flatten() {
            let n = e.file_name().to_string_lossy().into_owned();
            assert!(!n.ends_with(".tmp"), "left behind: {n}");
        }
    }
    // A third run does nothing; changing a shot's options redoes that shot only.
    let again = common::json(&["batch", s(&m), "-o", s(&out)]);
    assert_eq!(again["skipped"], 4, "{again}");
    let mut changed = shots.clone();
    changed[3] = changed[3].replace("clip = \"Dance\"", "clip = \"Punch\"");
    let m = manifest(dir.path(), &changed);
    let third = common::json(&["batch", s(&m), "-o", s(&out)]);
    assert_eq!(
        (third["skipped"].as_u64(), third["done"].as_u64()),
        (Some(3), Some(1)),
        "{third}"
    );
}

#[test]
fn a_failing_shot_is_reported_and_the_others_are_made() {
    let dir = tempfile::tempdir().unwrap();
    let robot = data("characters/RobotExpressive.glb");
    let shots = vec![
        shot("good", "convert", &robot, "Punch", &["good.abc"]),
        shot("bad_clip", "convert", &robot, "NoSuchClip", &["bad.abc"]),
        shot(
            "missing",
            "convert",
            &dir.path().join("absent.glb"),
            "Punch",
            &["m.abc"],
        ),
        shot("good2", "convert", &robot, "Wave", &["good2.usdc"]),
    ];
    let m = manifest(dir.path(), &shots);
    let out = dir.path().join("out");
    let run = toonkit(&["--json", "batch", s(&m), "-o", s(&out), "--jobs", "2"]);
    assert_eq!(
        run.status.code(),
        Some(2),
        "exit code 2 when any shot failed"
    );
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("2 of 4 shots failed") && !stderr.contains("panicked"),
        "{stderr}"
    );
    let summary: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    assert_eq!(
        (summary["done"].as_u64(), summary["failed"].as_u64()),
        (Some(2), Some(2))
    );
    for r in summary["shots"].as_array().unwrap() {
        let name = r["name"].as_str().unwrap();
        if name.starts_with("good") {
            assert_eq!(r["status"], "done", "{r}");
        } else {
            assert_eq!(r["status"], "failed", "{r}");
            let e = r["error"].as_str().unwrap();
            assert!(
                e.contains(&format!("shot '{name}'")) && !e.contains('\n'),
                "{e}"
            );
        }
    }
    assert!(summary["shots"][1]["error"]
        .as_str()
        .unwrap()
        .contains("NoSuchClip"));
    assert!(summary["shots"][2]["error"]
        .as_str()
        .unwrap()
        .contains("absent.glb"));
    assert_valid(&out.join("good.abc"));
    assert_valid(&out.join("good2.usdc"));
    assert!(!out.join("bad.abc").exists() && !out.join("m.abc").exists());
    // One shot only, by name.
    let one = common::json(&["batch", s(&m), "-o", s(&out), "--shot", "good"]);
    assert_eq!(
        (
            one["skipped"].as_u64(),
            one["shots"].as_array().unwrap().len()
        ),
        (Some(1), 1)
    );
    // The exit code is said in --help.
    let help = common::ok(&["batch", "--help"]);
    assert!(help.contains("2 when any shot failed"), "{help}");
    // A bad manifest is one line, exit 2.
    std::fs::write(&m, "[[shot]]\nname = \"x\"\n").unwrap();
    common::assert_bad_input(&["batch", s(&m)], "shots.toml");
}

#[test]
fn openjd_template_has_one_step_per_tool_and_one_task_per_shot() {
    let dir = tempfile::tempdir().unwrap();
    let robot = data("characters/RobotExpressive.glb");
    let shots = vec![
        shot("p1", "convert", &robot, "Punch", &["p1.abc"]),
        shot("p2", "smear elongate", &robot, "Punch", &["p2.abc"]),
        shot("p3", "convert", &robot, "Wave", &["p3.usdc"]),
    ];
    let m = manifest(dir.path(), &shots);
    let job = dir.path().join("job.yaml");
    common::ok(&[
        "batch",
        s(&m),
        "-o",
        s(&dir.path().join("out")),
        "--openjd",
        s(&job),
    ]);
    let text = std::fs::read_to_string(&job).unwrap();
    assert!(
        text.contains("specificationVersion: \"jobtemplate-2023-09\""),
        "{text}"
    );
    // Steps in order of first use, each listing its shots as the task parameter's range.
    let at = |needle: &str| {
        text.find(needle)
            .unwrap_or_else(|| panic!("{needle}:\n{text}"))
    };
    let order = [
        at("- name: \"convert\""),
        at("- \"p1\""),
        at("- \"p3\""),
        at("- name: \"smear\""),
        at("- \"p2\""),
    ];
    assert!(order.windows(2).all(|w| w[0] < w[1]), "{text}");
    assert_eq!(text.matches("name: \"Shot\"").count(), 2, "{text}");
    for p in [
        "ManifestFile",
        "OutputDir",
        "Toonkit",
        "{{Task.Param.Shot}}",
    ] {
        assert!(text.contains(p), "{p} missing:\n{text}");
    }
    assert!(!out_exists(dir.path()), "--openjd runs nothing");
}

fn out_exists(dir: &Path) -> bool {
    dir.join("out").exists()
}

/// `toonkit batch --json` on `m` into `out`: (exit code, shot name → status).
fn run_statuses(m: &Path, out: &Path) -> (Option<i32>, Vec<(String, String)>, String) {
    let o = toonkit(&["--json", "batch", s(m), "-o", s(out)]);
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
    let status = v["shots"]
        .as_array()
        .map(|a| {
            a.iter()
                .map(|r| {
                    let f = |k: &str| r[k].as_str().unwrap_or_default().to_string();
                    (f("name"), f("status"))
                })
                .collect()
        })
        .unwrap_or_default();
    (o.status.code(), status, text)
}

/// Outputs are confined to the output folder: `../../x.glb` and `/abs/x.glb` are refused
/// before anything runs, naming the shot, the output and the fix.
#[test]
fn outputs_outside_the_output_folder_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let robot = data("characters/RobotExpressive.glb");
    let escape = dir.path().join("escaped.pc2");
    for bad in ["../../x.pc2", s(&escape)] {
        let m = manifest(dir.path(), &[shot("a", "convert", &robot, "Punch", &[bad])]);
        common::assert_bad_input(
            &["batch", s(&m), "-o", s(&dir.path().join("out"))],
            "must stay inside the output folder",
        );
    }
    assert!(!escape.exists() && !dir.path().join("out").exists());
}

/// A shot whose output is its own input (or another shot's input) fails before it writes:
/// the input keeps every byte and the other shots are made.
#[test]
fn a_shot_writing_over_an_input_fails_and_the_input_is_kept() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("walk.glb");
    std::fs::copy(data("characters/CesiumMan.glb"), &input).unwrap();
    let before = std::fs::read(&input).unwrap();
    // Another shot's output names the input of `reader` (it would break that shot).
    let robot = data("characters/RobotExpressive.glb");
    let run = dir.path().join("run.glb");
    std::fs::copy(data("characters/CesiumMan.glb"), &run).unwrap();
    let shots = vec![
        shot("own", "convert", &input, "0", &["walk.glb"]),
        shot("fine", "convert", &input, "0", &["walk.abc"]),
        shot("across", "convert", &robot, "Wave", &["run.glb"]),
        shot("reader", "convert", &run, "0", &["run.abc"]),
    ];
    let m = manifest(dir.path(), &shots);
    let (code, status, text) = run_statuses(&m, dir.path());
    assert_eq!(code, Some(2), "shots failed: exit 2: {text}");
    assert_eq!(
        status,
        [
            ("own".into(), "failed".into()),
            ("fine".into(), "done".into()),
            ("across".into(), "failed".into()),
            ("reader".into(), "done".into())
        ],
        "{text}"
    );
    assert!(text.contains("is its own input"), "{text}");
    assert!(text.contains("is the input of shot 'reader'"), "{text}");
    assert!(text.contains("name another output"), "{text}");
    assert_eq!(std::fs::read(&input).unwrap(), before);
    assert_eq!(
        std::fs::read(&run).unwrap(),
        std::fs::read(data("characters/CesiumMan.glb")).unwrap()
    );
}

/// The stamp covers every file a shot read, not only the manifest's input: an edited
/// external `.bin` of a `.gltf`, an edited option file (`collider = "floor.obj"`) or a
/// deleted implicit rest `.obj` make the shot run again; an edited output is made again too.
#[test]
fn stamps_hash_every_file_a_shot_reads_and_writes() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("walk.pc2");
    common::ok(&["convert", s(&data("characters/CesiumMan.glb")), s(&cache)]);
    let floor = dir.path().join("floor.obj");
    std::fs::write(
        &floor,
        "v -9 0 -9\nv 9 0 -9\nv 9 0 9\nv -9 0 9\nf 1 2 3 4\n",
    )
    .unwrap();
    let mut collide = shot("collide", "smear elongate", &cache, "0", &["c.glb"]);
    collide = collide.replace(
        "clip = \"0\"",
        &format!("options = {{ collider = \"{}\" }}", s(&floor)),
    );
    let mut plain = shot("plain", "convert", &cache, "0", &["p.abc"]);
    plain = plain.replace("clip = \"0\"\n", "");
    // A .gltf whose one triangle lies in tri.bin beside it.
    let gltf = dir.path().join("tri.gltf");
    std::fs::write(
        &gltf,
        r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"tri.bin","byteLength":36}],
        "bufferViews":[{"buffer":0,"byteLength":36}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
        "min":[0,0,0],"max":[1,1,0]}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
        "nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0}"#,
    )
    .unwrap();
    let bin = |y: f32| -> Vec<u8> {
        [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, y, 0.0]
            .iter()
            .flat_map(|c| c.to_le_bytes())
            .collect()
    };
    std::fs::write(dir.path().join("tri.bin"), bin(1.0)).unwrap();
    let mut tri = shot("tri", "convert", &gltf, "0", &["tri.obj"]);
    tri = tri.replace("clip = \"0\"\n", "");
    let m = manifest(dir.path(), &[collide, plain, tri]);
    let out = dir.path().join("out");
    let statuses = |want: [&str; 3]| {
        let (_, status, text) = run_statuses(&m, &out);
        let got: Vec<&str> = status.iter().map(|(_, s)| s.as_str()).collect();
        assert_eq!(got, want, "{text}");
    };
    statuses(["done", "done", "done"]);
    statuses(["skipped", "skipped", "skipped"]);
    // The option file changes: only the shot that read it runs again.
    std::fs::write(
        &floor,
        "v -9 -1 -9\nv 9 -1 -9\nv 9 -1 9\nv -9 -1 9\nf 1 2 3 4\n",
    )
    .unwrap();
    statuses(["done", "skipped", "skipped"]);
    // The external buffer of the .gltf changes: its shot runs again, with the new bytes.
    std::fs::write(dir.path().join("tri.bin"), bin(2.0)).unwrap();
    statuses(["skipped", "skipped", "done"]);
    let obj = std::fs::read_to_string(out.join("tri.obj")).unwrap();
    assert!(obj.contains("v 0 2 0"), "{obj}");
    // An output edited by hand is made again.
    std::fs::write(out.join("p.abc"), b"edited").unwrap();
    statuses(["skipped", "done", "skipped"]);
    // The implicit rest mesh of the cache is gone: both its shots run again (and fail).
    std::fs::remove_file(dir.path().join("walk.obj")).unwrap();
    statuses(["failed", "failed", "skipped"]);
}
