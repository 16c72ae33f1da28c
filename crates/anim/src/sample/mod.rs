//! Sampling a scene clip at a fixed frame rate into point caches and skeletal animation.

use glam::{Mat4, Vec3};
use rayon::prelude::*;

use crate::{
    clip::frame_count,
    rest::{rest_bounds, rest_world},
    skin_positions, Aabb, AnimError, Bone, Camera, Mesh, MeshAnimation, Result, Scene,
    SkeletalAnimation, Skeleton, Skin, Transform, DEFAULT_FPS,
};

/// What to sample.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleOptions {
    /// Frames per second (default [`DEFAULT_FPS`]).
    pub fps: f32,
    /// Clip index; `None` samples the first clip, or the rest pose when there is none.
    pub clip: Option<usize>,
    /// Keep only the mesh objects whose name is listed (all when empty).
    pub meshes: Vec<String>,
}

impl Default for SampleOptions {
    fn default() -> Self {
        SampleOptions {
            fps: DEFAULT_FPS,
            clip: None,
            meshes: Vec::new(),
        }
    }
}

/// One mesh-drawing node of a sampled scene.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshObject {
    /// Node index in the scene.
    pub node: usize,
    /// Display name.
    pub name: String,
    /// World-space positions per frame.
    pub animation: MeshAnimation,
    /// Binding to [`SampledScene::skeleton`] when the node is skinned.
    pub skin: Option<Skin>,
    /// Nearest ancestor joint of an unskinned object (a rigid prop carried by a bone).
    pub parent_joint: Option<usize>,
    /// World-space bounding box of the object at its rest pose, the mesh as modelled rather
    /// than as the clip deforms it (`docs/smear-units.md`): a scene's base mesh skinned with
    /// its joints at their own transforms, a point cache's rest mesh, else the first frame.
    pub rest_bounds: Aabb,
}

impl MeshObject {
    /// An object whose rest pose is `animation`'s mesh positions when it holds one per
    /// vertex (a point cache read onto its rest mesh), else its first frame.
    pub fn new(node: usize, name: impl Into<String>, animation: MeshAnimation) -> MeshObject {
        let rest = if animation.mesh.positions.len() == animation.vertex_count() {
            &animation.mesh.positions[..]
        } else {
            animation.frame(0)
        };
        MeshObject {
            node,
            name: name.into(),
            rest_bounds: Aabb::from_points(rest),
            animation,
            skin: None,
            parent_joint: None,
        }
    }
}

/// A clip sampled at a fixed rate.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledScene {
    /// Frames per second.
    pub fps: f32,
    /// Time of frame 0 (the clip's first key).
    pub start_time: f32,
    /// Number of frames.
    pub frame_count: usize,
    /// Mesh objects in parent-first node order.
    pub objects: Vec<MeshObject>,
    /// Joints of all skins (empty when nothing is skinned).
    pub skeleton: Skeleton,
    /// Node of every skeleton joint.
    pub joint_nodes: Vec<usize>,
    /// Joint world matrices per frame (`None` when there is no joint).
    pub skeletal: Option<SkeletalAnimation>,
    /// Bones per frame, frame-major (`frames × joints`).
    pub bones: Vec<Bone>,
    /// Cameras.
    pub cameras: Vec<Camera>,
    /// World matrix of every node per frame, frame-major (`frames × nodes`).
    pub node_world: Vec<Mat4>,
}

impl SampledScene {
    /// A scene holding one point cache as its only object (no skeleton, no camera).
    pub fn from_animation(animation: MeshAnimation) -> SampledScene {
        let name = animation.mesh.name.clone();
        SampledScene {
            fps: animation.fps,
            start_time: animation.start_time,
            frame_count: animation.frame_count(),
            objects: vec![MeshObject::new(0, name, animation)],
            skeleton: Skeleton::default(),
            joint_nodes: Vec::new(),
            skeletal: None,
            bones: Vec::new(),
            cameras: Vec::new(),
            node_world: Vec::new(),
        }
    }

