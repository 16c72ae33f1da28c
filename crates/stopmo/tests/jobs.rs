//! The whole jobs `stopmo::{segment, library, run}` on a synthetic talking tube and on the
//! ICT face (sampled at 1 fps: 60 frames, cheap): options from serde, results, reports and
//! the output layout.

mod common;
mod segment_support;

use anim::MeshAnimation;
use glam::Vec3;
use segment_support::talking_tube;
use stopmo::segment::{PartSpec, Seed};
use stopmo::{FileData, LibraryJobOptions, PieceCount, RunOptions, SegmentJobOptions};

fn tube_parts() -> Vec<PartSpec> {
    vec![
        PartSpec::new("upper", vec![Seed::Point(Vec3::new(0.0, 0.95, 1.0))]),
        PartSpec::new("lower", vec![Seed::Point(Vec3::new(0.0, -0.95, 1.0))]),
    ]
}

#[test]
fn segment_then_library_on_a_tube_gives_the_spec_layout() {
    let anim = talking_tube(24, 30, 36);
    let seg = stopmo::segment(
        &anim,
        &SegmentJobOptions {
            parts: tube_parts(),
            figure: true,
            ..Default::default()
        },
    )
    .unwrap();
    let names: Vec<&str> = seg.parts.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["upper", "lower"]);
    let summary = seg.summary();
    assert_eq!(summary.frames, 36);
    assert!(
        summary.seam_vertices > 10 && summary.cut_length > 1.0,
        "{summary:?}"
    );
    let png = render::decode_png(seg.figure.as_ref().unwrap()).unwrap();
    assert!(
        png.width() > png.height(),
        "Fig. 5 has two panels side by side"
    );
    let report: serde_json::Value = serde_json::from_str(&seg.report_json()).unwrap();
    assert_eq!(report["parts"], serde_json::json!(["upper", "lower"]));

    let parts: Vec<MeshAnimation> = seg.parts.iter().map(|p| p.animation.clone()).collect();
    let opts = LibraryJobOptions {
        pieces: PieceCount::PerPart([("upper".into(), 3), ("lower".into(), 5)].into()),
        ..Default::default()
    };
    let lib = stopmo::library(&parts, &opts).unwrap();
    assert_eq!(lib.pieces.len(), 8);
    assert_eq!(lib.report.pieces, 8);
    assert_eq!(lib.labels().len(), 2);
    assert!(lib.labels().iter().all(|l| l.len() == 36));
    // Every piece is a closed solid in millimetres and a surface in model units.
    for p in &lib.pieces {
        let check = stopmo::library::check_solid(p.solid.as_ref().expect("a solid"));
        assert!(check.is_closed_manifold(), "{}: {check:?}", p.id);
        assert_eq!(p.surface.vertex_count(), parts[p.part].vertex_count());
    }
    // The reconstruction shows each frame's piece.
    for part in 0..lib.reconstruction.len() {
        let recon = lib.reconstruction_of(part).expect("a reconstruction");
        let sol = &lib.library.parts[part].solution;
        for f in [0, 17, 35] {
            assert_eq!(recon.frame(f), &sol.pieces[sol.labels[f] as usize][..]);
        }
    }
    // The report's errors are the library's, in mm at the default print height.
    assert_eq!(lib.report.errors_mm, lib.library.errors_mm);
    assert!(lib.report.errors_mm.position_mean > 0.0);
    assert!(lib.report.errors_mm.position_mean < lib.report.errors_mm.position_max);
    // The output layout.
    let files = lib.files().unwrap();
    let paths: Vec<&str> = files.iter().map(|f| f.path.as_str()).collect();
    for want in [
        "pieces/upper_00.obj",
        "pieces/upper_02.stl",
        "pieces/lower_04.stl",
        "assembly.csv",
        "assembly.md",
        "shooting_order.csv",
        "report.json",
        "reconstruction.glb",
        "reconstruction.pc2",
        "rest.obj",
    ] {
        assert!(paths.contains(&want), "no {want} in {paths:?}");
    }
    assert!(
        !paths.iter().any(|p| p.starts_with("error_curve")),
        "no size search ran"
    );
    assert!(
        !paths.iter().any(|p| p.starts_with("segmentation")),
        "library only"
    );
    let csv = lib.assembly_csv();
    assert_eq!(csv.lines().count(), 37);
    assert!(csv.starts_with("frame,upper,lower\n0,upper_"));
    let order = lib.shooting_order_csv();
    assert!(order.starts_with("shot,upper,lower,frames\n"));
    assert_eq!(order.lines().count(), lib.shooting_order.shots.len() + 1);
    let report: serde_json::Value = serde_json::from_str(&lib.report.to_json()).unwrap();
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
        assert!(!report[key].is_null(), "report.json lacks {key}");
    }
    assert!(
        report.get("input").is_none(),
        "no input file in a library call"
    );
    match &files
        .iter()
        .find(|f| f.path == "reconstruction.pc2")
        .unwrap()
        .data
    {
        FileData::Shapes { parts: shown, rest } => {
            assert!(shown.iter().all(|s| s.shown.len() == 36));
            assert_eq!(
                rest.vertex_count(),
                parts.iter().map(|p| p.vertex_count()).sum::<usize>()
            );
        }
        other => panic!("reconstruction.pc2 holds {other:?}"),
    }

    // Without printing: the same library, labels and surfaces, no solids, backs, `.stl` or
    // "printing" report.
    let quick = stopmo::library(
        &parts,
        &LibraryJobOptions {
            print: false,
            ..opts.clone()
        },
    )
    .unwrap();
    assert_eq!(quick.labels(), lib.labels());
    assert_eq!(quick.report.energy, lib.report.energy);
    assert_eq!(quick.report.errors_mm, lib.report.errors_mm);
    assert_eq!(quick.pieces.len(), 8);
    for (q, p) in quick.pieces.iter().zip(&lib.pieces) {
        assert_eq!((&q.id, &q.surface), (&p.id, &p.surface));
        assert!(q.solid.is_none(), "{} has a solid", q.id);
    }
    assert!(quick.backs.is_empty() && quick.report.printing.is_none());
    let files = quick.files().unwrap();
    assert!(files.iter().all(|f| !f.path.ends_with(".stl")));
    assert!(files.iter().any(|f| f.path == "pieces/lower_04.obj"));
    let report: serde_json::Value = serde_json::from_str(&quick.report.to_json()).unwrap();
    assert!(report["printing"].is_null(), "{}", report["printing"]);
}

