//! Male/female plugs that hold printed parts together (StopShop Section 3.4, Fig. 13).
//!
//! The paper does not generate connectors ("we simply created male/female plugs on parts
//! that connect; these plugs can be fused with the part and 3D printed"); this module makes
//! one pair per seam. Seams are identical in every frame after homogenization (Section 3.2),
//! so a plug placed at a seam of the rest geometry fits every piece of both parts.
//!
//! Geometry, in millimetres at print scale, for parts A (male, lower index) and B (female)
//! sharing a seam: the anchor `p` is the seam vertex whose plug footprint (the surface
//! within `L/2` across and along the seam, covered on all four sides) deviates least from
//! the tangent plane (ties, in 0.1 mm steps, go to the vertex nearest the seam centroid), `n`
//! the outward surface normal there, `t` the seam tangent (principal direction of the nearby
//! seam vertices, projected into the tangent plane) and `d = ±n × t` points across the seam
//! from A into B. The plug axis runs along `d` through `p − n·h`, beneath the inner surface of the
//! shells (`h = thickness + R − overlap`, `R = r + clearance + wall` the outer radius,
//! `overlap = min(wall, thickness) / 2`):
//! - **male** (fused to A): a boss of radius `R` under A (overlapping A's shell by `overlap`
//!   so it fuses) stepping down at the seam to a pin of radius `r` that protrudes `L/2` under
//!   B;
//! - **female** (fused to B): a tube of inner radius `r + clearance` and outer radius `R`,
//!   coaxial with the pin, overlapping B's shell by `overlap` while its bore stays
//!   `wall − overlap` below B's inner surface.
//!
//! Both are closed, consistently oriented surfaces of revolution appended as extra shells to
//! the piece's mesh: slicers union overlapping shells of one STL, so the plug prints fused to
//! the piece. Summed shell volumes count the overlap twice (a small overestimate).

use std::collections::HashMap;

use anim::Mesh;
use glam::Vec3;
use serde::Serialize;

use super::error::{LibraryError, Result};
use super::fabricate::DEFAULT_THICKNESS_MM;

/// Pin radius in millimetres.
pub const DEFAULT_PLUG_RADIUS_MM: f64 = 1.0;
/// Pin length (boss plus protruding pin) in millimetres.
pub const DEFAULT_PLUG_LENGTH_MM: f64 = 6.0;
/// Radial clearance between pin and socket bore in millimetres.
pub const DEFAULT_PLUG_CLEARANCE_MM: f64 = 0.15;
/// Wall of the socket tube in millimetres.
pub const DEFAULT_PLUG_WALL_MM: f64 = 0.8;
/// Polygon sides of the plug cross sections.
pub const DEFAULT_PLUG_SEGMENTS: usize = 24;

/// Footprint deviations from the tangent plane are compared in steps of this many
/// millimetres (a typical layer height), so near-ties go to the vertex nearest the seam
/// centroid.
const FLATNESS_STEP_MM: f32 = 0.1;

/// Plug dimensions (millimetres at print scale, like the printable pieces).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
#[serde(default)]
pub struct PlugOptions {
    /// Pin radius `r`.
    pub radius_mm: f64,
    /// Total length `L`: half boss under the male part, half pin under the female part.
    pub length_mm: f64,
    /// Radial clearance of the socket bore.
    pub clearance_mm: f64,
    /// Socket wall.
    pub wall_mm: f64,
    /// Shell thickness of the pieces (the plugs sit beneath it).
    pub thickness_mm: f64,
    /// Polygon sides of the cross sections (at least 3).
    pub segments: usize,
}

impl Default for PlugOptions {
    fn default() -> Self {
        PlugOptions {
            radius_mm: DEFAULT_PLUG_RADIUS_MM,
            length_mm: DEFAULT_PLUG_LENGTH_MM,
            clearance_mm: DEFAULT_PLUG_CLEARANCE_MM,
            wall_mm: DEFAULT_PLUG_WALL_MM,
            thickness_mm: DEFAULT_THICKNESS_MM,
            segments: DEFAULT_PLUG_SEGMENTS,
        }
    }
}

