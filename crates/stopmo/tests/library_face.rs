//! Acceptance on the ICT face talk animation (1,800 frames, 9,409 vertices): two parts with
//! 20 + 30 pieces; Fig. 19's comparison of λ = 2, λ = 0 (k-means) and uniform sampling.

use std::path::Path;

use anim::{sample, Mesh, MeshAnimation, SampleOptions};
use stopmo::library::{
    build_library, check_solid, shooting_order, Library, LibraryOptions, LibrarySize, Method,
    PartInput, PartSetup, SolveOptions,
};

const FACE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../assets/face/ict-face-talk.glb"
);

fn face() -> MeshAnimation {
    assert!(Path::new(FACE).exists(), "missing test asset {FACE}");
    let scene = tkio::gltf::read(Path::new(FACE)).unwrap_or_else(|e| panic!("{FACE}: {e}"));
    let sampled = sample(
        &scene,
        &SampleOptions {
            fps: 30.0,
            ..SampleOptions::default()
        },
    )
    .expect("sample the face clip");
    sampled
        .objects
        .into_iter()
        .next()
        .expect("face mesh")
        .animation
}

/// Splits the face into an upper and a lower part at the mean rest height (a stand-in for
/// the segmentation module): triangles go to the part of their first vertex.
fn split(face: &MeshAnimation) -> Vec<MeshAnimation> {
    let m = face.vertex_count();
    let rest = face.frame(0);
    let cut = rest.iter().map(|p| p.y).sum::<f32>() / m as f32;
    let mut parts = Vec::new();
    for (name, upper) in [("upper", true), ("lower", false)] {
        let tris: Vec<[u32; 3]> = face
            .mesh
            .triangles
            .iter()
            .copied()
            .filter(|t| (rest[t[0] as usize].y >= cut) == upper)
            .collect();
        let mut map = vec![u32::MAX; m];
        let mut keep = Vec::new();
        for t in &tris {
            for &i in t {
                if map[i as usize] == u32::MAX {
                    map[i as usize] = keep.len() as u32;
                    keep.push(i as usize);
                }
            }
        }
        let tris = tris.iter().map(|t| t.map(|i| map[i as usize])).collect();
        let mesh = Mesh::new(name, keep.iter().map(|&i| rest[i]).collect(), tris);
        let positions = face
            .frames()
            .flat_map(|f| keep.iter().map(move |&i| f[i]))
            .collect();
        parts.push(MeshAnimation::new(mesh, face.fps, positions).expect("part animation"));
    }
    parts
}

fn run(parts: &[MeshAnimation], method: Method) -> Library {
    let inputs: Vec<PartInput<'_>> = parts
        .iter()
        .map(|a| PartInput {
            animation: a,
            setup: PartSetup::default(),
        })
        .collect();
    let opts = LibraryOptions {
        size: LibrarySize::PerPart(vec![20, 30]),
        method,
        solve: SolveOptions {
            lambda: 2.0,
            restarts: 4,
            ..SolveOptions::default()
        },
        ..LibraryOptions::default()
    };
    build_library(&inputs, &opts).expect("library")
}

#[test]
fn face_fig19_stopshop_kmeans_uniform() {
    let face = face();
    assert_eq!((face.frame_count(), face.vertex_count()), (1800, 9409));
    let parts = split(&face);
    let (ours, km, uni) = (
        run(&parts, Method::StopShop),
        run(&parts, Method::KMeans),
        run(&parts, Method::Uniform),
    );
    for (name, lib) in [("lambda=2", &ours), ("lambda=0", &km), ("uniform", &uni)] {
        eprintln!(
            "{name}: energy {:.4e}, pieces {}, mm/unit {:.3}, {:.2} s, total mm {:?}",
            lib.energy,
            lib.total_pieces(),
            lib.mm_per_unit,
            lib.seconds,
            lib.errors_mm
        );
        for p in &lib.parts {
            eprintln!(
                "  {}: {:?} (iterations {})",
                p.name, p.errors_mm, p.solution.iterations
            );
        }
    }
    assert_eq!(ours.total_pieces(), 50);
    // Fig. 19b: the velocity term lowers the velocity error at the same piece count.
    assert!(ours.errors_mm.velocity_mean < km.errors_mm.velocity_mean);
    // Fig. 19a: both optimized libraries beat uniform sampling on position.
    assert!(ours.errors_mm.position_mean < uni.errors_mm.position_mean);
    assert!(km.errors_mm.position_mean < uni.errors_mm.position_mean);
    // StopShop Eq. 10 (same λ for all): ours is lowest.
    assert!(ours.energy < km.energy && ours.energy < uni.energy);
    // Every printable piece of the lower part is a closed, oriented 2-manifold.
    let k = ours.parts[1].solution.pieces.len();
    for piece in 0..k {
        let solid = ours
            .printable_piece(1, piece, &parts[1].mesh, 1.5)
            .expect("solidify");
        let check = check_solid(&solid);
        assert!(check.is_closed_manifold(), "piece {piece}: {check:?}");
    }
    let order = shooting_order(&ours.assembly());
    eprintln!(
        "shooting order: {} shots, {} swaps (in sequence: {})",
        order.shots.len(),
        order.swaps,
        order.sequential_swaps
    );
    assert!(order.swaps < order.sequential_swaps);
}
