//! Collider meshes (issue #22): meshes that elongated and multiple in-betweens never enter.
//!
//! **Inside.** A point p is *inside* a collider when it lies behind the surface at its
//! nearest surface point q: `(p − q) · n < 0`, where n is the angle-weighted pseudo-normal
//! of the feature q lies on (face normal; sum of the two face normals on an edge;
//! angle-weighted vertex normal at a corner — Bærentzen & Aanæs 2005, exact for closed,
//! consistently oriented meshes; a closed mesh wound inside out is turned outward). For a
//! closed mesh this is its solid; for an open mesh (a
//! ground quad, a ramp) it is the region under its front side, so a horizontal quad at
//! `y = g` acts as the ground plane `y = g` wherever the quad is the nearest geometry.
//! Vertices are welded by exact position first, so meshes split at UV or normal seams (a
//! glTF box has 24 corners) still have the pseudo-normals of their closed shape.
//!
//! **Pushed out.** A point inside is moved to q plus a skin of 10⁻⁵ × the collider's
//! diagonal along the pseudo-normal (see [`Collider::push_out`]). Displacements are
//! shortened first: [`Trajectories::displaced`](crate::Trajectories::displaced) stops a
//! displacement where its trajectory enters a collider (bisection on β, continuous along the
//! smear), then pushes out what is still inside.
//!
//! **Frames.** A collider has one shape per frame (an animated collider) or one for all
//! (static); frame f of the smeared animation uses the collider's frame f, its last frame
//! beyond its end.

mod bvh;
mod triangle;

use std::collections::HashMap;

use anim::{Aabb, MeshAnimation};
use glam::Vec3;

use bvh::Bvh;
use triangle::{closest_point, Feature};

/// Skin a pushed-out point keeps from the surface, as a fraction of the collider's diagonal.
const SKIN: f32 = 1e-5;

/// One frame of a collider: a welded triangle soup with pseudo-normals and a BVH.
#[derive(Debug, Clone)]
struct Shape {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    face_normals: Vec<Vec3>,
    vertex_normals: Vec<Vec3>,
    edge_normals: HashMap<(u32, u32), Vec3>,
    bvh: Bvh,
    skin: f32,
}

/// The corners of triangle `t` of `positions`.
fn corners(positions: &[Vec3], t: &[u32; 3]) -> [Vec3; 3] {
    t.map(|v| positions[v as usize])
}

impl Shape {
    fn new(points: &[Vec3], triangles: &[[u32; 3]]) -> Shape {
        let mut weld: HashMap<[u32; 3], u32> = HashMap::new();
        let mut positions = Vec::new();
        let index: Vec<u32> = points
            .iter()
            .map(|p| {
                *weld
                    .entry(p.to_array().map(f32::to_bits))
                    .or_insert_with(|| {
                        positions.push(*p);
                        positions.len() as u32 - 1
                    })
            })
            .collect();
        let mut tris = Vec::with_capacity(triangles.len());
        let mut face_normals = Vec::with_capacity(triangles.len());
        let mut vertex_normals = vec![Vec3::ZERO; positions.len()];
        let mut edge_normals: HashMap<(u32, u32), Vec3> = HashMap::new();
        for t in triangles {
            if t.iter().any(|&v| v as usize >= points.len()) {
                continue;
            }
            let t = t.map(|v| index[v as usize]);
            let c = corners(&positions, &t);
            let n = (c[1] - c[0]).cross(c[2] - c[0]).normalize_or_zero();
            if n == Vec3::ZERO || !c.iter().all(|p| p.is_finite()) {
                continue;
            }
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edge_normals.entry((a.min(b), a.max(b))).or_default() += n;
                let (u, w) = (c[(k + 1) % 3] - c[k], c[(k + 2) % 3] - c[k]);
                vertex_normals[t[k] as usize] += n * u.angle_between(w);
            }
            tris.push(t);
            face_normals.push(n);
        }
        // A closed mesh wound inside out (negative volume) gets its normals turned outward.
        let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
        let mut volume = 0.0f64;
        for t in &tris {
            let c = corners(&positions, t);
            volume += c[0].dot(c[1].cross(c[2])) as f64;
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *uses.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        if volume < 0.0 && uses.values().all(|&n| n == 2) {
            for n in face_normals
                .iter_mut()
                .chain(vertex_normals.iter_mut())
                .chain(edge_normals.values_mut())
            {
                *n = -*n;
            }
        }
        let boxes: Vec<Aabb> = tris
            .iter()
            .map(|t| Aabb::from_points(&corners(&positions, t)))
            .collect();
        let skin = SKIN
            * Aabb::from_points(&positions)
                .diagonal()
                .max(f32::MIN_POSITIVE);
        Shape {
            bvh: Bvh::new(&boxes),
            positions,
            triangles: tris,
            face_normals,
            vertex_normals,
            edge_normals,
            skin,
        }
    }

