//! Part boundary homogenization (Section 3.2, StopShop Eqs. 4–9): every frame is deformed minimally —
//! the squared cotangent-Laplacian energy of its displacement (StopShop Eq. 8, linear FEM with lumped
//! mass on the average mesh) is minimized — so that seam vertices and their one-ring sit at
//! their average positions (StopShop Eqs. 5–6, 9).
//!
//! One sparse Cholesky factorization of `Q_FF = (L M⁻¹ L)_FF` over the free vertices F; each
//! frame is then the back-substitution `Q_FF d_F = −Q_FP d_P` with `d_P = ỹ_P − y_P` the
//! prescribed displacement of the pinned vertices P, and `z = y + d`.
//!
//! When the seam is short (`F·P` small against the factor's size), the dense response
//! `R = −Q_FF⁻¹ Q_FP` is computed once (P solves, split over two threads) and every chunk of
//! frames becomes one dense product `d_F = R d_P` — the same solution, 3–4× faster here.

use std::time::Instant;

use anim::MeshAnimation;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::linalg::matmul::matmul;
use faer::reborrow::ReborrowMut;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymmetricOrdering,
};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Accum, Conj, Mat, MatMut, MatRef, Par, Side};
use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::error::{Result, SegmentError};
use super::laplacian::{bilaplacian_blocks, cotangent_laplacian, SparseRows};
use super::topology::{vertex_components, Topology};

/// Use the dense response matrix when `F·P ≤ RESPONSE_COST_RATIO · nnz(L)`.
const RESPONSE_COST_RATIO: usize = 8;

/// Default number of frames whose right-hand sides are solved together (one task).
pub const DEFAULT_CHUNK_FRAMES: usize = 64;

/// Frames whose seam displacements are multiplied by the dense response at once: a chunk's
/// buffers are `(F + P) × 3 · RESPONSE_FRAMES` floats instead of `× 3 · chunk` (1.9 MB
/// rather than 15 MB per thread on the face).
const RESPONSE_FRAMES: usize = 8;

/// Rows of the dense response multiplied at once (see [`Homogenizer::solve_chunk`]).
const RESPONSE_ROWS: usize = 240;

/// Frames whose right-hand sides are back-substituted at once without the dense response:
/// the buffer and faer's solve scratch are `F × 3 · SOLVE_FRAMES` floats each (3.4 MB on the
/// face) rather than `F × 3 · chunk` (13.6 MB each, allocated per chunk on every worker,
/// whose freed blocks stayed in the allocator's per-thread arenas: docs/studio.md, "Memory").
const SOLVE_FRAMES: usize = 16;

/// Measurements of one homogenization run.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct HomogenizeStats {
    /// Welded vertices on the seam.
    pub seam_vertices: usize,
    /// Welded vertices pinned to the seam targets (seam and one-ring).
    pub pinned_vertices: usize,
    /// Welded vertices pinned to their input motion (open borders), not counted in
    /// `pinned_vertices`.
    pub kept_vertices: usize,
    /// Welded vertices solved for.
    pub free_vertices: usize,
    /// Mean |z − y| over all vertices and frames, in model units.
    pub mean_change: f64,
    /// Max |z − y| over all vertices and frames, in model units.
    pub max_change: f64,
    /// Mean |z − y| over the free (interior) vertices, in model units.
    pub mean_free_change: f64,
    /// Max |z − y| over the free (interior) vertices, in model units.
    pub max_free_change: f64,
    /// Largest difference of displacement between the two ends of an edge relative to the
    /// edge's length on the average mesh (a measure of how smooth the deformation is).
    pub max_displacement_gradient: f64,
    /// Seconds spent building and factoring the system.
    pub factor_seconds: f64,
    /// Seconds spent solving all frames.
    pub solve_seconds: f64,
}

