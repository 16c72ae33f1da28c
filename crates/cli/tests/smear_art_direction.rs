//! Art direction of the smear effects from the CLI (paper Section 5): painted weights from a
//! weight group or a vertex attribute (Fig. 15b), keyframed effect options (Section 5.1),
//! style files using both.

mod common;

use std::path::Path;

use anim::{sample, MeshAnimation, SampleOptions};
use common::*;

/// Per vertex, the largest distance between two caches over all frames.
fn displacement(a: &MeshAnimation, b: &MeshAnimation) -> Vec<f32> {
    assert_eq!(
        (a.frame_count(), a.vertex_count()),
        (b.frame_count(), b.vertex_count())
    );
    let n = a.vertex_count();
    let mut d = vec![0.0f32; n];
    for (k, (p, q)) in a.positions().iter().zip(b.positions()).enumerate() {
        d[k % n] = d[k % n].max(p.distance(*q));
    }
    d
}

/// The clip `clip` of `path`, sampled as the CLI does by default.
fn sampled(path: &Path, clip: &str) -> anim::SampledScene {
    let scene = tkio::gltf::read(path).unwrap();
    let c = scene.clips.iter().position(|c| c.name == clip).unwrap();
    sample(
        &scene,
        &SampleOptions {
            clip: Some(c),
            ..SampleOptions::default()
        },
    )
    .unwrap()
}

/// Runs `smear elongate` on the Punch clip with β_max = `beta` and `extra` options; returns
/// the elongated cache and the JSON report.
fn elongate_punch(
    input: &Path,
    out: &Path,
    beta: &str,
    extra: &[&str],
) -> (MeshAnimation, serde_json::Value) {
    let mut args = vec![
        "smear",
        "elongate",
        s(input),
        "-o",
        s(out),
        "--clip",
        "Punch",
        "--beta-max",
        beta,
    ];
    args.extend_from_slice(extra);
    let v = json(&args);
    (read_pc2(out), v)
}

/// Elongates `input` without and with the painted-weight options `weighting` and checks
/// Fig. 15b: vertices of weight 0 stay, vertices of weight 1 smear as without weights.
/// Returns (unweighted, fully weighted, smeared) vertex counts.
fn check_weighted_elongation(
    input: &Path,
    dir: &Path,
    weighting: &[&str],
    w: &[f32],
) -> (usize, usize, usize) {
    let (still, _) = elongate_punch(input, &dir.join("still.pc2"), "0", &[]);
    let (full, _) = elongate_punch(input, &dir.join("full.pc2"), "2", &[]);
    let (part, v) = elongate_punch(input, &dir.join("part.pc2"), "2", weighting);
    assert_eq!(v["weighted"], true);
    assert_eq!(w.len(), still.vertex_count());
    let (d_full, d_part) = (displacement(&full, &still), displacement(&part, &still));
    let (mut outside, mut inside, mut moved) = (0usize, 0usize, 0usize);
    for ((&w, &df), &dp) in w.iter().zip(&d_full).zip(&d_part) {
        if w == 0.0 {
            outside += 1;
            assert!(dp < 1e-5, "unweighted vertex moved by {dp}");
        } else if w == 1.0 {
            inside += 1;
            assert!((dp - df).abs() < 1e-4, "fully weighted: {dp} vs {df}");
            moved += usize::from(dp > 1e-3);
        }
    }
    (outside, inside, moved)
}

#[test]
fn fig15b_weight_group_smears_only_the_punching_arm() {
    let dir = tempfile::tempdir().unwrap();
    let robot = data("characters/RobotExpressive.glb");
    let scene = sampled(&robot, "Punch");
    let names = vec!["ShoulderR".to_string()];
    let w: Vec<f32> = (0..scene.objects.len())
        .flat_map(|i| smear::group_weights(&scene, i, &names, true).unwrap())
        .collect();
    let (outside, inside, moved) =
        check_weighted_elongation(&robot, dir.path(), &["--weight-group", "ShoulderR"], &w);
    assert!(
        outside > inside && inside > 100,
        "{outside} out, {inside} in"
    );
    assert!(
        moved > inside / 2,
        "{moved} of {inside} arm vertices smeared"
    );
    // Unknown joints are one-line errors naming the joints.
    assert_bad_input(
        &[
            "smear",
            "elongate",
            s(&robot),
            "-o",
            s(&dir.path().join("x.pc2")),
            "--weight-group",
            "Tail",
        ],
        "ShoulderR",
    );
    assert_bad_input(
        &[
            "smear",
            "lines",
            s(&robot),
            "-o",
            s(&dir.path().join("x.glb")),
            "--weight-attribute",
            "_SMEAR_WEIGHT",
        ],
        "_SMEAR_WEIGHT",
    );
}

