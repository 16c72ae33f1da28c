//! How deep the back surface must lie under every front vertex: not only behind the vertex
//! itself but behind every front point (of any piece) in a column around the vertex's inward
//! direction, so a back surface that leaves the wall under the nose tip does not pass through
//! the nostrils behind it, nor one under a lip through the mouth corner.

use std::collections::HashMap;

use glam::Vec3;

/// Per shell vertex `v`, the largest height `back[v]·normals[v]` the back may have: the
/// smallest `q·normals[v]` over the front points `q` of every piece within `lateral` of the
/// line through `average[v]` along `normals[v]` and at most `reach` deeper or `lateral`
/// higher than `average[v]`, minus `wall`.
pub(super) fn envelope_limits(
    average: &[Vec3],
    fronts: &[Vec<Vec3>],
    normals: &[Vec3],
    wall: f32,
    lateral: f32,
    reach: f32,
) -> Vec<f32> {
    let n = average.len();
    let cell = (reach + lateral).max(1e-3);
    let key = |p: Vec3| {
        let q = (p / cell).floor();
        [q.x as i32, q.y as i32, q.z as i32]
    };
    // Bins of every vertex of every piece (a piece moves a vertex at most a little from the
    // average, the bins are indexed by its own position).
    let mut grid: HashMap<[i32; 3], Vec<(u32, u32)>> = HashMap::new();
    for (k, f) in fronts.iter().enumerate() {
        for (u, p) in f.iter().enumerate().take(n) {
            grid.entry(key(*p)).or_default().push((k as u32, u as u32));
        }
    }
    use rayon::prelude::*;
    (0..n)
        .into_par_iter()
        .map(|v| {
            let (c, d) = (average[v], normals[v]);
            let mut lowest = fronts.iter().map(|f| f[v].dot(d)).fold(c.dot(d), f32::min);
            let kc = key(c);
            for x in kc[0] - 1..=kc[0] + 1 {
                for y in kc[1] - 1..=kc[1] + 1 {
                    for z in kc[2] - 1..=kc[2] + 1 {
                        let Some(list) = grid.get(&[x, y, z]) else {
                            continue;
                        };
                        for &(k, u) in list {
                            let q = fronts[k as usize][u as usize];
                            let e = q - c;
                            let h = e.dot(d);
                            if h < -reach || h > lateral {
                                continue;
                            }
                            if (e - d * h).length_squared() <= lateral * lateral {
                                lowest = lowest.min(q.dot(d));
                            }
                        }
                    }
                }
            }
            lowest - wall
        })
        .collect()
}
