//! A style means the same on any character (`docs/smear-units.md`): speeds and lengths of a
//! style are in the character's size, so an object modelled at 0.01× or 100× its size gets the
//! same smear relative to its size; `speed_units = "scene"` keeps the paper's per-frame scene
//! units, which do not.

use anim::{Mesh, MeshAnimation, SampledScene};
use glam::Vec3;
use smear::{prepare, stylize, PrepareOptions, Style};

/// A tetrahedron of edge `scale` accelerating along +X and falling onto y = 0 (speeds vary
/// over the clip and across vertices once it tumbles).
fn tumbling_tet(scale: f32) -> SampledScene {
    let rest = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
    let mesh = Mesh::new(
        "tet",
        rest.iter().map(|p| *p * scale).collect(),
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    );
    let frames: Vec<Vec3> = (0..12)
        .flat_map(|f| {
            let t = f as f32;
            let turn = glam::Quat::from_rotation_z(0.08 * t);
            rest.map(move |p| (turn * p + Vec3::new(0.02 * t * t, 3.0 - 0.02 * t * t, 0.0)) * scale)
        })
        .collect();
    SampledScene::from_animation(MeshAnimation::new(mesh, 24.0, frames).unwrap())
}

/// Mean elongation and mean line length over the size, and the size.
fn relative(scale: f32, style: &str) -> (f64, f64, f32) {
    let prepared = prepare(tumbling_tet(scale), &PrepareOptions::default()).unwrap();
    let style = Style::from_toml_str(style).unwrap();
    let out = stylize(&prepared, &style).unwrap();
    let o = &out.report.objects[0];
    let size = prepared.size() as f64;
    (
        o.elongation_mean.unwrap() / size,
        o.lines_length_mean.unwrap_or(0.0) / size,
        prepared.size(),
    )
}

const STYLE: &str = r#"
[elongate]
function = { stages = [{ op = "speed" }, { op = "scale", by = 0.4 }] }
[lines]
count = 8
min_speed = 0.05
length = { expr = "0.3 * speed * delta" }
thickness = { stages = [{ op = "set", value = 0.004 }] }
[contact]
ground = 0.1
"#;

#[test]
fn speed_preset_and_lines_look_the_same_at_any_scale() {
    let (e, l, size) = relative(1.0, STYLE);
    assert!(e > 1e-3 && l > 1e-3, "{e} {l}");
    for k in [0.01f32, 100.0] {
        let (ek, lk, size_k) = relative(k, STYLE);
        assert!((size_k / size / k - 1.0).abs() < 1e-5, "size {size_k}");
        assert!((ek / e - 1.0).abs() < 1e-3, "×{k}: elongation {ek} vs {e}");
        assert!((lk / l - 1.0).abs() < 1e-3, "×{k}: line length {lk} vs {l}");
    }
}

#[test]
fn scene_units_are_the_papers_and_depend_on_the_scale() {
    let scene = format!("speed_units = \"scene\"\n{STYLE}");
    let (e, _, _) = relative(1.0, &scene);
    let (e100, _, _) = relative(100.0, &scene);
    // Per-frame scene speeds grow 100×, and so does β: the relative smear is not the same.
    assert!(e100 > 5.0 * e, "{e100} vs {e}");
}
