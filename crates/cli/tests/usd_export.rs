//! USD (`.usda`) outputs of `toonkit convert`, `smear elongate|multiples|lines` and
//! `smear --style` on RobotExpressive, checked against the other formats' numbers. Every
//! layer is kept in `$TOONKIT_VALIDATE_DIR` for `.ci/validate_usd.py` (Pixar's `pxr`).

mod common;

use std::path::{Path, PathBuf};

use common::{data, json, keep_for_validation, read_pc2, s, samples, toonkit, vec3s};

fn robot() -> PathBuf {
    data("characters/RobotExpressive.glb")
}

/// The text of the `def Mesh "name"` prim (up to the next prim).
fn prim<'a>(text: &'a str, name: &str) -> &'a str {
    let start = text
        .find(&format!("def Mesh \"{name}\""))
        .unwrap_or_else(|| panic!("no Mesh {name}"));
    let rest = &text[start + 1..];
    &text[start..start + 1 + rest.find("def Mesh").unwrap_or(rest.len())]
}

fn mesh_names(text: &str) -> Vec<&str> {
    text.lines()
        .filter_map(|l| l.trim().strip_prefix("def Mesh \""))
        .map(|l| l.trim_end_matches('"'))
        .collect()
}

/// Largest coordinate difference between a `.usda` point cache and a `.pc2` one.
fn max_difference(usda: &str, pc2: &anim::MeshAnimation) -> f32 {
    let frames = samples(usda, "point3f[] points");
    assert_eq!(frames.len(), pc2.frame_count());
    let mut max = 0.0f32;
    for (f, v) in frames.iter().enumerate() {
        let pts = vec3s(v);
        assert_eq!(pts.len(), pc2.vertex_count());
        for (a, b) in pts.iter().zip(pc2.frame(f)) {
            for k in 0..3 {
                max = max.max((a[k] - b[k]).abs());
            }
        }
    }
    max
}

#[test]
fn convert_robot_punch_to_usda_matches_the_pc2_cache_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let usda = dir.path().join("punch.usda");
    let pc2 = dir.path().join("punch.pc2");
    let v = json(&["convert", s(&robot()), s(&usda), "--clip", "Punch"]);
    json(&["convert", s(&robot()), s(&pc2), "--clip", "Punch"]);
    let frames = v["frames"].as_u64().unwrap() as usize;
    assert_eq!(v["outputs"][0].as_str().unwrap(), s(&usda));
    let text = std::fs::read_to_string(&usda).unwrap();
    assert!(text.starts_with("#usda 1.0\n"));
    assert!(text.contains(&format!("    endTimeCode = {frames}\n")));
    assert_eq!(mesh_names(&text), ["RobotExpressive"]);
    // The same numbers as the PC2 cache, bit for bit.
    assert_eq!(max_difference(&text, &read_pc2(&pc2)), 0.0);
    keep_for_validation(dir.path(), "usd_convert");
}

#[test]
fn smear_elongate_robot_punch_usda_matches_pc2() {
    let dir = tempfile::tempdir().unwrap();
    let usda = dir.path().join("e.usda");
    let pc2 = dir.path().join("e.pc2");
    let robot = robot();
    let run = |out: &Path| {
        json(&[
            "smear",
            "elongate",
            s(&robot),
            "--clip",
            "Punch",
            "-o",
            s(out),
        ])
    };
    let v = run(&usda);
    run(&pc2);
    let text = std::fs::read_to_string(&usda).unwrap();
    let smeared = read_pc2(&pc2);
    assert_eq!(
        v["frames"].as_u64().unwrap() as usize,
        smeared.frame_count()
    );
    assert_eq!(max_difference(&text, &smeared), 0.0);
    assert!(v["max_displacement"].as_f64().unwrap() > 0.0);
    // Velocities for motion blur: the smeared points' central difference per second.
    let velocities = samples(&text, "vector3f[] velocities");
    assert_eq!(velocities.len(), smeared.frame_count());
    let f = smeared.frame_count() / 2;
    let (before, after) = (smeared.frame(f - 1), smeared.frame(f + 1));
    for (k, v) in vec3s(velocities[f]).iter().enumerate() {
        let want = (after[k] - before[k]) * (24.0 / 2.0);
        let got = anim::glam::Vec3::from_array(*v);
        assert!(
            got.distance(want) <= 1e-3 * (1.0 + want.length()),
            "vertex {k}: {got} vs {want}"
        );
    }
    keep_for_validation(dir.path(), "usd_elongate");
}

