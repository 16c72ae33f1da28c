//! Motion offsets of whole scenes: grouping objects, camera space, pruning, surface points.

use std::cell::Cell;

use anim::{Aabb, Camera, MeshAnimation, SampledScene, Skin};
use glam::Vec3;
use rayon::prelude::*;
use serde::Serialize;

use crate::field::{Field, Tolerances};
use crate::rig::{Pruned, Rig};
use crate::surface::SurfacePoint;
use crate::velocity::CameraSpace;
use crate::{
    CameraSelect, MotionOffsets, OffsetOptions, Result, SmearError, DEFAULT_STILL_TOLERANCE,
    DEFAULT_ZERO_LENGTH, STILL_ROUNDING_FACTOR,
};

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

/// Where an object's vertices sit in its group.
#[derive(Debug, Clone)]
struct Slot {
    group: usize,
    base: usize,
    vertices: usize,
}

/// The positions a group's field was computed on: one object's own cache (not copied), or
/// several objects side by side.
#[derive(Debug, Clone)]
enum GroupPositions {
    /// The cache of this object (index into the solver's objects).
    Object(usize),
    /// Frame-major positions of several objects merged.
    Merged(Vec<Vec3>),
}

#[derive(Debug)]
struct Group {
    positions: GroupPositions,
    vertices: usize,
    mode: OffsetMode,
    field: Field,
    /// Unsmoothed vertex offsets, frame-major.
    raw: Vec<f32>,
}

