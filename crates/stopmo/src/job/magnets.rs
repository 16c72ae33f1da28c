//! Magnets in a printed library: the pocket's size from the magnet and the clearance, its
//! place per part, the cut in every piece, and the part's mount (`pieces/<part>_back.stl`)
//! with the matching pocket, the key sockets and a recess for the embossed ID.

use anim::Mesh;
use glam::Vec3;

use super::error::{Error, Result};
use super::options::PrintSettings;
use crate::library::{
    check_solid, cut_pocket, cylinder, exact_difference, regularize, self_intersecting_triangles,
    turned_cylinder, Key, MagnetOptions, PartShell, Pocket, PocketSpec, DEFAULT_ID_RELIEF_MM,
    DEFAULT_POCKET_SEGMENTS, MIN_MAGNET_WALL_MM,
};

/// Sizes of the pocket and mount for one magnet (millimetres).
pub(crate) struct MagnetPlan {
    /// Pocket radius: the magnet's plus the clearance.
    pub(crate) radius_mm: f32,
    /// Pocket depth: the magnet's height plus the clearance.
    pub(crate) depth_mm: f32,
    /// Material left around and in front of the pocket.
    pub(crate) wall_mm: f32,
    /// Clearance of every fit.
    pub(crate) clearance_mm: f32,
    /// Least thickness of the mount (`--thickness`).
    pub(crate) thickness_mm: f32,
}

impl MagnetPlan {
    pub(crate) fn new(m: &MagnetOptions, s: &PrintSettings<'_>) -> MagnetPlan {
        let c = s.clearance_mm;
        let depth = m.height_mm + c;
        // The printer's minimum wall when it asks for more than the magnet's own.
        let wall = MIN_MAGNET_WALL_MM.max(s.min_wall_mm);
        MagnetPlan {
            radius_mm: (m.diameter_mm / 2.0 + c) as f32,
            depth_mm: depth as f32,
            wall_mm: wall as f32,
            clearance_mm: c as f32,
            thickness_mm: s.thickness_mm as f32,
        }
    }

    /// What the pocket asks of the part's back.
    pub(crate) fn spec(&self) -> PocketSpec {
        PocketSpec {
            radius_mm: self.radius_mm,
            depth_mm: self.depth_mm,
            wall_mm: self.wall_mm,
            clearance_mm: self.clearance_mm,
        }
    }

    /// Thickness of the mount for `pocket`: its cuts (a boss's recess and the magnet pocket
    /// below it) and a wall behind them, at least `--thickness`.
    pub(crate) fn mount_mm(&self, pocket: &Pocket) -> f32 {
        (pocket.mount_depth_mm(self.clearance_mm) + self.wall_mm).max(self.thickness_mm)
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
        .magnet_pocket(pieces, &plan.spec(), keys, None)
        .map_err(|miss| {
            Error::option_error(
                "magnets",
                format!(
                    "part {part} is too small for the magnet: a pocket of {:.2} mm diameter and {:.2} mm depth in a boss with {} mm of material around it needs {:.1} mm from its centre to the part's edge, clear of the registration keys, and the widest place of the part's back has {:.1} mm; use a smaller magnet, a larger --print-height, or leave the keys off (--no-keys)",
                    2.0 * plan.radius_mm,
                    plan.depth_mm,
                    plan.wall_mm,
                    miss.needed_mm,
                    miss.widest_mm
                ),
            )
        })
}

/// `solid` with the pocket cut (and its boss joined) and the count of its self-intersecting
/// triangles; the cutter starts `below_mm` behind the back (clear of the back's curvature
/// and the ID's relief).
pub(crate) fn cut_piece_pocket(
    solid: &Mesh,
    pocket: &Pocket,
    below_mm: f32,
) -> Result<(Mesh, usize)> {
    let cut = cut_pocket(solid, pocket, below_mm)?;
    Ok(fewer_crossings(cut.mesh))
}

/// Rounds of [`fewer_crossings`] at most.
const ROUNDING_REPAIRS: usize = 3;

/// An exact boolean's new vertices are rounded to `f32`; where that makes triangles cross
/// (a boss's side meeting the embossed ID's steps or a seam wall at a grazing angle), the
/// rounded solid is regularized again, kept while it crosses less. The solid and its count
/// of crossing triangles (every triangle when the exact test cannot run).
pub(crate) fn fewer_crossings(mut mesh: Mesh) -> (Mesh, usize) {
    let count = |m: &Mesh| {
        self_intersecting_triangles(&m.positions, &m.triangles)
            .map_or(m.triangles.len(), |t| t.len())
    };
    let mut crossing = count(&mesh);
    for _ in 0..ROUNDING_REPAIRS {
        if crossing == 0 {
            break;
        }
        let Ok(r) = regularize(&mesh) else { break };
        let c = count(&r.mesh);
        if c >= crossing {
            break;
        }
        (mesh, crossing) = (r.mesh, c);
    }
    (mesh, crossing)
}

/// The part's mount with the pocket matching the pieces' (a second magnet sits there; below
/// the recess that takes the pieces' boss where they have one), a socket per key and a
/// recess for the embossed ID, every fit widened by the clearance.
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
    let into = -Vec3::from_array(pocket.axis);
    let mut cutters: Vec<Mesh> = Vec::new();
    let opening = match pocket.boss {
        Some(b) => {
            cutters.push(turned_cylinder(
                Vec3::from_array(pocket.center),
                into,
                b.radius_mm + c,
                margin,
                b.height_mm + c,
                DEFAULT_POCKET_SEGMENTS,
                0.5,
            ));
            // The second magnet faces the first across the recess's clearance.
            pocket.opening() + into * c
        }
        None => Vec3::from_array(pocket.center),
    };
    cutters.push(cylinder(
        opening,
        into,
        pocket.radius_mm,
        margin,
        pocket.depth_mm,
        DEFAULT_POCKET_SEGMENTS,
    ));
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
        let r = id_recess(shell, id_keys, pocket, keys, s);
        cutters.push(cylinder(
            r.centre,
            r.axis,
            r.radius_mm,
            margin,
            r.depth_mm,
            DEFAULT_POCKET_SEGMENTS / 2,
        ));
    }
    let cutter = concat(&cutters);
    let cut = exact_difference(mount, Some(&cutter))?;
    let (cut_mesh, _) = fewer_crossings(cut.mesh);
    if !check_solid(&cut_mesh).is_closed_manifold() {
        return Err(Error::option_error(
            "magnets",
            format!("the mount {} is not closed after its pockets", mount.name),
        ));
    }
    Ok(cut_mesh)
}

