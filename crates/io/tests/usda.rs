//! USD (`.usda`) export: exact numbers on RobotExpressive, per-frame topology (motion lines),
//! empty frames, determinism, names. Every layer written here is copied to
//! `$TOONKIT_VALIDATE_DIR` when set, for `.ci/validate_usd.py` (Pixar's `pxr` checks).

mod common;

use std::path::Path;

use anim::glam::Vec3;
use anim::{sample, Mesh, MeshAnimation, SampleOptions};
use common::data;
use tkio::usda::{self, UsdMesh, UsdStage};

/// Keeps `text` as `<name>.usda` for CI's USD validation run.
fn keep_usda(text: &str, name: &str) {
    let Ok(dest) = std::env::var("TOONKIT_VALIDATE_DIR") else {
        return;
    };
    let dest = std::path::PathBuf::from(dest);
    std::fs::create_dir_all(&dest).unwrap();
    std::fs::write(dest.join(format!("{name}.usda")), text).unwrap();
}

/// RobotExpressive's `clip` sampled at `fps`, all meshes merged.
fn robot(clip: &str, fps: f32) -> MeshAnimation {
    let scene = tkio::gltf::read(Path::new(&data("characters/RobotExpressive.glb"))).unwrap();
    let options = SampleOptions {
        fps,
        clip: Some(scene.find_clip(clip).unwrap()),
        meshes: Vec::new(),
    };
    sample(&scene, &options)
        .unwrap()
        .merged("RobotExpressive")
        .unwrap()
}

/// A test-only reader of one time-sampled (or static) array attribute: `time code → text
/// of the value`, in file order.
fn samples<'a>(text: &'a str, decl: &str) -> Vec<(f64, &'a str)> {
    let head = format!("{decl}.timeSamples = {{\n");
    if let Some(start) = text.find(&head) {
        let body = &text[start + head.len()..];
        let end = body.find("\n        }").unwrap();
        return body[..end]
            .lines()
            .map(|l| {
                let (t, v) = l.trim().split_once(": ").unwrap();
                (t.parse().unwrap(), v.trim_end_matches(','))
            })
            .collect();
    }
    let head = format!("{decl} = ");
    let start = text.find(&head).unwrap_or_else(|| panic!("no {decl}")) + head.len();
    let line = text[start..].lines().next().unwrap();
    vec![(f64::NAN, line.trim_end_matches(" ("))]
}

/// Parses `[(x, y, z), ...]`.
fn parse_vec3s(v: &str) -> Vec<Vec3> {
    let inner = v.trim().trim_start_matches('[').trim_end_matches(']');
    if inner.is_empty() {
        return Vec::new();
    }
    inner
        .trim_start_matches('(')
        .trim_end_matches(')')
        .split("), (")
        .map(|t| {
            let c: Vec<f32> = t.split(", ").map(|x| x.parse().unwrap()).collect();
            Vec3::new(c[0], c[1], c[2])
        })
        .collect()
}

/// Parses `[1, 2, 3]` (ints or floats).
fn parse_list(v: &str) -> Vec<f64> {
    let inner = v.trim().trim_start_matches('[').trim_end_matches(']');
    if inner.is_empty() {
        return Vec::new();
    }
    inner.split(", ").map(|x| x.parse().unwrap()).collect()
}

fn metadata<'a>(text: &'a str, key: &str) -> &'a str {
    let head = format!("    {key} = ");
    let start = text.find(&head).unwrap() + head.len();
    text[start..].lines().next().unwrap()
}

