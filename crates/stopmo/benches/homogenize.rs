//! Seam homogenization (StopShop Eqs. 4–9) of all 1,800 frames of the ICT face asset, two parts
//! (forehead / chin seeds). Target: ≤ 2 s on 2 cores.
//!
//! Run: `cargo bench -p toonkit-stopmo --bench homogenize` (prints the best and median of
//! five runs; a plain harness so it adds no benchmark framework to the build).

use std::time::Instant;

use stopmo::segment::{
    homogenize, resolve_seeds, PartSpec, Seed, SegmentationProblem, DEFAULT_GAMMA,
};

const FACE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../assets/face/ict-face-talk.glb"
);
const RUNS: usize = 5;

fn load_face() -> anim::MeshAnimation {
    let scene =
        tkio::gltf::read(std::path::Path::new(FACE)).unwrap_or_else(|e| panic!("{FACE}: {e}"));
    let opts = anim::SampleOptions {
        fps: 30.0,
        ..Default::default()
    };
    let sampled = anim::sample(&scene, &opts).unwrap_or_else(|e| panic!("{FACE}: {e}"));
    sampled
        .objects
        .into_iter()
        .next()
        .unwrap_or_else(|| panic!("{FACE}: no mesh"))
        .animation
}

fn main() {
    let face = load_face();
    let problem = SegmentationProblem::with_defaults(&face).expect("problem");
    let bbox = anim::Aabb::from_points(problem.average_positions());
    let mid = bbox.center();
    let parts = [
        PartSpec::new(
            "upper",
            vec![Seed::Point(glam::Vec3::new(mid.x, bbox.max.y, bbox.max.z))],
        ),
        PartSpec::new(
            "lower",
            vec![Seed::Point(glam::Vec3::new(mid.x, bbox.min.y, bbox.max.z))],
        ),
    ];
    let seeds = resolve_seeds(&face, &problem, &parts).expect("seeds");
    let labels = problem.label(&seeds, DEFAULT_GAMMA);
    let mut times = Vec::with_capacity(RUNS);
    let mut last = None;
    for _ in 0..RUNS {
        let t = Instant::now();
        let (_, stats) = homogenize(&face, &labels, 1e-6).expect("homogenize");
        times.push(t.elapsed().as_secs_f64());
        last = Some(stats);
    }
    times.sort_by(f64::total_cmp);
    let stats = last.expect("at least one run");
    println!(
        "homogenize {} frames x {} vertices ({} free, {} pinned): best {:.3} s, median {:.3} s \
         (last run: factor {:.3} s, solve {:.3} s; threads {})",
        face.frame_count(),
        face.vertex_count(),
        stats.free_vertices,
        stats.pinned_vertices,
        times[0],
        times[RUNS / 2],
        stats.factor_seconds,
        stats.solve_seconds,
        rayon::current_num_threads()
    );
}
