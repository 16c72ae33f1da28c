//! Previews of a character following a line of action: the skinned meshes (or only the
//! bones, for a BVH skeleton), the bones in grey, the line in red and the constrained joints in
//! blue, seen through an orthographic view along the action camera that follows the
//! character (the same scale on every frame, centred on its meshes' smoothed bounding-box
//! centre), or through a scene camera.

use anim::{Camera, MeshAnimation};
use glam::{Mat4, Vec3};
use rayon::prelude::*;

use crate::{encode_gif, encode_png, Color, Coords, DrawList, MeshItem, Overlay, Renderer};
use crate::{Result, View, DEFAULT_FOLLOW_SMOOTHING};

/// Size of rig previews.
pub const DEFAULT_RIG_PREVIEW_SIZE: (u32, u32) = (480, 480);
/// Margin around the followed character (fraction of its extent).
const MARGIN: f32 = 0.12;
const LINE_RED: Color = [0.85, 0.1, 0.1, 1.0];
const BONE_BLUE: Color = [0.1, 0.3, 0.85, 1.0];
const BONE_GREY: Color = [0.35, 0.35, 0.35, 0.8];

/// Axes of an orthographic view (unit vectors, right-handed: `right × up = −forward`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewAxes {
    /// Image right.
    pub right: Vec3,
    /// Image up.
    pub up: Vec3,
    /// Viewing direction (from the eye into the scene).
    pub forward: Vec3,
}

/// How a rig preview looks at the character.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RigView<'a> {
    /// Orthographic along these axes, following the character.
    Follow(ViewAxes),
    /// A scene camera (perspective allowed), fixed as animated in the file.
    Camera(&'a Camera),
}

/// What a rig preview draws, per frame.
#[derive(Debug, Clone, Copy)]
pub struct RigPreview<'a> {
    /// Skinned meshes, sampled at the preview's frames (may be empty).
    pub meshes: &'a [&'a MeshAnimation],
    /// Joints per frame.
    pub joints: usize,
    /// World joint positions, frames × joints.
    pub positions: &'a [Vec3],
    /// Bones as `(parent, child)` joint pairs.
    pub bones: &'a [(usize, usize)],
    /// The line of action per frame, as world points.
    pub lines: &'a [Vec<Vec3>],
    /// Constrained joints per frame.
    pub marked: &'a [Vec<usize>],
    /// Frames per second of the GIF.
    pub fps: f32,
}

impl RigPreview<'_> {
    fn frames(&self) -> usize {
        self.positions.len().checked_div(self.joints).unwrap_or(0)
    }

    fn joints_at(&self, f: usize) -> &[Vec3] {
        &self.positions[f * self.joints..(f + 1) * self.joints]
    }

    /// Centre of what is drawn of the character at frame `f`: the midpoint of its meshes'
    /// bounding box (of the joints' when it has no meshes). Joints bunch up in the spine and
    /// hands, so their centroid sits away from the middle of the body.
    fn subject_centre(&self, f: usize) -> Vec3 {
        let mut points = self
            .meshes
            .iter()
            .filter(|m| f < m.frame_count())
            .flat_map(|m| m.frame(f).iter())
            .filter(|q| q.is_finite())
            .peekable();
        if points.peek().is_none() {
            let j = self.joints_at(f);
            return j.iter().copied().sum::<Vec3>() / j.len().max(1) as f32;
        }
        let (min, max) = points.fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(a, b), &q| (a.min(q), b.max(q)),
        );
        0.5 * (min + max)
    }
}

/// One orthographic view per frame along `axes`, centred on the character (its meshes'
/// bounding-box centre, else the joints' centroid; see [`RigPreview::subject_centre`]) smoothed
/// over `±DEFAULT_FOLLOW_SMOOTHING` frames, with one scale for the whole clip: the largest
/// distance of any joint, mesh vertex or line point from its frame's centre (plus a
/// margin).
fn follow(p: &RigPreview<'_>, axes: ViewAxes, aspect: f32) -> Vec<View> {
    let frames = p.frames();
    let raw: Vec<Vec3> = (0..frames).map(|f| p.subject_centre(f)).collect();
    let centres: Vec<Vec3> = (0..frames)
        .map(|f| {
            let k = DEFAULT_FOLLOW_SMOOTHING.min(f).min(frames - 1 - f);
            raw[f - k..=f + k].iter().copied().sum::<Vec3>() / (2 * k + 1) as f32
        })
        .collect();
    let mut half: f32 = 1e-6;
    for (f, c) in centres.iter().enumerate() {
        let line = p.lines.get(f).map_or(&[][..], |l| l.as_slice());
        let meshes = p
            .meshes
            .iter()
            .filter(|m| f < m.frame_count())
            .flat_map(|m| m.frame(f).iter());
        let points = p.joints_at(f).iter().chain(line).chain(meshes);
        for q in points.filter(|q| q.is_finite()) {
            let d = *q - *c;
            half = half.max(d.dot(axes.right).abs() / aspect.max(1e-6));
            half = half.max(d.dot(axes.up).abs());
        }
    }
    let half = half * (1.0 + MARGIN);
    let depth = 8.0 * half + 2.0;
    let projection = anim::Projection::Orthographic {
        xmag: half * aspect,
        ymag: half,
        znear: 0.0,
        zfar: depth,
    }
    .matrix(aspect);
    centres
        .iter()
        .map(|&c| {
            let eye = c - axes.forward * (0.5 * depth);
            let camera = Mat4::from_cols(
                axes.right.extend(0.0),
                axes.up.extend(0.0),
                (-axes.forward).extend(0.0),
                eye.extend(1.0),
            );
            View::new(camera.inverse(), projection)
        })
        .collect()
}

