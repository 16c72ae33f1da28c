//! Styled smears and motion lines (per-frame topology) go to every scene-cache format, not only
//! `.glb`/`.usda`: `.usdc`, `.usdz` and Alembic `.abc` through the same `tkio::save`.

mod common;

use common::*;
use tkio::Format;

#[test]
fn styled_smear_and_motion_lines_write_usdc_usdz_and_abc() {
    let dir = tempfile::tempdir().unwrap();
    let robot = data("characters/RobotExpressive.glb");
    let style = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/smear/fig16_combined.toml"
    );
    for (ext, format) in [
        ("usdc", Format::Usdc),
        ("usdz", Format::Usdz),
        ("abc", Format::Abc),
    ] {
        let out = dir.path().join(format!("style.{ext}"));
        ok(&[
            "smear",
            s(&robot),
            "--clip",
            "Punch",
            "--style",
            style,
            "-o",
            s(&out),
        ]);
        let bytes = std::fs::read(&out).unwrap();
        assert_eq!(tkio::detect(&bytes, &out), Some(format), "{ext}");
    }
    // The Alembic archive holds every part of the style with the clip's 21 frames.
    let abc = tkio::abc::read(&std::fs::read(dir.path().join("style.abc")).unwrap()).unwrap();
    assert!(abc.meshes.len() > 2, "{} meshes", abc.meshes.len());
    assert!(abc.meshes.iter().any(|m| m.frames.len() == 21));

    // Motion lines: the body and one mesh whose topology changes per frame.
    let lines = dir.path().join("lines.abc");
    ok(&[
        "smear",
        "lines",
        s(&robot),
        "--clip",
        "Punch",
        "--count",
        "60",
        "-o",
        s(&lines),
    ]);
    let abc = tkio::abc::read(&std::fs::read(&lines).unwrap()).unwrap();
    let line_mesh = abc
        .meshes
        .iter()
        .find(|m| m.name.contains("motion_lines"))
        .expect("a motion_lines mesh");
    let sizes: std::collections::BTreeSet<usize> =
        line_mesh.frames.iter().map(|f| f.points.len()).collect();
    assert!(
        sizes.len() > 1,
        "line topology changes per frame: {sizes:?}"
    );
}
