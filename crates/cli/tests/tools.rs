//! The tools end to end from the CLI on real files.

mod common;

use common::*;

#[test]
fn smear_offsets_npy_matches_merged_vertex_order() {
    let dir = tempfile::tempdir().unwrap();
    let npy = dir.path().join("cesium.npy");
    let rest = dir.path().join("rest.obj");
    let cesium = data("characters/CesiumMan.glb");
    ok(&[
        "smear",
        "offsets",
        cesium.to_str().unwrap(),
        "-o",
        npy.to_str().unwrap(),
    ]);
    ok(&[
        "convert",
        cesium.to_str().unwrap(),
        rest.to_str().unwrap(),
        "--frame",
        "0",
    ]);
    let (shape, values) = tkio::npy::read_f32(&std::fs::read(&npy).unwrap()).unwrap();
    let mesh = tkio::obj::read(&std::fs::read(&rest).unwrap()).unwrap();
    assert_eq!(shape, vec![48, mesh.vertex_count()]);
    assert!(values.iter().all(|v| v.is_finite() && v.abs() <= 1.5));
    // A walking man has leading and trailing sides.
    let (lo, hi) = values
        .iter()
        .fold((0f32, 0f32), |(a, b), &v| (a.min(v), b.max(v)));
    assert!(lo < -0.9 && hi > 0.9, "range {lo}..{hi}");
}

#[test]
fn smear_offsets_glb_is_coloured_flipbook() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("robot_offsets.glb");
    let robot = data("characters/RobotExpressive.glb");
    let v = json(&[
        "smear",
        "offsets",
        robot.to_str().unwrap(),
        "-o",
        glb.to_str().unwrap(),
        "--clip",
        "Jump",
    ]);
    assert!(v.is_object());
    let scene = tkio::gltf::read(&glb).unwrap();
    assert_eq!(
        scene.meshes.len(),
        18,
        "one mesh per frame of Jump at 24 fps"
    );
    let colors = scene.meshes[9]
        .mesh
        .colors
        .as_ref()
        .expect("vertex colours");
    // Red (positive) and blue (negative) both appear mid-jump.
    assert!(colors.iter().any(|c| c[0] > 0.9 && c[2] < 0.5));
    assert!(colors.iter().any(|c| c[2] > 0.9 && c[0] < 0.5));
    keep_for_validation(dir.path(), "smear_offsets");
}

#[test]
fn render_writes_png_and_gif() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("robot.png");
    let gif = dir.path().join("spot.gif");
    let robot = data("characters/RobotExpressive.glb");
    ok(&[
        "render",
        robot.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--clip",
        "Wave",
        "--color",
        "offsets",
        "--size",
        "160x120",
    ]);
    let img = render::decode_png(&std::fs::read(&png).unwrap()).unwrap();
    assert_eq!((img.width(), img.height()), (160, 120));
    let non_white = img
        .pixels()
        .iter()
        .filter(|p| p[0] < 250 || p[1] < 250 || p[2] < 250)
        .count();
    assert!(
        non_white > 500,
        "the robot covers the image: {non_white} pixels"
    );
    ok(&[
        "render",
        data("meshes/spot.obj").to_str().unwrap(),
        "-o",
        gif.to_str().unwrap(),
        "--size",
        "64x64",
    ]);
    assert!(std::fs::read(&gif).unwrap().starts_with(b"GIF89a"));
    assert_bad_input(
        &["render", robot.to_str().unwrap(), "-o", "x.tiff"],
        "x.tiff",
    );
    // Contact sheet: Punch has 21 frames → frames 0, 5, …, 20 on 3 columns × 2 rows.
    let sheet = dir.path().join("sheet.png");
    let v = json(&[
        "render",
        robot.to_str().unwrap(),
        "-o",
        sheet.to_str().unwrap(),
        "--clip",
        "Punch",
        "--sheet",
        "--every",
        "5",
        "--columns",
        "3",
        "--size",
        "80x60",
    ]);
    assert_eq!(v["frames"], 5);
    let img = render::decode_png(&std::fs::read(&sheet).unwrap()).unwrap();
    let gap = render::DEFAULT_SHEET_GAP;
    assert_eq!(
        (img.width(), img.height()),
        (3 * 80 + 4 * gap, 2 * 60 + 3 * gap)
    );
    assert_bad_input(
        &[
            "render",
            robot.to_str().unwrap(),
            "-o",
            gif.to_str().unwrap(),
            "--sheet",
        ],
        ".png",
    );
}

