//! A uniform grid of triangle boxes for the search's neighbourhood queries (owned, unlike
//! [`TriangleGrid`](crate::library::nearest::TriangleGrid), because the search moves the
//! positions it was built from).

use rustc_hash::FxHashMap;

use glam::Vec3;

use crate::library::nearest::{finest_cell, floor_i32};

/// A uniform grid of triangle boxes of one piece's solid, built once per round.
pub(super) struct BoxGrid {
    cell: f32,
    cells: FxHashMap<[i32; 3], Vec<u32>>,
}

impl BoxGrid {
    /// Bins the boxes of `tris` into cells of `cell`, or coarser ([`finest_cell`]: at most
    /// ~64 cells per triangle in all), so that a few large wall triangles over a collapsed
    /// back do not fill 10⁵ tiny cells each.
    pub(super) fn new(positions: &[Vec3], tris: &[[u32; 3]], cell: f32) -> BoxGrid {
        let boxes: Vec<(Vec3, Vec3)> = tris
            .iter()
            .map(|tri| bounds(tri.map(|v| positions[v as usize])))
            .collect();
        let (lo, hi) = boxes.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(l, h), b| (l.min(b.0), h.max(b.1)),
        );
        let cell = cell.max(finest_cell(lo, hi, tris.len()));
        let mut cells: FxHashMap<[i32; 3], Vec<u32>> = FxHashMap::default();
        for (t, &(lo, hi)) in boxes.iter().enumerate() {
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
    pub(super) fn near(&self, lo: Vec3, hi: Vec3) -> Vec<u32> {
        let (a, b) = (key(lo, self.cell), key(hi, self.cell));
        let mut out = Vec::new();
        let span = (0..3)
            .map(|k| (i64::from(b[k]) - i64::from(a[k]) + 1).max(0))
            .product::<i64>();
        if span > self.cells.len() as i64 {
            // A box wider than the occupied grid: visit the occupied cells instead.
            for (k, list) in &self.cells {
                if (0..3).all(|i| a[i] <= k[i] && k[i] <= b[i]) {
                    out.extend_from_slice(list);
                }
            }
        } else {
            let keys = (a[0]..=b[0]).flat_map(|x| {
                (a[1]..=b[1]).flat_map(move |y| (a[2]..=b[2]).map(move |z| [x, y, z]))
            });
            for list in keys.filter_map(|k| self.cells.get(&k)) {
                out.extend_from_slice(list);
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

fn key(p: Vec3, cell: f32) -> [i32; 3] {
    (p / cell).to_array().map(floor_i32)
}

pub(super) fn bounds(t: [Vec3; 3]) -> (Vec3, Vec3) {
    (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]))
}

pub(super) fn boxes_overlap(a: (Vec3, Vec3), b: (Vec3, Vec3)) -> bool {
    !(a.0.cmpgt(b.1).any() || b.0.cmpgt(a.1).any())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Slivers under two triangles across the whole solid (the back of a cube's half,
    /// MorphStressTest): the grid stays coarse and a box wider than it finds exactly the
    /// triangles whose boxes a brute-force scan finds.
    #[test]
    fn wide_boxes_over_slivers_find_what_a_scan_finds() {
        let (p, t) = crate::library::nearest::slivers_under_large_triangles(5, 500);
        let mut rng = anim::SplitMix64::new(6, 0);
        let mut r = |s: f32| (rng.next_f32() - 0.5) * s;
        let grid = BoxGrid::new(&p, &t, 0.2);
        assert!(
            grid.cells.len() < 20 * t.len(),
            "{} cells",
            grid.cells.len()
        );
        for size in [0.5, 5.0, 200.0] {
            let (lo, hi) = (Vec3::new(r(60.0), r(60.0), -1.0), Vec3::splat(size));
            let hi = lo + hi;
            let found = grid.near(lo, hi);
            // Everything whose box overlaps the query box is found (cells may add more).
            for (i, tri) in t.iter().enumerate() {
                if boxes_overlap(bounds(tri.map(|v| p[v as usize])), (lo, hi)) {
                    assert!(found.binary_search(&(i as u32)).is_ok(), "{i} missing");
                }
            }
            assert!(found.windows(2).all(|w| w[0] < w[1]));
        }
    }
}
