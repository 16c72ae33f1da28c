//! Per-vertex joint weights and linear blend skinning.

use glam::{Mat4, Vec3, Vec4};
use rayon::prelude::*;

use crate::{AnimError, Result};

/// Per-vertex joint influences with any number of influences per vertex (compressed rows).
///
/// Joint ids are *slots*: indices into the owning [`Skin::joints`] (or a glTF skin's joint
/// list). Weights are normalized to sum 1 per vertex; a vertex with no positive weight has no
/// influence.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct VertexWeights {
    offsets: Vec<u32>,
    joints: Vec<u32>,
    weights: Vec<f32>,
}

impl VertexWeights {
    /// Builds from per-vertex `(slot, weight)` lists. Non-positive and non-finite weights are
    /// dropped, duplicate slots merged, and each vertex normalized to sum 1.
    pub fn from_influences<I, J>(per_vertex: I) -> VertexWeights
    where
        I: IntoIterator<Item = J>,
        J: IntoIterator<Item = (u32, f32)>,
    {
        let mut w = VertexWeights {
            offsets: vec![0],
            ..Default::default()
        };
        let mut row: Vec<(u32, f32)> = Vec::with_capacity(8);
        for inf in per_vertex {
            row.clear();
            for (j, x) in inf {
                if x.is_finite() && x > 0.0 {
                    match row.iter_mut().find(|(k, _)| *k == j) {
                        Some(e) => e.1 += x,
                        None => row.push((j, x)),
                    }
                }
            }
            let sum: f32 = row.iter().map(|e| e.1).sum();
            for &(j, x) in &row {
                w.joints.push(j);
                w.weights.push(x / sum);
            }
            w.offsets.push(w.joints.len() as u32);
        }
        w
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// The influences `(slots, weights)` of vertex `v`.
    pub fn influences(&self, v: usize) -> (&[u32], &[f32]) {
        let (a, b) = (self.offsets[v] as usize, self.offsets[v + 1] as usize);
        (&self.joints[a..b], &self.weights[a..b])
    }

    /// Largest slot referenced, plus one.
    pub fn slot_count(&self) -> usize {
        self.joints
            .iter()
            .map(|&j| j as usize + 1)
            .max()
            .unwrap_or(0)
    }

    /// Concatenates the vertices of `other` after those of `self`.
    pub fn append(&mut self, other: &VertexWeights) {
        if self.offsets.is_empty() {
            self.offsets.push(0);
        }
        let base = self.joints.len() as u32;
        self.joints.extend_from_slice(&other.joints);
        self.weights.extend_from_slice(&other.weights);
        self.offsets
            .extend(other.offsets.iter().skip(1).map(|o| o + base));
    }

    /// Renames the slots through `map` (slot → new slot).
    pub fn remap(&mut self, map: &[u32]) {
        for j in &mut self.joints {
            *j = map[*j as usize];
        }
    }
}

/// A mesh's binding to a skeleton: joint per slot, inverse bind matrices, weights.
#[derive(Debug, Clone, PartialEq)]
pub struct Skin {
    /// Skeleton joint index of each slot.
    pub joints: Vec<usize>,
    /// Inverse bind matrix of each slot.
    pub inverse_bind: Vec<Mat4>,
    /// Per-vertex influences over slots.
    pub weights: VertexWeights,
}

impl Skin {
    /// Checks slot counts against the joint list and the vertex count.
    pub fn validate(&self, vertices: usize, skeleton_joints: usize) -> Result<()> {
        if self.inverse_bind.len() != self.joints.len() {
            return Err(AnimError::LengthMismatch {
                what: "skin inverse bind matrices".into(),
                expected: self.joints.len(),
                found: self.inverse_bind.len(),
            });
        }
        if self.weights.vertex_count() != vertices {
            return Err(AnimError::LengthMismatch {
                what: "skin weights".into(),
                expected: vertices,
                found: self.weights.vertex_count(),
            });
        }
        if self.weights.slot_count() > self.joints.len() {
            return Err(AnimError::Invalid(format!(
                "skin weights refer to joint slot {} but the skin has {} joints",
                self.weights.slot_count() - 1,
                self.joints.len()
            )));
        }
        if let Some(&j) = self.joints.iter().find(|&&j| j >= skeleton_joints) {
            return Err(AnimError::Invalid(format!(
                "skin joint {j} is not in the skeleton"
            )));
        }
        Ok(())
    }

