//! Where a part's magnet pocket goes: one place on the shared back surface, the same for
//! every piece of the part, so one magnet in the head holds whichever piece is on it.
//!
//! A pocket is a cylinder along the back's smoothed direction field, opening on the back
//! surface. It fits where every piece keeps at least the minimum wall in front of the
//! pocket's floor, the part boundary (the solid's side wall) stays a wall away from its rim,
//! and the registration keys and the ID stay clear of it; of the places that fit, the one with
//! the thickest material in front of the pocket is taken (the back's deepest point under
//! every piece, usually the middle of a face's cheek or chin).
//!
//! The back is only the wall (`--thickness`, 1.5 mm by default) in front of most of a part,
//! less than a 2 mm deep pocket and a wall in front of it. Where no place is that thick, the
//! pocket stands in a *boss*: a cylinder one wall wider than the pocket on the back of every
//! piece, tall enough that the pocket's floor keeps the wall in front of it, its base inside
//! the material of every piece (so the exact union with the piece is one shell); the mount
//! gets a recess that takes it, one clearance wider and deeper. The boss needs room: its
//! recess and a wall of the mount between it and the part boundary, and a wall between the
//! recess and every key socket. Candidates are the thickest places with that room (the
//! deepest places of a face's back lie at the eye and mouth openings, where no pocket fits,
//! so the room is tested before the thickest are taken).

use glam::Vec3;

use super::PartShell;
use crate::library::piece_id::Key;

/// Candidate centres examined in full per kind of pocket (the back vertices with the most
/// material in front, among those with room for it).
const CANDIDATES: usize = 64;

/// Least distance of a boss's base from the back and the fronts it lies between (mm): the
/// exact union then meets no face it merely touches.
const BOSS_MARGIN_MM: f32 = 0.1;

/// What a magnet pocket asks of a part's back (millimetres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PocketSpec {
    /// Pocket radius (the magnet's plus the clearance).
    pub radius_mm: f32,
    /// Pocket depth (the magnet's height plus the clearance).
    pub depth_mm: f32,
    /// Material around and in front of the pocket.
    pub wall_mm: f32,
    /// Clearance of the mount's recess around a boss.
    pub clearance_mm: f32,
}

impl PocketSpec {
    /// Radius of a boss: the pocket's and a wall.
    pub fn boss_radius_mm(&self) -> f32 {
        self.radius_mm + self.wall_mm
    }

    /// Room a pocket in a boss needs from its centre to the part boundary: the boss, the
    /// mount's recess around it and a wall of the mount beyond.
    pub fn boss_room_mm(&self) -> f32 {
        self.boss_radius_mm() + self.clearance_mm + self.wall_mm
    }
}

/// A cylindrical thickening on the back of every piece of a part that holds its magnet
/// pocket where the back alone is too thin (millimetres, along the pocket's axis from the
/// pocket's centre on the back surface).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Boss {
    /// Radius (the pocket's plus a wall).
    pub radius_mm: f32,
    /// How far its flat top, where the pocket opens, stands behind the back surface.
    pub height_mm: f32,
    /// How far in front of the back surface its cylinder reaches, inside every piece.
    pub base_mm: f32,
}

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
    /// The boss the pocket stands in, where the back alone is too thin for it (the pocket
    /// then opens on the boss's top, `height_mm` behind `center`).
    pub boss: Option<Boss>,
}

/// Why no place of a part's back takes a pocket (millimetres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PocketMiss {
    /// Room a pocket in a boss needs from its centre to the part boundary
    /// ([`PocketSpec::boss_room_mm`]).
    pub needed_mm: f32,
    /// The most room any back point clear of the keys has (its distance to the boundary).
    pub widest_mm: f32,
}

/// Measurements of one candidate centre.
struct Fit {
    cover: f32,
    side: f32,
    boss: Option<Boss>,
}

/// What the back and the fronts are around a candidate centre (pocket frame: lateral
/// distance from the axis, axial coordinate from the centre towards the front).
struct Column {
    /// Nearest boundary point's lateral distance less the pocket radius.
    side: f32,
    /// Whether the back comes forward into the pocket by more than half its depth.
    bulge: bool,
    /// Back's axial extent within the boss radius.
    back: (f32, f32),
    /// Nearest front point (over every piece) within the boss radius.
    front: f32,
}

