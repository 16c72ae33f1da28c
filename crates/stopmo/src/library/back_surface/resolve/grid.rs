//! A uniform grid of triangle boxes for the search's neighbourhood queries (owned, unlike
//! [`TriangleGrid`](crate::library::nearest::TriangleGrid), because the search moves the
//! positions it was built from).

use std::collections::HashMap;

use glam::Vec3;

/// A uniform grid of triangle boxes of one piece's solid, built once per round.
pub(super) struct BoxGrid {
    cell: f32,
    cells: HashMap<[i32; 3], Vec<u32>>,
}

impl BoxGrid {
    pub(super) fn new(positions: &[Vec3], tris: &[[u32; 3]], cell: f32) -> BoxGrid {
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
    pub(super) fn near(&self, lo: Vec3, hi: Vec3) -> Vec<u32> {
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

pub(super) fn bounds(t: [Vec3; 3]) -> (Vec3, Vec3) {
    (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]))
}

pub(super) fn boxes_overlap(a: (Vec3, Vec3), b: (Vec3, Vec3)) -> bool {
    !(a.0.cmpgt(b.1).any() || b.0.cmpgt(a.1).any())
}
