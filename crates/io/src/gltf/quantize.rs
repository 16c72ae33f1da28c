//! Quantized glTF output (`KHR_mesh_quantization`): positions and morph deltas as normalized
//! SHORT, normals as normalized BYTE, the dequantization (a per-axis scale and a translation)
//! on the node above the mesh. Flipbooks and morph outputs shrink to about half.
//!
//! One dequantization `x ↦ c + s ∘ x` covers *every* quantized mesh of one output (all parts,
//! all frames): `c` is the centre of their common bounding box and `s` its per-axis half
//! extent (at least half the largest one, so normals stay well conditioned, and at least
//! every morph delta), so a point that two parts share (a seam) is written as the same
//! integers in both and reads back bit-identical. A position rounds by at most `s_i / 65534`
//! per axis, so by at most `√(Σ s_i²) / 65534 ≤ 9.4e-6` of the bounding-box diagonal; morph
//! deltas are written relative to the *rounded* base, so a target at weight 1 lands within
//! the same bound. The writer measures the error it makes and keeps the output float when it
//! exceeds [`MAX_ERROR`] of the diagonal (large morph deltas).
//!
//! The node above the mesh gets the dequantization: folded into the node's own TRS when the
//! node's transform is not animated (exact: `t' = t + R·(S ∘ c)`, `S' = S ∘ s`), else on a new
//! child node that carries the mesh. Normals are written as `normalize(s ∘ n)` so that the
//! renderer's inverse-transpose of the scale turns them back into `n`. Skinned meshes (the
//! node transform of a skinned mesh is ignored) and morphing meshes on a TRS-animated node
//! stay float.

use anim::glam::{Quat, Vec3};
use anim::{Property, Scene, SceneMesh};

/// Largest position error of quantized output, relative to the diagonal of the bounding box
/// of everything quantized together; above it the output stays float.
pub const MAX_ERROR: f32 = 1e-5;

/// The options of the glTF writers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct GlbOptions {
    /// Write mesh geometry with `KHR_mesh_quantization` (about half the bytes) where the
    /// position error stays within [`MAX_ERROR`] of the bounding-box diagonal.
    pub quantize: bool,
}

impl GlbOptions {
    /// Quantized geometry.
    pub const QUANTIZED: GlbOptions = GlbOptions { quantize: true };
}

/// The largest normalized SHORT.
const SHORT: f32 = 32767.0;

/// The dequantization transform shared by the meshes of one output: `x ↦ center + scale ∘ x`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Dequant {
    /// Centre of the bounding box.
    pub center: Vec3,
    /// Per-axis half extent (raised as the module documentation says; never 0).
    pub scale: Vec3,
}

/// The normalized SHORT a value in [−1, 1] is written as, read back (as `snorm_vec3s` writes).
fn snap(x: f32) -> f32 {
    if x.is_finite() {
        (x * SHORT).round().clamp(-SHORT, SHORT) / SHORT
    } else {
        0.0
    }
}

fn snap3(v: Vec3) -> Vec3 {
    Vec3::new(snap(v.x), snap(v.y), snap(v.z))
}

