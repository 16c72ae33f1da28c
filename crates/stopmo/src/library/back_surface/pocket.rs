//! Where a part's magnet pocket goes: one place on the shared back surface, the same for
//! every piece of the part, so one magnet in the head holds whichever piece is on it.
//!
//! A pocket is a cylinder along the back's smoothed direction field, opening on the back
//! surface. It fits where every piece keeps at least the minimum wall in front of the
//! pocket's floor, the part boundary (the solid's side wall) stays a wall away from its rim,
//! and the registration keys and the ID stay clear of it; of the places that fit, the one with
//! the thickest material in front of the pocket is taken (the back's deepest point under
//! every piece, usually the middle of a face's cheek or chin).

use glam::Vec3;

use super::PartShell;
use crate::library::piece_id::Key;

/// Candidate centres examined in full (the back vertices with the most material in front).
const CANDIDATES: usize = 64;

/// A pocket on a part's back surface (millimetres).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Pocket {
    /// Centre of the pocket's opening, on the back surface.
    pub center: [f32; 3],
    /// Unit axis from the opening into the piece (towards its front).
    pub axis: [f32; 3],
    /// Radius of the pocket (the magnet's radius plus the clearance).
    pub radius_mm: f32,
    /// Depth from the opening (the magnet's height plus the clearance).
    pub depth_mm: f32,
    /// Thinnest material between the pocket's floor and the front over every piece.
    pub cover_mm: f32,
    /// Thinnest material between the pocket's side and the part boundary.
    pub side_wall_mm: f32,
}

/// Measurements of one candidate centre, `None` where the pocket does not fit.
struct Fit {
    cover: f32,
    side: f32,
}

impl PartShell {
    /// The place for a pocket of `radius_mm` and `depth_mm` with at least `wall_mm` of
    /// material around and in front of it in every piece (millimetres, input vertex order),
    /// clear of `keys` and of the disc `avoid` (centre and radius: the ID), or `None` when
    /// no place of the back fits.
    ///
    /// # Performance
    /// Brute force over the shell vertices for `CANDIDATES` centres: ~10 M point tests for
    /// a 10k-vertex part of 16 pieces.
    pub fn magnet_pocket(
        &self,
        pieces: &[&[Vec3]],
        radius_mm: f32,
        depth_mm: f32,
        wall_mm: f32,
        keys: &[Key],
        avoid: Option<(Vec3, f32)>,
    ) -> Option<Pocket> {
        let fronts: Vec<Vec<Vec3>> = pieces.iter().map(|p| self.front(p)).collect();
        let axis = |v: usize| self.normals[v].normalize_or_zero();
        // Material in front of the back at every vertex, thinnest over the pieces.
        let thickness: Vec<f32> = (0..self.back.len())
            .map(|v| {
                fronts
                    .iter()
                    .map(|f| (f[v] - self.back[v]).dot(axis(v)))
                    .fold(f32::INFINITY, f32::min)
            })
            .collect();
        let need = depth_mm + wall_mm;
        // The keys and the avoided disc are cheap to test: they are left out before the
        // thickest candidates are taken (keys sit where the back is thick too).
        let reach = radius_mm + wall_mm;
        let mut order: Vec<usize> = (0..self.back.len())
            .filter(|&v| {
                !self.on_boundary[v]
                    && thickness[v] >= need
                    && axis(v) != Vec3::ZERO
                    && self.clear_of(v, reach, keys, avoid)
            })
            .collect();
        order.sort_by(|&a, &b| thickness[b].total_cmp(&thickness[a]).then(a.cmp(&b)));
        order.truncate(CANDIDATES);
        let mut best: Option<(usize, Fit)> = None;
        for v in order {
            let Some(fit) = self.pocket_fit(v, &fronts, radius_mm, depth_mm, wall_mm, keys, avoid)
            else {
                continue;
            };
            if best.as_ref().is_none_or(|(_, b)| fit.cover > b.cover) {
                best = Some((v, fit));
            }
        }
        best.map(|(v, fit)| Pocket {
            center: self.back[v].to_array(),
            axis: axis(v).to_array(),
            radius_mm,
            depth_mm,
            cover_mm: fit.cover,
            side_wall_mm: fit.side,
        })
    }

