//! The line-of-action motion as the skeleton's pose per frame instead of every vertex: the
//! page skins the character itself (three.js `SkinnedMesh`, linear blend skinning as any
//! glTF viewer does), from a binding sent once per character (rest positions, up to four
//! influences per vertex over a palette of node × inverse bind) and, per answer, the world
//! matrices of the palette's nodes for every motion frame (a few hundred KB instead of MBs).
//! A character's motion is checked against the core's skinned positions before it is first
//! sent this way; the binding is then kept as checked for the file's later motions
//! ([`CheckedSkin`]; docs/studio.md, "Loa: the skeleton's pose, skinned by the renderer").

use anim::glam::{Mat4, Vec3, Vec4};
use anim::{MeshAnimation, SampledScene, Scene};
use rayon::prelude::*;

use crate::pack::Pack;

/// Influences per vertex the page's skinning takes (three.js `skinIndex`/`skinWeight`).
const MAX_INFLUENCES: usize = 4;

/// Largest distance between the page's skinning and the core's positions, as a fraction of
/// the motion's bounding-box diagonal, for the pose to be sent instead of the positions.
pub(crate) const MAX_SKINNING_ERROR: f32 = 1e-5;

/// How every merged vertex is skinned: `nodes` (scene nodes whose world matrices the
/// answers carry; `None` for the identity of a vertex without influence), the palette
/// (`palette_node` into `nodes`, `inverse`), and per vertex four palette entries and weights.
#[derive(Debug)]
pub(crate) struct Binding {
    nodes: Vec<Option<usize>>,
    palette_node: Vec<u32>,
    inverse: Vec<Mat4>,
    index: Vec<u32>,
    weight: Vec<f32>,
    rest: Vec<Vec3>,
    /// Names this binding (the page keeps it while the id stays).
    pub(crate) id: String,
}

impl Binding {
    /// The binding of every mesh object of `sampled` (of `scene`), in object order; `None`
    /// when a vertex has more than [`MAX_INFLUENCES`] influences or an object is not found.
    pub(crate) fn new(scene: &Scene, sampled: &SampledScene) -> Option<Binding> {
        let mut nodes: Vec<Option<usize>> = vec![None];
        let node_slot = |n: Option<usize>, nodes: &mut Vec<Option<usize>>| -> u32 {
            match nodes.iter().position(|&m| m == n) {
                Some(i) => i as u32,
                None => {
                    nodes.push(n);
                    (nodes.len() - 1) as u32
                }
            }
        };
        // Palette entry 0: the identity (a vertex left at its rest position).
        let (mut palette_node, mut inverse) = (vec![0u32], vec![Mat4::IDENTITY]);
        let (mut index, mut weight, mut rest) = (Vec::new(), Vec::new(), Vec::new());
        for o in &sampled.objects {
            let mesh = &scene.meshes.get(scene.nodes.get(o.node)?.mesh?)?.mesh;
            let nv = o.animation.vertex_count();
            if mesh.positions.len() != nv {
                return None;
            }
            rest.extend_from_slice(&mesh.positions);
            let first = palette_node.len() as u32;
            match &o.skin {
                Some(skin) => {
                    for (&j, ib) in skin.joints.iter().zip(&skin.inverse_bind) {
                        palette_node
                            .push(node_slot(Some(*sampled.joint_nodes.get(j)?), &mut nodes));
                        inverse.push(*ib);
                    }
                    for v in 0..nv {
                        let (slots, w) = skin.weights.influences(v);
                        if slots.len() > MAX_INFLUENCES {
                            return None;
                        }
                        for k in 0..MAX_INFLUENCES {
                            match (slots.get(k), w.get(k)) {
                                (Some(&s), Some(&x)) => {
                                    index.push(first + s);
                                    weight.push(x);
                                }
                                _ => {
                                    // No influence at all: the identity, weight 1.
                                    index.push(0);
                                    weight.push(if k == 0 && slots.is_empty() { 1.0 } else { 0.0 });
                                }
                            }
                        }
                    }
                }
                None => {
                    palette_node.push(node_slot(Some(o.node), &mut nodes));
                    inverse.push(Mat4::IDENTITY);
                    for _ in 0..nv {
                        index.extend([first, 0, 0, 0]);
                        weight.extend([1.0, 0.0, 0.0, 0.0]);
                    }
                }
            }
        }
        let id = format!(
            "{}:{}:{}:{:08x}",
            rest.len(),
            palette_node.len(),
            nodes.len(),
            fnv(bytemuck::cast_slice(&weight)) ^ fnv(bytemuck::cast_slice(&index))
        );
        Some(Binding {
            nodes,
            palette_node,
            inverse,
            index,
            weight,
            rest,
            id,
        })
    }

