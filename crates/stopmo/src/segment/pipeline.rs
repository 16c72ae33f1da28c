//! The segmentation pipeline: seeds → graph cut (StopShop Eqs. 1–3) → smooth boundaries → cut mesh →
//! seam homogenization (StopShop Eqs. 4–9) → per-part animations.

use std::borrow::Cow;

use anim::{Mesh, MeshAnimation};
use glam::{DVec3, Vec3};

use super::cut::{cut_mesh, CutMesh, DEFAULT_SNAP};
use super::cut_animation::build_cut_animation;
use super::error::{Result, SegmentError};
use super::homogenize::{HomogenizeStats, Homogenizer};
use super::problem::{SegmentationProblem, DEFAULT_GAMMA};
use super::seeds::{auto_seeds, resolve_seeds, PartSpec, Seed};
use super::smooth::{smooth_votes, vertex_votes, DEFAULT_SMOOTH_ITERATIONS, DEFAULT_SMOOTH_STEP};
use super::topology::{open_border, Topology};
use super::weld::{Weld, DEFAULT_WELD_EPSILON};

/// Vertices of the cut released at once while [`Segmentation::take_parts`] moves its frames
/// (12 MiB: few reallocations, little held twice).
const RELEASE_VERTICES: usize = 1 << 20;

/// Parameters of [`segment`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct SegmentOptions {
    /// Weight γ of the binary term of StopShop Eq. 1 (unit-box units).
    pub gamma: f64,
    /// Laplacian smoothing iterations of the part votes (0 keeps the jagged per-triangle
    /// boundary, cut exactly along edges).
    pub smooth_iterations: usize,
    /// Step of one smoothing iteration, in (0, 1].
    pub smooth_step: f64,
    /// Snap threshold of level-set crossings (fraction of an edge), in [0, 0.49].
    pub snap: f64,
    /// Homogenize the seams (Section 3.2).
    pub homogenize: bool,
    /// Welding tolerance relative to the bounding-box diagonal.
    pub weld_epsilon: f32,
    /// Open mesh borders (neck, scalp) keep the input's motion during homogenization, so the
    /// deformation decays from the seams instead of moving the whole part.
    pub keep_open_borders: bool,
}

impl Default for SegmentOptions {
    fn default() -> SegmentOptions {
        SegmentOptions {
            gamma: DEFAULT_GAMMA,
            smooth_iterations: DEFAULT_SMOOTH_ITERATIONS,
            smooth_step: DEFAULT_SMOOTH_STEP,
            snap: DEFAULT_SNAP,
            homogenize: true,
            weld_epsilon: DEFAULT_WELD_EPSILON,
            keep_open_borders: true,
        }
    }
}

/// The result of [`segment`].
#[derive(Debug, Clone)]
pub struct Segmentation {
    /// Part names, in part order.
    pub part_names: Vec<String>,
    /// γ used.
    pub gamma: f64,
    /// Seed triangles of every part (input triangle ids).
    pub seeds: Vec<Vec<u32>>,
    /// Graph-cut label of every input triangle (before boundary smoothing).
    pub input_triangle_part: Vec<u32>,
    /// The cut (and, if requested, homogenized) animation: input vertices first, in input
    /// order, then the new boundary vertices; same frames as the input.
    pub animation: MeshAnimation,
    /// How every vertex of `animation` derives from the input vertices.
    pub cut: CutMesh,
    /// Part of every triangle of `animation`.
    pub triangle_part: Vec<u32>,
    /// Vertices of `animation` on a part boundary, sorted.
    pub seam_vertices: Vec<u32>,
    /// Length of the part boundaries on the average mesh, in model units.
    pub cut_length: f64,
    /// Homogenization measurements (`None` when not requested).
    pub homogenization: Option<HomogenizeStats>,
    /// Average position of every vertex of `animation` over the input clip: the seam targets
    /// of homogenization, kept so that another clip can reuse this cut
    /// ([`Segmentation::saved`]).
    pub reference: Vec<Vec3>,
}

/// One part as its own animation.
#[derive(Debug, Clone)]
pub struct Part {
    /// Part name.
    pub name: String,
    /// The part's triangles and vertices, all frames.
    pub animation: MeshAnimation,
    /// For every vertex of the part, its vertex in [`Segmentation::animation`].
    pub vertices: Vec<u32>,
}

