//! Round trips and corrupt-input checks of the OBJ, PC2, MDD, STL, BVH and NPY formats on the
//! real assets in `assets/`.

use std::collections::HashMap;
use std::path::PathBuf;

use anim::glam::{Quat, Vec3};
use anim::{sample, Mesh, MeshAnimation, SampleOptions, Scene};
use tkio::{bvh, mdd, npy, obj, pc2, stl};

fn asset(rel: &str) -> PathBuf {
    let p = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/")).join(rel);
    assert!(p.is_file(), "test asset missing: {}", p.display());
    p
}

fn bytes(rel: &str) -> Vec<u8> {
    let p = asset(rel);
    std::fs::read(&p).unwrap_or_else(|e| panic!("cannot read {}: {e}", p.display()))
}

fn spot() -> Mesh {
    obj::read(&bytes("meshes/spot.obj")).unwrap()
}

/// Spot twisting about +Y over `frames` frames (deterministic).
fn spot_twist(frames: usize) -> MeshAnimation {
    let mesh = spot();
    let mut pos = Vec::with_capacity(frames * mesh.vertex_count());
    for f in 0..frames {
        for p in &mesh.positions {
            pos.push(Quat::from_rotation_y(f as f32 * 0.3 * p.y) * *p + Vec3::X * f as f32 * 0.01);
        }
    }
    MeshAnimation::new(mesh, 24.0, pos).unwrap()
}

fn max_diff(a: &[Vec3], b: &[Vec3]) -> f32 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(p, q)| (*p - *q).abs().max_element())
        .fold(0.0, f32::max)
}

#[test]
fn spot_obj_reads_2930_vertices_in_file_order() {
    let text = bytes("meshes/spot.obj");
    let m = obj::read(&text).unwrap();
    assert_eq!(m.vertex_count(), 2930);
    assert_eq!(m.triangle_count(), 5856);
    m.validate().unwrap();
    // Vertex k is the k-th `v` line.
    let third_v = String::from_utf8_lossy(&text)
        .lines()
        .filter(|l| l.starts_with("v "))
        .nth(2)
        .map(|l| {
            l.split_whitespace()
                .skip(1)
                .map(|w| w.parse::<f32>().unwrap())
                .collect::<Vec<_>>()
        })
        .unwrap();
    assert_eq!(m.positions[2].to_array().to_vec(), third_v);
    // Oracle: tobj sees the same faces (it renumbers vertices, so compare positions).
    let (models, _) = tobj::load_obj_buf(
        &mut std::io::Cursor::new(&text),
        &tobj::LoadOptions {
            triangulate: true,
            ..Default::default()
        },
        |_| Err(tobj::LoadError::OpenFileFailed),
    )
    .unwrap();
    let t = &models[0].mesh;
    assert_eq!(t.indices.len(), 3 * m.triangle_count());
    let tp = |i: u32| Vec3::from_slice(&t.positions[3 * i as usize..3 * i as usize + 3]);
    for (k, tri) in m.triangles.iter().enumerate() {
        for c in 0..3 {
            assert_eq!(m.positions[tri[c] as usize], tp(t.indices[3 * k + c]));
        }
    }
}

#[test]
fn spot_obj_write_read_is_exact() {
    let m = spot();
    let again = obj::read(obj::write(&m).as_bytes()).unwrap();
    assert_eq!(again.positions, m.positions);
    assert_eq!(again.triangles, m.triangles);
    assert_eq!(again.uvs, m.uvs);
    assert_eq!(again.normals, m.normals);
}

#[test]
fn spot_obj_sequence_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let a = spot_twist(3);
    let files = obj::write_sequence(&a, &dir.path().join("spot"));
    assert_eq!(files.len(), 3);
    for (p, text) in &files {
        tkio::write_atomic(p, text.as_bytes()).unwrap();
    }
    let paths = obj::sequence_paths(&dir.path().join("spot_0001.obj")).unwrap();
    assert_eq!(paths.len(), 3);
    let b = obj::read_sequence(&paths, 24.0).unwrap();
    assert_eq!(b.frame_count(), 3);
    assert_eq!(max_diff(a.positions(), b.positions()), 0.0);
    // A frame with a different topology is rejected, naming the file.
    let mut m = a.mesh_at(0);
    m.triangles.swap(0, 1);
    tkio::write_atomic(&paths[2], obj::write(&m).as_bytes()).unwrap();
    let e = obj::read_sequence(&paths, 24.0).unwrap_err().to_string();
    assert!(
        e.contains("spot_0003.obj") && e.contains("faces differ"),
        "{e}"
    );
}

