//! The checked view of a [`UsdStage`] that every scene-cache writer reads (`.usda` text,
//! `.usdc` binary, `.abc` Alembic): per frame, the points, faces, colours and presence of each
//! mesh prim, so all three formats hold the same prims and samples.

use anim::glam::Vec3;
use anim::{Curves, Mesh};

use super::stage::{UsdGeometry, UsdMesh, UsdStage};
use crate::{IoError, Result};

/// Checks a stage (frame rate, units, frame counts, colour lengths, face indices) and returns
/// one [`Source`] per mesh prim, in order.
///
/// # Errors
/// A non-positive or non-finite frame rate or unit scale, point caches whose frame counts
/// differ from the stage's, colour arrays of the wrong length, faces indexing missing vertices.
pub(crate) fn check<'a>(stage: &'a UsdStage<'a>) -> Result<Vec<Source<'a>>> {
    if !(stage.fps.is_finite() && stage.fps > 0.0) {
        return Err(IoError::unsupported(format!(
            "USD export needs a positive frame rate, got {}",
            stage.fps
        )));
    }
    let units_ok = stage.meters_per_unit.is_finite() && stage.meters_per_unit > 0.0;
    if !(stage.start_time_code.is_finite() && units_ok) {
        return Err(IoError::unsupported(format!(
            "USD export needs a finite start time code and a positive metersPerUnit, got {} and {}",
            stage.start_time_code, stage.meters_per_unit
        )));
    }
    let frames = stage.frame_count();
    stage
        .meshes
        .iter()
        .map(|m| Source::new(m, frames, stage.fps))
        .collect()
}

/// The bounding box `(min, max)` of the points as written (non-finite coordinates count as
/// 0); the zero box for no point.
pub(crate) fn extent(points: &[Vec3]) -> (Vec3, Vec3) {
    let clean = |v: f32| if v.is_finite() { v } else { 0.0 };
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for p in points {
        let q = Vec3::new(clean(p.x), clean(p.y), clean(p.z));
        lo = lo.min(q);
        hi = hi.max(q);
    }
    if points.is_empty() {
        (lo, hi) = (Vec3::ZERO, Vec3::ZERO);
    }
    (lo, hi)
}

/// A coordinate as written: NaN and ±∞ become 0.
pub(crate) fn finite(v: f32) -> f32 {
    if v.is_finite() {
        v
    } else {
        0.0
    }
}

/// Bitwise equality of two point sets (so that NaN frames compare equal to themselves).
pub(crate) fn same_bits(a: &[Vec3], b: &[Vec3]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(p, q)| p.to_array().map(f32::to_bits) == q.to_array().map(f32::to_bits))
}

/// Colour of present frames that carry no vertex colour while others do (white, opaque,
/// as glTF renders a primitive without `COLOR_0`).
pub(crate) const NO_COLOR: [f32; 4] = [1.0, 1.0, 1.0, 1.0];

/// The faces of a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Faces<'a> {
    /// Triangles of a mesh without polygons.
    Triangles(&'a [[u32; 3]]),
    /// The mesh's own polygons.
    Polygons(&'a [Vec<u32>]),
}

impl Faces<'_> {
    /// Number of vertices of every face, in order.
    pub(crate) fn counts(&self) -> Vec<i32> {
        match self {
            Faces::Triangles(t) => vec![3; t.len()],
            Faces::Polygons(p) => p.iter().map(|f| f.len() as i32).collect(),
        }
    }

    /// Vertex indices of every face, concatenated.
    pub(crate) fn indices(&self) -> Vec<i32> {
        match self {
            Faces::Triangles(t) => t.iter().flatten().map(|&i| i as i32).collect(),
            Faces::Polygons(p) => p.iter().flatten().map(|&i| i as i32).collect(),
        }
    }

    /// Faces of a mesh: its polygons when it has usable ones (≥ 3 sides each), else triangles.
    pub(crate) fn of(mesh: &Mesh) -> Faces<'_> {
        match &mesh.polygons {
            Some(p) if !p.is_empty() && p.iter().all(|f| f.len() >= 3) => Faces::Polygons(p),
            _ => Faces::Triangles(&mesh.triangles),
        }
    }

    pub(crate) fn check(&self, vertices: usize, what: &str) -> Result<()> {
        let bad = |i: u32| {
            Err(IoError::unsupported(format!(
                "{what}: a face uses vertex {i} but the mesh has {vertices} vertices"
            )))
        };
        match self {
            Faces::Triangles(t) => match t.iter().flatten().find(|&&i| i as usize >= vertices) {
                Some(&i) => bad(i),
                None => Ok(()),
            },
            Faces::Polygons(p) => match p.iter().flatten().find(|&&i| i as usize >= vertices) {
                Some(&i) => bad(i),
                None => Ok(()),
            },
        }
    }
}

