//! A character taken from an `anim::Scene` (skinned glTF or BVH skeleton, in its rest pose or
//! a clip's frame) and a synthesized [`Motion`] put back into a scene as its only clip, ready
//! for `tkio`'s glTF and BVH writers.

use std::fmt;
use std::str::FromStr;

use anim::{Channel, Clip, Interpolation, Property, Scene, SkeletalAnimation, Transform};
use glam::Mat4;

use super::camera::ActionCamera;
use super::error::AnimateError;
use super::{Character, Motion};

/// Name of the clip [`Motion::to_scene`] writes.
pub const CLIP_NAME: &str = "loa";

/// The pose every frame of the synthesis starts from.
#[derive(Debug, Clone, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(into = "String", try_from = "String")]
pub enum InitialPose {
    /// The skeleton's rest (bind) pose.
    #[default]
    Rest,
    /// Frame `frame` (at the line's fps) of the clip named `clip`.
    Clip {
        /// Clip name.
        clip: String,
        /// Frame number, 0 = the clip's first key.
        frame: usize,
    },
}

impl FromStr for InitialPose {
    type Err = AnimateError;
    /// `rest` or `CLIP@FRAME`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.trim() == "rest" {
            return Ok(InitialPose::Rest);
        }
        let bad = |expected: String| AnimateError::BadPose {
            pose: s.to_string(),
            expected,
        };
        let (clip, frame) = s
            .rsplit_once('@')
            .ok_or_else(|| bad("rest or CLIP@FRAME".into()))?;
        let frame = frame
            .trim()
            .parse()
            .map_err(|_| bad("FRAME must be a frame number".into()))?;
        Ok(InitialPose::Clip {
            clip: clip.to_string(),
            frame,
        })
    }
}

impl fmt::Display for InitialPose {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InitialPose::Rest => write!(f, "rest"),
            InitialPose::Clip { clip, frame } => write!(f, "{clip}@{frame}"),
        }
    }
}

impl From<InitialPose> for String {
    fn from(p: InitialPose) -> String {
        p.to_string()
    }
}

impl TryFrom<String> for InitialPose {
    type Error = AnimateError;
    fn try_from(s: String) -> Result<Self, Self::Error> {
        s.parse()
    }
}

impl Character {
    /// The character of a scene: its skin joints (or BVH skeleton) in `pose`, clips sampled
    /// at `fps` frames per second.
    ///
    /// A leaf joint without a rest orientation (a BVH joint, whose rest rotation is the
    /// identity) has no local +Y of its own to put its bone tip on (SPEC bones): its
    /// `End Site` (a `<joint>_end` child node, see `tkio::bvh`) gives the bone's axis instead,
    /// so that e.g. a shin ends at the ankle rather than pointing up into the thigh. The tip
    /// stays at the parent bone's length, as for any leaf.
    ///
    /// # Errors
    /// [`AnimateError::EmptySkeleton`] without joints, [`AnimateError::BadPose`] for an
    /// unknown clip or a frame past its end, [`AnimateError::Scene`] when the clip cannot be
    /// sampled.
    pub fn from_scene(
        scene: &Scene,
        pose: &InitialPose,
        fps: f64,
    ) -> Result<Character, AnimateError> {
        let (skeleton, nodes) = scene.skeleton();
        if skeleton.is_empty() {
            return Err(AnimateError::EmptySkeleton);
        }
        let axes = end_site_axes(scene, &skeleton, &nodes);
        let InitialPose::Clip { clip, frame } = pose else {
            let rest: Vec<Transform> = skeleton.joints.iter().map(|j| j.bind_local).collect();
            return Character::with_axes(&skeleton, &rest, axes);
        };
        let bad = |expected: String| AnimateError::BadPose {
            pose: pose.to_string(),
            expected,
        };
        let index = scene
            .find_clip(clip)
            .map_err(|e| bad(format!("a clip of the file ({e})")))?;
        let sampled = anim::sample(
            scene,
            &anim::SampleOptions {
                fps: fps as f32,
                clip: Some(index),
                meshes: Vec::new(),
            },
        )
        .map_err(|source| AnimateError::Scene { source })?;
        let Some(skeletal) = sampled.skeletal else {
            return Err(bad("a clip that moves the skeleton".into()));
        };
        if *frame >= skeletal.frame_count() {
            return Err(bad(format!(
                "a frame below {} (clip '{clip}')",
                skeletal.frame_count()
            )));
        }
        let local = super::local_pose(&skeleton, skeletal.frame(*frame))?;
        Character::with_axes(&skeleton, &local, axes)
    }
}

