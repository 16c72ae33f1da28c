//! Live tuning in numbers: prepares RobotExpressive's Dance once, stylizes it with the
//! combined style of paper Fig. 16, then restyles it with the speed elongation of Fig. 11c,
//! and prints the first (prepare + stylize) and second (stylize only) times.
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
    let (first_style, second_style) = (style("fig16_combined.toml")?, style("fig11c_speed.toml")?);
    let vertices = sampled.vertex_count();
    let frames = sampled.frame_count;

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
    let t = Instant::now();
    let second = stylize(&prepared, &second_style)?;
    let second_seconds = t.elapsed().as_secs_f64();
    println!(
        "{} '{clip}': {vertices} vertices × {frames} frames",
        input.display()
    );
    println!(
        "first:  prepare {:.1} ms (offset solve {:.1} ms) + stylize fig16 {:.1} ms = {:.1} ms ({} parts)",
        prepare_seconds * 1e3,
        prepared.report().solve_seconds * 1e3,
        first.report.seconds.total * 1e3,
        first_seconds * 1e3,
        first.flipbook.parts.len()
    );
    println!(
        "second: stylize fig11c {:.1} ms ({} parts, {} offset solves) — {:.1}× faster",
        second_seconds * 1e3,
        second.flipbook.parts.len(),
        second.report.offset_solves,
        first_seconds / second_seconds
    );
    Ok(())
}