    /// What a clip of `frames` frames × `vertices` vertices holds once sampled and merged
    /// ([`SampledScene::merged`] checks it): the samples, the merged copy and the file a job
    /// writes it to. A server reserves it before sampling a clip of that size.
    pub fn merged_memory(frames: usize, vertices: usize) -> crate::budget::JobMemory {
        crate::budget::JobMemory::new().positions(
            "copies of the clip (sampled, merged, written)",
            frames,
            vertices,
            3,
        )
    }

    /// All objects merged into one cache (vertex order = object order).
    ///
    /// # Errors
    /// [`AnimError::OverBudget`] when the samples, the merged copy and a file written from
    /// it would be over [`crate::budget::DEFAULT_MAX_JOB_BYTES`]; those of
    /// [`MeshAnimation::concat`].
    pub fn merged(&self, name: &str) -> Result<MeshAnimation> {
        SampledScene::merged_memory(self.frame_count, self.vertex_count())
            .check("lower --fps or pick a shorter clip")?;
        if self.objects.len() == 1 {
            let mut a = self.objects[0].animation.clone();
            a.mesh.name = name.to_string();
            return Ok(a);
        }
        let parts: Vec<MeshAnimation> = self.objects.iter().map(|o| o.animation.clone()).collect();
        MeshAnimation::concat(name, &parts)
    }

    /// Total vertices over all objects.
    pub fn vertex_count(&self) -> usize {
        self.objects
            .iter()
            .map(|o| o.animation.vertex_count())
            .sum()
    }

    /// The bounding-box diagonal of every object at its rest pose
    /// ([`MeshObject::rest_bounds`]), 0 without objects: one *size* unit of a smear style
    /// (`docs/smear-units.md`).
    pub fn rest_diagonal(&self) -> f32 {
        self.objects
            .iter()
            .map(|o| o.rest_bounds)
            .reduce(Aabb::union)
            .map_or(0.0, |b| b.diagonal())
    }

    /// Bones of frame `f`.
    pub fn bones_at(&self, f: usize) -> &[Bone] {
        let n = self.skeleton.len();
        &self.bones[f * n..(f + 1) * n]
    }
}

/// Samples a clip of `scene` at `options.fps` from its first to its last key (inclusive),
/// evaluating node animation, morph weights and linear blend skinning. Parallel over frames.
///
/// # Errors
/// When the scene is invalid, the clip index is out of range, or a mesh filter matches
/// nothing.
pub fn sample(scene: &Scene, options: &SampleOptions) -> Result<SampledScene> {
    sample_with(scene, options, &mut [])
}

/// [`sample`], consuming the scene: the geometry of a mesh that one node draws (triangles,
/// texture coordinates, colours, attributes) moves into its object instead of being copied.
///
/// # Errors
/// As [`sample`].
pub fn sample_owned(mut scene: Scene, options: &SampleOptions) -> Result<SampledScene> {
    scene.validate()?;
    let mut uses = vec![0usize; scene.meshes.len()];
    for m in scene.nodes.iter().filter_map(|n| n.mesh) {
        if let Some(u) = uses.get_mut(m) {
            *u += 1;
        }
    }
    // Sampling still reads the name and rest positions: they stay in the scene.
    let mut spare: Vec<Option<Mesh>> = scene
        .meshes
        .iter_mut()
        .zip(&uses)
        .map(|(sm, &u)| {
            (u == 1).then(|| {
                let mut geometry = std::mem::take(&mut sm.mesh);
                sm.mesh.name = geometry.name.clone();
                sm.mesh.positions = std::mem::take(&mut geometry.positions);
                geometry
            })
        })
        .collect();
    sample_with(&scene, options, &mut spare)
}