#[test]
fn options_come_from_json_and_bad_options_name_themselves() {
    let opts: RunOptions = serde_json::from_str(
        r#"{
            "segment": {"parts": [
                {"name": "upper", "seeds": [{"Point": [0.0, 0.95, 1.0]}]},
                {"name": "lower", "seeds": [{"Point": [0.0, -0.95, 1.0]}]}
            ], "gamma": 1000.0},
            "library": {"pieces": {"each": 4}, "lambda": 1.5, "restarts": 2}
        }"#,
    )
    .unwrap();
    assert_eq!(opts.segment.segment.gamma, 1000.0);
    assert_eq!(opts.library.solve.lambda, 1.5);
    assert_eq!(opts.library.pieces, PieceCount::Each(4));
    assert_eq!(
        opts.library.thickness_mm,
        stopmo::library::DEFAULT_THICKNESS_MM
    );
    let anim = talking_tube(16, 20, 24);
    let result = stopmo::run(&anim, &opts).unwrap();
    assert_eq!(result.pieces.len(), 8);
    assert_eq!(result.report.lambda, 1.5);
    let paths: Vec<String> = result
        .files()
        .unwrap()
        .into_iter()
        .map(|f| f.path)
        .collect();
    assert!(paths.iter().any(|p| p == "segmentation.glb"));
    assert!(paths.iter().any(|p| p == "segmentation.json"));
    assert!(
        !paths.iter().any(|p| p == "segmentation.png"),
        "no figure asked for"
    );

    let parts: Vec<MeshAnimation> = result
        .segmented
        .as_ref()
        .unwrap()
        .parts
        .iter()
        .map(|p| p.animation.clone())
        .collect();
    let bad = |o: LibraryJobOptions| stopmo::library(&parts, &o).unwrap_err();
    let e = bad(LibraryJobOptions {
        saliency: Some(vec![1.0; 3]),
        ..Default::default()
    });
    assert_eq!(e.option(), Some("saliency"), "{e}");
    let e = bad(LibraryJobOptions {
        pieces: PieceCount::PerPart([("nose".into(), 3)].into()),
        ..Default::default()
    });
    assert_eq!(e.option(), Some("pieces"));
    assert!(e.to_string().contains("nose"), "{e}");
    let e = bad(LibraryJobOptions {
        pieces: PieceCount::MaxErrorMm(-1.0),
        ..Default::default()
    });
    assert_eq!(e.option(), Some("max_error_mm"));
    let e = stopmo::segment(&anim, &SegmentJobOptions::default()).unwrap_err();
    assert!(e.to_string().contains("two parts"), "{e}");
    // Stage errors keep their source chain.
    let e = bad(LibraryJobOptions {
        pieces: PieceCount::Each(0),
        ..Default::default()
    });
    assert!(matches!(e, stopmo::Error::Library(_)), "{e:?}");
}

