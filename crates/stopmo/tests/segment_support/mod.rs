//! Synthetic animations for the segmentation tests: an open cylinder ("face") whose seam
//! column is duplicated as glTF does along UV seams, with a "jaw" below and a "brow" above a
//! still ring.
#![allow(dead_code)]

use anim::{Mesh, MeshAnimation};
use glam::Vec3;

/// Height of the still ring of [`talking_tube`].
pub(crate) const STILL_Y: f32 = 0.2;

/// An open cylinder of radius 1, y ∈ [-1, 1], `around` columns (plus a duplicated seam
/// column with its own UVs) and `rows` rows.
pub(crate) fn tube(around: usize, rows: usize) -> Mesh {
    let mut pos = Vec::new();
    let mut uvs = Vec::new();
    for r in 0..=rows {
        let y = -1.0 + 2.0 * r as f32 / rows as f32;
        for c in 0..=around {
            let a = std::f32::consts::TAU * (c % around) as f32 / around as f32;
            pos.push(Vec3::new(a.sin(), y, a.cos()));
            uvs.push([c as f32 / around as f32, r as f32 / rows as f32]);
        }
    }
    let w = (around + 1) as u32;
    let mut tris = Vec::new();
    for r in 0..rows as u32 {
        for c in 0..around as u32 {
            let i = r * w + c;
            tris.push([i, i + 1, i + w + 1]);
            tris.push([i, i + w + 1, i + w]);
        }
    }
    let mut m = Mesh::new("tube", pos, tris);
    m.uvs = Some(uvs);
    m
}

/// Displacement of a rest point at frame `f` of `frames`: below [`STILL_Y`] the "jaw"
/// opens forward/down, above it the "brow" rises, both growing with the distance to the
/// still ring (like the square root of the distance); a little asymmetric wobble in x.
pub(crate) fn talk(p: Vec3, f: usize, frames: usize) -> Vec3 {
    let t = f as f32 / frames.max(1) as f32;
    let jaw = (t * 9.0).sin().powi(2);
    let brow = (t * 5.0 + 0.7).sin().powi(2);
    let d = p.y - STILL_Y;
    // Motion grows like sqrt(distance to the still ring): a sharp valley of low motion.
    let s = d.abs().sqrt();
    if d < 0.0 {
        Vec3::new(
            0.05 * (t * 13.0).sin() * s,
            -s * jaw,
            0.8 * s * jaw * p.z.max(0.0),
        )
    } else {
        Vec3::new(0.0, 0.6 * s * brow, 0.1 * s * brow)
    }
}

/// [`tube`] animated by [`talk`] over `frames` frames.
pub(crate) fn talking_tube(around: usize, rows: usize, frames: usize) -> MeshAnimation {
    let mesh = tube(around, rows);
    let pos: Vec<Vec3> = (0..frames)
        .flat_map(|f| {
            mesh.positions
                .iter()
                .map(move |&p| p + talk(p, f, frames))
                .collect::<Vec<_>>()
        })
        .collect();
    MeshAnimation::new(mesh, 30.0, pos).expect("valid synthetic animation")
}

/// Bounding-box diagonal over all frames.
pub(crate) fn diagonal(a: &MeshAnimation) -> f32 {
    a.bbox().diagonal()
}

/// Total area of a mesh with the given positions.
pub(crate) fn area(tris: &[[u32; 3]], x: &[Vec3]) -> f64 {
    tris.iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| x[i as usize].as_dvec3());
            0.5 * (b - a).cross(c - a).length()
        })
        .sum()
}
