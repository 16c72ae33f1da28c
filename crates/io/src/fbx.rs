//! FBX reader (binary and ASCII, 6.x–7.x) through `ufbx` into [`anim::Scene`].
//!
//! ufbx parses the file and converts it to toonkit's conventions while loading: right-handed,
//! Y up, metres (`SpaceConversion::ModifyGeometry`, so geometry, transforms, skins and
//! animation are all converted and no hidden root transform remains), geometric transforms
//! baked into the geometry, cameras looking down −Z. toonkit then maps:
//! - nodes → [`anim::Node`]s (local translation / rotation / scale at rest);
//! - meshes → one [`SceneMesh`] per mesh (its control points are the vertices, faces are
//!   triangulated; every UV set, of the first corner of each vertex, `v` flipped to glTF's
//!   top-left origin), with skin
//!   clusters as joints (`geometry_to_bone` is the inverse bind matrix) and blend channels as
//!   morph targets (deltas of the channel's full-weight shape);
//! - animation stacks → clips, sampled at the file's frame rate from `time_begin` to
//!   `time_end` (node TRS, blend weights), linear between samples;
//! - cameras → perspective or orthographic [`SceneCamera`]s.

use anim::glam::{Mat4, Quat, Vec3};
use anim::{
    Channel, Clip, Interpolation, Mesh, MorphTarget, Node, Projection, Property, Scene,
    SceneCamera, SceneMesh, SkinDef, Transform, VertexWeights,
};

use crate::{IoError, Result};

fn bad(message: impl Into<String>) -> IoError {
    IoError::malformed("FBX", message)
}

fn v3(v: ufbx::Vec3) -> Vec3 {
    Vec3::new(v.x as f32, v.y as f32, v.z as f32)
}

fn quat(q: ufbx::Quat) -> Quat {
    let q = Quat::from_xyzw(q.x as f32, q.y as f32, q.z as f32, q.w as f32);
    if q.is_finite() && q.length_squared() > 1e-12 {
        q.normalize()
    } else {
        Quat::IDENTITY
    }
}

fn transform(t: &ufbx::Transform) -> Transform {
    Transform {
        translation: v3(t.translation),
        rotation: quat(t.rotation),
        scale: v3(t.scale),
    }
}

fn mat4(m: &ufbx::Matrix) -> Mat4 {
    Mat4::from_cols_array(&[
        m.m00 as f32,
        m.m10 as f32,
        m.m20 as f32,
        0.0,
        m.m01 as f32,
        m.m11 as f32,
        m.m21 as f32,
        0.0,
        m.m02 as f32,
        m.m12 as f32,
        m.m22 as f32,
        0.0,
        m.m03 as f32,
        m.m13 as f32,
        m.m23 as f32,
        1.0,
    ])
}

/// ufbx's error in one line: its description and, when it gives one, its detail (`info`).
fn load_error(e: &ufbx::Error) -> String {
    let mut text = e.description.to_string();
    if !e.info().is_empty() {
        text.push_str(&format!(": {}", e.info()));
    }
    text.replace(['\n', '\r'], " ")
}

/// Reads FBX bytes; returns the scene and notes (version, creator, units and axes converted).
///
/// # Errors
/// When ufbx cannot parse the file, or its content is inconsistent.
pub fn read(bytes: &[u8]) -> Result<(Scene, Vec<String>)> {
    let opts = ufbx::LoadOpts {
        target_axes: ufbx::CoordinateAxes::right_handed_y_up(),
        target_camera_axes: ufbx::CoordinateAxes::right_handed_y_up(),
        target_unit_meters: 1.0,
        space_conversion: ufbx::SpaceConversion::ModifyGeometry,
        geometry_transform_handling: ufbx::GeometryTransformHandling::ModifyGeometry,
        inherit_mode_handling: ufbx::InheritModeHandling::Compensate,
        ..Default::default()
    };
    let root = ufbx::load_memory(bytes, opts).map_err(|e| bad(load_error(&e)))?;
    let fbx: &ufbx::Scene = &root;
    let notes = notes(fbx);
    let mut scene = Scene::default();
    for node in fbx.nodes.iter() {
        scene.nodes.push(Node {
            name: node.element.name.to_string(),
            parent: node.parent.as_ref().map(|p| p.element.typed_id as usize),
            children: node
                .children
                .iter()
                .map(|c| c.element.typed_id as usize)
                .collect(),
            transform: transform(&node.local_transform),
            mesh: node.mesh.as_ref().map(|m| m.element.typed_id as usize),
            skin: None,
            camera: node.camera.as_ref().map(|c| c.element.typed_id as usize),
            weights: None,
        });
    }
    for mesh in fbx.meshes.iter() {
        let (sm, skin) = read_mesh(mesh)?;
        if let Some(skin) = skin {
            let index = scene.skins.len();
            scene.skins.push(skin);
            for inst in mesh.element.instances.iter() {
                scene.nodes[inst.element.typed_id as usize].skin = Some(index);
            }
        }
        scene.meshes.push(sm);
    }
    for cam in fbx.cameras.iter() {
        scene.cameras.push(camera(cam));
    }
    for stack in fbx.anim_stacks.iter() {
        scene.clips.push(clip(fbx, stack, &scene)?);
    }
    scene.validate()?;
    Ok((scene, notes))
}

