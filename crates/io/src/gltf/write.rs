//! glTF 2.0 binary (`.glb`) writer: a whole [`anim::Scene`] (nodes, meshes with morph targets
//! and skins, cameras, clips). Writing is building `gltf-json` structures; the binary chunk
//! holds tightly packed, 4-byte aligned buffer views with correct accessor bounds, identical
//! data stored once (`accessors`), so that the Khronos validator accepts every file.

use anim::glam::{Mat4, Quat, Vec3};
use anim::{Interpolation, Mesh, Projection, Property, Scene, SceneMesh, VertexWeights};
use gltf_json as json;
use json::validation::Checked::Valid;
use serde_json::json as js;

use crate::gltf::accessors::{Builder, Usage};
use crate::gltf::quantize::Dequant;
use crate::gltf::quantize::GlbOptions;
use crate::{IoError, Result};

/// The extension quantized meshes need.
const QUANTIZATION: &str = "KHR_mesh_quantization";

impl Builder {
    /// Declares `KHR_mesh_quantization` as used and required (once).
    pub(crate) fn use_quantization(&mut self) {
        if !self.root.extensions_used.iter().any(|e| e == QUANTIZATION) {
            self.root.extensions_used.push(QUANTIZATION.into());
            self.root.extensions_required.push(QUANTIZATION.into());
        }
    }

    /// The shared material: opaque, or alpha-blended for translucent vertex colours.
    pub(crate) fn material(&mut self, blend: bool) -> json::Index<json::Material> {
        let slot = if blend { self.blend } else { self.opaque };
        if let Some(m) = slot {
            return m;
        }
        let mut m = json::Material {
            name: Some(
                if blend {
                    "toonkit_blend"
                } else {
                    "toonkit_opaque"
                }
                .into(),
            ),
            double_sided: true,
            ..Default::default()
        };
        m.pbr_metallic_roughness.metallic_factor = json::material::StrengthFactor(0.0);
        m.pbr_metallic_roughness.roughness_factor = json::material::StrengthFactor(0.8);
        if blend {
            m.alpha_mode = Valid(json::material::AlphaMode::Blend);
        }
        let idx = self.root.push(m);
        if blend {
            self.blend = Some(idx);
        } else {
            self.opaque = Some(idx);
        }
        idx
    }

