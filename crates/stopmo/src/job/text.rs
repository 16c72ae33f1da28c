//! The text and image files of a library: assembly sheet (CSV and Markdown), shooting order,
//! size-versus-error curve (CSV and chart).

use std::fmt::Write as _;

use super::result::LibraryResult;

impl LibraryResult {
    /// `assembly.csv`: header `frame,<part>,...`, one row per frame with the piece ids.
    pub fn assembly_csv(&self) -> String {
        let mut csv = format!("frame,{}\n", self.part_names.join(","));
        for (f, row) in self.frame_ids().iter().enumerate() {
            let _ = writeln!(csv, "{f},{}", row.join(","));
        }
        csv
    }

    /// `assembly.md`: pieces per part, then runs of frames with the same assembly.
    pub fn assembly_markdown(&self) -> String {
        let ids = self.frame_ids();
        let names = &self.part_names;
        let mut md = String::from("# Assembly sheet\n\n");
        let _ = writeln!(
            md,
            "{} frames, {} pieces ({}).\n",
            ids.len(),
            self.library.total_pieces(),
            self.library
                .parts
                .iter()
                .map(|p| format!("{}: {}", p.name, p.solution.pieces.len()))
                .collect::<Vec<_>>()
                .join(", ")
        );
        let _ = writeln!(
            md,
            "Piece IDs embossed on the backs: {}; renders in catalogue.png, thumbnails per shot in assembly_shotNN.png.\n",
            self.library
                .parts
                .iter()
                .enumerate()
                .map(|(p, part)| format!("{} = {}-NN", part.name, p + 1))
                .collect::<Vec<_>>()
                .join(", ")
        );
        let _ = writeln!(md, "| frames | {} |", names.join(" | "));
        let _ = writeln!(md, "|---|{}", "---|".repeat(names.len()));
        let mut f = 0;
        while f < ids.len() {
            let mut end = f;
            while end + 1 < ids.len() && ids[end + 1] == ids[f] {
                end += 1;
            }
            let range = if end == f {
                f.to_string()
            } else {
                format!("{f}–{end}")
            };
            let _ = writeln!(md, "| {range} | {} |", ids[f].join(" | "));
            f = end + 1;
        }
        self.print_markdown(&mut md);
        md
    }

