//! `--ground`: a walk with planted feet never goes through the floor.

use smear::{stylize, ContactStyle, MultiplesStyle, Param, Style};

use super::{elongation, legged, part_frames, prepared};

/// The lowest point of every part of a stylized result.
fn lowest(out: &smear::Stylized) -> f32 {
    out.flipbook
        .parts
        .iter()
        .flat_map(part_frames)
        .flatten()
        .fold(f32::INFINITY, |m, p| m.min(p.y))
}

#[test]
fn a_walk_with_planted_feet_stays_above_the_ground() {
    let walk = legged::gait(32, 0.1, 0.25);
    let input_low = walk
        .positions()
        .iter()
        .fold(f32::INFINITY, |m, p| m.min(p.y));
    assert!(input_low.abs() < 1e-6, "the feet touch y = 0: {input_low}");
    let p = prepared(&walk, |_| {});
    let style = Style {
        multiples: Some(MultiplesStyle {
            past: Param::Constant(2.0),
            future: Param::Constant(2.0),
            ..MultiplesStyle::default()
        }),
        ..elongation(&p, 2.0)
    };
    // Without contact, Catmull-Rom trajectories overshoot the landing and dive below.
    let free = stylize(&p, &style).unwrap();
    assert!(
        lowest(&free) < -1e-3,
        "nothing crossed the ground: {}",
        lowest(&free)
    );
    for squash in [0.0, 0.3] {
        for subdivide in [None, Some(2.0)] {
            let grounded = Style {
                contact: Some(ContactStyle {
                    ground: 0.0,
                    squash,
                    ..ContactStyle::default()
                }),
                subdivide,
                ..style.clone()
            };
            let out = stylize(&p, &grounded).unwrap();
            let low = lowest(&out);
            assert!(
                low >= 0.0,
                "squash {squash}, subdivide {subdivide:?}: lowest {low}"
            );
            // The smear is still there: grounding shortens, it does not cancel.
            let e = out.report.objects[0].elongation_max.unwrap();
            assert!(e > 0.1, "elongation {e}");
        }
    }
}