    /// The nearest surface point to `p` and the pseudo-normal there.
    fn nearest(&self, p: Vec3) -> Option<(Vec3, Vec3)> {
        let (t, _, (q, feature)) = self.bvh.nearest(p, |t| {
            let (q, f) = closest_point(p, corners(&self.positions, &self.triangles[t as usize]));
            (p.distance_squared(q), (q, f))
        })?;
        let tri = self.triangles[t as usize];
        let n = match feature {
            Feature::Face => self.face_normals[t as usize],
            Feature::Vertex(k) => self.vertex_normals[tri[k] as usize],
            Feature::Edge(k) => {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                self.edge_normals[&(a.min(b), a.max(b))]
            }
        };
        Some((q, n))
    }

    fn inside(&self, p: Vec3) -> bool {
        self.nearest(p).is_some_and(|(q, n)| (p - q).dot(n) < 0.0)
    }

    fn push_out(&self, p: Vec3) -> Vec3 {
        match self.nearest(p) {
            Some((q, n)) if (p - q).dot(n) < 0.0 => q + n.normalize_or_zero() * self.skin,
            _ => p,
        }
    }
}

/// A collider mesh, static or animated (see the module documentation).
#[derive(Debug, Clone)]
pub struct Collider {
    name: String,
    shapes: Vec<Shape>,
    /// Shape of every frame.
    frames: Vec<u32>,
}

impl Collider {
    /// A collider following `animation` frame by frame (frames equal to the previous one
    /// share its shape, so a static point cache costs one shape).
    ///
    /// # Performance
    /// One weld and one BVH build per distinct frame: O(T log T) for T triangles.
    pub fn from_animation(animation: &MeshAnimation) -> Collider {
        let tris = &animation.mesh.triangles;
        let mut shapes: Vec<Shape> = Vec::new();
        let mut frames = Vec::with_capacity(animation.frame_count());
        for f in 0..animation.frame_count() {
            let p = animation.frame(f);
            if f == 0 || p != animation.frame(f - 1) {
                shapes.push(Shape::new(p, tris));
            }
            frames.push(shapes.len() as u32 - 1);
        }
        Collider {
            name: animation.mesh.name.clone(),
            shapes,
            frames,
        }
    }

    /// A static collider.
    pub fn from_mesh(mesh: &anim::Mesh) -> Collider {
        Collider {
            name: mesh.name.clone(),
            shapes: vec![Shape::new(&mesh.positions, &mesh.triangles)],
            frames: vec![0],
        }
    }

    /// The collider's name (its mesh's).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Number of frames (1 for a static collider).
    pub fn frame_count(&self) -> usize {
        self.frames.len()
    }

    /// Number of (welded, non-degenerate) triangles at frame `f`.
    pub fn triangle_count(&self, f: usize) -> usize {
        self.shape(f).map_or(0, |s| s.triangles.len())
    }

    fn shape(&self, f: usize) -> Option<&Shape> {
        let k = *self.frames.get(f.min(self.frames.len().checked_sub(1)?))?;
        self.shapes.get(k as usize)
    }

    /// Whether `p` is inside the collider at frame `f` (behind its nearest surface point).
    pub fn inside(&self, f: usize, p: Vec3) -> bool {
        self.shape(f).is_some_and(|s| s.inside(p))
    }