#[test]
fn loa_line_writes_every_output_kind() {
    let dir = tempfile::tempdir().unwrap();
    let keys = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/loa/whip.json");
    for ext in ["json", "svg", "png", "gif"] {
        let out = dir.path().join(format!("whip.{ext}"));
        ok(&["loa", "line", keys, "-o", out.to_str().unwrap()]);
        assert!(
            std::fs::metadata(&out).unwrap().len() > 100,
            "{ext} output is empty"
        );
    }
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("whip.json")).unwrap()).unwrap();
    let frames = v["frames"].as_array().unwrap();
    assert_eq!(
        frames[0]["points"].as_array().unwrap().len(),
        11,
        "10 elements → 11 joints"
    );
    let png = render::decode_png(&std::fs::read(dir.path().join("whip.png")).unwrap()).unwrap();
    // Keystrokes are drawn in red.
    assert!(png
        .pixels()
        .iter()
        .any(|p| p[0] > 180 && p[1] < 90 && p[2] < 90));
}

/// `toonkit stopmo segment` on the face at 2 fps (120 frames of the 60 s talk, quick), seeds
/// on the forehead and the chin, writing `out` plus any `extra` options.
fn segment_face(out: &std::path::Path, extra: &[&str]) {
    let face = data("face/ict-face-talk.glb");
    let mut args = vec![
        "stopmo",
        "segment",
        face.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--fps",
        "2",
        "--part",
        "upper=point:0,10,13",
        "--part",
        "lower=point:0,-14,10",
    ];
    args.extend_from_slice(extra);
    ok(&args);
}

