//! `toonkit smear elongate | multiples` with the flags of issue #22: `--subdivide`,
//! `--ground`/`--squash`, `--causal`, `--revolve`.

mod common;

use std::path::{Path, PathBuf};

use anim::glam::Vec3;
use anim::{Mesh, MeshAnimation};
use common::*;

/// A low-poly ball (4 rings × 6 segments, 36 triangles) dropping onto y = 0 while moving
/// along +X, written as `dir/drop.pc2` + `dir/drop.obj`.
fn write_drop(dir: &Path) -> PathBuf {
    let (rings, segments) = (4usize, 6usize);
    let mut p = vec![Vec3::Y, -Vec3::Y];
    for a in 1..rings {
        let th = std::f32::consts::PI * a as f32 / rings as f32;
        for b in 0..segments {
            let ph = std::f32::consts::TAU * b as f32 / segments as f32;
            p.push(Vec3::new(
                th.sin() * ph.cos(),
                th.cos(),
                th.sin() * ph.sin(),
            ));
        }
    }
    let idx = |a: usize, b: usize| (2 + (a - 1) * segments + b % segments) as u32;
    let mut t = Vec::new();
    for b in 0..segments {
        t.push([0, idx(1, b + 1), idx(1, b)]);
        t.push([1, idx(rings - 1, b), idx(rings - 1, b + 1)]);
        for a in 1..rings - 1 {
            t.push([idx(a, b), idx(a, b + 1), idx(a + 1, b)]);
            t.push([idx(a + 1, b), idx(a, b + 1), idx(a + 1, b + 1)]);
        }
    }
    let mesh = Mesh::new("drop", p, t);
    let height = |f: f32| 1.0 + (4.0 - 0.5 * f).max(0.0);
    let pos = (0..16)
        .flat_map(|f| {
            let c = Vec3::new(0.5 * f as f32, height(f as f32), 0.0);
            mesh.positions
                .iter()
                .map(move |q| *q + c)
                .collect::<Vec<_>>()
        })
        .collect();
    let anim = MeshAnimation::new(mesh, 24.0, pos).unwrap();
    let pc2 = dir.join("drop.pc2");
    std::fs::write(&pc2, tkio::pc2::write(&anim)).unwrap();
    std::fs::write(dir.join("drop.obj"), tkio::obj::write(&anim.mesh)).unwrap();
    pc2
}

