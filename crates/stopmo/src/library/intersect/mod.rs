//! Exact triangle–triangle intersection and a self-intersection count for printable solids.
//!
//! Coordinates are snapped to a grid of 2⁻²⁴ units (6·10⁻⁸ mm for solids in millimetres) and
//! every orientation test is evaluated exactly in `i128`, so the answer does not depend on
//! rounding: two triangles intersect when their closed point sets share a point, except that
//! triangles sharing a vertex (or an edge) only count when they meet anywhere else. A grid of
//! cells about the size of the mean triangle limits the exact tests to nearby pairs.

use glam::Vec3;
use rayon::prelude::*;

use super::nearest::TriangleGrid;

/// Largest coordinate magnitude (in the mesh's units) the exact test accepts: `2¹²`, so snapped
/// coordinates fit 36 bits and orientation determinants fit `i128`.
pub const MAX_EXACT_COORDINATE: f32 = 4096.0;

const GRID: f64 = (1u64 << 24) as f64;

type P = [i64; 3];

/// Nearest grid point (ties away from zero, as `f64::round`). An `f32` times 2²⁴ is exact in
/// `f64` with at most 24 significant bits, so adding ½ is exact wherever it could matter and
/// the truncating cast rounds like `round` without its library call (the hot path of the
/// searches that move points and test again).
fn snap(p: Vec3) -> P {
    let r = |x: f32| {
        let x = f64::from(x) * GRID;
        (x + 0.5f64.copysign(x)) as i64
    };
    [r(p.x), r(p.y), r(p.z)]
}

/// Relative error bound of [`orient3d`]'s floating-point determinant over its permanent
/// (Shewchuk's `o3derrboundA` ≈ 7.8·10⁻¹⁶, with a margin): beyond it the sign is certain.
const ORIENT3D_FILTER: f64 = 4.0e-15;
/// Relative error bound of [`orient2d`]'s floating-point determinant (Shewchuk's
/// `ccwerrboundA` ≈ 3.3·10⁻¹⁶, with a margin).
const ORIENT2D_FILTER: f64 = 2.0e-15;

fn sub(a: P, b: P) -> [i128; 3] {
    [
        i128::from(a[0] - b[0]),
        i128::from(a[1] - b[1]),
        i128::from(a[2] - b[2]),
    ]
}

/// Sign of the volume of the tetrahedron `(a, b, c, d)` (positive when `d` is below the plane
/// of the counter-clockwise triangle `a b c`, following Shewchuk's convention).
fn orient3d(a: P, b: P, c: P, d: P) -> i32 {
    Plane::new([a, b, c]).side(d)
}

/// The plane of a triangle, for the side of any number of points ([`orient3d`] with the
/// normal computed once: a pair of triangles tests up to six points against each plane).
///
/// Differences of snapped points (≤ 2³⁷) are exact in `f64`; a side is the sign of the `f64`
/// determinant when it is beyond [`ORIENT3D_FILTER`] times its permanent (about 6 roundings
/// of it at most), and of the `i128` one ([`orient3d_exact`]) within, so always the exact one.
struct Plane {
    corners: [P; 3],
    /// `(t1 − t0) × (t2 − t0)`.
    normal: [f64; 3],
    /// The normal's components with the products' magnitudes added (the permanent's).
    weight: [f64; 3],
}

impl Plane {
    fn new(corners: [P; 3]) -> Plane {
        let [e1, e2] = [corners[1], corners[2]].map(|p| Plane::from_origin(corners[0], p));
        let m = [
            (e1[1] * e2[2], e1[2] * e2[1]),
            (e1[2] * e2[0], e1[0] * e2[2]),
            (e1[0] * e2[1], e1[1] * e2[0]),
        ];
        Plane {
            corners,
            normal: m.map(|(x, y)| x - y),
            weight: m.map(|(x, y)| x.abs() + y.abs()),
        }
    }

    /// `p − o`, exact in `f64`.
    fn from_origin(o: P, p: P) -> [f64; 3] {
        [0, 1, 2].map(|k| (p[k] - o[k]) as f64)
    }

