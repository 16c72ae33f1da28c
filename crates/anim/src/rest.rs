//! The rest pose of a scene's mesh objects: the character as modelled, not as the clip
//! deforms it. A smear style's *size* unit is its bounding-box diagonal
//! (`docs/smear-units.md`), so the same character gets the same size whatever clip or frame
//! range is sampled.

use glam::{Mat4, Vec3};

use crate::{skin_positions, Aabb, Clip, Scene, Transform};

/// World matrices of every node at the rest pose of `clip`: the clip's first frame (`start`)
/// with every joint of a skin at its own transform — the pose the file holds without a clip,
/// where exporters write the bind pose. Nodes that are not joints (the armature's own
/// object, a keyed prop, the root) keep their first-frame placement, as a host application
/// shows them with its armatures in rest position.
pub(crate) fn rest_world(
    scene: &Scene,
    order: &[usize],
    clip: Option<&Clip>,
    start: f32,
) -> Vec<Mat4> {
    let (mut locals, mut weights): (Vec<Transform>, Vec<Vec<f32>>) = (Vec::new(), Vec::new());
    scene.pose_at(clip, start, &mut locals, &mut weights);
    for skin in &scene.skins {
        for &j in &skin.joints {
            locals[j] = scene.nodes[j].transform;
        }
    }
    let mut world = Vec::new();
    scene.world_matrices(order, &locals, &mut world);
    world
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
