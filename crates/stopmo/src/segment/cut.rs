//! Cutting triangles along the level sets where the winning part vote changes (Section 3.1,
//! "Part boundary smoothing": "meshing the curves that delineate changes in the maximum
//! vote"). New vertices sit on input edges (or, where three parts meet inside a triangle, at
//! an interior point) at fixed barycentric coordinates, so they are evaluated identically in
//! every frame: the topology stays frame-invariant and the surface does not change.

use std::collections::HashMap;

/// Default snapping threshold: level-set crossings closer than this fraction of an edge to
/// an edge end are moved onto that vertex, which avoids sliver triangles.
pub const DEFAULT_SNAP: f64 = 0.05;

/// Tie-break bias per part index, so that equal votes go to the lower part everywhere.
const TIE_BIAS: f64 = 1e-12;

/// How a vertex of the cut mesh is computed from the input vertices.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum VertexSource {
    /// An input vertex.
    Original(u32),
    /// `(1 − t) x_a + t x_b` on the input edge `(a, b)`.
    Edge {
        /// First input vertex.
        a: u32,
        /// Second input vertex.
        b: u32,
        /// Parameter along the edge.
        t: f64,
    },
    /// `Σ w_k x_{v_k}` inside an input triangle.
    Interior {
        /// The triangle's input vertices.
        v: [u32; 3],
        /// Barycentric weights (sum 1).
        w: [f64; 3],
    },
}

impl VertexSource {
    /// Evaluates the source on input positions (any frame).
    pub fn eval(&self, x: &[glam::Vec3]) -> glam::Vec3 {
        match *self {
            VertexSource::Original(i) => x[i as usize],
            VertexSource::Edge { a, b, t } => {
                let (pa, pb) = (x[a as usize].as_dvec3(), x[b as usize].as_dvec3());
                (pa + (pb - pa) * t).as_vec3()
            }
            VertexSource::Interior { v, w } => {
                let p: glam::DVec3 = (0..3).map(|k| x[v[k] as usize].as_dvec3() * w[k]).sum();
                p.as_vec3()
            }
        }
    }
}

/// A mesh cut along part boundaries (the sequence Y of Section 3.1).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CutMesh {
    /// One source per vertex; the first `m` are the input vertices in input order.
    pub sources: Vec<VertexSource>,
    /// Triangles (indices into `sources`), counter-clockwise like the input.
    pub triangles: Vec<[u32; 3]>,
    /// Part of every triangle.
    pub triangle_part: Vec<u32>,
    /// Input triangle every triangle was cut from.
    pub triangle_origin: Vec<u32>,
    /// Welded class of every vertex (coincident vertices share a class).
    pub weld_class: Vec<u32>,
    /// Number of welded classes.
    pub welded_count: usize,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Line {
    None,
    Edge(u8),
    Pair(u8, u8),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Key {
    Corner(u8),
    /// A crossing on local edge `e` between parts `(j, l)`, `j < l`.
    Edge(u8, u8, u8),
    /// The point where three parts tie inside the triangle.
    Triple(u8, u8, u8),
    /// A point of a degenerate configuration, unique within the triangle.
    Free(u32),
}

#[derive(Debug, Clone, Copy)]
struct Pt {
    bary: [f64; 3],
    key: Key,
    lines: [Line; 3],
}

fn pair(a: usize, b: usize) -> Line {
    Line::Pair(a.min(b) as u8, a.max(b) as u8)
}

fn corner(k: usize) -> Pt {
    let mut bary = [0.0; 3];
    bary[k] = 1.0;
    Pt {
        bary,
        key: Key::Corner(k as u8),
        lines: [
            Line::Edge(k as u8),
            Line::Edge(((k + 2) % 3) as u8),
            Line::None,
        ],
    }
}

/// Removes repeated points of a closed polygon (consecutive ones, and the last when it
/// repeats the first).
fn dedup_ring(poly: &mut Vec<Pt>) {
    poly.dedup_by(|a, b| a.key == b.key);
    while poly.len() > 1 && poly.first().map(|p| p.key) == poly.last().map(|p| p.key) {
        poly.pop();
    }
}

/// Per-triangle scores `score[c * parts + j]` of the three corners.
struct Tri<'a> {
    parts: usize,
    score: &'a [f64],
    welded: [u32; 3],
    snap: f64,
    free_count: std::cell::Cell<u32>,
}