#[test]
fn elongate_subdivides_grounds_and_refuses_point_caches() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_drop(dir.path());
    let out = dir.path().join("drop_smear.glb");
    let v = json(&[
        "smear",
        "elongate",
        s(&input),
        "--beta-max",
        "4",
        "--subdivide",
        "2",
        "--ground",
        "0",
        "--squash",
        "0.3",
        "-o",
        s(&out),
    ]);
    let stretch = v["subdivision_max_stretch"].as_f64().unwrap();
    assert!(stretch <= 2.0, "{v}");
    assert!(v["subdivision_max_triangles"].as_u64().unwrap() > 36, "{v}");
    assert!(v["squashed_frames"].as_u64().unwrap() > 0, "{v}");
    let tkio::Loaded::Scene(scene) = tkio::load(&out, &tkio::LoadOptions::default()).unwrap()
    else {
        panic!("a glb is a scene");
    };
    assert!(scene.meshes.len() > 1, "a flipbook with one mesh per frame");
    keep_for_validation(dir.path(), "smear_subdivide");

    // Point caches hold one vertex count: a one-line refusal, exit code 2.
    let pc2 = dir.path().join("drop_smear.pc2");
    let bad = toonkit(&[
        "smear",
        "elongate",
        s(&input),
        "--subdivide",
        "2",
        "-o",
        s(&pc2),
    ]);
    assert_eq!(bad.status.code(), Some(2));
    let msg = String::from_utf8_lossy(&bad.stderr);
    assert!(msg.contains("--subdivide") && msg.contains(".abc"), "{msg}");
    assert_eq!(msg.trim().lines().count(), 1, "{msg}");
    assert!(!pc2.exists());
    let bad = toonkit(&[
        "smear",
        "elongate",
        s(&input),
        "--subdivide",
        "0.5",
        "-o",
        s(&out),
    ]);
    assert_eq!(bad.status.code(), Some(2));

    // Causal mode and multiples with subdivision and the ground plane.
    let causal = dir.path().join("drop_causal.pc2");
    ok(&["smear", "elongate", s(&input), "--causal", "-o", s(&causal)]);
    let m = dir.path().join("drop_copies.usda");
    ok(&[
        "smear",
        "multiples",
        s(&input),
        "--past",
        "2",
        "--future",
        "1",
        "--subdivide",
        "2",
        "--ground",
        "0",
        "-o",
        s(&m),
    ]);
    // Every copy its own prim with displayOpacity and velocities.
    let text = std::fs::read_to_string(&m).unwrap();
    let prims = usd_meshes(&text);
    let names: Vec<&str> = prims.iter().map(|p| p.0).collect();
    assert_eq!(prims.len(), 4, "the body and 3 copies: {names:?}");
    for (name, p) in &prims[1..] {
        assert!(p.contains("float[] primvars:displayOpacity"), "{name}");
        assert!(p.contains("vector3f[] velocities"), "{name}");
    }
    let bad = toonkit(&[
        "smear",
        "elongate",
        s(&input),
        "--revolve",
        "wheel",
        "-o",
        s(&out),
    ]);
    assert_eq!(bad.status.code(), Some(2));
    let msg = String::from_utf8_lossy(&bad.stderr);
    assert!(msg.contains("wheel") && msg.contains("drop"), "{msg}");
}

/// Lowest y over every frame of a `.pc2` written by toonkit.
fn lowest(path: &Path) -> f32 {
    read_pc2(path)
        .positions()
        .iter()
        .fold(f32::INFINITY, |m, p| m.min(p.y))
}

/// `toonkit smear elongate INPUT --beta-max 4 EXTRA… -o OUT`; returns `out`.
fn elongate_drop(input: &Path, out: &Path, extra: &[&str]) -> PathBuf {
    let mut args = vec!["smear", "elongate", s(input), "--beta-max", "4"];
    args.extend_from_slice(extra);
    args.extend(["-o", s(out)]);
    ok(&args);
    out.to_path_buf()
}

#[test]
fn elongate_stays_out_of_a_collider_file() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_drop(dir.path());
    // A platform under the landing (top y = 0) as an OBJ: 8 corners, 12 outward triangles.
    let (lo, hi) = (Vec3::new(-3.0, -1.0, -2.0), Vec3::new(12.0, 0.0, 2.0));
    let corner = |k: u32| {
        Vec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let faces = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ];
    let tris = faces
        .iter()
        .flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]])
        .collect();
    let platform = Mesh::new("platform", (0..8).map(corner).collect(), tris);
    let obj = dir.path().join("platform.obj");
    std::fs::write(&obj, tkio::obj::write(&platform)).unwrap();

    let run = |name: &str, extra: &[&str]| elongate_drop(&input, &dir.path().join(name), extra);
    let free = run("free.pc2", &[]);
    assert!(lowest(&free) < -1e-2, "nothing crossed: {}", lowest(&free));
    let collided = run("collided.pc2", &["--collider", s(&obj)]);
    let grounded = run("grounded.pc2", &["--ground", "0"]);
    assert!(lowest(&collided) >= 0.0, "{}", lowest(&collided));
    let (a, b) = (read_pc2(&collided), read_pc2(&grounded));
    let worst = a
        .positions()
        .iter()
        .zip(b.positions())
        .fold(0.0f32, |m, (p, q)| m.max(p.distance(*q)));
    assert!(
        worst < 1e-3,
        "the platform's top acts as the ground: {worst}"
    );

    // A missing collider file is one line naming it, exit code 2.
    let missing = dir.path().join("nope.obj");
    let bad = toonkit(&[
        "smear",
        "elongate",
        s(&input),
        "--collider",
        s(&missing),
        "-o",
        s(&dir.path().join("x.pc2")),
    ]);
    assert_eq!(bad.status.code(), Some(2));
    let msg = String::from_utf8_lossy(&bad.stderr);
    assert!(
        msg.contains("nope.obj") && msg.trim().lines().count() == 1,
        "{msg}"
    );
    // An unknown collider object names the input's objects.
    let bad = toonkit(&[
        "smear",
        "elongate",
        s(&input),
        "--collider-object",
        "Ramp",
        "-o",
        s(&dir.path().join("x.pc2")),
    ]);
    assert_eq!(bad.status.code(), Some(2));
    let msg = String::from_utf8_lossy(&bad.stderr);
    assert!(msg.contains("'Ramp'") && msg.contains("drop"), "{msg}");
}

