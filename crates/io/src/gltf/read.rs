//! glTF 2.0 reader (`.gltf` with external or embedded buffers, `.glb`) into [`anim::Scene`].
//!
//! Parsing and validation of the JSON is the `gltf` crate's; this module maps the document
//! onto the data model and checks what that crate assumes (accessor component types, counts,
//! buffer ranges) so that bad bytes give an error, never a panic. Application-specific scalar
//! attributes (`_NAME`) go to [`anim::Mesh::attributes`] (see `attributes`).

use std::path::Path;

use anim::glam::{Mat4, Quat, Vec3};
use anim::{
    triangulate_polygon, Channel, Clip, Interpolation, Mesh, MorphTarget, Node, Projection,
    Property, Scene, SceneCamera, SceneMesh, SkinDef, Transform, VertexWeights,
};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use crate::gltf::values::{packed, vec2s, vec3s};
use crate::{read_file, IoError, Result};

const FORMAT: &str = "glTF";

fn bad(message: impl Into<String>) -> IoError {
    IoError::malformed(FORMAT, message)
}

/// Reads a `.gltf` or `.glb` file; external buffers are resolved next to it.
pub fn read(path: &Path) -> Result<Scene> {
    let bytes = read_file(path)?;
    read_with_base(&bytes, path.parent()).map_err(|e| e.at(path))
}

/// Reads a glTF document from bytes (`.glb`, or `.gltf` with embedded `data:` buffers).
/// External buffer files are an error here since there is no directory to find them in.
pub fn read_bytes(bytes: &[u8]) -> Result<Scene> {
    read_with_base(bytes, None)
}

fn read_with_base(bytes: &[u8], base: Option<&Path>) -> Result<Scene> {
    read_full(bytes, base, None).map(|(scene, _)| scene)
}

/// Reads a glTF document; `choice` picks a scene by name or index (default: the file's
/// default scene when it has several). Returns the scene and one note per extension the
/// file uses (what toonkit did with it) and on the scene picked.
pub(crate) fn read_full(
    bytes: &[u8],
    base: Option<&Path>,
    choice: Option<&str>,
) -> Result<(Scene, Vec<String>)> {
    let base = base.map(|b| {
        if b.as_os_str().is_empty() {
            Path::new(".")
        } else {
            b
        }
    });
    let prepared = crate::gltf::prepare::prepare(bytes, base)?;
    crate::gltf::precheck::precheck(&prepared.root).map_err(bad)?;
    let mut notes = prepared.notes;
    // gltf-json's validation indexes some arrays unchecked; `precheck` covers the known
    // cases and this guard turns any other panic into an error.
    let root = prepared.root;
    let doc = std::panic::catch_unwind(|| gltf::Document::from_json(root))
        .map_err(|_| bad("the document is inconsistent (rejected during validation)"))?
        .map_err(|e| bad(e.to_string()))?;
    let data: Vec<&[u8]> = prepared.buffers.iter().map(|b| &**b).collect();
    // The gltf crate unwraps some fields it validated loosely; a panic there is bad input.
    let mut scene = std::panic::catch_unwind(|| convert(&doc, &data))
        .map_err(|_| bad("the document is inconsistent (rejected while reading)"))??;
    if let Some(note) = crate::gltf::scenes::select(&doc, &mut scene, choice)? {
        notes.push(note);
    }
    scene.validate()?;
    Ok((scene, notes))
}

