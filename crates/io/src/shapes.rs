//! Animations that show one of a few shapes of a mesh on every frame (a stop-motion
//! replacement library: pieces and the piece of every frame), written without expanding them
//! to every frame: `.glb` holds the shapes as morph targets with STEP weights, `.pc2` is
//! streamed to disk frame by frame; other formats get the expanded point caches.

use std::io::{BufWriter, Write};
use std::path::Path;

use anim::glam::Vec3;
use anim::{Channel, Clip, Interpolation, Mesh, MeshAnimation, MorphTarget, Node, Property};
use anim::{Scene, SceneMesh};

use crate::{IoError, Result};

/// One mesh that shows `shapes[shown[f]]` on frame `f`.
#[derive(Debug, Clone, Copy)]
pub struct ShapeAnimation<'a> {
    /// Name, topology and attributes (its positions are not used).
    pub mesh: &'a Mesh,
    /// The shapes, one position per vertex of `mesh` each.
    pub shapes: &'a [Vec<Vec3>],
    /// The shape shown on every frame.
    pub shown: &'a [u32],
    /// Frames per second.
    pub fps: f32,
    /// Time of frame 0 in seconds.
    pub start_time: f32,
}

impl ShapeAnimation<'_> {
    /// Every frame as a point cache.
    ///
    /// # Errors
    /// When a shown shape does not exist or has the wrong vertex count.
    pub fn expand(&self) -> Result<MeshAnimation> {
        self.check()?;
        let positions = self
            .shown
            .iter()
            .flat_map(|&s| self.shapes[s as usize].iter().copied())
            .collect();
        let mut a = MeshAnimation::new(self.mesh.clone(), self.fps, positions)?;
        a.start_time = self.start_time;
        Ok(a)
    }

    fn check(&self) -> Result<()> {
        let m = self.mesh.vertex_count();
        if let Some(bad) = self.shapes.iter().position(|s| s.len() != m) {
            return Err(IoError::unsupported(format!(
                "shape {bad} of '{}' has {} positions for {m} vertices",
                self.mesh.name,
                self.shapes[bad].len()
            )));
        }
        if let Some(&s) = self
            .shown
            .iter()
            .find(|&&s| s as usize >= self.shapes.len())
        {
            return Err(IoError::unsupported(format!(
                "'{}' shows shape {s} of {}",
                self.mesh.name,
                self.shapes.len()
            )));
        }
        Ok(())
    }
}

/// Checks that `parts` share their frames and are well formed.
pub(crate) fn check_parts(parts: &[ShapeAnimation<'_>]) -> Result<()> {
    let Some(first) = parts.first() else {
        return Err(IoError::unsupported("no part to write"));
    };
    for p in parts {
        p.check()?;
        if p.shown.len() != first.shown.len() || p.fps != first.fps {
            return Err(IoError::unsupported(format!(
                "part '{}' has {} frames at {} fps, '{}' {} at {}",
                p.mesh.name,
                p.shown.len(),
                p.fps,
                first.mesh.name,
                first.shown.len(),
                first.fps
            )));
        }
    }
    Ok(())
}

/// The scene of `parts`: one node per part whose mesh is the first shape with every shape as
/// a morph target (its difference from the first), keyed STEP so that frame `f` weighs its
/// shown shape 1 and the others 0.
pub(crate) fn shapes_scene(parts: &[ShapeAnimation<'_>]) -> Scene {
    let mut scene = Scene::default();
    let mut channels = Vec::new();
    for p in parts {
        let base = &p.shapes[0];
        let mut mesh = p.mesh.clone();
        mesh.positions.clone_from(base);
        mesh.normals = None;
        let d = p.shapes.len();
        let morph_targets = p
            .shapes
            .iter()
            .enumerate()
            .map(|(k, s)| MorphTarget {
                name: format!("shape_{k:02}"),
                positions: s.iter().zip(base).map(|(a, b)| *a - *b).collect(),
            })
            .collect();
        let node = scene.nodes.len();
        scene.nodes.push(Node {
            name: p.mesh.name.clone(),
            mesh: Some(scene.meshes.len()),
            ..Node::default()
        });
        let mut default_weights = vec![0.0; d];
        if let Some(&s) = p.shown.first() {
            default_weights[s as usize] = 1.0;
        }
        scene.meshes.push(SceneMesh {
            mesh,
            morph_targets,
            default_weights,
            joint_weights: None,
        });
        if p.shown.len() > 1 {
            let mut values = vec![0.0f32; p.shown.len() * d];
            for (f, &s) in p.shown.iter().enumerate() {
                values[f * d + s as usize] = 1.0;
            }
            channels.push(Channel {
                node,
                property: Property::Weights(d),
                interpolation: Interpolation::Step,
                times: (0..p.shown.len())
                    .map(|f| p.start_time + f as f32 / p.fps)
                    .collect(),
                values,
            });
        }
    }
    if !channels.is_empty() {
        scene.clips.push(Clip {
            name: "reconstruction".into(),
            channels,
        });
    }
    scene
}

/// Streams the parts, merged in part order, as one PC2 point cache to `path` (the same bytes
/// as [`crate::pc2::write`] of the expanded, merged cache).
pub(crate) fn write_pc2(path: &Path, parts: &[ShapeAnimation<'_>]) -> Result<()> {
    let first = &parts[0];
    let vertices: usize = parts.iter().map(|p| p.mesh.vertex_count()).sum();
    let frames = first.shown.len();
    crate::atomic::write_atomic_with(path, |file| {
        let mut w = BufWriter::with_capacity(1 << 20, file);
        let io = |e| IoError::io(path, e);
        let header = crate::pc2::header_bytes(vertices, frames, first.start_time, first.fps);
        w.write_all(&header).map_err(io)?;
        let mut le = Vec::new();
        for f in 0..frames {
            for p in parts {
                let shape: &[Vec3] = &p.shapes[p.shown[f] as usize];
                // PC2 is little-endian: on such machines a shape's memory is its bytes.
                let bytes: &[u8] = if cfg!(target_endian = "little") {
                    bytemuck::cast_slice(shape)
                } else {
                    le.clear();
                    le.extend(
                        shape
                            .iter()
                            .flat_map(|v| v.to_array())
                            .flat_map(f32::to_le_bytes),
                    );
                    &le
                };
                w.write_all(bytes).map_err(io)?;
            }
        }
        w.flush().map_err(io)
    })
}
