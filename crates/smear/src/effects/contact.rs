//! Contact-aware smears (issue #22): a ground plane that elongated and multiple in-betweens
//! never cross (enforced along the trajectories, see [`Trajectories`](super::Trajectories)),
//! and an optional volume-preserving squash-and-stretch when the object lands on it.

use anim::{Aabb, MeshAnimation};
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Default number of frames a squash lasts.
pub const DEFAULT_SQUASH_FRAMES: usize = 4;

/// Largest squash amount (the height never scales below 1 − this).
pub const MAX_SQUASH: f32 = 0.9;

/// A ground plane `y = ground` (Y-up) and the squash-and-stretch on impact.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ContactStyle {
    /// Height of the ground plane (Y up): in a [`Style`](crate::Style), size units (one unit
    /// = the character's bounding-box diagonal) or scene units with `speed_units = "scene"`;
    /// scene units once compiled.
    pub ground: f32,
    /// Squash on impact: the height scales by `1 − squash` at the impact frame (widths by
    /// `1/√(1 − squash)`, so the volume is kept), easing back over `squash_frames`. 0 = off.
    pub squash: f32,
    /// Frames the squash lasts.
    pub squash_frames: usize,
}

impl Default for ContactStyle {
    fn default() -> Self {
        ContactStyle {
            ground: 0.0,
            squash: 0.0,
            squash_frames: DEFAULT_SQUASH_FRAMES,
        }
    }
}

/// One frame's squash: heights above the ground scale by `s`, horizontal distances to
/// `centre` by `1/√s` (determinant 1: volume preserved).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Squash {
    /// Horizontal centre of the scaling (the object's centroid at that frame).
    pub centre: Vec3,
    /// Height scale s ∈ (0, 1].
    pub scale: f32,
}

impl Squash {
    /// Applies the squash to points, about the ground plane `y = ground`.
    pub fn apply(&self, ground: f32, points: &mut [Vec3]) {
        let w = 1.0 / self.scale.sqrt();
        for p in points {
            p.x = self.centre.x + (p.x - self.centre.x) * w;
            p.z = self.centre.z + (p.z - self.centre.z) * w;
            p.y = ground + (p.y - ground) * self.scale;
        }
    }
}

/// The squash of every frame of `input` (`None`: none). An impact is a frame where the
/// object's lowest point arrives within 1 % of its size of the ground while its centroid moves
/// down; the squash is `1 − amount` there and eases back linearly over `frames` frames.
/// Frame f depends on frames ≤ f only (it works in causal mode).
pub fn squash_frames(input: &MeshAnimation, style: &ContactStyle) -> Vec<Option<Squash>> {
    let n = input.frame_count();
    let mut out = vec![None; n];
    let amount = style.squash.clamp(0.0, MAX_SQUASH);
    if amount <= 0.0 || style.squash_frames == 0 || input.vertex_count() == 0 {
        return out;
    }
    let eps = 0.01 * Aabb::from_points(input.frame(0)).diagonal();
    let low = |f: usize| input.frame(f).iter().fold(f32::INFINITY, |m, p| m.min(p.y));
    let centre =
        |f: usize| input.frame(f).iter().copied().sum::<Vec3>() / input.vertex_count() as f32;
    for f in 1..n {
        let arrives = low(f) <= style.ground + eps && low(f - 1) > style.ground + eps;
        if !(arrives && centre(f).y < centre(f - 1).y) {
            continue;
        }
        for k in 0..style.squash_frames.min(n - f) {
            let ease = 1.0 - k as f32 / style.squash_frames as f32;
            out[f + k] = Some(Squash {
                centre: centre(f + k),
                scale: 1.0 - amount * ease,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::test_util::ball;

    /// Signed volume of a closed mesh (divergence theorem).
    fn volume(p: &[Vec3], tris: &[[u32; 3]]) -> f32 {
        tris.iter()
            .map(|t| p[t[0] as usize].dot(p[t[1] as usize].cross(p[t[2] as usize])) / 6.0)
            .sum()
    }

    #[test]
    fn a_landing_ball_squashes_and_keeps_its_volume() {
        // A unit ball falling onto y = 0 and resting there from frame 4.
        let mesh = ball(1.0, 8, 12);
        let heights = [4.0f32, 3.0, 2.0, 1.4, 1.0, 1.0, 1.0, 1.0, 1.0];
        let frames: Vec<Vec3> = heights
            .iter()
            .flat_map(|h| mesh.positions.iter().map(move |p| *p + Vec3::Y * *h))
            .collect();
        let anim = MeshAnimation::new(mesh.clone(), 24.0, frames).unwrap();
        let style = ContactStyle {
            squash: 0.3,
            ..ContactStyle::default()
        };
        let sq = squash_frames(&anim, &style);
        assert!(sq[..4].iter().all(Option::is_none));
        assert!((sq[4].unwrap().scale - 0.7).abs() < 1e-6);
        assert!(sq[5].unwrap().scale > sq[4].unwrap().scale);
        assert!(sq[8].is_none());
        let mut p = anim.frame(4).to_vec();
        let before = volume(&p, &mesh.triangles);
        sq[4].unwrap().apply(0.0, &mut p);
        let after = volume(&p, &mesh.triangles);
        assert!(
            (after - before).abs() < 1e-4 * before.abs(),
            "{before} → {after}"
        );
        let bb = Aabb::from_points(&p);
        assert!(bb.min.y >= -1e-6 && (bb.max.y - 1.4).abs() < 1e-3, "{bb:?}");
        // Off by default.
        assert!(squash_frames(&anim, &ContactStyle::default())
            .iter()
            .all(Option::is_none));
    }
}
