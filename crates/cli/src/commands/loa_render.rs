//! Raster previews of a line of action through the render crate: a PNG onion skin of every
//! frame (keystrokes in red, as the paper's Fig. 3) or an animated GIF.

use anim::glam::{Vec2, Vec3};
use anim::Aabb;
use anyhow::Result;
use render::{Color, Coords, DrawList, Overlay, Renderer, View, ViewDirection};

/// Image size of line previews.
pub const DEFAULT_SIZE: (u32, u32) = (640, 480);
const MARGIN: f32 = 0.08;
const KEY_RED: Color = [0.85, 0.1, 0.1, 1.0];
const LINE_BLUE: Color = [0.12, 0.3, 0.75, 1.0];

/// Maps the keystrokes' screen coordinates (y down) into the image, keeping proportions.
struct Fit {
    min: Vec2,
    scale: f32,
    offset: Vec2,
}

impl Fit {
    fn new(points: impl Iterator<Item = Vec2>, (w, h): (u32, u32)) -> Fit {
        let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for p in points.filter(|p| p.is_finite()) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        if lo.x > hi.x {
            (lo, hi) = (Vec2::ZERO, Vec2::ONE);
        }
        let size = (hi - lo).max(Vec2::splat(1e-6));
        let avail = Vec2::new(w as f32, h as f32) * (1.0 - 2.0 * MARGIN);
        let scale = (avail.x / size.x).min(avail.y / size.y);
        let offset = (Vec2::new(w as f32, h as f32) - size * scale) * 0.5;
        Fit {
            min: lo,
            scale,
            offset,
        }
    }

    fn map(&self, p: Vec2) -> Vec2 {
        (p - self.min) * self.scale + self.offset
    }
}

fn to_vec2(p: anim::glam::DVec2) -> Vec2 {
    Vec2::new(p.x as f32, p.y as f32)
}

fn polyline(fit: &Fit, pts: impl Iterator<Item = Vec2>, color: Color, width: f32) -> Overlay {
    Overlay::polyline(
        Coords::Pixel(pts.map(|p| fit.map(p)).collect()),
        color,
        width,
    )
}

/// Renders the animated line; `gif` picks an animation over a single onion-skin PNG.
pub fn render_line(
    animation: &loa::Animation,
    keys: &loa::Keystrokes,
    gif: bool,
) -> Result<Vec<u8>> {
    let size = DEFAULT_SIZE;
    let chains: Vec<Vec<Vec2>> = animation
        .frames
        .iter()
        .map(|f| f.chain.joints().into_iter().map(to_vec2).collect())
        .collect();
    let strokes: Vec<Vec<Vec2>> = keys
        .keys()
        .iter()
        .map(|k| k.stroke.points().iter().copied().map(to_vec2).collect())
        .collect();
    let fit = Fit::new(chains.iter().chain(&strokes).flatten().copied(), size);
    let renderer = Renderer::new(size.0, size.1)?;
    let view = View::fit(
        Aabb {
            min: Vec3::ZERO,
            max: Vec3::ONE,
        },
        ViewDirection::Front,
        renderer.aspect(),
    );
    let keys_faint: Vec<Overlay> = strokes
        .iter()
        .map(|s| {
            polyline(
                &fit,
                s.iter().copied(),
                [KEY_RED[0], KEY_RED[1], KEY_RED[2], 0.35],
                3.0,
            )
        })
        .collect();
    if gif {
        let frames: Result<Vec<_>, _> = chains
            .iter()
            .map(|c| {
                let mut list = DrawList::new();
                for k in &keys_faint {
                    list = list.overlay(k.clone());
                }
                list = list.overlay(polyline(&fit, c.iter().copied(), LINE_BLUE, 4.0));
                renderer.render(&list, &view)
            })
            .collect();
        return Ok(render::encode_gif(&frames?, animation.fps as f32)?);
    }
    let mut list = DrawList::new();
    let n = chains.len().max(1) as f32;
    for (i, c) in chains.iter().enumerate() {
        let a = 0.15 + 0.6 * (i as f32 / n);
        list = list.overlay(polyline(
            &fit,
            c.iter().copied(),
            [LINE_BLUE[0], LINE_BLUE[1], LINE_BLUE[2], a],
            1.5,
        ));
    }
    for s in &strokes {
        list = list.overlay(polyline(&fit, s.iter().copied(), KEY_RED, 3.5));
    }
    Ok(render::encode_png(&renderer.render(&list, &view)?)?)
}