    /// The world matrices of [`Binding::nodes`] for every frame of `node_world` (every
    /// scene node per frame, frame-major, as `anim` samples them), frame-major, column-major
    /// 4 × 4; `None` when `node_world` does not hold `frames` whole frames or lacks a node.
    pub(crate) fn world(&self, node_world: &[Mat4], frames: usize) -> Option<Vec<f32>> {
        let all = node_world.len() / frames.max(1);
        if frames == 0 || all * frames != node_world.len() {
            return None;
        }
        let mut world = Vec::with_capacity(frames * self.nodes.len() * 16);
        for f in 0..frames {
            for n in &self.nodes {
                let m = match n {
                    Some(n) => (*n < all).then(|| node_world[f * all + n])?,
                    None => Mat4::IDENTITY,
                };
                world.extend_from_slice(&m.to_cols_array());
            }
        }
        Some(world)
    }

    /// [`Binding::world`] of `sampled`'s frames, when skinning with it reproduces `merged`
    /// within [`MAX_SKINNING_ERROR`] of its diagonal on every frame (a morph target or
    /// another deformation the pose does not carry: `None`).
    pub(crate) fn pose(&self, sampled: &SampledScene, merged: &MeshAnimation) -> Option<Vec<f32>> {
        let frames = merged.frame_count();
        if self.rest.len() != merged.vertex_count() {
            return None;
        }
        let world = self.world(&sampled.node_world, frames)?;
        let bounds = merged.bbox();
        let tolerance = MAX_SKINNING_ERROR * (bounds.max - bounds.min).length();
        let exact = (0..frames).into_par_iter().all(|f| {
            let at = |k: u32| {
                let o = (f * self.nodes.len() + self.palette_node[k as usize] as usize) * 16;
                Mat4::from_cols_slice(&world[o..o + 16]) * self.inverse[k as usize]
            };
            let palette: Vec<Mat4> = (0..self.palette_node.len() as u32).map(at).collect();
            self.rest
                .iter()
                .zip(merged.frame(f))
                .enumerate()
                .all(|(v, (p, q))| {
                    let mut acc = Vec4::ZERO;
                    for k in 0..MAX_INFLUENCES {
                        let x = self.weight[v * MAX_INFLUENCES + k];
                        if x != 0.0 {
                            let m = &palette[self.index[v * MAX_INFLUENCES + k] as usize];
                            acc += m.mul_vec4(p.extend(1.0)) * x;
                        }
                    }
                    (acc.truncate() - *q).abs().max_element() <= tolerance
                })
        });
        exact.then_some(world)
    }

    /// Adds the binding's buffers: `skin.rest` (f32 vertices × 3), `skin.index` (u32
    /// vertices × 4, palette entries), `skin.weight` (f32 vertices × 4), `skin.node` (u32 per
    /// palette entry, into the pose's nodes), `skin.inverse` (f32 per entry × 16).
    pub(crate) fn pack(&self, pack: &mut Pack) {
        pack.f32_slices("skin.rest", [crate::pack::coordinates(&self.rest)]);
        pack.u32("skin.index", self.index.iter().copied());
        pack.f32("skin.weight", self.weight.iter().copied());
        pack.u32("skin.node", self.palette_node.iter().copied());
        pack.f32(
            "skin.inverse",
            self.inverse.iter().flat_map(|m| m.to_cols_array()),
        );
    }

    /// Nodes per frame of the pose.
    pub(crate) fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Vertices of the merged meshes it skins.
    pub(crate) fn vertex_count(&self) -> usize {
        self.rest.len()
    }
}

/// A character's binding once [`Binding::pose`] found that skinning reproduces the core's
/// positions, with the merged meshes' triangles. What makes the check pass — every mesh
/// skinned by node matrices alone, at most [`MAX_INFLUENCES`] influences, no morph target
/// away from its rest weight — belongs to the file, not to a pose: a line-of-action motion
/// keys only the skeleton's nodes (`loa::animate::CLIP_NAME`), so the character's later
/// motions are sent as the pose without sampling and checking every vertex again.
#[derive(Debug)]
pub(crate) struct CheckedSkin {
    /// The binding.
    pub(crate) binding: Binding,
    /// The merged meshes' triangles (the answers' `triangles`).
    pub(crate) triangles: std::sync::Arc<Vec<[u32; 3]>>,
}

/// FNV-1a of `bytes` (names a binding; not a security measure).
fn fnv(bytes: &[u8]) -> u32 {
    bytes.iter().fold(0x811c_9dc5u32, |h, &b| {
        (h ^ u32::from(b)).wrapping_mul(0x0100_0193)
    })
}
