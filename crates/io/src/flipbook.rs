//! Flipbooks (several parts with the same frames, some with per-frame topology) as glTF
//! scenes and USD stages: the layouts `save` writes for [`Output::Flipbook`] and
//! [`Output::MotionLines`](crate::Output::MotionLines).
//!
//! [`Output::Flipbook`]: crate::Output::Flipbook

use anim::glam::Vec3;
use anim::{
    Channel, Clip, Curves, Flipbook, FlipbookPart, Mesh, MeshAnimation, Node, Scene, SceneMesh,
};

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
        FlipbookPart::Frames { name, meshes, .. } => {
            let m = meshes.get(f)?;
            (!m.triangles.is_empty()).then(|| {
                let mut m = m.clone();
                m.name = format!("{name}_f{:04}", f + 1);
                m
            })
        }
    }
}

/// What the flipbook shows at frame `f`, one mesh per visible part named after the part: the
/// frame of an OBJ/STL sequence. A part shows nothing when its frame has no triangles or
/// [`shows`] nothing; a point cache's rest normals are dropped
/// (they are wrong once the mesh deforms).
pub(crate) fn frame_meshes(book: &Flipbook, f: usize) -> Vec<Mesh> {
    book.parts
        .iter()
        .filter_map(|part| {
            let mut m = part_mesh(part, f)?;
            if !shows(&m.positions, m.colors.as_deref()) {
                return None;
            }
            if matches!(part, FlipbookPart::Animation { .. }) {
                m.normals = None;
            }
            m.name = part.name().to_string();
            Some(m)
        })
        .collect()
}

/// Whether a point cache's frame draws anything: not when every position is the same point
/// (a glTF flipbook's hidden node, read back) or every colour is fully transparent (a
/// multiple in-between's copy between its appearances).
pub(crate) fn shows(positions: &[Vec3], colors: Option<&[[f32; 4]]>) -> bool {
    let collapsed = positions
        .split_first()
        .is_none_or(|(p, rest)| rest.iter().all(|q| q == p));
    let transparent = colors.is_some_and(|c| c.iter().all(|c| c[3] <= 0.0));
    !(collapsed || transparent)
}

/// A body and its motion lines at frame `f`, for an OBJ/STL sequence: the body's frame, and
/// `motion_lines` when the frame has any.
pub(crate) fn lines_frame(body: &MeshAnimation, lines: &[Mesh], f: usize) -> Vec<Mesh> {
    let mut b = body.mesh_at(f);
    b.normals = None;
    let mut out = vec![b];
    if let Some(l) = lines.get(f).filter(|l| !l.triangles.is_empty()) {
        let mut l = l.clone();
        l.name = "motion_lines".into();
        out.push(l);
    }
    out
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
/// colours, per-frame meshes with per-frame topology; parts that carry curves (motion lines)
/// as `BasisCurves` prims when `holds_curves` accepts them, else as their tube meshes.
pub(crate) fn flipbook_stage<'a>(
    book: &'a Flipbook,
    holds_curves: &dyn Fn(&[&Curves]) -> bool,
) -> UsdStage<'a> {
    let meshes = book
        .parts
        .iter()
        .map(|part| match part {
            FlipbookPart::Animation { animation, colors } => {
                UsdMesh::animation(animation, colors.as_deref())
            }
            FlipbookPart::Frames {
                name,
                meshes,
                curves,
                velocities,
            } => frames_prim(
                name,
                meshes,
                curves.as_deref(),
                velocities.as_deref(),
                holds_curves,
            ),
        })
        .collect();
    UsdStage::new(book.fps, meshes)
}

/// Per-frame meshes as a prim: their curves when there are some for every frame and the
/// format holds them, else the meshes (with their vertices' velocities when every frame has
/// them).
fn frames_prim<'a>(
    name: &str,
    meshes: &'a [Mesh],
    curves: Option<&'a [Curves]>,
    velocities: Option<&'a [Vec<Vec3>]>,
    holds_curves: &dyn Fn(&[&Curves]) -> bool,
) -> UsdMesh<'a> {
    let curves: Option<Vec<&Curves>> = curves
        .filter(|c| c.len() == meshes.len())
        .map(|c| c.iter().collect());
    match (curves, velocities) {
        (Some(c), _) if holds_curves(&c) => UsdMesh::curves(name, c),
        (_, Some(v)) if v.len() == meshes.len() => UsdMesh::moving_frames(
            name,
            meshes.iter().collect(),
            v.iter().map(Vec::as_slice).collect(),
        ),
        _ => UsdMesh::frames(name, meshes.iter().collect()),
    }
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
/// `motion_lines` prim, `BasisCurves` when the lines come with curves the format holds,
/// else a mesh whose topology changes per frame.
pub(crate) fn lines_stage<'a>(
    body: &'a MeshAnimation,
    lines: &'a [Mesh],
    curves: Option<&'a [Curves]>,
    holds_curves: &dyn Fn(&[&Curves]) -> bool,
) -> UsdStage<'a> {
    let lines = frames_prim("motion_lines", lines, curves, None, holds_curves);
    UsdStage::new(body.fps, vec![UsdMesh::animation(body, None), lines])
}