#[test]
fn smear_multiples_usda_has_one_mesh_per_copy_with_opacity() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m.usda");
    let v = json(&[
        "smear",
        "multiples",
        s(&robot()),
        "-o",
        s(&out),
        "--clip",
        "Punch",
        "--fps",
        "12",
        "--past",
        "2",
        "--future",
        "1",
    ]);
    let text = std::fs::read_to_string(&out).unwrap();
    let copies = v["copies"].as_array().unwrap().len();
    assert_eq!(copies, 3);
    let names = mesh_names(&text);
    assert_eq!(names.len(), 1 + copies, "{names:?}");
    let frames = v["frames"].as_u64().unwrap() as usize;
    for name in &names[1..] {
        let p = prim(&text, name);
        let opacity = samples(p, "float[] primvars:displayOpacity");
        assert!(opacity.len() == frames || opacity.len() == 1, "{name}");
        assert!(p.contains("interpolation = \"vertex\""));
    }
    keep_for_validation(dir.path(), "usd_multiples");
}

#[test]
fn smear_lines_usda_changes_topology_per_frame() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("l.usda");
    let v = json(&[
        "smear",
        "lines",
        s(&robot()),
        "-o",
        s(&out),
        "--clip",
        "Punch",
        "--fps",
        "12",
        "--count",
        "0:0,4:40",
        "--length-max",
        "4",
    ]);
    let text = std::fs::read_to_string(&out).unwrap();
    // The body is a Mesh, the lines are curves renderers draw as such.
    assert_eq!(mesh_names(&text), ["RobotExpressive"]);
    let start = text
        .find("def BasisCurves \"motion_lines\"")
        .expect("a BasisCurves prim");
    let lines = &text[start..];
    let per_frame: Vec<u64> = v["lines_per_frame"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap())
        .collect();
    // No line on frame 0 (count keyed to 0), lines later.
    assert_eq!(per_frame[0], 0);
    assert!(per_frame.iter().any(|&n| n > 0), "{per_frame:?}");
    let counts = samples(lines, "int[] curveVertexCounts");
    assert_eq!(counts.len(), per_frame.len());
    let vis = samples(lines, "token visibility");
    let widths = samples(lines, "float[] widths");
    let opacity = samples(lines, "float[] primvars:displayOpacity");
    let points = samples(lines, "point3f[] points");
    for (f, &n) in per_frame.iter().enumerate() {
        // One curve per line drawn; a frame with no line holds one hidden curve (two points,
        // zero width: Blender's importer crashes on empty samples) and is invisible.
        let curves = counts[f]
            .trim_matches(['[', ']'])
            .split(", ")
            .filter(|c| !c.is_empty());
        assert_eq!(curves.count() as u64, n.max(1), "frame {f}: {}", counts[f]);
        if n == 0 {
            assert_eq!(
                widths[f], "[0, 0]",
                "frame {f}: the hidden curve has no width"
            );
        }
        assert_eq!(vis[f] == "\"invisible\"", n == 0, "frame {f}");
        // A width and an opacity per point.
        let k = vec3s(points[f]).len();
        let w = widths[f]
            .trim_matches(['[', ']'])
            .split(", ")
            .filter(|c| !c.is_empty());
        let a = opacity[f]
            .trim_matches(['[', ']'])
            .split(", ")
            .filter(|c| !c.is_empty());
        assert_eq!((w.count(), a.count()), (k, k), "frame {f}");
    }
    keep_for_validation(dir.path(), "usd_lines");
}

#[test]
fn smear_style_fig16_usda_has_every_part() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("s.usda");
    let style = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/smear/fig16_combined.toml"
    ));
    assert!(style.exists(), "missing example style {}", style.display());
    let v = json(&[
        "smear",
        s(&robot()),
        "--style",
        s(&style),
        "--clip",
        "Punch",
        "--fps",
        "8",
        "-o",
        s(&out),
    ]);
    let text = std::fs::read_to_string(&out).unwrap();
    // Bodies and multiples are meshes; motion lines are BasisCurves prims.
    let mut names = mesh_names(&text);
    names.extend(
        text.lines()
            .filter_map(|l| l.trim().strip_prefix("def BasisCurves \""))
            .map(|l| l.trim_end_matches('"')),
    );
    assert!(
        text.contains("def BasisCurves \""),
        "the style's motion lines are curves"
    );
    assert_eq!(
        names.len() as u64,
        v["parts"].as_u64().unwrap(),
        "{names:?}"
    );
    let unique: std::collections::BTreeSet<_> = names.iter().collect();
    assert_eq!(
        unique.len(),
        names.len(),
        "prim names must be unique: {names:?}"
    );
    let fps = v["fps"].as_f64().unwrap() as f32;
    assert!(text.contains(&format!("    framesPerSecond = {fps}\n")));
    keep_for_validation(dir.path(), "usd_style");
}

#[test]
fn usda_input_is_refused_with_exit_2_and_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let usda = dir.path().join("in.usda");
    json(&["convert", s(&data("characters/SimpleSkin.gltf")), s(&usda)]);
    let out = toonkit(&["convert", s(&usda), s(&dir.path().join("x.glb"))]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("USD input is not supported") && err.contains("in.usda"),
        "{err}"
    );
    keep_for_validation(dir.path(), "usd_bad_input");
}
