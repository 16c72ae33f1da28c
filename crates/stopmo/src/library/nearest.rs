//! Nearest-distance queries against a triangle set: the closest point of a triangle and a
//! uniform grid of triangles searched ring by ring (the minimum wall of printable pieces).

use rustc_hash::FxHashMap;

use glam::Vec3;

/// Closest point of triangle `abc` to `p` (Ericson, *Real-Time Collision Detection* 5.1.5).
pub fn closest_point_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let (p, a, b, c) = (p.as_dvec3(), a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a.as_vec3();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b.as_vec3();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + ab * v).as_vec3();
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c.as_vec3();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + ac * w).as_vec3();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w).as_vec3();
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (a + ab * v + ac * w).as_vec3()
}

/// Cell of `p` in a grid of cube size `cell` anchored at `lo`.
fn cell_of(p: Vec3, lo: Vec3, cell: f32) -> [i32; 3] {
    ((p - lo) / cell).to_array().map(floor_i32)
}

/// `x.floor() as i32` (saturating, NaN → 0) without `floorf`'s library call: grid keys are
/// taken for every tested pair and every visited cell.
#[inline]
pub(crate) fn floor_i32(x: f32) -> i32 {
    let i = x as i32;
    if (i as f32) > x {
        i.saturating_sub(1)
    } else {
        i
    }
}

/// A uniform grid of triangles for nearest-distance queries (and the exact intersection
/// test's pair search).
#[derive(Debug, Clone)]
pub struct TriangleGrid<'a> {
    positions: &'a [Vec3],
    triangles: &'a [[u32; 3]],
    lo: Vec3,
    cell: f32,
    dims: [i32; 3],
    /// Bounding box of every triangle.
    boxes: Vec<(Vec3, Vec3)>,
    cells: FxHashMap<[i32; 3], Vec<u32>>,
    /// Largest coordinate magnitude of the triangles' boxes (the scale of f32 rounding).
    extent: f32,
    /// The same cells as one flat array over `dims` (None when the box has more cells than
    /// [`MAX_FLAT_CELLS`] allows): the ring search looks up every cell it passes, and an
    /// index is cheaper than a hash.
    flat: Option<FlatCells>,
}

/// Most cells of a flat cell array, per triangle and in all (a box of slivers under large
/// triangles, or one that is not finite, keeps the hash map's cells only).
const MAX_FLAT_CELLS_PER_TRIANGLE: usize = 128;
const MAX_FLAT_CELLS: usize = 1 << 25;

/// Every cell of a grid, `x`-major then `y` then `z`, as ranges of one array of triangles
/// (each cell's triangles in the hash map's order, so that searches visit them alike).
#[derive(Debug, Clone)]
struct FlatCells {
    /// `start[i]..start[i + 1]` of `triangles` are cell `i`'s triangles.
    start: Vec<u32>,
    triangles: Vec<u32>,
}

impl FlatCells {
    /// The flat copy of `cells` over a grid of `dims` cells, or None when it would have more
    /// than the budget's cells or a cell lies outside `dims`.
    fn new(
        cells: &FxHashMap<[i32; 3], Vec<u32>>,
        dims: [i32; 3],
        triangles: usize,
    ) -> Option<FlatCells> {
        let budget =
            MAX_FLAT_CELLS.min(MAX_FLAT_CELLS_PER_TRIANGLE.saturating_mul(triangles.max(1)));
        let mut count = 1usize;
        for d in dims {
            count = count.checked_mul(usize::try_from(d).ok()?)?;
        }
        if count > budget {
            return None;
        }
        let entries: usize = cells.values().map(Vec::len).sum();
        let mut lengths = vec![0u32; count];
        for (k, list) in cells {
            let i = flat_index(*k, dims)?;
            lengths[i] = u32::try_from(list.len()).ok()?;
        }
        let mut start = Vec::with_capacity(count + 1);
        let mut at = 0u32;
        start.push(0);
        for l in &lengths {
            at = at.checked_add(*l)?;
            start.push(at);
        }
        let mut flat = vec![0u32; entries];
        for (k, list) in cells {
            let i = flat_index(*k, dims)?;
            flat[start[i] as usize..start[i + 1] as usize].copy_from_slice(list);
        }
        Some(FlatCells {
            start,
            triangles: flat,
        })
    }

