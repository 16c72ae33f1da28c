//! Feature-film-scale benchmark of the whole `toonkit stopmo library` process.
//!
//! Writes the inputs (glTF, through `tkio`) from the bundled talking face, seeded:
//! * `face-speech.glb`: 10,000 frames of speech-like morph weights, 9,409 vertices,
//!   55 morph targets, 30 fps (`--face-frames N`);
//! * `face-table1.glb`: StopShop Table 1's Bunny row: refined to 11,595 vertices, 5,177
//!   frames (`--table1-frames N`, `--table1-vertices M`);
//!
//! then, for every `--toonkit BIN` given (several compare builds; runs interleave), runs
//! * `face20`: `BIN stopmo library face-speech.glb --fps 30 --pieces 20 --no-print`;
//! * `table1`: `BIN stopmo library face-table1.glb --fps 30 --pieces 200 --restarts 8
//!   --no-print`;
//! * `print20`: `BIN stopmo library ict-face-talk.glb --pieces 20` (printable pieces),
//!
//! `--repeat K` times each, and prints wall, user and system CPU seconds and peak resident
//! memory of the whole process (`/usr/bin/time -v`, Linux), plus the optimization seconds,
//! energy and `peak_memory_mib` of its `report.json`. `--cases face20,table1` picks cases.
//!
//! Run: `scripts/bench_stopmo.sh` (builds the release CLI first), or
//! `cargo bench --workspace --bench scale -- --toonkit target/release/toonkit`.
//! Without `--toonkit` only the inputs are written (to `--out DIR`, default
//! `target/stopmo-scale`; existing inputs are kept).

#[path = "../tests/scale_inputs/mod.rs"]
mod scale_inputs;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use scale_inputs::{face_scene, refine, speech_face};

/// The seed of every generated input.
const SEED: u64 = 52;

fn arg(name: &str) -> Vec<String> {
    let args: Vec<String> = std::env::args().collect();
    args.windows(2)
        .filter(|w| w[0] == name)
        .map(|w| w[1].clone())
        .collect()
}