impl PlugOptions {
    fn validate(&self) -> Result<()> {
        for (name, v, min) in [
            ("plug radius", self.radius_mm, 0.0),
            ("plug length", self.length_mm, 0.0),
            ("plug wall", self.wall_mm, 0.0),
            ("thickness", self.thickness_mm, 0.0),
        ] {
            if !(v.is_finite() && v > min) {
                return Err(LibraryError::InvalidParameter(format!(
                    "{name} must be finite and > 0 mm, got {v}"
                )));
            }
        }
        if !(self.clearance_mm.is_finite() && self.clearance_mm >= 0.0) {
            return Err(LibraryError::InvalidParameter(format!(
                "plug clearance must be finite and >= 0 mm, got {}",
                self.clearance_mm
            )));
        }
        if self.segments < 3 {
            return Err(LibraryError::InvalidParameter(format!(
                "plug segments must be >= 3, got {}",
                self.segments
            )));
        }
        Ok(())
    }

    /// Outer radius `R` of the boss and the socket tube.
    pub fn outer_radius_mm(&self) -> f64 {
        self.radius_mm + self.clearance_mm + self.wall_mm
    }

    /// How far boss and socket reach into their shells.
    pub fn overlap_mm(&self) -> f64 {
        self.wall_mm.min(self.thickness_mm) / 2.0
    }
}

/// One male/female pair across the seam of two parts (millimetres).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Plug {
    /// Index of the part carrying the male plug (boss and pin).
    pub male: usize,
    /// Index of the part carrying the female plug (socket tube).
    pub female: usize,
    /// Seam vertices shared by the two parts.
    pub seam_vertices: usize,
    /// Anchor: the seam vertex with the flattest plug footprint.
    pub anchor: [f32; 3],
    /// Outward unit surface normal at the anchor.
    pub normal: [f32; 3],
    /// Unit seam tangent at the anchor (perpendicular to `normal`).
    pub tangent: [f32; 3],
    /// Unit plug axis, from the male into the female part (`±normal × tangent`).
    pub axis: [f32; 3],
    /// Point of the axis below the anchor (`anchor − normal·depth`).
    pub center: [f32; 3],
    /// Depth of the axis below the outer surface.
    pub depth_mm: f32,
    /// Pin radius.
    pub radius_mm: f32,
    /// Socket bore radius (pin radius plus clearance).
    pub socket_radius_mm: f32,
    /// Outer radius of boss and socket.
    pub outer_radius_mm: f32,
    /// Total length of boss plus pin.
    pub length_mm: f32,
    /// Radial (and axial) clearance.
    pub clearance_mm: f32,
}

/// Normal, seam tangent and axis at a seam vertex.
type Frame = (Vec3, Vec3, Vec3);

fn v3(a: [f32; 3]) -> Vec3 {
    Vec3::from_array(a)
}

/// Vertices on edges used by a single triangle.
fn boundary_vertices(mesh: &Mesh) -> Vec<u32> {
    let mut count: HashMap<(u32, u32), u32> = HashMap::with_capacity(mesh.triangles.len() * 3);
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut out: Vec<u32> = count
        .iter()
        .filter(|(_, &c)| c == 1)
        .flat_map(|(&(a, b), _)| [a, b])
        .collect();
    out.sort_unstable();
    out.dedup();
    out.retain(|&v| (v as usize) < mesh.positions.len());
    out
}

/// Dominant direction of a point set (power iteration on its covariance).
fn principal_direction(points: &[Vec3]) -> Option<Vec3> {
    if points.len() < 2 {
        return None;
    }
    let c = points.iter().copied().sum::<Vec3>() / points.len() as f32;
    let mut cov = glam::Mat3::ZERO;
    for p in points {
        let q = *p - c;
        cov += glam::Mat3::from_cols(q * q.x, q * q.y, q * q.z);
    }
    let mut v = Vec3::new(1.0, 0.7, 0.3).normalize();
    for _ in 0..64 {
        let w = cov * v;
        if w.length_squared() < 1e-30 {
            return None;
        }
        v = w.normalize();
    }
    Some(v)
}