#[test]
fn fig15b_weight_group_limits_lines_and_multiples() {
    let dir = tempfile::tempdir().unwrap();
    let robot = data("characters/RobotExpressive.glb");
    let lines = |group: Option<&str>| {
        let out = dir.path().join("lines.glb");
        let mut args = vec![
            "smear",
            "lines",
            s(&robot),
            "-o",
            s(&out),
            "--clip",
            "Punch",
            "--count",
            "200",
            "--length-max",
            "4",
        ];
        if let Some(g) = group {
            args.extend(["--weight-group", g]);
        }
        let v = json(&args);
        v["lines_per_frame"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_u64().unwrap())
            .sum::<u64>()
    };
    let (all, arm) = (lines(None), lines(Some("ShoulderR")));
    assert!(arm > 0 && arm * 3 < all, "arm {arm} vs all {all}");
    let out = dir.path().join("multiples.glb");
    let visible = |group: Option<&str>| {
        let mut args = vec![
            "smear",
            "multiples",
            s(&robot),
            "-o",
            s(&out),
            "--clip",
            "Punch",
        ];
        if let Some(g) = group {
            args.extend(["--weight-group", g]);
        }
        let v = json(&args);
        v["copies"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["visible_fraction"].as_f64().unwrap())
            .sum::<f64>()
    };
    let (all, arm) = (visible(None), visible(Some("ShoulderR")));
    assert!(arm > 0.0 && arm * 3.0 < all, "arm {arm} vs all {all}");
    keep_for_validation(dir.path(), "smear_weight_group");
}

#[test]
fn keyframed_effect_options_from_the_command_line() {
    // Section 5.1: every numeric parameter may be keyframed, e.g. β_max ramping up, lines
    // appearing, copies spreading.
    let dir = tempfile::tempdir().unwrap();
    let robot = data("characters/RobotExpressive.glb");
    let still = dir.path().join("still.pc2");
    let ramp = dir.path().join("ramp.pc2");
    let base = ["--clip", "Punch"];
    let run = |out: &Path, beta: &str| {
        let mut a = vec![
            "smear",
            "elongate",
            s(&robot),
            "-o",
            s(out),
            "--beta-max",
            beta,
        ];
        a.extend(base);
        ok(&a);
        read_pc2(out)
    };
    let (still, ramp) = (run(&still, "0"), run(&ramp, "0:0,10:2,20:2"));
    let frame_move = |f: usize| {
        still
            .frame(f)
            .iter()
            .zip(ramp.frame(f))
            .map(|(a, b)| a.distance(*b))
            .fold(0.0f32, f32::max)
    };
    assert!(frame_move(0) < 1e-6, "β_max(0) = 0 moves nothing");
    assert!(frame_move(12) > 0.01, "β_max(12) = 2 smears");
    let glb = dir.path().join("lines.glb");
    let mut a = vec![
        "smear",
        "lines",
        s(&robot),
        "-o",
        s(&glb),
        "--count",
        "0:0,20:120",
        "--length-max",
        "3",
    ];
    a.extend(base);
    let v = json(&a);
    assert_eq!(v["seeds"], 120);
    let per: Vec<u64> = v["lines_per_frame"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap())
        .collect();
    assert_eq!(per[0], 0);
    assert!(per[5] <= 30 && per[20] > per[5], "{per:?}");
    let multiples = |options: &[&str]| {
        let mut a = vec![
            "smear",
            "multiples",
            s(&robot),
            "-o",
            s(&glb),
            "--clip",
            "Punch",
        ];
        a.extend_from_slice(options);
        json(&a)
    };
    let v = multiples(&["--spacing", "0:0.25,20:1"]);
    assert_eq!(
        (v["spacing"].as_f64(), v["spacing_keyframed"].as_bool()),
        (Some(0.25), Some(true))
    );
    // Past copies fading in: m_p keyed 0 → 2 over the first 10 frames; copy −2 shows on
    // fewer frames than copy −1.
    let v = multiples(&["--past", "0:0,10:2", "--future", "0", "--overlap", "1"]);
    let copies = v["copies"].as_array().unwrap();
    let seen = |k: usize| copies[k]["visible_fraction"].as_f64().unwrap();
    assert_eq!(copies.len(), 2);
    assert!(seen(0) > 0.0 && seen(0) < seen(1), "{copies:?}");
    assert_bad_input(
        &["smear", "lines", s(&robot), "-o", s(&glb), "--color", "1,0"],
        "R,G,B",
    );
    assert_bad_input(
        &[
            "smear",
            "lines",
            s(&robot),
            "-o",
            s(&glb),
            "--gap",
            "0:1,x:2",
        ],
        "FRAME:VALUE",
    );
    assert_bad_input(
        &["smear", "lines", s(&robot), "-o", s(&glb), "--count=-4"],
        "--count",
    );
    keep_for_validation(dir.path(), "smear_keyframes");
}