    /// Adds a mesh. Identical accessor data (a flipbook's triangles, UVs and painted
    /// attributes in every frame) is stored once.
    /// A mesh, quantized with `q` (`KHR_mesh_quantization`) when given.
    pub(crate) fn mesh_with(
        &mut self,
        sm: &SceneMesh,
        q: Option<Dequant>,
    ) -> Result<json::Index<json::Mesh>> {
        let m = &sm.mesh;
        if m.vertex_count() == 0 {
            return Err(IoError::unsupported(format!(
                "mesh '{}' has no vertex",
                m.name
            )));
        }
        let mut attributes = std::collections::BTreeMap::new();
        if q.is_some() {
            self.use_quantization();
        }
        let pos = match q {
            Some(q) => self.snorm_vec3s(&q.encode(&m.positions), true, true),
            None => self.vec3s(&m.positions, true),
        };
        attributes.insert(Valid(json::mesh::Semantic::Positions), pos);
        let normals = match &m.normals {
            Some(n) => n
                .iter()
                .map(|v| v.try_normalize().unwrap_or(Vec3::Y))
                .collect(),
            None => m.vertex_normals(&m.positions),
        };
        let nrm = match q {
            Some(q) => self.snorm_vec3s(&q.encode_normals(&normals), false, false),
            None => self.vec3s(&normals, false),
        };
        attributes.insert(Valid(json::mesh::Semantic::Normals), nrm);
        if let Some(uv) = &m.uvs {
            let flat: Vec<f32> = uv.iter().flatten().copied().collect();
            let acc = self.floats(&flat, 2, Usage::Vertex, false);
            attributes.insert(Valid(json::mesh::Semantic::TexCoords(0)), acc);
        }
        for (k, uv) in m.extra_uvs.iter().enumerate() {
            let flat: Vec<f32> = uv.iter().flatten().copied().collect();
            let acc = self.floats(&flat, 2, Usage::Vertex, false);
            // Set k + 1 follows set k: without `uvs`, the first extra set is TEXCOORD_0.
            let set = k as u32 + u32::from(m.uvs.is_some());
            attributes.insert(Valid(json::mesh::Semantic::TexCoords(set)), acc);
        }
        let mut blend = false;
        if let Some(c) = &m.colors {
            blend = c.iter().any(|v| v[3] < 1.0);
            let acc = self.colors(c);
            attributes.insert(Valid(json::mesh::Semantic::Colors(0)), acc);
        }
        for (semantic, acc) in self.scalar_attributes(m)? {
            attributes.insert(Valid(semantic), acc);
        }
        if let Some(w) = &sm.joint_weights {
            for (set, (j, x)) in split_influences(w).into_iter().enumerate() {
                let ja = self.joints(&j);
                let flat: Vec<f32> = x.iter().flatten().copied().collect();
                let wa = self.floats(&flat, 4, Usage::Vertex, false);
                attributes.insert(Valid(json::mesh::Semantic::Joints(set as u32)), ja);
                attributes.insert(Valid(json::mesh::Semantic::Weights(set as u32)), wa);
            }
        }
        let (mode, indices) = if m.triangles.is_empty() {
            (json::mesh::Mode::Points, None)
        } else {
            let acc = self.indices(&m.triangles);
            (json::mesh::Mode::Triangles, Some(acc))
        };
        let targets = (!sm.morph_targets.is_empty()).then(|| {
            sm.morph_targets
                .iter()
                .map(|t| json::mesh::MorphTarget {
                    positions: Some(match q {
                        Some(q) => self.snorm_vec3s(
                            &q.encode_delta(&m.positions, &t.positions),
                            true,
                            true,
                        ),
                        None => self.vec3s(&t.positions, true),
                    }),
                    normals: None,
                    tangents: None,
                })
                .collect::<Vec<_>>()
        });
        let material = Some(self.material(blend));
        let extras = (!sm.morph_targets.is_empty()).then(|| {
            let names: Vec<&str> = sm.morph_targets.iter().map(|t| t.name.as_str()).collect();
            serde_json::value::to_raw_value(&js!({ "targetNames": names })).expect("json")
        });
        let weights = (!sm.morph_targets.is_empty()).then(|| {
            let mut w = sm.default_weights.clone();
            w.resize(sm.morph_targets.len(), 0.0);
            w
        });
        let primitive = json::mesh::Primitive {
            attributes,
            extensions: None,
            extras: Default::default(),
            indices,
            material,
            mode: Valid(mode),
            targets,
        };
        Ok(self.root.push(json::Mesh {
            extensions: None,
            extras,
            name: (!m.name.is_empty()).then(|| m.name.clone()),
            primitives: vec![primitive],
            weights,
        }))
    }
}

/// Splits any number of influences into JOINTS_n/WEIGHTS_n sets of four, keeping the sum 1.
/// One JOINTS_n/WEIGHTS_n pair of attribute arrays.
type InfluenceSet = (Vec<[u16; 4]>, Vec<[f32; 4]>);

fn split_influences(w: &VertexWeights) -> Vec<InfluenceSet> {
    let n = w.vertex_count();
    let max = (0..n)
        .map(|v| w.influences(v).0.len())
        .max()
        .unwrap_or(0)
        .max(1);
    let sets = max.div_ceil(4);
    let mut out = vec![(vec![[0u16; 4]; n], vec![[0f32; 4]; n]); sets];
    for v in 0..n {
        let (s, x) = w.influences(v);
        if s.is_empty() {
            out[0].1[v][0] = 1.0; // validator: weights must sum to 1; joint 0 with weight 1
            continue;
        }
        for (k, (&j, &wt)) in s.iter().zip(x).enumerate() {
            out[k / 4].0[v][k % 4] = j as u16;
            out[k / 4].1[v][k % 4] = wt;
        }
    }
    out
}

