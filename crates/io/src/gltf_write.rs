//! glTF 2.0 binary (`.glb`) writer: a whole [`anim::Scene`] (nodes, meshes with morph targets
//! and skins, cameras, clips). Writing is building `gltf-json` structures; the binary chunk
//! holds tightly packed, 4-byte aligned buffer views with correct accessor bounds, so that
//! the Khronos validator accepts every file.

use std::borrow::Cow;

use anim::glam::{Mat4, Quat, Vec3};
use anim::{Interpolation, Mesh, Projection, Property, Scene, SceneMesh, VertexWeights};
use gltf_json as json;
use json::validation::Checked::Valid;
use json::validation::USize64;
use serde_json::json as js;

use crate::{IoError, Result};

/// Where a buffer view is bound (vertex attributes or indices).
#[derive(Clone, Copy)]
pub(crate) enum Bind {
    Vertex,
    Index,
    None,
}

/// Accumulates a glTF document and its binary chunk.
pub(crate) struct Builder {
    pub root: json::Root,
    bin: Vec<u8>,
    opaque: Option<json::Index<json::Material>>,
    blend: Option<json::Index<json::Material>>,
}

impl Builder {
    pub fn new() -> Builder {
        let mut root = json::Root::default();
        root.asset.generator = Some(format!("toonkit {}", env!("CARGO_PKG_VERSION")));
        root.buffers.push(json::Buffer {
            byte_length: USize64(0),
            name: None,
            uri: None,
            extensions: None,
            extras: Default::default(),
        });
        Builder {
            root,
            bin: Vec::new(),
            opaque: None,
            blend: None,
        }
    }