fn arg_usize(name: &str, default: usize) -> usize {
    arg(name)
        .last()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Writes `scene` as a float glTF at `path` unless it is there already.
fn write(path: &Path, make: impl FnOnce() -> anim::Scene) {
    if path.is_file() {
        println!("input {} (kept)", path.display());
        return;
    }
    let t = Instant::now();
    let scene = make();
    let bytes = tkio::gltf::write_glb_with(&scene, tkio::gltf::GlbOptions { quantize: false })
        .expect("encode glb");
    tkio::save(path, &tkio::Output::Bytes(&bytes)).expect("write glb");
    let sm = &scene.meshes[0];
    println!(
        "input {}: {} vertices, {} morph targets, {} frames at 30 fps ({:.1} s)",
        path.display(),
        sm.mesh.vertex_count(),
        sm.morph_targets.len(),
        scene.clips[0].frame_count(30.0),
        t.elapsed().as_secs_f64()
    );
}

/// One whole-process measurement.
struct Figures {
    wall: f64,
    user: f64,
    system: f64,
    rss_mib: f64,
    report: serde_json::Value,
}

/// `key: value` of `/usr/bin/time -v`'s output.
fn time_field(text: &str, key: &str) -> Option<String> {
    text.lines()
        .find_map(|l| l.trim().strip_prefix(key))
        .map(|v| v.trim_start_matches(':').trim().to_string())
}

fn seconds(clock: &str) -> f64 {
    // h:mm:ss or m:ss.ss
    clock.split(':').fold(0.0, |acc, p| {
        acc * 60.0 + p.parse::<f64>().unwrap_or(f64::NAN)
    })
}

fn run(bin: &Path, input: &Path, out: &Path, extra: &[&str]) -> Figures {
    let report = out.join("bench_report.json");
    let _ = std::fs::remove_dir_all(out);
    let o = Command::new("/usr/bin/time")
        .arg("-v")
        .arg(bin)
        .args(["stopmo", "library"])
        .arg(input)
        .arg("-o")
        .arg(out)
        .args(extra)
        .arg("--report")
        .arg(&report)
        .output()
        .expect("run /usr/bin/time (apt-get install time)");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{} failed:\n{err}", bin.display());
    let f = |k: &str| time_field(&err, k).unwrap_or_default();
    let report = std::fs::read_to_string(&report)
        .ok()
        .and_then(|s| serde_json::from_str(&s).ok())
        .unwrap_or(serde_json::Value::Null);
    Figures {
        wall: seconds(&f("Elapsed (wall clock) time (h:mm:ss or m:ss)")),
        user: f("User time (seconds)").parse().unwrap_or(f64::NAN),
        system: f("System time (seconds)").parse().unwrap_or(f64::NAN),
        rss_mib: f("Maximum resident set size (kbytes)")
            .parse::<f64>()
            .map_or(f64::NAN, |kb| kb / 1024.0),
        report,
    }
}

fn main() {
    let out = arg("--out")
        .last()
        .map_or_else(|| PathBuf::from("../../target/stopmo-scale"), PathBuf::from);
    std::fs::create_dir_all(&out).expect("output folder");
    let face_frames = arg_usize("--face-frames", 10_000);
    let (t1_frames, t1_vertices) = (
        arg_usize("--table1-frames", 5_177),
        arg_usize("--table1-vertices", 11_595),
    );
    let face = face_scene();
    let speech = out.join(format!("face-speech-{face_frames}.glb"));
    write(&speech, || speech_face(&face, face_frames, 30.0, SEED));
    let table1 = out.join(format!("face-table1-{t1_vertices}x{t1_frames}.glb"));
    write(&table1, || {
        speech_face(&refine(&face, t1_vertices), t1_frames, 30.0, SEED + 1)
    });
    drop(face);
    let talk = testdata::asset("face/ict-face-talk.glb");
    let all = [
        (
            "face20",
            speech.as_path(),
            vec!["--fps", "30", "--pieces", "20", "--no-print"],
        ),
        (
            "table1",
            table1.as_path(),
            vec![
                "--fps",
                "30",
                "--pieces",
                "200",
                "--restarts",
                "8",
                "--no-print",
            ],
        ),
        ("print20", talk.as_path(), vec!["--pieces", "20"]),
    ];
    let picked: Vec<String> = arg("--cases")
        .last()
        .map_or_else(
            || "face20,table1,print20".to_string(),
            std::string::ToString::to_string,
        )
        .split(',')
        .map(str::to_string)
        .collect();
    let bins: Vec<PathBuf> = arg("--toonkit").into_iter().map(PathBuf::from).collect();
    let repeat = arg_usize("--repeat", 1);
    println!(
        "{:8} {:40} {:>7} {:>7} {:>6} {:>8} {:>8} {:>8} {:>14}",
        "case", "binary", "wall s", "user s", "sys s", "RSS MiB", "report", "opt s", "energy"
    );
    for (name, input, extra) in &all {
        if !picked.iter().any(|p| p == name) {
            continue;
        }
        for _ in 0..repeat {
            for (i, bin) in bins.iter().enumerate() {
                let f = run(bin, input, &out.join(format!("{name}-{i}")), extra);
                let r = &f.report;
                println!(
                    "{:8} {:40} {:7.2} {:7.2} {:6.2} {:8.0} {:>8} {:8.2} {:14.6e}",
                    name,
                    bin.display().to_string(),
                    f.wall,
                    f.user,
                    f.system,
                    f.rss_mib,
                    r["peak_memory_mib"]
                        .as_f64()
                        .map_or("-".to_string(), |v| format!("{v:.0}")),
                    r["seconds"].as_f64().unwrap_or(f64::NAN),
                    r["energy"].as_f64().unwrap_or(f64::NAN),
                );
            }
        }
    }
}