#[test]
fn robot_expressive_punch_points_round_trip_bit_exactly() {
    let anim = robot("Punch", 24.0);
    let frames = anim.frame_count();
    assert!(frames > 10, "Punch has {frames} frames");
    let text = usda::write_animation(&anim, None).unwrap();
    keep_usda(&text, "io_robot_punch");
    assert!(text.starts_with("#usda 1.0\n"));
    assert_eq!(metadata(&text, "defaultPrim"), "\"root\"");
    assert_eq!(metadata(&text, "upAxis"), "\"Y\"");
    assert_eq!(metadata(&text, "metersPerUnit"), "1");
    assert_eq!(metadata(&text, "timeCodesPerSecond"), "24");
    assert_eq!(metadata(&text, "framesPerSecond"), "24");
    assert_eq!(metadata(&text, "startTimeCode"), "1");
    assert_eq!(metadata(&text, "endTimeCode"), frames.to_string());
    assert!(text.contains("uniform token subdivisionScheme = \"none\"\n"));
    assert!(text.contains("uniform token orientation = \"rightHanded\"\n"));

    let points = samples(&text, "point3f[] points");
    assert_eq!(points.len(), frames);
    let mut max_err = 0.0f32;
    for (f, (t, v)) in points.iter().enumerate() {
        assert_eq!(*t, (f + 1) as f64, "time code of frame {f}");
        let got = parse_vec3s(v);
        assert_eq!(got.len(), anim.vertex_count());
        for (a, b) in got.iter().zip(anim.frame(f)) {
            max_err = max_err.max((*a - *b).abs().max_element());
        }
    }
    // Shortest round-trip formatting: the parsed f32 are the cached ones, exactly.
    assert_eq!(max_err, 0.0);

    // Extent of a frame = the bounding box of its points.
    let extent = samples(&text, "float3[] extent");
    let mid = frames / 2;
    let b = anim::Aabb::from_points(anim.frame(mid));
    assert_eq!(parse_vec3s(extent[mid].1), vec![b.min, b.max]);

    // Topology: the merged triangles, fixed (no time samples).
    let counts = samples(&text, "int[] faceVertexCounts");
    let indices = samples(&text, "int[] faceVertexIndices");
    assert_eq!(counts.len(), 1);
    let idx = parse_list(indices[0].1);
    assert_eq!(idx.len(), 3 * anim.mesh.triangle_count());
    let want: Vec<f64> = anim
        .mesh
        .triangles
        .iter()
        .flatten()
        .map(|&i| i as f64)
        .collect();
    assert_eq!(idx, want);
    assert!(
        !text.contains("visibility"),
        "an always-visible cache has no visibility"
    );
}

#[test]
fn multiples_alpha_becomes_display_opacity_and_visibility() {
    let anim = robot("Punch", 6.0);
    let (n, frames) = (anim.vertex_count(), anim.frame_count());
    // A copy faded in over the clip: invisible (alpha 0 everywhere) on frame 0.
    let colors: Vec<[f32; 4]> = (0..frames * n)
        .map(|i| [0.8, 0.8, 0.8, (i / n) as f32 / (frames - 1) as f32])
        .collect();
    let mut copy = anim.clone();
    copy.mesh.name = "RobotExpressive m=-1".into();
    let text = usda::write_parts(&[(&anim, None), (&copy, Some(&colors))]).unwrap();
    keep_usda(&text, "io_robot_multiples");
    assert!(text.contains("def Mesh \"RobotExpressive\""));
    assert!(text.contains("def Mesh \"RobotExpressive_m__1\""));
    assert!(text.contains(
        "color3f[] primvars:displayColor (\n            interpolation = \"vertex\"\n        )\n"
    ));
    let opacity = samples(&text, "float[] primvars:displayOpacity");
    assert_eq!(opacity.len(), frames);
    let last = parse_list(opacity[frames - 1].1);
    assert_eq!(last.len(), n);
    assert!(last.iter().all(|&a| a == 1.0));
    let vis = samples(&text, "token visibility");
    assert_eq!(vis.len(), frames);
    assert_eq!(vis[0].1, "\"invisible\"");
    assert!(vis[1..].iter().all(|(_, v)| *v == "\"inherited\""));
}