    fn view(&mut self, bytes: &[u8], bind: Bind) -> json::Index<json::buffer::View> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        let target = match bind {
            Bind::Vertex => Some(Valid(json::buffer::Target::ArrayBuffer)),
            Bind::Index => Some(Valid(json::buffer::Target::ElementArrayBuffer)),
            Bind::None => None,
        };
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64(bytes.len() as u64),
            byte_offset: Some(USize64(offset as u64)),
            byte_stride: None,
            name: None,
            target,
            extensions: None,
            extras: Default::default(),
        })
    }

    #[allow(clippy::too_many_arguments)]
    fn accessor(
        &mut self,
        bytes: &[u8],
        count: usize,
        ty: json::accessor::Type,
        component: json::accessor::ComponentType,
        bind: Bind,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
        normalized: bool,
    ) -> json::Index<json::Accessor> {
        let view = self.view(bytes, bind);
        let (min, max) = match bounds {
            Some((a, b)) => (Some(js!(a)), Some(js!(b))),
            None => (None, None),
        };
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64(count as u64),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(ty),
            min,
            max,
            name: None,
            normalized,
            sparse: None,
        })
    }

    /// Float accessor of `n`-component items, with min/max bounds when asked.
    pub fn floats(
        &mut self,
        data: &[f32],
        n: usize,
        bind: Bind,
        bounds: bool,
    ) -> json::Index<json::Accessor> {
        use json::accessor::Type;
        let ty = match n {
            1 => Type::Scalar,
            2 => Type::Vec2,
            3 => Type::Vec3,
            4 => Type::Vec4,
            _ => Type::Mat4,
        };
        let b = bounds.then(|| {
            let mut lo = vec![f32::INFINITY; n];
            let mut hi = vec![f32::NEG_INFINITY; n];
            for item in data.chunks_exact(n) {
                for k in 0..n {
                    lo[k] = lo[k].min(item[k]);
                    hi[k] = hi[k].max(item[k]);
                }
            }
            (lo, hi)
        });
        let bytes: Vec<u8> = data.iter().flat_map(|f| f.to_le_bytes()).collect();
        self.accessor(
            &bytes,
            data.len() / n,
            ty,
            json::accessor::ComponentType::F32,
            bind,
            b,
            false,
        )
    }

    pub fn vec3s(&mut self, data: &[Vec3], bounds: bool) -> json::Index<json::Accessor> {
        let flat: Vec<f32> = data.iter().flat_map(|v| v.to_array()).collect();
        self.floats(&flat, 3, Bind::Vertex, bounds)
    }

    pub fn indices(&mut self, tris: &[[u32; 3]]) -> json::Index<json::Accessor> {
        let bytes: Vec<u8> = tris
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        use json::accessor::{ComponentType, Type};
        self.accessor(
            &bytes,
            tris.len() * 3,
            Type::Scalar,
            ComponentType::U32,
            Bind::Index,
            None,
            false,
        )
    }

    fn joints(&mut self, data: &[[u16; 4]]) -> json::Index<json::Accessor> {
        let bytes: Vec<u8> = data
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        use json::accessor::{ComponentType, Type};
        self.accessor(
            &bytes,
            data.len(),
            Type::Vec4,
            ComponentType::U16,
            Bind::Vertex,
            None,
            false,
        )
    }

    /// The shared material: opaque, or alpha-blended for translucent vertex colours.
    pub fn material(&mut self, blend: bool) -> json::Index<json::Material> {
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

    /// Adds a mesh; `shared` carries index/uv accessors reused across meshes with the same
    /// topology (flipbooks).
    pub fn mesh(
        &mut self,
        sm: &SceneMesh,
        shared: &mut SharedTopology,
    ) -> Result<json::Index<json::Mesh>> {
        let m = &sm.mesh;
        if m.vertex_count() == 0 {
            return Err(IoError::unsupported(format!(
                "mesh '{}' has no vertex",
                m.name
            )));
        }
        let mut attributes = std::collections::BTreeMap::new();
        let pos = self.vec3s(&m.positions, true);
        attributes.insert(Valid(json::mesh::Semantic::Positions), pos);
        let normals = match &m.normals {
            Some(n) => n
                .iter()
                .map(|v| v.try_normalize().unwrap_or(Vec3::Y))
                .collect(),
            None => m.vertex_normals(&m.positions),
        };
        let nrm = self.vec3s(&normals, false);
        attributes.insert(Valid(json::mesh::Semantic::Normals), nrm);
        if let Some(uv) = &m.uvs {
            let acc = match shared.uvs.filter(|_| shared.uv_data.as_ref() == Some(uv)) {
                Some(a) => a,
                None => {
                    let flat: Vec<f32> = uv.iter().flatten().copied().collect();
                    let a = self.floats(&flat, 2, Bind::Vertex, false);
                    shared.uvs = Some(a);
                    shared.uv_data = Some(uv.clone());
                    a
                }
            };
            attributes.insert(Valid(json::mesh::Semantic::TexCoords(0)), acc);
        }
        let mut blend = false;
        if let Some(c) = &m.colors {
            let flat: Vec<f32> = c
                .iter()
                .flat_map(|v| v.map(|x| x.clamp(0.0, 1.0)))
                .collect();
            blend = c.iter().any(|v| v[3] < 1.0);
            let acc = self.floats(&flat, 4, Bind::Vertex, false);
            attributes.insert(Valid(json::mesh::Semantic::Colors(0)), acc);
        }
        if let Some(w) = &sm.joint_weights {
            for (set, (j, x)) in split_influences(w).into_iter().enumerate() {
                let ja = self.joints(&j);
                let flat: Vec<f32> = x.iter().flatten().copied().collect();
                let wa = self.floats(&flat, 4, Bind::Vertex, false);
                attributes.insert(Valid(json::mesh::Semantic::Joints(set as u32)), ja);
                attributes.insert(Valid(json::mesh::Semantic::Weights(set as u32)), wa);
            }
        }
        let (mode, indices) = if m.triangles.is_empty() {
            (json::mesh::Mode::Points, None)
        } else {
            let acc = match shared
                .indices
                .filter(|_| shared.index_data.as_ref() == Some(&m.triangles))
            {
                Some(a) => a,
                None => {
                    let a = self.indices(&m.triangles);
                    shared.indices = Some(a);
                    shared.index_data = Some(m.triangles.clone());
                    a
                }
            };
            (json::mesh::Mode::Triangles, Some(acc))
        };
        let targets = (!sm.morph_targets.is_empty()).then(|| {
            sm.morph_targets
                .iter()
                .map(|t| json::mesh::MorphTarget {
                    positions: Some(self.vec3s(&t.positions, true)),
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

    /// Serializes to GLB bytes.
    pub fn finish(mut self) -> Result<Vec<u8>> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        if self.bin.is_empty() {
            self.root.buffers.clear();
        } else {
            self.root.buffers[0].byte_length = USize64(self.bin.len() as u64);
        }
        let json = json::serialize::to_vec(&self.root)
            .map_err(|e| IoError::unsupported(format!("cannot serialize glTF: {e}")))?;
        if self.bin.len() + json.len() > u32::MAX as usize - 64 {
            return Err(IoError::unsupported(
                "the result exceeds the 4 GiB limit of a .glb file",
            ));
        }
        let glb = gltf::binary::Glb {
            header: gltf::binary::Header {
                magic: *b"glTF",
                version: 2,
                length: 0,
            },
            json: Cow::Owned(json),
            bin: (!self.bin.is_empty()).then_some(Cow::Owned(self.bin)),
        };
        glb.to_vec()
            .map_err(|e| IoError::unsupported(format!("cannot write GLB: {e}")))
    }
}

/// Index and UV accessors of the last written topology, reused when identical.
#[derive(Default)]
pub(crate) struct SharedTopology {
    indices: Option<json::Index<json::Accessor>>,
    index_data: Option<Vec<[u32; 3]>>,
    uvs: Option<json::Index<json::Accessor>>,
    uv_data: Option<Vec<[f32; 2]>>,
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

/// Writes a whole scene as `.glb` bytes.
///
/// # Errors
/// When a mesh is empty or the result would exceed the GLB size limit.
pub fn write_glb(scene: &Scene) -> Result<Vec<u8>> {
    scene.validate()?;
    let mut b = Builder::new();
    let mut shared = SharedTopology::default();
    let mut meshes = Vec::new();
    for sm in &scene.meshes {
        meshes.push(b.mesh(sm, &mut shared)?);
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
        let ibm = b.floats(&flat, 16, Bind::None, false);
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
    for n in &scene.nodes {
        let t = n.transform;
        b.root.push(json::Node {
            camera: n.camera.map(|c| json::Index::new(c as u32)),
            children: (!n.children.is_empty()).then(|| {
                n.children
                    .iter()
                    .map(|&c| json::Index::new(c as u32))
                    .collect()
            }),
            extensions: None,
            extras: Default::default(),
            matrix: None,
            mesh: n.mesh.map(|m| meshes[m]),
            name: (!n.name.is_empty()).then(|| n.name.clone()),
            rotation: (t.rotation != Quat::IDENTITY)
                .then(|| json::scene::UnitQuaternion(t.rotation.normalize().to_array())),
            scale: (t.scale != Vec3::ONE).then(|| t.scale.to_array()),
            translation: (t.translation != Vec3::ZERO).then(|| t.translation.to_array()),
            skin: n.skin.map(|s| json::Index::new(s as u32)),
            weights: n.weights.clone(),
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

pub(crate) fn write_clip(b: &mut Builder, clip: &anim::Clip) {
    if clip.channels.is_empty() {
        return;
    }
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    for ch in &clip.channels {
        let input = b.floats(&ch.times, 1, Bind::None, true);
        let comps = match ch.property {
            Property::Weights(_) => 1,
            p => p.components(),
        };
        let output = b.floats(&ch.values, comps, Bind::None, false);
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
        colors: colors
            .map(<[[f32; 4]]>::to_vec)
            .or_else(|| base.colors.clone()),
    };
    SceneMesh {
        mesh,
        ..SceneMesh::default()
    }
}
