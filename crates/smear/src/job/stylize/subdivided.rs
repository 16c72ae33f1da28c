//! Subdivided smears: the elongated body and the multiple in-betweens split per frame where
//! the smeared surface leaves the flat triangle (SMEAR Sections 4.1–4.2), each new vertex
//! placed on, and moving along, its own smeared trajectory.

use std::ops::Range;

use anim::MeshAnimation;
use glam::Vec3;

use super::ObjectReport;
use crate::{EffectInputs, Result, Stylize};

/// One multiple in-between, adaptively subdivided per frame: every vertex of
/// copy m moves by β_m(f) = step · m · Δf(f) (Section 4.2); opacities are blended into the
/// colours' alpha. The copy's frame 0 is clip frame `first`.
pub(super) fn subdivided_copy(
    inputs: &EffectInputs<'_>,
    options: &crate::MultiplesOptions,
    copy: &crate::MultipleCopy,
    rgb: [f32; 3],
    tol: f32,
    first: usize,
) -> Result<(Vec<anim::Mesh>, Vec<Vec<Vec3>>)> {
    let tr = inputs.trajectories();
    let anim = &copy.animation;
    let (frames, n) = (anim.frame_count(), anim.vertex_count());
    let step = options.step.max(1);
    // Per frame: its held frame and the copy's uniform β there.
    let mut held = Vec::with_capacity(frames);
    for f in 0..frames {
        let h = crate::held_frame(first + f, step);
        let (past, future) = options.counts_at(h as f32);
        let shown = if copy.m < 0 {
            copy.m.unsigned_abs() as usize <= past
        } else {
            copy.m as usize <= future
        };
        let b = if shown {
            step as f32 * copy.m as f32 * options.spacing_at(h as f32)?
        } else {
            0.0
        };
        held.push((h, vec![b; n]));
    }
    let around = |f: usize| -> Option<crate::AroundFrame<'_>> {
        held.get(f).map(|(h, beta)| (*h, beta.as_slice()))
    };
    let mut meshes = Vec::with_capacity(frames);
    let mut velocities = Vec::with_capacity(frames);
    for (f, (h, beta)) in held.iter().enumerate() {
        let alpha = &copy.alpha[f * n..(f + 1) * n];
        // Every vertex's velocity: the derivative of its own trajectory across the copy's
        // frames (its surface point placed on the frames around).
        let (mesh, placed, _) = crate::subdivide_moving_frame(
            &tr,
            &anim.mesh,
            *h,
            beta,
            Some((alpha, rgb)),
            tol,
            [f.checked_sub(1).and_then(around), around(f + 1)],
        );
        velocities.push(crate::trajectory_velocities(&mesh.positions, &placed));
        meshes.push(mesh);
    }
    Ok((meshes, velocities))
}

/// The elongated body, adaptively subdivided per frame.
pub(super) struct SubdividedBody<'a, 'i> {
    pub(super) inputs: &'a EffectInputs<'i>,
    /// The elongation's stylization function.
    pub(super) f: &'a dyn Stylize,
    /// Frames each drawing is held for.
    pub(super) step: usize,
    /// Per clip frame: its squash, if any.
    pub(super) squash: &'a [Option<crate::Squash>],
    pub(super) ground: Option<f32>,
    pub(super) tol: f32,
}

impl SubdividedBody<'_, '_> {
    /// Every frame of `frames`: its subdivided mesh and the velocities of its vertices (units
    /// per frame: central differences of each vertex's own trajectory — its surface point
    /// placed on the in-betweens of the frames around, squash included — as a point cache of
    /// the unsubdivided smear has them at the input's vertices); the subdivision's figures go
    /// into `stats`.
    pub(super) fn frames(
        &self,
        anim: &MeshAnimation,
        frames: &Range<usize>,
        stats: &mut ObjectReport,
    ) -> (Vec<anim::Mesh>, Vec<Vec<Vec3>>) {
        let tr = self.inputs.trajectories();
        let n = anim.vertex_count();
        // Per frame of the range: its held frame and β (the frames around a frame place its
        // vertices' trajectories).
        let held: Vec<(usize, Vec<f32>)> = frames
            .clone()
            .map(|frame| {
                let h = crate::held_frame(frame, self.step);
                let beta = (0..n)
                    .map(|k| self.step as f32 * self.f.eval(&self.inputs.style_input(h, k)))
                    .collect();
                (h, beta)
            })
            .collect();
        let around = |i: usize| -> Option<crate::AroundFrame<'_>> {
            held.get(i).map(|(h, beta)| (*h, beta.as_slice()))
        };
        let squash = |frame: usize, p: &mut [Vec3]| {
            if let (Some(Some(sq)), Some(g)) = (self.squash.get(frame), self.ground) {
                sq.apply(g, p);
            }
        };
        let mut meshes = Vec::with_capacity(frames.len());
        let mut velocities = Vec::with_capacity(frames.len());
        let (mut stretch, mut most, mut vertices, mut error) = (0.0f32, 0, 0, 0.0f32);
        for (i, frame) in frames.clone().enumerate() {
            let (h, beta) = &held[i];
            let (mut mesh, mut placed, st) = crate::subdivide_moving_frame(
                &tr,
                &anim.mesh,
                *h,
                beta,
                None,
                self.tol,
                [i.checked_sub(1).and_then(around), around(i + 1)],
            );
            squash(frame, &mut mesh.positions);
            if let Some(p) = &mut placed[0] {
                squash(frame - 1, p);
            }
            if let Some(p) = &mut placed[1] {
                squash(frame + 1, p);
            }
            let v = crate::trajectory_velocities(&mesh.positions, &placed);
            stretch = stretch.max(st.max_stretch);
            most = most.max(st.triangles);
            vertices = vertices.max(st.vertices);
            error = error.max(st.max_error);
            meshes.push(mesh);
            velocities.push(v);
        }
        stats.subdivision_max_stretch = Some(stretch);
        stats.subdivision_max_triangles = Some(most);
        stats.subdivision_max_vertices = Some(vertices);
        stats.subdivision_max_error = Some(error);
        (meshes, velocities)
    }
}