fn convert(doc: &gltf::Document, buffers: &[&[u8]]) -> Result<Scene> {
    let mut scene = Scene::default();
    for mesh in doc.meshes() {
        scene.meshes.push(read_mesh(&mesh, buffers)?);
    }
    for (i, node) in doc.nodes().enumerate() {
        let (t, r, s) = node.transform().decomposed();
        let rotation = Quat::from_array(r);
        scene.nodes.push(Node {
            name: node.name().unwrap_or_default().to_string(),
            parent: None,
            children: node.children().map(|c| c.index()).collect(),
            transform: Transform {
                translation: Vec3::from_array(t),
                rotation: if rotation.length_squared() > 1e-12 && rotation.is_finite() {
                    rotation.normalize()
                } else {
                    Quat::IDENTITY
                },
                scale: Vec3::from_array(s),
            },
            mesh: node.mesh().map(|m| m.index()),
            skin: node.skin().map(|s| s.index()),
            camera: node.camera().map(|c| c.index()),
            weights: node.weights().map(<[f32]>::to_vec),
        });
        if !scene.nodes[i].transform.translation.is_finite()
            || !scene.nodes[i].transform.scale.is_finite()
        {
            return Err(bad(format!("node {i} has a non-finite transform")));
        }
    }
    for i in 0..scene.nodes.len() {
        for c in scene.nodes[i].children.clone() {
            if scene.nodes[c].parent.is_some() || c == i {
                return Err(bad(format!("node {c} has more than one parent")));
            }
            scene.nodes[c].parent = Some(i);
        }
    }
    for skin in doc.skins() {
        let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
        let inverse_bind = match skin.inverse_bind_matrices() {
            Some(acc) => {
                expect(
                    &acc,
                    &[DataType::F32],
                    Dimensions::Mat4,
                    "inverse bind matrices",
                )?;
                let reader = skin.reader(|b| buffers.get(b.index()).copied());
                let m: Vec<Mat4> = reader
                    .read_inverse_bind_matrices()
                    .ok_or_else(|| bad("inverse bind matrices lie outside their buffer"))?
                    .map(|c| Mat4::from_cols_array_2d(&c))
                    .collect();
                if m.len() != joints.len() {
                    return Err(bad(format!(
                        "skin {} has {} joints but {} inverse bind matrices",
                        skin.index(),
                        joints.len(),
                        m.len()
                    )));
                }
                m
            }
            None => vec![Mat4::IDENTITY; joints.len()],
        };
        scene.skins.push(SkinDef {
            name: skin.name().unwrap_or_default().to_string(),
            joints,
            inverse_bind,
            skeleton: skin.skeleton().map(|n| n.index()),
        });
    }
    for cam in doc.cameras() {
        let projection = match cam.projection() {
            gltf::camera::Projection::Perspective(p) => Projection::Perspective {
                yfov: p.yfov(),
                aspect: p.aspect_ratio(),
                znear: p.znear(),
                zfar: p.zfar(),
            },
            gltf::camera::Projection::Orthographic(o) => Projection::Orthographic {
                xmag: o.xmag(),
                ymag: o.ymag(),
                znear: o.znear(),
                zfar: o.zfar(),
            },
        };
        scene.cameras.push(SceneCamera {
            name: cam.name().unwrap_or_default().to_string(),
            projection,
        });
    }
    for (k, anim) in doc.animations().enumerate() {
        let name = anim
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("clip{k}"));
        let mut clip = Clip {
            name,
            channels: Vec::new(),
        };
        for ch in anim.channels() {
            clip.channels.push(read_channel(&scene, &ch, buffers)?);
        }
        scene.clips.push(clip);
    }
    Ok(scene)
}

fn expect(acc: &gltf::Accessor, types: &[DataType], dims: Dimensions, what: &str) -> Result<()> {
    if !types.contains(&acc.data_type()) || acc.dimensions() != dims {
        return Err(bad(format!(
            "accessor {} ({what}) has type {:?} {:?}, expected {:?} of {:?}",
            acc.index(),
            acc.dimensions(),
            acc.data_type(),
            dims,
            types
        )));
    }
    Ok(())
}

fn outside(what: &str) -> IoError {
    bad(format!("{what} accessor lies outside its buffer"))
}

