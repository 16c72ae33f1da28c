//! Adaptive subdivision of smeared frames (issue #22; the paper's limitation "adaptive
//! subdivision where the displacement gradient is high"): a triangle of a low-poly mesh that
//! elongation stretches into a long shard, or sweeps along a curved path, is split until no
//! edge is longer than `tolerance` times its rest length and none cuts across the smear's
//! curve by more than a fraction of it.
//!
//! Every vertex of the subdivided mesh is a blend of at most three input vertices (the
//! corners of the input triangle it lies in). Catmull-Rom is linear in its control points, so
//! its trajectory is the same blend of its parents' trajectories, and it is displaced by the
//! blend of their β: new vertices lie on the smear, not on the straight chord between the
//! displaced parents. Attributes (normals, UVs, colours, scalar attributes, multiples'
//! opacities) are blended with the same weights.
//!
//! An edge is split when either test holds (r its rest length):
//! * **stretch** — it is longer than `tolerance × r`;
//! * **bend** — its midpoint on the smear is off the straight edge by more than
//!   `BEND × (tolerance − 1) × r` ([`BEND`]), or by more than
//!   `DEVIATION_SHARE × (tolerance − 1)` of the frame's 99th-percentile deviation before
//!   subdivision ([`DEVIATION_SHARE`]; the first alone would leave the largest deviations of a
//!   mesh of many small triangles, each a small fraction of its edge, untouched). A triangle
//!   whose centroid on the smear is that far off the flat triangle splits all its edges
//!   (SMEAR §4.1: β and the trajectories vary inside it). Where the parents' β differ, the smear of an edge
//!   is the curve `u ↦ Q_u(h + β_u)` (`Q_u`, `β_u` blended along the edge): a leg swinging
//!   through an arc is smeared along that arc although its edges barely stretch (a rigid
//!   rotation keeps hip-to-foot lengths), so the stretch test alone leaves flat shards. A
//!   split puts the midpoint on the curve and leaves each half about a quarter of the bend,
//!   so repeated splits refine toward the curve.
//!
//! The rest length of an edge is measured on the input frame (the un-smeared drawing): for an
//! edge lying on an input edge, that edge's length; for an edge inside an input triangle, the
//! triangle's longest edge. Decisions are made per edge, so both triangles of an edge split it
//! the same way: the result is crack-free (a split edge's midpoint is shared).

use std::collections::{HashMap, HashSet};

use anim::Mesh;
use glam::Vec3;
use serde::Serialize;

use super::Trajectories;

/// Most rounds of edge splits per frame (each round at most halves every edge).
pub const MAX_SUBDIVISION_LEVELS: usize = 8;

/// The bend test's fraction: with `--subdivide TOL` an edge whose smear midpoint is off the
/// straight edge by more than `BEND × (TOL − 1)` of its rest length is split (5 % at TOL = 2).
pub const BEND: f32 = 0.05;

/// Bends below this fraction of the rest length are rounding, never split (TOL = 1).
const BEND_FLOOR: f32 = 1e-4;

/// The deviation test's share: with `--subdivide TOL` an edge or triangle whose smear is off
/// the flat one by more than `DEVIATION_SHARE × (TOL − 1)` of the frame's 99th-percentile
/// deviation before subdivision is split (a quarter at TOL = 2). The bend test alone is
/// relative to each edge's length, so a mesh of many small triangles, whose deviations are
/// small fractions of their edges, would keep its largest deviations; this one refines the
/// worst places of any mesh until they are a fraction of what they were.
pub const DEVIATION_SHARE: f32 = 0.25;

/// A vertex of the subdivided mesh: weights of up to three input vertices (unused slots 0).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Blend {
    v: [u32; 3],
    w: [f32; 3],
}

impl Blend {
    fn one(v: u32) -> Blend {
        Blend {
            v: [v, v, v],
            w: [1.0, 0.0, 0.0],
        }
    }