impl Tri<'_> {
    fn diff(&self, c: usize, j: usize, l: usize) -> f64 {
        self.score[c * self.parts + j] - self.score[c * self.parts + l]
    }

    fn f(&self, p: &Pt, j: usize, l: usize) -> f64 {
        (0..3).map(|c| p.bary[c] * self.diff(c, j, l)).sum()
    }

    /// Crossing of parts (j, l) on local edge e, computed from the edge's ends only, in the
    /// orientation of the welded ids, so both triangles of an edge agree bit for bit. Never
    /// snapped here: [`Tri::snapped`] moves it once the regions are known.
    fn edge_crossing(&self, e: usize, j: usize, l: usize) -> Pt {
        let (c0, c1) = (e, (e + 1) % 3);
        let (first, second) = if self.welded[c0] <= self.welded[c1] {
            (c0, c1)
        } else {
            (c1, c0)
        };
        let (j, l) = (j.min(l), j.max(l));
        let (g0, g1) = (self.diff(first, j, l), self.diff(second, j, l));
        let t = if g0 == g1 {
            0.5
        } else {
            (g0 / (g0 - g1)).clamp(0.0, 1.0)
        };
        let line = Line::Pair(j as u8, l as u8);
        let mut bary = [0.0; 3];
        bary[first] = 1.0 - t;
        bary[second] = t;
        Pt {
            bary,
            key: Key::Edge(e as u8, j as u8, l as u8),
            lines: [Line::Edge(e as u8), line, Line::None],
        }
    }

    /// The point where parts a, b, c tie (canonical for the sorted triple).
    fn triple(&self, parts: [usize; 3], fallback: [f64; 3]) -> Pt {
        let mut p = parts;
        p.sort_unstable();
        let u = glam::DVec3::new(
            self.diff(0, p[0], p[1]),
            self.diff(1, p[0], p[1]),
            self.diff(2, p[0], p[1]),
        );
        let v = glam::DVec3::new(
            self.diff(0, p[0], p[2]),
            self.diff(1, p[0], p[2]),
            self.diff(2, p[0], p[2]),
        );
        let w = u.cross(v);
        let s = w.x + w.y + w.z;
        let bary = if s.abs() > 1e-300 && (w / s).is_finite() {
            let b = w / s;
            [b.x, b.y, b.z]
        } else {
            fallback
        };
        Pt {
            bary,
            key: Key::Triple(p[0] as u8, p[1] as u8, p[2] as u8),
            lines: [pair(p[0], p[1]), pair(p[0], p[2]), pair(p[1], p[2])],
        }
    }

    /// Intersection of segment P–Q with the tie line of (j, l).
    fn intersect(&self, p: &Pt, q: &Pt, fp: f64, fq: f64, j: usize, l: usize) -> Pt {
        let common = p
            .lines
            .iter()
            .copied()
            .find(|a| *a != Line::None && q.lines.contains(a));
        let s = fp / (fp - fq);
        let lerp = [0, 1, 2].map(|c| p.bary[c] + (q.bary[c] - p.bary[c]) * s);
        match common {
            Some(Line::Edge(e)) => self.edge_crossing(e as usize, j, l),
            Some(Line::Pair(a, b)) => {
                let (a, b) = (a as usize, b as usize);
                match [j, l].into_iter().find(|x| *x != a && *x != b) {
                    Some(c) => self.triple([a, b, c], lerp),
                    None => self.free(lerp),
                }
            }
            _ => self.free(lerp),
        }
    }

    /// A point with no canonical construction (only reached on exact ties): unique per call.
    fn free(&self, bary: [f64; 3]) -> Pt {
        let k = self.free_count.get();
        self.free_count.set(k + 1);
        Pt {
            bary,
            key: Key::Free(k),
            lines: [Line::None; 3],
        }
    }

    /// The region of part j in the triangle as a convex polygon (Sutherland–Hodgman).
    fn region(&self, j: usize) -> Vec<Pt> {
        let mut poly = vec![corner(0), corner(1), corner(2)];
        for l in 0..self.parts {
            if l == j || poly.is_empty() {
                continue;
            }
            let mut out = Vec::with_capacity(poly.len() + 2);
            for i in 0..poly.len() {
                let (p, q) = (&poly[i], &poly[(i + 1) % poly.len()]);
                let (fp, fq) = (self.f(p, j, l), self.f(q, j, l));
                if fp >= 0.0 {
                    out.push(*p);
                }
                if (fp >= 0.0) != (fq >= 0.0) {
                    out.push(self.intersect(p, q, fp, fq, j, l));
                }
            }
            dedup_ring(&mut out);
            poly = out;
        }
        let mut poly: Vec<Pt> = poly.into_iter().map(|p| self.snapped(p)).collect();
        dedup_ring(&mut poly);
        poly
    }

    /// A crossing on an input edge within the snapping threshold of an end, moved onto that
    /// end (it depends on the edge's ends only, so both triangles of the edge snap alike).
    /// Snapping after clipping, not during it, keeps the regions a partition: every
    /// region's side through a snapped crossing moves with it, where snapping inside the
    /// clip let a later clip of another part run along the input edge instead and leave a
    /// hole at a three-part corner.
    fn snapped(&self, p: Pt) -> Pt {
        let Key::Edge(e, ..) = p.key else {
            return p;
        };
        let (c0, c1) = (e as usize, (e as usize + 1) % 3);
        let (first, second) = if self.welded[c0] <= self.welded[c1] {
            (c0, c1)
        } else {
            (c1, c0)
        };
        let t = p.bary[second];
        if t <= self.snap {
            corner(first)
        } else if t >= 1.0 - self.snap {
            corner(second)
        } else {
            p
        }
    }
}

