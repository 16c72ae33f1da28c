//! Writes the procedural low-poly four-legged critter of the issue #22 tests (60 triangles,
//! planted feet) as a point cache `OUT.pc2` + rest `OUT.obj`, for trying `--subdivide`,
//! `--ground` and `--causal` on the command line.
//!
//! Run: `cargo run -p toonkit-smear --example write_critter -- OUT.pc2 [SPEED] [FRAMES]`
//! (speed 0.35 runs, 0.1 walks).

#[path = "../tests/beyond/legged.rs"]
mod legged;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let out = std::path::PathBuf::from(
        args.next()
            .ok_or("usage: write_critter OUT.pc2 [SPEED] [FRAMES]")?,
    );
    let speed: f32 = args.next().map_or(Ok(0.35), |s| s.parse())?;
    let frames: usize = args.next().map_or(Ok(24), |s| s.parse())?;
    let anim = legged::gait(frames, speed, 0.3);
    tkio::save(
        &out,
        &tkio::Output::Animation {
            animation: &anim,
            layout: tkio::Layout::Flipbook,
            colors: None,
        },
    )?;
    println!(
        "wrote {} ({frames} frames, {} triangles)",
        out.display(),
        anim.mesh.triangle_count()
    );
    Ok(())
}
