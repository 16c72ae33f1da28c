//! How deep the back surface must lie under every front vertex: not only behind the vertex
//! itself but behind every front point (of any piece) in a column around the vertex's inward
//! direction, so a back surface that leaves the wall under the nose tip does not pass through
//! the nostrils behind it, nor one under a lip through the mouth corner.

use std::ops::Range;

use glam::Vec3;
use rayon::prelude::*;

use crate::library::nearest::floor_i32;

/// Grid cells per column radius (`lateral`): a column's bounding box then covers few cells
/// beyond it, whatever its direction.
const CELLS_PER_LATERAL: f32 = 2.0;

/// Points a column test handles at once: 16 `f32` lanes (one AVX-512 or two AVX2 registers).
const LANES: usize = 16;

/// Every front point of every piece binned in a uniform grid, each cell's points stored
/// contiguously (cell-major) and by coordinate (`x`, `y`, `z` apart, so that the column
/// test runs over many points per instruction), for the column queries of
/// [`envelope_limits`].
struct PointGrid {
    lo: Vec3,
    cell: f32,
    dims: [i32; 3],
    /// Start of every cell's points (cell `x + dims[0]·(y + dims[1]·z)`), plus the end.
    start: Vec<u32>,
    /// The points' coordinates, in cell order.
    xyz: [Vec<f32>; 3],
}

impl PointGrid {
    fn new(fronts: &[Vec<Vec3>], n: usize, cell: f32) -> PointGrid {
        let all = || fronts.iter().flat_map(|f| f.iter().take(n).copied());
        let (lo, hi) = all().filter(|p| p.is_finite()).fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(p), hi.max(p)),
        );
        let (lo, hi) = if lo.cmple(hi).all() {
            (lo, hi)
        } else {
            (Vec3::ZERO, Vec3::ZERO)
        };
        // Coarser cells where the points spread far (a stray vertex): at most a few cells
        // per point.
        let points = fronts.iter().map(|f| f.len().min(n)).sum::<usize>();
        let budget = (4 * points).max(1 << 12) as f64;
        let mut cell = cell;
        let dims = loop {
            let dims = ((hi - lo) / cell)
                .to_array()
                .map(|x| floor_i32(x).clamp(0, 1 << 20) + 1);
            if dims.iter().map(|&d| f64::from(d)).product::<f64>() <= budget {
                break dims;
            }
            cell *= 2.0;
        };
        let mut grid = PointGrid {
            lo,
            cell,
            dims,
            start: Vec::new(),
            xyz: [Vec::new(), Vec::new(), Vec::new()],
        };
        let cells = dims.iter().map(|&d| d as usize).product::<usize>();
        let mut count = vec![0u32; cells + 1];
        for p in all() {
            count[grid.index(p) + 1] += 1;
        }
        for i in 0..cells {
            count[i + 1] += count[i];
        }
        let mut next = count.clone();
        let mut xyz = [0; 3].map(|_| vec![0.0; count[cells] as usize]);
        for p in all() {
            let slot = &mut next[grid.index(p)];
            for (axis, value) in xyz.iter_mut().zip(p.to_array()) {
                axis[*slot as usize] = value;
            }
            *slot += 1;
        }
        grid.xyz = xyz;
        grid.start = count;
        grid
    }

    /// Cell coordinates of `p`, clamped to the grid.
    fn coords(&self, p: Vec3) -> [i32; 3] {
        let q = ((p - self.lo) / self.cell).to_array();
        [0, 1, 2].map(|k| floor_i32(q[k]).clamp(0, self.dims[k] - 1))
    }

    fn index(&self, p: Vec3) -> usize {
        let [x, y, z] = self.coords(p);
        (x + self.dims[0] * (y + self.dims[1] * z)) as usize
    }

    /// The points of every cell that meets the box `lo..=hi`, as ranges of indices (one per
    /// row of cells along x).
    fn in_box(&self, lo: Vec3, hi: Vec3) -> impl Iterator<Item = Range<usize>> + '_ {
        let (a, b) = (self.coords(lo), self.coords(hi));
        (a[2]..=b[2]).flat_map(move |z| {
            (a[1]..=b[1]).map(move |y| {
                let row = self.dims[0] * (y + self.dims[1] * z);
                let (s, e) = ((row + a[0]) as usize, (row + b[0]) as usize + 1);
                self.start[s] as usize..self.start[e] as usize
            })
        })
    }
}

/// One column: its centre `c`, unit direction `d`, how deep (`reach`) and how far up and
/// sideways (`lateral`) it goes.
#[derive(Clone, Copy)]
struct Column {
    c: Vec3,
    d: Vec3,
    reach: f32,
    lateral: f32,
}

impl Column {
    /// The smallest `q·d` of `lowest` and the points `q` (coordinates `x`, `y`, `z`) inside
    /// the column.
    ///
    /// Every point goes through the same operations in the same order as glam's `Vec3`
    /// (`e = q − c`, `h = e·d`, `|e − d h|²`, `q·d`), lane by lane, so the minimum is the one
    /// a point-by-point loop over `Vec3`s finds.
    #[inline]
    fn lowest(&self, x: &[f32], y: &[f32], z: &[f32], lowest: f32) -> f32 {
        let mut acc = [lowest; LANES];
        let (xs, ys, zs) = (
            x.chunks_exact(LANES),
            y.chunks_exact(LANES),
            z.chunks_exact(LANES),
        );
        let tail = (xs.remainder(), ys.remainder(), zs.remainder());
        for ((x, y), z) in xs.zip(ys).zip(zs) {
            for l in 0..LANES {
                acc[l] = self.lower(acc[l], x[l], y[l], z[l]);
            }
        }
        let mut lowest = acc.into_iter().fold(f32::INFINITY, f32::min);
        for ((&x, &y), &z) in tail.0.iter().zip(tail.1).zip(tail.2) {
            lowest = self.lower(lowest, x, y, z);
        }
        lowest
    }

