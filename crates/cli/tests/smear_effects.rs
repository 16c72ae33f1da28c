//! `toonkit smear elongate | multiples | lines` end to end on a generated ball and on
//! RobotExpressive.

mod common;

use std::path::{Path, PathBuf};

use anim::glam::Vec3;
use anim::{Aabb, Mesh, MeshAnimation};
use common::*;

/// A UV sphere of radius 1.
fn sphere() -> Mesh {
    let (rings, segments) = (12usize, 24usize);
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
    Mesh::new("ball", p, t)
}

/// Writes `dir/<name>.pc2` + `dir/<name>.obj`: a ball moving by `center(f)`.
fn write_ball(dir: &Path, name: &str, frames: usize, center: impl Fn(f32) -> Vec3) -> PathBuf {
    let mesh = sphere();
    let pos = (0..frames)
        .flat_map(|f| {
            let c = center(f as f32);
            mesh.positions
                .iter()
                .map(move |p| *p + c)
                .collect::<Vec<_>>()
        })
        .collect();
    let anim = MeshAnimation::new(mesh, 24.0, pos).unwrap();
    let pc2 = dir.join(format!("{name}.pc2"));
    std::fs::write(&pc2, tkio::pc2::write(&anim)).unwrap();
    std::fs::write(
        dir.join(format!("{name}.obj")),
        tkio::obj::write(&anim.mesh),
    )
    .unwrap();
    pc2
}

/// A ball bouncing along +X: 0.4 per frame forward, |sin| hops of height 3.
fn bouncing(f: f32) -> Vec3 {
    Vec3::new(
        0.4 * f,
        3.0 * (f * std::f32::consts::PI / 10.0).sin().abs(),
        0.0,
    )
}

#[test]
fn fig9_elongate_ball_covers_neighbour_frames() {
    // Section 5.2 / Fig. 9b: S_E(δ; 1) stretches the ball over the previous and next frames.
    let dir = tempfile::tempdir().unwrap();
    let input = write_ball(dir.path(), "slide", 12, |f| Vec3::X * 0.6 * f);
    let out = dir.path().join("slide_smear.pc2");
    let v = json(&[
        "smear",
        "elongate",
        s(&input),
        "-o",
        s(&out),
        "--beta-max",
        "1",
    ]);
    assert_eq!(
        (v["frames"].as_u64(), v["vertices"].as_u64()),
        (Some(12), Some(266))
    );
    assert!(v["seconds"]["effect"].as_f64().unwrap() >= 0.0);
    let smeared = read_pc2(&out);
    let original = read_pc2(&input);
    let bb = Aabb::from_points(smeared.frame(5));
    let cover = Aabb::from_points(original.frame(4)).union(Aabb::from_points(original.frame(6)));
    assert!((bb.min.x - cover.min.x).abs() < 1e-3, "{bb:?} vs {cover:?}");
    assert!((bb.max.x - cover.max.x).abs() < 1e-3, "{bb:?} vs {cover:?}");
    assert!((v["max_displacement"].as_f64().unwrap() - 0.6).abs() < 1e-3);
    // On twos: drawings held, β doubled → frame 4 covers frames 2..6.
    let twos = dir.path().join("slide_twos.pc2");
    ok(&[
        "smear",
        "elongate",
        s(&input),
        "-o",
        s(&twos),
        "--step",
        "2",
    ]);
    let t = read_pc2(&twos);
    assert_eq!(t.frame(4), t.frame(5));
    let bb = Aabb::from_points(t.frame(4));
    assert!(
        (bb.max.x - bb.min.x - (2.0 + 4.0 * 0.6)).abs() < 1e-3,
        "{bb:?}"
    );
}