/// The JSON report of `toonkit stopmo segment --report` (SPEC "Output layouts").
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SegmentReport {
    /// Part names.
    pub parts: Vec<String>,
    /// Part of every triangle of the output mesh.
    pub triangle_part: Vec<u32>,
    /// Output vertices on part boundaries.
    pub seam_vertices: Vec<u32>,
    /// γ used.
    pub gamma: f64,
    /// Boundary length on the average mesh (model units).
    pub cut_length: f64,
    /// Homogenization measurements, when run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub homogenization: Option<HomogenizeStats>,
}

impl Segmentation {
    /// Number of parts.
    pub fn part_count(&self) -> usize {
        self.part_names.len()
    }

    /// Every part as its own animation (vertices in increasing order of their id in
    /// [`Segmentation::animation`]; seam vertices are copied into every part they bound).
    pub fn parts(&self) -> Result<Vec<Part>> {
        (0..self.part_count()).map(|j| self.part(j)).collect()
    }

    /// Part `j` as its own animation.
    ///
    /// # Errors
    /// [`SegmentError::Parameter`] when `j` is not a part.
    pub fn part(&self, j: usize) -> Result<Part> {
        let (mesh, vertices) = self.part_layout(j)?;
        let positions: Vec<Vec3> = self
            .animation
            .frames()
            .flat_map(|f| vertices.iter().map(move |&i| f[i as usize]))
            .collect();
        self.part_from(j, mesh, vertices, positions)
    }

    /// Every part as [`Segmentation::parts`] makes them, with the cut's frames moved into
    /// them instead of copied: afterwards [`Segmentation::animation`] holds only the cut
    /// mesh (one frame, its rest positions). The cut is released from its last frame down
    /// as the parts are filled, so the clip is resident about once, not twice, at the peak.
    ///
    /// # Errors
    /// As [`Segmentation::parts`].
    pub fn take_parts(&mut self) -> Result<Vec<Part>> {
        let layouts = (0..self.part_count())
            .map(|j| self.part_layout(j))
            .collect::<Result<Vec<_>>>()?;
        let n = self.animation.vertex_count();
        let frames = self.animation.frame_count();
        let still = MeshAnimation::still(self.animation.mesh.clone());
        let (fps, start_time) = (self.animation.fps, self.animation.start_time);
        let (_, mut cut) = std::mem::replace(&mut self.animation, still).into_parts();
        self.animation.fps = fps;
        self.animation.start_time = start_time;
        // Zeroed (fresh, untouched pages): a part's pages become resident as its frames are
        // written, while the cut's are given back.
        let mut out: Vec<Vec<Vec3>> = layouts
            .iter()
            .map(|(_, v)| bytemuck::zeroed_vec(frames * v.len()))
            .collect();
        for f in (0..frames).rev() {
            let src = &cut[f * n..(f + 1) * n];
            for ((_, vertices), dst) in layouts.iter().zip(&mut out) {
                let m = vertices.len();
                for (d, &i) in dst[f * m..(f + 1) * m].iter_mut().zip(vertices) {
                    *d = src[i as usize];
                }
            }
            if cut.len() - f * n >= RELEASE_VERTICES {
                cut.truncate(f * n);
                cut.shrink_to_fit();
            }
        }
        drop(cut);
        layouts
            .into_iter()
            .zip(out)
            .enumerate()
            .map(|(j, ((mesh, vertices), positions))| self.part_from(j, mesh, vertices, positions))
            .collect()
    }

