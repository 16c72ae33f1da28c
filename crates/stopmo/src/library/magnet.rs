//! Disc magnets that hold a piece on the head: a cylindrical pocket cut into every piece of a
//! part at one shared place of its back surface ([`PartShell::magnet_pocket`]), and the
//! matching pocket in the part's mount, so one magnet in the head holds whichever piece is
//! on it (how replacement faces are mounted in production and on hobby puppets: 3×2 mm or
//! 4×3 mm discs).
//!
//! The pocket is an exact boolean difference ([`exact_difference`]): the solid stays closed,
//! oriented, one shell and free of self-intersections; only the triangles the cylinder
//! crosses are retriangulated.
//!
//! [`PartShell::magnet_pocket`]: super::PartShell::magnet_pocket

use anim::Mesh;
use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::back_surface::{Boss, Pocket};
use super::error::{LibraryError, Result};
use super::regularize::{exact_boolean, Regularized};

/// Thinnest material left around and in front of a magnet pocket (mm): resin and PolyJet
/// printers hold walls of 0.8–1 mm.
pub const MIN_MAGNET_WALL_MM: f64 = 1.0;

/// Sides of the polygon that approximates a pocket's circle (circumscribed, so the magnet
/// fits the polygon).
pub const DEFAULT_POCKET_SEGMENTS: usize = 48;

/// A disc magnet (millimetres): `--magnets DxH`. Deserialized from `"DxH"` text (`"3x2"`)
/// or from `{"diameter_mm": D, "height_mm": H}`, checked either way.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "MagnetSpec")]
pub struct MagnetOptions {
    /// Diameter.
    pub diameter_mm: f64,
    /// Height (thickness of the disc).
    pub height_mm: f64,
}

/// What [`MagnetOptions`] is read from.
#[derive(Deserialize)]
#[serde(untagged)]
enum MagnetSpec {
    Text(String),
    Sizes { diameter_mm: f64, height_mm: f64 },
}

impl TryFrom<MagnetSpec> for MagnetOptions {
    type Error = LibraryError;

    fn try_from(spec: MagnetSpec) -> Result<MagnetOptions> {
        match spec {
            MagnetSpec::Text(t) => MagnetOptions::parse(&t),
            MagnetSpec::Sizes {
                diameter_mm,
                height_mm,
            } => {
                let m = MagnetOptions {
                    diameter_mm,
                    height_mm,
                };
                m.validate()?;
                Ok(m)
            }
        }
    }
}

impl MagnetOptions {
    /// Parses `DxH` (`3x2`, `4x3`, `6.35x1.5`).
    ///
    /// # Errors
    /// [`LibraryError::InvalidParameter`] naming the text when it is not two positive
    /// millimetre sizes.
    pub fn parse(text: &str) -> Result<MagnetOptions> {
        let bad = || {
            LibraryError::InvalidParameter(format!(
                "magnet '{text}': expected DIAMETERxHEIGHT in millimetres, each > 0 and <= 100 mm, e.g. 3x2"
            ))
        };
        let (d, h) = text.trim().split_once(['x', 'X']).ok_or_else(bad)?;
        let m = MagnetOptions {
            diameter_mm: d.trim().parse().map_err(|_| bad())?,
            height_mm: h.trim().parse().map_err(|_| bad())?,
        };
        m.validate()?;
        Ok(m)
    }

    /// Checks that both sizes are finite, positive and at most 100 mm.
    ///
    /// # Errors
    /// [`LibraryError::InvalidParameter`] naming the size.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("diameter", self.diameter_mm), ("height", self.height_mm)] {
            if !(v.is_finite() && v > 0.0 && v <= 100.0) {
                return Err(LibraryError::InvalidParameter(format!(
                    "magnet {name} must be > 0 and <= 100 mm, got {v}"
                )));
            }
        }
        Ok(())
    }

    /// The magnet's own volume (mm³).
    pub fn volume_mm3(&self) -> f64 {
        std::f64::consts::PI * (self.diameter_mm / 2.0).powi(2) * self.height_mm
    }
}

