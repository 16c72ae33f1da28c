//! The solved offset fields of a scene (SMEAR Eqs. 1–9), evaluated at vertices and surface
//! points and smoothed (SMEAR Eq. 2) on demand.

use anim::{Camera, MeshAnimation, SampledScene, Skin};
use glam::Vec3;
use rayon::prelude::*;

use crate::field::Field;
use crate::rig::{Pruned, Rig};
use crate::surface::SurfacePoint;
use crate::velocity::CameraSpace;
use crate::{MotionOffsets, OffsetOptions, Result, SmearError};

use super::groups::{
    check_scene, group_keys, merged_positions, merged_triangles, tolerances, Group, GroupPositions,
    Slot,
};
use super::{count_solve, resolve_camera, OffsetMode};

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

impl SolvedField {
    /// Solves the offsets of every object of `scene` (see [`OffsetSolver::new`]).
    pub(crate) fn new(scene: &SampledScene, options: &OffsetOptions) -> Result<SolvedField> {
        count_solve();
        options.check_budget()?;
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
            let mode = match key {
                None => OffsetMode::Simple,
                Some(_) if options.whole_body => OffsetMode::WholeBody,
                Some(_) => OffsetMode::Articulated,
            };
            let tol = tolerances(positions, frames, vertices, space.as_ref(), options.causal);
            let (field, raw) = if mode == OffsetMode::Articulated {
                let skins: Vec<&Skin> = members
                    .iter()
                    .filter_map(|&i| scene.objects[i].skin.as_ref())
                    .collect();
                Field::ribbons(
                    Rig::new(&scene.skeleton, &pruned, &skins)?,
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
    pub(super) fn from_animation(
        anim: &MeshAnimation,
        options: &OffsetOptions,
        cameras: &[Camera],
    ) -> Result<SolvedField> {
        count_solve();
        options.check_budget()?;
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

    /// Number of frames.
    pub(crate) fn frame_count(&self) -> usize {
        self.frames
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

    /// [`SolvedField::all`], consuming the field: see [`SolvedField::take_all`].
    pub(crate) fn into_all(mut self) -> Vec<MotionOffsets> {
        self.take_all()
    }

    /// [`SolvedField::all`], taking the raw offsets out of the field: an object alone in its
    /// group is smoothed in its group's raw buffer, which becomes its offsets (no second
    /// `frames × vertices` buffer, no copy); every raw buffer is dropped after. The field
    /// still evaluates surface points ([`SolvedField::surface_offsets`]), but
    /// [`SolvedField::vertex_offsets`] and [`SolvedField::all`] must not be called after.
    pub(crate) fn take_all(&mut self) -> Vec<MotionOffsets> {
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
        for grp in &mut self.groups {
            grp.raw = Vec::new();
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
