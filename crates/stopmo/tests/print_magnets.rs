//! Pieces a studio prints and mounts, on the ICT face (0.5 fps: 30 frames, 3 pieces per part,
//! cheap): with a 3×2 mm magnet every solid stays one closed, outward-oriented shell without a
//! self-intersecting triangle (exact test), loses at least the magnet's volume to a pocket at
//! the same place in every piece of a part, the part's mount has the matching pocket, and
//! `library.3mf` holds every piece as a named object laid out on build plates; a magnet no
//! place fits is refused naming the part.

mod common;

use anim::Mesh;
use glam::Vec3;
use stopmo::library::{
    check_solid, components, self_intersecting_triangles, volume, MagnetOptions,
};
use stopmo::segment::{PartSpec, Seed};
use stopmo::{LibraryJobOptions, PieceCount, PrintFormat, RunOptions, SegmentJobOptions};

/// `upper`/`lower` seeds: the README's, or a cut through the eyes none of the printing was
/// tuned on.
fn options(seeds: [[f32; 3]; 2], magnets: Option<MagnetOptions>) -> RunOptions {
    RunOptions {
        segment: SegmentJobOptions {
            parts: vec![
                PartSpec::new("upper", vec![Seed::Point(Vec3::from_array(seeds[0]))]),
                PartSpec::new("lower", vec![Seed::Point(Vec3::from_array(seeds[1]))]),
            ],
            ..Default::default()
        },
        library: LibraryJobOptions {
            pieces: PieceCount::Each(3),
            solve: stopmo::library::SolveOptions {
                restarts: 1,
                ..Default::default()
            },
            magnets,
            print_format: PrintFormat::Both,
            plate_mm: [60.0, 50.0],
            ..Default::default()
        },
    }
}

const README: [[f32; 3]; 2] = [[0.0, 10.0, 13.0], [0.0, -14.0, 10.0]];
const THROUGH_THE_EYES: [[f32; 3]; 2] = [[0.0, 15.0, 8.0], [0.0, -8.0, 12.0]];

const MAGNET: MagnetOptions = MagnetOptions {
    diameter_mm: 3.0,
    height_mm: 2.0,
};

fn assert_printable(m: &Mesh) {
    let check = check_solid(m);
    assert!(check.is_closed_manifold(), "{}: {check:?}", m.name);
    assert_eq!(components(m).len(), 1, "{}: shells", m.name);
    assert!(volume(m) > 0.0, "{}: inside out", m.name);
    let crossing = self_intersecting_triangles(&m.positions, &m.triangles)
        .unwrap()
        .len();
    assert_eq!(crossing, 0, "{}: crossing triangles", m.name);
}