    /// Part `j`'s mesh (its triangles, vertices renumbered) and, for every part vertex, its
    /// vertex in [`Segmentation::animation`].
    fn part_layout(&self, j: usize) -> Result<(Mesh, Vec<u32>)> {
        if j >= self.part_count() {
            return Err(SegmentError::Parameter(format!("no part {j}")));
        }
        let mesh = &self.animation.mesh;
        let mut local = vec![u32::MAX; mesh.vertex_count()];
        let tris: Vec<[u32; 3]> = mesh
            .triangles
            .iter()
            .zip(&self.triangle_part)
            .filter(|(_, p)| **p as usize == j)
            .map(|(t, _)| *t)
            .collect();
        for t in &tris {
            for &i in t {
                local[i as usize] = 0;
            }
        }
        let mut vertices = Vec::new();
        for (i, l) in local.iter_mut().enumerate() {
            if *l == 0 {
                *l = vertices.len() as u32;
                vertices.push(i as u32);
            }
        }
        let pick =
            |src: &[Vec3]| -> Vec<Vec3> { vertices.iter().map(|&i| src[i as usize]).collect() };
        let mut part_mesh = Mesh::new(
            self.part_names[j].clone(),
            pick(&mesh.positions),
            tris.iter().map(|t| t.map(|i| local[i as usize])).collect(),
        );
        part_mesh.normals = mesh.normals.as_ref().map(|n| pick(n));
        part_mesh.uvs = mesh
            .uvs
            .as_ref()
            .map(|u| vertices.iter().map(|&i| u[i as usize]).collect());
        part_mesh.colors = mesh
            .colors
            .as_ref()
            .map(|c| vertices.iter().map(|&i| c[i as usize]).collect());
        Ok((part_mesh, vertices))
    }

    /// Part `j` from its layout and its frames.
    fn part_from(
        &self,
        j: usize,
        mesh: Mesh,
        vertices: Vec<u32>,
        positions: Vec<Vec3>,
    ) -> Result<Part> {
        let mut animation = MeshAnimation::new(mesh, self.animation.fps, positions)
            .map_err(|e| SegmentError::Invalid(e.to_string()))?;
        animation.start_time = self.animation.start_time;
        Ok(Part {
            name: self.part_names[j].clone(),
            animation,
            vertices,
        })
    }

    /// The report of SPEC "Output layouts".
    pub fn report(&self) -> SegmentReport {
        SegmentReport {
            parts: self.part_names.clone(),
            triangle_part: self.triangle_part.clone(),
            seam_vertices: self.seam_vertices.clone(),
            gamma: self.gamma,
            cut_length: self.cut_length,
            homogenization: self.homogenization,
        }
    }
}

/// Automatic parts: `n` parts named `part1`…`partN`, one seed triangle each, chosen by
/// [`auto_seeds`].
pub fn auto_parts(anim: &MeshAnimation, n: usize) -> Result<Vec<PartSpec>> {
    let problem = SegmentationProblem::with_defaults(anim)?;
    let seeds = auto_seeds(anim, &problem, n)?;
    Ok(seeds
        .into_iter()
        .enumerate()
        .map(|(j, s)| {
            PartSpec::new(
                format!("part{}", j + 1),
                s.into_iter().map(Seed::Triangle).collect(),
            )
        })
        .collect())
}

/// Segments an animation into parts and homogenizes the seams (Sections 3.1–3.2).
///
/// # Arguments
/// * `anim` — the input mesh animation X.
/// * `parts` — at least two named parts with seeds.
/// * `options` — γ, smoothing, snapping, homogenization ([`SegmentOptions::default`]).
///
/// # Errors
/// Bad seeds or parts ([`SegmentError`]), or a failed factorization.
///
/// # Performance
/// One parallel pass over the frames for StopShop Eq. 3, one min-cut (or a few α-expansion cycles),
/// one sparse Cholesky factorization and one parallel back-substitution pass.
pub fn segment(
    anim: &MeshAnimation,
    parts: &[PartSpec],
    options: &SegmentOptions,
) -> Result<Segmentation> {
    segment_input(Cow::Borrowed(anim), parts, options)
}

/// [`segment`] on an input that is borrowed or handed over: an owned input's frames become
/// the cut animation's (grown in place), so the input and its cut are never held at once.
pub(crate) fn segment_input(
    anim: Cow<'_, MeshAnimation>,
    parts: &[PartSpec],
    options: &SegmentOptions,
) -> Result<Segmentation> {
    check_options(options)?;
    let problem = SegmentationProblem::new(&anim, options.weld_epsilon)?;
    let seeds = resolve_seeds(&anim, &problem, parts)?;
    cut_input(
        anim,
        &problem,
        parts.iter().map(|p| p.name.clone()).collect(),
        seeds,
        options,
    )
}

