//! The repair rounds of a new back surface: where the exact test still finds crossings
//! after the smoothing, crossing wall rungs are set straight and the back relaxes around them.

use glam::Vec3;

use super::topology::grow_mask;
use super::{centroid, PartShell, ShellOptions};

/// Repair rounds without fewer crossings before the repair gives up.
const REPAIR_PATIENCE: usize = 3;
/// Relaxation steps per repair round.
const REPAIR_STEPS: usize = 10;

impl PartShell {
    /// Repairs the back where the exact test still finds crossings. A crossing wall rung is set
    /// straight along the direction field (the boundary smoothing slid its back end
    /// sideways, fanning the wall through the front at crooked boundaries), at the same
    /// depth so the envelope holds, and the back next to it follows its back end so the
    /// back does not fold over the moved wall. Then, around the crossings, the back relaxes
    /// *tangentially* (towards the neighbours' centroid, never shallower along the
    /// direction field), which unfolds it without thinning the wall; the boundary curve is
    /// smoothed along its loop. The state with the fewest crossings is kept; a round that
    /// brings the wall under the minimum is undone and its rungs are left alone after.
    ///
    /// # Arguments
    /// * `front` — the part's average front (shell vertices); `fixed` — seam back points
    ///   shared with built parts, which stay.
    /// * `pieces` — every piece (millimetres), measured each round.
    /// * `enforce` — the wall and rung constraints of the back; `along_loop` — one smoothing
    ///   step of a boundary point along its loop.
    pub(super) fn repair(
        &mut self,
        front: &[Vec3],
        fixed: &[Option<Vec3>],
        pieces: &[&[Vec3]],
        opts: &ShellOptions,
        enforce: &impl Fn(&mut [Vec3]),
        along_loop: &impl Fn(&[Vec3], usize) -> Option<Vec3>,
    ) {
        let n = self.back.len();
        let mut rounds = 0;
        // Fewest crossings: their count, the back, the crossing vertices, the wall.
        type State = (usize, Vec<Vec3>, Vec<u32>, f64);
        let mut best: Option<State> = None;
        let mut stale = 0;
        let mut frozen = vec![false; n];
        let mut straightened: Vec<usize> = Vec::new();
        let mut floor = f64::NEG_INFINITY;
        loop {
            let (mut bad_vertices, mut count) = self.crossings(pieces);
            let wall_now = self.min_wall_of(pieces);
            if best.is_none() {
                floor = wall_now.min(opts.wall_mm);
            }
            if !straightened.is_empty() && wall_now < floor {
                for &v in &straightened {
                    frozen[v] = true;
                }
                if let Some(b) = &best {
                    self.back.clone_from(&b.1);
                    bad_vertices.clone_from(&b.2);
                    count = b.0;
                }
                stale += 1;
            } else if best.as_ref().is_none_or(|b| count < b.0) {
                best = Some((count, self.back.clone(), bad_vertices.clone(), wall_now));
                stale = 0;
            } else {
                stale += 1;
            }
            if count == 0 || rounds >= opts.repair_rounds || stale >= REPAIR_PATIENCE {
                break;
            }
            rounds += 1;
            let mut delta = vec![Vec3::ZERO; n];
            straightened.clear();
            for &v in &bad_vertices {
                let v = v as usize;
                if !self.on_boundary[v] || fixed[v].is_some() || frozen[v] {
                    continue;
                }
                let d = self.normals[v];
                let depth = -(self.back[v] - front[v]).dot(d);
                let straight = front[v] - d * depth;
                delta[v] = straight - self.back[v];
                self.back[v] = straight;
                straightened.push(v);
            }
            let follow: Vec<Vec3> = (0..n)
                .map(|u| {
                    if self.on_boundary[u] || fixed[u].is_some() {
                        return Vec3::ZERO;
                    }
                    let (s, c) = self.adjacency[u]
                        .iter()
                        .filter(|&&w| delta[w as usize] != Vec3::ZERO)
                        .fold((Vec3::ZERO, 0usize), |(s, c), &w| {
                            (s + delta[w as usize], c + 1)
                        });
                    if c == 0 {
                        Vec3::ZERO
                    } else {
                        s / c as f32
                    }
                })
                .collect();
            for (b, f) in self.back.iter_mut().zip(&follow) {
                *b += *f;
            }
            enforce(&mut self.back);
            let mut mask = vec![false; n];
            for &v in &bad_vertices {
                mask[v as usize] = true;
            }
            let mask = grow_mask(mask, &self.adjacency, 1 + rounds.min(6));
            for _ in 0..REPAIR_STEPS {
                let back = &self.back;
                let next: Vec<Vec3> = (0..n)
                    .map(|v| {
                        if !mask[v] || fixed[v].is_some() {
                            return back[v];
                        }
                        if self.on_boundary[v] {
                            return along_loop(back, v).unwrap_or(back[v]);
                        }
                        if self.adjacency[v].is_empty() {
                            return back[v];
                        }
                        let c = centroid(back, &self.adjacency[v]);
                        let (d, nv) = (c - back[v], self.normals[v]);
                        let along_n = d.dot(nv);
                        back[v] + (d - nv * along_n + nv * along_n.min(0.0)) * 0.5
                    })
                    .collect();
                self.back = next;
                enforce(&mut self.back);
            }
        }
        if let Some((count, back, _, wall)) = best {
            self.back = back;
            self.stats.self_intersecting_triangles = count;
            self.stats.min_wall_mm = wall;
        }
        self.stats.repair_rounds = rounds;
    }
}