fn notes(fbx: &ufbx::Scene) -> Vec<String> {
    let m = &fbx.metadata;
    let s = &fbx.settings;
    let mut notes = vec![format!(
        "FBX {} ({}){}",
        m.version,
        if m.ascii { "ASCII" } else { "binary" },
        if m.creator.is_empty() {
            String::new()
        } else {
            format!(" by {}", m.creator)
        }
    )];
    notes.push(format!(
        "units: 1 file unit = {} m, converted to metres; axes converted to Y-up (file up axis {:?})",
        s.original_unit_meters, s.original_axis_up
    ));
    if s.frames_per_second > 0.0 {
        notes.push(format!(
            "animation stacks sampled at the file's {} fps",
            s.frames_per_second
        ));
    }
    notes
}

fn camera(cam: &ufbx::Camera) -> SceneCamera {
    let znear = cam.near_plane as f32;
    let zfar = cam.far_plane as f32;
    let projection = match cam.projection_mode {
        ufbx::ProjectionMode::Orthographic => Projection::Orthographic {
            xmag: cam.orthographic_size.x as f32 * 0.5,
            ymag: cam.orthographic_size.y as f32 * 0.5,
            znear,
            zfar,
        },
        _ => Projection::Perspective {
            yfov: (cam.field_of_view_deg.y as f32).to_radians(),
            aspect: (cam.aspect_ratio > 0.0).then_some(cam.aspect_ratio as f32),
            znear,
            zfar: (zfar > znear).then_some(zfar),
        },
    };
    SceneCamera {
        name: cam.element.name.to_string(),
        projection,
    }
}

/// One mesh: control points, triangles, first-corner UVs, skin, blend shapes.
fn read_mesh(mesh: &ufbx::Mesh) -> Result<(SceneMesh, Option<SkinDef>)> {
    let name = mesh.element.name.to_string();
    let positions: Vec<Vec3> = mesh.vertices.iter().map(|&p| v3(p)).collect();
    let n = positions.len();
    let mut triangles = Vec::with_capacity(mesh.num_triangles);
    let mut corners = vec![0u32; mesh.max_face_triangles * 3];
    for &face in mesh.faces.iter() {
        let count = ufbx::triangulate_face(&mut corners, mesh, face) as usize;
        for t in corners[..count * 3].chunks_exact(3) {
            let v = |c: u32| mesh.vertex_indices.get(c as usize).copied();
            if let (Some(a), Some(b), Some(c)) = (v(t[0]), v(t[1]), v(t[2])) {
                if (a as usize) < n && (b as usize) < n && (c as usize) < n {
                    triangles.push([a, b, c]);
                }
            }
        }
    }
    let mut part = Mesh::new(name.clone(), positions, triangles);
    // Every UV set: the first is `uvs`, the others `extra_uvs` (glTF TEXCOORD_1, …).
    let mut sets = mesh
        .uv_sets
        .iter()
        .filter(|set| set.vertex_uv.exists)
        .map(|set| vertex_uvs(mesh, &set.vertex_uv, n));
    part.uvs = sets.next();
    part.extra_uvs = sets.collect();
    let mut out = SceneMesh {
        mesh: part,
        ..SceneMesh::default()
    };
    for blend in mesh.blend_deformers.iter() {
        for channel in blend.channels.iter() {
            let mut deltas = vec![Vec3::ZERO; n];
            if let Some(shape) = channel.target_shape.as_ref() {
                for (&v, &d) in shape
                    .offset_vertices
                    .iter()
                    .zip(shape.position_offsets.iter())
                {
                    if let Some(slot) = deltas.get_mut(v as usize) {
                        *slot = v3(d);
                    }
                }
            }
            out.morph_targets.push(MorphTarget {
                name: channel.element.name.to_string(),
                positions: deltas,
            });
            out.default_weights.push(channel.weight as f32);
        }
    }
    let skin = match mesh.skin_deformers.first() {
        Some(skin) => {
            let joints: Vec<usize> = skin
                .clusters
                .iter()
                .map(|c| {
                    c.bone_node
                        .as_ref()
                        .map(|b| b.element.typed_id as usize)
                        .ok_or_else(|| {
                            bad(format!("skin cluster '{}' has no bone", c.element.name))
                        })
                })
                .collect::<Result<_>>()?;
            let inverse_bind = skin
                .clusters
                .iter()
                .map(|c| mat4(&c.geometry_to_bone))
                .collect();
            let mut influences: Vec<Vec<(u32, f32)>> = vec![Vec::new(); n];
            for (v, sv) in skin.vertices.iter().enumerate().take(n) {
                let begin = sv.weight_begin as usize;
                let end = begin + sv.num_weights as usize;
                for w in skin.weights.get(begin..end).unwrap_or_default() {
                    influences[v].push((w.cluster_index, w.weight as f32));
                }
            }
            out.joint_weights = Some(VertexWeights::from_influences(influences));
            Some(SkinDef {
                name: skin.element.name.to_string(),
                joints,
                inverse_bind,
                skeleton: None,
            })
        }
        None => None,
    };
    Ok((out, skin))
}