fn read_mesh(mesh: &gltf::Mesh, buffers: &[&[u8]]) -> Result<SceneMesh> {
    let name = mesh.name().unwrap_or_default().to_string();
    let mut out = SceneMesh {
        mesh: Mesh {
            name: name.clone(),
            ..Mesh::default()
        },
        ..SceneMesh::default()
    };
    let target_names = target_names(mesh);
    let mut any_weights = false;
    let mut weights = VertexWeights::default();
    let mut first = true;
    for prim in mesh.primitives() {
        let mode = prim.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            continue; // points and lines carry no surface
        }
        let Some(pos_acc) = prim.get(&gltf::Semantic::Positions) else {
            continue;
        };
        // The geometry and the joint influences are independent reads of the buffers (about
        // half of the load each): one core each, instead of the load's serial time on one
        // (issue #14).
        let (geometry, influences) = rayon::join(
            || primitive_geometry(&prim, mode, &pos_acc, buffers, &name),
            || primitive_influences(&prim, buffers),
        );
        let part = geometry?;
        let n = part.positions.len();
        let part_weights = match influences? {
            Some(w) if w.vertex_count() != n => {
                return Err(bad("JOINTS/WEIGHTS count differs from POSITION count"));
            }
            Some(w) => {
                any_weights = true;
                w
            }
            None => VertexWeights::from_influences((0..n).map(|_| std::iter::empty())),
        };
        // Morph targets: all primitives of a mesh have the same number.
        let mut targets = Vec::new();
        for t in prim.morph_targets() {
            let d = match t.positions() {
                Some(acc) => {
                    let v: Vec<Vec3> = vec3s(&acc, buffers, "morph POSITION")?
                        .into_iter()
                        .map(Vec3::from_array)
                        .collect();
                    if v.len() != n {
                        return Err(bad("morph target count differs from POSITION count"));
                    }
                    v
                }
                None => vec![Vec3::ZERO; n],
            };
            targets.push(d);
        }
        if first {
            out.morph_targets = (0..targets.len())
                .map(|k| MorphTarget {
                    name: target_names
                        .get(k)
                        .cloned()
                        .unwrap_or_else(|| format!("target{k}")),
                    positions: Vec::new(),
                })
                .collect();
        } else if targets.len() != out.morph_targets.len() {
            return Err(bad(format!(
                "primitives of mesh '{name}' have different morph target counts"
            )));
        }
        for (t, d) in out.morph_targets.iter_mut().zip(targets) {
            t.positions.extend(d);
        }
        weights.append(&part_weights);
        if first {
            out.mesh = part;
        } else {
            out.mesh.append(&part);
        }
        first = false;
    }
    if any_weights {
        out.joint_weights = Some(weights);
    }
    out.mesh.name = name;
    out.default_weights = mesh.weights().map(<[f32]>::to_vec).unwrap_or_default();
    out.default_weights.resize(out.morph_targets.len(), 0.0);
    Ok(out)
}

/// The mesh of one primitive: positions, triangles and every vertex attribute but the joint
/// influences (see [`primitive_influences`]) and morph targets.
fn primitive_geometry(
    prim: &gltf::Primitive,
    mode: Mode,
    pos_acc: &gltf::Accessor,
    buffers: &[&[u8]],
    name: &str,
) -> Result<Mesh> {
    let reader = prim.reader(|b| buffers.get(b.index()).copied());
    // KHR_mesh_quantization: integer positions, normals, texture coordinates.
    let positions: Vec<Vec3> = vec3s(pos_acc, buffers, "POSITION")?
        .into_iter()
        .map(Vec3::from_array)
        .collect();
    let n = positions.len();
    let indices: Vec<u32> = match prim.indices() {
        Some(acc) => {
            expect(
                &acc,
                &[DataType::U8, DataType::U16, DataType::U32],
                Dimensions::Scalar,
                "indices",
            )?;
            packed::<u16>(&acc, buffers, DataType::U16)
                .map(|v| v.into_iter().map(u32::from).collect())
                .or_else(|| packed::<u32>(&acc, buffers, DataType::U32))
                .or_else(|| reader.read_indices().map(|i| i.into_u32().collect()))
                .ok_or_else(|| outside("index"))?
        }
        None => (0..n as u32).collect(),
    };
    let triangles = assemble(mode, &indices);
    let mut part = Mesh::new(name.to_string(), positions, triangles);
    if let Some(acc) = prim.get(&gltf::Semantic::Normals) {
        let normals = vec3s(&acc, buffers, "NORMAL")?;
        part.normals = Some(normals.into_iter().map(Vec3::from_array).collect());
    }
    if let Some(acc) = prim.get(&gltf::Semantic::TexCoords(0)) {
        part.uvs = Some(vec2s(&acc, buffers, "TEXCOORD_0")?);
    }
    // Further sets (TEXCOORD_1, …) are numbered without gaps (glTF 2.0 §3.7.2.1).
    let mut set = 1;
    while let Some(acc) = prim.get(&gltf::Semantic::TexCoords(set)) {
        let name = format!("TEXCOORD_{set}");
        part.extra_uvs.push(vec2s(&acc, buffers, &name)?);
        set += 1;
    }
    if let Some(acc) = prim.get(&gltf::Semantic::Colors(0)) {
        let dims = acc.dimensions();
        if dims != Dimensions::Vec3 && dims != Dimensions::Vec4 {
            return Err(bad("COLOR_0 must be VEC3 or VEC4"));
        }
        expect(
            &acc,
            &[DataType::U8, DataType::U16, DataType::F32],
            dims,
            "COLOR_0",
        )?;
        part.colors = Some(
            reader
                .read_colors(0)
                .ok_or_else(|| outside("COLOR_0"))?
                .into_rgba_f32()
                .collect(),
        );
    }
    part.attributes = crate::gltf::attributes::read_attributes(prim, buffers, n)?;
    check_len(&part, n)?;
    Ok(part)
}

