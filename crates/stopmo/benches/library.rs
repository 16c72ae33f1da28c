//! Table 1 scale benchmark of the replacement-library optimization (Bunny row: 11,595
//! vertices × 5,177 frames × 200 labels; the paper reports 152 s).
//!
//! Data: the ICT face talk animation (9,409 vertices, 1,800 frames) looped to 5,177 frames
//! (each loop phase-shifted, its displacement amplitude varied, plus a smooth low-rank
//! perturbation) and padded to 11,595 vertices with displaced copies of face vertices.
//!
//! Run: `cargo bench -p toonkit-stopmo --bench library` (options after `--`:
//! `--frames N --vertices M --labels D --restarts R`). Prints energy, iterations, time and
//! peak memory, and the CPU seconds (user + system) of reduction + solve.

use std::time::Instant;

use anim::{sample, MeshAnimation, SampleOptions};
use glam::Vec3;
use stopmo::library::{PartProblem, PartSetup, SolveOptions, SubspaceOptions};

fn arg(name: &str, default: usize) -> usize {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn peak_rss_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| {
                l.split_whitespace()
                    .nth(1)
                    .and_then(|v| v.parse::<f64>().ok())
            })
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

/// User + system CPU seconds of this process so far (`/proc/self/stat`, 100 ticks per
/// second), to compare runs on a loaded machine where wall time is meaningless.
fn cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            let rest = s.rsplit_once(')')?.1;
            let f: Vec<&str> = rest.split_whitespace().collect();
            let (u, k): (f64, f64) = (f.get(11)?.parse().ok()?, f.get(12)?.parse().ok()?);
            Some((u + k) / 100.0)
        })
        .unwrap_or(f64::NAN)
}

fn main() {
    let (frames, vertices, labels) = (
        arg("--frames", 5177),
        arg("--vertices", 11_595),
        arg("--labels", 200),
    );
    let restarts = arg("--restarts", 2);
    let scene = tkio::gltf::read(testdata::asset("face/ict-face-talk.glb").as_path())
        .unwrap_or_else(|e| panic!("face/ict-face-talk.glb: {e}"));
    let sampled = sample(
        &scene,
        &SampleOptions {
            fps: 30.0,
            ..SampleOptions::default()
        },
    )
    .expect("sample face");
    let face = &sampled.objects[0].animation;
    let (fn_, fm) = (face.frame_count(), face.vertex_count());
    // Mean face for displacements.
    let mut mean = vec![Vec3::ZERO; fm];
    for f in face.frames() {
        mean.iter_mut()
            .zip(f)
            .for_each(|(m, p)| *m += *p / fn_ as f32);
    }
    let diag = face.bbox().diagonal();
    let t0 = Instant::now();
    let mut positions = Vec::with_capacity(frames * vertices);
    for f in 0..frames {
        let lap = f / fn_;
        let src = face.frame((f + lap * 377) % fn_);
        let amp = 1.0 + 0.15 * lap as f32;
        let wobble = 0.002 * diag * (f as f32 * 0.05).sin();
        for v in 0..vertices {
            let i = v % fm;
            let offset = if v >= fm {
                Vec3::new(0.0, 0.0, -0.05 * diag)
            } else {
                Vec3::ZERO
            };
            let p = mean[i] + (src[i] - mean[i]) * amp + offset;
            positions.push(p + Vec3::new(wobble * (mean[i].y / diag), 0.0, wobble));
        }
    }
    let mut mesh = face.mesh.clone();
    mesh.positions = positions[..vertices].to_vec();
    mesh.triangles.clear();
    mesh.normals = None;
    mesh.uvs = None;
    mesh.colors = None;
    let anim = MeshAnimation::new(mesh, 30.0, positions).expect("synthetic animation");
    println!(
        "data: {frames} frames x {vertices} vertices x {labels} labels (built in {:.2} s), {} threads",
        t0.elapsed().as_secs_f64(),
        rayon::current_num_threads()
    );
    let (t, cpu0) = (Instant::now(), cpu_seconds());
    let problem = PartProblem::new(&anim, &PartSetup::default(), &SubspaceOptions::default(), 1)
        .expect("problem");
    let t_reduce = t.elapsed().as_secs_f64();
    let opts = SolveOptions {
        restarts,
        max_iterations: arg("--iterations", stopmo::library::DEFAULT_MAX_ITERATIONS),
        ..SolveOptions::default()
    };
    let t = Instant::now();
    let s = problem.solve(labels, &opts).expect("solve");
    let t_solve = t.elapsed().as_secs_f64();
    println!(
        "reduction: {t_reduce:.2} s (dim {}, captured {:.7})",
        problem.reduced_dimension(),
        problem.captured()
    );
    println!(
        "solve: {t_solve:.2} s, {restarts} restarts, best run {} iterations, energy {:.6e} (first label step {:.6e})",
        s.iterations,
        s.energy,
        s.history[0]
    );
    println!(
        "total: {:.2} s (paper Table 1: 152 s; target <= 7.6 s), {:.2} CPU s",
        t_reduce + t_solve,
        cpu_seconds() - cpu0
    );
    println!("peak memory: {:.0} MiB", peak_rss_mib());
}
