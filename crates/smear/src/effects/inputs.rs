//! What the effects read per point and frame: positions (and their trajectories), motion
//! offsets, velocities, painted weights — gathered once so every effect builds its
//! [`StyleInput`]s the same way.

use std::borrow::Cow;
use std::sync::OnceLock;

use anim::MeshAnimation;
use glam::Vec3;
use rayon::prelude::*;

use super::{StyleBlock, StyleInput, Trajectories};
use crate::revolve::Arcs;
use crate::velocity::{
    buffer_velocities, camera_buffer_velocities, point_velocity, run_speeds, CameraSpace,
};
use crate::Collider;
use crate::{MotionOffsets, Result, SmearError, SurfacePoint};

/// Default frame step: every frame is its own drawing ("on ones").
pub const DEFAULT_FRAME_STEP: usize = 1;

/// The sampled animation of a set of points (mesh vertices, or surface points such as motion
/// line seeds) with everything a stylization function may read.
///
/// Offsets are computed beforehand with whatever [`OffsetOptions`](crate::OffsetOptions) the
/// user chose (smoothing, pruning, whole-body, camera), so every effect honours them.
#[derive(Debug, Clone)]
pub struct EffectInputs<'a> {
    positions: Cow<'a, [Vec3]>,
    frames: usize,
    points: usize,
    offsets: Cow<'a, MotionOffsets>,
    velocities: Velocities<'a>,
    weights: Option<Vec<f32>>,
    /// The point cache the points are the vertices of (`None` for surface points).
    source: Option<&'a MeshAnimation>,
    /// Past-only trajectories and velocities (issue #22).
    causal: bool,
    /// Ground plane height the displaced points never go below.
    ground: Option<f32>,
    /// Revolving parts: their points move along arcs.
    arcs: Option<Cow<'a, Arcs>>,
    /// Collider meshes the displaced points never enter.
    colliders: &'a [Collider],
    /// Per point its twin ([`MeshAnimation::twins`]): displaced by the same β, a point is its
    /// twin's result (docs/smear-speed.md, "Twins").
    twins: Option<&'a [u32]>,
}

/// Where the velocities of [`EffectInputs`] come from.
#[derive(Debug, Clone)]
enum Velocities<'a> {
    /// A frame-major `frames × points` buffer.
    Buffer(Cow<'a, [Vec3]>),
    /// Differences of the positions computed where they are read (a prepared scene: no
    /// `frames × points` buffer, so preparing and stylizing a few frames never fill one);
    /// [`EffectInputs::velocities`] fills `all` on first use.
    Differences {
        space: Option<&'a CameraSpace>,
        causal: bool,
        all: OnceLock<Vec<Vec3>>,
    },
}

fn mismatch(name: &'static str, expected: usize, found: usize) -> SmearError {
    SmearError::InvalidParameter {
        name,
        reason: format!("expected {expected} values, got {found}"),
    }
}