/// The solved offset fields of a scene, owning everything but the objects' caches: what
/// [`OffsetSolver`] and [`Prepared`](crate::Prepared) evaluate at vertices and surface points.
#[derive(Debug)]
pub(crate) struct SolvedField {
    frames: usize,
    smooth: usize,
    /// Past-only smoothing window (causal mode).
    causal: bool,
    slots: Vec<Slot>,
    groups: Vec<Group>,
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

/// Absolute tolerances from the bounding box of the first, middle and last frames.
///
/// The still tolerance is SPEC.md's `DEFAULT_STILL_TOLERANCE × diagonal`, raised to the f32
/// rounding of the coordinates involved ([`STILL_ROUNDING_FACTOR`] × the largest absolute
/// coordinate, camera translation included): below that a "velocity" is rounding noise
/// (e.g. an object followed by the camera) and would give a random separation plane.
fn tolerances(
    positions: &[Vec3],
    frames: usize,
    vertices: usize,
    space: Option<&CameraSpace>,
    causal: bool,
) -> Tolerances {
    let mut b = Aabb::EMPTY;
    if vertices > 0 {
        // Causal mode: frame 0 only, so no threshold depends on later frames.
        let probes = if causal {
            [0, 0, 0]
        } else {
            [0, frames / 2, frames.saturating_sub(1)]
        };
        for f in probes {
            b = b.union(Aabb::from_points(
                &positions[f * vertices..(f + 1) * vertices],
            ));
        }
    }
    let diag = b.diagonal();
    let mut scale = if b.is_empty() {
        0.0
    } else {
        b.min.abs().max(b.max.abs()).max_element()
    };
    if let Some(c) = space {
        scale = scale.max(c.max_translation());
    }
    Tolerances {
        still: (DEFAULT_STILL_TOLERANCE * diag).max(STILL_ROUNDING_FACTOR * scale),
        zero_length: DEFAULT_ZERO_LENGTH * diag,
        causal,
    }
}

/// Frame-major positions of several caches side by side (`None` when there is one: its own
/// cache is used as is).
fn merged_positions(parts: &[&MeshAnimation], frames: usize) -> Option<Vec<Vec3>> {
    if parts.len() == 1 {
        return None;
    }
    let n: usize = parts.iter().map(|a| a.vertex_count()).sum();
    let mut out = Vec::with_capacity(n * frames);
    for f in 0..frames {
        for a in parts {
            out.extend_from_slice(a.frame(f));
        }
    }
    Some(out)
}

fn merged_triangles(parts: &[&MeshAnimation]) -> Vec<[u32; 3]> {
    let mut base = 0u32;
    let mut out = Vec::new();
    for a in parts {
        out.extend(a.mesh.triangles.iter().map(|t| t.map(|i| i + base)));
        base += a.vertex_count() as u32;
    }
    out
}

/// `len` zeros whose pages are already mapped: one store per 4 KiB page (the value hidden
/// from the optimizer, which would drop stores of zero into zeroed memory) makes the kernel
/// map and clear each page here, on the calling thread.
fn touched_zeros(len: usize) -> Vec<f32> {
    let mut v = vec![0.0f32; len];
    for x in v.iter_mut().step_by(1024) {
        *x = std::hint::black_box(0.0);
    }
    v
}

/// Checks that the scene's buffers agree (bones per frame, frames per object, skin slots).
fn check_scene(scene: &SampledScene) -> Result<()> {
    let frames = scene.frame_count;
    let joints = scene.skeleton.len();
    if joints > 0 && scene.bones.len() != frames * joints {
        return Err(SmearError::InvalidScene(format!(
            "{} bones for {frames} frames × {joints} joints",
            scene.bones.len()
        )));
    }
    for o in &scene.objects {
        if o.animation.frame_count() != frames {
            return Err(SmearError::InvalidScene(format!(
                "object '{}' has {} frames, the scene {frames}",
                o.name,
                o.animation.frame_count()
            )));
        }
        if let Some(s) = &o.skin {
            s.validate(o.animation.vertex_count(), joints)
                .map_err(|e| SmearError::InvalidScene(format!("object '{}': {e}", o.name)))?;
        }
    }
    Ok(())
}

/// Objects grouped for the solve: `Some(root joint)` for characters, `None` for a standalone
/// simple object, with the members of each group in scene order.
fn group_keys(scene: &SampledScene, whole_body: bool) -> Vec<(Option<usize>, Vec<usize>)> {
    let joints = scene.skeleton.len();
    let root_of = |mut j: usize| {
        while let Some(p) = scene.skeleton.joints[j].parent {
            j = p;
        }
        j
    };
    let mut keys: Vec<(Option<usize>, Vec<usize>)> = Vec::new();
    for (i, o) in scene.objects.iter().enumerate() {
        let skin_root = o
            .skin
            .as_ref()
            .and_then(|s| s.joints.first())
            .map(|&j| root_of(j));
        let key = match (skin_root, o.parent_joint) {
            (Some(r), _) => Some(r),
            (None, Some(j)) if whole_body && j < joints => Some(root_of(j)),
            _ => None,
        };
        match keys.iter_mut().find(|(k, _)| key.is_some() && *k == key) {
            Some((_, members)) => members.push(i),
            None => keys.push((key, vec![i])),
        }
    }
    keys
}

impl SolvedField {
    /// Solves the offsets of every object of `scene` (see [`OffsetSolver::new`]).
    pub(crate) fn new(scene: &SampledScene, options: &OffsetOptions) -> Result<SolvedField> {
        count_solve();
        check_scene(scene)?;
        let frames = scene.frame_count;
        let pruned = Pruned::new(&scene.skeleton, &options.prune)?;
        let camera = resolve_camera(&scene.cameras, &options.camera)?;
        let space = camera.map(|c| CameraSpace::new(c, frames));

        let mut slots: Vec<Option<Slot>> = (0..scene.objects.len()).map(|_| None).collect();
        let keys = group_keys(scene, options.whole_body);
        let mut groups = Vec::with_capacity(keys.len());
        for (key, members) in keys {
            let parts: Vec<&MeshAnimation> = members
                .iter()
                .map(|&i| &scene.objects[i].animation)
                .collect();
            let merged = merged_positions(&parts, frames);
            let positions: &[Vec3] = merged.as_deref().unwrap_or_else(|| parts[0].positions());
            let vertices: usize = parts.iter().map(|a| a.vertex_count()).sum();
            let tol = tolerances(positions, frames, vertices, space.as_ref(), options.causal);
            let mode = match key {
                None => OffsetMode::Simple,
                Some(_) if options.whole_body => OffsetMode::WholeBody,
                Some(_) => OffsetMode::Articulated,
            };
            let (field, raw) = if mode == OffsetMode::Articulated {
                let skins: Vec<&Skin> = members
                    .iter()
                    .filter_map(|&i| scene.objects[i].skin.as_ref())
                    .collect();
                // The rig is built on one core while the other maps the output's fresh pages
                // (the kernel clears them on first touch): both serial costs at once.
                let (rig, raw) = rayon::join(
                    || Rig::new(&scene.skeleton, &pruned, &skins),
                    || touched_zeros(frames * vertices),
                );
                Field::ribbons(
                    rig?,
                    raw,
                    positions,
                    frames,
                    &scene.bones,
                    tol,
                    space.as_ref(),
                    options.collinear_weight,
                )
            } else {
                let tris = merged_triangles(&parts);
                Field::plane(positions, frames, vertices, &tris, tol, space.as_ref())
            };
            let mut base = 0;
            for (&i, a) in members.iter().zip(&parts) {
                slots[i] = Some(Slot {
                    group: groups.len(),
                    base,
                    vertices: a.vertex_count(),
                });
                base += a.vertex_count();
            }
            groups.push(Group {
                positions: match merged {
                    Some(m) => GroupPositions::Merged(m),
                    None => GroupPositions::Object(members[0]),
                },
                vertices,
                mode,
                field,
                raw,
            });
        }
        Ok(SolvedField {
            frames,
            smooth: options.smooth,
            causal: options.causal,
            slots: slots.into_iter().flatten().collect(),
            groups,
        })
    }

