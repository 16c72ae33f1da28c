//! The rest pose of a scene's mesh objects: the character as modelled, not as the clip
//! deforms it. A smear style's *size* unit is its bounding-box diagonal
//! (`docs/smear-units.md`), so the same character gets the same size whatever clip or frame
//! range is sampled.
//!
//! The rest pose is the **bind pose** the skins' inverse bind matrices encode — what Blender,
//! Maya and other host applications show as an armature's rest position — rebuilt by the rule
//! Blender's glTF importer follows, so that the command line, Python, the studio and the
//! Blender extension measure one character alike (`docs/smear-units.md`, "The rest pose").

use std::collections::{HashMap, HashSet};

use glam::{Mat4, Vec3};

use crate::{skin_positions, Aabb, Clip, Scene, Transform};

/// World matrices of every node at the rest pose of `clip`: every *bone* (a joint of a skin,
/// or a node between a joint and its armature) at its bind transform ([`bind_locals`]), every
/// other node (the armature, the root, a prop, a mesh riding a bone) at its placement at
/// the clip's first frame (`start`), as a host application shows them with its armatures in
/// rest position.
pub(crate) fn rest_world(
    scene: &Scene,
    order: &[usize],
    clip: Option<&Clip>,
    start: f32,
) -> Vec<Mat4> {
    let (mut locals, mut weights): (Vec<Transform>, Vec<Vec<f32>>) = (Vec::new(), Vec::new());
    scene.pose_at(clip, start, &mut locals, &mut weights);
    for (local, bind) in locals.iter_mut().zip(bind_locals(scene)) {
        if let Some(b) = bind {
            *local = b;
        }
    }
    let mut world = Vec::new();
    scene.world_matrices(order, &locals, &mut world);
    world
}

/// The bind-pose local transform of every bone (`None` for other nodes).
///
/// A skin's *armature* is the deepest common ancestor of its joints and its `skeleton` (its
/// parent when that is a joint; the scene root when there is none); the joints and the nodes
/// between them and the armature are bones. The inverse bind matrices are taken relative to
/// the skeleton's parent (the armature in the files Blender, Maya or three.js write), so a
/// bone's bind local is `IB(parent) · IB(bone)⁻¹`, where the scene root and that anchor
/// count as `IB = I`; a bone without an inverse bind matrix of its own or of its parent
/// keeps its node transform. Rotation and translation only: a rest bone has no scale (the
/// node scale is a pose). With inverse bind matrices that are rigid this places every joint
/// at `armature · IB⁻¹` — the skinned mesh exactly as stored, placed by its armature.
pub(crate) fn bind_locals(scene: &Scene) -> Vec<Option<Transform>> {
    let n = scene.nodes.len();
    let parent = |i: usize| scene.nodes[i].parent.filter(|&p| p < n);
    // None stands for the scene root (identity), as in `anchors`.
    let mut inverse_bind: HashMap<Option<usize>, Mat4> = HashMap::from([(None, Mat4::IDENTITY)]);
    let mut bone = vec![false; n];
    for skin in &scene.skins {
        let joints: HashSet<usize> = skin.joints.iter().copied().filter(|&j| j < n).collect();
        if let Some(s) = skin.skeleton.filter(|&s| s < n) {
            let anchor = if joints.contains(&s) {
                parent(s)
            } else {
                Some(s)
            };
            inverse_bind.entry(anchor).or_insert(Mat4::IDENTITY);
        }
        for (&j, ib) in skin.joints.iter().zip(&skin.inverse_bind) {
            if j < n {
                inverse_bind.insert(Some(j), *ib);
            }
        }
        let path = |mut i: usize| {
            let mut p = vec![i];
            while let Some(q) = parent(i) {
                if p.len() > n {
                    break; // a cycle: the scene's own order leaves it out
                }
                p.push(q);
                i = q;
            }
            p.reverse();
            p
        };
        let mut common: Option<Vec<usize>> = None;
        for d in skin
            .joints
            .iter()
            .copied()
            .chain(skin.skeleton)
            .filter(|&d| d < n)
        {
            let p = path(d);
            common = Some(match common {
                None => p,
                Some(c) => c
                    .iter()
                    .zip(&p)
                    .take_while(|(a, b)| a == b)
                    .map(|(a, _)| *a)
                    .collect(),
            });
        }
        let mut armature = common.and_then(|c| c.last().copied());
        if let Some(a) = armature.filter(|a| joints.contains(a)) {
            armature = parent(a);
        }
        for &j in &joints {
            let mut i = Some(j);
            let mut steps = 0;
            while let Some(k) = i.filter(|&k| Some(k) != armature && steps <= n) {
                bone[k] = true;
                i = parent(k);
                steps += 1;
            }
        }
    }
    (0..n)
        .map(|i| {
            if !bone[i] {
                return None;
            }
            let local = match (inverse_bind.get(&Some(i)), inverse_bind.get(&parent(i))) {
                (Some(ib), Some(ib_parent)) => *ib_parent * ib.inverse(),
                _ => scene.nodes[i].transform.matrix(),
            };
            let (_, rotation, translation) = local.to_scale_rotation_translation();
            Some(Transform {
                translation,
                rotation: rotation.normalize(),
                scale: Vec3::ONE,
            })
        })
        .collect()
}

/// Bounding box of the mesh `node` draws at the rest pose (`world` from [`rest_world`]): its
/// base positions (no morph target applied) skinned with the joints' rest matrices, or
/// placed by the node's rest matrix when it has no skin.
pub(crate) fn rest_bounds(scene: &Scene, node: usize, world: &[Mat4]) -> Aabb {
    let n = &scene.nodes[node];
    let sm = &scene.meshes[n.mesh.expect("mesh node")];
    let base = &sm.mesh.positions;
    match (n.skin, &sm.joint_weights) {
        (Some(s), Some(w)) => {
            let def = &scene.skins[s];
            let mats: Vec<Mat4> = def
                .joints
                .iter()
                .zip(&def.inverse_bind)
                .map(|(&j, ib)| world[j] * *ib)
                .collect();
            let mut out = vec![Vec3::ZERO; base.len()];
            skin_positions(w, &mats, base, &mut out);
            Aabb::from_points(&out)
        }
        _ => {
            let m = world[node];
            let mut b = Aabb::EMPTY;
            for p in base {
                b.grow(m.transform_point3(*p));
            }
            b
        }
    }
}
