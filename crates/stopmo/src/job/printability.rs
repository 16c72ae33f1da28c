//! Whether a printer can make what the job built: the thinnest wall and the smallest
//! free-standing feature of every piece and every mount, against the printer's minimums
//! (`--min-wall`, `--min-feature`), with a warning per part and shortfall that names the
//! pieces and the fix.
//!
//! Resin and PolyJet printers hold walls of 0.8–1 mm and free-standing features of
//! 0.25–0.3 mm: thinner walls crack or open, thinner features break off or do not form. The figures are measured on what the job builds, each
//! by the construction that made it:
//! - walls of a piece: its front against the shared back surface (every front vertex to the
//!   nearest back triangle), the material in front of the magnet pocket's floor (per piece)
//!   and beside it (to the part boundary), the socket tube of a plug;
//! - walls of a mount (`pieces/<part>_back.stl`): the material behind its magnet pocket,
//!   key sockets and ID recess, beside the sockets (to the part boundary) and between
//!   neighbouring cuts;
//! - features of a piece: the embossed ID's strokes (one font pixel wide) and relief, the
//!   registration keys' domes, the plug's pin.
//!
//! What the animated surface itself makes thin (a lip, an eyelid) shows as a thin front
//! against the back; a free-standing spike of the input surface is not measured.

use glam::Vec3;
use rayon::prelude::*;
use serde::Serialize;

use super::magnets::{id_pixel_mm, id_recess, lateral_distance as lateral, Cut, MagnetPlan};
use super::options::PrintSettings;
use crate::library::{piece_id, Key, PartShell, Pocket, ThinnestWall, DEFAULT_ID_RELIEF_MM};

/// What a wall or feature measure is of.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Thin {
    /// Material between a piece's front and the part's shared back surface.
    FrontToBack,
    /// Material in front of the magnet pocket's floor.
    AbovePocket,
    /// Material beside the magnet pocket (to the part boundary).
    BesidePocket,
    /// The socket tube of a plug (outer radius minus bore).
    PlugSocket,
    /// A mount's material behind its magnet pocket.
    BehindMountPocket,
    /// A mount's material behind a key socket.
    BehindKeySocket,
    /// A mount's material behind the ID recess.
    BehindIdRecess,
    /// A mount's material beside a key socket (to the part boundary).
    BesideKeySocket,
    /// A mount's material between two neighbouring cuts (pocket, key sockets, ID recess).
    BetweenCuts,
    /// The embossed ID's strokes (one font pixel wide).
    IdStroke,
    /// How far the embossed ID stands out of the back.
    IdRelief,
    /// A registration key's dome (the smaller of its diameter and height).
    KeyDome,
    /// A plug's pin (its diameter).
    PlugPin,
}

impl Thin {
    /// Whether this is a wall (else a free-standing feature).
    pub fn is_wall(self) -> bool {
        self < Thin::IdStroke
    }