fn tri(offset: f32) -> Vec<Vec3> {
    vec![
        Vec3::new(offset, 0.0, 0.0),
        Vec3::new(offset + 1.0, 0.0, 0.0),
        Vec3::new(offset, 1.0, 0.0),
    ]
}

#[test]
fn motion_lines_topology_changes_per_frame_and_empty_frames_are_valid() {
    // Frame 1: one triangle; frame 2: no line; frame 3: a quad as two triangles, coloured.
    let a = Mesh::new("l", tri(0.0), vec![[0, 1, 2]]);
    let empty = Mesh::new("l", Vec::new(), Vec::new());
    let mut quad = Mesh::new(
        "l",
        vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, -2.5), Vec3::Y],
        vec![[0, 1, 2], [0, 2, 3]],
    );
    quad.colors = Some(vec![[0.1, 0.2, 0.3, 0.5]; 4]);
    let body = MeshAnimation::new(
        Mesh::new("body", tri(5.0), vec![[0, 1, 2]]),
        12.0,
        [tri(5.0), tri(6.0), tri(7.0)].concat(),
    )
    .unwrap();
    let stage = UsdStage::new(
        12.0,
        vec![
            UsdMesh::animation(&body, None),
            UsdMesh::frames("motion_lines", vec![&a, &empty, &quad]),
        ],
    );
    let text = usda::write(&stage).unwrap();
    keep_usda(&text, "io_motion_lines_topology");
    let lines = &text[text.find("def Mesh \"motion_lines\"").unwrap()..];
    let counts = samples(lines, "int[] faceVertexCounts");
    assert_eq!(
        counts
            .iter()
            .map(|(_, v)| parse_list(v).len())
            .collect::<Vec<_>>(),
        [1, 0, 2]
    );
    let indices = samples(lines, "int[] faceVertexIndices");
    assert_eq!(parse_list(indices[2].1), [0.0, 1.0, 2.0, 0.0, 2.0, 3.0]);
    let points = samples(lines, "point3f[] points");
    assert_eq!(parse_vec3s(points[1].1), Vec::<Vec3>::new());
    let extent = samples(lines, "float3[] extent");
    assert_eq!(
        parse_vec3s(extent[2].1),
        [Vec3::new(0.0, 0.0, -2.5), Vec3::new(1.0, 1.0, 0.0)]
    );
    let vis: Vec<&str> = samples(lines, "token visibility")
        .iter()
        .map(|s| s.1)
        .collect();
    assert_eq!(vis, ["\"inherited\"", "\"invisible\"", "\"inherited\""]);
    // Frame 1 has no colours while frame 3 has: white, opaque.
    let rgb = samples(lines, "color3f[] primvars:displayColor");
    assert_eq!(parse_vec3s(rgb[0].1), [Vec3::ONE; 3]);
    assert_eq!(parse_vec3s(rgb[1].1), Vec::<Vec3>::new());
    assert_eq!(parse_vec3s(rgb[2].1), [Vec3::new(0.1, 0.2, 0.3); 4]);
    // The body prim keeps its fixed topology.
    let body_text = &text[..text.find("def Mesh \"motion_lines\"").unwrap()];
    assert_eq!(samples(body_text, "int[] faceVertexCounts").len(), 1);
    assert_eq!(samples(body_text, "point3f[] points").len(), 3);
}

#[test]
fn a_prim_with_no_line_on_any_frame_is_static_and_invisible() {
    let empty = Mesh::new("l", Vec::new(), Vec::new());
    let stage = UsdStage::new(24.0, vec![UsdMesh::frames("lines", vec![&empty; 4])]);
    let text = usda::write(&stage).unwrap();
    keep_usda(&text, "io_all_empty");
    assert!(text.contains("        int[] faceVertexCounts = []\n"));
    assert!(text.contains("        point3f[] points = []\n"));
    assert!(text.contains("        float3[] extent = [(0, 0, 0), (0, 0, 0)]\n"));
    assert!(text.contains("        token visibility = \"invisible\"\n"));
    assert_eq!(metadata(&text, "endTimeCode"), "4");
}