    fn support(&self) -> impl Iterator<Item = (u32, f32)> + '_ {
        self.v
            .iter()
            .copied()
            .zip(self.w.iter().copied())
            .filter(|e| e.1 > 0.0)
    }

    /// The midpoint of two blends (supports inside one input triangle: at most three vertices).
    fn mid(a: &Blend, b: &Blend) -> Blend {
        Blend::average(&[a, b])
    }

    /// The average of blends inside one input triangle (a centroid: at most three vertices).
    fn average(blends: &[&Blend]) -> Blend {
        let share = 1.0 / blends.len() as f32;
        let mut out: Vec<(u32, f32)> = Vec::with_capacity(9);
        for (v, w) in blends.iter().flat_map(|b| b.support()) {
            match out.iter_mut().find(|e| e.0 == v) {
                Some(e) => e.1 += share * w,
                None => out.push((v, share * w)),
            }
        }
        out.sort_by(|x, y| y.1.total_cmp(&x.1));
        out.truncate(3);
        let sum: f32 = out.iter().map(|e| e.1).sum();
        let mut r = Blend {
            v: [out[0].0; 3],
            w: [0.0; 3],
        };
        for (k, (v, w)) in out.into_iter().enumerate() {
            r.v[k] = v;
            r.w[k] = w / sum;
        }
        r
    }

    fn count(&self) -> usize {
        self.w.iter().filter(|w| **w > 0.0).count()
    }

    fn lerp<T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>>(
        &self,
        values: &[T],
    ) -> T {
        let mut acc = values[self.v[0] as usize] * self.w[0];
        for k in 1..3 {
            if self.w[k] > 0.0 {
                acc = acc + values[self.v[k] as usize] * self.w[k];
            }
        }
        acc
    }
}

/// What subdividing one frame did.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct SubdivisionStats {
    /// Triangles after subdivision.
    pub triangles: usize,
    /// Vertices after subdivision.
    pub vertices: usize,
    /// Largest ratio of an output edge's length to its rest length.
    pub max_stretch: f32,
    /// The achieved error: the largest distance (scene units) between the smear and the
    /// output's flat triangles, measured where it is largest between vertices that lie on
    /// the smear — at every edge's midpoint and every triangle's centroid.
    pub max_error: f32,
}

/// One smeared frame, adaptively subdivided.
///
/// # Arguments
/// * `tr` — the trajectories the frame was displaced along (causal mode, arcs, ground and
///   colliders apply).
/// * `mesh` — the input mesh (triangles and attributes; its positions are not used).
/// * `h` — the drawing's frame: rest lengths are measured on `tr.frame(h)`.
/// * `beta` — β of every input vertex at this frame, in frames.
/// * `alpha` — optional per-vertex opacities, blended into the output's colour alpha with
///   colour `rgb`.
/// * `tolerance` — split edges longer than `tolerance ×` their rest length (e.g. 2), or
///   whose smear bends away from them by more than [`BEND`]` × (tolerance − 1)` of it or
///   [`DEVIATION_SHARE`]` × (tolerance − 1)` of the frame's 99th-percentile deviation.
///
/// # Performance
/// One trajectory evaluation per parent of every edge's midpoint, per round; hash map of
/// edges per round.
pub fn subdivide_frame(
    tr: &Trajectories<'_>,
    mesh: &Mesh,
    h: usize,
    beta: &[f32],
    alpha: Option<(&[f32], [f32; 3])>,
    tolerance: f32,
) -> (Mesh, SubdivisionStats) {
    let (out, _, stats) = subdivide(tr, mesh, h, beta, alpha, tolerance);
    (out, stats)
}

/// A frame around a moving frame: its held frame and its elongation β per input vertex.
pub type AroundFrame<'a> = (usize, &'a [f32]);

