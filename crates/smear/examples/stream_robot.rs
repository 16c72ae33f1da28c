//! Streaming smear throughput (issue #22): pushes every frame of a clip through
//! [`smear::Stream`] (causal offsets, smoothing and elongation) and prints frames per second.
//!
//! ```text
//! cargo run --release -p toonkit-smear --example stream_robot [IN.glb] [CLIP] [PASSES]
//! ```
//! Default: `assets/characters/RobotExpressive.glb`, clip `Running`, 20 passes over the clip.

use std::path::{Path, PathBuf};
use std::time::Instant;

use smear::{FunctionSpec, Stream, StreamOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let input = args.next().map(PathBuf::from).unwrap_or_else(|| {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/characters/RobotExpressive.glb")
    });
    let clip = args.next().unwrap_or_else(|| "Running".into());
    let passes: usize = args.next().map_or(Ok(20), |p| p.parse())?;
    let tkio::Loaded::Scene(scene) = tkio::load(&input, &tkio::LoadOptions::default())? else {
        return Err(format!("{}: not a scene", input.display()).into());
    };
    let options = anim::SampleOptions {
        clip: Some(scene.find_clip(&clip)?),
        ..anim::SampleOptions::default()
    };
    let merged = anim::sample(&scene, &options)?.merged("robot")?;
    let (frames, n) = (merged.frame_count(), merged.vertex_count());
    let mut stream = Stream::new(
        &merged.mesh,
        &StreamOptions {
            elongate: FunctionSpec::speed(3.0),
            ..StreamOptions::default()
        },
    )?;
    let t = Instant::now();
    let mut check = 0.0f64;
    for _ in 0..passes {
        for f in 0..frames {
            let out = stream.push(merged.frame(f))?;
            check += out[f % n].x as f64;
        }
    }
    let seconds = t.elapsed().as_secs_f64();
    let pushed = passes * frames;
    println!(
        "{} '{clip}': {n} vertices, {pushed} frames pushed in {:.3} s = {:.0} frames/s ({:.3} ms/frame; checksum {check:.3})",
        input.display(),
        seconds,
        pushed as f64 / seconds,
        seconds * 1e3 / pushed as f64,
    );
    Ok(())
}