/// A closed, outward-oriented prism over a polygon circumscribing the circle of `radius`
/// around `axis` through `center`, from `below` behind the centre to `above` in front of it.
pub(crate) fn cylinder(
    center: Vec3,
    axis: Vec3,
    radius: f32,
    below: f32,
    above: f32,
    segments: usize,
) -> Mesh {
    turned_cylinder(center, axis, radius, below, above, segments, 0.0)
}

/// [`cylinder`] with its polygon turned by `turn` of a side: a boss (or the mount's recess
/// for it) is turned half a side against the pocket cut through it, so that no edge of one
/// runs through an edge of the other (degenerate crossings, rounded to slivers).
pub(crate) fn turned_cylinder(
    center: Vec3,
    axis: Vec3,
    radius: f32,
    below: f32,
    above: f32,
    segments: usize,
    turn: f32,
) -> Mesh {
    let n = segments.max(3);
    let axis = axis.normalize_or(Vec3::Z);
    let u = axis.any_orthonormal_vector();
    let w = axis.cross(u);
    let r = radius / (std::f32::consts::PI / n as f32).cos();
    let (lo, hi) = (center - axis * below, center + axis * above);
    let mut positions = Vec::with_capacity(2 * n + 2);
    for base in [lo, hi] {
        for i in 0..n {
            let t = std::f32::consts::TAU * (i as f32 + turn) / n as f32;
            positions.push(base + (u * t.cos() + w * t.sin()) * r);
        }
    }
    positions.push(lo);
    positions.push(hi);
    let (m, cl, ch) = (n as u32, 2 * n as u32, 2 * n as u32 + 1);
    let mut triangles = Vec::with_capacity(4 * n);
    for i in 0..m {
        let j = (i + 1) % m;
        // u × w = axis: counter-clockwise around the axis seen from the top.
        triangles.push([cl, j, i]);
        triangles.push([ch, m + i, m + j]);
        triangles.push([i, j, m + j]);
        triangles.push([i, m + j, m + i]);
    }
    Mesh::new("pocket", positions, triangles)
}

/// `solid` with the pocket cut: the cylinder from `below_mm` behind the opening (clear of the
/// back surface around it) to the pocket's floor; with its boss joined first where it has
/// one.
///
/// # Errors
/// [`LibraryError::Regularization`] when the exact boolean fails (the solid is not closed
/// and orientable).
pub(crate) fn cut_pocket(solid: &Mesh, pocket: &Pocket, below_mm: f32) -> Result<Regularized> {
    let axis = Vec3::from_array(pocket.axis);
    let cutter = cylinder(
        pocket.opening(),
        axis,
        pocket.radius_mm,
        below_mm,
        pocket.depth_mm,
        DEFAULT_POCKET_SEGMENTS,
    );
    let boss = pocket.boss.map(|b| boss_solid(pocket, &b));
    exact_boolean(solid, boss.as_ref(), Some(&cutter))
}