/// Renders the preview: every frame as a GIF (`gif`), else the first frame as a PNG.
///
/// # Errors
/// An empty preview (no frame) as a GIF, or encoding failures.
pub fn rig_preview(preview: &RigPreview<'_>, view: RigView<'_>, gif: bool) -> Result<Vec<u8>> {
    let (w, h) = DEFAULT_RIG_PREVIEW_SIZE;
    let renderer = Renderer::new(w, h)?;
    let frames = preview.frames();
    let views: Vec<View> = match view {
        RigView::Follow(axes) => follow(preview, axes, renderer.aspect()),
        RigView::Camera(camera) => (0..frames.max(1))
            .map(|f| View::camera(camera, f, renderer.aspect()))
            .collect(),
    };
    let which: Vec<usize> = if gif { (0..frames).collect() } else { vec![0] };
    renderer.check_frames(which.len())?;
    let images = which
        .par_iter()
        .map(|&f| {
            let mut list = DrawList::new();
            for m in preview.meshes.iter().filter(|m| f < m.frame_count()) {
                list = list.mesh(MeshItem::from_animation(m, f));
            }
            if f < frames {
                let p = preview.joints_at(f);
                for &(a, b) in preview.bones {
                    let pts = vec![p[a], p[b]];
                    list = list.overlay(Overlay::polyline(Coords::World(pts), BONE_GREY, 1.5));
                }
                if let Some(line) = preview.lines.get(f) {
                    let pts = Coords::World(line.clone());
                    list = list.overlay(Overlay::polyline(pts, LINE_RED, 3.0));
                }
                if let Some(marked) = preview.marked.get(f) {
                    let pts = Coords::World(marked.iter().map(|&j| p[j]).collect());
                    list = list.overlay(Overlay::points(pts, BONE_BLUE, 6.0));
                }
            }
            renderer.render(&list, &views[f.min(views.len() - 1)])
        })
        .collect::<Result<Vec<_>>>()?;
    if gif {
        encode_gif(&images, preview.fps)
    } else {
        encode_png(&images[0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn follow_view_centres_the_meshes_not_the_joints() {
        // Joints bunched at the top of a tall box mesh (as a robot's spine, arms and head).
        let corners = vec![Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 4.0, 0.0)];
        let mesh = anim::Mesh::new("body", corners.clone(), Vec::new());
        let frames = 3;
        let shift = |f: usize| Vec3::new(f as f32, 0.0, 0.0);
        let cache: Vec<Vec3> = (0..frames)
            .flat_map(|f| corners.iter().map(move |&c| c + shift(f)))
            .collect();
        let animation = MeshAnimation::new(mesh, 24.0, cache).unwrap();
        let positions: Vec<Vec3> = (0..frames)
            .flat_map(|f| {
                [
                    Vec3::new(0.0, 3.5, 0.0) + shift(f),
                    Vec3::new(0.5, 3.9, 0.0) + shift(f),
                ]
            })
            .collect();
        let meshes = [&animation];
        let lines = vec![Vec::new(); frames];
        let marked = vec![Vec::new(); frames];
        let preview = RigPreview {
            meshes: &meshes,
            joints: 2,
            positions: &positions,
            bones: &[(0, 1)],
            lines: &lines,
            marked: &marked,
            fps: 24.0,
        };
        let axes = ViewAxes {
            right: Vec3::X,
            up: Vec3::Y,
            forward: Vec3::NEG_Z,
        };
        let views = follow(&preview, axes, 1.0);
        // The middle frame is smoothed symmetrically: the box centre lands mid-image.
        let c = views[1]
            .project(Vec3::new(0.0, 2.0, 0.0) + shift(1), 100, 100)
            .unwrap();
        assert!((c.x - 50.0).abs() < 0.5 && (c.y - 50.0).abs() < 0.5, "{c}");
        // Without meshes the joints' centroid is the centre.
        let bare = RigPreview {
            meshes: &[],
            ..preview
        };
        let c = follow(&bare, axes, 1.0)[1]
            .project(Vec3::new(0.25, 3.7, 0.0) + shift(1), 100, 100)
            .unwrap();
        assert!((c.x - 50.0).abs() < 0.5 && (c.y - 50.0).abs() < 0.5, "{c}");
    }
}
