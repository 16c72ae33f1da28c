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
    ok(&["convert", cesium.to_str().unwrap(), rest.to_str().unwrap()]);
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

#[test]
fn stopmo_segment_face_writes_parts_report_and_render() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("face_parts.glb");
    let report = dir.path().join("seg.json");
    let png = dir.path().join("seg.png");
    let face = data("face/ict-face-talk.glb");
    // 2 fps keeps the test quick (120 frames of the 60 s talk).
    ok(&[
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
        "--report",
        report.to_str().unwrap(),
        "--render",
        png.to_str().unwrap(),
    ]);
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