    /// Skinning matrices for one frame: `world[joint] · inverse_bind`, one per slot.
    pub fn joint_matrices(&self, joint_world: &[Mat4], out: &mut Vec<Mat4>) {
        out.clear();
        out.extend(
            self.joints
                .iter()
                .zip(&self.inverse_bind)
                .map(|(&j, ib)| joint_world[j] * *ib),
        );
    }

    /// Per-vertex skin weights of one skeleton joint (0 where it has no influence).
    pub fn joint_weight(&self, joint: usize, v: usize) -> f32 {
        let (slots, w) = self.weights.influences(v);
        slots
            .iter()
            .zip(w)
            .filter(|(s, _)| self.joints[**s as usize] == joint)
            .map(|(_, w)| w)
            .sum()
    }
}

/// Linear blend skinning: `out[v] = Σ w · M_slot · rest[v]`. Vertices with no influence are
/// left at their rest position.
///
/// # Performance
/// Allocation-free; one pass over the influences. The blend is summed in 4-lane registers
/// (the w lane is dropped at the end): the same per-lane operations, in the same order, as
/// `x * M.transform_point3(p)` summed in a `Vec3`, so the same bits with fewer instructions.
pub fn skin_positions(weights: &VertexWeights, matrices: &[Mat4], rest: &[Vec3], out: &mut [Vec3]) {
    // Consecutive offsets bound each vertex's influences (no per-vertex index into `offsets`).
    let spans = weights.offsets.windows(2);
    for ((p, o), ab) in rest.iter().zip(out.iter_mut()).zip(spans) {
        let (a, b) = (ab[0] as usize, ab[1] as usize);
        let (slots, w) = (&weights.joints[a..b], &weights.weights[a..b]);
        if slots.is_empty() {
            *o = *p;
            continue;
        }
        let mut acc = Vec4::ZERO;
        for (&s, &x) in slots.iter().zip(w) {
            let m = &matrices[s as usize];
            // `Mat4::transform_point3`'s association: W + (Z·z + (Y·y + X·x)).
            let t = m.w_axis + (m.z_axis * p.z + (m.y_axis * p.y + m.x_axis * p.x));
            acc += t * x;
        }
        *o = acc.truncate();
    }
}

/// Linear blend skinning of a whole clip: frame `f` of `out` (frame-major, `rest.len()`
/// vertices per frame) is [`skin_positions`] with the `slots` matrices of frame `f` in
/// `matrices` (frame-major too). This is what a host application that evaluates only the pose
/// (Blender's bone matrices with the mesh's own evaluation off) needs to get the meshes of
/// every frame.
///
/// # Errors
/// [`AnimError::LengthMismatch`] when `weights`, `matrices` or `out` do not fit `rest` and
/// `slots`; [`AnimError::Invalid`] when a weight refers to a slot past `slots`.
///
/// # Performance
/// Parallel over frames, allocation-free: each frame writes its own part of `out`.
pub fn skin_frames(
    weights: &VertexWeights,
    slots: usize,
    matrices: &[Mat4],
    rest: &[Vec3],
    out: &mut [Vec3],
) -> Result<()> {
    let n = rest.len();
    let mismatch = |what: &str, expected: usize, found: usize| {
        Err(AnimError::LengthMismatch {
            what: what.into(),
            expected,
            found,
        })
    };
    if weights.vertex_count() != n {
        return mismatch("skin weights", n, weights.vertex_count());
    }
    if weights.slot_count() > slots {
        return Err(AnimError::Invalid(format!(
            "skin weights refer to joint slot {} but there are {slots} matrices per frame",
            weights.slot_count() - 1
        )));
    }
    let frames = matrices.len().checked_div(slots).unwrap_or(0);
    if frames * slots != matrices.len() {
        return mismatch("skin matrices", frames * slots, matrices.len());
    }
    if out.len() != frames * n {
        return mismatch("skinned positions", frames * n, out.len());
    }
    if n == 0 {
        return Ok(());
    }
    out.par_chunks_mut(n)
        .zip(matrices.par_chunks(slots.max(1)))
        .for_each(|(o, m)| skin_positions(weights, m, rest, o));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_normalize_and_merge() {
        let w = VertexWeights::from_influences(vec![
            vec![(0, 2.0), (1, 2.0), (0, 4.0)],
            vec![(3, f32::NAN)],
        ]);
        let (s, x) = w.influences(0);
        assert_eq!(s, &[0, 1]);
        assert!((x[0] - 0.75).abs() < 1e-6 && (x[1] - 0.25).abs() < 1e-6);
        assert!(w.influences(1).0.is_empty());
    }

    /// The 4-lane blend gives the bits of `Σ x · M.transform_point3(p)` summed in a `Vec3`.
    #[test]
    fn blend_matches_transform_point3_bit_for_bit() {
        let m: Vec<Mat4> = (0..3)
            .map(|i| {
                let f = i as f32 + 1.0;
                Mat4::from_scale_rotation_translation(
                    Vec3::new(1.1 * f, 0.7, 1.3),
                    glam::Quat::from_euler(glam::EulerRot::XYZ, 0.3 * f, -0.7, 1.1 / f),
                    Vec3::new(0.1 * f, -2.3, 0.77),
                )
            })
            .collect();
        let w = VertexWeights::from_influences((0..50).map(|v| match v % 3 {
            0 => vec![(0, 0.3), (1, 0.7)],
            1 => vec![(2, 1.0)],
            _ => vec![(0, 0.2), (1, 0.3), (2, 0.5)],
        }));
        let rest: Vec<Vec3> = (0..50)
            .map(|v| {
                let t = v as f32 * 0.37;
                Vec3::new(t.sin() * 3.1, t.cos() * 0.9, t * 0.013 - 0.2)
            })
            .collect();
        let mut out = vec![Vec3::ZERO; rest.len()];
        skin_positions(&w, &m, &rest, &mut out);
        for (v, (p, o)) in rest.iter().zip(&out).enumerate() {
            let (slots, x) = w.influences(v);
            let mut want = Vec3::ZERO;
            for (&s, &x) in slots.iter().zip(x) {
                want += x * m[s as usize].transform_point3(*p);
            }
            assert_eq!(
                o.to_array().map(f32::to_bits),
                want.to_array().map(f32::to_bits)
            );
        }
    }

    #[test]
    fn blend_of_two_translations_is_halfway() {
        let w = VertexWeights::from_influences(vec![vec![(0, 0.5), (1, 0.5)]]);
        let m = [
            Mat4::from_translation(Vec3::X),
            Mat4::from_translation(Vec3::Y),
        ];
        let mut out = [Vec3::ZERO];
        skin_positions(&w, &m, &[Vec3::ZERO], &mut out);
        assert!(out[0].abs_diff_eq(Vec3::new(0.5, 0.5, 0.0), 1e-6));
    }

    /// Every frame of `skin_frames` is `skin_positions` with that frame's matrices.
    #[test]
    fn skin_frames_is_skin_positions_per_frame() {
        let w = VertexWeights::from_influences((0..7).map(|v| vec![(0, 1.0 + v as f32), (1, 2.0)]));
        let rest: Vec<Vec3> = (0..7).map(|v| Vec3::new(v as f32, 1.0, -0.5)).collect();
        let m: Vec<Mat4> = (0..6)
            .map(|k| {
                Mat4::from_rotation_z(0.3 * k as f32) * Mat4::from_translation(Vec3::X * k as f32)
            })
            .collect();
        let mut out = vec![Vec3::ZERO; 3 * 7];
        skin_frames(&w, 2, &m, &rest, &mut out).unwrap();
        for f in 0..3 {
            let mut want = vec![Vec3::ZERO; 7];
            skin_positions(&w, &m[2 * f..2 * f + 2], &rest, &mut want);
            assert_eq!(&out[7 * f..7 * f + 7], &want[..]);
        }
        assert!(skin_frames(&w, 2, &m, &rest, &mut out[1..]).is_err());
        assert!(skin_frames(&w, 1, &m, &rest, &mut out).is_err());
    }
}