#[test]
fn spot_pc2_and_mdd_round_trip() {
    let a = spot_twist(6);
    let b = pc2::read(&pc2::write(&a), spot(), 24.0).unwrap();
    assert!(max_diff(a.positions(), b.positions()) <= 1e-6);
    assert_eq!((b.frame_count(), b.fps, b.start_time), (6, 24.0, 0.0));
    let c = mdd::read(&mdd::write(&a), spot(), 30.0).unwrap();
    assert!(max_diff(a.positions(), c.positions()) <= 1e-6);
    assert!(
        (c.fps - 24.0).abs() < 1e-3,
        "MDD times give the rate: {}",
        c.fps
    );
}

#[test]
fn spot_stl_is_a_closed_manifold() {
    let m = spot();
    let bytes = stl::write_binary(&m);
    assert_eq!(bytes.len(), 84 + 50 * m.triangle_count());
    let s = stl::read(&bytes).unwrap();
    assert_eq!((s.vertex_count(), s.triangle_count()), (2930, 5856));
    let mut edges: HashMap<(u32, u32), usize> = HashMap::new();
    for t in &s.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    assert!(
        edges.values().all(|&c| c == 2),
        "every edge is shared by two triangles"
    );
    // Euler characteristic of a sphere-like closed surface.
    let chi = s.vertex_count() as i64 - edges.len() as i64 + s.triangle_count() as i64;
    assert_eq!(chi, 2);
}

struct Mocap {
    scene: Scene,
    frames: usize,
    fps: f32,
}

fn mocap(rel: &str) -> Mocap {
    let scene = bvh::read(&bytes(rel)).unwrap();
    let clip = &scene.clips[0];
    let frames = clip.channels[0].times.len();
    let fps = 1.0 / (clip.channels[0].times[1] - clip.channels[0].times[0]);
    Mocap { scene, frames, fps }
}

fn joint_positions(scene: &Scene, fps: f32) -> (Vec<String>, Vec<Vec3>, usize) {
    let s = sample(
        scene,
        &SampleOptions {
            fps,
            ..SampleOptions::default()
        },
    )
    .unwrap();
    let names = s.skeleton.joints.iter().map(|j| j.name.clone()).collect();
    let w = s.skeletal.as_ref().unwrap();
    let pos = (0..w.frame_count()).flat_map(|f| w.frame(f).iter().map(|m| m.w_axis.truncate()));
    (names, pos.collect(), s.frame_count)
}

#[test]
fn cmu_bvh_files_read_and_sample() {
    // (file, ROOT/JOINT count, End Sites, frames) counted in the files themselves.
    for (rel, joints, ends, frames) in [
        ("mocap/02_02.bvh", 43, 14, 299),
        ("mocap/12_03.bvh", 31, 7, 566),
    ] {
        let m = mocap(rel);
        let end_nodes = m
            .scene
            .nodes
            .iter()
            .filter(|n| n.name.ends_with("_end"))
            .count();
        assert_eq!(m.scene.nodes.len(), joints + ends, "{rel}");
        assert_eq!(end_nodes, ends, "{rel}");
        assert_eq!(m.frames, frames, "{rel}");
        assert!((m.fps - 120.0).abs() < 0.01, "{rel}: {}", m.fps);
        // Sampled at the file's own rate (12_03 says .0083333 s, not 1/120: sampling at a
        // rounded 120 fps would lose the last frame).
        let (names, pos, sampled) = joint_positions(&m.scene, m.fps);
        assert_eq!(names.len(), joints, "{rel}: End Sites are not joints");
        assert_eq!(sampled, frames, "{rel}");
        assert!(pos.iter().all(|p| p.is_finite()), "{rel}");
        // The hip moves: CMU captures are not still.
        let travel = (pos[(frames - 1) * names.len()] - pos[0]).length();
        assert!(travel > 1.0, "{rel}: root travelled {travel}");
    }
}