fn check_options(o: &SegmentOptions) -> Result<()> {
    if !(o.gamma.is_finite() && o.gamma >= 0.0) {
        return Err(SegmentError::Parameter(format!(
            "gamma must be ≥ 0, got {}",
            o.gamma
        )));
    }
    if !(o.smooth_step > 0.0 && o.smooth_step <= 1.0) {
        return Err(SegmentError::Parameter(format!(
            "smooth step must be in (0, 1], got {}",
            o.smooth_step
        )));
    }
    if !(0.0..=0.49).contains(&o.snap) {
        return Err(SegmentError::Parameter(format!(
            "snap must be in [0, 0.49], got {}",
            o.snap
        )));
    }
    Ok(())
}

/// [`segment`] on a prepared problem with resolved seeds (reuse the problem to try several
/// seeds or γ values without recomputing StopShop Eq. 3).
pub fn segment_with(
    anim: &MeshAnimation,
    problem: &SegmentationProblem,
    part_names: Vec<String>,
    seeds: Vec<Vec<u32>>,
    options: &SegmentOptions,
) -> Result<Segmentation> {
    cut_input(Cow::Borrowed(anim), problem, part_names, seeds, options)
}

/// [`segment_with`] on a borrowed or handed-over input (see [`segment_input`]).
fn cut_input(
    anim: Cow<'_, MeshAnimation>,
    problem: &SegmentationProblem,
    part_names: Vec<String>,
    seeds: Vec<Vec<u32>>,
    options: &SegmentOptions,
) -> Result<Segmentation> {
    check_options(options)?;
    let s = seeds.len();
    if s < 2 {
        return Err(SegmentError::TooFewParts(s));
    }
    if part_names.len() != s {
        return Err(SegmentError::Parameter(format!(
            "{} names for {s} parts",
            part_names.len()
        )));
    }
    let labels = problem.label(&seeds, options.gamma);
    let mut votes = vertex_votes(
        s,
        &problem.topology.vertex_triangles,
        &labels,
        &problem.areas,
    );
    smooth_votes(
        &mut votes,
        s,
        &problem.topology.neighbors,
        options.smooth_iterations,
        options.smooth_step,
    );
    // Seeds stay hard constraints through smoothing: their corners vote for their part only.
    for (j, part) in seeds.iter().enumerate() {
        for &t in part {
            for v in anim.mesh.triangles[t as usize] {
                let w = problem.weld.class[v as usize] as usize;
                for (l, x) in votes[w * s..(w + 1) * s].iter_mut().enumerate() {
                    *x = if l == j { 1.0 } else { 0.0 };
                }
            }
        }
    }
    let cut = cut_mesh(
        &anim.mesh.triangles,
        &problem.weld.class,
        problem.weld.len(),
        &votes,
        s,
        options.snap,
    );
    let average_input = problem.average_positions();
    let reference: Vec<Vec3> = cut.sources.iter().map(|s| s.eval(average_input)).collect();
    finish(
        anim,
        cut,
        Labels {
            part_names,
            seeds,
            input_triangle_part: labels,
            gamma: options.gamma,
        },
        reference,
        options,
    )
}

/// What a cut carries besides its geometry.
pub(super) struct Labels {
    pub part_names: Vec<String>,
    pub seeds: Vec<Vec<u32>>,
    pub input_triangle_part: Vec<u32>,
    pub gamma: f64,
}

