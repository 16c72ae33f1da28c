//! Quantized glTF output (`KHR_mesh_quantization`): positions and morph deltas as normalized
//! SHORT, normals as normalized BYTE, the dequantization (a uniform scale and a translation)
//! on the node above the mesh. Flipbooks and morph outputs shrink to about half.
//!
//! Per mesh: `c` = centre of its bounding box, `s` = the largest of |p − c| and |delta| over
//! every component, so that `(p − c) / s` and `delta / s` lie in [−1, 1]; the position error
//! is at most `s / 65534` per component (≈ 1.5e-5 of the bounding box; twice that with morph
//! deltas, which are rounded too). The node above the mesh
//! gets the transform `x ↦ c + s·x`: folded into the node's own TRS when the node's transform
//! is not animated (exact: `t' = t + R·S·c`, `S' = S·s`), else on a new child node that
//! carries the mesh. Skinned meshes (the node transform of a skinned mesh is ignored) and
//! morphing meshes on a TRS-animated node stay float.

use anim::glam::{Quat, Vec3};
use anim::{Property, Scene, SceneMesh};

/// The options of the glTF writers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct GlbOptions {
    /// Write mesh geometry with `KHR_mesh_quantization` (about half the bytes).
    pub quantize: bool,
}

/// Options of the quantized outputs of [`crate::save`]: flipbooks and morph targets are
/// quantized by default.
impl GlbOptions {
    /// Quantized geometry.
    pub const QUANTIZED: GlbOptions = GlbOptions { quantize: true };
}

/// The dequantization transform of one mesh: `x ↦ center + scale·x`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Dequant {
    /// Centre of the mesh's bounding box.
    pub center: Vec3,
    /// Largest |p − c| or |delta| component (1 for an empty or flat mesh).
    pub scale: f32,
}

impl Dequant {
    /// The dequantization of `sm`'s positions and morph deltas.
    pub(crate) fn of(sm: &SceneMesh) -> Dequant {
        let finite = sm.mesh.positions.iter().filter(|p| p.is_finite());
        let (lo, hi) = finite.fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let center = if lo.x <= hi.x {
            (lo + hi) * 0.5
        } else {
            Vec3::ZERO
        };
        let mut scale = sm
            .mesh
            .positions
            .iter()
            .filter(|p| p.is_finite())
            .map(|p| (*p - center).abs().max_element())
            .fold(0.0f32, f32::max);
        for t in &sm.morph_targets {
            for d in t.positions.iter().filter(|d| d.is_finite()) {
                scale = scale.max(d.abs().max_element());
            }
        }
        if !(scale.is_finite() && scale > 0.0) {
            scale = 1.0;
        }
        Dequant { center, scale }
    }

    /// Positions mapped into [−1, 1].
    pub(crate) fn encode(&self, p: &[Vec3]) -> Vec<Vec3> {
        p.iter().map(|p| (*p - self.center) / self.scale).collect()
    }

    /// Morph deltas mapped into [−1, 1].
    pub(crate) fn encode_delta(&self, d: &[Vec3]) -> Vec<Vec3> {
        d.iter().map(|d| *d / self.scale).collect()
    }

    /// A node transform `(t, r, s)` with this dequantization below it, as one TRS.
    pub(crate) fn fold(&self, t: Vec3, r: Quat, s: Vec3) -> (Vec3, Quat, Vec3) {
        (t + r * (s * self.center), r, s * self.scale)
    }
}

/// Which meshes of `scene` are written quantized, and how.
pub(crate) fn plan(scene: &Scene) -> Vec<Option<Dequant>> {
    let animated = trs_animated(scene);
    scene
        .meshes
        .iter()
        .enumerate()
        .map(|(m, sm)| {
            let users = scene
                .nodes
                .iter()
                .enumerate()
                .filter(|(_, n)| n.mesh == Some(m));
            let blocked = sm.joint_weights.is_some()
                || users.clone().any(|(_, n)| n.skin.is_some())
                || (!sm.morph_targets.is_empty() && users.clone().any(|(i, _)| animated[i]));
            (!blocked && !sm.mesh.positions.is_empty()).then(|| Dequant::of(sm))
        })
        .collect()
}

/// Whether node `i`'s TRS is animated by some clip of `scene`.
pub(crate) fn trs_animated(scene: &Scene) -> Vec<bool> {
    let mut animated = vec![false; scene.nodes.len()];
    for c in scene.clips.iter().flat_map(|c| &c.channels) {
        if !matches!(c.property, Property::Weights(_)) && c.node < animated.len() {
            animated[c.node] = true;
        }
    }
    animated
}