/// Writes a whole scene as `.glb` bytes (float geometry).
///
/// # Errors
/// When a mesh is empty or the result would exceed the GLB size limit.
pub fn write_glb(scene: &Scene) -> Result<Vec<u8>> {
    write_glb_with(scene, GlbOptions::default())
}

/// Writes a whole scene as `.glb` bytes; with `options.quantize`, unskinned meshes are
/// written with `KHR_mesh_quantization`, all with one dequantization, unless the position
/// error would exceed [`MAX_ERROR`](crate::gltf::quantize::MAX_ERROR) of their bounding-box diagonal (see
/// [`GlbOptions`]).
///
/// # Errors
/// When a mesh is empty or the result would exceed the GLB size limit.
pub fn write_glb_with(scene: &Scene, options: GlbOptions) -> Result<Vec<u8>> {
    scene.validate()?;
    let mut b = Builder::new();
    let plan = if options.quantize {
        crate::gltf::quantize::plan(scene)
    } else {
        vec![None; scene.meshes.len()]
    };
    let animated = crate::gltf::quantize::trs_animated(scene);
    let mut meshes = Vec::new();
    for (sm, q) in scene.meshes.iter().zip(&plan) {
        meshes.push(b.mesh_with(sm, *q)?);
    }
    for c in &scene.cameras {
        let cam = match c.projection {
            Projection::Perspective {
                yfov,
                aspect,
                znear,
                zfar,
            } => json::Camera {
                name: Some(c.name.clone()),
                type_: Valid(json::camera::Type::Perspective),
                perspective: Some(json::camera::Perspective {
                    aspect_ratio: aspect,
                    yfov,
                    zfar,
                    znear,
                    extensions: None,
                    extras: Default::default(),
                }),
                orthographic: None,
                extensions: None,
                extras: Default::default(),
            },
            Projection::Orthographic {
                xmag,
                ymag,
                znear,
                zfar,
            } => json::Camera {
                name: Some(c.name.clone()),
                type_: Valid(json::camera::Type::Orthographic),
                orthographic: Some(json::camera::Orthographic {
                    xmag,
                    ymag,
                    zfar,
                    znear,
                    extensions: None,
                    extras: Default::default(),
                }),
                perspective: None,
                extensions: None,
                extras: Default::default(),
            },
        };
        b.root.push(cam);
    }
    for s in &scene.skins {
        let flat: Vec<f32> = s
            .inverse_bind
            .iter()
            .flat_map(Mat4::to_cols_array)
            .collect();
        let ibm = b.floats(&flat, 16, Usage::InverseBind, false);
        b.root.push(json::Skin {
            extensions: None,
            extras: Default::default(),
            inverse_bind_matrices: Some(ibm),
            joints: s
                .joints
                .iter()
                .map(|&j| json::Index::new(j as u32))
                .collect(),
            name: (!s.name.is_empty()).then(|| s.name.clone()),
            skeleton: None,
        });
    }
    // Quantized meshes under a TRS-animated node go on a new child carrying the
    // dequantization (appended after the scene's nodes, so channel targets keep their index).
    let mut extra = Vec::new();
    for (i, n) in scene.nodes.iter().enumerate() {
        let t = n.transform;
        let q = n.mesh.and_then(|m| plan[m]);
        let (translation, rotation, scale, mesh, mut children) = match q {
            Some(q) if animated[i] => {
                extra.push((n.mesh.map(|m| meshes[m]), q, n.name.clone()));
                let child = json::Index::new((scene.nodes.len() + extra.len() - 1) as u32);
                (t.translation, t.rotation, t.scale, None, vec![child])
            }
            Some(q) => {
                let (tt, r, s) = q.fold(t.translation, t.rotation, t.scale);
                (tt, r, s, n.mesh.map(|m| meshes[m]), Vec::new())
            }
            None => (
                t.translation,
                t.rotation,
                t.scale,
                n.mesh.map(|m| meshes[m]),
                Vec::new(),
            ),
        };
        children.splice(0..0, n.children.iter().map(|&c| json::Index::new(c as u32)));
        b.root.push(json::Node {
            camera: n.camera.map(|c| json::Index::new(c as u32)),
            children: (!children.is_empty()).then_some(children),
            mesh,
            name: (!n.name.is_empty()).then(|| n.name.clone()),
            skin: n.skin.map(|s| json::Index::new(s as u32)),
            weights: n.weights.clone(),
            ..trs_node(translation, rotation, scale)
        });
    }
    for (mesh, q, name) in extra {
        b.root.push(json::Node {
            mesh,
            name: (!name.is_empty()).then(|| format!("{name}_quantized")),
            ..trs_node(q.center, Quat::IDENTITY, q.scale)
        });
    }
    let roots = (0..scene.nodes.len()).filter(|&i| scene.nodes[i].parent.is_none());
    let sc = b.root.push(json::Scene {
        extensions: None,
        extras: Default::default(),
        name: None,
        nodes: roots.map(|i| json::Index::new(i as u32)).collect(),
    });
    b.root.scene = Some(sc);
    for clip in &scene.clips {
        write_clip(&mut b, clip);
    }
    b.finish()
}

