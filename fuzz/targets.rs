//! The fuzz targets' bodies, one function per target: `fuzz_targets/<name>.rs` hands each
//! libFuzzer input to the function of the same name, and the workspace's `cargo test`
//! (`crates/cli/tests/fuzz_regressions.rs`) replays the seeds and every saved crasher in
//! `regressions/<name>/` through the very same code. A function returns normally for any
//! input; a panic is a bug.
#![allow(dead_code)]

/// Alembic (Ogawa) archives from bytes: any bytes give Ok or Err; an archive that reads
/// gives every mesh's samples without panicking.
pub(crate) fn abc(data: &[u8]) {
    // 256 KiB of decoded samples: the default 512 MiB budget lets a 300-byte input expand
    // for a second (~250 runs/s), and 4 MiB still kept the fuzzer under 2,000 runs/s,
    // without exploring anything a small budget does not.
    let _ = tkio::abc::read_with_limit(data, 256 << 10);
}

/// BVH: any bytes give Ok or Err; a scene that reads samples without NaN (when short enough)
/// and its BVH export reads back.
pub(crate) fn bvh(data: &[u8]) {
    use anim::{sample, SampleOptions};
    use tkio::bvh;
    let Ok(scene) = bvh::read(data) else { return };
    let fps = scene
        .clips
        .first()
        .and_then(|c| c.key_rate())
        .unwrap_or(24.0);
    // Keep each run small: a huge `Frame Time` is valid but would sample millions of frames.
    let frames = scene
        .clips
        .first()
        .map_or(1.0, |c| c.duration() as f64 * fps as f64 + 1.0);
    let work = frames * scene.nodes.len() as f64;
    if work.is_nan() || work > 100_000.0 {
        return;
    }
    let Ok(s) = sample(
        &scene,
        &SampleOptions {
            fps,
            ..SampleOptions::default()
        },
    ) else {
        return;
    };
    if let Some(motion) = &s.skeletal {
        if let Ok(text) = bvh::write(&s.skeleton, motion) {
            bvh::read(text.as_bytes()).expect("re-read of written BVH");
        }
    }
}

/// Stylization expressions: any text gives Ok or Err; an expression that compiles evaluates
/// (to any number, NaN included) on ordinary and extreme inputs without panicking.
pub(crate) fn expr(data: &[u8]) {
    use smear::{Expression, Param, StyleInput, Stylize};
    use std::collections::BTreeMap;
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let params: BTreeMap<String, Param> = [
        ("beta_max".to_string(), Param::Constant(2.0)),
        (
            "tau_max".to_string(),
            Param::Curve(vec![[0.0, 0.0], [10.0, 3.0]]),
        ),
    ]
    .into();
    let Ok(e) = Expression::compile(text, Param::Constant(1.0), 7, params) else {
        return;
    };
    for x in [
        StyleInput::default(),
        StyleInput {
            delta: -1.0,
            speed: 3.5,
            weight: 1.0,
            frame: 12.5,
            m: -2.0,
            t: 0.5,
            ..StyleInput::default()
        },
        StyleInput {
            delta: f32::MAX,
            speed: f32::INFINITY,
            weight: f32::NAN,
            frame: -1e30,
            m: f32::MIN,
            t: 1.0,
            ..StyleInput::default()
        },
    ] {
        let _ = e.eval(&x);
    }
}

/// glTF/GLB from bytes: any bytes give Ok or Err.
pub(crate) fn gltf(data: &[u8]) {
    let _ = tkio::gltf::read_bytes(data);
}

/// Keystrokes from JSON or SVG text (`loa::Keystrokes::parse`): any text gives Ok or Err.
pub(crate) fn keystrokes(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = loa::Keystrokes::parse(text);
    // Both readers, whatever the first character says.
    let _ = loa::Keystrokes::from_json_str(text);
    let _ = loa::Keystrokes::from_svg_str(text);
}

/// MDD: any bytes give Ok or Err; a valid file re-encodes to the same positions.
pub(crate) fn mdd(data: &[u8]) {
    use tkio::mdd;
    let points = mdd::read_header(data).map(|h| h.points).ok();
    point_cache(data, points, mdd::read, mdd::write);
}

/// A point cache (PC2, MDD) with `points` vertices per frame by its header: any bytes give
/// Ok or Err; a file that reads re-encodes to the same positions.
fn point_cache(
    data: &[u8],
    points: Option<usize>,
    read: fn(&[u8], anim::Mesh, f32) -> tkio::Result<anim::MeshAnimation>,
    write: fn(&anim::MeshAnimation) -> Vec<u8>,
) {
    let points = points.unwrap_or(3).min(1 << 16);
    let rest = anim::Mesh::new("r", vec![anim::glam::Vec3::ZERO; points], Vec::new());
    if let Ok(a) = read(data, rest.clone(), 24.0) {
        let b = read(&write(&a), rest, a.fps).expect("re-read of written point cache");
        assert_eq!(a.positions(), b.positions());
    }
}

