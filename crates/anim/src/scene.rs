//! The scene data model: a node hierarchy with meshes, morph targets, skins, cameras and
//! clips. It mirrors glTF 2.0 so that every reader and writer maps onto it directly.

use glam::{Mat4, Vec3};

use crate::{AnimError, Clip, Mesh, Projection, Result, Skeleton, Transform, VertexWeights};

/// A node of the hierarchy.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Node {
    /// Node name (may be empty).
    pub name: String,
    /// Parent node.
    pub parent: Option<usize>,
    /// Child nodes.
    pub children: Vec<usize>,
    /// Rest local transform.
    pub transform: Transform,
    /// Mesh drawn at this node.
    pub mesh: Option<usize>,
    /// Skin deforming that mesh.
    pub skin: Option<usize>,
    /// Camera at this node.
    pub camera: Option<usize>,
    /// Morph weights overriding the mesh's defaults.
    pub weights: Option<Vec<f32>>,
}

/// A morph target: per-vertex position displacements.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MorphTarget {
    /// Target name.
    pub name: String,
    /// Displacement of every vertex.
    pub positions: Vec<Vec3>,
}

/// A mesh as stored in a scene: geometry (all primitives merged), morph targets, and the
/// joint influences used when a node skins it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SceneMesh {
    /// Geometry in the mesh's own (bind) space.
    pub mesh: Mesh,
    /// Morph targets.
    pub morph_targets: Vec<MorphTarget>,
    /// Default morph weights (one per target).
    pub default_weights: Vec<f32>,
    /// Joint influences over the skin's joint slots.
    pub joint_weights: Option<VertexWeights>,
}

/// A skin: which nodes are joints and their inverse bind matrices.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SkinDef {
    /// Skin name.
    pub name: String,
    /// Joint nodes, one per slot.
    pub joints: Vec<usize>,
    /// Inverse bind matrix per slot.
    pub inverse_bind: Vec<Mat4>,
    /// The skeleton root the file names (glTF `skin.skeleton`): the inverse bind matrices
    /// are relative to it (to its parent when it is a joint). `None` when the file names none.
    pub skeleton: Option<usize>,
}

/// A camera as stored in a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneCamera {
    /// Camera name.
    pub name: String,
    /// Projection.
    pub projection: Projection,
}

/// A whole animated scene.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Scene {
    /// All nodes.
    pub nodes: Vec<Node>,
    /// Meshes.
    pub meshes: Vec<SceneMesh>,
    /// Skins.
    pub skins: Vec<SkinDef>,
    /// Cameras.
    pub cameras: Vec<SceneCamera>,
    /// Animation clips.
    pub clips: Vec<Clip>,
}

