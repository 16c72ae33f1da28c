//! A [`MeshAnimation`] as glTF: a *flipbook* (one node per frame, visibility keyed with STEP
//! scale) or *morph targets* (one target per frame, STEP weights). Both open in Blender and
//! three.js; the flipbook also carries per-frame vertex colours (with alpha). The mesh's
//! scalar attributes (`_NAME`, [`anim::Mesh::attributes`]) are on every frame; data that is the
//! same in several frames or parts (triangles, UVs, attributes, still frames) is stored once.

use anim::glam::{Quat, Vec3};
use anim::{Channel, Clip, Interpolation, MeshAnimation, Property, SceneMesh};
use gltf_json as json;

use crate::gltf::accessors::Builder;
use crate::gltf::quantize::{Dequant, GlbOptions};
use crate::gltf::write::{frame_mesh, trs_node, write_clip};
use crate::{IoError, Result};

/// How a point cache is laid out in glTF.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AnimationLayout {
    /// One node (and mesh) per frame; only the current frame's node has scale 1.
    #[default]
    Flipbook,
    /// One mesh whose morph target `f` moves the base onto frame `f`; weights are one-hot
    /// (frame 0's by default). The base is frame 0, or, when quantized, every vertex's mid
    /// position over the frames (so that the deltas stay within the quantization range).
    Morph,
}

/// Writes a point cache as `.glb` bytes.
///
/// # Arguments
/// * `colors` — optional per-frame RGBA vertex colours, frame-major (`frames × vertices`).
///   Alpha below 1 selects an alpha-blended material. Morph layout uses frame 0's colours.
///
/// # Errors
/// When `colors` has the wrong length, or the mesh is empty.
pub fn write_animation(
    anim: &MeshAnimation,
    layout: AnimationLayout,
    colors: Option<&[[f32; 4]]>,
) -> Result<Vec<u8>> {
    write_animations(&[(anim, colors)], layout)
}

/// Writes several point caches with the same frames into one `.glb`: one top-level node per
/// cache, named after its mesh (a flipbook root with a child per frame, or one morphing
/// mesh), all driven by one clip.
///
/// # Errors
/// When the frame counts differ, colours have the wrong length, or a mesh is empty.
pub fn write_animations(
    parts: &[(&MeshAnimation, Option<&[[f32; 4]]>)],
    layout: AnimationLayout,
) -> Result<Vec<u8>> {
    write_animations_with(parts, layout, GlbOptions::default())
}

/// [`write_animations`] with writer options: with `options.quantize` every frame (flipbook)
/// or the base mesh and its targets (morph) are written with `KHR_mesh_quantization`.
///
/// # Errors
/// As [`write_animations`].
pub fn write_animations_with(
    parts: &[(&MeshAnimation, Option<&[[f32; 4]]>)],
    layout: AnimationLayout,
    options: GlbOptions,
) -> Result<Vec<u8>> {
    let Some((first, _)) = parts.first() else {
        return Err(IoError::unsupported("nothing to write"));
    };
    let frames = first.frame_count();
    for (anim, colors) in parts {
        if anim.frame_count() != frames {
            return Err(IoError::unsupported(format!(
                "mesh '{}' has {} frames, expected {frames}",
                anim.mesh.name,
                anim.frame_count()
            )));
        }
        let n = anim.vertex_count();
        if let Some(c) = colors {
            if c.len() != n * frames {
                return Err(IoError::unsupported(format!(
                    "vertex colours: expected {} values (frames × vertices), got {}",
                    n * frames,
                    c.len()
                )));
            }
        }
    }
    let times: Vec<f32> = (0..frames).map(|f| f as f32 / first.fps).collect();
    // One dequantization for every part and frame: seams that parts share stay identical.
    let q = if options.quantize {
        shared_dequant(parts, layout)
    } else {
        None
    };
    let mut b = Builder::new();
    let mut roots = Vec::new();
    let mut channels = Vec::new();
    for (anim, colors) in parts {
        let n = anim.vertex_count();
        let colors_of = |f: usize| colors.map(|c| &c[f * n..(f + 1) * n]);
        let root = match layout {
            AnimationLayout::Flipbook => {
                flipbook(&mut b, anim, &times, colors_of, q, &mut channels)?
            }
            AnimationLayout::Morph => morph(&mut b, anim, &times, colors_of(0), q, &mut channels)?,
        };
        roots.push(root);
    }
    let scene = b.root.push(json::Scene {
        extensions: None,
        extras: Default::default(),
        name: None,
        nodes: roots,
    });
    b.root.scene = Some(scene);
    if !channels.is_empty() {
        let name = if parts.len() == 1 {
            mesh_name(first).to_string()
        } else {
            "parts".into()
        };
        let suffix = match layout {
            AnimationLayout::Flipbook => "flipbook",
            AnimationLayout::Morph => "morph",
        };
        write_clip(
            &mut b,
            &Clip {
                name: format!("{name}_{suffix}"),
                channels,
            },
        );
    }
    b.finish()
}

fn mesh_name(anim: &MeshAnimation) -> &str {
    if anim.mesh.name.is_empty() {
        "mesh"
    } else {
        anim.mesh.name.as_str()
    }
}