#[test]
fn face_run_equals_segment_then_library_and_searches_a_size() {
    let anim = common::face(1.0);
    assert_eq!(anim.frame_count(), 60);
    let opts = RunOptions {
        segment: SegmentJobOptions {
            parts: vec![
                PartSpec::new("upper", vec![Seed::Point(Vec3::new(0.0, 10.0, 13.0))]),
                PartSpec::new("lower", vec![Seed::Point(Vec3::new(0.0, -14.0, 10.0))]),
            ],
            ..Default::default()
        },
        library: LibraryJobOptions {
            pieces: PieceCount::MaxErrorMm(0.3),
            solve: stopmo::library::SolveOptions {
                restarts: 2,
                ..Default::default()
            },
            // Labels, energies and the size search are the subject, not the solids.
            print: false,
            ..Default::default()
        },
    };
    let run = stopmo::run(&anim, &opts).unwrap();
    let seg = stopmo::segment(&anim, &opts.segment).unwrap();
    let parts: Vec<MeshAnimation> = seg.parts.iter().map(|p| p.animation.clone()).collect();
    let lib = stopmo::library(&parts, &opts.library).unwrap();
    assert_eq!(run.labels(), lib.labels(), "run = segment + library");
    assert_eq!(run.report.pieces, lib.report.pieces);
    assert_eq!(run.report.energy, lib.report.energy);
    // A size search ran: every part has a curve, and the chosen size meets the bound.
    assert!(run.has_curve());
    for p in &run.library.parts {
        let chosen = p
            .curve
            .iter()
            .find(|c| c.pieces == p.solution.pieces.len())
            .expect("chosen size on the curve");
        assert!(chosen.worst_frame_error * run.library.mm_per_unit <= 0.3);
    }
    let csv = run.error_curve_csv().unwrap();
    assert!(csv.starts_with("part,pieces,energy,worst_frame_error_mm,mean_error_mm\n"));
    let png = render::decode_png(&run.error_curve_png().unwrap().unwrap()).unwrap();
    assert_eq!((png.width(), png.height()), (720, 420));
    assert!(
        run.report.errors_mm.position_max < 5.0,
        "{:?}",
        run.report.errors_mm
    );
}

