//! Open borders (neck, scalp, mouth edge): homogenization leaves them where the input puts them, and the pieces spread there no more than the input moves.

use super::*;

/// Welded open-border vertices of the cut mesh that are not on the seam.
fn open_border_vertices(seg: &Segmentation) -> Vec<u32> {
    let mesh = &seg.animation.mesh;
    let class = &seg.cut.weld_class;
    let mut count = std::collections::HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (class[t[k] as usize], class[t[(k + 1) % 3] as usize]);
            *count.entry((a.min(b), a.max(b))).or_insert(0u32) += 1;
        }
    }
    let mut border = vec![false; seg.cut.welded_count];
    for (&(a, b), &c) in &count {
        if c == 1 {
            border[a as usize] = true;
            border[b as usize] = true;
        }
    }
    let seam: std::collections::HashSet<u32> = seg.seam_vertices.iter().copied().collect();
    (0..class.len() as u32)
        .filter(|&v| border[class[v as usize] as usize] && !seam.contains(&v))
        .collect()
}

#[test]
fn homogenization_keeps_open_borders_and_pieces_agree_there() {
    let seg = segmentation();
    let input = face();
    let mm = {
        let a = part_animations(seg);
        let refs: Vec<&MeshAnimation> = a.iter().collect();
        print_scale(&refs, HEIGHT_MM)
    };
    let border = open_border_vertices(seg);
    assert!(border.len() > 100, "{} open-border vertices", border.len());
    let mut worst = 0.0f64;
    for (f, (out, x)) in seg.animation.frames().zip(input.frames()).enumerate() {
        for &v in &border {
            let y = seg.cut.sources[v as usize].eval(x);
            let d = f64::from(out[v as usize].distance(y)) * mm;
            worst = worst.max(d);
            assert!(d <= 0.02, "frame {f}: border vertex {v} moved {d:.4} mm");
        }
    }
    let h = seg.homogenization.expect("homogenized");
    eprintln!(
        "open borders: {} vertices, max change {worst:.2e} mm; mean change {:.4} mm, max {:.4} mm",
        border.len(),
        h.mean_change * mm,
        h.max_change * mm
    );
    // Pieces of a part differ on the open borders by no more than the input moves there.
    let anims = part_animations(seg);
    let parts = seg.parts().expect("parts");
    let lib = library_of(&anims, 20);
    let border_set: std::collections::HashSet<u32> = border.iter().copied().collect();
    let mut worst_excess = 0.0f64;
    for (p, part) in parts.iter().enumerate() {
        for (local, &v) in part.vertices.iter().enumerate() {
            if !border_set.contains(&v) {
                continue;
            }
            let inputs: Vec<Vec3> = input
                .frames()
                .map(|x| seg.cut.sources[v as usize].eval(x))
                .collect();
            let spread = |pts: &[Vec3]| {
                pts.iter()
                    .flat_map(|a| pts.iter().map(move |b| a.distance(*b)))
                    .fold(0.0f32, f32::max)
            };
            let own = spread(&inputs);
            let pieces: Vec<Vec3> = lib.parts[p]
                .solution
                .pieces
                .iter()
                .map(|q| q[local])
                .collect();
            let between = spread(&pieces);
            let excess = f64::from(between - own) * mm;
            worst_excess = worst_excess.max(excess);
            // Pieces are confined where a part ends (library::BORDER_RINGS: a mean of frames
            // never leaves their hull; without it the inner lip edge spread 0.135 mm more
            // than the input's 5.8 mm); 0.01 mm is a fifth of a 0.05 mm printer resolution.
            assert!(
                excess <= 0.01,
                "part {}: border vertex {v}: pieces differ by {:.4} mm, input moves {:.4} mm",
                part.name,
                f64::from(between) * mm,
                f64::from(own) * mm
            );
        }
    }
    eprintln!("pieces' border spread minus input spread: at most {worst_excess:.2e} mm");
}