/// A factored homogenization system for one mesh and one seam; apply it to any number of
/// animations with that topology.
#[derive(Debug)]
pub struct Homogenizer {
    weld_class: Vec<u32>,
    /// Per welded vertex: `Some(local free index)`, or `None` when pinned or frozen.
    free_index: Vec<Option<u32>>,
    /// Per welded vertex: `Some(local pinned index)`.
    pinned_index: Vec<Option<u32>>,
    pinned: Vec<u32>,
    /// Per welded vertex: pinned to its input motion (displacement 0) rather than to its
    /// average position (open borders, user pins).
    keep_input: Vec<bool>,
    targets: Vec<Vec3>,
    representative: Vec<u32>,
    /// `Q_FP` by pinned column: `(free row, value)`.
    qfp: SparseRows,
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    /// Dense response `R = −Q_FF⁻¹ Q_FP` (free × pinned) when cheaper than per-frame solves.
    response: Option<Mat<f64>>,
    edges: Vec<[u32; 2]>,
    edge_lengths: Vec<f64>,
    seam_count: usize,
    factor_seconds: f64,
}

impl Homogenizer {
    /// Builds and factors the system.
    ///
    /// # Arguments
    /// * `average` — average positions of the (welded) vertices.
    /// * `triangles` — triangles over welded vertices.
    /// * `seam` — welded vertices on the seam; they and their one-ring are pinned to
    ///   `average` (StopShop Eqs. 5–6). Connected components that touch no seam are left unchanged.
    /// * `weld_class`, `representative` — map between the animation's vertices and the
    ///   welded ones (identity when nothing is welded).
    ///
    /// # Errors
    /// [`SegmentError::Solver`] when the factorization fails.
    pub fn new(
        average: &[DVec3],
        triangles: &[[u32; 3]],
        seam: &[bool],
        weld_class: Vec<u32>,
        representative: Vec<u32>,
    ) -> Result<Homogenizer> {
        let keep = vec![false; average.len()];
        Self::with_kept(average, triangles, seam, &keep, weld_class, representative)
    }

    /// [`Homogenizer::new`] with vertices that keep the input's motion: `keep[v]` pins welded
    /// vertex `v` to a zero displacement (open mesh borders such as the neck and scalp, or
    /// vertices the user pins), so the deformation decays from the seam to them instead of
    /// moving them. Seam vertices win where both apply; kept vertices in the seam's one-ring
    /// keep the input's motion.
    ///
    /// # Errors
    /// [`SegmentError::Solver`] when the factorization fails, [`SegmentError::Parameter`]
    /// when `keep` has the wrong length.
    pub fn with_kept(
        average: &[DVec3],
        triangles: &[[u32; 3]],
        seam: &[bool],
        keep: &[bool],
        weld_class: Vec<u32>,
        representative: Vec<u32>,
    ) -> Result<Homogenizer> {
        let start = Instant::now();
        let n = average.len();
        if keep.len() != n || seam.len() != n {
            return Err(SegmentError::Parameter(format!(
                "{} seam and {} kept flags for {n} welded vertices",
                seam.len(),
                keep.len()
            )));
        }
        let topo = Topology::new(n, triangles);
        let mut pinned_mask = seam.to_vec();
        for v in 0..n {
            if seam[v] {
                for &w in topo.neighbors.row(v) {
                    pinned_mask[w as usize] = true;
                }
            }
        }
        let keep_input: Vec<bool> = (0..n).map(|v| keep[v] && !seam[v]).collect();
        for v in 0..n {
            pinned_mask[v] |= keep_input[v];
        }
        let (comp, count) = vertex_components(&topo.neighbors);
        let mut comp_pinned = vec![false; count];
        for v in 0..n {
            comp_pinned[comp[v] as usize] |= pinned_mask[v];
        }
        let mut free_index = vec![None; n];
        let mut pinned_index = vec![None; n];
        let mut keep = vec![false; n];
        let mut local = vec![u32::MAX; n];
        let (mut nf, mut pinned) = (0u32, Vec::new());
        for v in 0..n {
            if pinned_mask[v] {
                pinned_index[v] = Some(pinned.len() as u32);
                local[v] = pinned.len() as u32;
                pinned.push(v as u32);
            } else if comp_pinned[comp[v] as usize] {
                free_index[v] = Some(nf);
                local[v] = nf;
                keep[v] = true;
                nf += 1;
            }
        }
        let (l, mass) = cotangent_laplacian(average, triangles);
        let (ff, fp) = bilaplacian_blocks(&l, &mass, &keep, &local);
        // Frozen vertices (components without a seam) are neither solved nor pinned; they
        // share no Laplacian row with solved vertices, but guard against it anyway.
        let fp: Vec<(u32, u32, f64)> = fp.into_iter().filter(|e| e.1 != u32::MAX).collect();
        // Q_FP stored by pinned column.
        let qfp = SparseRows::from_triplets(
            pinned.len(),
            fp.into_iter().map(|(r, c, v)| (c, r, v)).collect(),
        );
        let nf = nf as usize;
        let ff = SparseRows::from_triplets(nf, ff);
        let mut trip = Vec::with_capacity(ff.vals.len());
        for r in 0..nf {
            for (c, v) in ff.row(r) {
                if c as usize <= r {
                    trip.push(Triplet::new(r, c as usize, v));
                }
            }
        }
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(nf, nf, &trip)
            .map_err(|e| SegmentError::Solver(format!("{e:?}")))?;
        let symbolic = factorize_symbolic_cholesky(
            a.symbolic(),
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| SegmentError::Solver(format!("{e:?}")))?;
        let mut values = vec![0.0f64; symbolic.len_val()];
        let mut mem = MemBuffer::try_new(
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
        )
        .map_err(|e| SegmentError::Solver(format!("{e:?}")))?;
        symbolic
            .factorize_numeric_llt(
                &mut values,
                a.as_ref(),
                Side::Lower,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|e| SegmentError::Solver(format!("{e:?}")))?;
        let targets = average.iter().map(|p| p.as_vec3()).collect();
        let edge_lengths = topo
            .edges
            .iter()
            .map(|e| average[e[0] as usize].distance(average[e[1] as usize]))
            .collect();
        let mut h = Homogenizer {
            weld_class,
            free_index,
            pinned_index,
            pinned,
            keep_input,
            targets,
            representative,
            qfp,
            symbolic,
            values,
            response: None,
            edges: topo.edges,
            edge_lengths,
            seam_count: seam.iter().filter(|s| **s).count(),
            factor_seconds: 0.0,
        };
        // Per frame column, a dense product costs 2·F·P flops and two triangular solves
        // ~4·nnz(L) at lower efficiency: precompute R when that is cheaper.
        let (f, p) = (nf, h.pinned.len());
        if f > 0 && p > 0 && f * p <= RESPONSE_COST_RATIO * h.symbolic.len_val() {
            let mut r = Mat::<f64>::zeros(f, p);
            for pl in 0..p {
                for (row, q) in h.qfp.row(pl) {
                    r[(row as usize, pl)] = -q;
                }
            }
            h.solve_split(r.as_mut());
            h.response = Some(r);
        }
        h.factor_seconds = start.elapsed().as_secs_f64();
        Ok(h)
    }

