//! Flipbooks (several parts with the same frames, some with per-frame topology) as glTF
//! scenes and USD stages: the layouts `save` writes for [`Output::Flipbook`] and
//! [`Output::MotionLines`](crate::Output::MotionLines).
//!
//! [`Output::Flipbook`]: crate::Output::Flipbook

use anim::glam::Vec3;
use anim::{Channel, Clip, Flipbook, FlipbookPart, Mesh, MeshAnimation, Node, Scene, SceneMesh};

use crate::usda::{UsdMesh, UsdStage};

/// The mesh part `part` shows at frame `f` (`None` when it shows nothing), named
/// `<part>_fNNNN`: a point cache's frame with its UVs and that frame's colours, or the
/// frame's own mesh.
fn part_mesh(part: &FlipbookPart, f: usize) -> Option<Mesh> {
    match part {
        FlipbookPart::Animation {
            animation: a,
            colors,
        } => {
            let n = a.vertex_count();
            let mut m = Mesh::new(
                format!("{}_f{:04}", a.mesh.name, f + 1),
                a.frame(f).to_vec(),
                a.mesh.triangles.clone(),
            );
            m.uvs = a.mesh.uvs.clone();
            m.extra_uvs = a.mesh.extra_uvs.clone();
            m.colors = colors.as_ref().map(|c| c[f * n..(f + 1) * n].to_vec());
            Some(m)
        }
        FlipbookPart::Frames { name, meshes } => {
            let m = meshes.get(f)?;
            (!m.triangles.is_empty()).then(|| {
                let mut m = m.clone();
                m.name = format!("{name}_f{:04}", f + 1);
                m
            })
        }
    }
}

/// All parts as one glTF scene: one root node per part with one child per frame, the
/// visible child switched by STEP scale keys in a clip named `smear`. Frames without
/// geometry (no motion line) have no child.
pub(crate) fn flipbook_scene(book: &Flipbook) -> Scene {
    let mut scene = Scene::default();
    let mut channels = Vec::new();
    let times: Vec<f32> = (0..book.frames).map(|f| f as f32 / book.fps).collect();
    for part in &book.parts {
        let root = scene.nodes.len();
        scene.nodes.push(Node {
            name: part.name().to_string(),
            ..Default::default()
        });
        for f in 0..book.frames {
            let Some(mesh) = part_mesh(part, f) else {
                continue;
            };
            let node = scene.nodes.len();
            scene.nodes.push(Node {
                name: mesh.name.clone(),
                parent: Some(root),
                mesh: Some(scene.meshes.len()),
                transform: anim::Transform {
                    scale: if f == 0 { Vec3::ONE } else { Vec3::ZERO },
                    ..Default::default()
                },
                ..Default::default()
            });
            scene.nodes[root].children.push(node);
            scene.meshes.push(SceneMesh {
                mesh,
                ..Default::default()
            });
            channels.extend(Channel::flipbook_visibility(node, f, &times));
        }
    }
    if !channels.is_empty() {
        scene.clips.push(Clip {
            name: "smear".into(),
            channels,
        });
    }
    scene
}

/// All parts as one USD stage: one `Mesh` prim per part, point caches with their per-frame
/// colours, per-frame meshes with per-frame topology.
pub(crate) fn flipbook_stage(book: &Flipbook) -> UsdStage<'_> {
    let meshes = book
        .parts
        .iter()
        .map(|part| match part {
            FlipbookPart::Animation { animation, colors } => {
                UsdMesh::animation(animation, colors.as_deref())
            }
            FlipbookPart::Frames { name, meshes } => {
                UsdMesh::frames(name.clone(), meshes.iter().collect())
            }
        })
        .collect();
    UsdStage::new(book.fps, meshes)
}

/// A body and its motion lines as a glTF scene: the body (one node per frame, named
/// `<body>_fNNNN`) and `motion_lines` (one node per frame, without a mesh when the frame has
/// no line), visibility keyed with STEP scale in a clip named `<body>_lines`.
pub(crate) fn lines_scene(body: &MeshAnimation, lines: &[Mesh]) -> Scene {
    let frames = body.frame_count();
    let times: Vec<f32> = (0..frames).map(|f| f as f32 / body.fps).collect();
    let mut scene = Scene::default();
    let mut channels = Vec::new();
    let mut group =
        |scene: &mut Scene, name: &str, mesh_of: &dyn Fn(usize) -> Option<anim::Mesh>| {
            let root = scene.nodes.len();
            scene.nodes.push(Node {
                name: name.to_string(),
                ..Default::default()
            });
            for f in 0..frames {
                let id = scene.nodes.len();
                let mesh = mesh_of(f).filter(|m| m.vertex_count() > 0).map(|m| {
                    scene.meshes.push(SceneMesh {
                        mesh: m,
                        ..Default::default()
                    });
                    scene.meshes.len() - 1
                });
                let mut node = Node {
                    name: format!("{name}_f{:04}", f + 1),
                    parent: Some(root),
                    mesh,
                    ..Default::default()
                };
                if f != 0 {
                    node.transform.scale = Vec3::ZERO;
                }
                scene.nodes.push(node);
                scene.nodes[root].children.push(id);
                channels.extend(Channel::flipbook_visibility(id, f, &times));
            }
        };
    group(&mut scene, &body.mesh.name, &|f| Some(body.mesh_at(f)));
    group(&mut scene, "motion_lines", &|f| lines.get(f).cloned());
    if !channels.is_empty() {
        scene.clips.push(Clip {
            name: format!("{}_lines", body.mesh.name),
            channels,
        });
    }
    scene
}

/// A body and its motion lines as a USD stage: the body's point cache and one
/// `motion_lines` mesh whose topology changes per frame.
pub(crate) fn lines_stage<'a>(body: &'a MeshAnimation, lines: &'a [Mesh]) -> UsdStage<'a> {
    let lines = UsdMesh::frames("motion_lines", lines.iter().collect());
    UsdStage::new(body.fps, vec![UsdMesh::animation(body, None), lines])
}