/// [`subdivide_frame`] of a moving frame, with every output vertex also placed on the frames
/// `around` it (`[before, after]`, `None` past an end of the clip): the same surface point —
/// the same blend of input vertices — on those frames' in-betweens. Each vertex's velocity is
/// then the derivative of its own trajectory ([`trajectory_velocities`]), consistent with the
/// in-betweens it is placed on: a vertex placed on a curved smear moves with the curve, not
/// as the average of its parents (whose velocity lies off the smear).
pub fn subdivide_moving_frame(
    tr: &Trajectories<'_>,
    mesh: &Mesh,
    h: usize,
    beta: &[f32],
    alpha: Option<(&[f32], [f32; 3])>,
    tolerance: f32,
    around: [Option<AroundFrame<'_>>; 2],
) -> (Mesh, [Option<Vec<Vec3>>; 2], SubdivisionStats) {
    let (out, blends, stats) = subdivide(tr, mesh, h, beta, alpha, tolerance);
    let placed = around.map(|a| {
        a.map(|(h, beta)| {
            blends
                .iter()
                .map(|b| place(tr, h, beta, b))
                .collect::<Vec<Vec3>>()
        })
    });
    (out, placed, stats)
}

/// Per-frame velocities (units per frame) of points at `current` that are at `around`
/// (`[before, after]`) on the frames around: the central difference, one-sided at an end
/// (zero when the clip has one frame) — as SPEC's velocities of a point cache.
pub fn trajectory_velocities(current: &[Vec3], around: &[Option<Vec<Vec3>>; 2]) -> Vec<Vec3> {
    let (before, after, span) = match around {
        [Some(b), Some(a)] => (b.as_slice(), a.as_slice(), 2.0),
        [Some(b), None] => (b.as_slice(), current, 1.0),
        [None, Some(a)] => (current, a.as_slice(), 1.0),
        [None, None] => (current, current, 1.0),
    };
    before
        .iter()
        .zip(after)
        .map(|(b, a)| (*a - *b) / span)
        .collect()
}

/// Where the surface point `b` (a blend of input vertices) lies on the in-between of held
/// frame `h` elongated by `beta`: an input vertex on its own trajectory, a blend on the
/// trajectory of its point (offset interpolated), lifted off the flat triangle as the smear.
fn place(tr: &Trajectories<'_>, h: usize, beta: &[f32], b: &Blend) -> Vec3 {
    if b.count() == 1 {
        return tr.displaced(h, b.v[0] as usize, beta[b.v[0] as usize]);
    }
    let bb: f32 = b.support().map(|(v, w)| w * beta[v as usize]).sum();
    let bb = if bb.is_finite() { bb } else { 0.0 };
    let p: Vec3 = b
        .support()
        .map(|(v, w)| tr.seen_from(h, v as usize, h as f32 + bb) * w)
        .sum();
    tr.lifted(h, p)
}

/// [`subdivide_frame`], also returning every output vertex's blend of input vertices.
fn subdivide(
    tr: &Trajectories<'_>,
    mesh: &Mesh,
    h: usize,
    beta: &[f32],
    alpha: Option<(&[f32], [f32; 3])>,
    tolerance: f32,
) -> (Mesh, Vec<Blend>, SubdivisionStats) {
    let rest = tr.frame(h);
    let place = |b: &Blend| place(tr, h, beta, b);
    let mut blends: Vec<Blend> = (0..mesh.vertex_count() as u32).map(Blend::one).collect();
    let mut pos: Vec<Vec3> = blends.iter().map(place).collect();
    // Per triangle: its input triangle (for rest lengths).
    let mut tris: Vec<([u32; 3], u32)> = mesh
        .triangles
        .iter()
        .enumerate()
        .map(|(k, t)| (*t, k as u32))
        .collect();
    let rest_len = |a: u32, b: u32| rest[a as usize].distance(rest[b as usize]);
    // The rest length of an input triangle: its longest edge.
    let face_rest = |t: u32| {
        let [x, y, z] = mesh.triangles[t as usize];
        rest_len(x, y).max(rest_len(y, z)).max(rest_len(z, x))
    };
    let reference = |blends: &[Blend], a: u32, b: u32, t: u32| -> f32 {
        let mut s: Vec<u32> = blends[a as usize]
            .support()
            .chain(blends[b as usize].support())
            .map(|e| e.0)
            .collect();
        s.sort_unstable();
        s.dedup();
        match s.as_slice() {
            [u, v] => rest_len(*u, *v),
            _ => face_rest(t),
        }
    };
    let bend = (BEND * (tolerance - 1.0)).max(BEND_FLOOR);
    let deviation =
        DEVIATION_SHARE * (tolerance - 1.0).max(0.0) * initial_deviation(mesh, &pos, &place);
    // Whether a deviation `d` of the smear from an element of rest length `r` is split.
    let too_far = |d: f32, r: f32| d > (bend * r).min(deviation.max(BEND_FLOOR * r));
    let mut mids: HashMap<(u32, u32), u32> = HashMap::new();
    // Edges found short and straight: their ends never move, so they stay unsplit.
    let mut kept: HashSet<(u32, u32)> = HashSet::new();
    for _ in 0..MAX_SUBDIVISION_LEVELS {
        // Per edge: its midpoint (blend and place on the smear) when it is split.
        let mut split: HashMap<(u32, u32), Option<(Blend, Vec3)>> = HashMap::new();
        let mut any = false;
        for &(t, orig) in &tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                if split.contains_key(&key) || kept.contains(&key) {
                    continue;
                }
                let r = reference(&blends, a, b, orig);
                let (pa, pb) = (pos[a as usize], pos[b as usize]);
                let mut mid = None;
                if r > 0.0 {
                    let nb = Blend::mid(&blends[key.0 as usize], &blends[key.1 as usize]);
                    let q = place(&nb);
                    let long = pa.distance(pb) > tolerance * r;
                    let bent = too_far(q.distance(0.5 * (pa + pb)), r);
                    if long || bent {
                        mid = Some((nb, q));
                    }
                }
                match mid {
                    Some(_) => any = true,
                    None => {
                        kept.insert(key);
                    }
                }
                split.insert(key, mid);
            }
        }
        // Face test: a triangle whose edges all follow the smear can still bulge away from
        // it inside (β and the trajectories vary across it): its centroid on the smear is
        // compared with the flat triangle's, and a bulging triangle splits all its edges.
        for &(t, orig) in &tris {
            let keys = [0, 1, 2].map(|k| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                (a.min(b), a.max(b))
            });
            if keys
                .iter()
                .any(|key| matches!(split.get(key), Some(Some(_))))
            {
                continue;
            }
            let r = face_rest(orig);
            let [u, v, w] = t.map(|v| &blends[v as usize]);
            let c = Blend::average(&[u, v, w]);
            let flat = t.iter().map(|&v| pos[v as usize]).sum::<Vec3>() / 3.0;
            if r > 0.0 && too_far(place(&c).distance(flat), r) {
                for key in keys {
                    let nb = Blend::mid(&blends[key.0 as usize], &blends[key.1 as usize]);
                    let q = place(&nb);
                    kept.remove(&key);
                    split.insert(key, Some((nb, q)));
                }
                any = true;
            }
        }
        if !any {
            break;
        }
        let mut next = Vec::with_capacity(tris.len() * 2);
        for &(t, orig) in &tris {
            let mut m = [u32::MAX; 3];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                if let Some(Some((nb, q))) = split.get(&key) {
                    m[k] = *mids.entry(key).or_insert_with(|| {
                        blends.push(*nb);
                        pos.push(*q);
                        (blends.len() - 1) as u32
                    });
                }
            }
            split_triangle(t, m, orig, &mut next);
        }
        tris = next;
    }
    let (mut max_stretch, mut max_error) = (0.0f32, 0.0f32);
    for &(t, orig) in &tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let r = reference(&blends, a, b, orig);
            if r > 0.0 {
                max_stretch = max_stretch.max(pos[a as usize].distance(pos[b as usize]) / r);
            }
            if a < b {
                let mid = place(&Blend::mid(&blends[a as usize], &blends[b as usize]));
                max_error = max_error.max(mid.distance(0.5 * (pos[a as usize] + pos[b as usize])));
            }
        }
        let [u, v, w] = t.map(|v| &blends[v as usize]);
        let flat = t.iter().map(|&v| pos[v as usize]).sum::<Vec3>() / 3.0;
        max_error = max_error.max(place(&Blend::average(&[u, v, w])).distance(flat));
    }
    let mut out = Mesh::new(mesh.name.clone(), pos, tris.iter().map(|t| t.0).collect());
    out.normals = mesh.normals.as_ref().map(|n| {
        blends
            .iter()
            .map(|b| b.lerp(n).try_normalize().unwrap_or(Vec3::Y))
            .collect()
    });
    out.uvs = mesh.uvs.as_ref().map(|uv| {
        blends
            .iter()
            .map(|b| {
                let u: [f32; 2] =
                    [0, 1].map(|c| b.support().map(|(v, w)| w * uv[v as usize][c]).sum::<f32>());
                u
            })
            .collect()
    });
    out.colors = match alpha {
        Some((a, [r, g, bl])) => Some(blends.iter().map(|b| [r, g, bl, b.lerp(a)]).collect()),
        None => mesh.colors.as_ref().map(|c| {
            blends
                .iter()
                .map(|b| {
                    [0, 1, 2, 3]
                        .map(|k| b.support().map(|(v, w)| w * c[v as usize][k]).sum::<f32>())
                })
                .collect()
        }),
    };
    out.attributes = mesh
        .attributes
        .iter()
        .map(|(k, vals)| (k.clone(), blends.iter().map(|b| b.lerp(vals)).collect()))
        .collect();
    let stats = SubdivisionStats {
        triangles: out.triangle_count(),
        vertices: out.vertex_count(),
        max_stretch,
        max_error: if max_error.is_finite() {
            max_error
        } else {
            0.0
        },
    };
    (out, blends, stats)
}