#[test]
fn magnet_pockets_take_the_magnet_from_every_piece_and_the_3mf_holds_them_all() {
    let anim = common::face(0.5);
    let plain = stopmo::run(&anim, &options(README, None)).unwrap();
    let held = stopmo::run(&anim, &options(README, Some(MAGNET))).unwrap();
    assert_eq!(plain.pieces.len(), held.pieces.len());
    let printing = held.report.printing.as_ref().unwrap();
    assert_eq!(printing.magnet, Some(MAGNET));
    assert_eq!(printing.clearance_mm, stopmo::default_clearance_mm(0.05));
    for (a, b) in plain.pieces.iter().zip(&held.pieces) {
        let (a, b) = (a.solid.as_ref().unwrap(), b.solid.as_ref().unwrap());
        assert_printable(b);
        let taken = volume(a) - volume(b);
        assert!(
            taken >= MAGNET.volume_mm3(),
            "{}: {taken:.2} mm³ taken, the magnet is {:.2}",
            b.name,
            MAGNET.volume_mm3()
        );
    }
    // One pocket per part, on its mount too; the mount is as printable as the pieces.
    assert_eq!(held.mounts.len(), 2);
    for (part, mount) in printing.parts.iter().zip(&held.mounts) {
        let q = part.magnet_pocket.expect("pocket");
        assert!(q.cover_mm >= stopmo::library::MIN_MAGNET_WALL_MM as f32);
        assert!(check_solid(mount).is_closed_manifold(), "{}", mount.name);
        assert_eq!(components(mount).len(), 1, "{}", mount.name);
        assert_eq!(mount.name, format!("{}_back", part.name));
    }
    // The report lists every piece with its frames, volume, magnet and plate, and the
    // plates hold every piece once.
    assert_eq!(printing.pieces.len(), held.pieces.len());
    let frames: usize = printing.pieces.iter().map(|p| p.frames.len()).sum();
    assert_eq!(frames, 2 * anim.frame_count());
    let mut on_plates: Vec<&String> = printing.plates.iter().flat_map(|p| &p.pieces).collect();
    on_plates.sort();
    let mut ids: Vec<&String> = held.pieces.iter().map(|p| &p.id).collect();
    ids.sort();
    assert_eq!(on_plates, ids);
    assert!(printing
        .pieces
        .iter()
        .all(|p| p.magnet && p.plate.is_some()));
    let paths: Vec<String> = held.files().unwrap().into_iter().map(|f| f.path).collect();
    for p in [
        "library.3mf",
        "pieces/upper_back.stl",
        "pieces/upper_00.stl",
    ] {
        assert!(paths.iter().any(|x| x == p), "{p} missing: {paths:?}");
    }
    let bytes = held.library_3mf.as_ref().unwrap();
    assert_eq!(&bytes[..2], b"PK");
    sheet_and_report_list_every_piece(&held);
    // A normal setting (1.5 mm walls, a 3×2 mm magnet at 60 mm) is printable: every piece
    // and mount is measured, nothing is under the printer's minimums and nothing warns.
    let checked = &printing.printability;
    assert_eq!(checked.min_wall_mm, stopmo::DEFAULT_MIN_WALL_MM);
    assert_eq!(checked.min_feature_mm, stopmo::DEFAULT_MIN_FEATURE_MM);
    assert_eq!(checked.solids.len(), held.pieces.len() + held.mounts.len());
    for c in &checked.solids {
        assert!(c.thinnest_wall_mm >= 0.8, "{c:?}");
        assert_eq!(c.smallest_feature_mm.is_some(), !c.mount, "{c:?}");
    }
    assert!(
        checked.under_minimum.is_empty(),
        "{:?}",
        checked.under_minimum
    );
    let thin: Vec<&String> = held
        .report
        .warnings
        .iter()
        .filter(|w| w.contains("printer's minimum"))
        .collect();
    assert!(thin.is_empty(), "{thin:?}");
}

/// `report.json` and `assembly.md` as written: every piece with its ID, part, frames used,
/// volume, magnet and plate, as the job measured them.
fn sheet_and_report_list_every_piece(held: &stopmo::LibraryResult) {
    let files = held.files().unwrap();
    let text = |name: &str| match &files.iter().find(|f| f.path == name).unwrap().data {
        stopmo::FileData::Text(t) => t.clone(),
        _ => panic!("{name} is not text"),
    };
    let report: serde_json::Value = serde_json::from_str(&text("report.json")).unwrap();
    let sheet = text("assembly.md");
    let listed = report["printing"]["pieces"].as_array().unwrap();
    assert_eq!(listed.len(), held.pieces.len());
    let labels = &held.library.parts;
    for (entry, piece) in listed.iter().zip(&held.pieces) {
        let solid = piece.solid.as_ref().unwrap();
        assert_eq!(entry["id"], piece.id.as_str());
        assert_eq!(entry["part"], labels[piece.part].name.as_str());
        let label = stopmo::piece_label(piece.part, piece.index);
        assert_eq!(entry["label"], label.as_str());
        let frames: Vec<usize> = labels[piece.part]
            .solution
            .labels
            .iter()
            .enumerate()
            .filter(|(_, &l)| l as usize == piece.index)
            .map(|(f, _)| f)
            .collect();
        let written: Vec<usize> = entry["frames"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_u64().unwrap() as usize)
            .collect();
        assert_eq!(written, frames, "{}", piece.id);
        let v = entry["volume_mm3"].as_f64().unwrap();
        assert!((v - volume(solid)).abs() <= 1e-6 * v, "{}: {v}", piece.id);
        assert_eq!(entry["magnet"], true);
        let plate = entry["plate"].as_u64().expect("a plate");
        let on = report["printing"]["plates"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["plate"] == plate)
            .unwrap();
        assert!(on["pieces"]
            .as_array()
            .unwrap()
            .iter()
            .any(|x| x == piece.id.as_str()));
        // The sheet's row: piece, ID, part, frames, volume, magnet, plate.
        let row = format!(
            "| {} | {label} | {} | {} | {v:.1} | yes | {plate} |",
            piece.id,
            labels[piece.part].name,
            frames.len()
        );
        assert!(sheet.contains(&row), "{row} not in the sheet:\n{sheet}");
    }
}