impl PartShell {
    /// The place for a pocket of `spec` with at least its wall of material around and in
    /// front of it in every piece (millimetres, input vertex order), clear of `keys` and of
    /// the disc `avoid` (centre and radius: the ID): where the back is thick enough the
    /// pocket opens on the back; elsewhere it stands in a [`Boss`].
    ///
    /// # Errors
    /// A [`PocketMiss`] saying how much room was needed and found when no place of the back
    /// has room for even a boss.
    ///
    /// # Performance
    /// Brute force over the shell vertices for `CANDIDATES` centres per kind: ~10 M point
    /// tests for a 10k-vertex part of 16 pieces.
    pub fn magnet_pocket(
        &self,
        pieces: &[&[Vec3]],
        spec: &PocketSpec,
        keys: &[Key],
        avoid: Option<(Vec3, f32)>,
    ) -> Result<Pocket, PocketMiss> {
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
        let from_boundary = self.distances_to_boundary();
        let (r, wall, c) = (spec.radius_mm, spec.wall_mm, spec.clearance_mm);
        // A plain pocket: its rim a wall from the boundary and the keys. In a boss: the
        // mount's recess a wall from the boundary and from the key sockets (each one
        // clearance wider than what it takes).
        let plain_reach = r + wall;
        let boss_reach = spec.boss_radius_mm() + 2.0 * c + wall;
        let usable = |v: usize, room: f32, reach: f32| {
            !self.on_boundary[v]
                && from_boundary[v] >= room
                && axis(v) != Vec3::ZERO
                && self.clear_of(v, reach, keys, avoid)
        };
        let thickest = |ok: &dyn Fn(usize) -> bool| {
            let mut order: Vec<usize> = (0..self.back.len()).filter(|&v| ok(v)).collect();
            order.sort_by(|&a, &b| thickness[b].total_cmp(&thickness[a]).then(a.cmp(&b)));
            order.truncate(CANDIDATES);
            order
        };
        let need = spec.depth_mm + wall;
        let plain = thickest(&|v| thickness[v] >= need && usable(v, plain_reach, plain_reach));
        let mut best = self.best_fit(&plain, &fronts, spec, false, keys, avoid);
        if best.is_none() {
            let bossed = thickest(&|v| usable(v, spec.boss_room_mm(), boss_reach));
            best = self.best_fit(&bossed, &fronts, spec, true, keys, avoid);
        }
        let Some((v, fit)) = best else {
            let widest = (0..self.back.len())
                .filter(|&v| !self.on_boundary[v] && self.clear_of(v, boss_reach, keys, avoid))
                .map(|v| from_boundary[v])
                .fold(0.0f32, f32::max);
            return Err(PocketMiss {
                needed_mm: spec.boss_room_mm(),
                widest_mm: widest,
            });
        };
        Ok(Pocket {
            center: self.back[v].to_array(),
            axis: axis(v).to_array(),
            radius_mm: r,
            depth_mm: spec.depth_mm,
            cover_mm: fit.cover,
            side_wall_mm: fit.side,
            boss: fit.boss,
        })
    }

    /// The best of `candidates`: the most material in front of a plain pocket, the lowest
    /// boss.
    fn best_fit(
        &self,
        candidates: &[usize],
        fronts: &[Vec<Vec3>],
        spec: &PocketSpec,
        boss: bool,
        keys: &[Key],
        avoid: Option<(Vec3, f32)>,
    ) -> Option<(usize, Fit)> {
        let score = |f: &Fit| f.cover - f.boss.map_or(0.0, |b| 10.0 * b.height_mm);
        let mut best: Option<(usize, Fit)> = None;
        for &v in candidates {
            let column = self.column(v, fronts, spec, keys, avoid);
            let fit = column.and_then(|col| {
                if boss {
                    boss_fit(&col, spec)
                } else {
                    plain_fit(&col, spec)
                }
            });
            if let Some(fit) = fit {
                if best.as_ref().is_none_or(|(_, b)| score(&fit) > score(b)) {
                    best = Some((v, fit));
                }
            }
        }
        best
    }

