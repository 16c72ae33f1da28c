//! `--causal` and the streaming API: frame f never reads a later frame.

use anim::MeshAnimation;
use glam::Vec3;
use smear::{
    stylize, ContactStyle, FunctionSpec, MultiplesStyle, Param, Stream, StreamOptions, Style,
};

use super::{elongation, legged, part_frames, prepared};

/// The clip with every frame after `f` replaced by a different motion.
fn altered_after(anim: &MeshAnimation, f: usize) -> MeshAnimation {
    let n = anim.vertex_count();
    let mut p = anim.positions().to_vec();
    for (k, q) in p.iter_mut().enumerate().skip((f + 1) * n) {
        let g = (k / n) as f32;
        *q = *q * 1.3 + Vec3::new(-0.4 * g, 0.2 * (g * 1.7).sin(), 0.1 * g);
    }
    MeshAnimation::new(anim.mesh.clone(), anim.fps, p).unwrap()
}

fn styled(anim: &MeshAnimation, causal: bool, revolve: bool) -> Vec<Vec<Vec<Vec3>>> {
    let p = prepared(anim, |o| {
        o.offsets.causal = causal;
        if revolve {
            o.offsets.revolve = vec!["critter".into()];
        }
    });
    let style = Style {
        multiples: Some(MultiplesStyle {
            past: Param::Constant(2.0),
            future: Param::Constant(1.0),
            ..MultiplesStyle::default()
        }),
        contact: Some(ContactStyle::default()),
        ..elongation(&p, 2.0)
    };
    let out = stylize(&p, &style).unwrap();
    out.flipbook.parts.iter().map(part_frames).collect()
}

#[test]
fn causal_frames_do_not_depend_on_later_frames() {
    let walk = legged::gait(24, 0.2, 0.25);
    for f in [0, 5, 12, 22] {
        let other = altered_after(&walk, f);
        for revolve in [false, true] {
            let (a, b) = (styled(&walk, true, revolve), styled(&other, true, revolve));
            for (part_a, part_b) in a.iter().zip(&b) {
                assert_eq!(part_a[f], part_b[f], "frame {f}, revolve {revolve}");
            }
        }
        // Offline, the smear at f looks ahead (sanity check of the alteration).
        if f < 22 {
            let (a, b) = (styled(&walk, false, false), styled(&other, false, false));
            assert_ne!(a[0][f], b[0][f], "offline frame {f} ignored the future");
        }
    }
}

#[test]
fn the_stream_matches_the_causal_mode() {
    let walk = legged::gait(20, 0.2, 0.25);
    let p = prepared(&walk, |o| o.offsets.causal = true);
    let offline = stylize(&p, &elongation(&p, 1.0)).unwrap();
    let body = offline.animation(0).unwrap();
    let mut stream = Stream::new(&walk.mesh, &StreamOptions::default()).unwrap();
    for f in 0..walk.frame_count() {
        let out = stream.push(walk.frame(f)).unwrap();
        for (k, (s, o)) in out.iter().zip(body.frame(f)).enumerate() {
            assert!(s.distance(*o) < 1e-4, "frame {f} vertex {k}: {s} vs {o}");
        }
        let d = p.offsets(0).frame(f);
        for (s, o) in stream.offsets().iter().zip(d) {
            assert!((s - o).abs() < 1e-5);
        }
    }
    assert!(stream.push(&[Vec3::ZERO]).is_err());
}

/// The stream's frames of `walk` scaled by `k`, divided back by `k`.
fn streamed(walk: &MeshAnimation, k: f32, options: &StreamOptions) -> Vec<Vec3> {
    let mut stream = Stream::new(&walk.mesh, options).unwrap();
    let mut out = Vec::new();
    for f in 0..walk.frame_count() {
        let frame: Vec<Vec3> = walk.frame(f).iter().map(|p| *p * k).collect();
        out.extend(stream.push(&frame).unwrap().iter().map(|p| *p / k));
    }
    out
}

#[test]
fn the_stream_reads_speeds_in_the_characters_size() {
    // docs/smear-units.md: by default the stream's speeds are in sizes per second (the first
    // frame's bounding-box diagonal), so one function smears a walk in centimetres and in
    // metres alike; in scene units per frame the same β converted by hand gives the same.
    let walk = legged::gait(24, 0.35, 0.3);
    let size = anim::Aabb::from_points(walk.frame(0)).diagonal();
    let options = StreamOptions {
        elongate: FunctionSpec::speed(0.5),
        ..StreamOptions::default()
    };
    let base = streamed(&walk, 1.0, &options);
    let moved = base
        .iter()
        .zip(walk.positions())
        .map(|(a, b)| a.distance(*b))
        .fold(0.0f32, f32::max);
    assert!(
        moved > 0.01 * size,
        "the speed function smears nothing: {moved}"
    );
    for k in [0.01, 100.0] {
        let scaled = streamed(&walk, k, &options);
        for (a, b) in scaled.iter().zip(&base) {
            assert!(a.distance(*b) <= 1e-4 * size, "×{k}: {a} vs {b}");
        }
    }
    let scene = StreamOptions {
        elongate: FunctionSpec::speed(0.5 * 24.0 / size),
        speed_units: smear::SpeedUnits::Scene,
        ..StreamOptions::default()
    };
    for (a, b) in streamed(&walk, 1.0, &scene).iter().zip(&base) {
        assert!(a.distance(*b) <= 1e-5 * size, "scene units: {a} vs {b}");
    }
    let bad = StreamOptions {
        size_reference: Some(-1.0),
        ..StreamOptions::default()
    };
    assert!(Stream::new(&walk.mesh, &bad).is_err());
}