/// Walls and features under the printer's minimums warn, in `report.json` and on the
/// assembly sheet, naming the part, the pieces and the fix: 0.5 mm walls against the
/// default 0.8 mm, and a printer that forms nothing under 0.5 mm against the 0.4 mm relief
/// of the embossed IDs.
#[test]
fn thin_walls_and_features_warn_naming_the_pieces_and_the_fix() {
    let anim = common::face(0.5);
    let mut opts = options(README, None);
    opts.library.thickness_mm = 0.5;
    opts.library.min_feature_mm = 0.5;
    opts.library.print_format = PrintFormat::Stl;
    let thin = stopmo::run(&anim, &opts).unwrap();
    let checked = &thin.report.printing.as_ref().unwrap().printability;
    assert_eq!(checked.solids.len(), thin.pieces.len());
    for piece in &thin.pieces {
        let c = checked.solids.iter().find(|c| c.id == piece.id).unwrap();
        assert!(c.thinnest_wall_mm < 0.8, "{c:?}");
        assert!(checked
            .under_minimum
            .iter()
            .any(|t| t.id == piece.id && t.what == stopmo::Thin::FrontToBack));
        assert!(checked
            .under_minimum
            .iter()
            .any(|t| t.id == piece.id && t.what == stopmo::Thin::IdRelief && t.mm == 0.4));
    }
    let warned = |what: &str, fix: &str| -> Vec<&String> {
        thin.report
            .warnings
            .iter()
            .filter(|w| w.contains(what) && w.contains(fix) && w.contains("printer's minimum"))
            .collect()
    };
    let walls = warned(
        "wall between front and back",
        "give --thickness 0.8 or more",
    );
    let ids = warned("embossed ID relief", "--no-ids");
    assert_eq!(walls.len(), 2, "{:?}", thin.report.warnings);
    assert_eq!(ids.len(), 2, "{:?}", thin.report.warnings);
    for part in ["upper", "lower"] {
        assert!(walls
            .iter()
            .any(|w| w.starts_with(&format!("part {part}:")) && w.contains(&format!("{part}_0"))));
    }
    let sheet = thin.assembly_markdown();
    for w in walls.iter().chain(&ids) {
        assert!(sheet.contains(w.as_str()), "{w} not on the sheet");
    }
}

/// A cut the printing was not tuned on (the seam through the eyes: its solids cross as
/// built and are regularized), with a 4×3 mm magnet; and a magnet too large for any place.
#[test]
fn magnets_on_a_cut_not_tuned_on_and_a_magnet_too_large_is_refused() {
    let anim = common::face(0.5);
    let big = MagnetOptions {
        diameter_mm: 4.0,
        height_mm: 3.0,
    };
    let held = stopmo::run(&anim, &options(THROUGH_THE_EYES, Some(big))).unwrap();
    for p in &held.pieces {
        assert_printable(p.solid.as_ref().unwrap());
    }
    let huge = MagnetOptions {
        diameter_mm: 40.0,
        height_mm: 30.0,
    };
    let e = stopmo::run(&anim, &options(README, Some(huge))).unwrap_err();
    assert_eq!(e.option(), Some("magnets"), "{e}");
    assert!(e.to_string().contains("part upper"), "{e}");
}

/// Cuts of the face none of the printing was tuned on (upper and lower seeds), each with its
/// own solver seed and piece count. The first was refused before pockets were looked for away
/// from the eye and mouth openings (where the back is deepest); the second, one piece per
/// part, leaves the upper part's back too thin for the pocket at the default 1.5 mm: a boss.
const UNTUNED: [([[f32; 3]; 2], u64, usize); 3] = [
    ([[0.0, 12.0, 11.0], [0.0, -11.0, 12.0]], 7, 3),
    ([[0.0, 5.0, 14.0], [0.0, -16.0, 6.0]], 11, 1),
    ([[6.0, 10.0, 10.0], [-6.0, -12.0, 10.0]], 23, 2),
];