    /// The printing half of `assembly.md`: fits, magnets, plates and one line per piece.
    fn print_markdown(&self, md: &mut String) {
        let Some(p) = &self.report.printing else {
            return;
        };
        let _ = writeln!(md, "\n## Printing\n");
        let _ = writeln!(
            md,
            "Millimetres. Clearance of fits: {} mm. Files: {}.",
            p.clearance_mm,
            match p.print_format {
                super::options::PrintFormat::Stl => "pieces/<ID>.stl",
                super::options::PrintFormat::ThreeMf => "library.3mf",
                super::options::PrintFormat::Both => "pieces/<ID>.stl and library.3mf",
            }
        );
        if let Some(m) = &p.magnet {
            let _ = writeln!(
                md,
                "Magnets: {} x {} mm discs, one in every piece and one in each part's mount (pieces/<part>_back.stl), at the same place:",
                m.diameter_mm, m.height_mm
            );
            for part in &p.parts {
                if let Some(q) = &part.magnet_pocket {
                    let _ = writeln!(
                        md,
                        "- {}: pocket {:.2} mm wide, {:.2} mm deep at ({:.1}, {:.1}, {:.1}); {:.2} mm of material in front of it{}",
                        part.name,
                        2.0 * q.radius_mm,
                        q.depth_mm,
                        q.center[0],
                        q.center[1],
                        q.center[2],
                        q.cover_mm,
                        q.boss.map_or(String::new(), |b| format!(
                            "; it stands in a boss {:.2} mm wide and {:.2} mm high on the back of every piece, which the mount's recess takes",
                            2.0 * b.radius_mm,
                            b.height_mm
                        ))
                    );
                }
            }
        }
        for plate in &p.plates {
            let _ = writeln!(
                md,
                "Plate {} ({} x {} mm): {}.",
                plate.plate,
                plate.size_mm[0],
                plate.size_mm[1],
                plate.pieces.join(", ")
            );
        }
        let checked = &p.printability;
        let _ = writeln!(
            md,
            "\nThe printer's minimums: walls {} mm, free-standing features {} mm.",
            checked.min_wall_mm, checked.min_feature_mm
        );
        let _ = writeln!(
            md,
            "\n| piece | ID | part | frames | volume (mm³) | magnet | plate | thinnest wall (mm) | smallest feature (mm) |\n|---|---|---|---|---|---|---|---|---|"
        );
        let fit = |id: &str| checked.solids.iter().find(|c| c.id == id);
        for q in &p.pieces {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {:.1} | {} | {} | {} | {} |",
                q.id,
                q.label,
                q.part,
                q.frames.len(),
                q.volume_mm3,
                if q.magnet { "yes" } else { "no" },
                q.plate.map_or("–".to_string(), |k| k.to_string()),
                fit(&q.id).map_or("–".into(), |c| format!("{:.2}", c.thinnest_wall_mm)),
                fit(&q.id)
                    .and_then(|c| c.smallest_feature_mm)
                    .map_or("–".into(), |f| format!("{f:.2}"))
            );
        }
        for c in checked.solids.iter().filter(|c| c.mount) {
            let _ = writeln!(
                md,
                "\nMount pieces/{}.stl (part {}): thinnest wall {:.2} mm.",
                c.id, c.part, c.thinnest_wall_mm
            );
        }
        for w in &self.report.warnings {
            let _ = writeln!(md, "\nWarning: {w}");
        }
    }

    /// `shooting_order.csv`: header `shot,<part>,...,frames`, one row per shot with its
    /// pieces and the frames (space separated) photographed with them.
    pub fn shooting_order_csv(&self) -> String {
        let ids = self.frame_ids();
        let mut csv = format!("shot,{},frames\n", self.part_names.join(","));
        for (s, shot) in self.shooting_order.shots.iter().enumerate() {
            let pieces = &ids[shot.frames[0]];
            let frames: Vec<String> = shot.frames.iter().map(|f| f.to_string()).collect();
            let _ = writeln!(csv, "{s},{},{}", pieces.join(","), frames.join(" "));
        }
        csv
    }

    /// `error_curve.csv` after a size search (StopShop Figs. 8/16): header
    /// `part,pieces,energy,worst_frame_error_mm,mean_error_mm`; `None` without a search.
    pub fn error_curve_csv(&self) -> Option<String> {
        if !self.has_curve() {
            return None;
        }
        let mm = self.library.mm_per_unit;
        let mut csv = String::from("part,pieces,energy,worst_frame_error_mm,mean_error_mm\n");
        for p in &self.library.parts {
            for c in &p.curve {
                let _ = writeln!(
                    csv,
                    "{},{},{},{},{}",
                    p.name,
                    c.pieces,
                    c.energy,
                    c.worst_frame_error * mm,
                    c.mean_error * mm
                );
            }
        }
        Some(csv)
    }

    /// `error_curve.png` after a size search: one colour per part (`render::categorical` in
    /// part order), a solid line for the worst frame's mean position error and a dashed one
    /// for the mean over frames, against the number of pieces; errors in **micrometres** at
    /// the print height (the chart's digits-only labels). `None` without a search.
    ///
    /// # Errors
    /// Only if the image cannot be allocated or encoded.
    pub fn error_curve_png(&self) -> render::Result<Option<Vec<u8>>> {
        if !self.has_curve() {
            return Ok(None);
        }
        let um = self.library.mm_per_unit * 1000.0;
        let mut series = Vec::new();
        for (i, part) in self.library.parts.iter().enumerate() {
            let color = render::to_srgb8(render::categorical(i));
            let pts = |f: fn(&crate::library::CurvePoint) -> f64| {
                part.curve
                    .iter()
                    .map(|c| (c.pieces as f64, f(c) * um))
                    .collect::<Vec<_>>()
            };
            series.push(render::chart::Series::solid(
                color,
                pts(|c| c.worst_frame_error),
            ));
            series.push(render::chart::Series::dashed(color, pts(|c| c.mean_error)));
        }
        let image = render::chart::line_chart(&series)?;
        Ok(Some(render::encode_png(&image)?))
    }
}