    /// Solves a bare point cache as a simple object (see [`OffsetSolver::from_animation`]).
    fn from_animation(
        anim: &MeshAnimation,
        options: &OffsetOptions,
        cameras: &[Camera],
    ) -> Result<SolvedField> {
        count_solve();
        if let Some(name) = options.prune.first() {
            return Err(SmearError::UnknownJoint {
                name: name.clone(),
                available: String::new(),
            });
        }
        let camera = resolve_camera(cameras, &options.camera)?;
        let frames = anim.frame_count();
        let space = camera.map(|c| CameraSpace::new(c, frames));
        let tol = tolerances(
            anim.positions(),
            frames,
            anim.vertex_count(),
            space.as_ref(),
            options.causal,
        );
        let (field, raw) = Field::plane(
            anim.positions(),
            frames,
            anim.vertex_count(),
            &anim.mesh.triangles,
            tol,
            space.as_ref(),
        );
        Ok(SolvedField {
            frames,
            smooth: options.smooth,
            causal: options.causal,
            slots: vec![Slot {
                group: 0,
                base: 0,
                vertices: anim.vertex_count(),
            }],
            groups: vec![Group {
                positions: GroupPositions::Object(0),
                vertices: anim.vertex_count(),
                mode: OffsetMode::Simple,
                field,
                raw,
            }],
        })
    }

    /// Number of objects (scene order).
    pub(crate) fn object_count(&self) -> usize {
        self.slots.len()
    }

    /// How object `i`'s offsets are computed (`None` when out of range).
    pub(crate) fn mode(&self, i: usize) -> Option<OffsetMode> {
        self.slots.get(i).map(|s| self.groups[s.group].mode)
    }

    fn slot(&self, i: usize) -> Result<&Slot> {
        self.slots.get(i).ok_or(SmearError::UnknownObject {
            index: i,
            count: self.slots.len(),
        })
    }

    /// Smoothed (SMEAR Eq. 2) offsets of one object, straight from its group's raw offsets.
    fn slot_offsets(&self, slot: &Slot) -> MotionOffsets {
        let grp = &self.groups[slot.group];
        let values = crate::smooth::smooth_columns(
            &grp.raw,
            self.frames,
            grp.vertices,
            slot.base..slot.base + slot.vertices,
            self.smooth,
            self.causal,
        );
        MotionOffsets::new(self.frames, slot.vertices, values).expect("frames × vertices")
    }