/// The mount's recess for the ID raised on the back of every piece.
pub(crate) struct IdRecess {
    /// Centre on the back surface.
    pub(crate) centre: Vec3,
    /// Direction it is cut (into the mount).
    pub(crate) axis: Vec3,
    /// Radius: the label's half diagonal plus the clearance.
    pub(crate) radius_mm: f32,
    /// Depth: the ID's relief plus the clearance.
    pub(crate) depth_mm: f32,
}

/// Where the ID sits on the back of every piece of the part: the same place in all of them
/// (the label's extent bounds a recess; the labels of one part have the same length). A
/// recess that would leave a sliver thinner than the printer's minimum wall beside the
/// magnet pocket or a key socket is widened into it instead (a wider recess still fits).
pub(crate) fn id_recess(
    shell: &PartShell,
    id_keys: &[Key],
    pocket: &Pocket,
    keys: &[Key],
    s: &PrintSettings<'_>,
) -> IdRecess {
    let c = s.clearance_mm as f32;
    let (centre, right, up) = shell.id_frame(id_keys);
    let axis = right.cross(up);
    let pixel = id_pixel_mm(s.print_height_mm) as f32;
    let (w, h) = render::text_size("0-00", 1);
    let half = Vec3::new(w as f32, h as f32, 0.0) * pixel / 2.0;
    let mut radius = half.truncate().length() + c;
    // The other cuts, as [`cut_mount`] cuts them.
    let others: Vec<Cut> = std::iter::once(Cut {
        at: Vec3::from_array(pocket.center),
        axis: Vec3::from_array(pocket.axis),
        radius: pocket.mount_cut_radius_mm(c),
    })
    .chain(keys.iter().map(|k| Cut {
        at: Vec3::from_array(k.center),
        axis: Vec3::from_array(k.direction),
        radius: k.radius_mm + c,
    }))
    .collect();
    let min_wall = s.min_wall_mm as f32;
    for _ in 0..others.len() {
        let sliver = others
            .iter()
            .map(|o| {
                let recess = Cut {
                    at: centre,
                    axis,
                    radius,
                };
                recess.gap(o)
            })
            .filter(|&gap| gap > 0.0 && gap < min_wall)
            .fold(0.0f32, f32::max);
        if sliver == 0.0 {
            break;
        }
        radius += sliver + 0.01;
    }
    IdRecess {
        centre,
        axis,
        radius_mm: radius,
        depth_mm: DEFAULT_ID_RELIEF_MM as f32 + c,
    }
}

/// Distance of `p` from the axis through `at` along `axis`.
pub(crate) fn lateral_distance(at: Vec3, axis: Vec3, p: Vec3) -> f32 {
    let n = axis.normalize_or_zero();
    let d = p - at;
    (d - n * d.dot(n)).length()
}

/// A cylindrical cut into a mount (pocket, key socket, ID recess).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Cut {
    /// Centre on the back surface.
    pub(crate) at: Vec3,
    /// Its axis.
    pub(crate) axis: Vec3,
    /// Its radius.
    pub(crate) radius: f32,
}

impl Cut {
    /// Material between two cuts (negative where they overlap): the nearer of the two centres'
    /// distances from the other's axis, less both radii.
    pub(crate) fn gap(&self, other: &Cut) -> f32 {
        let apart = lateral_distance(self.at, self.axis, other.at)
            .min(lateral_distance(other.at, other.axis, self.at));
        apart - self.radius - other.radius
    }
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

/// Width of one pixel of the embossed ID (mm): 2 % of the print height, 0.3–1 mm.
pub(crate) fn id_pixel_mm(print_height_mm: f64) -> f64 {
    (print_height_mm * 0.02).clamp(0.3, 1.0)
}