/// One mesh prim's frames, checked.
pub(crate) struct Source<'a> {
    /// The prim's geometry.
    pub(crate) geometry: &'a UsdGeometry<'a>,
    /// Frames of the stage.
    pub(crate) frames: usize,
    /// Frames per second (velocities are per second).
    fps: f32,
}

impl<'a> Source<'a> {
    /// Checks one mesh prim against the stage's frame count.
    pub(crate) fn new(mesh: &'a UsdMesh<'a>, frames: usize, fps: f32) -> Result<Source<'a>> {
        let what = format!("USD mesh '{}'", mesh.name);
        match &mesh.geometry {
            UsdGeometry::Animation { animation, colors } => {
                if animation.frame_count() != frames {
                    return Err(IoError::unsupported(format!(
                        "{what} has {} frames, expected {frames} like the other meshes",
                        animation.frame_count()
                    )));
                }
                let n = animation.vertex_count();
                if let Some(c) = colors {
                    if c.len() != n * frames {
                        return Err(IoError::unsupported(format!(
                            "{what}: expected {} vertex colours (frames × vertices), got {}",
                            n * frames,
                            c.len()
                        )));
                    }
                }
                Faces::of(&animation.mesh).check(n, &what)?;
            }
            UsdGeometry::Frames { meshes, velocities } => {
                if let Some(v) = velocities {
                    let bad = (v.len() != meshes.len()).then_some(0).or_else(|| {
                        (0..meshes.len()).find(|&f| v[f].len() != meshes[f].vertex_count())
                    });
                    if let Some(f) = bad {
                        return Err(IoError::unsupported(format!(
                            "{what} frame {}: velocities do not match the mesh's {} vertices",
                            f + 1,
                            meshes.get(f).map_or(0, |m| m.vertex_count())
                        )));
                    }
                }
                for (f, m) in meshes.iter().enumerate() {
                    let what = format!("{what} frame {}", f + 1);
                    Faces::of(m).check(m.vertex_count(), &what)?;
                    if let Some(c) = m.colors.as_ref().filter(|c| c.len() != m.vertex_count()) {
                        return Err(IoError::unsupported(format!(
                            "{what}: {} vertex colours for {} vertices",
                            c.len(),
                            m.vertex_count()
                        )));
                    }
                }
            }
            UsdGeometry::Curves(curves) => {
                for (f, c) in curves.iter().enumerate() {
                    let n = c.points.len();
                    let total: u64 = c.counts.iter().map(|&k| k as u64).sum();
                    if total != n as u64
                        || c.counts.iter().any(|&k| k < 2)
                        || c.widths.len() != n
                        || c.colors.len() != n
                    {
                        return Err(IoError::unsupported(format!(
                            "{what} frame {}: curves of {total} points (each at least 2) with {} widths and {} colours for {n} points",
                            f + 1,
                            c.widths.len(),
                            c.colors.len()
                        )));
                    }
                }
            }
        }
        Ok(Source {
            geometry: &mesh.geometry,
            frames,
            fps,
        })
    }

    /// The curves of frame `f` when the prim is `BasisCurves` and the frame has some.
    pub(crate) fn frame_curves(&self, f: usize) -> Option<&'a Curves> {
        match self.geometry {
            UsdGeometry::Curves(c) => c.get(f).copied().filter(|c| !c.is_empty()),
            _ => None,
        }
    }

    /// Whether the prim is `BasisCurves` (else `Mesh`).
    pub(crate) fn is_curves(&self) -> bool {
        matches!(self.geometry, UsdGeometry::Curves(_))
    }

    /// Points per curve of frame `f` (empty for meshes and absent frames).
    pub(crate) fn curve_counts(&self, f: usize) -> &'a [u32] {
        match self.geometry {
            UsdGeometry::Curves(_) => self
                .frame_curves(f)
                .map_or(&HIDDEN_CURVE_COUNTS, |c| &c.counts),
            _ => &[],
        }
    }

    /// Width of every point of frame `f` (empty for meshes and absent frames).
    pub(crate) fn widths(&self, f: usize) -> &'a [f32] {
        match self.geometry {
            UsdGeometry::Curves(_) => self
                .frame_curves(f)
                .map_or(&HIDDEN_CURVE_WIDTHS, |c| &c.widths),
            _ => &[],
        }
    }

    /// The bounding box of frame `f` as written: the points' box ([`extent`]), grown by
    /// half the widest curve for `BasisCurves` (USD's extent of curves covers their width).
    pub(crate) fn extent(&self, f: usize) -> (Vec3, Vec3) {
        let (lo, hi) = extent(self.points(f));
        let half = self
            .widths(f)
            .iter()
            .map(|&w| finite(w).abs())
            .fold(0.0f32, f32::max)
            / 2.0;
        (lo - Vec3::splat(half), hi + Vec3::splat(half))
    }

    /// Whether the prim carries `velocities`: a point cache whose points move, or per-frame
    /// meshes given with their velocities. (Otherwise per-frame meshes and curves change
    /// their points' count or meaning from frame to frame: no difference to take.)
    pub(crate) fn has_velocities(&self) -> bool {
        match self.geometry {
            UsdGeometry::Animation { .. } => {
                self.frames > 1 && !self.points(0).is_empty() && !self.points_static()
            }
            UsdGeometry::Frames { velocities, .. } => velocities.is_some(),
            UsdGeometry::Curves(_) => false,
        }
    }

    /// Velocity of every point at frame `f` in units per second, the derivative of the
    /// points as written: the central difference `(p(f+1) − p(f−1)) / 2` per frame,
    /// one-sided at the first and last frame (as SPEC's smear velocities), times the frame
    /// rate (USD's `velocities` are per second of time codes). So a renderer's motion blur
    /// sweeps each point along the path the frames show (a smear's in-betweens included).
    ///
    /// Per-frame meshes whose vertices change from frame to frame carry their own velocities
    /// (units per frame, e.g. a subdivided smear's: each vertex's own trajectory across the
    /// in-betweens, as the point cache's at the input's vertices), written per second; none
    /// for an absent frame.
    pub(crate) fn velocities(&self, f: usize) -> Vec<Vec3> {
        if let UsdGeometry::Frames {
            velocities: Some(v),
            ..
        } = self.geometry
        {
            if self.frame_mesh(f).is_none() {
                return Vec::new();
            }
            return v[f]
                .iter()
                .map(|v| {
                    let v = *v * self.fps;
                    Vec3::new(finite(v.x), finite(v.y), finite(v.z))
                })
                .collect();
        }
        let last = self.frames.saturating_sub(1);
        let (a, b) = (f.saturating_sub(1), (f + 1).min(last));
        let per_frame = if b > a { (b - a) as f32 } else { 1.0 };
        let scale = self.fps / per_frame;
        let (pa, pb) = (self.points(a), self.points(b));
        pa.iter()
            .zip(pb)
            .map(|(p, q)| {
                let v = (*q - *p) * scale;
                Vec3::new(finite(v.x), finite(v.y), finite(v.z))
            })
            .collect()
    }

    /// The mesh of frame `f` when the geometry is per-frame and the frame has a drawable one.
    pub(crate) fn frame_mesh(&self, f: usize) -> Option<&'a Mesh> {
        match self.geometry {
            UsdGeometry::Frames { meshes: m, .. } => m
                .get(f)
                .copied()
                .filter(|m| m.vertex_count() > 0 && !m.triangles.is_empty()),
            _ => None,
        }
    }

    /// Points of frame `f` (empty when absent).
    pub(crate) fn points(&self, f: usize) -> &'a [Vec3] {
        match self.geometry {
            UsdGeometry::Animation { animation, .. } => match animation.vertex_count() {
                0 => &[],
                _ => animation.frame(f),
            },
            UsdGeometry::Frames { .. } => self.frame_mesh(f).map_or(&[], |m| &m.positions),
            UsdGeometry::Curves(_) => self
                .frame_curves(f)
                .map_or(&HIDDEN_CURVE_POINTS, |c| &c.points),
        }
    }

    /// Faces of frame `f` (none when absent).
    pub(crate) fn faces(&self, f: usize) -> Faces<'a> {
        match self.geometry {
            UsdGeometry::Animation { animation, .. } => Faces::of(&animation.mesh),
            UsdGeometry::Frames { .. } => self
                .frame_mesh(f)
                .map_or(Faces::Triangles(&[]), |m| Faces::of(m)),
            UsdGeometry::Curves(_) => Faces::Triangles(&[]),
        }
    }

    /// Colours of frame `f`, `None` when the prim has no colour at all.
    pub(crate) fn colors(&self, f: usize) -> Option<ColorsOf<'a>> {
        match self.geometry {
            UsdGeometry::Animation { animation, colors } => {
                let n = animation.vertex_count();
                colors.map(|c| ColorsOf::Given(&c[f * n..(f + 1) * n]))
            }
            UsdGeometry::Frames { meshes, .. } => {
                if !meshes.iter().any(|m| m.colors.is_some()) {
                    return None;
                }
                Some(match self.frame_mesh(f) {
                    Some(m) => match &m.colors {
                        Some(c) => ColorsOf::Given(c),
                        None => ColorsOf::Default(m.vertex_count()),
                    },
                    None => ColorsOf::Given(&[]),
                })
            }
            UsdGeometry::Curves(_) => Some(ColorsOf::Given(
                self.frame_curves(f)
                    .map_or(&HIDDEN_CURVE_COLORS, |c| &c.colors),
            )),
        }
    }

    /// Whether frame `f` shows anything: some face, and (with colours) some non-zero alpha.
    pub(crate) fn present(&self, f: usize) -> bool {
        match self.geometry {
            UsdGeometry::Animation { animation, colors } => {
                let n = animation.vertex_count();
                let has_faces = match Faces::of(&animation.mesh) {
                    Faces::Triangles(t) => !t.is_empty(),
                    Faces::Polygons(p) => !p.is_empty(),
                };
                n > 0
                    && has_faces
                    && colors.is_none_or(|c| c[f * n..(f + 1) * n].iter().any(|c| c[3] > 0.0))
            }
            UsdGeometry::Frames { .. } => self.frame_mesh(f).is_some(),
            UsdGeometry::Curves(_) => self.frame_curves(f).is_some(),
        }
    }

    /// True when `eq(f)` holds for every frame after the first.
    fn all_frames(&self, eq: impl Fn(usize) -> bool) -> bool {
        (1..self.frames).all(eq)
    }

    /// Whether every frame has the faces of frame 0.
    pub(crate) fn topology_static(&self) -> bool {
        let (first, counts) = (self.faces(0), self.curve_counts(0));
        self.all_frames(|f| self.faces(f) == first && self.curve_counts(f) == counts)
    }

    /// Whether every frame has the points of frame 0 (bitwise).
    pub(crate) fn points_static(&self) -> bool {
        let first = self.points(0);
        self.all_frames(|f| same_bits(self.points(f), first))
    }

    /// Whether the colours (when there are any) are the same on every frame.
    pub(crate) fn colors_static(&self) -> bool {
        let Some(first) = self.colors(0) else {
            return true;
        };
        self.topology_static()
            && self.all_frames(|f| self.colors(f).is_some_and(|c| c.same(&first)))
    }

    /// Whether some frame is absent (nothing to draw).
    pub(crate) fn any_absent(&self) -> bool {
        (0..self.frames).any(|f| !self.present(f))
    }

    /// Whether every frame is present, or every frame absent.
    pub(crate) fn presence_static(&self) -> bool {
        let first = self.present(0);
        self.all_frames(|f| self.present(f) == first)
    }

    /// Texture coordinates of a point cache (one per vertex, toonkit's v-down convention).
    pub(crate) fn uvs(&self) -> Option<&'a [[f32; 2]]> {
        match self.geometry {
            UsdGeometry::Animation { animation, .. } => {
                let n = animation.vertex_count();
                animation
                    .mesh
                    .uvs
                    .as_deref()
                    .filter(|u| u.len() == n && n > 0)
            }
            UsdGeometry::Frames { .. } | UsdGeometry::Curves(_) => None,
        }
    }

    /// Whether the widths are the same on every frame.
    pub(crate) fn widths_static(&self) -> bool {
        let first = self.widths(0);
        self.all_frames(|f| {
            let w = self.widths(f);
            w.len() == first.len() && w.iter().zip(first).all(|(a, b)| a.to_bits() == b.to_bits())
        })
    }
}