/// The joint influences of one primitive, `None` when it has no `JOINTS_n` / `WEIGHTS_n`
/// pair.
fn primitive_influences(
    prim: &gltf::Primitive,
    buffers: &[&[u8]],
) -> Result<Option<VertexWeights>> {
    let reader = prim.reader(|b| buffers.get(b.index()).copied());
    // Joint influences over every JOINTS_n / WEIGHTS_n pair, read set by set and joined
    // per vertex (no list per vertex).
    let mut sets: Vec<InfluenceSet> = Vec::new();
    let mut set = 0;
    while let (Some(ja), Some(wa)) = (
        prim.get(&gltf::Semantic::Joints(set)),
        prim.get(&gltf::Semantic::Weights(set)),
    ) {
        expect(
            &ja,
            &[DataType::U8, DataType::U16],
            Dimensions::Vec4,
            "JOINTS",
        )?;
        expect(
            &wa,
            &[DataType::U8, DataType::U16, DataType::F32],
            Dimensions::Vec4,
            "WEIGHTS",
        )?;
        let j: Vec<[u16; 4]> = packed(&ja, buffers, DataType::U16)
            .or_else(|| reader.read_joints(set).map(|j| j.into_u16().collect()))
            .ok_or_else(|| outside("JOINTS"))?;
        let w: Vec<[f32; 4]> = packed(&wa, buffers, DataType::F32)
            .or_else(|| reader.read_weights(set).map(|w| w.into_f32().collect()))
            .ok_or_else(|| outside("WEIGHTS"))?;
        sets.push((j, w));
        set += 1;
    }
    let Some(len) = sets.first().map(|(j, _)| j.len()) else {
        return Ok(None);
    };
    if sets.iter().any(|(j, w)| j.len() != len || w.len() != len) {
        return Err(bad("JOINTS/WEIGHTS count differs from POSITION count"));
    }
    let sets = &sets;
    Ok(Some(VertexWeights::from_influences((0..len).map(|v| {
        sets.iter()
            .flat_map(move |(j, w)| j[v].iter().zip(&w[v]).map(|(&a, &b)| (u32::from(a), b)))
    }))))
}

/// One `JOINTS_n` / `WEIGHTS_n` pair of a primitive: four joint slots and weights per vertex.
type InfluenceSet = (Vec<[u16; 4]>, Vec<[f32; 4]>);

fn check_len(m: &Mesh, n: usize) -> Result<()> {
    let lens = [
        m.normals.as_ref().map(Vec::len),
        m.uvs.as_ref().map(Vec::len),
        m.colors.as_ref().map(Vec::len),
    ];
    let sets = m.extra_uvs.iter().map(Vec::len);
    if lens.iter().flatten().copied().chain(sets).any(|l| l != n) {
        return Err(bad(
            "a vertex attribute count differs from the POSITION count",
        ));
    }
    Ok(())
}

