//! Seams: the parts' seams are one curve, and a saved cut puts the seams of another clip at the same place.

use super::*;

/// Boundary vertices of every part that lie neither on the input's open border nor on
/// another part's boundary at the same point, and the seam vertices (on another part's
/// boundary), over all parts.
fn unshared_seam_points(seg: &Segmentation) -> (usize, usize) {
    let key = |p: Vec3| p.to_array().map(f32::to_bits);
    let boundary = |tris: &[[u32; 3]], at: &dyn Fn(u32) -> [u32; 3]| {
        let mut uses: HashMap<([u32; 3], [u32; 3]), u32> = HashMap::new();
        for t in tris {
            for k in 0..3 {
                let (a, b) = (at(t[k]), at(t[(k + 1) % 3]));
                *uses.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        uses.into_iter()
            .filter(|(_, n)| *n == 1)
            .flat_map(|((a, b), _)| [a, b])
            .collect::<std::collections::HashSet<[u32; 3]>>()
    };
    let avg_in = face().average_positions();
    let open = boundary(&face().mesh.triangles, &|v| key(avg_in[v as usize]));
    let parts: Vec<std::collections::HashSet<[u32; 3]>> = part_animations(seg)
        .iter()
        .map(|a| {
            let avg = a.average_positions();
            boundary(&a.mesh.triangles, &|v| key(avg[v as usize]))
        })
        .collect();
    let (mut unshared, mut seam) = (0, 0);
    for (p, points) in parts.iter().enumerate() {
        for k in points {
            if parts
                .iter()
                .enumerate()
                .any(|(q, o)| q != p && o.contains(k))
            {
                seam += 1;
            } else if !open.contains(k) {
                unshared += 1;
            }
        }
    }
    (unshared, seam)
}

/// The seams of the parts are one curve: every point where a part ends is on another part
/// or on the face's own open border. The cut left T-junctions (a crossing kept on one side
/// of an input edge, dropped on the other) and, at a three-part corner, a hole: 7 points of
/// one part missing from the other on the README's cut, 1 with three automatic parts, and
/// the printed walls crossed there (the nose wing, the lips).
#[test]
fn seams_of_the_parts_are_one_curve() {
    let (unshared, seam) = unshared_seam_points(segmentation());
    assert_eq!(
        unshared, 0,
        "README cut: {unshared} unshared of {seam} seam points"
    );
    assert!(seam >= 2 * 150, "README cut: {seam} seam points");
    let parts = auto_parts(face(), 3).expect("auto parts");
    let seg = segment(face(), &parts, &SegmentOptions::default()).expect("segment");
    let (unshared, seam) = unshared_seam_points(&seg);
    assert_eq!(
        unshared, 0,
        "three parts: {unshared} unshared of {seam} seam points"
    );
}

#[test]
fn reused_segmentation_puts_seams_of_two_clips_together() {
    let full = face();
    let m = full.vertex_count();
    let clip = |range: std::ops::Range<usize>| {
        let pos: Vec<Vec3> = range.flat_map(|f| full.frame(f).to_vec()).collect();
        MeshAnimation::new(full.mesh.clone(), full.fps, pos).expect("clip")
    };
    let (a, b) = (clip(0..30), clip(30..60));
    let seg_a = segment(&a, &parts(), &SegmentOptions::default()).expect("segment clip A");
    let saved = seg_a.saved(m, full.mesh.triangle_count());
    // Through JSON, as `--segmentation segmentation.json` reads it.
    let json = serde_json::to_string(&saved).expect("serialize");
    let saved: SavedSegmentation = serde_json::from_str(&json).expect("deserialize");
    let seg_b = segment_reusing(&b, &saved, &SegmentOptions::default()).expect("reuse on B");
    let diag = full.bbox().diagonal();
    let mut worst = 0.0f32;
    for (seg, clip) in [(&seg_a, &a), (&seg_b, &b)] {
        let anims = part_animations(seg);
        let lib = library_of(&anims, 8);
        assert_eq!(clip.vertex_count(), m);
        for (p, part) in seg.parts().expect("parts").iter().enumerate() {
            for (local, &v) in part.vertices.iter().enumerate() {
                if seg_a.seam_vertices.binary_search(&v).is_err() {
                    continue;
                }
                let target = Vec3::from_array(saved.reference[v as usize]);
                for piece in &lib.parts[p].solution.pieces {
                    worst = worst.max(piece[local].distance(target));
                }
            }
        }
    }
    assert_eq!(seg_a.seam_vertices, seg_b.seam_vertices);
    eprintln!(
        "seam vertices of both clips' pieces within {:.2e} of the diagonal",
        worst / diag
    );
    assert!(
        worst <= 1e-5 * diag,
        "seams differ by {worst} (diag {diag})"
    );
}