/// Smallest barycentric area (twice) of a triangle of a region's triangulation.
const MIN_AREA: f64 = 1e-12;

/// Twice the area of a triangle in barycentric coordinates.
fn bary_area(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs()
}

/// The corner a convex region is fanned from: the first whose fan has no degenerate
/// triangle. A region often has a point in the middle of a straight side (a crossing on an
/// input edge whose other side snapped to a corner): fanning from a corner on the line of
/// that side would give a zero-area triangle, and dropping it leaves the point out of this
/// triangle's side while the neighbour across the edge uses it — a T-junction, a crack in
/// the cut mesh and two parts whose seams differ.
fn fan_apex(ids: &[(u32, [f64; 3])]) -> usize {
    let n = ids.len();
    let min_area = |apex: usize| {
        (1..n - 1)
            .map(|k| {
                bary_area(
                    ids[apex].1,
                    ids[(apex + k) % n].1,
                    ids[(apex + k + 1) % n].1,
                )
            })
            .fold(f64::INFINITY, f64::min)
    };
    if min_area(0) >= MIN_AREA {
        return 0;
    }
    // No fan without one (several points on one side): the fan losing the least.
    (0..n)
        .find(|&a| min_area(a) >= MIN_AREA)
        .unwrap_or_else(|| (0..n).fold(0, |b, a| if min_area(a) > min_area(b) { a } else { b }))
}