    /// `orient3d(t0, t1, t2, p) = −(p − t0)·((t1 − t0) × (t2 − t0))`.
    fn side(&self, p: P) -> i32 {
        let d = Plane::from_origin(self.corners[0], p);
        let (n, w) = (self.normal, self.weight);
        let det = -(d[0] * n[0] + d[1] * n[1] + d[2] * n[2]);
        let bound = ORIENT3D_FILTER * (d[0].abs() * w[0] + d[1].abs() * w[1] + d[2].abs() * w[2]);
        if det > bound {
            1
        } else if -det > bound {
            -1
        } else {
            let [a, b, c] = self.corners;
            orient3d_exact(a, b, c, p)
        }
    }
}

/// [`orient3d`] in `i128` arithmetic.
fn orient3d_exact(a: P, b: P, c: P, d: P) -> i32 {
    let (u, v, w) = (sub(a, d), sub(b, d), sub(c, d));
    let det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0]);
    det.signum() as i32
}

/// The two coordinate axes kept when projecting a plane with normal `n` (drop its largest
/// component).
fn projection_axes(a: P, b: P, c: P) -> (usize, usize) {
    let (u, v) = (sub(b, a), sub(c, a));
    let n = [
        (u[1] * v[2] - u[2] * v[1]).abs(),
        (u[2] * v[0] - u[0] * v[2]).abs(),
        (u[0] * v[1] - u[1] * v[0]).abs(),
    ];
    if n[0] >= n[1] && n[0] >= n[2] {
        (1, 2)
    } else if n[1] >= n[2] {
        (2, 0)
    } else {
        (0, 1)
    }
}

type Q = [i128; 2];

/// Sign of the signed area of `a b c` (positive counter-clockwise); filtered in `f64` like
/// [`orient3d`], exact in `i128`.
fn orient2d(a: Q, b: Q, c: Q) -> i32 {
    let l = (b[0] - a[0]) as f64 * (c[1] - a[1]) as f64;
    let r = (b[1] - a[1]) as f64 * (c[0] - a[0]) as f64;
    let (det, bound) = (l - r, ORIENT2D_FILTER * (l.abs() + r.abs()));
    if det > bound {
        return 1;
    }
    if -det > bound {
        return -1;
    }
    orient2d_exact(a, b, c)
}

/// [`orient2d`] in `i128` arithmetic.
fn orient2d_exact(a: Q, b: Q, c: Q) -> i32 {
    ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).signum() as i32
}

/// Closed segments `ab` and `cd` share a point (2D).
fn segments_meet_2d(a: Q, b: Q, c: Q, d: Q) -> bool {
    let (o1, o2, o3, o4) = (
        orient2d(a, b, c),
        orient2d(a, b, d),
        orient2d(c, d, a),
        orient2d(c, d, b),
    );
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return true;
    }
    let on = |p: Q, q: Q, r: Q| {
        r[0] >= p[0].min(q[0])
            && r[0] <= p[0].max(q[0])
            && r[1] >= p[1].min(q[1])
            && r[1] <= p[1].max(q[1])
    };
    (o1 == 0 && on(a, b, c))
        || (o2 == 0 && on(a, b, d))
        || (o3 == 0 && on(c, d, a))
        || (o4 == 0 && on(c, d, b))
}

/// `p` lies in the closed triangle `t` (2D, either orientation).
fn point_in_triangle_2d(p: Q, t: [Q; 3]) -> bool {
    let o = [
        orient2d(t[0], t[1], p),
        orient2d(t[1], t[2], p),
        orient2d(t[2], t[0], p),
    ];
    !(o.iter().any(|&x| x > 0) && o.iter().any(|&x| x < 0))
}

fn project(p: P, axes: (usize, usize)) -> Q {
    [i128::from(p[axes.0]), i128::from(p[axes.1])]
}

/// Closed segment `pq` meets closed triangle `t` (3D, exact).
fn segment_meets_triangle(p: P, q: P, t: [P; 3]) -> bool {
    let plane = Plane::new(t);
    let (op, oq) = (plane.side(p), plane.side(q));
    segment_meets_triangle_given(p, q, op, oq, t)
}

/// [`segment_meets_triangle`] with the sides `op`, `oq` of `p` and `q` to the plane of `t`
/// (`orient3d(t[0], t[1], t[2], ·)`) already known.
fn segment_meets_triangle_given(p: P, q: P, op: i32, oq: i32, t: [P; 3]) -> bool {
    if op * oq > 0 {
        return false;
    }
    if op == 0 && oq == 0 {
        let axes = projection_axes(t[0], t[1], t[2]);
        let (a, b) = (project(p, axes), project(q, axes));
        let tt = t.map(|v| project(v, axes));
        return point_in_triangle_2d(a, tt)
            || point_in_triangle_2d(b, tt)
            || (0..3).any(|k| segments_meet_2d(a, b, tt[k], tt[(k + 1) % 3]));
    }
    let s = [
        orient3d(p, q, t[0], t[1]),
        orient3d(p, q, t[1], t[2]),
        orient3d(p, q, t[2], t[0]),
    ];
    !(s.iter().any(|&x| x > 0) && s.iter().any(|&x| x < 0))
}