    /// Solves `Q_FF X = B` in place (sequential; callers parallelize over columns).
    fn solve_in_place(&self, rhs: MatMut<'_, f64>) {
        let mut mem = self.solve_scratch(rhs.ncols());
        self.solve_in_place_with(rhs, &mut mem);
    }

    /// faer's scratch for solving up to `columns` right-hand sides at once.
    fn solve_scratch(&self, columns: usize) -> MemBuffer {
        MemBuffer::new(
            self.symbolic
                .solve_in_place_scratch::<f64>(columns, Par::Seq),
        )
    }

    /// [`Homogenizer::solve_in_place`] with the caller's scratch (from
    /// [`Homogenizer::solve_scratch`] for at least `rhs.ncols()` columns).
    fn solve_in_place_with(&self, rhs: MatMut<'_, f64>, mem: &mut MemBuffer) {
        let llt = LltRef::new(&self.symbolic, &self.values);
        llt.solve_in_place_with_conj(Conj::No, rhs, Par::Seq, MemStack::new(mem));
    }

    /// Solves `Q_FF X = B` with the columns split across two threads (`rayon::join`).
    fn solve_split(&self, mut rhs: MatMut<'_, f64>) {
        let half = rhs.ncols() / 2;
        if half == 0 {
            self.solve_in_place(rhs);
            return;
        }
        let (left, right) = rhs.rb_mut().split_at_col_mut(half);
        rayon::join(|| self.solve_in_place(left), || self.solve_in_place(right));
    }

    /// Number of free (solved) welded vertices.
    pub fn free_count(&self) -> usize {
        self.symbolic.nrows()
    }