/// The 99th percentile of the unsubdivided frame's deviations from the smear: at every edge's
/// midpoint and every triangle's centroid, the distance between the point on the smear and
/// the point on the flat triangle through the smeared vertices `corners`.
fn initial_deviation(mesh: &Mesh, corners: &[Vec3], place: &dyn Fn(&Blend) -> Vec3) -> f32 {
    let mut d = Vec::with_capacity(mesh.triangles.len() * 4);
    for t in &mesh.triangles {
        let b = t.map(Blend::one);
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            if u < v {
                let flat = 0.5 * (corners[u as usize] + corners[v as usize]);
                d.push(place(&Blend::mid(&b[k], &b[(k + 1) % 3])).distance(flat));
            }
        }
        let flat = t.iter().map(|&v| corners[v as usize]).sum::<Vec3>() / 3.0;
        d.push(place(&Blend::average(&[&b[0], &b[1], &b[2]])).distance(flat));
    }
    d.retain(|x| x.is_finite());
    if d.is_empty() {
        return 0.0;
    }
    let k = ((d.len() - 1) as f32 * 0.99) as usize;
    *d.select_nth_unstable_by(k, f32::total_cmp).1
}

/// Splits triangle `t` (its input triangle `orig`) at the midpoints `m` of its edges
/// (`m[k]` on edge `t[k] → t[k+1]`, `u32::MAX` when not split), keeping the winding.
fn split_triangle(t: [u32; 3], m: [u32; 3], orig: u32, out: &mut Vec<([u32; 3], u32)>) {
    let on = |k: usize| m[k] != u32::MAX;
    let n = (0..3).filter(|&k| on(k)).count();
    // Rotate so the split edges come first (one: edge 0; two: edges 0 and 1).
    let r = (0..3)
        .find(|&r| match n {
            1 => on(r),
            2 => on(r) && on((r + 1) % 3),
            _ => true,
        })
        .unwrap_or(0);
    let [a, b, c] = [t[r], t[(r + 1) % 3], t[(r + 2) % 3]];
    let [m0, m1, m2] = [m[r], m[(r + 1) % 3], m[(r + 2) % 3]];
    let mut push = |x: [u32; 3]| out.push((x, orig));
    match n {
        0 => push(t),
        1 => {
            push([a, m0, c]);
            push([m0, b, c]);
        }
        2 => {
            push([m0, b, m1]);
            push([a, m0, m1]);
            push([a, m1, c]);
        }
        _ => {
            push([a, m0, m2]);
            push([m0, b, m1]);
            push([m2, m1, c]);
            push([m0, m1, m2]);
        }
    }
}