/// Cuts every triangle along the boundaries of the maximum vote.
///
/// # Arguments
/// * `triangles` — input triangles (input vertex ids).
/// * `weld_class` — welded class of every input vertex; `welded_count` classes.
/// * `votes` — vertex-major smoothed votes per welded vertex (`parts` per vertex).
/// * `snap` — crossings within this fraction of an edge end snap to the end
///   ([`DEFAULT_SNAP`]).
///
/// # Returns
/// The cut mesh: triangles whose corners all win the same part are kept as they are; mixed
/// triangles are split into convex pieces (one per part present) and fan-triangulated.
pub(super) fn cut_mesh(
    triangles: &[[u32; 3]],
    weld_class: &[u32],
    welded_count: usize,
    votes: &[f64],
    parts: usize,
    snap: f64,
) -> CutMesh {
    let m = weld_class.len();
    let mut sources: Vec<VertexSource> = (0..m as u32).map(VertexSource::Original).collect();
    let mut class = weld_class.to_vec();
    let mut welded_count = welded_count;
    let mut out = CutMesh {
        sources: Vec::new(),
        triangles: Vec::with_capacity(triangles.len()),
        triangle_part: Vec::with_capacity(triangles.len()),
        triangle_origin: Vec::with_capacity(triangles.len()),
        weld_class: Vec::new(),
        welded_count: 0,
    };
    let mut edge_vertex: HashMap<(u32, u32, u8, u8), u32> = HashMap::new();
    let mut edge_class: HashMap<(u32, u32, u8, u8), u32> = HashMap::new();
    let mut score = vec![0.0; 3 * parts];
    let snap = snap.clamp(0.0, 0.49);
    for (ti, tri) in triangles.iter().enumerate() {
        let welded = tri.map(|i| weld_class[i as usize]);
        for c in 0..3 {
            for j in 0..parts {
                score[c * parts + j] = votes[welded[c] as usize * parts + j] - TIE_BIAS * j as f64;
            }
        }
        let win: [usize; 3] = [0, 1, 2].map(|c| {
            let row = &score[c * parts..(c + 1) * parts];
            (0..parts).fold(0, |b, j| if row[j] > row[b] { j } else { b })
        });
        if win[0] == win[1] && win[1] == win[2] {
            out.triangles.push(*tri);
            out.triangle_part.push(win[0] as u32);
            out.triangle_origin.push(ti as u32);
            continue;
        }
        let t = Tri {
            parts,
            score: &score,
            welded,
            snap,
            free_count: Default::default(),
        };
        let mut triple_vertex: HashMap<Key, u32> = HashMap::new();
        for j in 0..parts {
            let poly = t.region(j);
            if poly.len() < 3 {
                continue;
            }
            let ids: Vec<(u32, [f64; 3])> = poly
                .iter()
                .map(|p| {
                    let id = match p.key {
                        Key::Corner(k) => tri[k as usize],
                        Key::Edge(e, a, b) => {
                            let (c0, c1) = (e as usize, (e as usize + 1) % 3);
                            let (f, s) = if welded[c0] <= welded[c1] {
                                (c0, c1)
                            } else {
                                (c1, c0)
                            };
                            let key = (tri[f], tri[s], a, b);
                            *edge_vertex.entry(key).or_insert_with(|| {
                                let wkey = (welded[f], welded[s], a, b);
                                let wc = *edge_class.entry(wkey).or_insert_with(|| {
                                    welded_count += 1;
                                    welded_count as u32 - 1
                                });
                                class.push(wc);
                                sources.push(VertexSource::Edge {
                                    a: tri[f],
                                    b: tri[s],
                                    t: p.bary[s],
                                });
                                sources.len() as u32 - 1
                            })
                        }
                        Key::Triple(..) | Key::Free(_) => {
                            *triple_vertex.entry(p.key).or_insert_with(|| {
                                class.push(welded_count as u32);
                                welded_count += 1;
                                sources.push(VertexSource::Interior { v: *tri, w: p.bary });
                                sources.len() as u32 - 1
                            })
                        }
                    };
                    (id, p.bary)
                })
                .collect();
            let apex = fan_apex(&ids);
            let n = ids.len();
            for k in 1..n - 1 {
                let (a, b, c) = (ids[apex], ids[(apex + k) % n], ids[(apex + k + 1) % n]);
                if a.0 == b.0 || b.0 == c.0 || a.0 == c.0 || bary_area(a.1, b.1, c.1) < MIN_AREA {
                    continue;
                }
                out.triangles.push([a.0, b.0, c.0]);
                out.triangle_part.push(j as u32);
                out.triangle_origin.push(ti as u32);
            }
        }
    }
    out.sources = sources;
    out.weld_class = class;
    out.welded_count = welded_count;
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Area of the cut mesh's triangles and length of its edges used by one triangle only,
    /// with the input vertices at `x`.
    fn area_and_border(cut: &CutMesh, x: &[Vec3]) -> (f32, f32) {
        let p: Vec<Vec3> = cut.sources.iter().map(|s| s.eval(x)).collect();
        let mut area = 0.0;
        let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
        for t in &cut.triangles {
            let [a, b, c] = t.map(|i| p[i as usize]);
            area += 0.5 * (b - a).cross(c - a).length();
            for k in 0..3 {
                let (u, v) = (t[k], t[(k + 1) % 3]);
                *uses.entry((u.min(v), u.max(v))).or_default() += 1;
            }
        }
        let border = uses
            .iter()
            .filter(|(_, &n)| n == 1)
            .map(|(&(u, v), _)| p[u as usize].distance(p[v as usize]))
            .sum();
        (area, border)
    }

    /// The alar crease of the ICT face (README seeds): the tie line crosses the shared edge
    /// B–C 6.6 % from C, and snaps to C on A–C and to B on D–B, so each triangle of the edge
    /// keeps the crossing on one side of a straight region side. Dropping it there (a
    /// zero-area fan triangle) left a T-junction: the seams of the two parts differed and the
    /// printed walls crossed.
    #[test]
    fn alar_crease_has_no_t_junction() {
        // A, B, C, D in a unit square; triangles A B C and B D C share B–C.
        let x = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ];
        let votes = [
            0.293_138, 0.706_862, // A: lower part
            0.492_463, 0.507_537, // B: lower, barely
            0.500_534, 0.499_466, // C: upper, barely
            0.727_025, 0.272_975, // D: upper
        ];
        let cut = cut_mesh(
            &[[0, 1, 2], [1, 3, 2]],
            &[0, 1, 2, 3],
            4,
            &votes,
            2,
            DEFAULT_SNAP,
        );
        let (area, border) = area_and_border(&cut, &x);
        assert!((area - 1.0).abs() < 1e-5, "area {area}");
        assert!(
            (border - 4.0).abs() < 1e-5,
            "open edges {border}: a crack inside"
        );
        assert!(cut.triangle_part.contains(&0) && cut.triangle_part.contains(&1));
    }

    /// A corner of three parts where the tie of two snaps onto a corner: the regions must
    /// still cover the triangle (snapping during the clip left a hole between the three).
    #[test]
    fn three_part_corner_with_a_snapped_tie_has_no_hole() {
        let x = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let votes = [
            0.345_510, 0.333_369, 0.321_120, // wins part 0, barely
            0.210_751, 0.221_881, 0.567_368, // part 2
            0.152_555, 0.432_862, 0.414_583, // part 1
        ];
        let cut = cut_mesh(&[[0, 1, 2]], &[0, 1, 2], 3, &votes, 3, DEFAULT_SNAP);
        let (area, border) = area_and_border(&cut, &x);
        assert!((area - 0.5).abs() < 1e-6, "area {area}: a hole");
        assert!(
            (border - (2.0 + 2f32.sqrt())).abs() < 1e-5,
            "open edges {border}"
        );
    }
}