    /// The triangles of cell `i` (a [`flat_index`]).
    #[inline]
    fn get(&self, i: usize) -> &[u32] {
        &self.triangles[self.start[i] as usize..self.start[i + 1] as usize]
    }
}

/// Index of cell `k` in a flat array over `dims` cells (None outside it).
#[inline]
fn flat_index(k: [i32; 3], dims: [i32; 3]) -> Option<usize> {
    if (0..3).all(|a| (0..dims[a]).contains(&k[a])) {
        Some(
            ((k[0] as usize * dims[1] as usize) + k[1] as usize) * dims[2] as usize + k[2] as usize,
        )
    } else {
        None
    }
}

/// The finest cell a uniform grid of `triangles` triangles over the box `lo..hi` may use:
/// 4 ∛`triangles` cells along the box's longest side, so at most ~64 cells per triangle in
/// all (and at least 10⁻⁶; a box that is not finite gives that floor).
pub(crate) fn finest_cell(lo: Vec3, hi: Vec3, triangles: usize) -> f32 {
    let cell = (hi - lo).max_element() / (4.0 * (triangles.max(1) as f32).cbrt());
    if cell.is_finite() {
        cell.max(1e-6)
    } else {
        1e-6
    }
}

impl<'a> TriangleGrid<'a> {
    /// Bins the triangles (indices must be valid) into cells of about twice their mean size.
    pub fn new(positions: &'a [Vec3], triangles: &'a [[u32; 3]]) -> TriangleGrid<'a> {
        let boxes: Vec<(Vec3, Vec3)> = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| positions[v as usize]);
                (a.min(b).min(c), a.max(b).max(c))
            })
            .collect();
        let lo = boxes.iter().fold(Vec3::INFINITY, |m, b| m.min(b.0));
        let hi = boxes.iter().fold(Vec3::NEG_INFINITY, |m, b| m.max(b.1));
        let mean = boxes
            .iter()
            .map(|(l, h)| (*h - *l).max_element())
            .sum::<f32>()
            / triangles.len().max(1) as f32;
        // Twice the mean triangle, but never so fine that the grid has more than ~64 cells
        // per triangle (finest_cell): a back surface that collapsed to slivers
        // under a few large triangles (a cube's, MorphStressTest) made 0.1 mm cells over
        // 80 mm, each large triangle in ~10⁵ of them, and every nearest query walked
        // thousands of empty cells (133 s to measure 8 pieces; results do not depend on the
        // cell size, only the time).
        let cell = (2.0 * mean).max(finest_cell(lo, hi, triangles.len()));
        let key = |p: Vec3| cell_of(p, lo, cell);
        let mut cells: FxHashMap<[i32; 3], Vec<u32>> = FxHashMap::default();
        for (t, (a, b)) in boxes.iter().enumerate() {
            let (ka, kb) = (key(*a), key(*b));
            for x in ka[0]..=kb[0] {
                for y in ka[1]..=kb[1] {
                    for z in ka[2]..=kb[2] {
                        cells.entry([x, y, z]).or_default().push(t as u32);
                    }
                }
            }
        }
        let dims = if triangles.is_empty() {
            [0; 3]
        } else {
            key(hi).map(|d| d + 1)
        };
        let flat = FlatCells::new(&cells, dims, triangles.len());
        let extent = lo.abs().max(hi.abs()).max_element();
        TriangleGrid {
            positions,
            triangles,
            lo,
            cell,
            dims,
            boxes,
            cells,
            extent,
            flat,
        }
    }

    /// The triangles whose boxes overlap cell `k` (empty for a cell nobody overlaps).
    #[inline]
    fn cell(&self, k: [i32; 3]) -> &[u32] {
        match &self.flat {
            Some(flat) => flat_index(k, self.dims).map_or(&[], |i| flat.get(i)),
            None => self.cells.get(&k).map_or(&[], Vec::as_slice),
        }
    }

    /// The cell holding `p`.
    pub(crate) fn key(&self, p: Vec3) -> [i32; 3] {
        cell_of(p, self.lo, self.cell)
    }

    /// Bounding box of every triangle, in triangle order.
    pub(crate) fn boxes(&self) -> &[(Vec3, Vec3)] {
        &self.boxes
    }

    /// The occupied cells and the triangles whose boxes overlap each (any order).
    pub(crate) fn cells(&self) -> impl Iterator<Item = (&[i32; 3], &[u32])> {
        self.cells.iter().map(|(k, v)| (k, v.as_slice()))
    }

    /// Distance from `p` to the nearest triangle (infinity without triangles).
    pub fn distance(&self, p: Vec3) -> f64 {
        self.distance_below(p, f64::INFINITY)
    }

    /// Distance from `p` to the nearest triangle when it is below `limit`; otherwise some value
    /// `>= limit` (infinity without triangles).
    ///
    /// # Performance
    /// Visits the grid ring by ring (only the cells on each ring's surface) and stops at the
    /// first ring farther than the best distance found or `limit`: O(d³/cell³) cells for a
    /// nearest distance d. Folding a minimum over many points with the running minimum as
    /// `limit` (as [`PartShell::min_wall`](super::PartShell::min_wall) does) keeps every query
    /// after the first to a few rings.
    ///
    /// A triangle whose box is farther than `limit` is not measured at all: over a thick
    /// wall most queries find nothing below it, and answer after box tests alone.
    pub fn distance_below(&self, p: Vec3, limit: f64) -> f64 {
        self.nearest_within(p, limit, true).0
    }

    /// [`TriangleGrid::distance_below`] and the nearest triangle (`None` when none was
    /// found below `limit`). Above `limit`, what is returned is the nearest of the
    /// triangles measured on the way (callers weigh such near misses).
    pub(crate) fn nearest_below(&self, p: Vec3, limit: f64) -> (f64, Option<u32>) {
        self.nearest_within(p, limit, false)
    }

    /// [`TriangleGrid::nearest_below`]; with `cut`, triangles whose boxes are farther than
    /// `limit` are skipped too (the answer below `limit` is the same).
    fn nearest_within(&self, p: Vec3, limit: f64, cut: bool) -> (f64, Option<u32>) {
        if self.triangles.is_empty() {
            return (f64::INFINITY, None);
        }
        let c = self.key(p);
        let max_ring = (0..3)
            .map(|k| (c[k]).abs().max((self.dims[k] - c[k]).abs()))
            .max()
            .unwrap_or(0)
            + 1;
        let mut best = (f64::INFINITY, None);
        // A triangle whose box is farther than the best distance by more than f32 rounding
        // of its closest point (1e-4 of the coordinates' size) cannot replace it: skipping
        // it leaves the result as it was, without the closest-point computation.
        let slack = 1e-4 * (1.0 + p.abs().max_element() + self.extent);
        let nearest_in = |list: &[u32], best: &mut (f64, Option<u32>)| {
            for &t in list {
                let (lo, hi) = self.boxes[t as usize];
                let gap = (lo - p).max(p - hi).max(Vec3::ZERO).length();
                let reach = if cut { best.0.min(limit) } else { best.0 };
                if f64::from(gap) > reach + f64::from(slack) {
                    continue;
                }
                let [a, b, c] = self.triangles[t as usize].map(|v| self.positions[v as usize]);
                let d = f64::from(closest_point_on_triangle(p, a, b, c).distance(p));
                if d < best.0 {
                    *best = (d, Some(t));
                }
            }
        };
        let visit = |x: i32, y: i32, z: i32, best: &mut (f64, Option<u32>)| {
            nearest_in(self.cell([x, y, z]), best);
        };
        let mut visited = 0usize;
        for r in 0..=max_ring {
            // Cells of ring r lie at least (r − 1)·cell from p.
            if f64::from((r - 1).max(0) as f32 * self.cell) >= best.0.min(limit) {
                break;
            }
            // Far from every triangle (a back far behind a thin part, a point outside the
            // grid) the rings hold mostly empty cells: scan the occupied ones instead.
            let ring_cells =
                (2 * r as usize + 1).pow(3) - (2 * r as usize).saturating_sub(1).pow(3);
            visited += ring_cells;
            if visited > self.cells.len() {
                let reach = best.0.min(limit);
                for (k, list) in &self.cells {
                    let lo = self.lo + Vec3::new(k[0] as f32, k[1] as f32, k[2] as f32) * self.cell;
                    let gap = (lo - p)
                        .max(p - lo - Vec3::splat(self.cell))
                        .max(Vec3::ZERO);
                    if f64::from(gap.length()) < reach.min(best.0) {
                        nearest_in(list, &mut best);
                    }
                }
                return best;
            }
            for x in c[0] - r..=c[0] + r {
                for y in c[1] - r..=c[1] + r {
                    if (x - c[0]).abs() == r || (y - c[1]).abs() == r {
                        for z in c[2] - r..=c[2] + r {
                            visit(x, y, z, &mut best);
                        }
                    } else {
                        // Inside the ring's x/y extent only the two z faces belong to it.
                        visit(x, y, c[2] - r, &mut best);
                        if r > 0 {
                            visit(x, y, c[2] + r, &mut best);
                        }
                    }
                }
            }
        }
        best
    }
}