    /// What it is, in words.
    fn describe(self) -> &'static str {
        match self {
            Thin::FrontToBack => "wall between front and back",
            Thin::AbovePocket => "material in front of the magnet pocket",
            Thin::BesidePocket => "material beside the magnet pocket",
            Thin::PlugSocket => "plug socket wall",
            Thin::BehindMountPocket => "material behind the mount's magnet pocket",
            Thin::BehindKeySocket => "material behind a key socket",
            Thin::BehindIdRecess => "material behind the ID recess",
            Thin::BesideKeySocket => "material beside a key socket",
            Thin::BetweenCuts => "material between the mount's pockets and sockets",
            Thin::IdStroke => "embossed ID stroke",
            Thin::IdRelief => "embossed ID relief",
            Thin::KeyDome => "registration key",
            Thin::PlugPin => "plug pin",
        }
    }

    /// How to make it printable.
    fn fix(self, s: &PrintSettings<'_>) -> String {
        match self {
            Thin::FrontToBack if s.thickness_mm < s.min_wall_mm => {
                format!("give --thickness {} or more", s.min_wall_mm)
            }
            Thin::FrontToBack => "the surface folds too close to the back there for the asked --thickness: cut the parts so that a seam runs through that place, or look at it before printing".into(),
            Thin::AbovePocket | Thin::BesidePocket => {
                "use a smaller magnet (--magnets), a thicker --thickness or a larger --print-height".into()
            }
            Thin::PlugSocket => "give the plugs a thicker socket wall (plugs wall_mm)".into(),
            Thin::PlugPin => format!("give a --plug-radius of {} or more", s.min_feature_mm / 2.0),
            Thin::BehindMountPocket | Thin::BehindKeySocket | Thin::BehindIdRecess => {
                "give a thicker --thickness (the mount is at least that thick)".into()
            }
            Thin::BesideKeySocket => {
                "leave the keys off (--no-keys) or glue the mount where its rim is thin".into()
            }
            Thin::BetweenCuts => {
                "use a smaller magnet (--magnets) or leave the IDs off (--no-ids)".into()
            }
            Thin::IdStroke => {
                "print larger (--print-height: an ID pixel is 2 % of it) or leave the IDs off (--no-ids)".into()
            }
            Thin::IdRelief => format!(
                "leave the IDs off (--no-ids): they stand {DEFAULT_ID_RELIEF_MM} mm out of the back"
            ),
            Thin::KeyDome => {
                "print larger (--print-height: a key's radius is 3.5 % of it) or leave the keys off (--no-keys)".into()
            }
        }
    }
}

/// The thinnest wall and smallest feature of one printed solid.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SolidPrintability {
    /// Piece ID `<part>_<NN>`, or the mount `<part>_back`.
    pub id: String,
    /// Part name.
    pub part: String,
    /// Whether it is the part's mount (`pieces/<part>_back.stl`), not a piece.
    pub mount: bool,
    /// Thinnest wall (mm).
    pub thinnest_wall_mm: f64,
    /// Which wall it is.
    pub thinnest_wall: Thin,
    /// Where it is (mm, print coordinates), when it is one place.
    pub thinnest_wall_at_mm: Option<[f32; 3]>,
    /// Smallest free-standing feature (mm; `null` when the solid has none: a mount, or a
    /// piece without ID, keys and plug pin).
    pub smallest_feature_mm: Option<f64>,
    /// Which feature it is.
    pub smallest_feature: Option<Thin>,
}

/// One wall or feature under the printer's minimum.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThinSpot {
    /// Piece ID or mount.
    pub id: String,
    /// Part name.
    pub part: String,
    /// What is thin.
    pub what: Thin,
    /// How thin (mm).
    pub mm: f64,
    /// The printer's minimum it is under (mm).
    pub minimum_mm: f64,
}

/// `report.json` `"printing"."printability"`.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct PrintabilityReport {
    /// The printer's thinnest wall checked against (mm).
    pub min_wall_mm: f64,
    /// The printer's smallest free-standing feature checked against (mm).
    pub min_feature_mm: f64,
    /// Every piece, then every mount.
    pub solids: Vec<SolidPrintability>,
    /// Every wall and feature under the minimum.
    pub under_minimum: Vec<ThinSpot>,
}

/// What one solid was measured to be.
struct Measured {
    id: String,
    mount: bool,
    /// `(what, mm, where)` of every wall measured.
    walls: Vec<(Thin, f64, Option<Vec3>)>,
    /// `(what, mm)` of every feature measured.
    features: Vec<(Thin, f64)>,
}

/// The measures of one part's pieces and mount ([`measure_part`]).
pub(crate) struct PartMeasures {
    part: String,
    solids: Vec<Measured>,
}

