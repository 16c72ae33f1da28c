//! Magnets in a printed library: the pocket's size from the magnet and the clearance, its
//! place per part, the cut in every piece, and the part's mount (`pieces/<part>_back.stl`)
//! with the matching pocket, the key sockets and a recess for the embossed ID.

use anim::Mesh;
use glam::Vec3;

use super::error::{Error, Result};
use super::options::PrintSettings;
use crate::library::{
    check_solid, cut_pocket, cylinder, exact_difference, Key, MagnetOptions, PartShell, Pocket,
    DEFAULT_ID_RELIEF_MM, DEFAULT_POCKET_SEGMENTS, MIN_MAGNET_WALL_MM,
};

/// Sizes of the pocket and mount for one magnet (millimetres).
pub(crate) struct MagnetPlan {
    /// Pocket radius: the magnet's plus the clearance.
    pub(crate) radius_mm: f32,
    /// Pocket depth: the magnet's height plus the clearance.
    pub(crate) depth_mm: f32,
    /// Material left around and in front of the pocket.
    pub(crate) wall_mm: f32,
    /// Thickness of the mount: the pocket, the clearance and a wall behind it.
    pub(crate) mount_mm: f32,
}

impl MagnetPlan {
    pub(crate) fn new(m: &MagnetOptions, s: &PrintSettings<'_>) -> MagnetPlan {
        let c = s.clearance_mm;
        let depth = m.height_mm + c;
        MagnetPlan {
            radius_mm: (m.diameter_mm / 2.0 + c) as f32,
            depth_mm: depth as f32,
            wall_mm: MIN_MAGNET_WALL_MM as f32,
            mount_mm: (depth + MIN_MAGNET_WALL_MM).max(s.thickness_mm) as f32,
        }
    }
}

/// The pocket of part `part` (an error naming the part when no place fits).
pub(crate) fn find_pocket(
    shell: &PartShell,
    pieces: &[&[Vec3]],
    plan: &MagnetPlan,
    keys: &[Key],
    part: &str,
) -> Result<Pocket> {
    shell
        .magnet_pocket(
            pieces,
            plan.radius_mm,
            plan.depth_mm,
            plan.wall_mm,
            keys,
            None,
        )
        .ok_or_else(|| {
            Error::option_error(
                "magnets",
                format!(
                    "part {part}: no place on the back fits a pocket of {:.2} mm diameter and {:.2} mm depth with {} mm of material around and in front of it in every piece; use a smaller magnet, a larger --print-height or a thicker --thickness",
                    2.0 * plan.radius_mm,
                    plan.depth_mm,
                    plan.wall_mm
                ),
            )
        })
}

/// `solid` with the pocket cut; the cutter starts `below_mm` behind the back (clear of the
/// back's curvature and the ID's relief).
pub(crate) fn cut_piece_pocket(solid: &Mesh, pocket: &Pocket, below_mm: f32) -> Result<Mesh> {
    let cut = cut_pocket(solid, pocket, below_mm)?;
    Ok(cut.mesh)
}

/// The part's mount with the pocket matching the pieces' (a second magnet sits there), a
/// socket per key and a recess for the embossed ID, every fit widened by the clearance.
pub(crate) fn cut_mount(
    shell: &PartShell,
    mount: &Mesh,
    pocket: &Pocket,
    keys: &[Key],
    id_keys: &[Key],
    s: &PrintSettings<'_>,
) -> Result<Mesh> {
    let c = s.clearance_mm as f32;
    let margin = s.thickness_mm as f32;
    let mut cutters: Vec<Mesh> = vec![cylinder(
        Vec3::from_array(pocket.center),
        -Vec3::from_array(pocket.axis),
        pocket.radius_mm,
        margin,
        pocket.depth_mm,
        DEFAULT_POCKET_SEGMENTS,
    )];
    for k in keys {
        cutters.push(cylinder(
            Vec3::from_array(k.center),
            Vec3::from_array(k.direction),
            k.radius_mm + c,
            margin,
            k.height_mm + c,
            DEFAULT_POCKET_SEGMENTS / 2,
        ));
    }
    if s.ids {
        // The ID is raised on the back of every piece at the same place (the label's
        // extent bounds a recess; the labels of one part have the same length).
        let (centre, right, up) = shell.id_frame(id_keys);
        let pixel = (s.print_height_mm * 0.02).clamp(0.3, 1.0) as f32;
        let (w, h) = render::text_size("0-00", 1);
        let half = Vec3::new(w as f32, h as f32, 0.0) * pixel / 2.0;
        cutters.push(cylinder(
            centre,
            right.cross(up),
            half.truncate().length() + c,
            margin,
            DEFAULT_ID_RELIEF_MM as f32 + c,
            DEFAULT_POCKET_SEGMENTS / 2,
        ));
    }
    let cutter = concat(&cutters);
    let cut = exact_difference(mount, Some(&cutter))?;
    if !check_solid(&cut.mesh).is_closed_manifold() {
        return Err(Error::option_error(
            "magnets",
            format!("the mount {} is not closed after its pockets", mount.name),
        ));
    }
    Ok(cut.mesh)
}

/// Several meshes as one (their shells side by side).
fn concat(meshes: &[Mesh]) -> Mesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for m in meshes {
        let base = positions.len() as u32;
        positions.extend_from_slice(&m.positions);
        triangles.extend(m.triangles.iter().map(|t| t.map(|i| i + base)));
    }
    Mesh::new("cutters", positions, triangles)
}
