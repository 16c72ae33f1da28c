//! Painted weights ω ∈ [0, 1] (paper Fig. 15b: "painted weights" restrict an effect to part of
//! the body): from a weight group of the skeleton, from a vertex attribute painted in the
//! animation package, or interpolated at surface points (motion-line seeds).

use anim::{Mesh, SampledScene};

use crate::{Result, SmearError, SurfacePoint};

fn unit(w: f32) -> f32 {
    if w.is_finite() {
        w.clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Weights of a *weight group*: per vertex of object `object`, the summed skin weights of the
/// named joints (and, with `descendants`, of every joint below them) — e.g. `["Head"]` smears
/// the head and what hangs from it. An unskinned object carried by a joint (a rigid prop) gets
/// 1 when that joint is in the group, 0 otherwise; a free object gets 0.
///
/// # Errors
/// [`SmearError::UnknownJoint`] listing the skeleton's joints for a name that is not a joint;
/// [`SmearError::UnknownObject`] for an object index out of range.
///
/// # Performance
/// One pass over the skin influences.
pub fn group_weights(
    scene: &SampledScene,
    object: usize,
    joints: &[String],
    descendants: bool,
) -> Result<Vec<f32>> {
    let obj = scene.objects.get(object).ok_or(SmearError::UnknownObject {
        index: object,
        count: scene.objects.len(),
    })?;
    let skeleton = &scene.skeleton;
    let mut in_group = vec![false; skeleton.len()];
    let mut stack = Vec::new();
    for name in joints {
        let j = skeleton.find(name).map_err(|_| SmearError::UnknownJoint {
            name: name.clone(),
            available: joint_names(scene),
        })?;
        stack.push(j);
    }
    let children = skeleton.children();
    while let Some(j) = stack.pop() {
        if !std::mem::replace(&mut in_group[j], true) && descendants {
            stack.extend(&children[j]);
        }
    }
    let n = obj.animation.vertex_count();
    Ok(match (&obj.skin, obj.parent_joint) {
        (Some(skin), _) => (0..n)
            .map(|v| {
                let (slots, w) = skin.weights.influences(v);
                unit(
                    slots
                        .iter()
                        .zip(w)
                        .filter(|(s, _)| {
                            skin.joints
                                .get(**s as usize)
                                .is_some_and(|&j| in_group.get(j) == Some(&true))
                        })
                        .map(|(_, w)| w)
                        .sum(),
                )
            })
            .collect(),
        (None, Some(j)) => vec![if in_group[j] { 1.0 } else { 0.0 }; n],
        (None, None) => vec![0.0; n],
    })
}

fn joint_names(scene: &SampledScene) -> String {
    let names: Vec<&str> = scene
        .skeleton
        .joints
        .iter()
        .map(|j| j.name.as_str())
        .collect();
    if names.is_empty() {
        "(none: the input has no skeleton)".into()
    } else {
        names.join(", ")
    }
}

/// Weights painted as a scalar vertex attribute (a glTF `_NAME` attribute, e.g. exported from
/// a Blender colour/attribute layer), or one channel of the vertex colours (`COLOR_0.r`, `.g`,
/// `.b`, `.a`; linear values as stored), clamped to [0, 1]; non-finite values read 0. The
/// leading underscore of `_NAME` may be omitted.
///
/// # Errors
/// [`SmearError::UnknownAttribute`] listing the mesh's attributes.
pub fn attribute_weights(mesh: &Mesh, name: &str) -> Result<Vec<f32>> {
    if let (Some(channel), Some(colors)) = (color_channel(name), &mesh.colors) {
        return Ok(colors.iter().map(|c| unit(c[channel])).collect());
    }
    let values = mesh
        .attributes
        .get(name)
        .or_else(|| mesh.attributes.get(&format!("_{name}")))
        .ok_or_else(|| SmearError::UnknownAttribute {
            name: name.to_string(),
            available: {
                let mut names: Vec<String> = mesh.attributes.keys().cloned().collect();
                if mesh.colors.is_some() {
                    names.extend(
                        ["COLOR_0.r", "COLOR_0.g", "COLOR_0.b", "COLOR_0.a"].map(String::from),
                    );
                }
                if names.is_empty() {
                    "(none)".into()
                } else {
                    names.join(", ")
                }
            },
        })?;
    Ok(values.iter().map(|&w| unit(w)).collect())
}

/// `COLOR_0.r` → 0, … `COLOR_0.a` → 3.
fn color_channel(name: &str) -> Option<usize> {
    let channel = name.strip_prefix("COLOR_0.")?;
    ["r", "g", "b", "a"].iter().position(|c| *c == channel)
}

/// Per-vertex weights interpolated at surface points (barycentric blend of the three corners),
/// e.g. for motion-line seeds, so a seed gets the weight painted around it.
///
/// # Errors
/// [`SmearError::InvalidSurfacePoint`] for a missing triangle or unusable coordinates;
/// [`SmearError::InvalidParameter`] when a corner has no weight.
pub fn surface_point_weights(
    vertex_weights: &[f32],
    triangles: &[[u32; 3]],
    points: &[SurfacePoint],
) -> Result<Vec<f32>> {
    points
        .iter()
        .enumerate()
        .map(|(index, pt)| {
            let mut w = 0.0;
            for (v, b) in pt.corners(index, triangles)? {
                w += b * vertex_weights
                    .get(v)
                    .ok_or_else(|| SmearError::InvalidParameter {
                        name: "weights",
                        reason: format!(
                            "vertex {v} has no weight ({} given)",
                            vertex_weights.len()
                        ),
                    })?;
            }
            Ok(unit(w))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attribute_weights_clamp_and_name_the_missing_attribute() {
        let mut mesh = Mesh::new("m", vec![glam::Vec3::ZERO; 3], vec![[0, 1, 2]]);
        mesh.attributes
            .insert("_SMEAR".into(), vec![0.5, 2.0, f32::NAN]);
        assert_eq!(attribute_weights(&mesh, "SMEAR").unwrap(), [0.5, 1.0, 0.0]);
        let e = attribute_weights(&mesh, "_OTHER").unwrap_err().to_string();
        assert!(e.contains("_OTHER") && e.contains("_SMEAR"), "{e}");
        assert!(attribute_weights(&mesh, "COLOR_0.g").is_err());
        mesh.colors = Some(vec![
            [0.0, 0.25, 1.0, 1.0],
            [0.0, 0.5, 1.0, 1.0],
            [0.0, 3.0, 1.0, 1.0],
        ]);
        assert_eq!(
            attribute_weights(&mesh, "COLOR_0.g").unwrap(),
            [0.25, 0.5, 1.0]
        );
        let e = attribute_weights(&mesh, "COLOR_0.x")
            .unwrap_err()
            .to_string();
        assert!(e.contains("COLOR_0.a"), "{e}");
        let pts = [SurfacePoint {
            triangle: 0,
            barycentric: [1.0, 1.0, 0.0],
        }];
        let w = surface_point_weights(&[0.2, 0.6, 1.0], &mesh.triangles, &pts).unwrap();
        assert!((w[0] - 0.4).abs() < 1e-6);
        assert!(surface_point_weights(&[0.2], &mesh.triangles, &pts).is_err());
    }
}
