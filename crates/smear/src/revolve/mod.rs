//! Revolving parts (issue #22; the limitation of SMEAR Fig. 19): objects whose motion is
//! mostly a rotation about an axis — a wheel, a propeller, a sword turning about the wrist.
//!
//! # Construction
//! SMEAR Eq. 1 separates an object by a plane through its centroid normal to the centroid's
//! velocity; a spinning propeller has a still centroid, so every offset is 0, and Catmull-Rom
//! trajectories through samples far apart on a circle cut its chord. For a revolving object we
//! instead
//! 1. fit, per frame interval k → k+1, the rigid motion of its vertices as a screw
//!    ([`fit_screw`]: rotation by θ_k about the line through c_k along a_k, slide along a_k);
//! 2. take as offsets the signed arc length ahead of each connected piece's angular centre:
//!    with φ_i the angle of vertex i about the axis, φ̄ the radius-weighted circular mean of
//!    its piece and r_i its distance to the axis, δ̃_i = r_i · wrap(φ_i − φ̄), normalized by
//!    the largest |δ̃| of the object (so δ ∈ [−1, 1], leading edges of every blade > 0),
//!    then smoothed by SMEAR Eq. 2 — Eq. 1 with the plane replaced by the half-plane through
//!    the axis;
//! 3. move points along arcs: `Q_{i,k}(t) = S_k(p_i(k), t) + t·(p_i(k+1) − S_k(p_i(k), 1))`,
//!    the screw applied to the fraction t plus a linear correction that is zero for a rigid
//!    motion, so points stay on their circles and the trajectory still passes through every
//!    frame (beyond the clip, or beyond the current frame in causal mode, the last screw keeps
//!    turning).

mod offsets;
mod screw;

pub use offsets::revolving_offsets;
pub use screw::{fit_screw, Screw};

use anim::SampledScene;
use glam::Vec3;

use crate::{MotionOffsets, OffsetOptions, Result, SmearError};

/// The word of [`OffsetOptions::revolve`](crate::OffsetOptions::revolve) that asks to detect
/// revolving objects.
pub const REVOLVE_AUTO: &str = "auto";

/// Slowest rotation (radians per frame, median over the clip) that `auto` detects.
const AUTO_MIN_ANGLE: f32 = 0.05;

/// Largest fit residual (fraction of the object's bounding-box diagonal) `auto` accepts.
const AUTO_MAX_RESIDUAL: f32 = 0.02;

/// Revolving parts of one effect target: for each point the part it belongs to, and each
/// part's screw per frame interval.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Arcs {
    part: Vec<u32>,
    screws: Vec<Vec<Screw>>,
}

/// No part.
const NONE: u32 = u32::MAX;

impl Arcs {
    /// No revolving part among `points` points.
    pub fn none(points: usize) -> Arcs {
        Arcs {
            part: vec![NONE; points],
            screws: Vec::new(),
        }
    }

    /// Marks points `range` as one revolving part moving by `screws` (one per frame interval).
    pub fn add_part(&mut self, range: std::ops::Range<usize>, screws: Vec<Screw>) {
        let id = self.screws.len() as u32;
        for p in &mut self.part[range] {
            *p = id;
        }
        self.screws.push(screws);
    }

    /// Whether no point revolves.
    pub fn is_empty(&self) -> bool {
        self.screws.is_empty()
    }

    /// Number of points.
    pub fn point_count(&self) -> usize {
        self.part.len()
    }

    /// The screws of point `i`'s part, `None` when it does not revolve.
    #[inline]
    pub fn screws_of(&self, i: usize) -> Option<&[Screw]> {
        match self.part.get(i) {
            Some(&p) if p != NONE => Some(&self.screws[p as usize]),
            _ => None,
        }
    }

    /// Whether points `i` and `j` move along the same arcs (or neither revolves).
    #[inline]
    pub(crate) fn same_part(&self, i: usize, j: usize) -> bool {
        self.part.get(i) == self.part.get(j)
    }

    /// The arcs of other points, each taking the part of point `source(k)` (e.g. a surface
    /// point takes its triangle's first corner's).
    pub fn remap(&self, count: usize, source: impl Fn(usize) -> usize) -> Arcs {
        Arcs {
            part: (0..count)
                .map(|k| self.part.get(source(k)).copied().unwrap_or(NONE))
                .collect(),
            screws: self.screws.clone(),
        }
    }
}