    /// (lateral distance, axial coordinate) of `p` in the frame of a pocket centred at back
    /// vertex `v`.
    fn pocket_frame(&self, v: usize, p: Vec3) -> (f32, f32) {
        let n = self.normals[v].normalize_or_zero();
        let d = p - self.back[v];
        let a = d.dot(n);
        ((d - n * a).length(), a)
    }

    /// Whether a pocket reaching `reach` around back vertex `v` keeps clear of every key and
    /// of the avoided disc.
    fn clear_of(&self, v: usize, reach: f32, keys: &[Key], avoid: Option<(Vec3, f32)>) -> bool {
        let lateral = |p: Vec3| self.pocket_frame(v, p).0;
        keys.iter()
            .all(|k| lateral(Vec3::from_array(k.center)) >= reach + k.radius_mm)
            && avoid.is_none_or(|(at, r)| lateral(at) >= reach + r)
    }

    /// Measures a pocket centred at back vertex `v`; `None` where it breaks a wall, a key or
    /// the avoided disc.
    #[allow(clippy::too_many_arguments)]
    fn pocket_fit(
        &self,
        v: usize,
        fronts: &[Vec<Vec3>],
        radius: f32,
        depth: f32,
        wall: f32,
        keys: &[Key],
        avoid: Option<(Vec3, f32)>,
    ) -> Option<Fit> {
        if !self.clear_of(v, radius + wall, keys, avoid) {
            return None;
        }
        let frame = |p: Vec3| self.pocket_frame(v, p);
        let reach = radius + wall;
        // The side wall: boundary points of the back (where the solid's side wall starts).
        let mut side = f32::INFINITY;
        for (u, &b) in self.back.iter().enumerate() {
            let (lateral, axial) = frame(b);
            if self.on_boundary[u] {
                side = side.min(lateral - radius);
            } else if lateral < radius && axial > 0.5 * depth {
                // The back bulges into the pocket: the magnet would not seat.
                return None;
            }
        }
        if side < wall {
            return None;
        }
        // The cover: every front point over the pocket (and a wall around it) lies at least
        // a wall beyond the pocket's floor.
        let mut cover = f32::INFINITY;
        for f in fronts {
            for &p in f {
                let (lateral, axial) = frame(p);
                if lateral < reach && axial > -2.0 * (depth + wall) {
                    cover = cover.min(axial - depth);
                }
            }
        }
        (cover >= wall).then_some(Fit { cover, side })
    }
}

impl PartShell {
    /// The part's mount: the back surface as it is before keys and IDs (the surface every
    /// piece seats on), thickened `thickness_mm` towards the head, with the pieces' winding
    /// (outward). A studio glues it to the armature or prints it into the head; the pockets
    /// and sockets that match the pieces are cut into it afterwards.
    pub fn mount(&self, thickness_mm: f32, name: &str) -> anim::Mesh {
        let mut positions = self.back.clone();
        positions.extend(
            self.back
                .iter()
                .zip(&self.normals)
                .map(|(&b, n)| b - n.normalize_or_zero() * thickness_mm),
        );
        anim::Mesh::new(name, positions, self.solid_topology())
    }
}

impl Pocket {
    /// The pocket as a key-like disc on the back (centre, radius), so that what keeps away
    /// from keys (the embossed ID) keeps away from it too.
    pub fn as_key(&self) -> Key {
        Key {
            center: self.center,
            direction: (-Vec3::from_array(self.axis)).to_array(),
            radius_mm: self.radius_mm,
            height_mm: 0.0,
            seam: None,
        }
    }
}