/// Evaluates the cut on `anim` (an owned input becomes the cut animation in place), finds the
/// seam and homogenizes it towards `reference` (the average positions of the cut vertices on
/// the clip that defined the cut).
pub(super) fn finish(
    anim: Cow<'_, MeshAnimation>,
    cut: CutMesh,
    labels: Labels,
    reference: Vec<Vec3>,
    options: &SegmentOptions,
) -> Result<Segmentation> {
    let mut animation = build_cut_animation(anim, &cut)?;
    // Seam and cut length on the welded cut mesh.
    let weld_y = Weld {
        class: cut.weld_class.clone(),
        representative: representatives(&cut.weld_class, cut.welded_count),
    };
    let welded_tris = weld_y.triangles(&cut.triangles);
    let topo = Topology::new(weld_y.len(), &welded_tris);
    let average: Vec<DVec3> = weld_y
        .representative
        .iter()
        .map(|&r| reference[r as usize].as_dvec3())
        .collect();
    let mut seam = vec![false; weld_y.len()];
    let mut first_part = vec![u32::MAX; weld_y.len()];
    for (t, tri) in welded_tris.iter().enumerate() {
        for &v in tri {
            let f = &mut first_part[v as usize];
            if *f == u32::MAX {
                *f = cut.triangle_part[t];
            } else if *f != cut.triangle_part[t] {
                seam[v as usize] = true;
            }
        }
    }
    let cut_length = topo
        .dual
        .iter()
        .filter(|e| cut.triangle_part[e.a as usize] != cut.triangle_part[e.b as usize])
        .map(|e| average[e.v[0] as usize].distance(average[e.v[1] as usize]))
        .sum();
    let seam_vertices: Vec<u32> = (0..cut.weld_class.len() as u32)
        .filter(|&i| seam[cut.weld_class[i as usize] as usize])
        .collect();

    let homogenization = if options.homogenize {
        let keep = if options.keep_open_borders {
            open_border(weld_y.len(), &welded_tris)
        } else {
            vec![false; weld_y.len()]
        };
        let h = Homogenizer::with_kept(
            &average,
            &welded_tris,
            &seam,
            &keep,
            weld_y.class.clone(),
            weld_y.representative.clone(),
        )?;
        Some(h.apply(&mut animation))
    } else {
        None
    };
    Ok(Segmentation {
        part_names: labels.part_names,
        gamma: labels.gamma,
        seeds: labels.seeds,
        input_triangle_part: labels.input_triangle_part,
        animation,
        triangle_part: cut.triangle_part.clone(),
        cut,
        seam_vertices,
        cut_length,
        homogenization,
        reference,
    })
}

fn representatives(class: &[u32], count: usize) -> Vec<u32> {
    let mut rep = vec![u32::MAX; count];
    for (i, &c) in class.iter().enumerate() {
        if rep[c as usize] == u32::MAX {
            rep[c as usize] = i as u32;
        }
    }
    rep
}

/// Homogenizes the seams of an animation whose triangles already carry part labels
/// (Section 3.2, StopShop Eqs. 4–9), without cutting.
///
/// # Arguments
/// * `anim` — the animation (vertices coincident in the average mesh are welded).
/// * `triangle_part` — part of every triangle.
/// * `weld_epsilon` — welding tolerance relative to the bounding-box diagonal.
///
/// # Returns
/// The deformed animation and measurements.
///
/// # Errors
/// Wrong label count, or a failed factorization.
pub fn homogenize(
    anim: &MeshAnimation,
    triangle_part: &[u32],
    weld_epsilon: f32,
) -> Result<(MeshAnimation, HomogenizeStats)> {
    let k = anim.mesh.triangle_count();
    if triangle_part.len() != k {
        return Err(SegmentError::LabelCount {
            expected: k,
            found: triangle_part.len(),
        });
    }
    anim.mesh
        .validate()
        .map_err(|e| SegmentError::Invalid(e.to_string()))?;
    let avg = anim.average_positions();
    let bbox = anim::Aabb::from_points(&avg);
    let weld = Weld::new(
        &avg,
        if weld_epsilon > 0.0 {
            weld_epsilon * bbox.diagonal()
        } else {
            0.0
        },
    );
    let tris = weld.triangles(&anim.mesh.triangles);
    let mut first = vec![u32::MAX; weld.len()];
    let mut seam = vec![false; weld.len()];
    for (t, tri) in tris.iter().enumerate() {
        for &v in tri {
            let f = &mut first[v as usize];
            if *f == u32::MAX {
                *f = triangle_part[t];
            } else if *f != triangle_part[t] {
                seam[v as usize] = true;
            }
        }
    }
    let average: Vec<DVec3> = weld.gather(&avg).iter().map(|p| p.as_dvec3()).collect();
    let keep = open_border(weld.len(), &tris);
    let h = Homogenizer::with_kept(
        &average,
        &tris,
        &seam,
        &keep,
        weld.class.clone(),
        weld.representative.clone(),
    )?;
    let mut out = anim.clone();
    let stats = h.apply(&mut out);
    Ok((out, stats))
}