/// Per joint of `skeleton` (the scene's, at `nodes`, see [`Scene::skeleton`]): the local bone axis of a
/// leaf joint without rest orientation, from its `End Site` node — a `<joint>_end` child that
/// is no joint and carries nothing (no mesh, camera or children).
fn end_site_axes(
    scene: &Scene,
    skeleton: &anim::Skeleton,
    nodes: &[usize],
) -> Vec<Option<glam::DVec3>> {
    let joint_node: std::collections::HashSet<usize> = nodes.iter().copied().collect();
    skeleton
        .joints
        .iter()
        .zip(nodes)
        .map(|(joint, &node)| {
            if joint.bind_local.rotation != glam::Quat::IDENTITY {
                return None;
            }
            let name = format!("{}_end", joint.name);
            let site = scene.nodes.get(node)?.children.iter().find_map(|&c| {
                let n = scene.nodes.get(c)?;
                let bare = n.mesh.is_none() && n.camera.is_none() && n.children.is_empty();
                (bare && !joint_node.contains(&c) && n.name == name).then_some(n)
            })?;
            let t = site.transform.translation.as_dvec3();
            (t.length() > 0.0).then_some(t)
        })
        .collect()
}

impl ActionCamera {
    /// The action camera of the glTF camera node (or camera) named `name` in `scene`, at its
    /// first frame, focused on `character`'s centre (see [`ActionCamera::from_scene_camera`]);
    /// also returns the sampled scene camera (for previews through it).
    ///
    /// # Errors
    /// [`AnimateError::UnknownCamera`] listing the scene's cameras, or [`AnimateError::Scene`]
    /// when the scene cannot be sampled.
    pub fn from_scene(
        scene: &Scene,
        name: &str,
        character: &Character,
        fps: f64,
    ) -> Result<(ActionCamera, anim::Camera), AnimateError> {
        let sampled = anim::sample(
            scene,
            &anim::SampleOptions {
                fps: fps as f32,
                clip: None,
                meshes: Vec::new(),
            },
        )
        .map_err(|source| AnimateError::Scene { source })?;
        let names = || {
            let all: Vec<&str> = sampled.cameras.iter().map(|c| c.name.as_str()).collect();
            if all.is_empty() {
                "the file has none".to_string()
            } else {
                all.join(", ")
            }
        };
        let Some(camera) = sampled.cameras.iter().find(|c| c.name == name) else {
            return Err(AnimateError::UnknownCamera {
                name: name.to_string(),
                cameras: names(),
            });
        };
        let (min, max) = character.bounds();
        let world = camera.world.first().copied().unwrap_or_default();
        let action = ActionCamera::from_scene_camera(&camera.projection, &world, 0.5 * (min + max));
        Ok((action, camera.clone()))
    }
}

impl Motion {
    /// The motion as a skeletal animation of `skeleton` (the character's, same joint order),
    /// e.g. for `tkio::bvh::write`.
    ///
    /// # Errors
    /// [`AnimateError::Scene`] when the joint count does not match.
    pub fn skeletal_animation(
        &self,
        skeleton: &anim::Skeleton,
    ) -> Result<SkeletalAnimation, AnimateError> {
        SkeletalAnimation::new(self.fps as f32, skeleton.len(), self.world_matrices())
            .map_err(|source| AnimateError::Scene { source })
    }

    /// `scene` (the character's source) with its clips replaced by one clip [`CLIP_NAME`]
    /// holding the motion: translation, rotation and scale of every joint node, LINEAR, one
    /// key per frame. Meshes, skins and materials are kept, so the result is the skinned
    /// character animated by the line.
    pub fn to_scene(&self, scene: &Scene) -> Scene {
        let (skeleton, joint_nodes) = scene.skeleton();
        let world = self.world_matrices();
        let n = skeleton.len();
        let frames = if n == self.joints { self.frames() } else { 0 };
        // Rest world matrices of every node (for joints whose parent node is not a joint).
        let order = scene.topological_order();
        let (mut locals, mut weights, mut rest_world) = (Vec::new(), Vec::new(), Vec::new());
        scene.pose_at(None, 0.0, &mut locals, &mut weights);
        scene.world_matrices(&order, &locals, &mut rest_world);
        let fps = self.fps as f32;
        let times: Vec<f32> = (0..frames).map(|f| f as f32 / fps).collect();
        let mut channels = Vec::with_capacity(3 * n);
        for (k, j) in skeleton.joints.iter().enumerate() {
            let node = joint_nodes[k];
            let (mut t, mut r, mut s) = (Vec::new(), Vec::new(), Vec::new());
            for f in 0..frames {
                let parent = match j.parent {
                    Some(p) => world[f * n + p],
                    None => scene.nodes[node]
                        .parent
                        .map_or(Mat4::IDENTITY, |p| rest_world[p]),
                };
                let local = Transform::from_matrix(parent.inverse() * world[f * n + k]);
                t.extend_from_slice(&local.translation.to_array());
                r.extend_from_slice(&local.rotation.normalize().to_array());
                s.extend_from_slice(&local.scale.to_array());
            }
            for (property, values) in [
                (Property::Translation, t),
                (Property::Rotation, r),
                (Property::Scale, s),
            ] {
                channels.push(Channel {
                    node,
                    property,
                    interpolation: Interpolation::Linear,
                    times: times.clone(),
                    values,
                });
            }
        }
        let mut out = scene.clone();
        out.clips = vec![Clip {
            name: CLIP_NAME.to_string(),
            channels,
        }];
        out
    }
}