#[test]
fn elongate_bouncing_ball_writes_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_ball(dir.path(), "bounce", 20, bouncing);
    let glb = dir.path().join("bounce_smear.glb");
    let morph = dir.path().join("bounce_morph.glb");
    let mdd = dir.path().join("bounce_smear.mdd");
    let obj = dir.path().join("seq/bounce_0001.obj");
    std::fs::create_dir_all(obj.parent().unwrap()).unwrap();
    ok(&[
        "smear",
        "elongate",
        s(&input),
        "-o",
        s(&glb),
        "--beta-max",
        "1.5",
    ]);
    ok(&[
        "smear",
        "elongate",
        s(&input),
        "-o",
        s(&morph),
        "--layout",
        "morph",
    ]);
    ok(&[
        "smear",
        "elongate",
        s(&input),
        "-o",
        s(&mdd),
        "--preset",
        "speed",
    ]);
    ok(&[
        "smear",
        "elongate",
        s(&input),
        "-o",
        s(&obj),
        "--layout",
        "sequence",
    ]);
    let scene = tkio::gltf::read(&glb).unwrap();
    assert_eq!(scene.meshes.len(), 20, "one mesh per frame");
    assert_eq!(
        tkio::gltf::read(&morph).unwrap().meshes[0]
            .morph_targets
            .len(),
        20
    );
    assert!(mdd.exists() && mdd.with_extension("obj").exists());
    assert_eq!(
        std::fs::read_dir(obj.parent().unwrap()).unwrap().count(),
        20
    );
    // A user expression equal to the linear preset gives the same bytes.
    let expr = dir.path().join("bounce_expr.glb");
    ok(&[
        "smear",
        "elongate",
        s(&input),
        "-o",
        s(&expr),
        "--beta-max",
        "1.5",
        "--expr",
        "beta_max * delta",
    ]);
    assert_eq!(std::fs::read(&glb).unwrap(), std::fs::read(&expr).unwrap());
    keep_for_validation(dir.path(), "smear_elongate");
}

#[test]
fn elongate_robot_speed_preset_scales_with_beta_max() {
    let dir = tempfile::tempdir().unwrap();
    let robot = data("characters/RobotExpressive.glb");
    let run = |beta: &str, name: &str| {
        let out = dir.path().join(name);
        json(&[
            "smear",
            "elongate",
            s(&robot),
            "-o",
            s(&out),
            "--clip",
            "Punch",
            "--fps",
            "12",
            "--preset",
            "speed",
            "--beta-max",
            beta,
            "--smooth",
            "1",
        ])
    };
    let one = run("1", "robot_punch_1.glb");
    let two = run("2", "robot_punch_2.glb");
    assert_eq!(one["vertices"].as_u64(), Some(7214));
    let (m1, m2) = (
        one["mean_displacement"].as_f64().unwrap(),
        two["mean_displacement"].as_f64().unwrap(),
    );
    assert!(m1 > 0.0 && m2 > 1.5 * m1, "mean displacement {m1} → {m2}");
    keep_for_validation(dir.path(), "smear_elongate_robot");
}

#[test]
fn fig10_multiples_bouncing_ball_overlap_gives_unit_spacing() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_ball(dir.path(), "bounce", 16, bouncing);
    let glb = dir.path().join("bounce_multiples.glb");
    let v = json(&[
        "smear",
        "multiples",
        s(&input),
        "-o",
        s(&glb),
        "--past",
        "1",
        "--future",
        "1",
        "--overlap",
        "2",
    ]);
    assert_eq!(v["spacing"].as_f64(), Some(1.0));
    let copies = v["copies"].as_array().unwrap();
    assert_eq!(copies.len(), 2);
    for c in copies {
        // SMEAR Eq. 12: each copy shows only the side facing its direction in time (about half).
        let f = c["visible_fraction"].as_f64().unwrap();
        assert!(f > 0.3 && f < 0.55, "copy {}: visible fraction {f}", c["m"]);
    }
    let scene = tkio::gltf::read(&glb).unwrap();
    assert_eq!(scene.meshes.len(), 3 * 16, "original + 2 copies per frame");
    let translucent = scene
        .meshes
        .iter()
        .filter(|m| {
            m.mesh
                .colors
                .as_ref()
                .is_some_and(|c| c.iter().any(|x| x[3] < 1.0))
        })
        .count();
    assert_eq!(translucent, 2 * 16);
    keep_for_validation(dir.path(), "smear_multiples");
}

#[test]
fn fig1_multiples_robot_overlap_one_gives_third_frame_spacing() {
    let dir = tempfile::tempdir().unwrap();
    let robot = data("characters/RobotExpressive.glb");
    let glb = dir.path().join("robot_multiples.glb");
    let v = json(&[
        "smear",
        "multiples",
        s(&robot),
        "-o",
        s(&glb),
        "--clip",
        "Jump",
        "--fps",
        "12",
        "--past",
        "2",
        "--future",
        "1",
        "--overlap",
        "1",
        "--m-max",
        "1",
    ]);
    assert!((v["spacing"].as_f64().unwrap() - 1.0 / 3.0).abs() < 1e-6);
    let ms: Vec<i64> = v["copies"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["m"].as_i64().unwrap())
        .collect();
    assert_eq!(ms, [-2, -1, 1]);
    assert!(glb.exists());
    keep_for_validation(dir.path(), "smear_multiples_robot");
}

