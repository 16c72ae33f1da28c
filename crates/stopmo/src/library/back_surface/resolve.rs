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

use super::{centroid, position_key, PartShell};
use crate::library::intersect::{degenerate, intersecting_pairs, triangles_cross};
use crate::library::nearest::closest_point_on_triangle;

/// Rings of back vertices around the crossing ones that may move too.
const RESOLVE_RINGS: usize = 1;

/// Deeper steps tried along the direction field, in walls.
const DEEPER_WALLS: [f32; 3] = [0.25, 0.5, 1.0];

/// A uniform grid of triangle boxes of one piece's solid, built once per round.
struct BoxGrid {
    cell: f32,
    cells: HashMap<[i32; 3], Vec<u32>>,
}

impl BoxGrid {
    fn new(positions: &[Vec3], tris: &[[u32; 3]], cell: f32) -> BoxGrid {
        let mut cells: HashMap<[i32; 3], Vec<u32>> = HashMap::new();
        for (t, tri) in tris.iter().enumerate() {
            let (lo, hi) = bounds(tri.map(|v| positions[v as usize]));
            let (a, b) = (key(lo, cell), key(hi, cell));
            for x in a[0]..=b[0] {
                for y in a[1]..=b[1] {
                    for z in a[2]..=b[2] {
                        cells.entry([x, y, z]).or_default().push(t as u32);
                    }
                }
            }
        }
        BoxGrid { cell, cells }
    }

