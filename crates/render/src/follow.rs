//! Views that follow a travelling subject: the same orthographic scale on every frame, centred
//! on the subject's (smoothed) centroid, so a character running across the scene stays large
//! in the frame instead of shrinking to fit the whole path.

use anim::MeshAnimation;
use glam::Vec3;

use crate::{View, ViewDirection};

/// Default half-width, in frames, of the box filter that smooths the followed centre (limbs
/// swinging would otherwise shake the view).
pub const DEFAULT_FOLLOW_SMOOTHING: usize = 3;

/// One orthographic view per frame from `direction`, all with the same scale: frame f frames
/// the box of half-extent `h` around the smoothed centroid c̄_f, where `h` is the largest
/// per-axis distance of any vertex from its frame's c̄_f over the clip.
///
/// # Arguments
/// * `parts` — the animations drawn (same frame count; vertices averaged together).
/// * `smoothing` — half-width in frames of the centroid's box filter (0 = none).
///
/// # Returns
/// One view per frame (one view for a clip with no frame or no vertex).
///
/// # Performance
/// Two passes over the positions.
pub fn follow_views(
    parts: &[&MeshAnimation],
    direction: ViewDirection,
    aspect: f32,
    smoothing: usize,
) -> Vec<View> {
    let frames = parts.iter().map(|a| a.frame_count()).max().unwrap_or(0);
    let centroid = |f: usize| {
        let (mut sum, mut n) = (glam::DVec3::ZERO, 0usize);
        for a in parts.iter().filter(|a| f < a.frame_count()) {
            for p in a.frame(f).iter().filter(|p| p.is_finite()) {
                sum += p.as_dvec3();
                n += 1;
            }
        }
        (n > 0).then(|| (sum / n as f64).as_vec3())
    };
    let raw: Vec<Option<Vec3>> = (0..frames).map(centroid).collect();
    let centres: Vec<Vec3> = (0..frames)
        .map(|f| {
            // A symmetric window (narrower at the clip ends) keeps steady motion centred.
            let k = smoothing.min(f).min(frames - 1 - f);
            let (lo, hi) = (f - k, f + k);
            let known: Vec<Vec3> = raw[lo..=hi].iter().flatten().copied().collect();
            if known.is_empty() {
                Vec3::ZERO
            } else {
                known.iter().sum::<Vec3>() / known.len() as f32
            }
        })
        .collect();
    let mut half = Vec3::ZERO;
    for (f, c) in centres.iter().enumerate() {
        for a in parts.iter().filter(|a| f < a.frame_count()) {
            for p in a.frame(f).iter().filter(|p| p.is_finite()) {
                half = half.max((*p - *c).abs());
            }
        }
    }
    if centres.is_empty() {
        return vec![View::fit(anim::Aabb::EMPTY, direction, aspect)];
    }
    centres
        .iter()
        .map(|&c| {
            let bbox = anim::Aabb {
                min: c - half,
                max: c + half,
            };
            View::fit(bbox, direction, aspect)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim::Mesh;

    #[test]
    fn a_running_subject_stays_centred_and_keeps_its_size() {
        // A unit square travelling 10 units per frame along X: a whole-motion fit would make
        // it 1/90 of the image; following views keep it centred at the same size.
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let mesh = Mesh::new("sq", p.clone(), vec![[0, 1, 2], [0, 2, 3]]);
        let frames = 10;
        let pos = (0..frames)
            .flat_map(|f| p.iter().map(move |q| *q + Vec3::X * 10.0 * f as f32))
            .collect();
        let anim = MeshAnimation::new(mesh, 24.0, pos).unwrap();
        let views = follow_views(&[&anim], ViewDirection::Front, 1.0, 0);
        assert_eq!(views.len(), frames);
        for (f, v) in views.iter().enumerate() {
            let centre = Vec3::new(0.5 + 10.0 * f as f32, 0.5, 0.0);
            let c = v.project(centre, 100, 100).unwrap();
            assert!(
                (c.x - 50.0).abs() < 0.5 && (c.y - 50.0).abs() < 0.5,
                "frame {f}: {c}"
            );
            let corner = v
                .project(centre + Vec3::new(0.5, 0.0, 0.0), 100, 100)
                .unwrap();
            let size = corner.x - c.x;
            assert!(size > 30.0, "frame {f}: half-width {size} px");
        }
        let whole = View::fit(crate::animation_bbox(&anim), ViewDirection::Front, 1.0);
        let a = whole.project(Vec3::ZERO, 100, 100).unwrap();
        let b = whole.project(Vec3::X, 100, 100).unwrap();
        assert!(
            (b.x - a.x) < 2.0,
            "the whole-motion fit is tiny: {}",
            b.x - a.x
        );
        // Smoothing keeps a constant-velocity subject centred (symmetric filter).
        let smooth = follow_views(
            &[&anim],
            ViewDirection::Front,
            1.0,
            DEFAULT_FOLLOW_SMOOTHING,
        );
        for (f, v) in smooth.iter().enumerate() {
            let centre = Vec3::new(0.5 + 10.0 * f as f32, 0.5, 0.0);
            let c = v.project(centre, 100, 100).unwrap();
            assert!((c.x - 50.0).abs() < 0.5, "frame {f}: {c}");
        }
        let corner = smooth[0]
            .project(Vec3::new(1.0, 0.5, 0.0), 100, 100)
            .unwrap();
        assert!(corner.x - 50.0 > 30.0, "no lag at the clip ends");
        assert_eq!(follow_views(&[], ViewDirection::Front, 1.0, 3).len(), 1);
    }
}