fn flipbook<'a>(
    b: &mut Builder,
    anim: &MeshAnimation,
    times: &[f32],
    colors_of: impl Fn(usize) -> Option<&'a [[f32; 4]]>,
    q: Option<Dequant>,
    channels: &mut Vec<Channel>,
) -> Result<json::Index<json::Node>> {
    let frames = anim.frame_count();
    let name = mesh_name(anim);
    let mut children = Vec::with_capacity(frames);
    for f in 0..frames {
        let sm = frame_mesh(&anim.mesh, anim.frame(f), colors_of(f));
        let mesh = b.mesh_with(&sm, q)?;
        // The frame node's scale switches visibility; a quantized mesh's dequantization
        // goes on a child below it.
        let (mesh, sub) = match q {
            Some(q) => {
                let child = b.root.push(json::Node {
                    mesh: Some(mesh),
                    name: Some(format!("{name}_f{:04}_quantized", f + 1)),
                    ..trs_node(q.center, Quat::IDENTITY, q.scale)
                });
                (None, Some(vec![child]))
            }
            None => (Some(mesh), None),
        };
        let node = b.root.push(json::Node {
            mesh,
            children: sub,
            name: Some(format!("{name}_f{:04}", f + 1)),
            scale: (f != 0).then_some([0.0; 3]),
            ..empty_node()
        });
        children.push(node);
        channels.extend(Channel::flipbook_visibility(node.value(), f, times));
    }
    Ok(b.root.push(json::Node {
        name: Some(name.to_string()),
        children: Some(children),
        ..empty_node()
    }))
}

fn morph(
    b: &mut Builder,
    anim: &MeshAnimation,
    times: &[f32],
    colors: Option<&[[f32; 4]]>,
    q: Option<Dequant>,
    channels: &mut Vec<Channel>,
) -> Result<json::Index<json::Node>> {
    let frames = anim.frame_count();
    let sm = morph_mesh(anim, colors, q.is_some());
    let mesh = b.mesh_with(&sm, q)?;
    // Only the weights of this node are animated: the dequantization is its own transform.
    let trs = match q {
        Some(q) => trs_node(q.center, Quat::IDENTITY, q.scale),
        None => empty_node(),
    };
    let node = b.root.push(json::Node {
        mesh: Some(mesh),
        name: Some(mesh_name(anim).to_string()),
        ..trs
    });
    if frames > 1 {
        let mut values = vec![0.0f32; frames * frames];
        for f in 0..frames {
            values[f * frames + f] = 1.0;
        }
        channels.push(Channel {
            node: node.value(),
            property: Property::Weights(frames),
            interpolation: Interpolation::Step,
            times: times.to_vec(),
            values,
        });
    }
    Ok(node)
}

/// The morph layout's mesh: the base with one target per frame (the base onto frame `f`)
/// and frame 0's weights by default. The base is frame 0, or with `midrange` every vertex's
/// mid position over all frames, which halves the largest delta (quantized output).
fn morph_mesh(anim: &MeshAnimation, colors: Option<&[[f32; 4]]>, midrange: bool) -> SceneMesh {
    let frames = anim.frame_count();
    let base: Vec<Vec3> = if midrange && frames > 1 {
        let n = anim.vertex_count();
        let (mut lo, mut hi) = (anim.frame(0).to_vec(), anim.frame(0).to_vec());
        for f in 1..frames {
            for (v, p) in anim.frame(f).iter().enumerate().take(n) {
                lo[v] = lo[v].min(*p);
                hi[v] = hi[v].max(*p);
            }
        }
        lo.iter().zip(&hi).map(|(a, b)| (*a + *b) * 0.5).collect()
    } else {
        anim.frame(0).to_vec()
    };
    let mut sm = frame_mesh(&anim.mesh, &base, colors);
    if frames > 1 {
        sm.morph_targets = (0..frames)
            .map(|f| anim::MorphTarget {
                name: format!("frame_{:04}", f + 1),
                positions: anim
                    .frame(f)
                    .iter()
                    .zip(&base)
                    .map(|(p, q)| *p - *q)
                    .collect::<Vec<Vec3>>(),
            })
            .collect();
        sm.default_weights = vec![0.0; frames];
        if midrange {
            sm.default_weights[0] = 1.0;
        }
    }
    sm
}

/// The dequantization every part and frame of one output shares, when the position error
/// stays within [`MAX_ERROR`](crate::gltf::quantize::MAX_ERROR) of their common bounding-box diagonal.
fn shared_dequant(
    parts: &[(&MeshAnimation, Option<&[[f32; 4]]>)],
    layout: AnimationLayout,
) -> Option<Dequant> {
    let meshes: Vec<SceneMesh> = match layout {
        // Positions only: one mesh per part holding all its frames.
        AnimationLayout::Flipbook => parts
            .iter()
            .map(|(a, _)| SceneMesh {
                mesh: anim::Mesh::new("", a.positions().to_vec(), Vec::new()),
                ..SceneMesh::default()
            })
            .collect(),
        AnimationLayout::Morph => parts
            .iter()
            .map(|(a, _)| morph_mesh(a, None, true))
            .collect(),
    };
    Dequant::shared(meshes.iter())
}

/// A node with no transform (the flipbook roots and frames that need no dequantization).
fn empty_node() -> json::Node {
    trs_node(Vec3::ZERO, Quat::IDENTITY, Vec3::ONE)
}