/// What [`measure_part`] looks at: one part as `print_pieces` built it.
pub(crate) struct PartGeometry<'a> {
    /// Index of the part.
    pub(crate) part: usize,
    /// Its name.
    pub(crate) name: &'a str,
    /// Its shared back surface (keys and ID placed).
    pub(crate) shell: &'a PartShell,
    /// Its pieces in millimetres (input vertex order).
    pub(crate) pieces: &'a [&'a [Vec3]],
    /// Its registration keys.
    pub(crate) keys: &'a [Key],
    /// Its magnet pocket.
    pub(crate) pocket: Option<&'a Pocket>,
    /// What the ID keeps away from (keys and the pocket).
    pub(crate) id_keys: &'a [Key],
    /// Where every piece's wall is thinnest ([`PartShell::thinnest_walls`]).
    pub(crate) thinnest: &'a [Option<ThinnestWall>],
}

/// Measures the walls and features of every piece of a part and of its mount.
///
/// # Performance
/// The walls in front of the back come measured ([`PartGeometry::thinnest`]); one pass over
/// the front per piece for the pocket; the rest is per key.
pub(crate) fn measure_part(g: &PartGeometry<'_>, s: &PrintSettings<'_>) -> PartMeasures {
    let n = g.pieces.len();
    let mut solids: Vec<Measured> = g
        .pieces
        .par_iter()
        .enumerate()
        .map(|(k, piece)| Measured {
            id: piece_id(g.name, k, n),
            mount: false,
            walls: piece_walls(g, k, piece, s),
            features: piece_features(g, s),
        })
        .collect();
    if let (Some(m), Some(q)) = (&s.magnet, g.pocket) {
        solids.push(Measured {
            id: format!("{}_back", g.name),
            mount: true,
            walls: mount_walls(g, q, MagnetPlan::new(m, s).mount_mm(q), s),
            features: Vec::new(),
        });
    }
    PartMeasures {
        part: g.name.to_string(),
        solids,
    }
}

/// Walls of one piece: front to back, around the pocket, plug sockets.
fn piece_walls(
    g: &PartGeometry<'_>,
    k: usize,
    piece: &[Vec3],
    s: &PrintSettings<'_>,
) -> Vec<(Thin, f64, Option<Vec3>)> {
    let mut walls = Vec::new();
    if let Some(t) = g.thinnest.get(k).copied().flatten() {
        walls.push((Thin::FrontToBack, t.mm, Some(t.at)));
    }
    if let Some(q) = g.pocket {
        let wall = s.magnet.map_or(0.0, |m| MagnetPlan::new(&m, s).wall_mm);
        walls.push((Thin::AbovePocket, pocket_cover(q, piece, wall), None));
        walls.push((Thin::BesidePocket, f64::from(q.side_wall_mm), None));
    }
    for p in s.plugs.iter().filter(|p| p.female == g.part) {
        walls.push((
            Thin::PlugSocket,
            f64::from(p.outer_radius_mm - p.socket_radius_mm),
            Some(Vec3::from_array(p.center)),
        ));
    }
    walls
}

/// Material in front of the pocket's floor in one piece: the front points over the pocket
/// and a wall around it (as [`PartShell::magnet_pocket`] measures it over all pieces; the
/// floor is nearer the front by the boss's height where the pocket stands in a boss).
fn pocket_cover(q: &Pocket, piece: &[Vec3], wall_mm: f32) -> f64 {
    let (c, n) = (Vec3::from_array(q.center), Vec3::from_array(q.axis));
    let reach = q.radius_mm + wall_mm;
    let floor = q.floor_mm();
    piece
        .iter()
        .filter_map(|&p| {
            let d = p - c;
            let axial = d.dot(n);
            let lateral = (d - n * axial).length();
            (lateral < reach && axial > -2.0 * (q.depth_mm + wall_mm)).then_some(axial - floor)
        })
        .fold(f64::INFINITY, |a, b| a.min(f64::from(b)))
}

