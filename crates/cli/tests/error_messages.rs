//! Every error variant of every crate, as its message reads (issue #23): one line, no
//! `Debug` output, no OS error codes or repeated text, numbers written for people. Each row
//! builds the variant with the awkward values real inputs produce (f32::MAX, NaN, long
//! paths); the CLI's own messages are covered by `no_surprises.rs` and `assert_bad_input`.

mod common;

use std::path::Path;

use common::assert_readable;

fn io(kind: std::io::ErrorKind) -> std::io::Error {
    std::io::Error::from(kind)
}

fn anim_errors() -> Vec<anim::AnimError> {
    use anim::AnimError as E;
    vec![
        E::LengthMismatch {
            what: "positions of mesh 'body'".into(),
            expected: 9819,
            found: 9816,
        },
        E::IndexOutOfRange {
            triangle: 12,
            index: u32::MAX,
            vertices: 3273,
        },
        E::NonFinite {
            what: "frame 3 of mesh 'body'".into(),
        },
        E::NotFound {
            kind: "clip",
            name: "Wak".into(),
            available: "Walk, Run".into(),
        },
        E::Invalid("a clip needs at least one key".into()),
        E::OverBudget(anim::OverBudget {
            what: "frames at 24 fps".into(),
            asked: 480_001,
            limit: anim::budget::DEFAULT_MAX_FRAMES,
            hint: "; the clip lasts 20000.0 s: lower --fps or pick a shorter clip".into(),
        }),
    ]
}

fn io_errors() -> Vec<tkio::IoError> {
    use std::io::ErrorKind as K;
    let p = Path::new("/tmp/out/walk.glb");
    let mut v: Vec<tkio::IoError> = [
        K::NotFound,
        K::PermissionDenied,
        K::IsADirectory,
        K::NotADirectory,
        K::ReadOnlyFilesystem,
        K::StorageFull,
        K::FileTooLarge,
        K::QuotaExceeded,
        K::UnexpectedEof,
        K::InvalidData,
        K::Interrupted,
    ]
    .into_iter()
    .map(|k| tkio::IoError::io(p, io(k)))
    .collect();
    v.push(tkio::IoError::io(p, std::io::Error::from_raw_os_error(28)));
    v.push(tkio::IoError::io(p, std::io::Error::from_raw_os_error(21)));
    v.push(tkio::IoError::malformed("glTF", "accessor 3 reads past its buffer view").at(p));
    v.push(tkio::IoError::unsupported("KHR_draco_mesh_compression is not supported").at(p));
    v.push(tkio::IoError::encode("USD binary", "int array of 7 elements").at(p));
    v.push(tkio::IoError::FramesDoNotFit {
        path: tkio::FilePath(p.with_extension("obj")),
        frames: 48,
        extension: "obj",
    });
    v.push(tkio::IoError::NoSuchFrame {
        path: tkio::FilePath(p.into()),
        frame: 48,
        last: 47,
    });
    v.push(tkio::IoError::from(anim_errors().remove(2)).at(p));
    v
}

fn render_errors() -> Vec<render::RenderError> {
    use render::RenderError as E;
    vec![
        E::InvalidSize {
            width: 0,
            height: 100000,
            max: 8192,
        },
        E::IndexOutOfRange {
            mesh: "body".into(),
            triangle: 3,
            index: 99999,
            vertices: 3,
        },
        E::AttributeLength {
            mesh: "body".into(),
            what: "colours",
            expected: 3273,
            found: 3,
        },
        E::SizeMismatch {
            index: 2,
            width: 400,
            height: 400,
            found_w: 200,
            found_h: 200,
        },
        E::NoFrames,
        E::InvalidFps(f32::MAX),
        E::InvalidFps(f32::NAN),
        E::FrameOutOfRange {
            frame: 99,
            frames: 48,
        },
        E::CameraNotFound {
            name: "cam".into(),
            available: "Camera".into(),
        },
        E::Png("out of memory".into()),
        E::Gif("too many colours".into()),
    ]
}

fn style_errors() -> Vec<smear::StyleError> {
    use smear::StyleError as E;
    let mut v = vec![
        E::Expression {
            expr: "beta_max * (delta".into(),
            problem: "unclosed parenthesis".into(),
        },
        E::UnknownVariable {
            expr: "beta * delta".into(),
            name: "beta".into(),
            known: "delta, speed, weight".into(),
        },
        E::ExprAndStages,
        E::Syntax("line 3, key 'elongate.stpe': unknown field".into()),
        E::NotFinite {
            expr: "sqrt(x)".into(),
            frame: 12,
            item: "vertex",
            index: 3071,
        },
    ];
    // Parameter: through the validation a user really hits, with extreme values.
    for (p, lo, hi) in [
        (smear::Param::Constant(f32::NAN), f32::MIN, f32::MAX),
        (smear::Param::Constant(1e8), 0.0, 1e7),
        (smear::Param::Constant(-1.0), 0.0, f32::MAX),
        (smear::Param::Constant(2.0), f32::MIN, 1.0),
        (smear::Param::Constant(f32::MAX), 0.0, 1.0),
    ] {
        v.push(
            p.validate("beta_max", (lo, false), (hi, false))
                .unwrap_err(),
        );
    }
    v
}