/// A node with only a translation, rotation and scale (each omitted when it is the identity).
pub(crate) fn trs_node(translation: Vec3, rotation: Quat, scale: Vec3) -> json::Node {
    json::Node {
        camera: None,
        children: None,
        extensions: None,
        extras: Default::default(),
        matrix: None,
        mesh: None,
        name: None,
        rotation: (rotation != Quat::IDENTITY)
            .then(|| json::scene::UnitQuaternion(rotation.normalize().to_array())),
        scale: (scale != Vec3::ONE).then(|| scale.to_array()),
        translation: (translation != Vec3::ZERO).then(|| translation.to_array()),
        skin: None,
        weights: None,
    }
}

pub(crate) fn write_clip(b: &mut Builder, clip: &anim::Clip) {
    if clip.channels.is_empty() {
        return;
    }
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    for ch in &clip.channels {
        let input = b.floats(&ch.times, 1, Usage::AnimationInput, true);
        let comps = match ch.property {
            Property::Weights(_) => 1,
            p => p.components(),
        };
        let output = b.floats(&ch.values, comps, Usage::AnimationOutput, false);
        let interpolation = match ch.interpolation {
            Interpolation::Linear => json::animation::Interpolation::Linear,
            Interpolation::Step => json::animation::Interpolation::Step,
            Interpolation::CubicSpline => json::animation::Interpolation::CubicSpline,
        };
        let sampler = json::Index::new(samplers.len() as u32);
        samplers.push(json::animation::Sampler {
            extensions: None,
            extras: Default::default(),
            input,
            interpolation: Valid(interpolation),
            output,
        });
        let path = match ch.property {
            Property::Translation => json::animation::Property::Translation,
            Property::Rotation => json::animation::Property::Rotation,
            Property::Scale => json::animation::Property::Scale,
            Property::Weights(_) => json::animation::Property::MorphTargetWeights,
        };
        channels.push(json::animation::Channel {
            sampler,
            target: json::animation::Target {
                extensions: None,
                extras: Default::default(),
                node: json::Index::new(ch.node as u32),
                path: Valid(path),
            },
            extensions: None,
            extras: Default::default(),
        });
    }
    b.root.push(json::Animation {
        extensions: None,
        extras: Default::default(),
        channels,
        name: Some(clip.name.clone()),
        samplers,
    });
}

/// A mesh with its own attributes, for flipbook frames.
pub(crate) fn frame_mesh(
    base: &Mesh,
    positions: &[Vec3],
    colors: Option<&[[f32; 4]]>,
) -> SceneMesh {
    let mesh = Mesh {
        name: base.name.clone(),
        positions: positions.to_vec(),
        triangles: base.triangles.clone(),
        polygons: None,
        normals: None,
        uvs: base.uvs.clone(),
        extra_uvs: base.extra_uvs.clone(),
        colors: colors
            .map(<[[f32; 4]]>::to_vec)
            .or_else(|| base.colors.clone()),
        attributes: base.attributes.clone(),
    };
    SceneMesh {
        mesh,
        ..SceneMesh::default()
    }
}
