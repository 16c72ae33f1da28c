//! The moves the search tries for one back point.

use glam::Vec3;

use super::patient::Patient;
use crate::library::back_surface::{centroid, PartShell};

/// Deeper steps tried along the direction field, in walls.
const DEEPER_WALLS: [f32; 3] = [0.25, 0.5, 1.0];

impl PartShell {
    /// Positions tried for back vertex `v` (`patient` this part under search), each kept
    /// behind the envelope of every part in `members` (the vertices moving with it): always
    /// the same rules in the same order (`None` where a rule does not apply), so that two
    /// points can move by the same rule together.
    pub(super) fn candidates(
        &self,
        v: usize,
        patient: &Patient,
        shells: &[PartShell],
        members: &[(usize, usize)],
        wall_mm: f64,
    ) -> Vec<Option<Vec3>> {
        let wall = wall_mm as f32;
        let (p, d) = (self.back[v], self.normals[v]);
        let mut out: Vec<Option<Vec3>> = Vec::with_capacity(24);
        let c = (!self.adjacency[v].is_empty()).then(|| centroid(&self.back, &self.adjacency[v]));
        out.push(c);
        out.push(c.map(|c| p + (c - p) * 0.5));
        // Tangential: towards the neighbours, never shallower.
        out.push(c.map(|c| p + (c - p) - d * (c - p).dot(d).max(0.0)));
        out.push(c.map(|c| c - d * (0.5 * wall)));
        for s in DEEPER_WALLS {
            out.push(Some(p - d * (s * wall)));
        }
        let boundary = self.on_boundary[v];
        let [a, b] = patient.along[v];
        let ends = boundary && a != u32::MAX && b != u32::MAX;
        out.push(ends.then(|| p * 0.5 + (self.back[a as usize] + self.back[b as usize]) * 0.25));
        // The rung set straight along the direction field, same depth; along the front's own
        // normal there (a wall leaving the front square to it does not cut back through it
        // where the front curls, at the temples) and half way; deeper too.
        let front = patient.mean_front[v];
        let depth = (front - p).dot(d).max(wall);
        let own = patient.normals[v];
        for dir in [d, own, (d + own).normalize_or(d)] {
            for s in [1.0, 1.3] {
                out.push(boundary.then(|| front - dir * (depth * s)));
            }
        }
        // Parallel to a neighbour's rung along the loop (one and two steps): where the
        // boundary doubles back on itself (a spike of the cut) the two walls of the spike
        // then run side by side instead of through each other.
        let step = |u: u32, side: usize| {
            (u != u32::MAX)
                .then(|| patient.along[u as usize][side])
                .filter(|&w| w != u32::MAX)
        };
        for (u, side) in [(a, 0), (b, 1)] {
            let u1 = boundary.then_some(u).filter(|&u| u != u32::MAX);
            let u2 = u1.and_then(|u| step(u, side));
            for w in [u1, u2] {
                out.push(w.map(|w| {
                    let w = w as usize;
                    front + (self.back[w] - patient.mean_front[w])
                }));
            }
        }
        // Sideways: along the boundary and across it, half a wall.
        let t = if ends {
            (patient.mean_front[b as usize] - patient.mean_front[a as usize]).normalize_or_zero()
        } else {
            Vec3::ZERO
        };
        let across = own.cross(t).normalize_or_zero();
        for step in [t, -t, across, -across] {
            out.push((ends && step != Vec3::ZERO).then(|| p + step * (0.5 * wall)));
        }
        out.into_iter()
            .map(|q| {
                let mut q = q.filter(|q| q.is_finite())?;
                for &(pm, vm) in members {
                    let (dm, limit) = (shells[pm].normals[vm], shells[pm].limits[vm]);
                    q -= dm * (q.dot(dm) - limit).max(0.0);
                }
                Some(q)
            })
            .collect()
    }
}