/// Places one plug per pair of parts sharing a seam.
///
/// # Arguments
/// * `surfaces` — one surface per part (rest or average geometry) in millimetres, in part
///   order; seam vertices are copies with equal positions in both parts.
/// * `opts` — plug dimensions.
///
/// # Returns
/// The plugs, ordered by `(male, female)`; pairs without a common seam get none.
///
/// # Errors
/// [`LibraryError::InvalidParameter`] for invalid options.
///
/// # Performance
/// `O(boundary² + seam · vertices)` per part pair.
pub fn plan_plugs(surfaces: &[Mesh], opts: &PlugOptions) -> Result<Vec<Plug>> {
    opts.validate()?;
    let diag = surfaces
        .iter()
        .map(Mesh::bbox)
        .fold(anim::Aabb::EMPTY, anim::Aabb::union)
        .diagonal();
    let tol = if diag.is_finite() && diag > 0.0 {
        diag * 1e-5
    } else {
        1e-6
    };
    let boundaries: Vec<Vec<u32>> = surfaces.iter().map(boundary_vertices).collect();
    let normals: Vec<Vec<Vec3>> = surfaces
        .iter()
        .map(|m| m.vertex_normals(&m.positions))
        .collect();
    let mut plugs = Vec::new();
    for a in 0..surfaces.len() {
        for b in a + 1..surfaces.len() {
            let (pa, pb) = (&surfaces[a].positions, &surfaces[b].positions);
            // Seam: boundary vertices of A with a coincident boundary vertex of B.
            let seam: Vec<(u32, u32)> = boundaries[a]
                .iter()
                .filter_map(|&i| {
                    let p = pa[i as usize];
                    boundaries[b]
                        .iter()
                        .find(|&&j| pb[j as usize].distance(p) <= tol)
                        .map(|&j| (i, j))
                })
                .collect();
            if seam.len() < 2 {
                continue;
            }
            let pts: Vec<Vec3> = seam.iter().map(|&(i, _)| pa[i as usize]).collect();
            let centroid = pts.iter().copied().sum::<Vec3>() / pts.len() as f32;
            // Anchor: the seam vertex whose plug footprint is flattest (ties: nearest the
            // seam centroid); vertices whose footprint is not covered on both sides are
            // skipped unless no vertex qualifies.
            let reach = (opts.length_mm as f32).max(1e-6);
            let frame = |k: usize| -> Option<Frame> {
                let (ia, ib) = seam[k];
                let p = pts[k];
                let n = (normals[a][ia as usize] + normals[b][ib as usize]).normalize_or_zero();
                if n == Vec3::ZERO {
                    return None;
                }
                let near: Vec<Vec3> = pts
                    .iter()
                    .copied()
                    .filter(|q| q.distance(p) <= reach)
                    .collect();
                let t = principal_direction(&near).or_else(|| principal_direction(&pts))?;
                let t = (t - n * n.dot(t)).normalize_or_zero();
                if t == Vec3::ZERO {
                    return None;
                }
                // Across the seam: from A's nearby vertices towards B's.
                let side = |m: &[Vec3]| {
                    let (s, c) = m
                        .iter()
                        .filter(|q| q.distance(p) <= reach && q.distance(p) > tol)
                        .fold((Vec3::ZERO, 0usize), |(s, c), q| (s + *q, c + 1));
                    if c == 0 {
                        p
                    } else {
                        s / c as f32
                    }
                };
                let d = n.cross(t);
                let d = if d.dot(side(pb) - side(pa)) < 0.0 {
                    -d
                } else {
                    d
                };
                Some((n, t, d))
            };
            let (half, outer_r) = (opts.length_mm as f32 / 2.0, opts.outer_radius_mm() as f32);
            let flatness = |k: usize, (n, t, d): Frame| -> Option<f32> {
                let p = pts[k];
                let mut worst = 0.0f32;
                // Quadrants beyond half the footprint: [A, B, one side of the seam, other].
                let mut covered = [false; 4];
                for (m, sign) in [(pa, -1.0f32), (pb, 1.0)] {
                    for q in m {
                        let r = *q - p;
                        let (x, y) = (r.dot(d) * sign, r.dot(t));
                        if (0.0..=half).contains(&x) && y.abs() <= half.max(outer_r) {
                            worst = worst.max(r.dot(n).abs());
                            covered[usize::from(sign > 0.0)] |= x >= half / 2.0;
                            covered[2] |= y >= half / 2.0;
                            covered[3] |= y <= -half / 2.0;
                        }
                    }
                }
                (covered == [true; 4]).then_some((worst / FLATNESS_STEP_MM).round())
            };
            let candidates: Vec<(usize, Frame, Option<f32>)> = (0..pts.len())
                .filter_map(|k| frame(k).map(|f| (k, f, flatness(k, f))))
                .collect();
            let key = |c: &(usize, Frame, Option<f32>)| {
                (
                    c.2.unwrap_or(f32::INFINITY),
                    pts[c.0].distance_squared(centroid),
                )
            };
            let Some(&(k, (n, t, d), _)) = candidates.iter().min_by(|x, y| {
                let (kx, ky) = (key(x), key(y));
                kx.0.total_cmp(&ky.0).then(kx.1.total_cmp(&ky.1))
            }) else {
                continue;
            };
            let p = pts[k];
            let outer = opts.outer_radius_mm();
            let depth = opts.thickness_mm + outer - opts.overlap_mm();
            plugs.push(Plug {
                male: a,
                female: b,
                seam_vertices: seam.len(),
                anchor: p.to_array(),
                normal: n.to_array(),
                tangent: t.to_array(),
                axis: d.to_array(),
                center: (p - n * depth as f32).to_array(),
                depth_mm: depth as f32,
                radius_mm: opts.radius_mm as f32,
                socket_radius_mm: (opts.radius_mm + opts.clearance_mm) as f32,
                outer_radius_mm: outer as f32,
                length_mm: opts.length_mm as f32,
                clearance_mm: opts.clearance_mm as f32,
            });
        }
    }
    Ok(plugs)
}