impl<'a> EffectInputs<'a> {
    /// The point cache these inputs were built from with [`EffectInputs::new`] (its mesh,
    /// frame rate and start time go to the outputs of the effects that rebuild it).
    ///
    /// # Errors
    /// [`SmearError::InvalidParameter`] for inputs at surface points, which have no mesh.
    pub(crate) fn animation(&self) -> Result<&'a MeshAnimation> {
        self.source.ok_or_else(|| SmearError::InvalidParameter {
            name: "inputs",
            reason: "built at surface points, not from a mesh's vertices".into(),
        })
    }

    /// Inputs from parts computed beforehand (by [`prepare`](crate::prepare)), borrowed:
    /// the vertices of `anim` with their offsets and velocities (frame-major, already in
    /// the right space). The caller guarantees the shapes agree.
    pub(crate) fn from_prepared(
        anim: &'a MeshAnimation,
        offsets: &'a MotionOffsets,
        (space, causal): (Option<&'a CameraSpace>, bool),
        weights: Option<Vec<f32>>,
    ) -> EffectInputs<'a> {
        EffectInputs {
            positions: Cow::Borrowed(anim.positions()),
            frames: anim.frame_count(),
            points: anim.vertex_count(),
            offsets: Cow::Borrowed(offsets),
            velocities: Velocities::Differences {
                space,
                causal,
                all: OnceLock::new(),
            },
            weights,
            source: Some(anim),
            causal: false,
            ground: None,
            arcs: None,
            colliders: &[],
            twins: None,
        }
    }

    /// The vertices of a point cache with their motion offsets.
    ///
    /// # Errors
    /// [`SmearError::FrameMismatch`] / [`SmearError::InvalidParameter`] when the offsets do
    /// not have the animation's frames and vertices.
    ///
    /// # Performance
    /// Computes the velocities (central differences, parallel over frames).
    pub fn new(anim: &'a MeshAnimation, offsets: &'a MotionOffsets) -> Result<EffectInputs<'a>> {
        let mut inputs = Self::build(
            Cow::Borrowed(anim.positions()),
            anim.frame_count(),
            anim.vertex_count(),
            Cow::Borrowed(offsets),
        )?;
        inputs.source = Some(anim);
        Ok(inputs)
    }

    /// Surface points of a point cache (e.g. motion-line seeds, Section 4.3) with their
    /// offsets (from [`OffsetSolver::surface_offsets`](crate::OffsetSolver::surface_offsets)).
    /// Positions are blended barycentrically per frame, which makes their trajectories the
    /// blends of the corner trajectories.
    ///
    /// # Errors
    /// [`SmearError::InvalidSurfacePoint`] for a missing triangle or unusable barycentric
    /// coordinates; a mismatch as in [`EffectInputs::new`].
    pub fn at_surface_points(
        anim: &MeshAnimation,
        points: &[SurfacePoint],
        offsets: MotionOffsets,
    ) -> Result<EffectInputs<'static>> {
        let corners = corners(&anim.mesh.triangles, points)?;
        let (frames, n, k) = (anim.frame_count(), anim.vertex_count(), points.len());
        let mut positions = vec![Vec3::ZERO; frames * k];
        if k > 0 && n > 0 {
            positions
                .par_chunks_mut(k)
                .zip(anim.positions().par_chunks(n))
                .for_each(|(dst, src)| {
                    for (d, c) in dst.iter_mut().zip(&corners) {
                        *d = c.iter().map(|&(v, w)| src[v] * w).sum();
                    }
                });
        }
        EffectInputs::build(Cow::Owned(positions), frames, k, Cow::Owned(offsets))
    }

    fn build(
        positions: Cow<'a, [Vec3]>,
        frames: usize,
        points: usize,
        offsets: Cow<'a, MotionOffsets>,
    ) -> Result<EffectInputs<'a>> {
        if offsets.frame_count() != frames {
            return Err(SmearError::FrameMismatch {
                expected: frames,
                found: offsets.frame_count(),
            });
        }
        if offsets.vertex_count() != points {
            return Err(mismatch(
                "offsets per frame",
                points,
                offsets.vertex_count(),
            ));
        }
        let velocities = buffer_velocities(&positions, frames, points, false);
        Ok(EffectInputs {
            positions,
            frames,
            points,
            offsets,
            velocities: Velocities::Buffer(Cow::Owned(velocities)),
            weights: None,
            source: None,
            causal: false,
            ground: None,
            arcs: None,
            colliders: &[],
            twins: None,
        })
    }

    /// Past-only mode (issue #22): trajectories read no frame after the one they displace,
    /// and velocities computed here from the positions become backward differences
    /// (velocities given by [`prepare`](crate::prepare) are causal already when asked).
    pub fn with_causal(mut self, causal: bool) -> Self {
        let computed = matches!(self.velocities, Velocities::Buffer(Cow::Owned(_)));
        if causal && !self.causal && computed {
            self.velocities = Velocities::Buffer(Cow::Owned(buffer_velocities(
                &self.positions,
                self.frames,
                self.points,
                true,
            )));
        }
        self.causal = causal;
        self
    }

    /// A ground plane `y = ground` that displaced points never go below (issue #22).
    pub fn with_ground(mut self, ground: Option<f32>) -> Self {
        self.ground = ground;
        self
    }

    /// Collider meshes that displaced points never enter (issue #22; see [`Collider`]).
    pub fn with_colliders(mut self, colliders: &'a [Collider]) -> Self {
        self.colliders = colliders;
        self
    }

    /// The points' twins ([`MeshAnimation::twins`] of the positions these inputs hold): an
    /// effect displaces a point whose twin has the same β once.
    ///
    /// The effects copy only from an earlier point (`twins[i] < i`), so any other entry
    /// means "no twin".
    ///
    /// # Errors
    /// [`SmearError::InvalidParameter`] when there is not one twin per point.
    pub(crate) fn with_twins(mut self, twins: &'a [u32]) -> Result<Self> {
        if twins.len() != self.points {
            return Err(mismatch("twins", self.points, twins.len()));
        }
        self.twins = Some(twins);
        Ok(self)
    }

    /// The points' twins, if known ([`EffectInputs::with_twins`]).
    pub(crate) fn twins(&self) -> Option<&'a [u32]> {
        self.twins
    }

    /// The collider meshes.
    pub fn colliders(&self) -> &'a [Collider] {
        self.colliders
    }

    /// Arcs of revolving parts, one entry per point (issue #22; see `crate::revolve`).
    ///
    /// # Errors
    /// [`SmearError::InvalidParameter`] when `arcs` do not have one entry per point.
    pub fn with_arcs(mut self, arcs: Option<Cow<'a, Arcs>>) -> Result<Self> {
        if let Some(a) = &arcs {
            if a.point_count() != self.points {
                return Err(mismatch("arcs", self.points, a.point_count()));
            }
        }
        self.arcs = arcs;
        Ok(self)
    }

    /// The arcs of revolving parts, if any.
    pub fn arcs(&self) -> Option<&Arcs> {
        self.arcs.as_deref()
    }

    /// Whether trajectories are evaluated past-only.
    pub fn is_causal(&self) -> bool {
        self.causal
    }

    /// The ground plane height, if any.
    pub fn ground(&self) -> Option<f32> {
        self.ground
    }

    /// Sets painted weights ω_i ∈ [0, 1] (one per point; default 1).
    ///
    /// # Errors
    /// [`SmearError::InvalidParameter`] when there is not one weight per point.
    pub fn with_weights(mut self, weights: Vec<f32>) -> Result<Self> {
        if weights.len() != self.points {
            return Err(mismatch("weights", self.points, weights.len()));
        }
        self.weights = Some(weights);
        Ok(self)
    }

    /// Replaces the velocities (frame-major, units per frame), e.g. by camera-relative ones
    /// from [`camera_vertex_velocities`](crate::camera_vertex_velocities).
    ///
    /// # Errors
    /// [`SmearError::InvalidParameter`] when the length is not `frames × points`.
    pub fn with_velocities(mut self, velocities: Vec<Vec3>) -> Result<Self> {
        if velocities.len() != self.frames * self.points {
            return Err(mismatch(
                "velocities",
                self.frames * self.points,
                velocities.len(),
            ));
        }
        self.velocities = Velocities::Buffer(Cow::Owned(velocities));
        Ok(self)
    }

    /// Measures the velocities — hence the `speed` stylization functions read — relative to a
    /// (moving) camera, as the offsets are with [`OffsetOptions::camera`](crate::OffsetOptions):
    /// an object the camera follows is slow on screen and gets no speed-driven smear.
    ///
    /// `None` (no camera selected: world space) keeps the inputs as they are.
    ///
    /// # Performance
    /// One pass over the positions, parallel over frames.
    pub fn relative_to_camera(mut self, camera: Option<&anim::Camera>) -> Self {
        let Some(camera) = camera else {
            return self;
        };
        let space = crate::velocity::CameraSpace::new(camera, self.frames);
        self.velocities = Velocities::Buffer(Cow::Owned(camera_buffer_velocities(
            &self.positions,
            self.frames,
            self.points,
            &space,
            self.causal,
        )));
        self
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.frames
    }

    /// Number of points.
    pub fn point_count(&self) -> usize {
        self.points
    }

    /// All positions, frame-major.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// The painted weights ω, one per point, `None` when every weight is 1.
    pub fn weights(&self) -> Option<&[f32]> {
        self.weights.as_deref()
    }

    /// The motion offsets.
    pub fn offsets(&self) -> &MotionOffsets {
        &self.offsets
    }

    /// The velocities, frame-major (of a prepared scene: computed on the first call).
    pub fn velocities(&self) -> &[Vec3] {
        match &self.velocities {
            Velocities::Buffer(v) => v,
            Velocities::Differences { space, causal, all } => all.get_or_init(|| match space {
                Some(c) => {
                    camera_buffer_velocities(&self.positions, self.frames, self.points, c, *causal)
                }
                None => buffer_velocities(&self.positions, self.frames, self.points, *causal),
            }),
        }
    }

    /// The trajectories of the points (Section 4.1).
    pub fn trajectories(&self) -> Trajectories<'_> {
        Trajectories::new(&self.positions, self.frames, self.points)
            .expect("length checked on construction")
            .shaped(self.causal, self.ground, self.arcs.as_deref())
            .with_colliders(self.colliders)
    }

    /// The stylization inputs of points `start..start + len` of frame `f` as one run
    /// ([`Stylize::eval_block`](super::Stylize::eval_block)), `m` 0. Panics when the run is
    /// out of range.
    pub fn style_block(&self, f: usize, start: usize, len: usize) -> StyleBlock<'_> {
        StyleBlock::new(self, f, start, len)
    }

    /// The speeds of points `start..start + out.len()` at frame `f`: those of
    /// [`EffectInputs::style_input`], bit for bit.
    pub(crate) fn run_speeds(&self, f: usize, start: usize, out: &mut [f32]) {
        match &self.velocities {
            Velocities::Buffer(v) => {
                let (k, len) = (f * self.points + start, out.len());
                for (o, v) in out.iter_mut().zip(&v[k..k + len]) {
                    *o = v.length();
                }
            }
            Velocities::Differences { space, causal, .. } => run_speeds(
                &self.positions,
                (self.frames, self.points),
                (f, start),
                *space,
                *causal,
                out,
            ),
        }
    }

    /// The stylization inputs of point `i` at frame `f` (`m` and `t` left 0). `f` and `i`
    /// must be in range.
    #[inline]
    pub fn style_input(&self, f: usize, i: usize) -> StyleInput {
        let k = f * self.points + i;
        let velocity = match &self.velocities {
            Velocities::Buffer(v) => v[k],
            Velocities::Differences { space, causal, .. } => point_velocity(
                &self.positions,
                (self.frames, self.points),
                (f, i),
                *space,
                *causal,
            ),
        };
        StyleInput {
            delta: self.offsets.values()[k],
            speed: velocity.length(),
            velocity,
            weight: self.weights.as_ref().map_or(1.0, |w| w[i]),
            rest: self.positions[i],
            frame: f as f32,
            m: 0.0,
            t: 0.0,
            vertex: i as u32,
        }
    }
}