/// Screws of every frame interval of one object (frame-major `frames × vertices` positions)
/// and the largest RMS fit residual.
pub fn object_screws(positions: &[Vec3], frames: usize, vertices: usize) -> (Vec<Screw>, f32) {
    let frame = |f: usize| &positions[f * vertices..(f + 1) * vertices];
    let fits: Vec<(Screw, f32)> = (0..frames.saturating_sub(1))
        .map(|k| fit_screw(frame(k), frame(k + 1)))
        .collect();
    let worst = fits.iter().fold(0.0f32, |m, f| m.max(f.1));
    (fits.into_iter().map(|f| f.0).collect(), worst)
}

/// Whether an object's motion is mostly a rotation: median angle ≥ 0.05 rad per frame and a
/// rigid fit within 2 % of its size.
fn looks_revolving(screws: &[Screw], residual: f32, diagonal: f32) -> bool {
    if screws.is_empty() || residual > AUTO_MAX_RESIDUAL * diagonal {
        return false;
    }
    let mut angles: Vec<f32> = screws.iter().map(|s| s.angle).collect();
    angles.sort_by(f32::total_cmp);
    angles[angles.len() / 2] >= AUTO_MIN_ANGLE
}

/// The objects of `scene` named in `names` (or detected, with [`REVOLVE_AUTO`]) with their
/// screws, in scene order.
///
/// # Errors
/// [`SmearError::InvalidParameter`] naming an object the scene does not have.
pub(crate) fn revolving_objects(
    scene: &SampledScene,
    names: &[String],
) -> Result<Vec<Option<Vec<Screw>>>> {
    let auto = names.iter().any(|n| n == REVOLVE_AUTO);
    for n in names.iter().filter(|n| *n != REVOLVE_AUTO) {
        if !scene.objects.iter().any(|o| o.name == *n) {
            let known: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
            return Err(SmearError::InvalidParameter {
                name: "revolve",
                reason: format!(
                    "no object named '{n}' (objects: {}; or 'auto')",
                    known.join(", ")
                ),
            });
        }
    }
    Ok(scene
        .objects
        .iter()
        .map(|o| {
            let named = names.contains(&o.name);
            if !(named || auto && o.skin.is_none()) {
                return None;
            }
            let a = &o.animation;
            let (screws, residual) =
                object_screws(a.positions(), a.frame_count(), a.vertex_count());
            let diagonal = anim::Aabb::from_points(a.frame(0)).diagonal();
            (named || looks_revolving(&screws, residual, diagonal)).then_some(screws)
        })
        .collect())
}

/// The offsets of every object with those of revolving objects replaced by
/// [`revolving_offsets`].
pub(crate) fn replace_offsets(
    scene: &SampledScene,
    options: &OffsetOptions,
    revolving: &[Option<Vec<Screw>>],
    mut per_object: Vec<MotionOffsets>,
) -> Vec<MotionOffsets> {
    for ((o, screws), d) in scene
        .objects
        .iter()
        .zip(revolving)
        .zip(per_object.iter_mut())
    {
        if let Some(screws) = screws {
            let a = &o.animation;
            let values = revolving_offsets(
                a.positions(),
                a.frame_count(),
                &a.mesh.triangles,
                screws,
                options.smooth,
                options.causal,
            );
            *d = MotionOffsets::new(a.frame_count(), a.vertex_count(), values)
                .expect("frames × vertices");
        }
    }
    per_object
}

/// The arcs of one effect target: all objects merged (`merged`), or object `only`.
pub(crate) fn target_arcs(
    scene: &SampledScene,
    revolving: &[Option<Vec<Screw>>],
    only: Option<usize>,
) -> Option<Arcs> {
    let mut base = 0;
    let count = match only {
        Some(i) => scene.objects[i].animation.vertex_count(),
        None => scene.vertex_count(),
    };
    let mut arcs = Arcs::none(count);
    for (i, (o, screws)) in scene.objects.iter().zip(revolving).enumerate() {
        let n = o.animation.vertex_count();
        if only.is_none_or(|k| k == i) {
            if let Some(s) = screws {
                arcs.add_part(base..base + n, s.clone());
            }
            base += n;
        }
    }
    (!arcs.is_empty()).then_some(arcs)
}