/// NPY: any bytes give Ok or Err; an array that reads writes back to the same bits.
pub(crate) fn npy(data: &[u8]) {
    use tkio::npy;
    if let Ok((shape, values)) = npy::read_f32(data) {
        let bytes = npy::write_f32(&shape, &values).expect("write of a read array");
        let (shape2, values2) = npy::read_f32(&bytes).expect("re-read of written NPY");
        assert_eq!(shape, shape2);
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&values), bits(&values2));
    }
}

/// OBJ: any bytes give Ok or Err; a mesh that reads writes back to exactly the same mesh.
pub(crate) fn obj(data: &[u8]) {
    use tkio::obj;
    if let Ok(m) = obj::read(data) {
        let again = obj::read(obj::write(&m).as_bytes()).expect("re-read of written OBJ");
        assert_eq!(again, m);
    }
}

/// PC2: any bytes give Ok or Err; a valid file re-encodes to the same positions.
pub(crate) fn pc2(data: &[u8]) {
    use tkio::pc2;
    let points = pc2::read_header(data).map(|h| h.points).ok();
    point_cache(data, points, pc2::read, pc2::write);
}

/// STL: any bytes give Ok or Err; a mesh that reads writes back to the same welded mesh.
pub(crate) fn stl(data: &[u8]) {
    use tkio::stl;
    if let Ok(m) = stl::read(data) {
        let again = stl::read(&stl::write_binary(&m)).expect("re-read of written STL");
        assert_eq!(again.positions, m.positions);
        assert_eq!(again.triangles, m.triangles);
    }
}

/// Smear style files (TOML): any text gives Ok or Err; a style that parses compiles for a
/// unit-size scene without panicking.
pub(crate) fn style(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(style) = smear::Style::from_toml_str(text) {
        let _ = style.for_object("body").compile(1.0);
        if let Ok(text) = style.to_toml_string() {
            let _ = smear::Style::from_toml_str(&text);
        }
    }
}

/// glTF buffer URIs: the confinement rule of a `.gltf` (a URI resolves only inside the
/// file's folder). Any text gives Ok or Err; an accepted URI is a relative path of plain
/// names (no root, no `..`, no scheme or drive), so joined to the folder it stays inside.
pub(crate) fn gltf_uri(data: &[u8]) {
    use std::path::Component;
    let Ok(uri) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(rel) = tkio::gltf::confined_uri(uri) {
        assert!(!uri.contains(':'), "a scheme or drive passed: {uri:?}");
        assert!(
            rel.components()
                .all(|c| matches!(c, Component::Normal(_) | Component::CurDir)),
            "{uri:?} leaves the folder as {rel:?}"
        );
        assert!(rel.is_relative(), "{uri:?}");
    }
}

/// Option sizes: eight little-endian u64 values read as `--smooth`, a motion-line count,
/// samples, sides, frames, an image's width and height, and keystrokes (and a job's memory
/// estimate from them). The budget checks never panic (products saturate), and a size they
/// accept is within its limit.
pub(crate) fn sizes(data: &[u8]) {
    use anim::budget::{self, product};
    let mut v = [0u64; 8];
    for (k, chunk) in data.chunks(8).take(8).enumerate() {
        let mut b = [0u8; 8];
        b[..chunk.len()].copy_from_slice(chunk);
        v[k] = u64::from_le_bytes(b);
    }
    let [smooth, count, samples, sides, frames, width, height, keys] = v;
    let options = smear::OffsetOptions {
        smooth: smooth.min(usize::MAX as u64) as usize,
        ..Default::default()
    };
    if options.check_budget().is_ok() {
        assert!(smooth <= budget::DEFAULT_MAX_SMOOTH);
    }
    let lines = product(&[count, samples, sides, frames]);
    match anim::check_budget("lines", lines, budget::DEFAULT_MAX_LINE_VERTICES, "") {
        Ok(()) => assert!(lines <= budget::DEFAULT_MAX_LINE_VERTICES),
        Err(e) => assert!(e.to_string().contains("over the limit")),
    }
    let pixels = product(&[width, height, frames]);
    let _ = anim::check_budget("pixels", pixels, budget::DEFAULT_MAX_PIXELS, "");
    let _ = anim::check_budget("keystrokes", keys, budget::DEFAULT_MAX_KEYSTROKES, "");
    // A job's memory: frames × vertices (width) × copies (count) and the lines' bytes.
    let job = budget::JobMemory::new()
        .positions("copies", frames as usize, width as usize, count)
        .bytes("lines", lines);
    match job.check("") {
        Ok(()) => assert!(job.total() <= budget::max_job_bytes()),
        Err(e) => assert!(e.to_string().contains("over the limit")),
    }
}