/// The texture coordinates of the first corner of every vertex, with `v` flipped from FBX's
/// bottom-left origin to glTF's top-left one (as OBJ's reader does).
fn vertex_uvs(mesh: &ufbx::Mesh, uv: &ufbx::VertexVec2, n: usize) -> Vec<[f32; 2]> {
    let mut uvs = vec![[0.0f32; 2]; n];
    for (v, &first) in mesh.vertex_first_index.iter().enumerate().take(n) {
        let value = uv
            .indices
            .get(first as usize)
            .and_then(|&i| uv.values.get(i as usize));
        if let Some(value) = value {
            uvs[v] = [value.x as f32, 1.0 - value.y as f32];
        }
    }
    uvs
}

/// One animation stack sampled at the file's frame rate: TRS of every node, weights of
/// every blend channel.
fn clip(fbx: &ufbx::Scene, stack: &ufbx::AnimStack, scene: &Scene) -> Result<Clip> {
    let fps = if fbx.settings.frames_per_second > 0.0 {
        fbx.settings.frames_per_second
    } else {
        30.0
    };
    let (begin, end) = (stack.time_begin, stack.time_end.max(stack.time_begin));
    let frames = ((end - begin) * fps).round() as usize + 1;
    if frames > 1_000_000 {
        return Err(bad(format!(
            "animation stack '{}' is {} s long",
            stack.element.name,
            end - begin
        )));
    }
    let times: Vec<f32> = (0..frames).map(|f| (f as f64 / fps) as f32).collect();
    let at = |f: usize| (begin + f as f64 / fps).min(end);
    let anim = &stack.anim;
    let mut channels = Vec::new();
    for node in fbx.nodes.iter() {
        if node.is_root {
            continue;
        }
        let index = node.element.typed_id as usize;
        let mut t = Vec::with_capacity(frames * 3);
        let mut r = Vec::with_capacity(frames * 4);
        let mut s = Vec::with_capacity(frames * 3);
        for f in 0..frames {
            let x = ufbx::evaluate_transform(anim, node, at(f));
            let x = transform(&x);
            t.extend(x.translation.to_array());
            r.extend(x.rotation.to_array());
            s.extend(x.scale.to_array());
        }
        for (property, values) in [
            (Property::Translation, t),
            (Property::Rotation, r),
            (Property::Scale, s),
        ] {
            channels.push(Channel {
                node: index,
                property,
                interpolation: Interpolation::Linear,
                times: times.clone(),
                values,
            });
        }
        if let Some(mesh) = node.mesh.as_ref() {
            let targets = scene.meshes[mesh.element.typed_id as usize]
                .morph_targets
                .len();
            if targets > 0 {
                let mut values = Vec::with_capacity(frames * targets);
                for f in 0..frames {
                    for blend in mesh.blend_deformers.iter() {
                        for ch in blend.channels.iter() {
                            values.push(ufbx::evaluate_blend_weight(anim, ch, at(f)) as f32);
                        }
                    }
                }
                channels.push(Channel {
                    node: index,
                    property: Property::Weights(targets),
                    interpolation: Interpolation::Linear,
                    times: times.clone(),
                    values,
                });
            }
        }
    }
    for c in &channels {
        c.validate()
            .map_err(|e| bad(format!("animation stack '{}': {e}", stack.element.name)))?;
    }
    Ok(Clip {
        name: stack.element.name.to_string(),
        channels,
    })
}