/// Closed triangles share a point (exact; no shared vertex assumed).
fn triangles_meet(a: [P; 3], b: [P; 3]) -> bool {
    let plane_b = Plane::new(b);
    let oa = a.map(|v| plane_b.side(v));
    if oa.iter().all(|&o| o > 0) || oa.iter().all(|&o| o < 0) {
        return false;
    }
    let plane_a = Plane::new(a);
    let ob = b.map(|v| plane_a.side(v));
    if ob.iter().all(|&o| o > 0) || ob.iter().all(|&o| o < 0) {
        return false;
    }
    // The intersection (if any) is a segment whose ends lie on an edge of one triangle inside
    // the other (also in the coplanar case, or a vertex of one lies inside the other).
    (0..3).any(|k| segment_meets_triangle_given(a[k], a[(k + 1) % 3], oa[k], oa[(k + 1) % 3], b))
        || (0..3)
            .any(|k| segment_meets_triangle_given(b[k], b[(k + 1) % 3], ob[k], ob[(k + 1) % 3], a))
}

/// Triangles `a` and `b` share exactly the vertex at corner `ia` of `a` and `ib` of `b`: do they
/// meet anywhere else?
fn meet_beyond_vertex(a: [P; 3], ia: usize, b: [P; 3], ib: usize) -> bool {
    let (a1, a2) = (a[(ia + 1) % 3], a[(ia + 2) % 3]);
    let (b1, b2) = (b[(ib + 1) % 3], b[(ib + 2) % 3]);
    let plane = Plane::new(b);
    let (o1, o2) = (plane.side(a1), plane.side(a2));
    if o1 != 0 || o2 != 0 {
        // Both meet the common line of their planes in segments starting at the shared vertex:
        // they overlap beyond it iff the shorter one's far end (on its opposite edge) lies in
        // the other triangle.
        return segment_meets_triangle_given(a1, a2, o1, o2, b)
            || segment_meets_triangle(b1, b2, a);
    }
    let axes = projection_axes(b[0], b[1], b[2]);
    let (v, pa1, pa2, pb1, pb2) = (
        project(a[ia], axes),
        project(a1, axes),
        project(a2, axes),
        project(b1, axes),
        project(b2, axes),
    );
    // Opposite edges meeting the other triangle, or an edge from the shared vertex running
    // into the other triangle's angle.
    let ta = [v, pa1, pa2];
    let tb = [v, pb1, pb2];
    let strictly_inside_angle = |p: Q, t: [Q; 3]| {
        let (o1, o2) = (orient2d(t[0], t[1], p), orient2d(t[0], t[2], p));
        let s = orient2d(t[0], t[1], t[2]);
        (o1 == s && o2 == -s) || (o1 == 0 && o2 == -s && dot_positive(t[0], t[1], p))
    };
    (0..3).any(|k| segments_meet_2d(pa1, pa2, tb[k], tb[(k + 1) % 3]))
        || (0..3).any(|k| segments_meet_2d(pb1, pb2, ta[k], ta[(k + 1) % 3]))
        || strictly_inside_angle(pa1, tb)
        || strictly_inside_angle(pa2, tb)
        || strictly_inside_angle(pb1, ta)
        || strictly_inside_angle(pb2, ta)
}

/// `p − o` points the same way as `q − o` (positive dot product).
fn dot_positive(o: Q, q: Q, p: Q) -> bool {
    (q[0] - o[0]) * (p[0] - o[0]) + (q[1] - o[1]) * (p[1] - o[1]) > 0
}

