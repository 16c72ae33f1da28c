//! The whole smear job on a real character: `prepare` once, `stylize` many times. A second
//! `stylize` with another style reuses the prepared offsets (no solve; `benches/restyle.rs`
//! measures the cost), and the merged job gives the offsets of the per-object solve. A frame range
//! (`stylize_frames`, the studio's current frame first) gives those frames of the whole clip.

mod common;

use anim::{sample, SampleOptions, SampledScene};
use smear::{prepare, stylize, stylize_frames, OffsetOptions, PrepareOptions, Style};

fn robot_dance() -> SampledScene {
    let path = common::asset("characters/RobotExpressive.glb");
    let scene = tkio::gltf::read(&path).unwrap();
    let clip = scene.find_clip("Dance").unwrap();
    sample(
        &scene,
        &SampleOptions {
            clip: Some(clip),
            ..SampleOptions::default()
        },
    )
    .unwrap()
}

fn example_style(name: &str) -> Style {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/smear")
        .join(name);
    Style::from_toml_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

#[test]
fn second_stylize_reuses_prepared_offsets() {
    let scene = robot_dance();
    // Live tuning: the animator drags the elongation strength from 1.53 to 0.75 (paper
    // Fig. 11c, in sizes per second).
    let first_style = example_style("fig11c_speed.toml");
    let second_style = Style::from_toml_str(
        "[elongate]\nfunction = { stages = [{ op = \"speed\" }, { op = \"scale\", by = 0.75 }] }",
    )
    .unwrap();
    assert_ne!(first_style, second_style);
    let options = PrepareOptions {
        offsets: first_style.offsets.clone(),
        ..PrepareOptions::default()
    };

    let prepared = prepare(scene, &options).unwrap();
    let solves = smear::offset_solves();
    let a = stylize(&prepared, &first_style).unwrap();
    let b = stylize(&prepared, &second_style).unwrap();

    // Structural: stylize never solved offsets, and says so.
    assert_eq!(
        smear::offset_solves(),
        solves,
        "stylize solved offsets again"
    );
    assert_eq!((a.report.offset_solves, b.report.offset_solves), (0, 0));
    // The second style is really another style on the same prepared offsets.
    let objects = prepared.object_count();
    assert!(objects > 1, "RobotExpressive has several meshes");
    assert_eq!(a.flipbook.parts.len(), objects);
    assert_eq!(b.flipbook.parts.len(), objects);
    let max = |s: &smear::Stylized| {
        s.report
            .objects
            .iter()
            .map(|o| o.elongation_max.unwrap())
            .fold(0.0f32, f32::max)
    };
    // Half the strength, less stretch.
    assert!(max(&a) > 0.0);
    assert!(max(&b) < max(&a), "{} vs {}", max(&b), max(&a));
    // What restyling costs against preparing is measured by `benches/restyle.rs`.
}

#[test]
fn merged_prepare_matches_per_object_offsets() {
    let scene = robot_dance();
    let per_object = smear::scene_offsets(&scene, &OffsetOptions::default()).unwrap();
    let expected = smear::MotionOffsets::concat(&per_object).unwrap();
    let offsets = smear::offsets(&scene, &OffsetOptions::default()).unwrap();
    assert_eq!(offsets.offsets, expected);
    assert_eq!(offsets.report.objects.len(), scene.objects.len());
    let (lo, hi) = expected.range();
    assert_eq!(offsets.report.range, (lo, hi));

    let merged = prepare(
        scene.clone(),
        &PrepareOptions {
            merge: Some("robot".into()),
            ..PrepareOptions::default()
        },
    )
    .unwrap();
    assert_eq!(merged.object_count(), 1);
    assert_eq!(merged.offsets(0), &expected);
    assert_eq!(merged.animation(0).vertex_count(), scene.vertex_count());
    assert_eq!(merged.animation(0).mesh.name, "robot");
    // A style with other offset options is refused rather than silently ignored.
    let other = Style {
        offsets: OffsetOptions {
            smooth: 0,
            ..OffsetOptions::default()
        },
        ..Style::default()
    };
    assert!(stylize(&merged, &other).is_err());
}

/// Frame `f` of every part of a stylized flipbook: positions and colours.
fn part_frame(part: &anim::FlipbookPart, f: usize) -> (Vec<anim::glam::Vec3>, Vec<[f32; 4]>) {
    match part {
        anim::FlipbookPart::Animation { animation, colors } => {
            let n = animation.vertex_count();
            let c = colors
                .as_ref()
                .map_or(Vec::new(), |c| c[f * n..(f + 1) * n].to_vec());
            (animation.frame(f).to_vec(), c)
        }
        anim::FlipbookPart::Frames { meshes, .. } => (
            meshes[f].positions.clone(),
            meshes[f].colors.clone().unwrap_or_default(),
        ),
    }
}

#[test]
fn stylize_frames_gives_those_frames_of_the_clip() {
    // All three effects (SMEAR Fig. 16): elongation, multiples, motion lines.
    let style = example_style("fig16_combined.toml");
    let options = PrepareOptions {
        offsets: style.offsets.clone(),
        ..PrepareOptions::default()
    };
    let prepared = prepare(robot_dance(), &options).unwrap();
    let whole = stylize(&prepared, &style).unwrap();
    let frames = prepared.report().frames;
    assert_eq!(whole.first_frame, 0);
    let mut lines_seen = 0;
    for range in [40..41, 0..1, frames - 3..frames] {
        let part = stylize_frames(&prepared, &style, range.clone()).unwrap();
        assert_eq!(part.first_frame, range.start);
        assert_eq!(part.flipbook.frames, range.len());
        assert_eq!(part.flipbook.parts.len(), whole.flipbook.parts.len());
        assert_eq!(part.objects, whole.objects);
        for (a, b) in part.flipbook.parts.iter().zip(&whole.flipbook.parts) {
            for (k, f) in range.clone().enumerate() {
                let (pa, ca) = part_frame(a, k);
                let (pb, cb) = part_frame(b, f);
                assert_eq!(pa.len(), pb.len(), "{} frame {f}", a.name());
                for (p, q) in pa.iter().zip(&pb) {
                    assert!(p.distance(*q) < 1e-5, "{} frame {f}: {p} vs {q}", a.name());
                }
                assert_eq!(ca, cb, "{} frame {f} colours", a.name());
                if matches!(a, anim::FlipbookPart::Frames { .. }) {
                    lines_seen += pa.len();
                }
            }
        }
    }
    assert!(
        lines_seen > 0,
        "no motion line drawn in the frames compared"
    );
    for bad in [5..5, frames..frames + 1, 0..frames + 1] {
        let e = stylize_frames(&prepared, &style, bad.clone()).unwrap_err();
        assert!(e.to_string().contains("frames"), "{bad:?}: {e}");
    }
}