#[test]
fn style_file_with_weight_group_and_keyframed_lines() {
    let dir = tempfile::tempdir().unwrap();
    let robot = data("characters/RobotExpressive.glb");
    let style = dir.path().join("arm.toml");
    std::fs::write(
        &style,
        r#"
weights = { group = ["ShoulderR"] }
[elongate]
function = { stages = [{ op = "weight" }, { op = "scale", by = [[0, 0], [10, 3]] }] }
[lines]
count = [[0, 0], [10, 60]]
length = { expr = "3 * weight * delta" }
"#,
    )
    .unwrap();
    let out = dir.path().join("arm.glb");
    let v = json(&[
        "smear",
        s(&robot),
        "--style",
        s(&style),
        "-o",
        s(&out),
        "--clip",
        "Punch",
    ]);
    let objects = v["objects"].as_array().unwrap();
    let per_frame = |o: &serde_json::Value| -> Vec<u64> {
        o["lines_per_frame"]
            .as_array()
            .map(|a| a.iter().map(|x| x.as_u64().unwrap()).collect())
            .unwrap_or_default()
    };
    let total: Vec<u64> = (0..v["frames"].as_u64().unwrap() as usize)
        .map(|f| {
            objects
                .iter()
                .map(|o| per_frame(o).get(f).copied().unwrap_or(0))
                .sum()
        })
        .collect();
    assert_eq!(total[0], 0, "count keyed to 0 at frame 0");
    assert!(total.iter().any(|&n| n > 0), "{total:?}");
    // Objects the arm does not drive draw no line and do not stretch.
    let unweighted: Vec<&serde_json::Value> = objects
        .iter()
        .filter(|o| per_frame(o).iter().all(|&n| n == 0))
        .collect();
    assert!(!unweighted.is_empty());
    assert!(objects
        .iter()
        .any(|o| o["elongation_max"].as_f64().unwrap() < 1e-6));
    assert!(objects
        .iter()
        .any(|o| o["elongation_max"].as_f64().unwrap() > 0.01));
    keep_for_validation(dir.path(), "smear_style_weights");
}

/// A unit cube sliding +1 per frame along X, watched by camera `cam` sliding `cam_speed` per
/// frame beside it, as a `.glb`.
fn write_tracked_cube(path: &Path, frames: usize, cam_speed: f32) {
    use anim::glam::Vec3;
    use anim::{
        Channel, Clip, Interpolation, Mesh, Node, Projection, Property, Scene, SceneCamera,
        SceneMesh,
    };
    let p: Vec<Vec3> = (0..8)
        .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32))
        .collect();
    let t = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    let times: Vec<f32> = (0..frames).map(|f| f as f32 / 24.0).collect();
    let slide = |node: usize, speed: f32, z: f32| Channel {
        node,
        property: Property::Translation,
        interpolation: Interpolation::Linear,
        times: times.clone(),
        values: (0..frames)
            .flat_map(|f| [speed * f as f32, 0.0, z])
            .collect(),
    };
    let scene = Scene {
        nodes: vec![
            Node {
                name: "cube".into(),
                mesh: Some(0),
                ..Default::default()
            },
            Node {
                name: "cam".into(),
                camera: Some(0),
                ..Default::default()
            },
        ],
        meshes: vec![SceneMesh {
            mesh: Mesh::new("cube", p, t),
            ..Default::default()
        }],
        cameras: vec![SceneCamera {
            name: "cam".into(),
            projection: Projection::Perspective {
                yfov: 0.8,
                aspect: None,
                znear: 0.1,
                zfar: None,
            },
        }],
        clips: vec![Clip {
            name: "slide".into(),
            channels: vec![slide(0, 1.0, 0.0), slide(1, cam_speed, 10.0)],
        }],
        ..Default::default()
    };
    std::fs::write(path, tkio::gltf::write_glb(&scene).unwrap()).unwrap();
}