/// [`sample`] taking each object's geometry from `spare` (by mesh index) where it holds one.
fn sample_with(
    scene: &Scene,
    options: &SampleOptions,
    spare: &mut [Option<Mesh>],
) -> Result<SampledScene> {
    scene.validate()?;
    let (clip, start, frames) = clip_frames(scene, options)?;
    let fps = options.fps;
    let cache_values = frames.saturating_mul(
        scene
            .meshes
            .iter()
            .map(|m| m.mesh.vertex_count())
            .sum::<usize>()
            .max(1),
    );
    check_sampling(
        clip.map_or(0.0, |c| c.duration()),
        fps,
        frames,
        cache_values,
    )?;
    let order = scene.topological_order();
    let nn = scene.nodes.len();

    let poses = pose_frames(scene, clip, start, fps, frames, &order);
    let mut node_world = Vec::with_capacity(frames * nn);
    for (w, _) in &poses {
        node_world.extend_from_slice(w);
    }

    let (skeleton, joint_nodes) = scene.skeleton();
    let mut joint_of_node = vec![None; nn];
    for (k, &n) in joint_nodes.iter().enumerate() {
        joint_of_node[n] = Some(k);
    }
    let skeletal = if skeleton.is_empty() {
        None
    } else {
        let mut w = Vec::with_capacity(frames * joint_nodes.len());
        for (world, _) in &poses {
            w.extend(joint_nodes.iter().map(|&n| world[n]));
        }
        let mut s = SkeletalAnimation::new(fps, joint_nodes.len(), w)?;
        s.start_time = start;
        Some(s)
    };
    let bones = skeletal
        .as_ref()
        .map(|s| s.bones(&skeleton))
        .unwrap_or_default();

    let rest = rest_world(scene, &order, clip, start);
    let mut objects = Vec::new();
    for node in scene.mesh_nodes() {
        let name = scene.object_name(node);
        if !options.meshes.is_empty() && !options.meshes.contains(&name) {
            continue;
        }
        let geometry = scene.nodes[node]
            .mesh
            .and_then(|m| spare.get_mut(m))
            .and_then(Option::take);
        objects.push(sample_object(
            scene,
            node,
            name,
            &poses,
            &joint_of_node,
            fps,
            start,
            geometry,
            rest_bounds(scene, node, &rest),
        )?);
    }
    if !options.meshes.is_empty() && objects.is_empty() {
        return Err(AnimError::NotFound {
            kind: "mesh",
            name: options.meshes.join(","),
            available: scene
                .mesh_nodes()
                .iter()
                .map(|&n| scene.object_name(n))
                .collect::<Vec<_>>()
                .join(", "),
        });
    }

    let cameras = (0..nn)
        .filter_map(|n| scene.nodes[n].camera.map(|c| (n, c)))
        .map(|(n, c)| Camera {
            name: if scene.nodes[n].name.is_empty() {
                scene.cameras[c].name.clone()
            } else {
                scene.nodes[n].name.clone()
            },
            projection: scene.cameras[c].projection,
            world: poses.iter().map(|(w, _)| w[n]).collect(),
        })
        .collect();

    Ok(SampledScene {
        fps,
        start_time: start,
        frame_count: frames,
        objects,
        skeleton,
        joint_nodes,
        skeletal,
        bones,
        cameras,
        node_world,
    })
}

