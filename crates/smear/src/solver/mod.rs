//! Motion offsets of whole scenes: grouping objects, camera space, pruning, surface points.

use std::cell::Cell;

use anim::{Camera, MeshAnimation, SampledScene};
use serde::Serialize;

use crate::surface::SurfacePoint;
use crate::{CameraSelect, MotionOffsets, OffsetOptions, Result, SmearError};

mod field;
mod groups;

pub(crate) use field::SolvedField;

thread_local! {
    /// Offset solves started on this thread (see [`offset_solves`]).
    static SOLVES: Cell<usize> = const { Cell::new(0) };
}

fn count_solve() {
    SOLVES.with(|n| n.set(n.get() + 1));
}

/// Number of motion-offset solves (SMEAR Eqs. 1–9 over a scene or point cache) started on
/// the calling thread so far: lets tests and front ends check that restyling a
/// [`Prepared`](crate::Prepared) scene reuses its offsets instead of solving them again.
pub fn offset_solves() -> usize {
    SOLVES.with(Cell::get)
}

/// How an object's offsets are computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum OffsetMode {
    /// A simple object on its own: separation plane of SMEAR Eq. 1.
    Simple,
    /// Part of a skinned character treated as one simple object (whole-body mode, Fig. 14).
    WholeBody,
    /// A skinned mesh: ribbons of SMEAR Eqs. 3–9.
    Articulated,
}

/// Motion offsets of every object of a sampled scene (or of one bare point cache), computed
/// once and evaluated at vertices or arbitrary surface points.
///
/// Objects are grouped so that a character stays continuous across its meshes: all meshes
/// skinned to one skeleton tree form one articulated group (SMEAR Eqs. 3–9, neighbourhood
/// maxima of SMEAR Eq. 9 taken over all of them); in whole-body mode they form one simple
/// object together with the rigid props parented to its joints. Other objects, including
/// props parented to a joint outside whole-body mode, are simple objects moving with whatever
/// carries them.
#[derive(Debug)]
pub struct OffsetSolver<'a> {
    objects: Vec<&'a MeshAnimation>,
    field: SolvedField,
}

impl OffsetOptions {
    /// The camera [`OffsetOptions::camera`] selects among `cameras` (`None` when no camera is
    /// selected: world space).
    ///
    /// # Errors
    /// [`SmearError::UnknownCamera`] listing the cameras when the selection matches none.
    pub fn selected_camera<'c>(&self, cameras: &'c [Camera]) -> Result<Option<&'c Camera>> {
        resolve_camera(cameras, &self.camera)
    }
}

fn resolve_camera<'c>(
    cameras: &'c [Camera],
    select: &Option<CameraSelect>,
) -> Result<Option<&'c Camera>> {
    let Some(select) = select else {
        return Ok(None);
    };
    let found = match select {
        CameraSelect::Index(i) => cameras.get(*i),
        CameraSelect::Name(n) => cameras.iter().find(|c| c.name == *n),
    };
    found.map(Some).ok_or_else(|| SmearError::UnknownCamera {
        name: match select {
            CameraSelect::Index(i) => i.to_string(),
            CameraSelect::Name(n) => n.clone(),
        },
        available: cameras
            .iter()
            .map(|c| c.name.as_str())
            .collect::<Vec<_>>()
            .join(", "),
    })
}

impl<'a> OffsetSolver<'a> {
    /// Prepares the offsets of every object of `scene`.
    ///
    /// # Errors
    /// Unknown pruned joint or camera, a pruned root with skinned vertices, or an inconsistent
    /// scene (see [`SmearError`]).
    ///
    /// # Performance
    /// Computes the per-frame planes, ribbons, SMEAR Eq. 9 maxima and unsmoothed vertex
    /// offsets (parallel over frames); [`OffsetSolver::all`] then only smooths (SMEAR Eq. 2)
    /// and splits.
    pub fn new(scene: &'a SampledScene, options: &OffsetOptions) -> Result<OffsetSolver<'a>> {
        Ok(OffsetSolver {
            field: SolvedField::new(scene, options)?,
            objects: scene.objects.iter().map(|o| &o.animation).collect(),
        })
    }

    /// Prepares the offsets of a bare point cache, a simple object (SMEAR Eq. 1).
    ///
    /// # Arguments
    /// * `cameras` — cameras that `options.camera` may select from (may be empty).
    ///
    /// # Errors
    /// [`SmearError::UnknownCamera`] when the selected camera is not in `cameras`;
    /// [`SmearError::UnknownJoint`] when `options.prune` names a joint (there is no skeleton).
    pub fn from_animation(
        anim: &'a MeshAnimation,
        options: &OffsetOptions,
        cameras: &[Camera],
    ) -> Result<OffsetSolver<'a>> {
        Ok(OffsetSolver {
            field: SolvedField::from_animation(anim, options, cameras)?,
            objects: vec![anim],
        })
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.field.frame_count()
    }

    /// Number of objects (scene order).
    pub fn object_count(&self) -> usize {
        self.field.object_count()
    }

    /// How object `i`'s offsets are computed (`None` when out of range).
    pub fn mode(&self, i: usize) -> Option<OffsetMode> {
        self.field.mode(i)
    }

    /// Smoothed (SMEAR Eq. 2) offsets of every vertex of object `i`.
    ///
    /// # Errors
    /// [`SmearError::UnknownObject`] when `i` is out of range.
    ///
    /// # Performance
    /// Smooths only the object's own vertices (its group's neighbourhood maxima were taken
    /// when the solver was built).
    pub fn vertex_offsets(&self, i: usize) -> Result<MotionOffsets> {
        self.field.vertex_offsets(i)
    }

    /// Smoothed offsets of every object, in object order.
    pub fn all(&self) -> Vec<MotionOffsets> {
        self.field.all()
    }

    /// Smoothed offsets at surface points of object `i` (SMEAR Section 4.3: SMEAR Eq. 8
    /// evaluated at the points' own positions, skin weights interpolated barycentrically, the
    /// neighbourhood maxima of the mesh).
    ///
    /// # Returns
    /// `frames × points` offsets.
    ///
    /// # Errors
    /// [`SmearError::UnknownObject`], or [`SmearError::InvalidSurfacePoint`] for a triangle out
    /// of range or unusable barycentric coordinates.
    pub fn surface_offsets(&self, i: usize, points: &[SurfacePoint]) -> Result<MotionOffsets> {
        self.field.surface_offsets(&self.objects, i, points)
    }
}

/// Motion offsets of every object of a sampled scene (see [`OffsetSolver`]).
///
/// # Errors
/// As [`OffsetSolver::new`].
pub fn scene_offsets(scene: &SampledScene, options: &OffsetOptions) -> Result<Vec<MotionOffsets>> {
    Ok(OffsetSolver::new(scene, options)?.all())
}

/// Motion offsets of a bare point cache treated as a simple object (SMEAR Eqs. 1–2).
///
/// # Errors
/// As [`OffsetSolver::from_animation`] with no camera.
pub fn mesh_offsets(anim: &MeshAnimation, options: &OffsetOptions) -> Result<MotionOffsets> {
    let s = OffsetSolver::from_animation(anim, options, &[])?;
    Ok(s.all().remove(0))
}
