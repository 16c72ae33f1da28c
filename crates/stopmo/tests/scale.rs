//! Small versions of the scale bench's inputs (`benches/scale.rs`): the speech-like face and
//! the refined Table 1 face, written as glTF and read back the way the jobs read a user's
//! file, then solved.

mod scale_inputs;

use anim::{sample, SampleOptions, Scene};
use stopmo::{LibraryJobOptions, PieceCount};

use scale_inputs::{face_scene, refine, speech_face};

/// Through a glTF file, as a front end reads it.
fn round_trip(scene: &Scene) -> anim::MeshAnimation {
    let bytes = tkio::gltf::write_glb_with(scene, tkio::gltf::GlbOptions { quantize: false })
        .expect("encode");
    let back = tkio::gltf::read_bytes(&bytes).expect("decode");
    let s = sample(
        &back,
        &SampleOptions {
            fps: 30.0,
            ..SampleOptions::default()
        },
    )
    .expect("sample");
    s.objects.into_iter().next().expect("one mesh").animation
}

fn options(pieces: usize) -> LibraryJobOptions {
    LibraryJobOptions {
        pieces: PieceCount::Each(pieces),
        print: false,
        ..LibraryJobOptions::default()
    }
}

/// Table 1's input at small scale: refining keeps the surface closed where it was, adds
/// exactly the vertices asked for, and the new vertices move as the midpoints of their edge
/// in every frame (the animation is still a blend of the same morph targets).
#[test]
fn table1_refinement_adds_midpoint_vertices() {
    let face = face_scene();
    let m0 = face.meshes[0].mesh.vertex_count();
    let refined = speech_face(&refine(&face, m0 + 300), 40, 30.0, 7);
    let mesh = &refined.meshes[0].mesh;
    assert_eq!(mesh.vertex_count(), m0 + 300);
    assert_eq!(
        mesh.triangle_count(),
        face.meshes[0].mesh.triangle_count() + 600
    );
    // No T-junction: every edge is used by one or two triangles, as in the input.
    let mut uses = std::collections::BTreeMap::<(u32, u32), usize>::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    assert!(
        uses.values().all(|&u| u <= 2),
        "an edge has three triangles"
    );
    let anim = round_trip(&refined);
    assert_eq!((anim.frame_count(), anim.vertex_count()), (40, m0 + 300));
    // Each new vertex sits at the midpoint of an edge it splits, in the last frame too.
    let f = anim.frame(39);
    let new = m0 + 17;
    let mid_of_neighbours = mesh
        .triangles
        .iter()
        .filter(|t| t.contains(&(new as u32)))
        .flat_map(|t| t.iter().copied())
        .filter(|&v| (v as usize) < m0)
        .collect::<Vec<u32>>();
    let hit = mid_of_neighbours.iter().any(|&a| {
        mid_of_neighbours
            .iter()
            .any(|&b| (0.5 * (f[a as usize] + f[b as usize]) - f[new]).length() < 1e-4)
    });
    assert!(
        hit,
        "vertex {new} is not the midpoint of two of its neighbours"
    );
}

/// The speech-like face at small scale: seeded (same seed, same curves; another seed,
/// other curves), it talks (the mouth moves), and the library job solves it with its peak
/// memory in the report.
#[test]
fn speech_face_is_seeded_and_solves() {
    let face = face_scene();
    let a = speech_face(&face, 240, 30.0, 1);
    assert_eq!(a.clips[0].frame_count(30.0), 240);
    assert_eq!(a, speech_face(&face, 240, 30.0, 1));
    assert_ne!(
        a.clips[0].channels[0].values,
        speech_face(&face, 240, 30.0, 2).clips[0].channels[0].values
    );
    let anim = round_trip(&a);
    let spread = (1..anim.frame_count())
        .map(|f| {
            anim.frame(f)
                .iter()
                .zip(anim.frame(0))
                .map(|(p, q)| p.distance(*q))
                .fold(0.0f32, f32::max)
        })
        .fold(0.0f32, f32::max);
    assert!(
        spread > 0.01 * anim.bbox().diagonal(),
        "the face hardly moves: {spread}"
    );
    let result = stopmo::library(std::slice::from_ref(&anim), &options(6)).expect("library");
    assert_eq!(result.report.pieces, 6);
    assert!(result.report.energy.is_finite() && result.report.energy > 0.0);
    if cfg!(target_os = "linux") {
        let peak = result.report.peak_memory_mib.expect("VmHWM on Linux");
        // At least the sampled frames themselves were resident.
        let frames_mib = (anim.positions().len() * 12) as f64 / (1024.0 * 1024.0);
        assert!(
            peak > frames_mib,
            "peak {peak} MiB < frames {frames_mib} MiB"
        );
    }
}

/// The library job borrows its parts: references to parts held elsewhere (a segmentation's,
/// a session's) give the library of the parts themselves, with no copy of their frames.
#[test]
fn borrowed_parts_give_the_library_of_owned_parts() {
    let anim = round_trip(&speech_face(&face_scene(), 90, 30.0, 3));
    let owned = stopmo::library(std::slice::from_ref(&anim), &options(4)).expect("owned");
    let borrowed = stopmo::library(&[&anim], &options(4)).expect("borrowed");
    assert_eq!(borrowed.library.parts, owned.library.parts);
    assert_eq!(borrowed.report.energy, owned.report.energy);
    assert_eq!(
        stopmo::library_memory(&[&anim]).total(),
        stopmo::library_memory(std::slice::from_ref(&anim)).total()
    );
}
