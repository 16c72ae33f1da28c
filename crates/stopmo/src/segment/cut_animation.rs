//! The cut mesh over the clip: every frame of the cut animation evaluated from the input's
//! frame (its new vertices interpolate the input's along the cut edges, StopShop Section 3.1).

use std::borrow::Cow;

use anim::{Mesh, MeshAnimation};
use glam::Vec3;
use rayon::prelude::*;

use super::cut::{CutMesh, VertexSource};
use super::error::{Result, SegmentError};

/// Evaluates the cut mesh's vertices in every frame and interpolates the attributes. An owned
/// input's position buffer is grown into the cut's (its vertices come first, in input
/// order), not copied: the same numbers without a second copy of the clip.
pub(super) fn build_cut_animation(
    anim: Cow<'_, MeshAnimation>,
    cut: &CutMesh,
) -> Result<MeshAnimation> {
    let src = &anim.mesh;
    let mut mesh = Mesh::new(
        src.name.clone(),
        cut.sources.iter().map(|s| s.eval(&src.positions)).collect(),
        cut.triangles.clone(),
    );
    let lerp = |s: &VertexSource, f: &dyn Fn(u32) -> Vec<f32>| -> Vec<f32> {
        match *s {
            VertexSource::Original(i) => f(i),
            VertexSource::Edge { a, b, t } => f(a)
                .iter()
                .zip(f(b))
                .map(|(x, y)| x + (y - x) * t as f32)
                .collect(),
            VertexSource::Interior { v, w } => {
                let vals: Vec<Vec<f32>> = v.iter().map(|&i| f(i)).collect();
                (0..vals[0].len())
                    .map(|c| (0..3).map(|k| vals[k][c] * w[k] as f32).sum())
                    .collect()
            }
        }
    };
    mesh.normals = src.normals.as_ref().map(|n| {
        cut.sources
            .iter()
            .map(|s| {
                let v = lerp(s, &|i| n[i as usize].to_array().to_vec());
                Vec3::new(v[0], v[1], v[2])
                    .try_normalize()
                    .unwrap_or(Vec3::Y)
            })
            .collect()
    });
    mesh.uvs = src.uvs.as_ref().map(|u| {
        cut.sources
            .iter()
            .map(|s| {
                let v = lerp(s, &|i| u[i as usize].to_vec());
                [v[0], v[1]]
            })
            .collect()
    });
    mesh.colors = src.colors.as_ref().map(|c| {
        cut.sources
            .iter()
            .map(|s| {
                let v = lerp(s, &|i| c[i as usize].to_vec());
                [v[0], v[1], v[2], v[3]]
            })
            .collect()
    });
    let (fps, start_time) = (anim.fps, anim.start_time);
    let positions = match anim {
        Cow::Owned(input) if input_first(cut, input.vertex_count()) => {
            let (m, frames) = (input.vertex_count(), input.frame_count());
            grow_frames(input.into_parts().1, m, frames, cut)
        }
        anim => {
            let n = cut.sources.len();
            let mut positions = vec![Vec3::ZERO; n * anim.frame_count()];
            positions
                .par_chunks_mut(n.max(1))
                .zip(anim.positions().par_chunks(anim.vertex_count().max(1)))
                .for_each(|(out, x)| {
                    for (o, s) in out.iter_mut().zip(&cut.sources) {
                        *o = s.eval(x);
                    }
                });
            positions
        }
    };
    let mut out = MeshAnimation::new(mesh, fps, positions)
        .map_err(|e| SegmentError::Invalid(e.to_string()))?;
    out.start_time = start_time;
    Ok(out)
}

/// Whether the cut's first `m` vertices are the input's `m` vertices in order (what
/// [`cut_mesh`](super::cut::cut_mesh) makes), so that a frame of the input is the start of the cut's frame.
fn input_first(cut: &CutMesh, m: usize) -> bool {
    m > 0
        && cut.sources.len() >= m
        && cut.sources[..m]
            .iter()
            .enumerate()
            .all(|(i, s)| matches!(s, VertexSource::Original(j) if *j as usize == i))
}

/// The input's frame-major positions (`frames × m`) grown in place into the cut's
/// (`frames × n`, [`input_first`]): frames move from the last to the first (each one's new
/// place only covers itself and frames already moved), then the new vertices of the frame
/// are evaluated from its input vertices.
fn grow_frames(mut positions: Vec<Vec3>, m: usize, frames: usize, cut: &CutMesh) -> Vec<Vec3> {
    let n = cut.sources.len();
    positions.truncate(frames * m);
    positions.reserve_exact(frames * (n - m));
    positions.resize(frames * n, Vec3::ZERO);
    for f in (0..frames).rev() {
        positions.copy_within(f * m..(f + 1) * m, f * n);
        let (x, new) = positions[f * n..(f + 1) * n].split_at_mut(m);
        for (o, s) in new.iter_mut().zip(&cut.sources[m..]) {
            *o = s.eval(x);
        }
    }
    positions
}