fn assemble(mode: Mode, idx: &[u32]) -> Vec<[u32; 3]> {
    let mut out = Vec::with_capacity(idx.len() / 3);
    match mode {
        Mode::TriangleStrip => {
            for k in 0..idx.len().saturating_sub(2) {
                out.push(if k % 2 == 0 {
                    [idx[k], idx[k + 1], idx[k + 2]]
                } else {
                    [idx[k + 1], idx[k], idx[k + 2]]
                });
            }
        }
        Mode::TriangleFan => triangulate_polygon(idx, &mut out),
        _ => out.extend(idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]])),
    }
    out
}

fn target_names(mesh: &gltf::Mesh) -> Vec<String> {
    let Some(raw) = mesh.extras() else {
        return Vec::new();
    };
    let Ok(v) = serde_json::from_str::<serde_json::Value>(raw.get()) else {
        return Vec::new();
    };
    v.get("targetNames")
        .and_then(|t| t.as_array())
        .map(|a| {
            a.iter()
                .map(|s| s.as_str().unwrap_or_default().to_string())
                .collect()
        })
        .unwrap_or_default()
}

fn read_channel(
    scene: &Scene,
    ch: &gltf::animation::Channel,
    buffers: &[&[u8]],
) -> Result<Channel> {
    use gltf::animation::util::ReadOutputs;
    let node = ch.target().node().index();
    let sampler = ch.sampler();
    let interpolation = match sampler.interpolation() {
        gltf::animation::Interpolation::Linear => Interpolation::Linear,
        gltf::animation::Interpolation::Step => Interpolation::Step,
        gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
    };
    expect(
        &sampler.input(),
        &[DataType::F32],
        Dimensions::Scalar,
        "animation input",
    )?;
    let out_acc = sampler.output();
    let reader = ch.reader(|b| buffers.get(b.index()).copied());
    let times: Vec<f32> = reader
        .read_inputs()
        .ok_or_else(|| outside("animation input"))?
        .collect();
    let mut values = Vec::new();
    let property = match ch.target().property() {
        gltf::animation::Property::Translation => {
            expect(
                &out_acc,
                &[DataType::F32],
                Dimensions::Vec3,
                "translation output",
            )?;
            if let Some(ReadOutputs::Translations(it)) = reader.read_outputs() {
                values.extend(it.flatten());
            }
            Property::Translation
        }
        gltf::animation::Property::Scale => {
            expect(&out_acc, &[DataType::F32], Dimensions::Vec3, "scale output")?;
            if let Some(ReadOutputs::Scales(it)) = reader.read_outputs() {
                values.extend(it.flatten());
            }
            Property::Scale
        }
        gltf::animation::Property::Rotation => {
            let ok = [
                DataType::I8,
                DataType::U8,
                DataType::I16,
                DataType::U16,
                DataType::F32,
            ];
            expect(&out_acc, &ok, Dimensions::Vec4, "rotation output")?;
            if let Some(ReadOutputs::Rotations(it)) = reader.read_outputs() {
                values.extend(it.into_f32().flatten());
            }
            Property::Rotation
        }
        gltf::animation::Property::MorphTargetWeights => {
            let ok = [
                DataType::I8,
                DataType::U8,
                DataType::I16,
                DataType::U16,
                DataType::F32,
            ];
            expect(&out_acc, &ok, Dimensions::Scalar, "weights output")?;
            if let Some(ReadOutputs::MorphTargetWeights(it)) = reader.read_outputs() {
                values.extend(it.into_f32());
            }
            let targets = scene.nodes[node]
                .mesh
                .map(|m| scene.meshes[m].morph_targets.len())
                .unwrap_or(0);
            Property::Weights(targets)
        }
    };
    let channel = Channel {
        node,
        property,
        interpolation,
        times,
        values,
    };
    channel
        .validate()
        .map_err(|e| bad(format!("animation channel on node {node}: {e}")))?;
    Ok(channel)
}
