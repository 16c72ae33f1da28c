//! Offsets of a revolving object: SMEAR Eq. 1 with the separation plane replaced by the
//! half-plane through the rotation axis (construction in the module docs).

use glam::Vec3;

use super::Screw;

/// Connected pieces of a triangle mesh: a piece index per vertex (union-find over triangle
/// edges; isolated vertices are pieces of their own).
fn pieces(vertices: usize, triangles: &[[u32; 3]]) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..vertices).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for t in triangles {
        let [a, b, c] = t.map(|v| v as usize);
        if a.max(b).max(c) >= vertices {
            continue;
        }
        for (x, y) in [(a, b), (b, c)] {
            let (rx, ry) = (root(&mut parent, x), root(&mut parent, y));
            if rx != ry {
                parent[rx.max(ry)] = rx.min(ry);
            }
        }
    }
    (0..vertices).map(|i| root(&mut parent, i)).collect()
}

/// Wraps an angle into (−π, π].
fn wrap(a: f32) -> f32 {
    let t = std::f32::consts::TAU;
    let r = a.rem_euclid(t);
    if r > std::f32::consts::PI {
        r - t
    } else {
        r
    }
}

/// Unsmoothed offsets of one frame of a revolving object turning by `screw`.
fn frame_offsets(p: &[Vec3], piece: &[usize], screw: &Screw, out: &mut [f32]) {
    if screw.angle <= 0.0 || screw.axis == Vec3::ZERO {
        out.fill(0.0);
        return;
    }
    let a = screw.axis;
    let u = a.any_orthonormal_vector();
    let v = a.cross(u);
    let polar = |q: Vec3| {
        let d = q - screw.point;
        let (x, y) = (d.dot(u), d.dot(v));
        ((x * x + y * y).sqrt(), y.atan2(x))
    };
    // Radius-weighted circular mean angle per piece.
    let n = p.len();
    let mut sum = vec![(0.0f32, 0.0f32); n];
    for (q, &k) in p.iter().zip(piece) {
        let (r, phi) = polar(*q);
        sum[k].0 += r * phi.cos();
        sum[k].1 += r * phi.sin();
    }
    let mut max = 0.0f32;
    for ((q, &k), o) in p.iter().zip(piece).zip(out.iter_mut()) {
        let (r, phi) = polar(*q);
        let mean = sum[k].1.atan2(sum[k].0);
        *o = r * wrap(phi - mean);
        max = max.max(o.abs());
    }
    if max > 0.0 && max.is_finite() {
        for o in out.iter_mut() {
            *o /= max;
        }
    } else {
        out.fill(0.0);
    }
}

/// Motion offsets of a revolving object (frame-major `frames × vertices` positions, its
/// triangles and its screws per frame interval), smoothed by SMEAR Eq. 2 with half-window
/// `smooth` (past-only when `causal`).
///
/// Frame f uses the screw of interval f → f+1 (the last one at the last frame); in causal mode
/// the interval f−1 → f, and frame 0 has offsets 0.
pub fn revolving_offsets(
    positions: &[Vec3],
    frames: usize,
    triangles: &[[u32; 3]],
    screws: &[Screw],
    smooth: usize,
    causal: bool,
) -> Vec<f32> {
    let vertices = positions.len().checked_div(frames).unwrap_or(0);
    let piece = pieces(vertices, triangles);
    let mut raw = vec![0.0f32; frames * vertices];
    for f in 0..frames {
        let k = if causal {
            f.checked_sub(1)
        } else {
            Some(f.min(screws.len().saturating_sub(1)))
        };
        let screw = k.and_then(|k| screws.get(k)).unwrap_or(&Screw::IDENTITY);
        frame_offsets(
            &positions[f * vertices..(f + 1) * vertices],
            &piece,
            screw,
            &mut raw[f * vertices..(f + 1) * vertices],
        );
    }
    crate::smooth::smooth_columns(&raw, frames, vertices, 0..vertices, smooth, causal)
}