/// Triangles sharing the edge `a[ia] a[ia+1]` (as `b[ib+1] b[ib]` or `b[ib] b[ib+1]`): do they
/// overlap (fold onto each other)?
fn overlap_across_edge(a: [P; 3], opposite_a: P, b: [P; 3], opposite_b: P) -> bool {
    if orient3d(b[0], b[1], b[2], opposite_a) != 0 {
        return false;
    }
    // Coplanar: they overlap when both opposite vertices lie on the same side of the edge.
    let axes = projection_axes(b[0], b[1], b[2]);
    let (pa, pb) = (project(opposite_a, axes), project(opposite_b, axes));
    let shared: Vec<P> = a.iter().copied().filter(|v| b.contains(v)).collect();
    if shared.len() < 2 {
        return false;
    }
    let (e0, e1) = (project(shared[0], axes), project(shared[1], axes));
    orient2d(e0, e1, pa) * orient2d(e0, e1, pb) > 0
}

/// Whether triangles `i` and `j` of a mesh intersect anywhere but in the vertices and edges
/// they share.
fn pair_intersects(tris: &[[u32; 3]], snapped: &[P], i: usize, j: usize) -> bool {
    let (ti, tj) = (tris[i], tris[j]);
    pair_meets(
        ti,
        ti.map(|v| snapped[v as usize]),
        tj,
        tj.map(|v| snapped[v as usize]),
    )
}

/// Whether triangles with vertex ids `ti` and `tj` (corners `a` and `b`, in the mesh's units)
/// intersect anywhere but in the vertices and edges they share: the test of
/// [`intersecting_pairs`] for one pair, for callers that move vertices and test again.
/// Corners must be finite and within [`MAX_EXACT_COORDINATE`].
pub(crate) fn triangles_cross(ti: [u32; 3], a: [Vec3; 3], tj: [u32; 3], b: [Vec3; 3]) -> bool {
    pair_meets(ti, a.map(snap), tj, b.map(snap))
}

/// Whether the triangle with corners `t` has zero area on the exact grid (it counts as
/// crossing in [`intersecting_pairs`]).
pub(crate) fn degenerate(t: [Vec3; 3]) -> bool {
    let [a, b, c] = t.map(snap);
    let (u, v) = (sub(b, a), sub(c, a));
    u[1] * v[2] == u[2] * v[1] && u[2] * v[0] == u[0] * v[2] && u[0] * v[1] == u[1] * v[0]
}

/// [`pair_intersects`] on snapped corners.
fn pair_meets(ti: [u32; 3], a: [P; 3], tj: [u32; 3], b: [P; 3]) -> bool {
    // Shared corners (at most three), without allocating: this runs for every tested pair.
    let mut shared = [(0usize, 0usize); 3];
    let mut count = 0;
    for x in 0..3 {
        for y in 0..3 {
            if ti[x] == tj[y] && count < 3 {
                shared[count] = (x, y);
                count += 1;
            }
        }
    }
    let shared = &shared[..count];
    match shared.len() {
        0 => triangles_meet(a, b),
        1 => meet_beyond_vertex(a, shared[0].0, b, shared[0].1),
        2 => {
            let oa = (0..3)
                .find(|x| shared.iter().all(|s| s.0 != *x))
                .unwrap_or(0);
            let ob = (0..3)
                .find(|y| shared.iter().all(|s| s.1 != *y))
                .unwrap_or(0);
            overlap_across_edge(a, a[oa], b, b[ob])
        }
        _ => true, // the same triangle twice
    }
}

/// The triangles of `tris` (over `positions`) that intersect another triangle of the same
/// mesh anywhere but in the vertices and edges they share (MeshLab's "self-intersecting
/// faces"). Degenerate (zero-area) triangles count as intersecting.
///
/// # Returns
/// Sorted ids of the intersecting triangles; `None` when a coordinate exceeds
/// [`MAX_EXACT_COORDINATE`] or is not finite.
///
/// # Performance
/// One uniform grid (cell ≈ mean triangle size), exact tests only for pairs whose bounding
/// boxes overlap, in parallel over cells.
pub fn self_intersecting_triangles(positions: &[Vec3], tris: &[[u32; 3]]) -> Option<Vec<u32>> {
    let mut hits: Vec<u32> = intersecting_pairs(positions, tris)?
        .into_iter()
        .flat_map(|(i, j)| [i, j])
        .collect();
    hits.sort_unstable();
    hits.dedup();
    Some(hits)
}

/// The pairs `(i, j)`, `i ≤ j`, of triangles of `tris` that intersect anywhere but in the
/// vertices and edges they share; a degenerate triangle `t` is reported as `(t, t)`. Where
/// [`self_intersecting_triangles`] counts, this tells which parts of a solid cross.
///
/// # Returns
/// Sorted pairs; `None` as for [`self_intersecting_triangles`].
pub fn intersecting_pairs(positions: &[Vec3], tris: &[[u32; 3]]) -> Option<Vec<(u32, u32)>> {
    pairs_touching(positions, tris, None)
}