/// Revolves a profile of `(axial, radius)` points around the axis through `center` along
/// `axis`. Open profiles must start and end at radius 0 (cap centres, one vertex each);
/// closed profiles are loops (a torus-like tube). The result is outward oriented.
fn revolve(
    profile: &[(f32, f32)],
    closed: bool,
    center: Vec3,
    axis: Vec3,
    segments: usize,
) -> Mesh {
    let (u, v) = axis.any_orthonormal_pair();
    let mut positions = Vec::new();
    let mut rings: Vec<Vec<u32>> = Vec::with_capacity(profile.len());
    for &(a, r) in profile {
        let c = center + axis * a;
        if r == 0.0 {
            positions.push(c);
            rings.push(vec![(positions.len() - 1) as u32; segments]);
        } else {
            let start = positions.len() as u32;
            positions.extend((0..segments).map(|k| {
                let th = std::f32::consts::TAU * k as f32 / segments as f32;
                c + (u * th.cos() + v * th.sin()) * r
            }));
            rings.push((start..start + segments as u32).collect());
        }
    }
    let mut tris = Vec::new();
    let pairs = if closed {
        profile.len()
    } else {
        profile.len() - 1
    };
    for i in 0..pairs {
        let (ri, rj) = (&rings[i], &rings[(i + 1) % profile.len()]);
        for k in 0..segments {
            let k1 = (k + 1) % segments;
            let (a, b, c, d) = (ri[k], rj[k], rj[k1], ri[k1]);
            if a != b && b != c && a != c {
                tris.push([a, b, c]);
            }
            if a != c && c != d && a != d {
                tris.push([a, c, d]);
            }
        }
    }
    let mut mesh = Mesh::new("plug", positions, tris);
    if super::fabricate::volume(&mesh) < 0.0 {
        mesh.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    }
    mesh
}