/// A clip handed over to the job (its frames grown into the cut's in place) segments exactly
/// as a borrowed one: the same cut animation, parts and reports, bit for bit, with fresh seeds
/// and when reusing a saved cut; with the cut's frames moved into the parts, the same parts.
#[test]
fn face_handed_over_segments_bit_for_bit_as_borrowed() {
    let anim = common::face(1.0);
    let opts = SegmentJobOptions {
        parts: vec![
            PartSpec::new("upper", vec![Seed::Point(Vec3::new(0.0, 10.0, 13.0))]),
            PartSpec::new("lower", vec![Seed::Point(Vec3::new(0.0, -14.0, 10.0))]),
        ],
        ..Default::default()
    };
    let borrowed = stopmo::segment(&anim, &opts).unwrap();
    let reuse = SegmentJobOptions {
        reuse: Some(borrowed.saved.clone()),
        ..Default::default()
    };
    for (opts, expected) in [
        (&opts, borrowed.clone()),
        (&reuse, stopmo::segment(&anim, &reuse).unwrap()),
    ] {
        let owned = stopmo::segment_owned(anim.clone(), opts).unwrap();
        let (a, b) = (
            &owned.segmentation.animation,
            &expected.segmentation.animation,
        );
        assert!(
            a.vertex_count() > anim.vertex_count(),
            "the cut adds vertices"
        );
        assert_eq!(a.positions(), b.positions());
        assert_eq!(a.mesh.positions, b.mesh.positions);
        assert_eq!(a.mesh.normals, b.mesh.normals);
        assert_eq!(
            untimed(&owned.report_json()),
            untimed(&expected.report_json())
        );
        assert_eq!(owned.parts.len(), expected.parts.len());
        for (p, q) in owned.parts.iter().zip(&expected.parts) {
            assert_eq!(p.vertices, q.vertices);
            assert_eq!(p.animation.positions(), q.animation.positions());
        }
        // Keeping only the parts: the cut's frames moved into them, the same parts and
        // report (the summary still counts every frame).
        let taken = stopmo::segment_into_parts(anim.clone(), opts).unwrap();
        assert_eq!(taken.segmentation.animation.frame_count(), 1);
        let (a, b) = (taken.summary(), expected.summary());
        assert_eq!((a.parts, a.frames), (b.parts, b.frames));
        assert_eq!(
            untimed(&taken.report_json()),
            untimed(&expected.report_json())
        );
        assert_eq!(taken.parts.len(), expected.parts.len());
        for (p, q) in taken.parts.iter().zip(&expected.parts) {
            assert_eq!(p.vertices, q.vertices);
            assert_eq!(p.animation.mesh.triangles, q.animation.mesh.triangles);
            assert_eq!(p.animation.fps, q.animation.fps);
            assert_eq!(p.animation.positions(), q.animation.positions());
        }
    }
}

/// A report without its timings (`*seconds`), which differ from run to run.
fn untimed(report: &str) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(map) => {
                map.retain(|k, _| !k.ends_with("seconds"));
                map.values_mut().for_each(strip);
            }
            serde_json::Value::Array(items) => items.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut v: serde_json::Value = serde_json::from_str(report).unwrap();
    strip(&mut v);
    v
}

/// A part whose own animated surface presses through itself (as lips can at a mouth corner
/// inside one part): the report counts it apart from the back's crossings, the warning
/// says what to do, and the written solids are regularized.
#[test]
fn a_surface_that_presses_through_itself_is_reported_with_advice() {
    let rest = segment_support::tube(16, 12);
    let frames = 6;
    // The middle rows' cross-section flattens, then inverts (z scaled 1 → −0.6): the front and
    // back walls pass through each other between the inverted and the untouched rows.
    let pos: Vec<Vec3> = (0..frames)
        .flat_map(|f| {
            let s = 1.0 - 1.6 * f as f32 / (frames - 1) as f32;
            rest.positions.iter().map(move |&p| {
                let band = (1.0 - (p.y / 0.5).abs()).clamp(0.0, 1.0);
                let k = 1.0 + (s - 1.0) * band;
                Vec3::new(p.x, p.y, p.z * k)
            })
        })
        .collect();
    let anim = MeshAnimation::new(rest, 30.0, pos).unwrap();
    let three_pieces = |a: &MeshAnimation| {
        let options = LibraryJobOptions {
            pieces: PieceCount::Each(3),
            ..Default::default()
        };
        stopmo::library(std::slice::from_ref(a), &options).unwrap()
    };
    let lib = three_pieces(&anim);
    let part = &lib.report.printing.as_ref().expect("printed").parts[0];
    assert!(
        part.surface_self_intersecting_triangles > 0,
        "{:?}",
        lib.report.warnings
    );
    assert!(
        lib.report
            .warnings
            .iter()
            .any(|w| w.contains("the animated surface itself crosses")
                && w.contains("a seam runs between the touching surfaces")),
        "{:?}",
        lib.report.warnings
    );
    // What is written is regularized: the pieces that crossed are named, and none of the
    // written solids crosses itself any more (closed, one shell).
    assert!(part.built_self_intersecting_triangles > 0, "{part:?}");
    assert!(!part.regularized_pieces.is_empty(), "{part:?}");
    assert_eq!(part.shell.self_intersecting_triangles, 0, "{part:?}");
    for piece in &lib.pieces {
        let solid = piece.solid.as_ref().expect("solid");
        let crossing =
            stopmo::library::self_intersecting_triangles(&solid.positions, &solid.triangles)
                .expect("coordinates in range");
        assert!(
            crossing.is_empty(),
            "{}: {} crossing",
            piece.id,
            crossing.len()
        );
        assert!(
            stopmo::library::check_solid(solid).is_closed_manifold(),
            "{}",
            piece.id
        );
        assert_eq!(stopmo::library::components(solid).len(), 1, "{}", piece.id);
    }
    assert!(lib
        .report
        .warnings
        .iter()
        .any(|w| w.contains("regularized to the material it encloses")));
    // An untouched tube reports none.
    let lib = three_pieces(&segment_support::talking_tube(16, 12, 6));
    assert_eq!(
        lib.report.printing.as_ref().expect("printed").parts[0].surface_self_intersecting_triangles,
        0
    );
}