/// The boss as a closed cylinder: from its top behind the back to its base inside the piece.
pub(crate) fn boss_solid(pocket: &Pocket, boss: &Boss) -> Mesh {
    turned_cylinder(
        Vec3::from_array(pocket.center),
        Vec3::from_array(pocket.axis),
        boss.radius_mm,
        boss.height_mm,
        boss.base_mm,
        DEFAULT_POCKET_SEGMENTS,
        0.5,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::library::plugs::components;
    use crate::library::test_shapes::cuboid;
    use crate::library::{check_solid, self_intersecting_triangles, volume};

    #[test]
    fn magnet_sizes_parse_and_refuse_nonsense() {
        let m = MagnetOptions::parse("3x2").unwrap();
        assert_eq!((m.diameter_mm, m.height_mm), (3.0, 2.0));
        assert_eq!(MagnetOptions::parse(" 4 X 3 ").unwrap().height_mm, 3.0);
        for bad in ["3", "x2", "3x", "0x2", "-3x2", "3x1e9", "nanx2", "3x2x1"] {
            assert!(MagnetOptions::parse(bad).is_err(), "{bad}");
        }
        let from_text: MagnetOptions = serde_json::from_str("\"4x3\"").unwrap();
        let from_sizes: MagnetOptions =
            serde_json::from_str(r#"{"diameter_mm": 4, "height_mm": 3}"#).unwrap();
        assert_eq!(from_text, from_sizes);
        assert!(
            serde_json::from_str::<MagnetOptions>(r#"{"diameter_mm": -4, "height_mm": 3}"#)
                .is_err()
        );
    }

    #[test]
    fn cylinder_is_closed_outward_and_circumscribes_the_circle() {
        let c = cylinder(Vec3::ONE, Vec3::new(0.0, 1.0, 1.0), 1.5, 0.5, 2.0, 48);
        assert!(check_solid(&c).is_closed_manifold());
        let v = volume(&c);
        let circle = std::f64::consts::PI * 1.5f64.powi(2) * 2.5;
        assert!(v > circle && v < circle * 1.01, "{v} vs {circle}");
    }

    #[test]
    fn pocket_in_a_block_removes_at_least_the_magnet() {
        let (p, t) = cuboid(Vec3::ZERO, Vec3::new(10.0, 10.0, 5.0));
        let block = Mesh::new("block", p, t);
        let pocket = Pocket {
            center: [5.0, 5.0, 0.0],
            axis: [0.0, 0.0, 1.0],
            radius_mm: 1.5,
            depth_mm: 2.0,
            cover_mm: 3.0,
            side_wall_mm: 3.5,
            boss: None,
        };
        let cut = cut_pocket(&block, &pocket, 0.5).unwrap();
        assert!(check_solid(&cut.mesh).is_closed_manifold());
        assert_eq!(
            self_intersecting_triangles(&cut.mesh.positions, &cut.mesh.triangles)
                .unwrap()
                .len(),
            0
        );
        let magnet = MagnetOptions {
            diameter_mm: 3.0,
            height_mm: 2.0,
        };
        let removed = volume(&block) - volume(&cut.mesh);
        assert!(removed >= magnet.volume_mm3(), "{removed}");
        assert!(removed < magnet.volume_mm3() * 1.01, "{removed}");
    }

    /// A back too thin for the pocket (a 1.5 mm plate): the pocket stands in a boss joined to
    /// the plate, one closed shell that crosses nowhere, and the boss adds its cylinder less
    /// the pocket.
    #[test]
    fn pocket_in_a_boss_on_a_thin_plate_is_one_clean_shell() {
        let (p, t) = cuboid(Vec3::ZERO, Vec3::new(12.0, 12.0, 1.5));
        let plate = Mesh::new("plate", p, t);
        let boss = Boss {
            radius_mm: 2.6,
            height_mm: 1.6,
            base_mm: 0.8,
        };
        let pocket = Pocket {
            center: [6.0, 6.0, 0.0],
            axis: [0.0, 0.0, 1.0],
            radius_mm: 1.6,
            depth_mm: 2.1,
            cover_mm: 1.0,
            side_wall_mm: 4.4,
            boss: Some(boss),
        };
        let cut = cut_pocket(&plate, &pocket, 1.5).unwrap();
        assert!(check_solid(&cut.mesh).is_closed_manifold());
        assert_eq!(components(&cut.mesh).len(), 1);
        assert_eq!(
            self_intersecting_triangles(&cut.mesh.positions, &cut.mesh.triangles)
                .unwrap()
                .len(),
            0
        );
        let pi = std::f64::consts::PI;
        let added = pi * 2.6f64.powi(2) * 1.6;
        let taken = pi * 1.6f64.powi(2) * 2.1;
        let expected = volume(&plate) + added - taken;
        let v = volume(&cut.mesh);
        assert!((v - expected).abs() < 0.01 * expected, "{v} vs {expected}");
        // The pocket opens on the boss's top and its floor keeps a wall (1 mm) in front of
        // it: 2.1 mm deep from 1.6 mm behind the back, 1.5 - 0.5 mm in front.
        assert!((pocket.floor_mm() - 0.5).abs() < 1e-6);
        let over_pocket = |q: &&Vec3| q.truncate().distance(glam::Vec2::new(6.0, 6.0)) < 1.7;
        let floor = cut
            .mesh
            .positions
            .iter()
            .filter(over_pocket)
            .map(|q| q.z)
            .fold(f32::NEG_INFINITY, f32::max);
        assert!((floor - 0.5).abs() < 1e-5, "floor at {floor}");
        let top = cut.mesh.bbox().min.z;
        assert!((top + 1.6).abs() < 1e-5, "top at {top}");
    }
}