impl Plug {
    /// The male plug: boss of the outer radius under the male part, stepping down (half a
    /// clearance before the seam) to the pin protruding `length/2` under the female part.
    pub fn male_solid(&self, segments: usize) -> Mesh {
        let (h, c) = (self.length_mm / 2.0, self.clearance_mm / 2.0);
        let profile = [
            (-h, 0.0),
            (-h, self.outer_radius_mm),
            (-c, self.outer_radius_mm),
            (-c, self.radius_mm),
            (h, self.radius_mm),
            (h, 0.0),
        ];
        revolve(
            &profile,
            false,
            v3(self.center),
            v3(self.axis),
            segments.max(3),
        )
    }

    /// The female plug: an open tube (bore of the socket radius, wall out to the outer
    /// radius) coaxial with the pin, from half a clearance past the seam to a clearance past
    /// the pin's tip.
    pub fn female_solid(&self, segments: usize) -> Mesh {
        let (c, end) = (
            self.clearance_mm / 2.0,
            self.length_mm / 2.0 + self.clearance_mm,
        );
        let profile = [
            (c, self.socket_radius_mm),
            (c, self.outer_radius_mm),
            (end, self.outer_radius_mm),
            (end, self.socket_radius_mm),
        ];
        revolve(
            &profile,
            true,
            v3(self.center),
            v3(self.axis),
            segments.max(3),
        )
    }
}

/// Appends the plugs of part `part` to its printable solid as extra closed shells (male
/// plugs where it is the male part, sockets where it is the female part).
pub fn add_plugs(solid: &Mesh, part: usize, plugs: &[Plug], segments: usize) -> Mesh {
    let mut out = solid.clone();
    out.normals = None;
    for plug in plugs {
        let shell = if plug.male == part {
            plug.male_solid(segments)
        } else if plug.female == part {
            plug.female_solid(segments)
        } else {
            continue;
        };
        let base = out.positions.len() as u32;
        out.positions.extend_from_slice(&shell.positions);
        out.triangles
            .extend(shell.triangles.iter().map(|t| t.map(|i| i + base)));
    }
    out
}

/// Splits a mesh into its edge-connected components (vertices renumbered, in order of first
/// appearance), e.g. a piece and its plug shells.
pub fn components(mesh: &Mesh) -> Vec<Mesh> {
    let n = mesh.positions.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    let valid = |t: &[u32; 3]| t.iter().all(|&i| (i as usize) < n);
    for t in mesh.triangles.iter().filter(|t| valid(t)) {
        for k in 1..3 {
            let (a, b) = (
                find(&mut parent, t[0] as usize),
                find(&mut parent, t[k] as usize),
            );
            parent[a] = b;
        }
    }
    let mut index: HashMap<usize, usize> = HashMap::new();
    let mut out: Vec<(Mesh, HashMap<u32, u32>)> = Vec::new();
    for t in mesh.triangles.iter().filter(|t| valid(t)) {
        let root = find(&mut parent, t[0] as usize);
        let c = *index.entry(root).or_insert_with(|| {
            out.push((
                Mesh::new(format!("{}#{}", mesh.name, out.len()), vec![], vec![]),
                HashMap::new(),
            ));
            out.len() - 1
        });
        let (m, map) = &mut out[c];
        let tri = t.map(|i| {
            *map.entry(i).or_insert_with(|| {
                m.positions.push(mesh.positions[i as usize]);
                (m.positions.len() - 1) as u32
            })
        });
        m.triangles.push(tri);
    }
    out.into_iter().map(|(m, _)| m).collect()
}