/// `slivers` triangles 0.01 across scattered over 80 × 80 × 2, under two triangles across
/// all of it: a back surface that collapsed under its walls (MorphStressTest's cube).
#[cfg(test)]
pub(crate) fn slivers_under_large_triangles(seed: u64, slivers: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut rng = anim::SplitMix64::new(seed, 0);
    let mut r = |s: f32| (rng.next_f32() - 0.5) * s;
    let mut p: Vec<Vec3> = Vec::new();
    for _ in 0..slivers {
        let c = Vec3::new(r(80.0), r(80.0), r(2.0));
        p.extend([
            c,
            c + Vec3::new(0.01, 0.0, 0.0),
            c + Vec3::new(0.0, 0.01, 0.0),
        ]);
    }
    let n = 3 * slivers;
    p.extend([
        Vec3::new(-40.0, -40.0, 0.0),
        Vec3::new(40.0, -40.0, 0.0),
        Vec3::new(-40.0, 40.0, 0.0),
        Vec3::new(40.0, 40.0, 1.0),
    ]);
    let t = (0..slivers)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .chain([[n, n + 1, n + 2], [n + 1, n + 3, n + 2]])
        .collect();
    (p, t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_i32_is_floor_then_cast() {
        let xs = [
            0.0f32,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            -1.0001,
            2.9999,
            -2.9999,
            1e-30,
            -1e-30,
            16_777_217.0,
            -16_777_217.0,
            3e9,
            -3e9,
            2_147_483_520.0,
            -2_147_483_648.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            f32::MAX,
            f32::MIN,
        ];
        let mut rng = anim::SplitMix64::new(3, 0);
        let random = (0..10_000).map(|_| (rng.next_f32() - 0.5) * 1e4);
        for x in xs.into_iter().chain(random) {
            assert_eq!(floor_i32(x), x.floor() as i32, "{x}");
        }
    }

    /// Distance from `q` to the nearest triangle, by trying every one.
    fn brute(p: &[Vec3], t: &[[u32; 3]], q: Vec3) -> f64 {
        t.iter()
            .map(|&[a, b, c]| {
                let [a, b, c] = [a, b, c].map(|v| p[v as usize]);
                f64::from(closest_point_on_triangle(q, a, b, c).distance(q))
            })
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn grid_distance_matches_brute_force_near_and_far() {
        let mut rng = anim::SplitMix64::new(7, 0);
        let mut r = |s: f32| (rng.next_f32() - 0.5) * s;
        // A small dense patch, so that far points need many rings.
        let p: Vec<Vec3> = (0..300)
            .map(|_| Vec3::new(r(4.0), r(4.0), r(0.4)))
            .collect();
        let t: Vec<[u32; 3]> = (0..100).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        let grid = TriangleGrid::new(&p, &t);
        for i in 0..200 {
            let scale = if i % 2 == 0 { 5.0 } else { 40.0 };
            let q = Vec3::new(r(scale), r(scale), r(scale));
            let brute = brute(&p, &t, q);
            assert!((grid.distance(q) - brute).abs() < 1e-9, "{q}");
            // Under a limit: the exact distance when nearer, else at least the limit.
            let below = grid.distance_below(q, brute * 0.5);
            assert!(below >= brute * 0.5 - 1e-9);
            assert!((grid.distance_below(q, brute * 2.0) - brute).abs() < 1e-9);
        }
    }

    #[test]
    fn flat_cells_find_what_the_hash_map_and_a_scan_of_every_triangle_find() {
        let mut rng = anim::SplitMix64::new(5, 0);
        let mut r = |s: f32| (rng.next_f32() - 0.5) * s;
        // A curved sheet of small triangles, like a back surface.
        let p: Vec<Vec3> = (0..900)
            .map(|_| {
                let (x, y) = (r(30.0), r(20.0));
                Vec3::new(x + r(0.8), y + r(0.8), 0.02 * x * x + r(0.8))
            })
            .collect();
        let t: Vec<[u32; 3]> = (0..300).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        let grid = TriangleGrid::new(&p, &t);
        let flat = grid.flat.as_ref().expect("a flat cell array within budget");
        for (k, list) in &grid.cells {
            let i = flat_index(*k, grid.dims).expect("every occupied cell inside dims");
            assert_eq!(flat.get(i), list.as_slice(), "{k:?}");
        }
        let occupied: usize = (0..flat.start.len() - 1)
            .filter(|&i| !flat.get(i).is_empty())
            .count();
        assert_eq!(occupied, grid.cells.len());
        let hashed = TriangleGrid {
            flat: None,
            ..grid.clone()
        };
        for i in 0..400 {
            let scale = if i % 2 == 0 { 35.0 } else { 120.0 };
            let q = Vec3::new(r(scale), r(scale), r(scale));
            let found = grid.nearest_below(q, f64::INFINITY);
            assert_eq!(found, hashed.nearest_below(q, f64::INFINITY), "{q}");
            assert!((found.0 - brute(&p, &t, q)).abs() < 1e-9, "{q}");
            let limit = found.0 * 0.7;
            assert_eq!(
                grid.nearest_below(q, limit),
                hashed.nearest_below(q, limit),
                "{q}"
            );
        }
    }

    #[test]
    fn grid_distance_far_from_tiny_triangles_scans_the_occupied_cells() {
        // Triangles 10⁻³ across and a point 2,000 away, 10⁴ cells: ring by ring this would
        // visit ~10¹² empty cells (the jobs test's tube hung here); it must answer at once,
        // exactly.
        let p = vec![
            Vec3::ZERO,
            Vec3::new(1e-3, 0.0, 0.0),
            Vec3::new(0.0, 1e-3, 0.0),
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.501, 0.0, 0.0),
            Vec3::new(0.5, 1e-3, 0.0),
        ];
        let t = [[0, 1, 2], [3, 4, 5]];
        let grid = TriangleGrid::new(&p, &t);
        let q = Vec3::new(0.0, 0.0, 2000.0);
        assert!((grid.distance(q) - 2000.0).abs() < 1e-3);
        assert!(grid.distance_below(q, 1.0) >= 1.0);
    }

    /// The back of a cube's half (MorphStressTest, `--auto-parts 2`): a thousand slivers
    /// where the back collapsed, under two triangles across the whole part. Cells of twice
    /// the mean triangle put each large triangle in ~10⁴–10⁵ cells and every query walked
    /// them (133 s to measure 8 pieces, 1.9 s with the coarser grid).
    #[test]
    fn collapsed_back_under_large_triangles_keeps_the_grid_coarse() {
        let (p, t) = slivers_under_large_triangles(11, 1000);
        let grid = TriangleGrid::new(&p, &t);
        let cells = grid.cells().count();
        assert!(
            cells < 20 * t.len(),
            "{cells} cells for {} triangles",
            t.len()
        );
        let mut rng = anim::SplitMix64::new(12, 0);
        for _ in 0..50 {
            let q = Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, 0.1) * 90.0;
            assert!((grid.distance(q) - brute(&p, &t, q)).abs() < 1e-9, "{q}");
        }
    }
}
