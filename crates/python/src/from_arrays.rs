//! Scenes from a host application's arrays and the skin dict both ways: joint world matrices
//! per frame (row-major 4 × 4, translation in column 3) and dense per-vertex weights.

use anim::glam::{Mat4, Vec3};
use anim::{
    Aabb, Joint, Mesh, MeshAnimation, SampledScene, SkeletalAnimation, Skeleton, Skin, Transform,
    VertexWeights,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::{frozen, shape, values, ArrayIn};
use crate::errors::{at, value_error};

const SOURCE: &str = "<arrays>";

/// The clip of `Scene.from_arrays`: frame-major points (`frames × vertices`).
pub(crate) struct Clip {
    /// Every frame's points, frame after frame.
    pub(crate) points: Vec<Vec3>,
    /// Number of frames.
    pub(crate) frames: usize,
    /// Number of vertices per frame.
    pub(crate) vertices: usize,
}

impl Clip {
    /// One copy of a host's `(frames, vertices, 3)` buffer (its shape ends in 3, so it casts
    /// whole).
    pub(crate) fn copied(positions: &ArrayIn<'_, f32>) -> PyResult<Clip> {
        let s = shape(positions, "positions", &[None, None, Some(3)])?;
        Ok(Clip {
            points: bytemuck::cast_slice(&values(positions)).to_vec(),
            frames: s[0],
            vertices: s[1],
        })
    }
}

/// The sampled scene of `Scene.from_arrays`.
pub(crate) fn sampled(
    clip: Clip,
    triangles: &ArrayIn<'_, i64>,
    fps: f32,
    skin: Option<&Bound<'_, PyDict>>,
    objects: Option<Vec<(String, usize, usize)>>,
    attributes: Vec<(String, Vec<f32>)>,
    rest: Option<&ArrayIn<'_, f32>>,
) -> PyResult<SampledScene> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(value_error(format!(
            "fps must be a positive number, got {fps}"
        )));
    }
    let Clip {
        points,
        frames,
        vertices,
    } = clip;
    if frames == 0 || vertices == 0 {
        return Err(value_error(format!(
            "positions must have at least one frame and one vertex, got shape {:?}",
            [frames, vertices, 3]
        )));
    }
    let rest: Vec<Vec3> = match rest {
        Some(r) => {
            shape(r, "rest", &[Some(vertices), Some(3)])?;
            let r: Vec<Vec3> = values(r).chunks_exact(3).map(Vec3::from_slice).collect();
            if !r.iter().all(|p| p.is_finite()) {
                return Err(value_error("rest holds a position that is not finite"));
            }
            r
        }
        None => points[..vertices].to_vec(),
    };
    let nt = shape(triangles, "triangles", &[None, Some(3)])?[0];
    let mut tris = Vec::with_capacity(nt);
    for (i, t) in values(triangles).chunks_exact(3).enumerate() {
        let mut tri = [0u32; 3];
        for (k, &v) in t.iter().enumerate() {
            if v < 0 || v as usize >= vertices {
                return Err(value_error(format!(
                    "triangles[{i}] refers to vertex {v}, but there are {vertices} vertices"
                )));
            }
            tri[k] = v as u32;
        }
        tris.push(tri);
    }
    let mut mesh = Mesh::new("arrays", points[..vertices].to_vec(), tris);
    for (name, values) in attributes {
        if values.len() != vertices {
            return Err(value_error(format!(
                "attributes[{name:?}] has {} values for {vertices} vertices",
                values.len()
            )));
        }
        mesh.attributes.insert(name, values);
    }
    let animation =
        MeshAnimation::new(mesh, fps, points).map_err(|e| value_error(at(SOURCE, e)))?;
    let mut scene = SampledScene::from_animation(animation);
    scene.objects[0].rest_bounds = Aabb::from_points(&rest);
    let mut object_parents = None;
    if let Some(skin) = skin {
        add_skin(&mut scene, skin)?;
        if let Some(p) = skin.get_item("object_parents")? {
            object_parents = Some(p.extract::<Vec<i64>>()?);
        }
    }
    if let Some(objects) = objects {
        split_objects(&mut scene, &objects, object_parents.as_deref(), &rest)?;
    }
    Ok(scene)
}