/// Free-standing features every piece of the part has: ID, keys, plug pins.
fn piece_features(g: &PartGeometry<'_>, s: &PrintSettings<'_>) -> Vec<(Thin, f64)> {
    let mut features = Vec::new();
    if s.ids {
        features.push((Thin::IdStroke, id_pixel_mm(s.print_height_mm)));
        features.push((Thin::IdRelief, DEFAULT_ID_RELIEF_MM));
    }
    for k in g.keys {
        let dome = (2.0 * k.radius_mm).min(k.height_mm);
        features.push((Thin::KeyDome, f64::from(dome)));
    }
    for p in s.plugs.iter().filter(|p| p.male == g.part) {
        features.push((Thin::PlugPin, f64::from(2.0 * p.radius_mm)));
    }
    features
}

/// Walls of a part's mount: behind and beside its cuts, and between them.
fn mount_walls(
    g: &PartGeometry<'_>,
    q: &Pocket,
    mount_mm: f32,
    s: &PrintSettings<'_>,
) -> Vec<(Thin, f64, Option<Vec3>)> {
    let c = s.clearance_mm as f32;
    let back = g.shell.back();
    let rim: Vec<Vec3> = g
        .shell
        .boundary_edges()
        .iter()
        .map(|&(a, _)| back[a as usize])
        .collect();
    // Every cut, as the mount is cut (a boss's recess the widest and deepest at the pocket).
    let mut cuts = vec![Cut {
        at: Vec3::from_array(q.center),
        axis: Vec3::from_array(q.axis),
        radius: q.mount_cut_radius_mm(c),
    }];
    let mut walls = vec![(
        Thin::BehindMountPocket,
        f64::from(mount_mm - q.mount_depth_mm(c)),
        Some(Vec3::from_array(q.center)),
    )];
    walls.push((
        Thin::BesidePocket,
        f64::from(q.side_wall_mm - (q.mount_cut_radius_mm(c) - q.radius_mm)),
        None,
    ));
    for k in g.keys {
        let (at, axis) = (Vec3::from_array(k.center), Vec3::from_array(k.direction));
        let radius = k.radius_mm + c;
        walls.push((
            Thin::BehindKeySocket,
            f64::from(mount_mm - (k.height_mm + c)),
            Some(at),
        ));
        // The rim points level with the socket (its depth either way) bound the wall
        // beside it; those far above or below it do not reach it.
        let depth = k.height_mm + c;
        let side = rim
            .iter()
            .filter(|&&b| (b - at).dot(axis.normalize_or_zero()).abs() <= depth)
            .map(|&b| lateral(at, axis, b) - radius)
            .fold(f32::INFINITY, f32::min);
        if side.is_finite() {
            walls.push((Thin::BesideKeySocket, f64::from(side), Some(at)));
        }
        cuts.push(Cut { at, axis, radius });
    }
    if s.ids {
        let r = id_recess(g.shell, g.id_keys, q, g.keys, s);
        walls.push((
            Thin::BehindIdRecess,
            f64::from(mount_mm - r.depth_mm),
            Some(r.centre),
        ));
        cuts.push(Cut {
            at: r.centre,
            axis: r.axis,
            radius: r.radius_mm,
        });
    }
    // Cuts that overlap merge into one (no wall between them); those apart leave a wall.
    for (i, a) in cuts.iter().enumerate() {
        for b in &cuts[i + 1..] {
            let gap = a.gap(b);
            if gap > 0.0 {
                walls.push((Thin::BetweenCuts, f64::from(gap), Some((a.at + b.at) / 2.0)));
            }
        }
    }
    walls
}