    /// `p` if it is not inside at frame `f`, else its nearest surface point moved out by a
    /// skin of 10⁻⁵ × the collider's diagonal along the surface's pseudo-normal.
    pub fn push_out(&self, f: usize, p: Vec3) -> Vec3 {
        self.shape(f).map_or(p, |s| s.push_out(p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim::Mesh;

    /// An axis-aligned box as 12 triangles with 24 corners (split at every edge, as glTF
    /// writes flat-shaded boxes), outward-facing.
    pub(crate) fn split_box(min: Vec3, max: Vec3) -> Mesh {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for axis in 0..3 {
            for side in [0.0f32, 1.0] {
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let corner = |a: f32, b: f32| {
                    let mut p = [0.0f32; 3];
                    p[axis] = side;
                    p[u] = a;
                    p[v] = b;
                    min + (max - min) * Vec3::from(p)
                };
                let base = positions.len() as u32;
                let c = [
                    corner(0., 0.),
                    corner(1., 0.),
                    corner(1., 1.),
                    corner(0., 1.),
                ];
                let outward = Vec3::AXES[axis] * (2.0 * side - 1.0);
                let flip = (c[1] - c[0]).cross(c[2] - c[0]).dot(outward) < 0.0;
                positions.extend(c);
                for t in [[0, 1, 2], [0, 2, 3]] {
                    let t = if flip { [t[0], t[2], t[1]] } else { t };
                    triangles.push(t.map(|k| base + k));
                }
            }
        }
        Mesh::new("box", positions, triangles)
    }

    #[test]
    fn a_split_box_knows_inside_from_outside_and_pushes_out() {
        let c = Collider::from_mesh(&split_box(Vec3::ZERO, Vec3::ONE));
        assert_eq!(c.triangle_count(0), 12);
        let mut state = 7u32;
        let mut next = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1 << 24) as f32 * 3.0 - 1.0
        };
        for _ in 0..2000 {
            let p = Vec3::new(next(), next(), next());
            let truly = p.cmpgt(Vec3::ZERO).all() && p.cmplt(Vec3::ONE).all();
            assert_eq!(c.inside(0, p), truly, "{p}");
            let q = c.push_out(0, p);
            assert!(!c.inside(0, q), "{p} → {q}");
            if truly {
                let depth = p.min_element().min((Vec3::ONE - p).min_element());
                assert!((q.distance(p) - depth).abs() < 1e-4, "{p} → {q}");
            } else {
                assert_eq!(q, p);
            }
        }
    }

    #[test]
    fn an_inside_out_box_is_turned_outward() {
        let mut b = split_box(Vec3::ZERO, Vec3::ONE);
        for t in &mut b.triangles {
            t.swap(1, 2);
        }
        let c = Collider::from_mesh(&b);
        assert!(c.inside(0, Vec3::splat(0.5)) && !c.inside(0, Vec3::splat(1.5)));
        assert!(c.push_out(0, Vec3::new(0.5, 0.9, 0.5)).y > 1.0);
    }

    #[test]
    fn an_animated_collider_moves_frame_by_frame() {
        let b = split_box(Vec3::ZERO, Vec3::ONE);
        let n = b.positions.len();
        let frames: Vec<Vec3> = [0.0f32, 0.0, 2.0]
            .iter()
            .flat_map(|x| b.positions.iter().map(move |p| *p + Vec3::X * *x))
            .collect();
        let c = Collider::from_animation(&MeshAnimation::new(b, 24.0, frames).unwrap());
        assert_eq!((c.frame_count(), c.shapes.len()), (3, 2), "{n} corners");
        let p = Vec3::splat(0.5);
        assert!(c.inside(0, p) && c.inside(1, p) && !c.inside(2, p) && !c.inside(9, p));
        assert!(
            c.inside(9, p + Vec3::X * 2.0),
            "beyond its end: its last frame"
        );
    }

    #[test]
    fn a_ramp_blocks_what_is_under_it() {
        // A ramp rising 1 in 2 along +X, facing up; the plane y = x / 2.
        let ramp = Mesh::new(
            "ramp",
            vec![
                Vec3::new(0.0, 0.0, -1.0),
                Vec3::new(0.0, 0.0, 1.0),
                Vec3::new(4.0, 2.0, 1.0),
                Vec3::new(4.0, 2.0, -1.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        let c = Collider::from_mesh(&ramp);
        for x in [0.5f32, 1.0, 2.0, 3.5] {
            let on = Vec3::new(x, x / 2.0, 0.3);
            assert!(!c.inside(0, on + Vec3::Y * 0.01) && c.inside(0, on - Vec3::Y * 0.01));
            let q = c.push_out(0, on - Vec3::Y * 0.2);
            // Out along the ramp's normal (−1, 2, 0)/√5, onto the plane.
            assert!((q.y - q.x / 2.0).abs() < 1e-3 && q.x < on.x, "{x}: {q}");
        }
    }

    #[test]
    fn an_open_quad_acts_as_a_plane_under_it() {
        let quad = Mesh::new(
            "floor",
            vec![
                Vec3::new(-5.0, 0.5, -5.0),
                Vec3::new(-5.0, 0.5, 5.0),
                Vec3::new(5.0, 0.5, 5.0),
                Vec3::new(5.0, 0.5, -5.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        let c = Collider::from_mesh(&quad);
        assert!(c.inside(0, Vec3::new(1.0, 0.4, 2.0)));
        assert!(c.inside(0, Vec3::new(7.0, 0.0, 0.0)));
        assert!(!c.inside(0, Vec3::new(1.0, 0.6, 2.0)));
        let q = c.push_out(0, Vec3::new(1.0, -2.0, 2.0));
        assert!((q - Vec3::new(1.0, 0.5, 2.0)).length() < 1e-3, "{q}");
    }
}
