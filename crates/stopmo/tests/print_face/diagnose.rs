//! Diagnostics of crossing solids (ignored; run with `--ignored --nocapture`).

use super::*;

/// Diagnostics: which parts of the solids cross (run with `--ignored --nocapture`;
/// `STOPMO_PIECES` sets the library size, default 8; `STOPMO_AUTO_PARTS=N` cuts N automatic
/// parts, `STOPMO_SEEDS="x,y,z;x,y,z"` one part per point seed, `STOPMO_HEIGHT=MM` another
/// print height).
#[test]
#[ignore]
fn diagnose_crossings() {
    let pieces: usize = std::env::var("STOPMO_PIECES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(8);
    // STOPMO_AUTO_PARTS=N: N automatic parts instead of the README's seeds.
    let auto: Option<usize> = std::env::var("STOPMO_AUTO_PARTS")
        .ok()
        .and_then(|s| s.parse().ok());
    // STOPMO_SEEDS="x,y,z;x,y,z": one part per point seed (mm of the input) instead.
    let seeds: Option<Vec<PartSpec>> = std::env::var("STOPMO_SEEDS").ok().map(|s| {
        s.split(';')
            .enumerate()
            .map(|(k, p)| {
                let c: Vec<f32> = p
                    .split(',')
                    .map(|x| x.trim().parse().expect("x,y,z"))
                    .collect();
                PartSpec::new(
                    format!("p{k}"),
                    vec![Seed::Point(Vec3::new(c[0], c[1], c[2]))],
                )
            })
            .collect()
    });
    let anims = match (auto, seeds) {
        (_, Some(parts)) => {
            part_animations(&segment(face(), &parts, &SegmentOptions::default()).expect("segment"))
        }
        (Some(n), None) => {
            let parts = auto_parts(face(), n).expect("auto parts");
            part_animations(&segment(face(), &parts, &SegmentOptions::default()).expect("segment"))
        }
        (None, None) => part_animations(segmentation()),
    };
    let refs: Vec<&MeshAnimation> = anims.iter().collect();
    let lib = library_of(&anims, pieces);
    // STOPMO_HEIGHT=MM: another print height than the acceptance's.
    let height: f64 = std::env::var("STOPMO_HEIGHT")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(HEIGHT_MM);
    let mm = print_scale(&refs, height) as f32;
    let all_mm = in_mm(&lib, mm);
    for (p, (shell, keys, _)) in shells(&anims, &all_mm, mm, height).into_iter().enumerate() {
        let a = &anims[p];
        let pieces_mm = &all_mm[p];
        let avg: Vec<Vec3> = a.average_positions().iter().map(|x| *x * mm).collect();
        let avg_hits = self_intersecting_triangles(&avg, &a.mesh.triangles).unwrap();
        let input_hits: usize = (0..a.frame_count())
            .map(|f| {
                let x: Vec<Vec3> = a.frame(f).iter().map(|v| *v * mm).collect();
                self_intersecting_triangles(&x, &a.mesh.triangles)
                    .unwrap()
                    .len()
            })
            .max()
            .unwrap_or(0);
        eprintln!(
            "part {}: {} triangles; average crosses {}, worst input frame {}",
            a.mesh.name,
            a.mesh.triangles.len(),
            avg_hits.len(),
            input_hits
        );
        eprintln!("  shell {:?}, {} keys", shell.stats, keys.len());
        let t = shell.triangles().len() as u32;
        let caps = shell.cap_triangle_count() as u32;
        let kind = |x: u32| -> &'static str {
            if x < t - caps {
                "front"
            } else if x < t {
                "front-cap"
            } else if x < 2 * t - caps {
                "back"
            } else if x < 2 * t {
                "back-cap"
            } else {
                "wall"
            }
        };
        for (k, piece) in pieces_mm.iter().enumerate() {
            let front = self_intersecting_triangles(piece, &a.mesh.triangles).unwrap();
            let solid = shell
                .solid_with_id(piece, "x", &id_bitmap(), 0.5, 0.4, &keys)
                .unwrap();
            let pairs =
                stopmo::library::intersecting_pairs(&solid.positions, &solid.triangles).unwrap();
            let mut tally: std::collections::BTreeMap<(&str, &str), usize> = Default::default();
            for &(i, j) in &pairs {
                *tally.entry((kind(i), kind(j))).or_default() += 1;
            }
            let centre = |x: u32| {
                solid.triangles[x as usize]
                    .iter()
                    .map(|&v| solid.positions[v as usize])
                    .sum::<Vec3>()
                    / 3.0
            };
            let samples: Vec<String> = pairs
                .iter()
                .step_by((pairs.len() / 6).max(1))
                .map(|&(i, j)| {
                    let c = centre(i);
                    format!("{}/{}@({:.1},{:.1},{:.1})", kind(i), kind(j), c.x, c.y, c.z)
                })
                .collect();
            // STOPMO_DUMP=DIR: every solid as OBJ, the triangle ranges of each kind and the
            // crossing pairs.
            if let Ok(dir) = std::env::var("STOPMO_DUMP") {
                let base = format!("{dir}/{}_{k}", a.mesh.name);
                std::fs::write(format!("{base}.obj"), tkio::obj::write(&solid)).unwrap();
                let mut ranges = String::new();
                let mut start = 0u32;
                for i in 1..=solid.triangles.len() as u32 {
                    if i == solid.triangles.len() as u32 || kind(i) != kind(start) {
                        ranges += &format!("{} {start} {i}\n", kind(start));
                        start = i;
                    }
                }
                std::fs::write(format!("{base}.kinds"), ranges).unwrap();
                let list: String = pairs.iter().map(|(i, j)| format!("{i} {j}\n")).collect();
                std::fs::write(format!("{base}.pairs"), list).unwrap();
            }
            eprintln!(
                "  piece {k}: front alone {}, solid pairs {} {:?}; wall {:.3} mm; e.g. {}",
                front.len(),
                pairs.len(),
                tally,
                shell.min_wall(piece),
                samples.join(" ")
            );
        }
    }
}