/// Colours of one frame: given, or `n` times [`NO_COLOR`].
#[derive(Debug, Clone, Copy)]
pub(crate) enum ColorsOf<'a> {
    /// One colour per vertex.
    Given(&'a [[f32; 4]]),
    /// `n` vertices without colour.
    Default(usize),
}

impl ColorsOf<'_> {
    /// Colour of vertex `i`.
    pub(crate) fn get(&self, i: usize) -> [f32; 4] {
        match self {
            ColorsOf::Given(c) => c[i],
            ColorsOf::Default(_) => NO_COLOR,
        }
    }

    /// Number of vertices.
    pub(crate) fn len(&self) -> usize {
        match self {
            ColorsOf::Given(c) => c.len(),
            ColorsOf::Default(n) => *n,
        }
    }

    /// Bitwise equality.
    pub(crate) fn same(&self, other: &ColorsOf) -> bool {
        self.len() == other.len()
            && (0..self.len())
                .all(|i| self.get(i).map(f32::to_bits) == other.get(i).map(f32::to_bits))
    }
}

// A frame without motion lines still holds one curve: two points at the origin, zero width,
// transparent, and the prim is `invisible` there. Blender 4.2's USD importer crashes on
// `BasisCurves` whose time samples hold empty arrays; USD itself allows them.
/// Points per curve of the hidden curve that stands in for a frame with no curves.
static HIDDEN_CURVE_COUNTS: [u32; 1] = [2];
/// Widths of the hidden curve.
static HIDDEN_CURVE_WIDTHS: [f32; 2] = [0.0; 2];
/// Points of the hidden curve.
static HIDDEN_CURVE_POINTS: [Vec3; 2] = [Vec3::ZERO; 2];
/// Colours of the hidden curve (transparent).
static HIDDEN_CURVE_COLORS: [[f32; 4]; 2] = [[0.0; 4]; 2];