    /// Deforms every frame of `anim` in place (StopShop Eqs. 4–9), in parallel over chunks of
    /// [`DEFAULT_CHUNK_FRAMES`] frames; each chunk is solved by multi-column
    /// back-substitutions (or dense products) of a few frames at a time with `Par::Seq`.
    ///
    /// After the call, every pinned vertex holds exactly its average position in every
    /// frame (coincident duplicates included).
    ///
    /// # Performance
    /// One pass over the frames; per worker task an `F × 3·SOLVE_FRAMES` dense buffer and
    /// faer's solve scratch of the same size, or with the dense response an
    /// `(F + P) × 3·RESPONSE_FRAMES` buffer, reused for every chunk of the task.
    pub fn apply(&self, anim: &mut MeshAnimation) -> HomogenizeStats {
        let start = Instant::now();
        let m = anim.vertex_count();
        let chunk = DEFAULT_CHUNK_FRAMES;
        let nf = self.free_count();
        // One set of buffers per worker task, reused for every chunk it solves.
        let block = self.block_frames().min(anim.frame_count()).max(1);
        let partials: Vec<[f64; 6]> = anim
            .positions_mut()
            .par_chunks_mut((m * chunk).max(1))
            .map_init(
                || self.chunk_scratch(block),
                |scratch, frames| self.solve_chunk(frames, m, scratch),
            )
            .collect();
        let frames = anim.frame_count().max(1) as f64;
        let mut s = [0.0f64; 6];
        for p in &partials {
            s[0] += p[0];
            s[1] = s[1].max(p[1]);
            s[2] += p[2];
            s[3] = s[3].max(p[3]);
            s[4] = s[4].max(p[4]);
            s[5] += p[5];
        }
        HomogenizeStats {
            seam_vertices: self.seam_count,
            pinned_vertices: self.pinned.len() - self.kept_count(),
            kept_vertices: self.kept_count(),
            free_vertices: nf,
            mean_change: s[0] / (m.max(1) as f64 * frames),
            max_change: s[1],
            mean_free_change: s[2] / s[5].max(1.0),
            max_free_change: s[3],
            max_displacement_gradient: s[4],
            factor_seconds: self.factor_seconds,
            solve_seconds: start.elapsed().as_secs_f64(),
        }
    }

    /// Pinned welded vertices that keep the input's motion.
    fn kept_count(&self) -> usize {
        self.keep_input.iter().filter(|&&k| k).count()
    }

    /// Prescribed displacement of pinned welded vertex `w` in frame `y`: to its average
    /// position, or none when it keeps the input's motion.
    fn pinned_displacement(&self, w: usize, y: &[Vec3]) -> DVec3 {
        if self.keep_input[w] {
            DVec3::ZERO
        } else {
            (self.targets[w] - y[self.representative[w] as usize]).as_dvec3()
        }
    }

    /// Frames solved at once within a chunk.
    fn block_frames(&self) -> usize {
        if self.response.is_some() {
            RESPONSE_FRAMES
        } else {
            SOLVE_FRAMES
        }
    }

    /// Buffers for solving `block` frames at once (see [`ChunkScratch`]).
    fn chunk_scratch(&self, block: usize) -> ChunkScratch {
        let (nf, np) = (self.free_count(), self.pinned.len());
        let dense = self.response.is_some();
        ChunkScratch {
            d_free: Mat::zeros(nf, 3 * block),
            d_pinned: Mat::zeros(if dense { np } else { 0 }, 3 * block),
            disp: vec![DVec3::ZERO; self.targets.len()],
            solve: self.solve_scratch(if dense || nf == 0 { 0 } else { 3 * block }),
            block,
        }
    }