/// Splits the one object of `scene` into `objects` (`(name, start, stop)` vertex ranges
/// tiling the vertices in order). An object whose vertices have no skin weight is unskinned
/// (a simple object, SMEAR Eq. 1), carried by `object_parents[i]` when that is a joint.
/// `rest` holds every vertex at the rest pose.
fn split_objects(
    scene: &mut SampledScene,
    objects: &[(String, usize, usize)],
    object_parents: Option<&[i64]>,
    rest: &[Vec3],
) -> PyResult<()> {
    let whole = scene.objects.remove(0);
    let vertices = whole.animation.vertex_count();
    let mut next = 0;
    for (name, start, stop) in objects {
        if *start != next || stop < start || *stop > vertices {
            return Err(value_error(format!(
                "objects must tile the {vertices} vertices in order; {name:?} covers {start}..{stop}"
            )));
        }
        next = *stop;
    }
    if next != vertices {
        return Err(value_error(format!(
            "objects cover {next} of the {vertices} vertices"
        )));
    }
    if let Some(p) = object_parents {
        if p.len() != objects.len() {
            return Err(value_error(format!(
                "skin has {} object_parents for {} objects",
                p.len(),
                objects.len()
            )));
        }
    }
    let parent_of = |k: usize| {
        object_parents
            .and_then(|p| usize::try_from(p[k]).ok())
            .filter(|&j| j < scene.skeleton.len())
    };
    if let [(name, _, _)] = objects {
        // One object (a host's single mesh): the whole scene's, named, its frames moved
        // rather than copied.
        let mut animation = whole.animation;
        animation.mesh.name.clone_from(name);
        let skin = whole
            .skin
            .filter(|s| (0..vertices).any(|v| !s.weights.influences(v).0.is_empty()));
        let parent_joint = parent_of(0);
        scene.objects.push(anim::MeshObject {
            skin,
            parent_joint,
            rest_bounds: Aabb::from_points(rest),
            ..anim::MeshObject::new(0, name.clone(), animation)
        });
        return Ok(());
    }
    let mut triangles: Vec<Vec<[u32; 3]>> = vec![Vec::new(); objects.len()];
    for (i, t) in whole.animation.mesh.triangles.iter().enumerate() {
        let k = objects.partition_point(|o| o.2 <= t[0] as usize);
        let (_, a, b) = &objects[k];
        if !t.iter().all(|&v| (*a..*b).contains(&(v as usize))) {
            return Err(value_error(format!(
                "triangles[{i}] joins vertices of two objects"
            )));
        }
        triangles[k].push(t.map(|v| v - *a as u32));
    }
    let frames = whole.animation.frame_count();
    for (k, ((name, a, b), tris)) in objects.iter().zip(triangles).enumerate() {
        let mut positions = Vec::with_capacity(frames * (b - a));
        for f in 0..frames {
            positions.extend_from_slice(&whole.animation.frame(f)[*a..*b]);
        }
        let mut mesh = Mesh::new(name.clone(), positions[..b - a].to_vec(), tris);
        for (attribute, values) in &whole.animation.mesh.attributes {
            mesh.attributes
                .insert(attribute.clone(), values[*a..*b].to_vec());
        }
        let animation = MeshAnimation::new(mesh, whole.animation.fps, positions)
            .map_err(|e| value_error(at(SOURCE, e)))?;
        let skin = whole.skin.as_ref().and_then(|s| {
            let rows: Vec<Vec<(u32, f32)>> = (*a..*b)
                .map(|v| {
                    let (j, w) = s.weights.influences(v);
                    j.iter().copied().zip(w.iter().copied()).collect()
                })
                .collect();
            rows.iter().any(|r| !r.is_empty()).then(|| Skin {
                joints: s.joints.clone(),
                inverse_bind: s.inverse_bind.clone(),
                weights: VertexWeights::from_influences(rows),
            })
        });
        let parent_joint = parent_of(k);
        scene.objects.push(anim::MeshObject {
            skin,
            parent_joint,
            rest_bounds: Aabb::from_points(&rest[*a..*b]),
            ..anim::MeshObject::new(k, name.clone(), animation)
        });
    }
    Ok(())
}

fn item<'py>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<Bound<'py, PyAny>> {
    d.get_item(key)?.ok_or_else(|| {
        value_error(format!(
            "skin has no \"{key}\" (needs parents, matrices, weights)"
        ))
    })
}