impl Dequant {
    /// One dequantization covering the positions and morph deltas of `meshes`, with the
    /// diagonal of their common bounding box (over the base and every morph target at weight
    /// 1); `None` when there is no finite position.
    pub(crate) fn covering<'a>(
        meshes: impl Iterator<Item = &'a SceneMesh> + Clone,
    ) -> Option<(Dequant, f32)> {
        // Every shape the meshes take: the base and each morph target at weight 1.
        let points = meshes
            .clone()
            .flat_map(|sm| {
                let base = &sm.mesh.positions;
                let targets = sm
                    .morph_targets
                    .iter()
                    .flat_map(move |t| base.iter().zip(&t.positions).map(|(p, d)| *p + *d));
                base.iter().copied().chain(targets)
            })
            .filter(|p| p.is_finite());
        let (lo, hi) = points.fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(p), hi.max(p)),
        );
        if lo.x > hi.x {
            return None;
        }
        let center = (lo + hi) * 0.5;
        let mut scale = (hi - lo) * 0.5;
        for d in meshes
            .flat_map(|sm| sm.morph_targets.iter())
            .flat_map(|t| t.positions.iter())
            .filter(|d| d.is_finite())
        {
            scale = scale.max(d.abs());
        }
        // At least half the largest axis (normals), a margin for deltas measured from the
        // rounded base (they grow by at most s / 65534), never 0.
        let largest = scale.max_element();
        let largest = if largest.is_finite() && largest > 0.0 {
            largest
        } else {
            1.0
        };
        let scale = scale.max(Vec3::splat(0.5 * largest)) * (1.0 + 1e-4);
        Some((Dequant { center, scale }, (hi - lo).length()))
    }

    /// Positions mapped into [−1, 1].
    pub(crate) fn encode(&self, p: &[Vec3]) -> Vec<Vec3> {
        p.iter().map(|p| (*p - self.center) / self.scale).collect()
    }

    /// A position as it reads back.
    fn decode(&self, p: Vec3) -> Vec3 {
        self.center + self.scale * snap3((p - self.center) / self.scale)
    }

    /// Morph deltas of a mesh with base `base`, relative to the rounded base (so that the
    /// target at weight 1 lands on `base + delta` within the rounding of one value), mapped
    /// into [−1, 1].
    pub(crate) fn encode_delta(&self, base: &[Vec3], d: &[Vec3]) -> Vec<Vec3> {
        base.iter()
            .zip(d)
            .map(|(p, d)| (*p + *d - self.decode(*p)) / self.scale)
            .collect()
    }

    /// Unit normals as written below this dequantization: `normalize(s ∘ n)`.
    pub(crate) fn encode_normals(&self, n: &[Vec3]) -> Vec<Vec3> {
        n.iter()
            .map(|n| (self.scale * *n).try_normalize().unwrap_or(Vec3::Y))
            .collect()
    }

    /// The largest distance between a position (base, and each morph target at weight 1)
    /// and what a reader gets back.
    pub(crate) fn error(&self, sm: &SceneMesh) -> f32 {
        let base = &sm.mesh.positions;
        let mut worst = base
            .iter()
            .map(|p| p.distance(self.decode(*p)))
            .fold(0.0f32, f32::max);
        for t in &sm.morph_targets {
            let encoded = self.encode_delta(base, &t.positions);
            for ((p, d), e) in base.iter().zip(&t.positions).zip(encoded) {
                let back = self.decode(*p) + self.scale * snap3(e);
                worst = worst.max((*p + *d).distance(back));
            }
        }
        worst
    }

    /// `Some(self)` when every mesh reads back within [`MAX_ERROR`] of `diagonal`.
    pub(crate) fn checked<'a>(
        self,
        diagonal: f32,
        meshes: impl Iterator<Item = &'a SceneMesh>,
    ) -> Option<Dequant> {
        let limit = MAX_ERROR * diagonal;
        let mut worst = 0.0f32;
        for sm in meshes {
            worst = worst.max(self.error(sm));
            if worst.is_nan() || worst > limit {
                return None;
            }
        }
        Some(self)
    }

    /// The dequantization of `meshes` when their error stays within bounds.
    pub(crate) fn shared<'a>(
        meshes: impl Iterator<Item = &'a SceneMesh> + Clone,
    ) -> Option<Dequant> {
        let (q, diagonal) = Dequant::covering(meshes.clone())?;
        q.checked(diagonal, meshes)
    }

    /// A node transform `(t, r, s)` with this dequantization below it, as one TRS.
    pub(crate) fn fold(&self, t: Vec3, r: Quat, s: Vec3) -> (Vec3, Quat, Vec3) {
        (t + r * (s * self.center), r, s * self.scale)
    }
}

/// Which meshes of `scene` are written quantized: every mesh that can be (not skinned, no
/// morph targets under a TRS-animated node), all with one shared dequantization, or none
/// when the error would exceed [`MAX_ERROR`].
pub(crate) fn plan(scene: &Scene) -> Vec<Option<Dequant>> {
    let animated = trs_animated(scene);
    let eligible: Vec<bool> = scene
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
            !blocked && !sm.mesh.positions.is_empty()
        })
        .collect();
    let chosen = scene
        .meshes
        .iter()
        .zip(&eligible)
        .filter(|(_, &e)| e)
        .map(|(sm, _)| sm);
    let q = Dequant::shared(chosen);
    eligible.iter().map(|&e| if e { q } else { None }).collect()
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

#[cfg(test)]
mod tests {
    use super::*;
    use anim::{Mesh, MorphTarget};

    fn mesh(points: Vec<Vec3>) -> SceneMesh {
        SceneMesh {
            mesh: Mesh::new("m", points, Vec::new()),
            ..SceneMesh::default()
        }
    }

    #[test]
    fn two_meshes_share_one_range_and_read_back_within_the_bound() {
        let a = mesh(
            (0..500)
                .map(|i| Vec3::new(i as f32 * 0.013, 0.7, 0.2))
                .collect(),
        );
        let b = mesh(
            (0..500)
                .map(|i| Vec3::new(2.0, i as f32 * 0.0071, -1.0))
                .collect(),
        );
        let (q, diagonal) = Dequant::covering([&a, &b].into_iter()).unwrap();
        let q = q.checked(diagonal, [&a, &b].into_iter()).unwrap();
        let worst = q.error(&a).max(q.error(&b));
        assert!(
            worst > 0.0 && worst <= 9.4e-6 * diagonal,
            "{worst} of {diagonal}"
        );
    }

    #[test]
    fn deltas_are_measured_from_the_rounded_base() {
        let mut sm = mesh(vec![Vec3::ZERO, Vec3::ONE, Vec3::new(0.3, 0.9, 0.1)]);
        sm.morph_targets.push(MorphTarget {
            name: "t".into(),
            positions: vec![Vec3::splat(0.5), Vec3::new(-0.2, 0.0, 0.1), Vec3::ZERO],
        });
        let (q, diagonal) = Dequant::covering([&sm].into_iter()).unwrap();
        assert!(q.error(&sm) <= 9.4e-6 * diagonal, "{}", q.error(&sm));
        // A delta larger than the half extent widens the range.
        assert!(q.scale.x >= 0.5);
    }

    #[test]
    fn normals_come_back_through_the_inverse_transpose() {
        let q = Dequant {
            center: Vec3::ZERO,
            scale: Vec3::new(2.0, 1.0, 1.5),
        };
        let n = Vec3::new(0.3, 0.8, -0.52).normalize();
        let written = q.encode_normals(&[n])[0];
        let rendered = (written / q.scale).normalize();
        assert!(rendered.distance(n) < 1e-6);
    }
}
