//! The last step of the shells: where the exact test still finds crossings in some piece's
//! solid, back vertices move one at a time to the candidate position that leaves the fewest
//! crossings over *all* pieces, never nearer to any piece's front than the wall and never
//! past the envelope. A seam's back point moves in every part that shares it (their walls
//! are one surface) and is tested in all of them. The smoothing and the repair rounds fix
//! the shape; this search fixes the spots they leave (walls meeting the front at the
//! temples, the back meeting the seam wall under the nose), because it tests every move
//! exactly instead of trusting a rule.

use std::collections::{BTreeMap, HashMap};

use glam::Vec3;
use rayon::prelude::*;

mod candidates;
mod grid;
mod patient;

use grid::BoxGrid;
use patient::{Near, Patient};

use super::{centroid, position_key, PartShell};

/// Rings of back vertices around the crossing ones that may move too.
const RESOLVE_RINGS: usize = 1;

/// A move of one solid vertex (`at`: front `v` or back `n + v`) to a point, or (`shift`)
/// by a vector in every piece.
#[derive(Debug, Clone, Copy)]
pub(super) struct Move {
    pub(super) at: usize,
    pub(super) to: Vec3,
    pub(super) shift: bool,
}

/// How far a front point may move to clear a crossing (mm): the default printer
/// resolution, below which a print does not change.
const FRONT_NUDGE_MM: f32 = 0.05;

/// One part's share of a move: the moved solid vertices (group of the unit, solid vertex),
/// the triangles incident to them, and what those may meet in every piece.
type PartMoves = (Vec<(usize, usize)>, Vec<u32>, Vec<Near>);

