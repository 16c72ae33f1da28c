//! `--subdivide`: acceptance of issue #22 on a low-poly run cycle.

use std::collections::HashMap;

use anim::FlipbookPart;
use smear::{stylize, Style};

use super::{elongation, legged, prepared};

/// Largest ratio of an edge's length in `output` to its length in `input`.
fn edge_ratio_max(input: &[glam::Vec3], output: &[glam::Vec3], tris: &[[u32; 3]]) -> f32 {
    let mut worst = 0.0f32;
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let rest = input[a].distance(input[b]);
            worst = worst.max(output[a].distance(output[b]) / rest);
        }
    }
    worst
}

#[test]
fn subdivide_2_keeps_every_edge_within_twice_its_rest_length() {
    let run = legged::gait(24, 0.35, 0.3);
    let p = prepared(&run, |_| {});
    let style = elongation(&p, 3.0);
    // Without subdivision the legs and body stretch into shards (edges > 2× their rest length).
    let plain = stylize(&p, &style).unwrap();
    let body = plain.animation(0).unwrap();
    let shards = (0..run.frame_count())
        .map(|f| edge_ratio_max(run.frame(f), body.frame(f), &run.mesh.triangles))
        .fold(0.0f32, f32::max);
    assert!(
        shards > 2.5,
        "the run does not stretch: worst ratio {shards}"
    );

    let sub = stylize(
        &p,
        &Style {
            subdivide: Some(2.0),
            ..style
        },
    )
    .unwrap();
    let stats = &sub.report.objects[0];
    let stretch = stats.subdivision_max_stretch.unwrap();
    assert!(stretch <= 2.0, "max stretch {stretch}");
    let FlipbookPart::Frames { meshes, .. } = &sub.flipbook.parts[0] else {
        panic!("a subdivided body has one mesh per frame");
    };
    assert_eq!(meshes.len(), run.frame_count());
    let n = run.vertex_count();
    let mut grew = false;
    for (f, m) in meshes.iter().enumerate() {
        // The input vertices keep their elongated places; new ones come after them.
        assert_eq!(&m.positions[..n], body.frame(f), "frame {f}");
        grew |= m.triangle_count() > run.mesh.triangle_count();
        // Independent bound: no output edge is longer than twice the longest input edge.
        let longest_in = run
            .mesh
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k] as usize, t[(k + 1) % 3] as usize)))
            .map(|(a, b)| run.frame(f)[a].distance(run.frame(f)[b]))
            .fold(0.0, f32::max);
        // Crack-free: every edge of the closed input stays shared by exactly two triangles,
        // in opposite directions.
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let l = m.positions[a as usize].distance(m.positions[b as usize]);
                assert!(
                    l <= 2.0 * longest_in + 1e-5,
                    "frame {f}: edge {l} vs {longest_in}"
                );
                *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
            }
        }
        assert!(
            edges.values().all(|&v| v == 0),
            "frame {f}: a crack or a flipped triangle"
        );
    }
    assert!(grew, "nothing was subdivided");
}