fn smear_errors() -> Vec<smear::SmearError> {
    use smear::SmearError as E;
    let mut v = vec![
        E::UnknownJoint {
            name: "Hand".into(),
            available: "Hips, Spine".into(),
        },
        E::PruneWithoutAncestor {
            name: "Hips".into(),
        },
        E::UnknownAttribute {
            name: "_W".into(),
            available: "_WEIGHT".into(),
        },
        E::UnknownCamera {
            name: "cam".into(),
            available: "Camera".into(),
        },
        E::UnknownObject { index: 5, count: 2 },
        E::InvalidSurfacePoint {
            index: 4,
            reason: "barycentric coordinates must be finite, ≥ 0, not all 0".into(),
        },
        E::FrameMismatch {
            expected: 48,
            found: 24,
        },
        E::LengthMismatch {
            expected: 157104,
            found: 3,
        },
        E::InvalidParameter {
            name: "line count",
            reason: "must be a number of lines ≥ 0".into(),
        },
        E::InvalidScene("object 'body' has 0 frames".into()),
    ];
    v.extend(style_errors().into_iter().map(E::Style));
    v
}

fn loa_errors() -> Vec<loa::LoaError> {
    use loa::{LoaError as E, StrokeError as S};
    let strokes = [
        S::TooFewPoints { points: 1 },
        S::NonFinite { sample: 3 },
        S::Collapsed { extent: 1e-12 },
    ];
    let mut v: Vec<E> = strokes
        .into_iter()
        .map(|source| E::Stroke {
            keystroke: 2,
            frame: 24,
            source,
        })
        .collect();
    v.extend([
        E::TooShort {
            keystroke: 1,
            frame: 12,
            length: 0.001,
            longest: 340.0,
        },
        E::FrameOrder {
            keystroke: 3,
            frame: 10,
            previous: 12,
        },
        E::NoKeystrokes,
        E::InvalidParameter {
            name: "stiffness",
            value: f64::from(f32::MAX),
            expected: "a number in [5, 100]",
        },
        E::InvalidParameter {
            name: "damping",
            value: f64::NAN,
            expected: "a number in [0.05, 0.5]",
        },
        E::OutOfRange {
            name: "stiffness",
            value: 540.0,
            min: 5.0,
            max: 100.0,
            keystroke: 1,
            frame: 12,
        },
        E::Json("line 1 column 2: expected value".into()),
        E::Xml("unexpected end of file".into()),
        E::SvgElement {
            element: 4,
            tag: "path".into(),
            message: "no data-frame attribute".into(),
        },
        E::Wobble("20:2".into()),
    ]);
    v
}

fn animate_errors() -> Vec<loa::animate::AnimateError> {
    use loa::animate::AnimateError as E;
    vec![
        E::EmptySkeleton,
        E::PoseLength {
            expected: 20,
            found: 3,
        },
        E::BadHierarchy("Spine".into()),
        E::NonFinitePose("Head".into()),
        E::UnknownPreset("leg".into()),
        E::PresetJoint {
            role: "spine",
            joints: "Root, Tail".into(),
        },
        E::UnknownJoint {
            name: "Hand".into(),
            joints: "Hips, Spine".into(),
        },
        E::EmptyBoneSet,
        E::BadFrame {
            what: "contact",
            frame: 99,
            expected: "the line has frames 0 to 47".into(),
        },
        E::PlaneNormal([0.0, f64::NAN, 0.0]),
        E::EmptyLine,
        E::BadPose {
            pose: "frame:x".into(),
            expected: "rest, or frame:N".into(),
        },
        E::UnknownCamera {
            name: "cam".into(),
            cameras: "Camera".into(),
        },
        E::Scene {
            source: anim_errors().remove(3),
        },
        E::InvalidParameter {
            name: "iterations",
            value: 1e300,
            expected: "a number from 1 to 1000",
        },
    ]
}

