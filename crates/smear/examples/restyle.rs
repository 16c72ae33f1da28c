//! Live tuning in numbers: prepares RobotExpressive's Dance once and stylizes it with the
//! speed elongation of paper Fig. 11c (the first call: prepare + stylize), then restyles the
//! same prepared offsets with every style of `examples/smear/` (second calls: stylize only)
//! and prints the times and the first/second ratios.
//!
//! Run: `cargo run --release -p toonkit-smear --example restyle [-- CHARACTER.glb [CLIP]]`
//! (default: the bundled `assets/characters/RobotExpressive.glb`, clip `Dance`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use smear::{prepare, stylize, PrepareOptions, Style};

fn style(name: &str) -> Result<Style, Box<dyn std::error::Error>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/smear")
        .join(name);
    Ok(Style::from_toml_str(&std::fs::read_to_string(path)?)?)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let input = args.next().map(PathBuf::from).unwrap_or_else(|| {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/characters/RobotExpressive.glb")
    });
    let clip = args.next().unwrap_or_else(|| "Dance".into());
    let tkio::Loaded::Scene(scene) = tkio::load(&input, &tkio::LoadOptions::default())? else {
        return Err(format!("{}: not a scene", input.display()).into());
    };
    let options = anim::SampleOptions {
        clip: Some(scene.find_clip(&clip)?),
        ..anim::SampleOptions::default()
    };
    let sampled = anim::sample(&scene, &options)?;
    let first_style = style("fig11c_speed.toml")?;
    let vertices = sampled.vertex_count();
    let frames = sampled.frame_count;
    println!(
        "{} '{clip}': {vertices} vertices × {frames} frames",
        input.display()
    );

    let t = Instant::now();
    let prepared = prepare(
        sampled,
        &PrepareOptions {
            offsets: first_style.offsets.clone(),
            ..PrepareOptions::default()
        },
    )?;
    let prepare_seconds = t.elapsed().as_secs_f64();
    let first = stylize(&prepared, &first_style)?;
    let first_seconds = t.elapsed().as_secs_f64();
    println!(
        "first:  prepare {:.1} ms (offset solve {:.1} ms) + stylize fig11c_speed {:.1} ms = {:.1} ms",
        prepare_seconds * 1e3,
        prepared.report().solve_seconds * 1e3,
        first.report.seconds.total * 1e3,
        first_seconds * 1e3,
    );
    let solves = smear::offset_solves();
    let mut names: Vec<PathBuf> =
        std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/smear"))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .collect();
    names.sort();
    for path in names {
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default();
        let second_style = style(name)?;
        if second_style.offsets != first_style.offsets {
            println!("second: {name} needs other offset options (prepare again), skipped");
            continue;
        }
        let t = Instant::now();
        // A style written for another character (e.g. its joint names) does not fit this one.
        let second = match stylize(&prepared, &second_style) {
            Ok(second) => second,
            Err(e) => {
                println!("second: {name} does not fit this character ({e}), skipped");
                continue;
            }
        };
        let s = t.elapsed().as_secs_f64();
        println!(
            "second: stylize {name} {:.1} ms ({} parts) — {:.1}× faster than the first call",
            s * 1e3,
            second.flipbook.parts.len(),
            first_seconds / s
        );
    }
    println!(
        "offset solves during restyling: {}",
        smear::offset_solves() - solves
    );
    Ok(())
}
