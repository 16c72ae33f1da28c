//! Cotangent Laplacian and lumped (barycentric) mass matrix of a triangle mesh, the linear
//! FEM discretization used by StopShop Eqs. 7–8.

use glam::DVec3;

/// Default cap on |cot| of a triangle's angles: a sliver's three cotangents are scaled
/// down together (which keeps its stiffness matrix positive semi-definite).
pub const DEFAULT_MAX_COT: f64 = 1e4;

/// A sparse matrix in compressed rows (sorted columns, duplicates summed).
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct SparseRows {
    /// Row starts (`rows + 1` entries).
    pub offsets: Vec<usize>,
    /// Column of every entry.
    pub cols: Vec<u32>,
    /// Value of every entry.
    pub vals: Vec<f64>,
}

impl SparseRows {
    /// Builds an `n`-row matrix from `(row, col, value)` triplets, summing duplicates.
    pub(super) fn from_triplets(n: usize, mut t: Vec<(u32, u32, f64)>) -> SparseRows {
        t.sort_unstable_by_key(|e| (e.0, e.1));
        let mut offsets = vec![0usize; n + 1];
        let mut cols = Vec::with_capacity(t.len());
        let mut vals: Vec<f64> = Vec::with_capacity(t.len());
        let mut last = None;
        for (r, c, v) in t {
            if last == Some((r, c)) {
                *vals.last_mut().expect("an entry was pushed") += v;
            } else {
                offsets[r as usize + 1] += 1;
                cols.push(c);
                vals.push(v);
                last = Some((r, c));
            }
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        SparseRows {
            offsets,
            cols,
            vals,
        }
    }

    /// Number of rows.
    pub(super) fn rows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Entries of row `i` as `(column, value)`.
    pub(super) fn row(&self, i: usize) -> impl Iterator<Item = (u32, f64)> + '_ {
        let r = self.offsets[i]..self.offsets[i + 1];
        self.cols[r.clone()]
            .iter()
            .copied()
            .zip(self.vals[r].iter().copied())
    }
}

/// The symmetric positive semi-definite cotangent Laplacian `L` (`L_ij = −½(cot α + cot β)`,
/// `L_ii = −Σ_j L_ij`) and the lumped mass `M_ii = Σ_{t ∋ i} A_t / 3`.
///
/// Zero-area triangles contribute nothing to L; masses are floored at 1e-8 × the mean mass
/// so that `M⁻¹` exists.
///
/// # Performance
/// O(k log k) for k triangles.
pub(super) fn cotangent_laplacian(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> (SparseRows, Vec<f64>) {
    let n = positions.len();
    let mut t = Vec::with_capacity(triangles.len() * 9);
    let mut mass = vec![0.0; n];
    for tri in triangles {
        let p = tri.map(|i| positions[i as usize]);
        let cross = (p[1] - p[0]).cross(p[2] - p[0]);
        let double_area = cross.length();
        for &i in tri {
            mass[i as usize] += double_area / 6.0;
        }
        if double_area.is_nan()
            || double_area <= 1e-300
            || tri[0] == tri[1]
            || tri[1] == tri[2]
            || tri[0] == tri[2]
        {
            continue;
        }
        let mut cot = [0.0; 3];
        for k in 0..3 {
            let (a, b) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            cot[k] = a.dot(b) / double_area;
        }
        let big = cot.iter().fold(0.0f64, |m, c| m.max(c.abs()));
        if big > DEFAULT_MAX_COT {
            cot.iter_mut().for_each(|c| *c *= DEFAULT_MAX_COT / big);
        }
        for k in 0..3 {
            let (i, j) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let w = 0.5 * cot[k];
            t.push((i, j, -w));
            t.push((j, i, -w));
            t.push((i, i, w));
            t.push((j, j, w));
        }
    }
    let mean = mass.iter().sum::<f64>() / n.max(1) as f64;
    let floor = (mean * 1e-8).max(f64::MIN_POSITIVE);
    mass.iter_mut().for_each(|m| *m = m.max(floor));
    (SparseRows::from_triplets(n, t), mass)
}

/// A sparse matrix entry `(row, column, value)`.
pub(super) type Entry = (u32, u32, f64);

/// The bi-Laplacian `Q = L M⁻¹ L` of StopShop Eq. 8 restricted to the rows in `keep` (true) and
/// split by column into kept and other columns.
///
/// # Returns
/// Triplets `(row, col, value)` of `Q[keep, keep]` and of `Q[keep, !keep]`, both in the local
/// numbering given by `local` (position of a vertex within its own group).
pub(super) fn bilaplacian_blocks(
    l: &SparseRows,
    mass: &[f64],
    keep: &[bool],
    local: &[u32],
) -> (Vec<Entry>, Vec<Entry>) {
    let mut ff = Vec::new();
    let mut fp = Vec::new();
    for k in 0..l.rows() {
        let inv = 1.0 / mass[k];
        for (i, li) in l.row(k) {
            if !keep[i as usize] {
                continue;
            }
            for (j, lj) in l.row(k) {
                let v = li * inv * lj;
                let (a, b) = (local[i as usize], local[j as usize]);
                if keep[j as usize] {
                    ff.push((a, b, v));
                } else {
                    fp.push((a, b, v));
                }
            }
        }
    }
    (ff, fp)
}
