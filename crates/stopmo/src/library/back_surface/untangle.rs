//! Fronts that cross themselves (lips pressed through each other in the input's own frames
//! carry into the pieces) are untangled before they are closed into solids: the vertices of
//! crossing triangles, and a ring around them, retract along their inward normal in small
//! steps until the exact test finds no crossing. Both sides of a crossing retract, so two
//! surfaces pressed into each other part where they met, by the least depth that separates
//! them; the crossing vertices also relax towards their neighbours, which opens folds (a
//! mouth corner pinched through itself) that retraction alone does not (ICT face, 8 pieces:
//! 132 crossing pairs left in one lower piece with retraction only, none with both), and so
//! does their ring, half as fast: a crumpled lip corner whose crossing triangles share
//! vertices with uncrossed ones stayed crumpled when only the crossing vertices relaxed
//! (ICT face: 10 crossing triangles left at 20 pieces, 19 at 50; none with the ring).

use glam::Vec3;

use super::topology::grow_mask;
use crate::library::fabricate::DEFAULT_PRINT_HEIGHT_MM;
use crate::library::intersect::intersecting_pairs;

/// Retraction per round (mm) at the default print height and above.
const STEP_MM: f32 = 0.02;
/// Rounds at most (`ROUNDS × STEP_MM` = 3 mm of retraction at the default print height; the
/// first round without a crossing ends it).
const ROUNDS: usize = 150;
/// Fraction of the way to the neighbours' centroid a crossing vertex moves per round.
const RELAX: f32 = 0.5;
/// Rings around the first crossings that the later rounds test.
const REGION_RINGS: usize = 8;

/// Retraction per round for a print `model_height_mm` tall: [`STEP_MM`], smaller in
/// proportion on a smaller print. A lip of a 25 mm face is 2.4 times thinner than at 60 mm:
/// the 60 mm step pushed its crossing vertices through the lip's other side there, and
/// the README cut's 20 pieces kept a crossing lower piece at 25 mm (40 triangles; none with
/// the scaled step).
pub(super) fn step_for_height(model_height_mm: f64) -> f32 {
    let scale = (model_height_mm / DEFAULT_PRINT_HEIGHT_MM).min(1.0) as f32;
    if scale.is_finite() && scale > 0.0 {
        STEP_MM * scale
    } else {
        STEP_MM
    }
}

/// Untangles `front` (positions of the triangles `tris`, `adj` their vertex adjacency) in
/// place, never moving a `pinned` vertex (the part boundary: a seam's front must stay the
/// same curve in every piece of every part that meets there, an open border where the input
/// puts it), retracting by `step_mm` per round (see [`step_for_height`]); returns the
/// vertices moved.
pub(super) fn untangle(
    front: &mut [Vec3],
    tris: &[[u32; 3]],
    adj: &[Vec<u32>],
    pinned: &[bool],
    step_mm: f32,
) -> usize {
    let free = |v: usize| !pinned.get(v).copied().unwrap_or(false);
    let n = front.len();
    let Some(first) = intersecting_pairs(front, tris) else {
        return 0;
    };
    if first.iter().all(|(i, j)| i == j) {
        return 0;
    }
    // Only the neighbourhood of the first crossings moves (a few rings per round at most):
    // later rounds test its triangles only, not the whole front again.
    let mut region = vec![false; n];
    for &(i, j) in first.iter().filter(|(i, j)| i != j) {
        for t in [i, j] {
            for &v in &tris[t as usize] {
                region[v as usize] = true;
            }
        }
    }
    let region = grow_mask(region, adj, REGION_RINGS);
    let local: Vec<[u32; 3]> = tris
        .iter()
        .filter(|t| t.iter().any(|&v| region[v as usize]))
        .copied()
        .collect();
    let tris = &local[..];
    let mut moved = vec![false; n];
    let mut best: Option<(usize, Vec<Vec3>, Vec<bool>)> = None;
    for round in 0..=ROUNDS {
        let Some(pairs) = intersecting_pairs(front, tris) else {
            break;
        };
        let crossing = pairs.iter().filter(|(i, j)| i != j).count();
        if best.as_ref().is_none_or(|b| crossing < b.0) {
            best = Some((crossing, front.to_vec(), moved.clone()));
        }
        if crossing == 0 || round == ROUNDS {
            break;
        }
        // Only front triangles that cross another one (not degenerate ones).
        let mut mark = vec![false; n];
        for &(i, j) in pairs.iter().filter(|(i, j)| i != j) {
            for t in [i, j] {
                for &v in &tris[t as usize] {
                    mark[v as usize] = true;
                }
            }
        }
        if !mark.iter().any(|&m| m) {
            break;
        }
        let ring: Vec<bool> = (0..n)
            .map(|v| mark[v] || adj[v].iter().any(|&w| mark[w as usize]))
            .collect();
        let normals = anim::vertex_normals(front, tris);
        // A fold (the mouth corner pinched through itself) does not open by retraction:
        // relax the crossing vertices and their ring towards their neighbours too.
        let relaxed: Vec<Vec3> = (0..n)
            .map(|v| {
                if !ring[v] || adj[v].is_empty() || !free(v) {
                    return front[v];
                }
                let c = adj[v]
                    .iter()
                    .fold(Vec3::ZERO, |a, &w| a + front[w as usize])
                    / adj[v].len() as f32;
                front[v] + (c - front[v]) * if mark[v] { RELAX } else { RELAX * 0.5 }
            })
            .collect();
        front.copy_from_slice(&relaxed);
        for v in 0..n {
            if ring[v] && free(v) {
                let s = if mark[v] { step_mm } else { step_mm * 0.5 };
                front[v] -= normals[v] * s;
                moved[v] = true;
            }
        }
    }
    // Keep the state with the fewest crossings (retracting never makes it worse).
    if let Some((_, positions, m)) = best {
        front.copy_from_slice(&positions);
        moved = m;
    }
    moved.iter().filter(|&&m| m).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_step_shrinks_with_a_smaller_print_only() {
        assert_eq!(step_for_height(60.0), STEP_MM);
        assert_eq!(step_for_height(150.0), STEP_MM);
        assert!((step_for_height(30.0) - STEP_MM * 0.5).abs() < 1e-9);
        assert_eq!(step_for_height(f64::NAN), STEP_MM);
        assert_eq!(step_for_height(0.0), STEP_MM);
    }
}