#[test]
fn stopmo_segment_face_writes_parts_report_and_render() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("face_parts.glb");
    let report = dir.path().join("seg.json");
    let png = dir.path().join("seg.png");
    segment_face(
        &out,
        &[
            "--layout",
            "morph",
            "--report",
            report.to_str().unwrap(),
            "--render",
            png.to_str().unwrap(),
        ],
    );
    let r: serde_json::Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    assert_eq!(r["parts"], serde_json::json!(["upper", "lower"]));
    assert_eq!(r["gamma"], 100.0);
    assert!(r["cut_length"].as_f64().unwrap() > 10.0);
    assert!(r["seam_vertices"].as_array().unwrap().len() > 50);
    let tp = r["triangle_part"].as_array().unwrap();
    assert!(tp.len() >= 18460, "every (cut) triangle has a part");
    // One mesh node per part, each morphing through the same frames.
    let scene = tkio::gltf::read(&out).unwrap();
    let names: Vec<&str> = scene.nodes.iter().map(|n| n.name.as_str()).collect();
    assert_eq!(names, ["upper", "lower"]);
    assert!(scene.meshes.iter().all(|m| m.morph_targets.len() == 120));
    let s = anim::sample(
        &scene,
        &anim::SampleOptions {
            fps: 2.0,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(s.frame_count, 120);
    // Seam vertices are shared by both parts and identical across frames: the parts' boundary
    // positions coincide in every frame (mixing frames leaves no gap).
    let upper = &s.objects[0].animation;
    let lower = &s.objects[1].animation;
    let shared: Vec<(usize, usize)> = (0..upper.vertex_count())
        .filter_map(|i| {
            let p = upper.frame(0)[i];
            (0..lower.vertex_count())
                .find(|&j| (lower.frame(0)[j] - p).length() < 1e-6)
                .map(|j| (i, j))
        })
        .collect();
    assert!(
        shared.len() > 50,
        "parts share their seam: {}",
        shared.len()
    );
    for &(i, j) in &shared {
        assert!(
            (upper.frame(7)[i] - lower.frame(90)[j]).length() < 1e-4,
            "gap at seam vertex {i}"
        );
    }
    let img = render::decode_png(&std::fs::read(&png).unwrap()).unwrap();
    assert!(img.width() > img.height(), "two panels side by side");
    keep_for_validation(dir.path(), "stopmo_segment");
}

#[test]
fn stopmo_library_face_writes_spec_layout() {
    let dir = tempfile::tempdir().unwrap();
    let parts = dir.path().join("face_parts.glb");
    let out = dir.path().join("lib");
    segment_face(&parts, &[]);
    let summary = json(&[
        "stopmo",
        "library",
        parts.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--pieces",
        "upper=4,lower=6",
        "--restarts",
        "2",
        "--seed",
        "1",
        "--fps",
        "2",
    ]);
    assert_eq!(summary["pieces"], 10);
    for f in [
        "assembly.csv",
        "assembly.md",
        "shooting_order.csv",
        "report.json",
        "reconstruction.glb",
        "reconstruction.pc2",
        "rest.obj",
    ] {
        assert!(out.join(f).is_file(), "missing {f}");
    }
    assert!(!out.join("error_curve.csv").exists(), "no size search ran");
    let mut ids = Vec::new();
    for (part, n) in [("upper", 4), ("lower", 6)] {
        for k in 0..n {
            let id = format!("{part}_{k:02}");
            assert!(out.join(format!("pieces/{id}.obj")).is_file(), "{id}.obj");
            let stl = std::fs::read(out.join(format!("pieces/{id}.stl"))).unwrap();
            let solid = tkio::stl::read(&stl).unwrap();
            // Closed: every undirected edge is shared by exactly two triangles.
            let mut edges = std::collections::HashMap::new();
            for t in &solid.triangles {
                for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                    *edges.entry((a.min(b), a.max(b))).or_insert(0usize) += 1;
                }
            }
            assert!(solid.triangle_count() > 100, "{id}: tiny solid");
            assert!(edges.values().all(|&c| c == 2), "{id} is not closed");
            ids.push(id);
        }
    }
    let csv = std::fs::read_to_string(out.join("assembly.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("frame,upper,lower"));
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 120);
    for (f, row) in rows.iter().enumerate() {
        let cells: Vec<&str> = row.split(',').collect();
        assert_eq!(cells.len(), 3, "row {row}");
        assert_eq!(cells[0], f.to_string());
        assert!(cells[1].starts_with("upper_") && ids.iter().any(|i| i == cells[1]));
        assert!(cells[2].starts_with("lower_") && ids.iter().any(|i| i == cells[2]));
    }
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    for key in [
        "energy",
        "lambda",
        "pieces",
        "errors_mm",
        "parts",
        "seconds",
        "iterations",
        "restarts",
    ] {
        assert!(!r[key].is_null(), "report.json lacks {key}");
    }
    assert_eq!(r["lambda"], 2.0);
    assert_eq!(r["restarts"], 2);
    let e = &r["errors_mm"];
    let mean = e["position_mean"].as_f64().unwrap();
    assert!(mean > 0.0 && mean < e["position_max"].as_f64().unwrap());
    assert!(e["velocity_mean"].as_f64().unwrap() > 0.0);
    let names: Vec<&str> = r["parts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["upper", "lower"]);
    // The reconstruction has both parts and the talk's 120 frames.
    let scene = tkio::gltf::read(&out.join("reconstruction.glb")).unwrap();
    let s = anim::sample(
        &scene,
        &anim::SampleOptions {
            fps: 2.0,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!((s.objects.len(), s.frame_count), (2, 120));
    let shots = std::fs::read_to_string(out.join("shooting_order.csv")).unwrap();
    assert!(shots.starts_with("shot,upper,lower,frames\n"));
    keep_for_validation(&out, "stopmo_library");
}
