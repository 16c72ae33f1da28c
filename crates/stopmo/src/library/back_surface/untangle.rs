//! Fronts that cross themselves (lips pressed through each other in the input's own frames
//! carry into the pieces) are untangled before they are closed into solids: the vertices of
//! crossing triangles, and a ring around them, retract along their inward normal in small
//! steps until the exact test finds no crossing. Both sides of a crossing retract, so two
//! surfaces pressed into each other part where they met, by the least depth that separates
//! them.

use glam::Vec3;

use crate::library::intersect::intersecting_pairs;

/// Retraction per round (mm).
const STEP_MM: f32 = 0.02;
/// Rounds at most (`ROUNDS × STEP_MM` = 1 mm of retraction).
const ROUNDS: usize = 50;

/// Untangles `front` (positions of the triangles `tris`, `adj` their vertex adjacency) in
/// place; returns the vertices moved.
pub(super) fn untangle(front: &mut [Vec3], tris: &[[u32; 3]], adj: &[Vec<u32>]) -> usize {
    let n = front.len();
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
        for v in 0..n {
            if ring[v] {
                let s = if mark[v] { STEP_MM } else { STEP_MM * 0.5 };
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
