//! Twins: the vertices of a point cache that are one point of the surface.
//!
//! A mesh split at its seams and hard edges holds each corner several times (the bundled
//! robot's 7,214 vertices are 1,820 points). Whatever is a function of a vertex's positions
//! alone is the same for all of its twins, so it can be worked out once per point.

use std::hash::Hasher;

use rayon::prelude::*;
use rustc_hash::{FxHashMap, FxHasher};

use crate::MeshAnimation;

/// Vertices hashed per parallel task.
const CHUNK: usize = 4096;

impl MeshAnimation {
    /// Per vertex its twin: the first vertex whose positions are the same bits in every frame
    /// (itself when no earlier vertex is), so `twins[v] <= v`. `−0.0` and `0.0` differ, as do
    /// two vertices that meet in some frames only.
    ///
    /// ```
    /// use anim::{Mesh, MeshAnimation};
    /// use glam::Vec3;
    /// // Vertex 2 is vertex 0 again (a seam); vertex 1 meets vertex 0 in frame 0 only.
    /// let mesh = Mesh::new("seam", vec![Vec3::ZERO; 3], vec![[0, 1, 2]]);
    /// let frames = vec![Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::X];
    /// let anim = MeshAnimation::new(mesh, 24.0, frames)?;
    /// assert_eq!(anim.twins(), vec![0, 1, 0]);
    /// # Ok::<(), anim::AnimError>(())
    /// ```
    ///
    /// # Performance
    /// One pass over the frames (each vertex's coordinates hashed, in parallel over vertices),
    /// then every vertex whose hash an earlier one has is compared with it in full.
    pub fn twins(&self) -> Vec<u32> {
        let (frames, n) = (self.frame_count(), self.vertex_count());
        let mut hashes = vec![0u64; n];
        hashes
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(c, out)| {
                let first = c * CHUNK;
                let mut hashers = vec![FxHasher::default(); out.len()];
                for f in 0..frames {
                    let points = &self.frame(f)[first..first + out.len()];
                    for (h, p) in hashers.iter_mut().zip(points) {
                        for x in p.to_array() {
                            h.write_u32(x.to_bits());
                        }
                    }
                }
                for (o, h) in out.iter_mut().zip(&hashers) {
                    *o = h.finish();
                }
            });
        let same = |u: usize, v: usize| {
            (0..frames).all(|f| {
                let p = self.frame(f);
                p[u].to_array().map(f32::to_bits) == p[v].to_array().map(f32::to_bits)
            })
        };
        first_of_each(&hashes, same)
    }
}

/// Per item the first item it is the `same` as, comparing only items of equal hashes: the
/// first item of each hash in a map, the first items of other groups with that hash (a
/// collision) chained behind it, newest first.
fn first_of_each(hashes: &[u64], same: impl Fn(usize, usize) -> bool) -> Vec<u32> {
    let mut head: FxHashMap<u64, u32> = FxHashMap::default();
    let mut chain = vec![u32::MAX; hashes.len()];
    (0..hashes.len())
        .map(|v| {
            let mut u = head.get(&hashes[v]).copied().unwrap_or(u32::MAX);
            while u != u32::MAX && !same(u as usize, v) {
                u = chain[u as usize];
            }
            if u == u32::MAX {
                if let Some(h) = head.insert(hashes[v], v as u32) {
                    chain[v] = h;
                }
                u = v as u32;
            }
            u
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use crate::{Mesh, MeshAnimation};
    use glam::Vec3;

    #[test]
    fn twins_are_the_same_point_in_every_frame() {
        // 0, 2 and 4 are one point; 1 parts from 0 in frame 1; 3 is 0 with a −0.0; 5 alone.
        let z = Vec3::ZERO;
        let f0 = [z, z, z, Vec3::new(-0.0, 0.0, 0.0), z, Vec3::X];
        let f1 = [Vec3::Y, Vec3::Z, Vec3::Y, Vec3::Y, Vec3::Y, Vec3::X];
        let mesh = Mesh::new("m", f0.to_vec(), vec![[0, 1, 2], [3, 4, 5]]);
        let m = MeshAnimation::new(mesh, 24.0, [f0, f1].concat()).unwrap();
        assert_eq!(m.twins(), vec![0, 1, 0, 3, 0, 5]);
    }

    #[test]
    fn colliding_hashes_still_compare_in_full() {
        // Every item hashed alike: three groups (by value) found through the chain.
        let values = [5, 7, 5, 9, 7, 9, 5];
        let firsts = super::first_of_each(&[0; 7], |u, v| values[u] == values[v]);
        assert_eq!(firsts, vec![0, 1, 0, 3, 1, 3, 0]);
    }

    #[test]
    fn twins_across_hash_chunks() {
        // More vertices than one parallel task hashes: twins found across tasks.
        let n = 2 * super::CHUNK + 10;
        let p: Vec<Vec3> = (0..n)
            .map(|v| Vec3::new((v % 7) as f32, 0.0, 1.0))
            .collect();
        let mesh = Mesh::new("m", p.clone(), vec![[0, 1, 2]]);
        let frames = [p.clone(), p.iter().map(|q| *q * 2.0).collect()].concat();
        let twins = MeshAnimation::new(mesh, 24.0, frames).unwrap().twins();
        assert!(twins.iter().enumerate().all(|(v, &t)| t as usize == v % 7));
    }
}