    /// Distance of every back point from the nearest back boundary point (where the solid's
    /// side wall starts).
    fn distances_to_boundary(&self) -> Vec<f32> {
        let rim: Vec<Vec3> = (0..self.back.len())
            .filter(|&u| self.on_boundary[u])
            .map(|u| self.back[u])
            .collect();
        self.back
            .iter()
            .map(|&p| {
                rim.iter()
                    .map(|&b| b.distance_squared(p))
                    .fold(f32::INFINITY, f32::min)
                    .sqrt()
            })
            .collect()
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

    /// The back and fronts around a pocket centred at back vertex `v` (within the boss
    /// radius, and two pockets' depth either way along the axis: farther points belong to
    /// another sheet of the surface); `None` where the keys or the avoided disc are in the
    /// way.
    fn column(
        &self,
        v: usize,
        fronts: &[Vec<Vec3>],
        spec: &PocketSpec,
        keys: &[Key],
        avoid: Option<(Vec3, f32)>,
    ) -> Option<Column> {
        let (r, depth, wall) = (spec.radius_mm, spec.depth_mm, spec.wall_mm);
        if !self.clear_of(v, r + wall, keys, avoid) {
            return None;
        }
        let frame = |p: Vec3| self.pocket_frame(v, p);
        let reach = spec.boss_radius_mm();
        let window = 2.0 * (depth + wall);
        let mut col = Column {
            side: f32::INFINITY,
            bulge: false,
            back: (f32::INFINITY, f32::NEG_INFINITY),
            front: f32::INFINITY,
        };
        for (u, &b) in self.back.iter().enumerate() {
            let (lateral, axial) = frame(b);
            if self.on_boundary[u] {
                col.side = col.side.min(lateral - r);
                continue;
            }
            // The back coming forward into the pocket: a magnet would not seat.
            col.bulge |= lateral < r && axial > 0.5 * depth;
            if lateral < reach && axial.abs() < window {
                col.back = (col.back.0.min(axial), col.back.1.max(axial));
            }
        }
        // Every front point over the pocket and a wall around it.
        for f in fronts {
            for &p in f {
                let (lateral, axial) = frame(p);
                if lateral < reach && axial > -window {
                    col.front = col.front.min(axial);
                }
            }
        }
        Some(col)
    }
}

/// A pocket opening on the back, where the back is thick enough for it.
fn plain_fit(col: &Column, spec: &PocketSpec) -> Option<Fit> {
    let cover = col.front - spec.depth_mm;
    (!col.bulge && col.side >= spec.wall_mm && cover >= spec.wall_mm).then_some(Fit {
        cover,
        side: col.side,
        boss: None,
    })
}

/// A pocket in a boss: its top far enough behind the back that the pocket's floor keeps a
/// wall in front of it (and behind the back everywhere under it, so the pocket opens on a
/// flat top), its base halfway between the back (or the pocket's floor) and the fronts.
fn boss_fit(col: &Column, spec: &PocketSpec) -> Option<Fit> {
    let (depth, wall) = (spec.depth_mm, spec.wall_mm);
    let (back_min, back_max) = col.back;
    if col.side < spec.boss_room_mm() - spec.radius_mm
        || !back_min.is_finite()
        || col.front - back_max < 2.0 * BOSS_MARGIN_MM
    {
        return None;
    }
    let top = (col.front - depth - wall)
        .min(0.0)
        .min(back_min - BOSS_MARGIN_MM);
    let floor = top + depth;
    let base = (back_max.max(floor) + col.front) / 2.0;
    Some(Fit {
        cover: col.front - floor,
        side: col.side,
        boss: Some(Boss {
            radius_mm: spec.boss_radius_mm(),
            height_mm: -top,
            base_mm: base,
        }),
    })
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
    /// Centre of the pocket's opening: on the back, or on its boss's top.
    pub fn opening(&self) -> Vec3 {
        Vec3::from_array(self.center)
            - Vec3::from_array(self.axis) * self.boss.map_or(0.0, |b| b.height_mm)
    }

    /// Axial coordinate of the pocket's floor in front of the back surface at its centre.
    pub fn floor_mm(&self) -> f32 {
        self.depth_mm - self.boss.map_or(0.0, |b| b.height_mm)
    }

    /// Radius of the mount's cut that takes the pocket's side: the pocket's (a second magnet
    /// sits there), or the boss's recess, one clearance wider than the boss.
    pub fn mount_cut_radius_mm(&self, clearance_mm: f32) -> f32 {
        self.boss
            .map_or(self.radius_mm, |b| b.radius_mm + clearance_mm)
    }

    /// How far behind the back surface the mount's cuts reach at the pocket: its magnet
    /// pocket's floor, below the boss's recess when there is a boss.
    pub fn mount_depth_mm(&self, clearance_mm: f32) -> f32 {
        self.depth_mm + self.boss.map_or(0.0, |b| b.height_mm + clearance_mm)
    }

    /// The pocket as a key-like disc on the back (centre, radius), so that what keeps away
    /// from keys (the embossed ID) keeps away from it too.
    pub fn as_key(&self) -> Key {
        Key {
            center: self.center,
            direction: (-Vec3::from_array(self.axis)).to_array(),
            radius_mm: self.boss.map_or(self.radius_mm, |b| b.radius_mm),
            height_mm: 0.0,
            seam: None,
        }
    }
}