impl Scene {
    /// Checks that every index is in range, the hierarchy has no cycle, meshes are valid,
    /// and clip channels match their targets.
    pub fn validate(&self) -> Result<()> {
        let n = self.nodes.len();
        for (i, node) in self.nodes.iter().enumerate() {
            let bad = |what: &str, idx: usize| {
                AnimError::Invalid(format!(
                    "node {i} ('{}') refers to missing {what} {idx}",
                    node.name
                ))
            };
            if let Some(p) = node.parent.filter(|&p| p >= n) {
                return Err(bad("parent", p));
            }
            if let Some(&c) = node.children.iter().find(|&&c| c >= n) {
                return Err(bad("child", c));
            }
            if let Some(m) = node.mesh.filter(|&m| m >= self.meshes.len()) {
                return Err(bad("mesh", m));
            }
            if let Some(s) = node.skin.filter(|&s| s >= self.skins.len()) {
                return Err(bad("skin", s));
            }
            if let Some(c) = node.camera.filter(|&c| c >= self.cameras.len()) {
                return Err(bad("camera", c));
            }
            if let (Some(s), Some(m)) = (node.skin, node.mesh) {
                let skin = &self.skins[s];
                match &self.meshes[m].joint_weights {
                    Some(w) if w.slot_count() <= skin.joints.len() => {}
                    Some(_) => {
                        return Err(AnimError::Invalid(format!(
                            "mesh of node '{}' uses more joints than its skin has",
                            node.name
                        )))
                    }
                    None => {
                        return Err(AnimError::Invalid(format!(
                            "node '{}' has a skin but its mesh has no joint weights",
                            node.name
                        )))
                    }
                }
            }
        }
        if self.topological_order().len() != n {
            return Err(AnimError::Invalid("the node hierarchy has a cycle".into()));
        }
        for (k, m) in self.meshes.iter().enumerate() {
            m.mesh.validate()?;
            let nv = m.mesh.vertex_count();
            for t in &m.morph_targets {
                if t.positions.len() != nv {
                    return Err(AnimError::LengthMismatch {
                        what: format!("morph target '{}' of mesh {k}", t.name),
                        expected: nv,
                        found: t.positions.len(),
                    });
                }
                if !t.positions.iter().all(|p| p.is_finite()) {
                    return Err(AnimError::NonFinite {
                        what: format!("morph target '{}'", t.name),
                    });
                }
            }
            if let Some(w) = &m.joint_weights {
                if w.vertex_count() != nv {
                    return Err(AnimError::LengthMismatch {
                        what: format!("joint weights of mesh {k}"),
                        expected: nv,
                        found: w.vertex_count(),
                    });
                }
            }
        }
        for s in &self.skins {
            if s.inverse_bind.len() != s.joints.len() || s.joints.iter().any(|&j| j >= n) {
                return Err(AnimError::Invalid(format!(
                    "skin '{}' is inconsistent",
                    s.name
                )));
            }
            if !s.inverse_bind.iter().all(|m| m.is_finite()) {
                return Err(AnimError::NonFinite {
                    what: format!("skin '{}' inverse bind matrices", s.name),
                });
            }
        }
        for c in &self.clips {
            for ch in &c.channels {
                if ch.node >= n {
                    return Err(AnimError::Invalid(format!(
                        "clip '{}' animates missing node {}",
                        c.name, ch.node
                    )));
                }
                ch.validate()
                    .map_err(|e| AnimError::Invalid(format!("clip '{}': {e}", c.name)))?;
            }
        }
        Ok(())
    }

    /// Nodes in parent-first order (roots first). Nodes on a cycle are left out.
    pub fn topological_order(&self) -> Vec<usize> {
        let mut order = Vec::with_capacity(self.nodes.len());
        let mut stack: Vec<usize> = (0..self.nodes.len())
            .filter(|&i| self.nodes[i].parent.is_none())
            .rev()
            .collect();
        let mut seen = vec![false; self.nodes.len()];
        while let Some(i) = stack.pop() {
            if std::mem::replace(&mut seen[i], true) {
                continue;
            }
            order.push(i);
            for &c in self.nodes[i].children.iter().rev() {
                if c < self.nodes.len() && !seen[c] && self.nodes[c].parent == Some(i) {
                    stack.push(c);
                }
            }
        }
        order
    }