    /// Triangles whose box (when the grid was built) overlaps cells of `lo..hi`, sorted.
    fn near(&self, lo: Vec3, hi: Vec3) -> Vec<u32> {
        let (a, b) = (key(lo, self.cell), key(hi, self.cell));
        let mut out = Vec::new();
        for x in a[0]..=b[0] {
            for y in a[1]..=b[1] {
                for z in a[2]..=b[2] {
                    if let Some(list) = self.cells.get(&[x, y, z]) {
                        out.extend_from_slice(list);
                    }
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

fn key(p: Vec3, cell: f32) -> [i32; 3] {
    (p / cell).floor().to_array().map(|x| x as i32)
}

fn bounds(t: [Vec3; 3]) -> (Vec3, Vec3) {
    (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]))
}

fn boxes_overlap(a: (Vec3, Vec3), b: (Vec3, Vec3)) -> bool {
    !(a.0.cmpgt(b.1).any() || b.0.cmpgt(a.1).any())
}

/// A move of one solid vertex (`at`: front `v` or back `n + v`) to a point, or (`shift`)
/// by a vector in every piece.
#[derive(Debug, Clone, Copy)]
struct Move {
    at: usize,
    to: Vec3,
    shift: bool,
}

/// How far a front point may move to clear a crossing (mm): the default printer
/// resolution, below which a print does not change.
const FRONT_NUDGE_MM: f32 = 0.05;

/// One part under search: its solids' topology and positions per piece.
struct Patient {
    /// Back vertex count `n` (back copy of `v` is `n + v` in a solid).
    n: usize,
    tris: Vec<[u32; 3]>,
    /// Front and back positions of every piece's solid.
    solids: Vec<Vec<Vec3>>,
    /// Solid triangles incident to each solid vertex (front `v`, back `n + v`).
    incident: Vec<Vec<u32>>,
    /// Previous and next vertex along the boundary loops.
    along: Vec<[u32; 2]>,
    /// Mean front over the pieces.
    mean_front: Vec<Vec3>,
    /// Vertex normals of the mean front (outward).
    normals: Vec<Vec3>,
    /// Nearest a back triangle may come to a front vertex.
    floor: f32,
    /// Mean triangle box size (grid cells).
    size: f32,
}

impl Patient {
    fn new(shell: &PartShell, pieces: &[&[Vec3]], wall_mm: f64) -> Patient {
        let n = shell.back.len();
        let tris = shell.solid_topology();
        let fronts: Vec<Vec<Vec3>> = pieces.iter().map(|p| shell.front(p)).collect();
        let mean_front: Vec<Vec3> = (0..n)
            .map(|v| fronts.iter().map(|f| f[v]).sum::<Vec3>() / fronts.len().max(1) as f32)
            .collect();
        let normals = anim::vertex_normals(&mean_front, &shell.triangles);
        let mut incident: Vec<Vec<u32>> = vec![Vec::new(); 2 * n];
        for (t, tri) in tris.iter().enumerate() {
            for &v in tri {
                incident[v as usize].push(t as u32);
            }
        }
        let mut along: Vec<[u32; 2]> = vec![[u32::MAX; 2]; n];
        for &(a, b) in &shell.boundary {
            along[a as usize][1] = b;
            along[b as usize][0] = a;
        }
        // A little under the thinnest wall now, so rounding never rejects the current state.
        let floor = (shell.min_wall_of(pieces).min(wall_mm) - 1e-4) as f32;
        let size = {
            let s: f32 = tris
                .iter()
                .map(|t| {
                    let (lo, hi) = bounds(t.map(|v| shell.back[v as usize % n]));
                    (hi - lo).max_element()
                })
                .sum();
            (s / tris.len().max(1) as f32).max(1e-3)
        };
        let solids = fronts
            .into_iter()
            .map(|mut f| {
                f.extend_from_slice(&shell.back);
                f
            })
            .collect();
        Patient {
            n,
            tris,
            solids,
            incident,
            along,
            mean_front,
            normals,
            floor,
            size,
        }
    }

    /// Shell vertices whose back copy (first) or front (second) belongs to a triangle that
    /// crosses in some piece, and the crossing triangles summed over pieces.
    fn hot(&self) -> (Vec<bool>, Vec<bool>, usize) {
        let pairs: Vec<Vec<(u32, u32)>> = self
            .solids
            .par_iter()
            .map(|p| intersecting_pairs(p, &self.tris).unwrap_or_default())
            .collect();
        let mut hot = vec![false; self.n];
        let mut hot_front = vec![false; self.n];
        let mut count = 0;
        for piece in &pairs {
            let mut crossing: Vec<u32> = piece.iter().flat_map(|&(i, j)| [i, j]).collect();
            crossing.sort_unstable();
            crossing.dedup();
            count += crossing.len();
            for t in crossing {
                for &v in &self.tris[t as usize] {
                    if v as usize >= self.n {
                        hot[v as usize - self.n] = true;
                    } else {
                        hot_front[v as usize] = true;
                    }
                }
            }
        }
        (hot, hot_front, count)
    }

    /// Solid triangles incident to the solid vertices `at`, sorted.
    fn moving(&self, at: &[usize]) -> Vec<u32> {
        let mut moving: Vec<u32> = at
            .iter()
            .flat_map(|&a| self.incident[a].iter().copied())
            .collect();
        moving.sort_unstable();
        moving.dedup();
        moving
    }

    /// Per piece, what the triangles `moving` may meet while their moved vertices take any
    /// of the points `extra` (or shift by up to `pad`): the triangles near them (`touched`
    /// ones, moved after `grids` were built, always) and the front vertices among those.
    fn neighbourhood(
        &self,
        grids: &[BoxGrid],
        touched: &[u32],
        moving: &[u32],
        extra: &[Vec3],
        pad: f32,
    ) -> Vec<Near> {
        let reach = self.floor + pad;
        self.solids
            .par_iter()
            .zip(grids)
            .map(|(pos, grid)| {
                let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
                for &t in moving {
                    let (a, b) = bounds(self.tris[t as usize].map(|i| pos[i as usize]));
                    lo = lo.min(a);
                    hi = hi.max(b);
                }
                for &q in extra {
                    lo = lo.min(q);
                    hi = hi.max(q);
                }
                let (lo, hi) = (lo - reach, hi + reach);
                let mut tris = grid.near(lo, hi);
                tris.extend_from_slice(touched);
                tris.sort_unstable();
                tris.dedup();
                // The moving triangles are tested against each other apart.
                tris.retain(|t| moving.binary_search(t).is_err());
                let boxes: Vec<(Vec3, Vec3)> = tris
                    .iter()
                    .map(|&t| bounds(self.tris[t as usize].map(|i| pos[i as usize])))
                    .collect();
                let mut fronts: Vec<u32> = tris
                    .iter()
                    .chain(moving)
                    .flat_map(|&t| self.tris[t as usize])
                    .filter(|&f| (f as usize) < self.n)
                    .collect();
                fronts.sort_unstable();
                fronts.dedup();
                let back_tris = tris
                    .iter()
                    .copied()
                    .filter(|&t| self.tris[t as usize].iter().all(|&i| i as usize >= self.n))
                    .collect();
                Near {
                    tris,
                    boxes,
                    fronts,
                    back_tris,
                }
            })
            .collect()
    }

    /// Crossing pairs of the triangles `moving` (those incident to the moved vertices) over
    /// all pieces after `moves` (`near` from [`Patient::neighbourhood`] for these moves), or
    /// with `thin`, whether a back triangle comes nearer than the floor to a front vertex
    /// (1) or not (0).
    fn count(&self, near: &[Near], moving: &[u32], moves: &[Move], thin: bool) -> usize {
        let (n, tris) = (self.n, &self.tris);
        let floor = self.floor;
        let per_piece = |k: usize| -> usize {
            let pos = &self.solids[k];
            let near = &near[k];
            let at = |i: u32| {
                let i = i as usize;
                moves.iter().find(|m| m.at == i).map_or(pos[i], |m| {
                    if m.shift {
                        pos[i] + m.to
                    } else {
                        m.to
                    }
                })
            };
            let corners = |t: u32| tris[t as usize].map(at);
            let mut hits = 0;
            for &t in moving {
                let a = corners(t);
                let ba = bounds(a);
                if thin {
                    if tris[t as usize].iter().all(|&i| i as usize >= n) {
                        // The wall in front of a moved back triangle.
                        let reach = (ba.0 - floor, ba.1 + floor);
                        for &f in &near.fronts {
                            let p = at(f);
                            if !(p.cmplt(reach.0).any() || p.cmpgt(reach.1).any())
                                && p.distance(closest_point_on_triangle(p, a[0], a[1], a[2]))
                                    < floor
                            {
                                return 1;
                            }
                        }
                    }
                    continue;
                }
                if degenerate(a) {
                    hits += 1;
                    continue;
                }
                for (&u, &bu) in near.tris.iter().zip(&near.boxes) {
                    if boxes_overlap(ba, bu)
                        && triangles_cross(
                            tris[t as usize],
                            a,
                            tris[u as usize],
                            tris[u as usize].map(|i| pos[i as usize]),
                        )
                    {
                        hits += 1;
                    }
                }
                // Pairs of moving triangles, each once.
                for &u in moving.iter().filter(|&&u| u > t) {
                    let b = corners(u);
                    if boxes_overlap(ba, bounds(b))
                        && triangles_cross(tris[t as usize], a, tris[u as usize], b)
                    {
                        hits += 1;
                    }
                }
            }
            if !thin {
                return hits;
            }
            // The wall behind a moved front vertex.
            for m in moves.iter().filter(|m| m.at < n) {
                let p = at(m.at as u32);
                for &u in near.back_tris.iter().chain(moving) {
                    if tris[u as usize].iter().any(|&i| (i as usize) < n) {
                        continue;
                    }
                    let b = corners(u);
                    let (lo, hi) = bounds(b);
                    if !(p.cmplt(lo - floor).any() || p.cmpgt(hi + floor).any())
                        && p.distance(closest_point_on_triangle(p, b[0], b[1], b[2])) < floor
                    {
                        return 1;
                    }
                }
            }
            0
        };
        if thin {
            usize::from(
                (0..self.solids.len())
                    .into_par_iter()
                    .any(|k| per_piece(k) > 0),
            )
        } else {
            (0..self.solids.len()).into_par_iter().map(per_piece).sum()
        }
    }
}

/// One part's share of a move: the moved solid vertices (group of the unit, solid vertex),
/// the triangles incident to them, and what those may meet in every piece.
type PartMoves = (Vec<(usize, usize)>, Vec<u32>, Vec<Near>);

/// What moving triangles may meet in one piece ([`Patient::neighbourhood`]).
struct Near {
    /// Solid triangles that do not move (sorted).
    tris: Vec<u32>,
    /// Their bounding boxes.
    boxes: Vec<(Vec3, Vec3)>,
    /// Front vertices of those triangles.
    fronts: Vec<u32>,
    /// Those triangles that belong to the back.
    back_tris: Vec<u32>,
}

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

impl PartShell {
    /// Positions tried for back vertex `v` (`patient` this part under search), each kept
    /// behind the envelope of every part in `members` (the vertices moving with it): always
    /// the same rules in the same order (`None` where a rule does not apply), so that two
    /// points can move by the same rule together.
    fn candidates(
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