#[test]
fn one_frame_clip_and_still_cache_are_written_without_time_samples() {
    let still = MeshAnimation::still(Mesh::new("still", tri(0.0), vec![[0, 1, 2]]));
    let text = usda::write_animation(&still, None).unwrap();
    keep_usda(&text, "io_one_frame");
    assert!(!text.contains("timeSamples"));
    assert_eq!(metadata(&text, "endTimeCode"), "1");
    assert!(text.contains("point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]\n"));
    // Three identical frames: static too, but the time range spans them.
    let three = MeshAnimation::new(
        still.mesh.clone(),
        24.0,
        [tri(0.0), tri(0.0), tri(0.0)].concat(),
    )
    .unwrap();
    let text = usda::write_animation(&three, None).unwrap();
    assert!(!text.contains("timeSamples"));
    assert_eq!(metadata(&text, "endTimeCode"), "3");
}

#[test]
fn nan_and_infinity_are_written_as_zero_inside_the_extent() {
    let m = Mesh::new(
        "bad",
        vec![
            Vec3::new(f32::NAN, 2.0, 3.0),
            Vec3::new(4.0, f32::INFINITY, -1.0),
            Vec3::X,
        ],
        vec![[0, 1, 2]],
    );
    let stage = UsdStage::new(24.0, vec![UsdMesh::frames("bad", vec![&m])]);
    let text = usda::write(&stage).unwrap();
    keep_usda(&text, "io_nan");
    assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
    assert!(text.contains("points = [(0, 2, 3), (4, 0, -1), (1, 0, 0)]"));
    assert!(text.contains("extent = [(0, 0, -1), (4, 2, 3)]"));
}

#[test]
fn same_input_gives_the_same_bytes() {
    let anim = robot("Wave", 8.0);
    let a = usda::write_animation(&anim, None).unwrap();
    let b = usda::write_animation(&anim, None).unwrap();
    // Frames are formatted in parallel: one thread must give the same bytes.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let c = pool.install(|| usda::write_animation(&anim, None).unwrap());
    assert_eq!((a.len(), a.len()), (b.len(), c.len()));
    assert!(a == b && a == c, "writes differ");
}

#[test]
fn prim_names_are_sanitized_and_unique_among_siblings() {
    let mk = |name: &str| MeshAnimation::still(Mesh::new(name, tri(0.0), vec![[0, 1, 2]]));
    let parts = [mk("arm.L"), mk("arm.L"), mk("3d body"), mk(""), mk("Ünï")];
    let refs: Vec<(&MeshAnimation, Option<&[[f32; 4]]>)> =
        parts.iter().map(|p| (p, None)).collect();
    let mut stage = UsdStage::new(24.0, Vec::new());
    stage.meshes = refs
        .iter()
        .map(|(a, c)| UsdMesh::animation(a, *c))
        .collect();
    stage.root = "my scene".into();
    let text = usda::write(&stage).unwrap();
    keep_usda(&text, "io_names");
    let names: Vec<&str> = text
        .lines()
        .filter_map(|l| l.trim().strip_prefix("def Mesh \""))
        .map(|l| l.trim_end_matches('"'))
        .collect();
    assert_eq!(names, ["arm_L", "arm_L_1", "_3d_body", "mesh", "_n_"]);
    assert_eq!(metadata(&text, "defaultPrim"), "\"my_scene\"");
    assert!(text.contains("def Xform \"my_scene\"\n"));
}