    /// Index of the clip named `name`, or with that decimal index.
    pub fn find_clip(&self, name: &str) -> Result<usize> {
        if let Some(i) = self.clips.iter().position(|c| c.name == name) {
            return Ok(i);
        }
        match name.parse::<usize>() {
            Ok(i) if i < self.clips.len() => Ok(i),
            _ => Err(AnimError::NotFound {
                kind: "clip",
                name: name.to_string(),
                available: self
                    .clips
                    .iter()
                    .map(|c| c.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            }),
        }
    }

    /// Nodes that draw a mesh, in parent-first order.
    pub fn mesh_nodes(&self) -> Vec<usize> {
        self.topological_order()
            .into_iter()
            .filter(|&i| self.nodes[i].mesh.is_some())
            .collect()
    }

    /// Display name of a mesh node: the node's name, else the mesh's, else `mesh<N>`.
    pub fn object_name(&self, node: usize) -> String {
        let n = &self.nodes[node];
        if !n.name.is_empty() {
            return n.name.clone();
        }
        match n.mesh {
            Some(m) if !self.meshes[m].mesh.name.is_empty() => self.meshes[m].mesh.name.clone(),
            _ => format!("node{node}"),
        }
    }

    /// Evaluates local transforms and morph weights of every node at time `t` of `clip`.
    pub fn pose_at(
        &self,
        clip: Option<&Clip>,
        t: f32,
        locals: &mut Vec<Transform>,
        weights: &mut Vec<Vec<f32>>,
    ) {
        locals.clear();
        locals.extend(self.nodes.iter().map(|n| n.transform));
        weights.clear();
        weights.extend(self.nodes.iter().map(|n| self.rest_weights(n)));
        if let Some(c) = clip {
            for ch in &c.channels {
                ch.apply(t, &mut locals[ch.node], &mut weights[ch.node]);
            }
        }
    }

    fn rest_weights(&self, n: &Node) -> Vec<f32> {
        match (n.mesh, &n.weights) {
            (Some(m), Some(w)) if w.len() == self.meshes[m].morph_targets.len() => w.clone(),
            (Some(m), _) => {
                let sm = &self.meshes[m];
                let mut w = sm.default_weights.clone();
                w.resize(sm.morph_targets.len(), 0.0);
                w
            }
            (None, Some(w)) => w.clone(),
            (None, None) => Vec::new(),
        }
    }

    /// World matrices from local transforms, using a precomputed parent-first order.
    pub fn world_matrices(&self, order: &[usize], locals: &[Transform], out: &mut Vec<Mat4>) {
        out.clear();
        out.resize(self.nodes.len(), Mat4::IDENTITY);
        for &i in order {
            let l = locals[i].matrix();
            out[i] = match self.nodes[i].parent {
                Some(p) => out[p] * l,
                None => l,
            };
        }
    }

    /// The joints used by any skin (plus their ancestors, so that the hierarchy is closed),
    /// as a skeleton; also returns the node of each joint.
    pub fn skeleton(&self) -> (Skeleton, Vec<usize>) {
        let mut is_joint = vec![false; self.nodes.len()];
        for s in &self.skins {
            for &j in &s.joints {
                is_joint[j] = true;
            }
        }
        // Close over ancestors that lie between joints (a joint's ancestors up to the
        // topmost joint ancestor).
        for i in 0..self.nodes.len() {
            if !is_joint[i] {
                continue;
            }
            let mut path = Vec::new();
            let mut p = self.nodes[i].parent;
            while let Some(q) = p {
                if is_joint[q] {
                    for &x in &path {
                        is_joint[x] = true;
                    }
                    break;
                }
                path.push(q);
                p = self.nodes[q].parent;
            }
        }
        let order = self.topological_order();
        let nodes: Vec<usize> = order.into_iter().filter(|&i| is_joint[i]).collect();
        let mut index = vec![usize::MAX; self.nodes.len()];
        for (k, &n) in nodes.iter().enumerate() {
            index[n] = k;
        }
        let order = self.topological_order();
        let mut locals = Vec::new();
        let mut weights = Vec::new();
        let mut rest_world = Vec::new();
        self.pose_at(None, 0.0, &mut locals, &mut weights);
        self.world_matrices(&order, &locals, &mut rest_world);
        let joints = nodes
            .iter()
            .map(|&n| {
                let node = &self.nodes[n];
                let mut p = node.parent;
                while let Some(q) = p {
                    if index[q] != usize::MAX {
                        break;
                    }
                    p = self.nodes[q].parent;
                }
                // A root joint absorbs the transforms of its non-joint ancestors.
                let bind_local = match p {
                    Some(_) => node.transform,
                    None => Transform::from_matrix(rest_world[n]),
                };
                crate::Joint {
                    name: if node.name.is_empty() {
                        format!("joint{n}")
                    } else {
                        node.name.clone()
                    },
                    parent: p.map(|q| index[q]),
                    bind_local,
                }
            })
            .collect();
        (Skeleton { joints }, nodes)
    }

    /// Total morph targets over all meshes.
    pub fn morph_target_count(&self) -> usize {
        self.meshes.iter().map(|m| m.morph_targets.len()).sum()
    }
}