/// [`intersecting_pairs`] restricted to the pairs that, between them, carry every bit of
/// `need` in `kinds` (one byte of flags per triangle; a degenerate triangle `t` counts when
/// `kinds[t]` alone carries them): the pairs touching a triangle marked varying (one bit) give,
/// with the pairs among the unmarked triangles found once, [`intersecting_pairs`] of meshes
/// that share those triangles (a part's pieces on one back surface); two bits split the pairs
/// further (those that also touch the back, which alone moves while a back is repaired).
///
/// # Returns
/// Sorted pairs; `None` as for [`intersecting_pairs`], or when `kinds` does not have one
/// byte per triangle.
pub(crate) fn intersecting_pairs_touching(
    positions: &[Vec3],
    tris: &[[u32; 3]],
    kinds: &[u8],
    need: u8,
) -> Option<Vec<(u32, u32)>> {
    if kinds.len() != tris.len() {
        return None;
    }
    pairs_touching(positions, tris, Some((kinds, need)))
}

/// The pairs of [`intersecting_pairs`]; with `filter` (`kinds`, `need`), only those that
/// carry every bit of `need` between them.
fn pairs_touching(
    positions: &[Vec3],
    tris: &[[u32; 3]],
    filter: Option<(&[u8], u8)>,
) -> Option<Vec<(u32, u32)>> {
    if positions
        .iter()
        .any(|p| !p.is_finite() || p.abs().max_element() > MAX_EXACT_COORDINATE)
        || tris
            .iter()
            .any(|t| t.iter().any(|&v| v as usize >= positions.len()))
    {
        return None;
    }
    if tris.is_empty() {
        return Some(Vec::new());
    }
    let (kinds, need) = filter.unwrap_or((&[], 0));
    let kind = |t: u32| kinds.get(t as usize).copied().unwrap_or(0);
    let wanted = |bits: u8| bits & need == need;
    let snapped: Vec<P> = positions.iter().map(|&p| snap(p)).collect();
    // Cells of about twice the mean triangle size limit the exact tests to nearby pairs.
    let grid = TriangleGrid::new(positions, tris);
    let boxes = grid.boxes();
    let degenerate: Vec<u32> = tris
        .iter()
        .enumerate()
        .filter(|&(t, _)| wanted(kind(t as u32)))
        .filter(|(_, t)| {
            let [a, b, c] = t.map(|v| snapped[v as usize]);
            let (u, v) = (sub(b, a), sub(c, a));
            u[1] * v[2] == u[2] * v[1] && u[2] * v[0] == u[0] * v[2] && u[0] * v[1] == u[1] * v[0]
        })
        .map(|(t, _)| t as u32)
        .collect();
    let cells: Vec<(&[i32; 3], &[u32])> = grid.cells().collect();
    let mut hits: Vec<(u32, u32)> = cells
        .par_iter()
        .flat_map_iter(|(cell_key, list)| {
            let mut out = Vec::new();
            // A cell whose triangles do not carry `need` between them has no pair to test
            // (a fine front's crowded cells while only the back moves).
            if !wanted(list.iter().fold(0, |bits, &t| bits | kind(t))) {
                return out;
            }
            for (x, &i) in list.iter().enumerate() {
                let kind_i = kind(i);
                for &j in &list[x + 1..] {
                    if !wanted(kind_i | kind(j)) {
                        continue;
                    }
                    let (bi, bj) = (boxes[i as usize], boxes[j as usize]);
                    if bi.0.cmpgt(bj.1).any() || bj.0.cmpgt(bi.1).any() {
                        continue;
                    }
                    // Test each pair once: in the first cell of their boxes' overlap.
                    if grid.key(bi.0.max(bj.0)) != **cell_key {
                        continue;
                    }
                    if pair_intersects(tris, &snapped, i as usize, j as usize) {
                        out.push((i.min(j), i.max(j)));
                    }
                }
            }
            out
        })
        .collect();
    hits.extend(degenerate.into_iter().map(|t| (t, t)));
    hits.sort_unstable();
    hits.dedup();
    Some(hits)
}

#[cfg(test)]
mod tests;