    /// `lowest`, or `q·d` when the point `q = (x, y, z)` is inside the column and lower.
    #[inline(always)]
    fn lower(&self, lowest: f32, x: f32, y: f32, z: f32) -> f32 {
        let (c, d) = (self.c, self.d);
        let (ex, ey, ez) = (x - c.x, y - c.y, z - c.z);
        let h = ex * d.x + ey * d.y + ez * d.z;
        let (sx, sy, sz) = (ex - d.x * h, ey - d.y * h, ez - d.z * h);
        let side = sx * sx + sy * sy + sz * sz;
        let inside = !(h < -self.reach || h > self.lateral) && side <= self.lateral * self.lateral;
        let q = x * d.x + y * d.y + z * d.z;
        if inside {
            lowest.min(q)
        } else {
            lowest
        }
    }
}

/// Per shell vertex `v`, the largest height `back[v]·normals[v]` the back may have: the
/// smallest `q·normals[v]` over the front points `q` of every piece within `lateral` of the
/// line through `average[v]` along `normals[v]` and at most `reach` deeper or `lateral`
/// higher than `average[v]`, minus `wall`.
///
/// # Performance
/// The points of all pieces in one flat grid of cells half a column radius wide; each
/// vertex reads the cells of its column's bounding box only (a minimum: which cells are
/// read does not change it, as long as they hold the whole column), [`LANES`] points at a
/// time.
pub(super) fn envelope_limits(
    average: &[Vec3],
    fronts: &[Vec<Vec3>],
    normals: &[Vec3],
    wall: f32,
    lateral: f32,
    reach: f32,
) -> Vec<f32> {
    let n = average.len();
    let grid = PointGrid::new(fronts, n, (lateral / CELLS_PER_LATERAL).max(1e-3));
    (0..n)
        .into_par_iter()
        .map(|v| {
            let (c, d) = (average[v], normals[v]);
            let mut lowest = fronts.iter().map(|f| f[v].dot(d)).fold(c.dot(d), f32::min);
            // A column point is `c + d·h + s` with `h ∈ [−reach, lateral]` and `|s| ≤ lateral`
            // (`d` unit): its box, with a margin for rounding.
            let (deep, high) = (c - d * reach, c + d * lateral);
            let pad = Vec3::splat(lateral * 1.01 + 1e-3);
            let column = Column {
                c,
                d,
                reach,
                lateral,
            };
            let [x, y, z] = &grid.xyz;
            for r in grid.in_box(deep.min(high) - pad, deep.max(high) + pad) {
                lowest = column.lowest(&x[r.clone()], &y[r.clone()], &z[r], lowest);
            }
            lowest - wall
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`envelope_limits`] as it was: every point of every piece tested against every column.
    fn every_point(
        average: &[Vec3],
        fronts: &[Vec<Vec3>],
        normals: &[Vec3],
        wall: f32,
        lateral: f32,
        reach: f32,
    ) -> Vec<f32> {
        (0..average.len())
            .map(|v| {
                let (c, d) = (average[v], normals[v]);
                let mut lowest = fronts.iter().map(|f| f[v].dot(d)).fold(c.dot(d), f32::min);
                for q in fronts.iter().flat_map(|f| f.iter().take(average.len())) {
                    let e = *q - c;
                    let h = e.dot(d);
                    if h >= -reach
                        && h <= lateral
                        && (e - d * h).length_squared() <= lateral * lateral
                    {
                        lowest = lowest.min(q.dot(d));
                    }
                }
                lowest - wall
            })
            .collect()
    }

    #[test]
    fn columns_in_the_grid_find_what_a_scan_of_every_point_finds() {
        // A wavy sheet 40 × 40 mm, five pieces pressing it in and out, tilted directions.
        let mut rng = anim::SplitMix64::new(19, 0);
        let mut r = |s: f32| (rng.next_f32() - 0.5) * s;
        let average: Vec<Vec3> = (0..900)
            .map(|i| {
                let (x, y) = ((i % 30) as f32 * 1.4 - 20.0, (i / 30) as f32 * 1.4 - 20.0);
                Vec3::new(x, y, 3.0 * (x * 0.2).sin() * (y * 0.15).cos())
            })
            .collect();
        let fronts: Vec<Vec<Vec3>> = (0..5)
            .map(|_| {
                average
                    .iter()
                    .map(|p| *p + Vec3::new(r(1.0), r(1.0), r(6.0)))
                    .collect()
            })
            .collect();
        let normals: Vec<Vec3> = average
            .iter()
            .map(|_| Vec3::new(r(1.5), r(1.5), 1.0).normalize())
            .collect();
        for (lateral, reach) in [(3.0, 4.5), (0.7, 9.0), (12.0, 2.0)] {
            let grid = envelope_limits(&average, &fronts, &normals, 1.5, lateral, reach);
            let scan = every_point(&average, &fronts, &normals, 1.5, lateral, reach);
            assert_eq!(grid, scan, "lateral {lateral}, reach {reach}");
        }
    }
}