/// "On twos" (paper Section 5.2): with a frame step `s`, output frame `f` shows the drawing of
/// frame `⌊f / s⌋·s`, and displacements β, β_m and τ are scaled by `s`. A step of 0 counts as 1.
#[inline]
pub fn held_frame(f: usize, step: usize) -> usize {
    let s = step.max(1);
    f - f % s
}

pub(crate) fn check_step(step: usize) -> Result<usize> {
    if step == 0 {
        return Err(SmearError::InvalidParameter {
            name: "frame step",
            reason: "must be ≥ 1 (1 = on ones, 2 = on twos)".into(),
        });
    }
    Ok(step)
}

pub(crate) fn check_frame(f: usize, frames: usize) -> Result<()> {
    if f >= frames {
        return Err(SmearError::InvalidParameter {
            name: "frame",
            reason: format!("frame {f} is past the last frame ({frames} frames)"),
        });
    }
    Ok(())
}

/// Per point: the three corners (vertex, normalized weight).
fn corners(triangles: &[[u32; 3]], points: &[SurfacePoint]) -> Result<Vec<[(usize, f32); 3]>> {
    points
        .iter()
        .enumerate()
        .map(|(index, pt)| pt.corners(index, triangles))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim::Mesh;

    fn sliding_triangle(frames: usize) -> MeshAnimation {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let mesh = Mesh::new("tri", p.clone(), vec![[0, 1, 2]]);
        let pos = (0..frames)
            .flat_map(|f| p.iter().map(move |q| *q + Vec3::Z * (f * f) as f32))
            .collect();
        MeshAnimation::new(mesh, 24.0, pos).unwrap()
    }

    #[test]
    fn inputs_match_vertex_velocities_and_surface_points_blend_corners() {
        let anim = sliding_triangle(5);
        let off = MotionOffsets::zeros(5, 3);
        let inputs = EffectInputs::new(&anim, &off).unwrap();
        assert_eq!(
            inputs.velocities(),
            crate::vertex_velocities(&anim).as_slice()
        );
        let x = inputs.style_input(2, 1);
        assert_eq!(
            (x.speed, x.weight, x.rest, x.frame),
            (4.0, 1.0, Vec3::X, 2.0)
        );
        let pt = SurfacePoint {
            triangle: 0,
            barycentric: [2.0, 1.0, 1.0],
        };
        let seeds = EffectInputs::at_surface_points(&anim, &[pt], MotionOffsets::zeros(5, 1))
            .unwrap()
            .with_weights(vec![0.5])
            .unwrap();
        let q = seeds.positions()[3];
        assert!((q - Vec3::new(0.25, 0.25, 9.0)).length() < 1e-6, "{q}");
        assert_eq!(seeds.style_input(3, 0).weight, 0.5);
        let bad = SurfacePoint {
            triangle: 4,
            barycentric: [1.0; 3],
        };
        assert!(
            EffectInputs::at_surface_points(&anim, &[bad], MotionOffsets::zeros(5, 1)).is_err()
        );
        assert!(EffectInputs::new(&anim, &MotionOffsets::zeros(4, 3)).is_err());
    }

    #[test]
    fn held_frames_on_twos() {
        let held: Vec<usize> = (0..6).map(|f| held_frame(f, 2)).collect();
        assert_eq!(held, [0, 0, 2, 2, 4, 4]);
        assert_eq!(held_frame(5, 0), 5);
    }
}