/// Moves back points of `shells` (a seam's point in every part sharing it, alone or with its
/// neighbours along the boundary), and shifts front points by at most [`FRONT_NUDGE_MM`] in
/// every piece, where pieces' solids still cross themselves; measures the shells again.
///
/// # Arguments
/// * `shells`, `averages`, `pieces` — the parts, their average surfaces and pieces
///   (millimetres, input vertex order), in the same order.
/// * `frozen` — parts whose back must stay (printed); a seam point shared with one stays.
/// * `wall_mm` — the minimum wall: a move never brings the back nearer than
///   `min(wall_mm, the part's thinnest wall now)` to any piece's front vertex.
/// * `rounds` — rounds at most ([`DEFAULT_RESOLVE_ROUNDS`](super::DEFAULT_RESOLVE_ROUNDS)).
///
/// # Returns
/// Points moved (a seam point counts once).
///
/// # Performance
/// Per round one exact test and one box grid per piece; each candidate position is tested
/// only against the triangles near the moving ones, in parallel over pieces.
pub(super) fn resolve_crossings(
    shells: &mut [PartShell],
    averages: &[&[Vec3]],
    pieces: &[Vec<&[Vec3]>],
    frozen: &[bool],
    wall_mm: f64,
    rounds: usize,
) -> usize {
    if rounds == 0 || shells.is_empty() {
        return 0;
    }
    let mut patients: Vec<Patient> = shells
        .iter()
        .zip(pieces)
        .map(|(s, p)| Patient::new(s, p, wall_mm))
        .collect();
    // Shell vertices moving together: a seam's boundary vertices (same average position)
    // in every part, in a fixed order (parts, then vertices).
    let mut groups: BTreeMap<(usize, usize), Vec<(usize, usize)>> = BTreeMap::new();
    let mut by_key: HashMap<[u32; 3], (usize, usize)> = HashMap::new();
    for (p, (shell, average)) in shells.iter().zip(averages).enumerate() {
        for v in 0..shell.back.len() {
            let head = if shell.on_boundary[v] {
                average
                    .get(shell.source[v] as usize)
                    .map(|a| *by_key.entry(position_key(*a)).or_insert((p, v)))
                    .unwrap_or((p, v))
            } else {
                (p, v)
            };
            groups.entry(head).or_default().push((p, v));
        }
    }
    let mut group_of: Vec<Vec<(usize, usize)>> =
        shells.iter().map(|s| vec![(0, 0); s.back.len()]).collect();
    for (&head, members) in &groups {
        for &(p, v) in members {
            group_of[p][v] = head;
        }
    }
    let mut moved_points = 0;
    let mut used = 0;
    for _ in 0..rounds {
        let hot: Vec<(Vec<bool>, Vec<bool>, usize)> = patients.iter().map(Patient::hot).collect();
        if hot.iter().all(|(_, _, c)| *c == 0) {
            break;
        }
        used += 1;
        let mut heads: Vec<(usize, usize)> = Vec::new();
        for (p, (h, _, _)) in hot.iter().enumerate() {
            let adjacency = &shells[p].adjacency;
            let mut h = h.clone();
            for _ in 0..RESOLVE_RINGS {
                h = (0..h.len())
                    .map(|v| h[v] || adjacency[v].iter().any(|&w| h[w as usize]))
                    .collect();
            }
            heads.extend((0..h.len()).filter(|&v| h[v]).map(|v| group_of[p][v]));
        }
        heads.sort_unstable();
        heads.dedup();
        let grids: Vec<Vec<BoxGrid>> = patients
            .iter()
            .map(|pt| {
                pt.solids
                    .par_iter()
                    .map(|s| BoxGrid::new(s, &pt.tris, 2.0 * pt.size))
                    .collect()
            })
            .collect();
        let mut touched: Vec<Vec<u32>> = vec![Vec::new(); patients.len()];
        let mut moved = 0;
        // A hot point alone, and with the next point along its boundary loop (the two back
        // ends of one wall quad swing together: neither alone may clear a crossing rung).
        let mut units: Vec<Vec<(usize, usize)>> = Vec::new();
        for &head in &heads {
            units.push(vec![head]);
            let (p, v) = head;
            if shells[p].on_boundary[v] {
                let [prev, next] = patients[p].along[v];
                if next != u32::MAX {
                    units.push(vec![head, group_of[p][next as usize]]);
                    if prev != u32::MAX {
                        // A spike of the cut: both sides of its tip.
                        units.push(vec![
                            group_of[p][prev as usize],
                            head,
                            group_of[p][next as usize],
                        ]);
                    }
                }
            }
        }
        for unit in units {
            let members: Vec<&Vec<(usize, usize)>> = unit.iter().map(|h| &groups[h]).collect();
            if members
                .iter()
                .flat_map(|m| m.iter())
                .any(|&(p, _)| frozen.get(p).copied().unwrap_or(true))
            {
                continue;
            }
            // Candidate rule `r` applied to every group of the unit.
            let rules: Vec<Vec<Option<Vec3>>> = members
                .iter()
                .map(|m| {
                    let (p0, v0) = m[0];
                    shells[p0].candidates(v0, &patients[p0], shells, m, wall_mm)
                })
                .collect();
            let now_points: Vec<Vec3> = members
                .iter()
                .map(|m| shells[m[0].0].back[m[0].1])
                .collect();
            // Per part: the moved solid vertices (member index, vertex), the moving
            // triangles and what they may meet (with `all`, under any rule; else where they
            // are now).
            let local = |all: bool| -> Vec<Option<PartMoves>> {
                (0..patients.len())
                    .map(|p| {
                        let pt = &patients[p];
                        let at: Vec<(usize, usize)> = members
                            .iter()
                            .enumerate()
                            .flat_map(|(g, m)| {
                                m.iter().filter(|x| x.0 == p).map(move |x| (g, pt.n + x.1))
                            })
                            .collect();
                        if at.is_empty() {
                            return None;
                        }
                        let ids: Vec<usize> = at.iter().map(|x| x.1).collect();
                        let moving = pt.moving(&ids);
                        let extra: Vec<Vec3> = if all {
                            at.iter()
                                .flat_map(|&(g, _)| rules[g].iter().flatten().copied())
                                .collect()
                        } else {
                            Vec::new()
                        };
                        let near = pt.neighbourhood(&grids[p], &touched[p], &moving, &extra, 0.0);
                        Some((at, moving, near))
                    })
                    .collect()
            };
            // New points of the unit's groups (one per group) → crossing count over parts
            // (or with `thin`, 1 when the wall would be too thin somewhere).
            let count_in = |local: &[Option<PartMoves>], points: &[Vec3], thin: bool| -> usize {
                let mut total = 0;
                for (p, l) in local.iter().enumerate() {
                    let Some((at, moving, near)) = l else {
                        continue;
                    };
                    let moves: Vec<Move> = at
                        .iter()
                        .map(|&(g, i)| Move {
                            at: i,
                            to: points[g],
                            shift: false,
                        })
                        .collect();
                    total += patients[p].count(near, moving, &moves, thin);
                }
                total
            };
            // Most hot points are only next to a crossing: a small neighbourhood says so.
            let now = count_in(&local(false), &now_points, false);
            if now == 0 {
                continue;
            }
            let everywhere = local(true);
            let count = |points: &[Vec3], thin: bool| count_in(&everywhere, points, thin);
            let mut tried: Vec<(usize, usize, Vec<Vec3>)> = Vec::new();
            for r in 0..rules[0].len() {
                let Some(points) = rules.iter().map(|c| c[r]).collect::<Option<Vec<Vec3>>>() else {
                    continue;
                };
                if points == now_points {
                    continue;
                }
                let c = count(&points, false);
                if c < now {
                    tried.push((c, r, points));
                    // Nothing beats none: stop at the first rule that clears all (and
                    // keeps the wall).
                    if c == 0 && count(&tried[tried.len() - 1].2, true) == 0 {
                        break;
                    }
                }
            }
            tried.sort_by_key(|(c, r, _)| (*c, *r));
            let best = tried
                .into_iter()
                .find(|(_, _, points)| count(points, true) == 0)
                .map(|(c, _, points)| (c, points));
            if let Some((_, points)) = best.filter(|(c, _)| *c < now) {
                for (m, q) in members.iter().zip(points) {
                    for &(p, v) in m.iter() {
                        shells[p].back[v] = q;
                        let pt = &mut patients[p];
                        let n = pt.n;
                        for s in &mut pt.solids {
                            s[n + v] = q;
                        }
                        touched[p].extend_from_slice(&pt.incident[n + v]);
                    }
                }
                moved += 1;
                moved_points += unit.len();
            }
        }
        // Fronts that still cross a wall where they fold over the boundary (a sliver at the
        // end of a seam): their points shift by at most the printer resolution, in every
        // piece (a seam point in every part, so the seam stays one curve).
        let mut fronts: Vec<(usize, usize)> = hot
            .iter()
            .enumerate()
            .flat_map(|(p, (_, f, _))| (0..f.len()).filter(|&v| f[v]).map(move |v| (p, v)))
            .map(|(p, v)| group_of[p][v])
            .collect();
        fronts.sort_unstable();
        fronts.dedup();
        for head in fronts {
            let members = &groups[&head];
            if members
                .iter()
                .any(|&(p, _)| frozen.get(p).copied().unwrap_or(true))
            {
                continue;
            }
            let local: Vec<(usize, usize, Vec<u32>, Vec<Near>)> = members
                .iter()
                .map(|&(p, v)| {
                    let pt = &patients[p];
                    let moving = pt.moving(&[v]);
                    let near =
                        pt.neighbourhood(&grids[p], &touched[p], &moving, &[], FRONT_NUDGE_MM);
                    (p, v, moving, near)
                })
                .collect();
            let count = |delta: Vec3, thin: bool| -> usize {
                let mut total = 0;
                for (p, v, moving, near) in &local {
                    let moves = [Move {
                        at: *v,
                        to: delta,
                        shift: true,
                    }];
                    total += patients[*p].count(near, moving, &moves, thin);
                }
                total
            };
            let now = count(Vec3::ZERO, false);
            if now == 0 {
                continue;
            }
            let (p0, v0) = head;
            let pt = &patients[p0];
            let own = pt.normals[v0];
            let adj = &shells[p0].adjacency[v0];
            let inward = if adj.is_empty() {
                Vec3::ZERO
            } else {
                (centroid(&pt.mean_front, adj) - pt.mean_front[v0]).clamp_length_max(FRONT_NUDGE_MM)
            };
            let best = [
                own * 0.4,
                -own * 0.4,
                own,
                -own,
                shells[p0].normals[v0],
                -shells[p0].normals[v0],
            ]
            .into_iter()
            .map(|x| x * FRONT_NUDGE_MM)
            .chain([inward, inward * 0.4])
            .filter(|x| *x != Vec3::ZERO && x.is_finite())
            .filter(|x| {
                members
                    .iter()
                    .all(|&(p, v)| (shells[p].nudge[v] + *x).length() <= FRONT_NUDGE_MM * 1.0001)
            })
            .map(|x| (count(x, false), x))
            .filter(|(c, x)| *c < now && count(*x, true) == 0)
            .min_by_key(|(c, _)| *c);
            if let Some((_, delta)) = best {
                for &(p, v) in members {
                    shells[p].nudge[v] += delta;
                    let pt = &mut patients[p];
                    for s in &mut pt.solids {
                        s[v] += delta;
                    }
                    touched[p].extend_from_slice(&pt.incident[v]);
                }
                moved += 1;
                moved_points += 1;
            }
        }
        if moved == 0 {
            break;
        }
    }
    for ((shell, p), &f) in shells.iter_mut().zip(pieces).zip(frozen) {
        if !f {
            shell.measure(p);
            shell.stats.resolve_rounds = used;
            shell.stats.front_nudged_points =
                shell.nudge.iter().filter(|d| **d != Vec3::ZERO).count();
        }
    }
    moved_points
}