fn add_skin(scene: &mut SampledScene, skin: &Bound<'_, PyDict>) -> PyResult<()> {
    let (frames, vertices) = (scene.frame_count, scene.vertex_count());
    let parents: ArrayIn<'_, i64> = item(skin, "parents")?.extract()?;
    let joints = shape(&parents, "skin[\"parents\"]", &[None])?[0];
    if joints == 0 {
        return Err(value_error("skin[\"parents\"] is empty"));
    }
    let names: Vec<String> = match skin.get_item("joint_names")? {
        Some(n) => n.extract()?,
        None => (0..joints).map(|k| format!("joint_{k}")).collect(),
    };
    if names.len() != joints {
        return Err(value_error(format!(
            "skin has {} joint_names for {joints} parents",
            names.len()
        )));
    }
    let matrices: ArrayIn<'_, f32> = item(skin, "matrices")?.extract()?;
    shape(
        &matrices,
        "skin[\"matrices\"]",
        &[Some(frames), Some(joints), Some(4), Some(4)],
    )?;
    let world: Vec<Mat4> = values(&matrices)
        .chunks_exact(16)
        .map(|m| Mat4::from_cols_slice(m).transpose())
        .collect();
    let weights: ArrayIn<'_, f32> = item(skin, "weights")?.extract()?;
    shape(
        &weights,
        "skin[\"weights\"]",
        &[Some(vertices), Some(joints)],
    )?;

    let parent_of: Vec<Option<usize>> = values(&parents)
        .iter()
        .enumerate()
        .map(|(k, &p)| match p {
            -1 => Ok(None),
            p if p >= 0 && (p as usize) < k => Ok(Some(p as usize)),
            p => Err(value_error(format!(
                "skin[\"parents\"][{k}] = {p}: a parent must be -1 or an earlier joint"
            ))),
        })
        .collect::<PyResult<_>>()?;
    let bind_world = &world[..joints];
    let skeleton = Skeleton {
        joints: (0..joints)
            .map(|k| Joint {
                name: names[k].clone(),
                parent: parent_of[k],
                bind_local: Transform::from_matrix(match parent_of[k] {
                    Some(p) => bind_world[p].inverse() * bind_world[k],
                    None => bind_world[k],
                }),
            })
            .collect(),
    };
    let w = values(&weights);
    // Each row's nonzero weights, read in place (no list per vertex).
    let influences = w.chunks_exact(joints).map(|row| {
        row.iter()
            .enumerate()
            .filter(|(_, x)| **x != 0.0)
            .map(|(k, &x)| (k as u32, x))
    });
    let skin = Skin {
        joints: (0..joints).collect(),
        inverse_bind: bind_world.iter().map(|m| m.inverse()).collect(),
        weights: VertexWeights::from_influences(influences),
    };
    skin.validate(vertices, joints)
        .map_err(|e| value_error(at(SOURCE, e)))?;
    let skeletal =
        SkeletalAnimation::new(scene.fps, joints, world).map_err(|e| value_error(at(SOURCE, e)))?;
    scene.bones = skeletal.bones(&skeleton);
    scene.joint_nodes = (1..=joints).collect();
    scene.skeletal = Some(skeletal);
    scene.skeleton = skeleton;
    scene.objects[0].skin = Some(skin);
    Ok(())
}

/// `Scene.skin`: the skeleton, joint world matrices and dense weights of a sampled scene
/// (objects merged in order), or `None` when nothing is skinned.
pub(crate) fn skin_dict<'py>(
    py: Python<'py>,
    scene: &SampledScene,
) -> PyResult<Option<Bound<'py, PyDict>>> {
    let Some(skeletal) = &scene.skeletal else {
        return Ok(None);
    };
    let joints = scene.skeleton.len();
    let frames = skeletal.frame_count();
    let mut matrices = Vec::with_capacity(frames * joints * 16);
    for f in 0..frames {
        for m in skeletal.frame(f) {
            matrices.extend_from_slice(&m.transpose().to_cols_array());
        }
    }
    let vertices = scene.vertex_count();
    let mut weights = vec![0f32; vertices * joints];
    let mut base = 0;
    for o in &scene.objects {
        if let Some(skin) = &o.skin {
            for v in 0..o.animation.vertex_count() {
                let (slots, w) = skin.weights.influences(v);
                for (&s, &x) in slots.iter().zip(w) {
                    weights[(base + v) * joints + skin.joints[s as usize]] += x;
                }
            }
        }
        base += o.animation.vertex_count();
    }
    let parents: Vec<i32> = scene
        .skeleton
        .joints
        .iter()
        .map(|j| j.parent.map_or(-1, |p| p as i32))
        .collect();
    let d = PyDict::new(py);
    d.set_item(
        "joint_names",
        scene
            .skeleton
            .joints
            .iter()
            .map(|j| j.name.clone())
            .collect::<Vec<_>>(),
    )?;
    d.set_item("parents", frozen(py, &[joints], parents)?)?;
    d.set_item("matrices", frozen(py, &[frames, joints, 4, 4], matrices)?)?;
    d.set_item("weights", frozen(py, &[vertices, joints], weights)?)?;
    let object_parents: Vec<i64> = scene
        .objects
        .iter()
        .map(|o| o.parent_joint.map_or(-1, |j| j as i64))
        .collect();
    d.set_item("object_parents", object_parents)?;
    Ok(Some(d))
}