/// The clip `options` pick, its start time and its frame count at `options.fps`.
fn clip_frames<'s>(
    scene: &'s Scene,
    options: &SampleOptions,
) -> Result<(Option<&'s crate::Clip>, f32, usize)> {
    if !(options.fps.is_finite() && options.fps > 0.0) {
        return Err(AnimError::Invalid(format!(
            "frame rate must be positive, got {}",
            options.fps
        )));
    }
    let clip = match options.clip {
        Some(i) => Some(scene.clips.get(i).ok_or_else(|| {
            AnimError::NotFound {
                kind: "clip",
                name: i.to_string(),
                available: scene
                    .clips
                    .iter()
                    .map(|c| c.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            }
        })?),
        None => scene.clips.first(),
    };
    let (start, frames) = match clip {
        Some(c) => (c.start(), frame_count(c.duration(), options.fps)),
        None => (0.0, 1),
    };
    Ok((clip, start, frames))
}

/// The frame and point budgets of sampling `duration` seconds at `fps` into `frames` frames of
/// `points` positions in all, checked before the poses are allocated.
fn check_sampling(duration: f32, fps: f32, frames: usize, points: usize) -> Result<()> {
    use crate::budget::{check_budget, DEFAULT_MAX_FRAMES};
    let hint = format!("the clip lasts {duration:.1} s: lower --fps or pick a shorter clip");
    let points_hint = format!("{hint} (or raise {})", crate::budget::MAX_JOB_BYTES_ENV);
    check_budget(
        &format!("frames at {fps} fps"),
        frames as u64,
        DEFAULT_MAX_FRAMES,
        &hint,
    )
    .and_then(|()| {
        check_budget(
            "frames × vertices",
            points as u64,
            crate::budget::max_points(),
            &points_hint,
        )
    })
    .map_err(AnimError::OverBudget)
}

mod morph;
mod poses;
mod weights;

pub use poses::sample_node_world;
pub use weights::sample_morph;

use morph::{morphed, rigid_batch, MORPH_BATCH};
use poses::pose_frames;

/// Per frame: every node's world matrix and every node's morph weights.
type Pose = (Vec<Mat4>, Vec<Vec<f32>>);

fn sample_object(
    scene: &Scene,
    node: usize,
    name: String,
    poses: &[Pose],
    joint_of_node: &[Option<usize>],
    fps: f32,
    start: f32,
    geometry: Option<Mesh>,
    rest_bounds: Aabb,
) -> Result<MeshObject> {
    let n = &scene.nodes[node];
    let sm = &scene.meshes[n.mesh.expect("mesh node")];
    let rest = &sm.mesh.positions;
    let nv = rest.len();
    let skin = match (n.skin, &sm.joint_weights) {
        (Some(s), Some(w)) => {
            let def = &scene.skins[s];
            Some(Skin {
                joints: def
                    .joints
                    .iter()
                    .map(|&j| joint_of_node[j].expect("skin joints are skeleton joints"))
                    .collect(),
                inverse_bind: def.inverse_bind.clone(),
                weights: w.clone(),
            })
        }
        _ => None,
    };
    let skin_nodes: Vec<usize> = n
        .skin
        .map(|s| scene.skins[s].joints.clone())
        .unwrap_or_default();
    let mut parent_joint = None;
    let mut p = n.parent;
    while let Some(q) = p {
        if let Some(j) = joint_of_node[q] {
            parent_joint = Some(j);
            break;
        }
        p = scene.nodes[q].parent;
    }

    // Zeroed by the allocator (fresh pages for a large cache, none touched here): the skinning
    // workers write every frame and so fault its pages in on all cores, instead of this
    // thread clearing the whole cache first.
    // Within the point budget the allocation can still fail (a smaller machine, a process
    // limit): said in one line instead of bytemuck's panic.
    let mut positions: Vec<Vec3> =
        bytemuck::allocation::try_zeroed_vec(poses.len() * nv).map_err(|()| {
            AnimError::Invalid(format!(
                "{} frames × {nv} vertices ({:.1} GB) could not be allocated (the memory of this \
                 machine or process): lower --fps or pick a shorter clip",
                poses.len(),
                (poses.len() * nv * std::mem::size_of::<Vec3>()) as f64 / 1e9
            ))
        })?;
    // Each frame is checked for non-finite positions while it is still in cache, instead of
    // a second pass over the whole buffer in `MeshAnimation::new`.
    let finite = if skin.is_none() {
        // Unskinned: frames in batches, so that each block of the morph targets is read once
        // per batch rather than once per frame (the same sums in the same order).
        let batch = (poses.len() / (4 * rayon::current_num_threads().max(1))).clamp(1, MORPH_BATCH);
        positions
            .par_chunks_mut(nv.max(1) * batch)
            .zip(poses.par_chunks(batch))
            .map_init(Vec::new, |scratch, (out, frames)| {
                rigid_batch(rest, &sm.morph_targets, node, frames, out, scratch)
            })
            .all(|ok| ok)
    } else {
        positions
            .par_chunks_mut(nv.max(1))
            .zip(poses.par_iter())
            .map_init(
                || (Vec::new(), Vec::new()),
                |(scratch, mats): &mut (Vec<Vec3>, Vec<Mat4>), (out, (world, weights))| {
                    let source = morphed(rest, &sm.morph_targets, &weights[node], 0..nv, scratch);
                    if let (Some(s), Some(w)) = (&skin, &sm.joint_weights) {
                        mats.clear();
                        mats.extend(
                            skin_nodes
                                .iter()
                                .zip(&s.inverse_bind)
                                .map(|(&j, ib)| world[j] * *ib),
                        );
                        skin_positions(w, mats, source, out);
                    }
                    out.iter().all(|p| p.is_finite())
                },
            )
            .all(|ok| ok)
    };
    if !finite {
        return Err(AnimError::NonFinite {
            what: format!("point cache of '{name}'"),
        });
    }
    // Everything but the positions (which become frame 0's), moved when the caller owns it.
    let mut mesh = geometry.unwrap_or_else(|| {
        let m = &sm.mesh;
        Mesh {
            name: String::new(),
            positions: Vec::new(),
            triangles: m.triangles.clone(),
            polygons: m.polygons.clone(),
            normals: None,
            uvs: m.uvs.clone(),
            extra_uvs: m.extra_uvs.clone(),
            colors: m.colors.clone(),
            attributes: m.attributes.clone(),
        }
    });
    mesh.name = name.clone();
    mesh.normals = None; // normals of the bind pose are wrong once deformed
    mesh.positions = positions[..nv.min(positions.len())].to_vec();
    let mut animation = MeshAnimation::from_finite(mesh, fps, positions);
    animation.start_time = start;
    Ok(MeshObject {
        node,
        name,
        animation,
        skin,
        parent_joint,
        rest_bounds,
    })
}

/// Local transform of a node at the scene's rest pose, for writers.
pub fn rest_transform(scene: &Scene, node: usize) -> Transform {
    scene.nodes[node].transform
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Node, SceneMesh};

    /// One mesh node scaled by `scale` whose only vertex lies at x = 3e38 (finite data).
    fn far_vertex(scale: f32) -> Scene {
        Scene {
            nodes: vec![Node {
                mesh: Some(0),
                transform: Transform {
                    scale: Vec3::splat(scale),
                    ..Transform::default()
                },
                ..Node::default()
            }],
            meshes: vec![SceneMesh {
                mesh: Mesh {
                    positions: vec![Vec3::new(3e38, 0.0, 0.0)],
                    ..Mesh::default()
                },
                ..SceneMesh::default()
            }],
            ..Scene::default()
        }
    }

    #[test]
    fn sampled_positions_that_overflow_are_an_error() {
        let ok = sample(&far_vertex(1.0), &SampleOptions::default()).unwrap();
        assert_eq!(
            ok.objects[0].animation.frame(0),
            &[Vec3::new(3e38, 0.0, 0.0)]
        );
        // Finite input, infinite world position (3e38 × 10): checked per frame while sampling.
        let err = sample(&far_vertex(10.0), &SampleOptions::default()).unwrap_err();
        assert!(matches!(err, AnimError::NonFinite { .. }), "{err}");
    }

    /// Consuming the scene gives the same sampled scene: geometry moved for a mesh drawn
    /// once, copied for a mesh two nodes draw, the object names unchanged.
    #[test]
    fn owned_sampling_equals_borrowed_sampling() {
        let mut scene = far_vertex(1.0);
        let m = &mut scene.meshes[0].mesh;
        m.name = "tri".into();
        m.positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        m.triangles = vec![[0, 1, 2]];
        m.uvs = Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        let opts = SampleOptions::default();
        let want = sample(&scene, &opts).unwrap();
        assert_eq!(sample_owned(scene.clone(), &opts).unwrap(), want);
        assert_eq!(want.objects[0].name, "tri");
        assert_eq!(want.objects[0].animation.mesh.triangles, [[0, 1, 2]]);
        scene.nodes.push(scene.nodes[0].clone());
        let twice = sample(&scene, &opts).unwrap();
        assert_eq!(twice.objects.len(), 2);
        assert_eq!(sample_owned(scene, &opts).unwrap(), twice);
    }
}