/// With the defaults (1.5 mm back, 0.8 mm printer wall) and `--magnets 3x2`, on every cut of
/// [`UNTUNED`]: a pocket in every part (in a boss where the back is too thin), every piece
/// and mount one closed, outward shell with no self-intersecting triangle (exact test), the
/// printability checks finding nothing under the printer's minimums, and the magnet fitting
/// its pocket in every piece with material around and in front of it.
#[test]
fn magnets_with_the_defaults_fit_cuts_not_tuned_on() {
    let anim = common::face(0.5);
    let mut bosses = 0;
    for (seeds, seed, pieces) in UNTUNED {
        let mut opts = options(seeds, Some(MAGNET));
        opts.library.pieces = PieceCount::Each(pieces);
        opts.library.solve.seed = seed;
        opts.library.print_format = PrintFormat::Stl;
        let held = stopmo::run(&anim, &opts).unwrap_or_else(|e| panic!("{seeds:?}: {e}"));
        let printing = held.report.printing.as_ref().unwrap();
        for m in held
            .pieces
            .iter()
            .filter_map(|p| p.solid.as_ref())
            .chain(&held.mounts)
        {
            assert_printable(m);
        }
        let checked = &printing.printability;
        assert_eq!(checked.solids.len(), held.pieces.len() + held.mounts.len());
        assert!(
            checked.under_minimum.is_empty(),
            "{seeds:?}: {:?}",
            checked.under_minimum
        );
        let thin: Vec<&String> = held
            .report
            .warnings
            .iter()
            .filter(|w| w.contains("printer's minimum") || w.contains("cross the solid"))
            .collect();
        assert!(thin.is_empty(), "{seeds:?}: {thin:?}");
        for piece in &held.pieces {
            let part = &printing.parts[piece.part];
            let q = part.magnet_pocket.expect("a pocket in every part");
            bosses += usize::from(piece.index == 0 && q.boss.is_some());
            magnet_fits(piece.solid.as_ref().unwrap(), &q);
        }
    }
    // The sweep holds a boss, or it checks nothing new.
    assert!(bosses >= 1, "{bosses} parts with a boss");
}

/// The magnet (3×2 mm) seated on the pocket's floor is in empty space, and the piece holds it:
/// material a wall's half around its side and in front of its floor.
fn magnet_fits(solid: &Mesh, q: &stopmo::library::Pocket) {
    let axis = Vec3::from_array(q.axis);
    let floor = q.opening() + axis * q.depth_mm;
    let u = axis.any_orthonormal_vector();
    let w = axis.cross(u);
    let (r, h) = (MAGNET.diameter_mm as f32 / 2.0, MAGNET.height_mm as f32);
    let wall = stopmo::DEFAULT_MIN_WALL_MM as f32;
    let at = |radius: f32, angle: f32, below_floor: f32| {
        floor + (u * angle.cos() + w * angle.sin()) * radius - axis * below_floor
    };
    for i in 0..12 {
        let angle = std::f32::consts::TAU * i as f32 / 12.0;
        for k in 0..=4 {
            let below = h * k as f32 / 4.0;
            for radius in [0.0, 0.5 * r, 0.98 * r] {
                let p = at(radius, angle, below.clamp(0.01, h - 0.01));
                let wn = winding_number(solid, p);
                assert!(
                    wn.abs() < 0.5,
                    "{}: magnet point {p} inside ({wn})",
                    solid.name
                );
            }
            // Beside the pocket (in the boss where there is one) around the magnet's inner
            // part: towards the opening a curved back may come forward (up to half the
            // pocket's depth, as the placement allows).
            let p = at(q.radius_mm + 0.5 * wall, angle, below.clamp(0.01, 0.4 * h));
            let wn = winding_number(solid, p);
            assert!(
                wn > 0.5,
                "{}: no material beside the magnet at {p}",
                solid.name
            );
        }
        let p = at(0.5 * r, angle, -0.5 * wall);
        assert!(
            winding_number(solid, p) > 0.5,
            "{}: no material in front of the magnet at {p}",
            solid.name
        );
    }
}

/// Generalized winding number of a closed mesh at `p` (1 inside, 0 outside): the solid
/// angles of its triangles (Van Oosterom and Strackee 1983) over 4π.
fn winding_number(m: &Mesh, p: Vec3) -> f64 {
    let total: f64 = m
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| (m.positions[i as usize] - p).as_dvec3());
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let num = a.dot(b.cross(c));
            let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
            2.0 * num.atan2(den)
        })
        .sum();
    total / (4.0 * std::f64::consts::PI)
}