#[test]
fn bad_colours_and_indices_are_errors_not_panics() {
    let anim = MeshAnimation::still(Mesh::new("t", tri(0.0), vec![[0, 1, 2]]));
    let err = usda::write_animation(&anim, Some(&[[1.0; 4]; 2])).unwrap_err();
    assert!(
        err.to_string().contains("expected 3 vertex colours"),
        "{err}"
    );
    let broken = Mesh::new("b", tri(0.0), vec![[0, 1, 7]]);
    let stage = UsdStage::new(24.0, vec![UsdMesh::frames("b", vec![&broken])]);
    let err = usda::write(&stage).unwrap_err();
    assert!(err.to_string().contains("vertex 7"), "{err}");
    let two = MeshAnimation::new(anim.mesh.clone(), 24.0, [tri(0.0), tri(1.0)].concat()).unwrap();
    assert!(usda::write_parts(&[(&anim, None), (&two, None)]).is_err());
    assert!(usda::write(&UsdStage::new(0.0, Vec::new())).is_err());
}

#[test]
fn usda_input_is_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("x.usda");
    let anim = MeshAnimation::still(Mesh::new("t", tri(0.0), vec![[0, 1, 2]]));
    std::fs::write(&p, usda::write_animation(&anim, None).unwrap()).unwrap();
    let bytes = std::fs::read(&p).unwrap();
    // Detected by content whatever the extension, and by extension for outputs.
    let usda = Some(tkio::Format::Usda);
    assert_eq!(tkio::detect(&bytes, Path::new("x.bin")), usda);
    assert_eq!(tkio::Format::from_extension(Path::new("OUT.USDA")), usda);
    let err = tkio::load(&p, &tkio::LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("USD input is not supported"), "{err}");
    assert!(err.contains("x.usda") && !err.contains('\n'), "{err}");
}

#[test]
fn obj_polygons_are_kept_as_n_gons() {
    // A quad from an OBJ keeps its 4 sides (the triangles are the fallback).
    let mut quad = Mesh::new(
        "quad",
        vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
        vec![[0, 1, 2], [0, 2, 3]],
    );
    quad.polygons = Some(vec![vec![0, 1, 2, 3]]);
    quad.uvs = Some(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    let text = usda::write_animation(&MeshAnimation::still(quad), None).unwrap();
    keep_usda(&text, "io_quad");
    assert_eq!(samples(&text, "int[] faceVertexCounts")[0].1, "[4]");
    assert_eq!(
        samples(&text, "int[] faceVertexIndices")[0].1,
        "[0, 1, 2, 3]"
    );
    // UVs (glTF convention) are written as USD `st` with v flipped.
    assert_eq!(
        samples(&text, "texCoord2f[] primvars:st")[0].1,
        "[(0, 1), (1, 1), (1, 0), (0, 0)]"
    );
}

#[test]
fn cesium_man_texture_coordinates_are_st_with_v_up() {
    // toonkit's UVs follow glTF (v down from the image top); USD's `st` has v up.
    let scene = tkio::gltf::read(Path::new(&data("characters/CesiumMan.glb"))).unwrap();
    let options = SampleOptions {
        fps: 6.0,
        clip: Some(0),
        meshes: Vec::new(),
    };
    let anim = sample(&scene, &options)
        .unwrap()
        .merged("CesiumMan")
        .unwrap();
    let uvs = anim.mesh.uvs.clone().expect("CesiumMan has TEXCOORD_0");
    let text = usda::write_animation(&anim, None).unwrap();
    let st = samples(&text, "texCoord2f[] primvars:st");
    assert_eq!(st.len(), 1, "static: one value for every frame");
    let values: Vec<[f32; 2]> = st[0]
        .1
        .trim_start_matches("[(")
        .trim_end_matches(")]")
        .split("), (")
        .map(|t| {
            let c: Vec<f32> = t.split(", ").map(|x| x.parse().unwrap()).collect();
            [c[0], c[1]]
        })
        .collect();
    assert_eq!(values.len(), uvs.len());
    for (st, uv) in values.iter().zip(&uvs) {
        assert_eq!(st[0], uv[0]);
        assert_eq!(st[1], 1.0 - uv[1]);
    }
    assert!(text.contains("interpolation = \"vertex\""));
    keep_usda(&text, "io_usda_cesium_st");
}