/// The `"printability"` report of every part's measures, and a warning per part and thin
/// wall or feature naming the pieces (or mount) and the fix.
pub(crate) fn printability(
    parts: Vec<PartMeasures>,
    s: &PrintSettings<'_>,
) -> (PrintabilityReport, Vec<String>) {
    let mut report = PrintabilityReport {
        min_wall_mm: s.min_wall_mm,
        min_feature_mm: s.min_feature_mm,
        ..Default::default()
    };
    let mut warnings = Vec::new();
    let mut mounts = Vec::new();
    for part in parts {
        let pieces = part.solids.iter().filter(|m| !m.mount).count();
        let mut thin: Vec<ThinSpot> = Vec::new();
        for m in &part.solids {
            let solid = summary(m, &part.part);
            thin.extend(under_minimum(m, &part.part, s));
            if m.mount {
                mounts.push(solid);
            } else {
                report.solids.push(solid);
            }
        }
        warn_part(&mut warnings, &part.part, pieces, &thin, s);
        report.under_minimum.extend(thin);
    }
    report.solids.extend(mounts);
    (report, warnings)
}

/// The thinnest wall and smallest feature of a solid.
fn summary(m: &Measured, part: &str) -> SolidPrintability {
    let wall = m
        .walls
        .iter()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .copied()
        .unwrap_or((Thin::FrontToBack, f64::INFINITY, None));
    let feature = m.features.iter().min_by(|a, b| a.1.total_cmp(&b.1));
    SolidPrintability {
        id: m.id.clone(),
        part: part.to_string(),
        mount: m.mount,
        thinnest_wall_mm: wall.1,
        thinnest_wall: wall.0,
        thinnest_wall_at_mm: wall.2.map(|v| v.to_array()),
        smallest_feature_mm: feature.map(|f| f.1),
        smallest_feature: feature.map(|f| f.0),
    }
}

/// The walls and features of a solid under the printer's minimums, the thinnest of each kind.
fn under_minimum(m: &Measured, part: &str, s: &PrintSettings<'_>) -> Vec<ThinSpot> {
    let all = m
        .walls
        .iter()
        .map(|w| (w.0, w.1))
        .chain(m.features.iter().copied());
    let mut thin: Vec<ThinSpot> = Vec::new();
    for (what, mm) in all {
        let minimum_mm = if what.is_wall() {
            s.min_wall_mm
        } else {
            s.min_feature_mm
        };
        // A small tolerance: a wall built to the minimum measures it in f32.
        if mm >= minimum_mm - 1e-4 {
            continue;
        }
        match thin.iter_mut().find(|t| t.what == what) {
            Some(t) => t.mm = t.mm.min(mm),
            None => thin.push(ThinSpot {
                id: m.id.clone(),
                part: part.to_string(),
                what,
                mm,
                minimum_mm,
            }),
        }
    }
    thin.sort_by_key(|t| t.what);
    thin
}

/// One warning per kind of thin wall or feature of a part: how thin, which solids, the fix.
fn warn_part(
    warnings: &mut Vec<String>,
    part: &str,
    pieces: usize,
    thin: &[ThinSpot],
    s: &PrintSettings<'_>,
) {
    let mut kinds: Vec<Thin> = thin.iter().map(|t| t.what).collect();
    kinds.sort();
    kinds.dedup();
    for what in kinds {
        let spots: Vec<&ThinSpot> = thin.iter().filter(|t| t.what == what).collect();
        let mm = spots.iter().map(|t| t.mm).fold(f64::INFINITY, f64::min);
        let ids: Vec<&str> = spots.iter().map(|t| t.id.as_str()).collect();
        let on_mount = spots.iter().filter(|t| t.id.ends_with("_back")).count();
        let whose = if on_mount == spots.len() {
            format!("the mount {}", ids.join(", "))
        } else {
            format!("{} of {pieces} pieces ({})", ids.len(), ids.join(", "))
        };
        let (kind, minimum) = if what.is_wall() {
            ("wall", s.min_wall_mm)
        } else {
            ("feature", s.min_feature_mm)
        };
        warnings.push(format!(
            "part {part}: {} down to {mm:.2} mm in {whose}, under the printer's minimum {kind} of {minimum} mm (--min-{kind}); {}",
            what.describe(),
            what.fix(s)
        ));
    }
}