#[test]
fn camera_relative_speed_drives_speed_presets() {
    // With --camera the offsets *and* the speed the stylization reads are camera-relative: a
    // camera following at half speed halves the speed-weighted smear (Fig. 11c preset).
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("tracked.glb");
    write_tracked_cube(&input, 12, 0.5);
    let out = dir.path().join("out.pc2");
    let run = |extra: &[&str]| {
        let mut a = vec![
            "smear",
            "elongate",
            s(&input),
            "-o",
            s(&out),
            "--preset",
            "speed",
            "--beta-max",
            "2",
            // The paper's per-frame scene units: the expected β below is in them.
            "--speed-units",
            "scene",
        ];
        a.extend_from_slice(extra);
        json(&a)
    };
    let world = run(&[]);
    let seen = run(&["--camera", "cam"]);
    assert_eq!(seen["camera_speed"], true);
    let (w, c) = (
        world["max_displacement"].as_f64().unwrap(),
        seen["max_displacement"].as_f64().unwrap(),
    );
    assert!(
        (w - 2.0).abs() < 0.05,
        "world: β = 2·1·δ frames = 2 units, got {w}"
    );
    assert!(
        (c - 1.0).abs() < 0.05,
        "camera: β = 2·0.5·δ = 1 unit, got {c}"
    );
    // A speed threshold between the two speeds keeps the lines in world space only.
    let glb = dir.path().join("lines.glb");
    let lines = |extra: &[&str]| {
        let mut a = vec![
            "smear",
            "lines",
            s(&input),
            "-o",
            s(&glb),
            "--min-speed",
            "0.75",
            "--speed-units",
            "scene",
            "--count",
            "50",
        ];
        a.extend_from_slice(extra);
        json(&a)["lines_per_frame"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_u64().unwrap())
            .sum::<u64>()
    };
    assert!(lines(&[]) > 0);
    assert_eq!(lines(&["--camera", "cam"]), 0);
    assert_bad_input(
        &[
            "smear",
            "elongate",
            s(&input),
            "-o",
            s(&out),
            "--camera",
            "nope",
        ],
        "cam",
    );
}

#[test]
fn fig15b_painted_vertex_attribute_weights() {
    // Weights painted in the animation package and exported as a glTF `_SMEAR_WEIGHT`
    // attribute: here 1 on the front half of every mesh (bind-space z > 0), 0 elsewhere.
    let dir = tempfile::tempdir().unwrap();
    let mut scene = tkio::gltf::read(&data("characters/RobotExpressive.glb")).unwrap();
    for m in &mut scene.meshes {
        let w = m
            .mesh
            .positions
            .iter()
            .map(|p| f32::from(p.z > 0.0))
            .collect();
        m.mesh.attributes.insert("_SMEAR_WEIGHT".into(), w);
    }
    let painted = dir.path().join("painted.glb");
    std::fs::write(&painted, tkio::gltf::write_glb(&scene).unwrap()).unwrap();
    let back = sampled(&painted, "Punch");
    let w: Vec<f32> = back
        .objects
        .iter()
        .flat_map(|o| smear::attribute_weights(&o.animation.mesh, "_SMEAR_WEIGHT").unwrap())
        .collect();
    let (outside, inside, moved) = check_weighted_elongation(
        &painted,
        dir.path(),
        &["--weight-attribute", "_SMEAR_WEIGHT"],
        &w,
    );
    assert!(outside > 100 && inside > 100, "{outside} out, {inside} in");
    assert!(moved > 10, "{moved} painted vertices smeared");
    keep_for_validation(dir.path(), "smear_painted_attribute");
}