/// Vertex count of every mesh of a `.glb`, in file order (a flipbook: one per frame).
fn glb_mesh_vertices(path: &Path) -> Vec<usize> {
    let v = json(&["info", s(path)]);
    v["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["vertices"].as_u64().unwrap() as usize)
        .collect()
}

/// The `v` lines of every file of an OBJ sequence.
fn obj_vertices(files: &serde_json::Value) -> Vec<usize> {
    let files = files.as_array().unwrap();
    files
        .iter()
        .map(|f| {
            let text = std::fs::read_to_string(f.as_str().unwrap()).unwrap();
            text.lines().filter(|l| l.starts_with("v ")).count()
        })
        .collect()
}

#[test]
fn subdivided_smear_and_converted_flipbook_as_obj_sequences_keep_each_frames_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_drop(dir.path());
    let args = |out: &Path| {
        let args = [
            "smear",
            "elongate",
            s(&input),
            "--beta-max",
            "4",
            "--subdivide",
            "2",
        ];
        let mut v: Vec<String> = args.iter().map(|a| a.to_string()).collect();
        v.extend(["-o".into(), s(out).to_string()]);
        v
    };
    let glb = dir.path().join("drop_smear.glb");
    let a = args(&glb);
    json(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let per_frame = glb_mesh_vertices(&glb);
    assert_eq!(per_frame.len(), 16, "one mesh per frame");
    assert!(
        per_frame.iter().any(|&n| n != per_frame[0]),
        "the subdivision changes the mesh from frame to frame: {per_frame:?}"
    );

    // The smear itself as an OBJ sequence: file f holds frame f's own mesh.
    let obj = dir.path().join("seq").join("drop.obj");
    std::fs::create_dir_all(obj.parent().unwrap()).unwrap();
    let mut a = args(&obj);
    a.extend(["--layout".into(), "sequence".into()]);
    let v = json(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(obj_vertices(&v["files"]), per_frame, "{v}");
    assert!(v["files"][0].as_str().unwrap().ends_with("drop_0001.obj"));
    let v0 = v["subdivision_max_vertices"].as_u64().unwrap() as usize;
    assert_eq!(v0, *per_frame.iter().max().unwrap());

    // Without --layout sequence an .obj cannot hold 16 frames: a one-line refusal.
    let bad = toonkit(
        &a[..a.len() - 2]
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
    );
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--layout sequence"));

    // The flipbook converted: each file the frame's visible mesh only (the hidden frames'
    // nodes, scaled to zero, are left out).
    let conv = dir.path().join("conv").join("flip.obj");
    std::fs::create_dir_all(conv.parent().unwrap()).unwrap();
    let v = json(&["convert", s(&glb), s(&conv), "--layout", "sequence"]);
    assert_eq!(obj_vertices(&v["outputs"]), per_frame, "{v}");

    // Multiples and motion lines as OBJ sequences: each file one `o` object per part shown.
    let lines = dir.path().join("lines").join("drop.obj");
    std::fs::create_dir_all(lines.parent().unwrap()).unwrap();
    let v = json(&[
        "smear",
        "lines",
        s(&input),
        "--count",
        "20",
        "--length-max",
        "3",
        "--layout",
        "sequence",
        "-o",
        s(&lines),
    ]);
    let drawn = v["lines_per_frame"].as_array().unwrap();
    let files = v["files"].as_array().unwrap();
    assert_eq!(files.len(), 16);
    for (f, (file, n)) in files.iter().zip(drawn).enumerate() {
        let text = std::fs::read_to_string(file.as_str().unwrap()).unwrap();
        let objects = text.lines().filter(|l| l.starts_with("o ")).count();
        let with_lines = n.as_u64().unwrap() > 0;
        assert_eq!(objects, 1 + with_lines as usize, "frame {f}");
        assert_eq!(text.contains("o motion_lines"), with_lines, "frame {f}");
        // Reads back as one valid mesh (face indices of the second object run on).
        tkio::obj::read(text.as_bytes()).unwrap();
    }
    let copies = dir.path().join("copies").join("drop.obj");
    std::fs::create_dir_all(copies.parent().unwrap()).unwrap();
    let v = json(&[
        "smear",
        "multiples",
        s(&input),
        "--past",
        "2",
        "--future",
        "0",
        "--layout",
        "sequence",
        "-o",
        s(&copies),
    ]);
    assert_eq!(v["files"].as_array().unwrap().len(), 16, "{v}");
}

/// The `def Mesh` prims of a `.usda` layer: name and text (up to the next prim).
fn usd_meshes(text: &str) -> Vec<(&str, &str)> {
    text.split("def Mesh \"")
        .skip(1)
        .map(|p| (p.split('"').next().unwrap(), p))
        .collect()
}

#[test]
fn subdivided_smear_usd_velocities_agree_with_the_point_cache() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_drop(dir.path());
    let run = |name: &str, extra: &[&str]| {
        std::fs::read_to_string(elongate_drop(&input, &dir.path().join(name), extra)).unwrap()
    };
    let plain = run("plain.usda", &[]);
    let sub = run("subdivided.usda", &["--subdivide", "2"]);
    let (plain_p, plain_v) = (
        samples(&plain, "point3f[] points"),
        samples(&plain, "vector3f[] velocities"),
    );
    let (sub_p, sub_v) = (
        samples(&sub, "point3f[] points"),
        samples(&sub, "vector3f[] velocities"),
    );
    assert_eq!((sub_p.len(), sub_v.len()), (16, 16));
    let mut grew = false;
    for f in 0..16 {
        let (pp, pv) = (vec3s(plain_p[f]), vec3s(plain_v[f]));
        let (sp, sv) = (vec3s(sub_p[f]), vec3s(sub_v[f]));
        let n = pp.len();
        assert_eq!(sv.len(), sp.len(), "frame {f}: one velocity per point");
        grew |= sp.len() > n;
        for (k, v) in sv.iter().enumerate() {
            let v = Vec3::from_array(*v);
            if k < n {
                // The input's vertices come first, where the point cache has them, moving
                // as the point cache says.
                assert!(Vec3::from_array(sp[k]).distance(Vec3::from_array(pp[k])) < 1e-4);
                let want = Vec3::from_array(pv[k]);
                assert!(
                    v.distance(want) <= 1e-4 * (1.0 + want.length()),
                    "frame {f} vertex {k}: {v} vs the point cache's {want}"
                );
            } else {
                // New vertices move along their own trajectory on the in-betweens (checked
                // against their positions in the smear crate's subdivision tests): defined.
                assert!(v.is_finite(), "frame {f} vertex {k}: {v}");
            }
        }
    }
    assert!(grew, "nothing was subdivided");

    keep_for_validation(dir.path(), "usd_subdivided");
}