#[test]
fn cmu_bvh_write_read_keeps_world_joint_positions() {
    for rel in ["mocap/02_02.bvh", "mocap/12_03.bvh"] {
        let m = mocap(rel);
        let s = sample(
            &m.scene,
            &SampleOptions {
                fps: m.fps,
                ..SampleOptions::default()
            },
        )
        .unwrap();
        let text = bvh::write(&s.skeleton, s.skeletal.as_ref().unwrap()).unwrap();
        let again = bvh::read(text.as_bytes()).unwrap();
        let (n1, p1, f1) = joint_positions(&m.scene, m.fps);
        let (n2, p2, f2) = joint_positions(&again, m.fps);
        assert_eq!((n1.len(), f1), (n2.len(), f2), "{rel}");
        assert_eq!(n1, n2, "{rel}: joint names and order survive");
        let err = max_diff(&p1, &p2);
        let size = anim::Aabb::from_points(&p1).diagonal();
        eprintln!(
            "{rel}: {} joints × {f1} frames, max round-trip error {err:e} (size {size})",
            n1.len()
        );
        assert!(err < 1e-4, "{rel}: max joint position difference {err}");
    }
}

#[test]
fn npy_round_trip_of_a_per_frame_field() {
    let a = spot_twist(4);
    let field: Vec<f32> = a.positions().iter().map(|p| p.length()).collect();
    let bytes = npy::write_f32(&[4, a.vertex_count()], &field).unwrap();
    assert!(bytes.len().is_multiple_of(4));
    let (shape, values) = npy::read_f32(&bytes).unwrap();
    assert_eq!(shape, vec![4, 2930]);
    assert_eq!(values, field);
}

#[test]
fn corrupt_real_files_are_errors() {
    let a = spot_twist(2);
    let p = pc2::write(&a);
    assert!(pc2::read(&p[..p.len() / 2], spot(), 24.0).is_err());
    let mut nan = p.clone();
    nan[32 + 12 * 100..32 + 12 * 100 + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    assert!(pc2::read(&nan, spot(), 24.0).is_err());
    let d = mdd::write(&a);
    assert!(mdd::read(&d[..d.len() - 7], spot(), 24.0).is_err());
    let mut wrong = d.clone();
    wrong[4..8].copy_from_slice(&2931i32.to_be_bytes());
    assert!(mdd::read(&wrong, spot(), 24.0).is_err());

    let text = bytes("meshes/spot.obj");
    let cut = String::from_utf8_lossy(&text).replacen("v ", "v 1e999 ", 1);
    assert!(obj::read(cut.as_bytes())
        .unwrap_err()
        .to_string()
        .contains("line"));
    let s = stl::write_binary(&spot());
    assert!(stl::read(&s[..s.len() - 25]).is_err());

    let b = bytes("mocap/12_03.bvh");
    let e = bvh::read(&b[..b.len() - 200]).unwrap_err().to_string();
    assert!(e.contains("MOTION has") && e.contains("line"), "{e}");
    let text = String::from_utf8_lossy(&b).replacen("{", "", 3);
    assert!(bvh::read(text.as_bytes()).is_err());
    let n = npy::write_f32(&[2, 2], &[0.0; 4]).unwrap();
    assert!(npy::read_f32(&n[..n.len() - 2]).is_err());
}

#[test]
fn cesium_man_texture_stays_upright_in_obj() {
    // glTF's v runs down from the image top, OBJ's up from the bottom: converting must flip v
    // so the texture maps the same way in both files.
    let scene = tkio::gltf::read(&asset("characters/CesiumMan.glb")).unwrap();
    let mesh = &scene.meshes[0].mesh;
    let uvs = mesh.uvs.as_ref().expect("CesiumMan has TEXCOORD_0");
    let text = obj::write(mesh);
    let vt: Vec<[f32; 2]> = text
        .lines()
        .filter_map(|l| l.strip_prefix("vt "))
        .map(|l| {
            let v: Vec<f32> = l.split(' ').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1]]
        })
        .collect();
    assert_eq!(vt.len(), uvs.len());
    for (o, g) in vt.iter().zip(uvs) {
        assert_eq!(o[0], g[0]);
        assert!((o[1] - (1.0 - g[1])).abs() < 1e-6, "{o:?} vs {g:?}");
    }
    let back = obj::read(text.as_bytes()).unwrap();
    for (a, b) in back.uvs.unwrap().iter().zip(uvs) {
        assert!((a[1] - b[1]).abs() < 1e-6);
    }
}