    /// Smoothed offsets of object `i`'s vertices.
    pub(crate) fn vertex_offsets(&self, i: usize) -> Result<MotionOffsets> {
        Ok(self.slot_offsets(self.slot(i)?))
    }

    /// Smoothed offsets of every object, in object order.
    pub(crate) fn all(&self) -> Vec<MotionOffsets> {
        self.slots.iter().map(|s| self.slot_offsets(s)).collect()
    }

    /// [`SolvedField::all`], consuming the field: an object alone in its group is smoothed in
    /// its group's raw buffer, which becomes its offsets (no second `frames × vertices`
    /// buffer, no copy).
    pub(crate) fn into_all(mut self) -> Vec<MotionOffsets> {
        let (frames, smooth, causal) = (self.frames, self.smooth, self.causal);
        let mut out = Vec::with_capacity(self.slots.len());
        for slot in &self.slots {
            let alone = self.slots.iter().filter(|s| s.group == slot.group).count() == 1;
            let grp = &mut self.groups[slot.group];
            if alone && slot.vertices == grp.vertices {
                let mut values = std::mem::take(&mut grp.raw);
                crate::smooth::smooth_in_place(&mut values, frames, grp.vertices, smooth, causal);
                out.push(
                    MotionOffsets::new(frames, slot.vertices, values).expect("frames × vertices"),
                );
            } else {
                out.push(self.slot_offsets(slot));
            }
        }
        out
    }

    /// Smoothed offsets at surface points of object `i`; `objects` are the caches the field
    /// was solved on (scene order).
    pub(crate) fn surface_offsets(
        &self,
        objects: &[&MeshAnimation],
        i: usize,
        points: &[SurfacePoint],
    ) -> Result<MotionOffsets> {
        let slot = self.slot(i)?;
        let grp = &self.groups[slot.group];
        let tris = &objects[i].mesh.triangles;
        let positions: &[Vec3] = match &grp.positions {
            GroupPositions::Object(k) => objects[*k].positions(),
            GroupPositions::Merged(p) => p,
        };
        // Per point: three group vertices and weights, then merged influences (CSR).
        let mut corners = Vec::with_capacity(points.len());
        let (mut start, mut joints, mut weights) = (vec![0u32], Vec::new(), Vec::new());
        let mut row: Vec<(u32, f32)> = Vec::new();
        for (k, pt) in points.iter().enumerate() {
            let c = pt.corners(k, tris)?.map(|(v, w)| (slot.base + v, w));
            row.clear();
            if let Field::Ribbons(rf) = &grp.field {
                for &(v, bw) in &c {
                    let (js, ws) = rf.rig.influences(v);
                    for (&j, &w) in js.iter().zip(ws) {
                        match row.iter_mut().find(|e| e.0 == j) {
                            Some(e) => e.1 += bw * w,
                            None => row.push((j, bw * w)),
                        }
                    }
                }
            }
            joints.extend(row.iter().map(|e| e.0));
            weights.extend(row.iter().map(|e| e.1));
            start.push(joints.len() as u32);
            corners.push(c);
        }
        let np = points.len();
        let mut raw = vec![0.0f32; self.frames * np];
        if np > 0 {
            raw.par_chunks_mut(np).enumerate().for_each(|(f, dst)| {
                let pos = &positions[f * grp.vertices..(f + 1) * grp.vertices];
                for (k, d) in dst.iter_mut().enumerate() {
                    let p: Vec3 = corners[k].iter().map(|&(v, w)| w * pos[v]).sum();
                    let (a, b) = (start[k] as usize, start[k + 1] as usize);
                    *d = grp.field.eval(f, p, &joints[a..b], &weights[a..b]);
                }
            });
        }
        let values =
            crate::smooth::smooth_columns(&raw, self.frames, np, 0..np, self.smooth, self.causal);
        MotionOffsets::new(self.frames, np, values)
    }
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
        self.field.frames
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