#[test]
fn a_pieces_folder_gives_each_part_its_pieces_and_back_by_name() {
    let names = vec!["upper".to_string(), "upper_lip".to_string()];
    let mesh = |x: f32| anim::Mesh {
        positions: vec![Vec3::splat(x)],
        ..anim::Mesh::default()
    };
    let files = vec![
        ("upper_01".to_string(), mesh(1.0)),
        ("upper_02".to_string(), mesh(2.0)),
        ("upper_back".to_string(), mesh(3.0)),
        ("upper_lip_01".to_string(), mesh(4.0)),
        ("upper_x1".to_string(), mesh(5.0)),
    ];
    assert!(stopmo::is_library_piece("upper_lip_01", &names));
    assert!(!stopmo::is_library_piece("upper_x1", &names));
    assert!(!stopmo::is_library_piece("lower_01", &names));
    let (fixed, backs) = stopmo::library_pieces(&names, files);
    assert_eq!(fixed["upper"].len(), 2);
    assert_eq!(fixed["upper_lip"], vec![vec![Vec3::splat(4.0)]]);
    assert_eq!(backs["upper"], vec![Vec3::splat(3.0)]);
    assert!(!backs.contains_key("upper_lip"));
}

/// A clip cut into shots (each frame's piece IDs, StopShop Sec. 4, read on set shot by
/// shot): one assembly sheet per shot, numbered in shot order, each showing only its own
/// shot's faces (the shots are made in parallel and listed in order).
#[test]
fn each_shot_has_its_assembly_sheet_in_order() {
    let anim = talking_tube(24, 30, 36);
    let parts: Vec<MeshAnimation> = stopmo::segment(
        &anim,
        &SegmentJobOptions {
            parts: tube_parts(),
            ..Default::default()
        },
    )
    .unwrap()
    .parts
    .iter()
    .map(|p| p.animation.clone())
    .collect();
    let opts = LibraryJobOptions {
        pieces: PieceCount::Each(4),
        cuts: vec![2, 30],
        print: false,
        ..Default::default()
    };
    let lib = stopmo::library(&parts, &opts).unwrap();
    let names: Vec<&str> = lib.sheets.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "assembly_shot01.png",
            "assembly_shot02.png",
            "assembly_shot03.png"
        ]
    );
    // Each sheet has a cell per run of equal assemblies in its shot, 12 to a row: a sheet is
    // as tall as its own shot's rows say.
    let labels = lib.labels();
    let rows_of = |shot: std::ops::Range<usize>| {
        shot.clone()
            .filter(|&f| f == shot.start || labels.iter().any(|l| l[f] != l[f - 1]))
            .count()
            .div_ceil(12)
    };
    let rows = [rows_of(0..2), rows_of(2..30), rows_of(30..36)];
    // The long middle shot needs more rows: a sheet given to the wrong shot shows here.
    assert!(rows[1] > rows[0] && rows[1] > rows[2], "{rows:?}");
    let heights: Vec<u32> = lib
        .sheets
        .iter()
        .map(|(_, png)| render::decode_png(png).unwrap().height())
        .collect();
    for i in 0..3 {
        for j in 0..3 {
            assert_eq!(
                rows[i].cmp(&rows[j]),
                heights[i].cmp(&heights[j]),
                "rows {rows:?}, heights {heights:?}"
            );
        }
    }
}