#[test]
fn fig3e_lines_bouncing_ball_trail_and_fade() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_ball(dir.path(), "bounce", 20, bouncing);
    let glb = dir.path().join("bounce_lines.glb");
    let args = |out: &Path, seed: &str| {
        json(&[
            "smear",
            "lines",
            s(&input),
            "-o",
            s(out),
            "--count",
            "40",
            "--length-max",
            "3",
            "--seed",
            seed,
            "--past-only",
            "--opacity-expr",
            "1 - t",
        ])
    };
    let v = args(&glb, "11");
    assert_eq!(v["seeds"].as_u64(), Some(40));
    let per_frame: Vec<u64> = v["lines_per_frame"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap())
        .collect();
    assert_eq!(per_frame.len(), 20);
    // Nothing lies before the first frame (β clamps), so frame 0 has no past line; later,
    // about half the seeds trail (δ < 0).
    assert_eq!(per_frame[0], 0);
    assert!(
        per_frame[1..].iter().all(|&n| (8..=32).contains(&n)),
        "{per_frame:?}"
    );
    // Deterministic: same seed, same bytes; another seed, other lines.
    let again = dir.path().join("again.glb");
    args(&again, "11");
    assert_eq!(std::fs::read(&glb).unwrap(), std::fs::read(&again).unwrap());
    std::fs::remove_file(&again).unwrap();
    let scene = tkio::gltf::read(&glb).unwrap();
    let lines = scene
        .nodes
        .iter()
        .find(|n| n.name == "motion_lines")
        .expect("lines root");
    assert_eq!(lines.children.len(), 20);
    // The frame's mesh, on the frame node or (quantized output) on its dequantizing child.
    let frame = &scene.nodes[lines.children[10]];
    let mesh = frame
        .mesh
        .or_else(|| frame.children.iter().find_map(|&c| scene.nodes[c].mesh))
        .expect("frame 10 has a line mesh");
    let line_mesh = &scene.meshes[mesh].mesh;
    let alpha: Vec<f32> = line_mesh
        .colors
        .as_ref()
        .unwrap()
        .iter()
        .map(|c| c[3])
        .collect();
    assert!(alpha.iter().any(|a| *a > 0.99) && alpha.iter().any(|a| *a < 0.01));
    keep_for_validation(dir.path(), "smear_lines");
}

#[test]
fn lines_robot_with_speed_threshold() {
    let dir = tempfile::tempdir().unwrap();
    let robot = data("characters/RobotExpressive.glb");
    let glb = dir.path().join("robot_lines.glb");
    let run = |min_speed: &str| {
        json(&[
            "smear",
            "lines",
            s(&robot),
            "-o",
            s(&glb),
            "--clip",
            "Punch",
            "--fps",
            "12",
            "--count",
            "80",
            "--length-max",
            "4",
            "--min-speed",
            min_speed,
        ])
    };
    let total = |v: &serde_json::Value| -> u64 {
        v["lines_per_frame"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_u64().unwrap())
            .sum()
    };
    let slow = run("0.05");
    let all = run("0");
    assert!(total(&all) > 0);
    assert!(
        total(&slow) < total(&all),
        "{} vs {}",
        total(&slow),
        total(&all)
    );
    keep_for_validation(dir.path(), "smear_lines_robot");
}

#[test]
fn smear_effects_reject_bad_options() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_ball(dir.path(), "bounce", 6, bouncing);
    let out = dir.path().join("x.glb");
    assert_bad_input(
        &[
            "smear",
            "multiples",
            s(&input),
            "-o",
            s(&out),
            "--overlap",
            "3",
        ],
        "N∩",
    );
    assert_bad_input(
        &[
            "smear",
            "lines",
            s(&input),
            "-o",
            s(&dir.path().join("x.pc2")),
        ],
        ".glb",
    );
    assert_bad_input(
        &[
            "smear",
            "elongate",
            s(&input),
            "-o",
            s(&out),
            "--expr",
            "delta * nope",
        ],
        "nope",
    );
    assert_bad_input(
        &["smear", "elongate", s(&input), "-o", s(&out), "--step", "0"],
        "--step",
    );
    assert!(!out.exists());
}
