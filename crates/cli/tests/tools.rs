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