fn stopmo_errors() -> Vec<stopmo::Error> {
    use stopmo::library::LibraryError as L;
    use stopmo::segment::SegmentError as S;
    let segment = [
        S::NoTriangles,
        S::TooFewParts(1),
        S::EmptyPart("upper".into()),
        S::SeedOutOfRange {
            part: "upper".into(),
            index: u32::MAX,
            triangles: 18460,
        },
        S::NonFiniteSeed("lower".into()),
        S::ConflictingSeeds {
            triangle: 7,
            first: "upper".into(),
            second: "lower".into(),
        },
        S::BadLabel {
            triangle: 3,
            part: 9,
            parts: 2,
        },
        S::LabelCount {
            expected: 18460,
            found: 3,
        },
        S::Invalid("frames differ in vertex count".into()),
        S::Parameter("gamma must be > 0".into()),
        S::Solver("not positive definite".into()),
    ];
    let library = [
        L::NoParts,
        L::EmptyPart {
            part: "upper".into(),
        },
        L::FrameCountMismatch {
            part: "lower".into(),
            expected: 120,
            found: 60,
        },
        L::ZeroPieces,
        L::TooManyPieces {
            part: "upper".into(),
            pieces: 500,
            frames: 120,
        },
        L::BudgetTooSmall {
            budget: 1,
            minimum: 2,
        },
        L::InvalidParameter("lambda must be ≥ 0".into()),
        L::BadSaliency {
            part: "upper".into(),
            reason: "all zero".into(),
        },
        L::BadFixedPiece {
            part: "upper".into(),
            piece: 2,
            reason: "3 vertices, the part has 9000".into(),
        },
        L::BadCut {
            cut: 500,
            frames: 120,
        },
        L::BadSurface {
            mesh: "upper_03".into(),
            reason: "edge 4-5 has 3 faces".into(),
        },
        L::Numerical("the Potts solve".into()),
    ];
    let mut v: Vec<stopmo::Error> = segment.into_iter().map(stopmo::Error::from).collect();
    v.extend(library.into_iter().map(stopmo::Error::from));
    v.extend(render_errors().into_iter().map(stopmo::Error::from));
    v.extend(anim_errors().into_iter().map(stopmo::Error::from));
    v
}

/// Checks one message and returns it (for the count).
fn check(crate_name: &str, e: &dyn std::error::Error) -> String {
    let m = e.to_string();
    assert!(!m.is_empty(), "{crate_name}: empty message");
    assert!(!m.contains('\n'), "{crate_name}: two lines: {m:?}");
    assert_readable(&m);
    // A source is never repeated by its wrapper.
    if let Some(source) = e.source() {
        let s = source.to_string();
        assert!(
            !m.contains(&format!("{s}: {s}")),
            "{crate_name}: {m:?} repeats {s:?}"
        );
    }
    m
}

#[test]
fn every_error_variant_of_every_crate_reads_well() {
    let mut n = 0;
    for e in anim_errors() {
        check("anim", &e);
        n += 1;
    }
    for e in io_errors() {
        let m = check("io", &e);
        assert!(
            m.starts_with("/tmp/out/walk."),
            "io: the file comes first: {m}"
        );
        n += 1;
    }
    for e in render_errors() {
        check("render", &e);
        n += 1;
    }
    for e in smear_errors() {
        check("smear", &e);
        n += 1;
    }
    for e in loa_errors() {
        check("loa", &e);
        n += 1;
    }
    for e in animate_errors() {
        check("loa::animate", &e);
        n += 1;
    }
    for e in stopmo_errors() {
        check("stopmo", &e);
        n += 1;
    }
    assert!(n >= 100, "{n} messages");
}

#[test]
fn os_errors_are_said_in_the_users_terms_with_the_fix() {
    let p = Path::new("out.glb");
    for (code, want) in [
        (2, "out.glb: no such file or directory (check the path)"),
        (13, "out.glb: permission denied"),
        (21, "out.glb: is a directory: name a file"),
        (
            28,
            "out.glb: no space left on the device: free some space and run again",
        ),
        (
            30,
            "out.glb: the file system is read-only: write somewhere else",
        ),
        (27, "out.glb: the file is larger than this system allows"),
    ] {
        let m = tkio::IoError::io(p, std::io::Error::from_raw_os_error(code)).to_string();
        assert!(m.starts_with(want), "errno {code}: {m}");
        assert!(!m.contains("os error"), "{m}");
    }
}

#[test]
fn numbers_in_parameter_messages_are_short() {
    let e = smear::Param::Constant(f32::NAN)
        .validate_finite("stages[0].by")
        .unwrap_err()
        .to_string();
    assert!(e.contains("NaN is not a finite number"), "{e}");
    let e = smear::Param::Constant(1e8)
        .validate("count", (0.0, false), (1e7, false))
        .unwrap_err()
        .to_string();
    assert!(e.contains("1e8 is not in [0, 1e7]"), "{e}");
    let e = render::RenderError::InvalidFps(f32::MAX).to_string();
    assert!(e.contains("3.4028235e38"), "{e}");
}