    /// Solves the frames of one chunk; returns [Σ|d|, max|d|, Σ|d_F|, max|d_F|, max grad, n_F].
    fn solve_chunk(&self, frames: &mut [Vec3], m: usize, s: &mut ChunkScratch) -> [f64; 6] {
        let nf = self.free_count();
        let nfr = frames.len() / m.max(1);
        let mut stats = [0.0f64; 6];
        if m == 0 || nfr == 0 {
            return stats;
        }
        // [`ChunkScratch::block`] frames at a time: every column is the same solve or
        // product whatever the columns beside it, and the frames are visited in the same
        // order, so the chunk's sums are unchanged.
        for y in frames.chunks_mut(m * s.block) {
            let cols = 3 * (y.len() / m);
            let mut rhs = s.d_free.as_mut().subcols_mut(0, cols);
            if let Some(response) = &self.response {
                // d_F = R d_P.
                let mut dp = s.d_pinned.as_mut().subcols_mut(0, cols);
                for (lf, y) in y.chunks_exact(m).enumerate() {
                    for (pl, &p) in self.pinned.iter().enumerate() {
                        let d = self.pinned_displacement(p as usize, y);
                        for k in 0..3 {
                            dp[(pl, 3 * lf + k)] = d[k];
                        }
                    }
                }
                // By blocks of rows: the product packs the rows of R it multiplies into a
                // buffer of the calling thread that lives as long as the thread (a worker of
                // the global pool: for good), so whole R would stay resident once per thread
                // (36 MB on the face); a block keeps it under 1 MB. Every entry is the same
                // sum in the same order.
                for r0 in (0..nf).step_by(RESPONSE_ROWS) {
                    let rows = RESPONSE_ROWS.min(nf - r0);
                    matmul(
                        rhs.rb_mut().subrows_mut(r0, rows),
                        Accum::Replace,
                        response.as_ref().subrows(r0, rows),
                        dp.as_ref(),
                        1.0,
                        Par::Seq,
                    );
                }
            } else {
                // Q_FF d_F = −Q_FP d_P.
                rhs.fill(0.0);
                for (lf, y) in y.chunks_exact(m).enumerate() {
                    for (pl, &p) in self.pinned.iter().enumerate() {
                        let d = self.pinned_displacement(p as usize, y);
                        for (r, q) in self.qfp.row(pl) {
                            for k in 0..3 {
                                rhs[(r as usize, 3 * lf + k)] -= q * d[k];
                            }
                        }
                    }
                }
                if nf > 0 {
                    self.solve_in_place_with(rhs.rb_mut(), &mut s.solve);
                }
            }
            self.move_frames(y, m, rhs.as_ref(), &mut s.disp, &mut stats);
        }
        stats
    }

    /// Moves `frames` (frame-major, `m` vertices each) by their solved free displacements
    /// (`d_F`, three columns per frame) and their pinned ones, adding to `stats` as
    /// [`Homogenizer::solve_chunk`] returns them; `disp` is scratch of one displacement per
    /// welded vertex.
    fn move_frames(
        &self,
        frames: &mut [Vec3],
        m: usize,
        d_free: MatRef<'_, f64>,
        disp: &mut [DVec3],
        stats: &mut [f64; 6],
    ) {
        for (lf, y) in frames.chunks_exact_mut(m).enumerate() {
            for (w, d) in disp.iter_mut().enumerate() {
                *d = match (self.free_index[w], self.pinned_index[w]) {
                    (Some(r), _) => DVec3::new(
                        d_free[(r as usize, 3 * lf)],
                        d_free[(r as usize, 3 * lf + 1)],
                        d_free[(r as usize, 3 * lf + 2)],
                    ),
                    (None, Some(_)) => self.pinned_displacement(w, y),
                    (None, None) => DVec3::ZERO,
                };
            }
            for (i, p) in y.iter_mut().enumerate() {
                let w = self.weld_class[i] as usize;
                let old = *p;
                *p = if self.pinned_index[w].is_some() && !self.keep_input[w] {
                    self.targets[w]
                } else {
                    (p.as_dvec3() + disp[w]).as_vec3()
                };
                let change = (*p - old).length() as f64;
                stats[0] += change;
                stats[1] = stats[1].max(change);
                if self.free_index[w].is_some() {
                    stats[2] += change;
                    stats[3] = stats[3].max(change);
                    stats[5] += 1.0;
                }
            }
            for (e, len) in self.edges.iter().zip(&self.edge_lengths) {
                if *len > 0.0 {
                    let g = (disp[e[0] as usize] - disp[e[1] as usize]).length() / len;
                    stats[4] = stats[4].max(g);
                }
            }
        }
    }
}

/// Buffers of one worker task of [`Homogenizer::apply`], reused for every chunk it solves.
struct ChunkScratch {
    /// Free displacements (or right-hand sides), three columns per frame.
    d_free: Mat<f64>,
    /// Pinned displacements, three columns per frame (with the dense response only).
    d_pinned: Mat<f64>,
    /// One displacement per welded vertex.
    disp: Vec<DVec3>,
    /// faer's solve scratch (without the dense response only).
    solve: MemBuffer,
    /// Frames solved at once.
    block: usize,
}
