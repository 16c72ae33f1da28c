//! Previews of a 2D line of action in screen coordinates (y down): a PNG onion skin of every
//! frame with the keystrokes in red (as LoA Fig. 3), or an animated GIF.

use anim::Aabb;
use glam::{Vec2, Vec3};

use crate::ViewDirection;
use crate::{encode_gif, encode_png, Color, Coords, DrawList, Overlay, Renderer, Result, View};

/// Image size of line previews.
pub const DEFAULT_LINE_PREVIEW_SIZE: (u32, u32) = (640, 480);
const MARGIN: f32 = 0.08;
const KEY_RED: Color = [0.85, 0.1, 0.1, 1.0];
const LINE_BLUE: Color = [0.12, 0.3, 0.75, 1.0];

/// Maps screen coordinates (y down) into the image, keeping proportions.
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

    fn polyline(&self, pts: &[Vec2], color: Color, width: f32) -> Overlay {
        let pixels = pts
            .iter()
            .map(|&p| (p - self.min) * self.scale + self.offset)
            .collect();
        Overlay::polyline(Coords::Pixel(pixels), color, width)
    }
}

/// Renders a line of action: `chains` holds the line's points per frame, `strokes` the
/// keystrokes (both in screen coordinates, y down). `gif` gives every frame at `fps` over the
/// faint keystrokes; otherwise one PNG onion skin (frames fading in, keystrokes in red).
///
/// # Errors
/// Encoding failures (none for finite input).
pub fn line_preview(
    chains: &[Vec<Vec2>],
    strokes: &[Vec<Vec2>],
    fps: f32,
    gif: bool,
) -> Result<Vec<u8>> {
    let size = DEFAULT_LINE_PREVIEW_SIZE;
    let fit = Fit::new(chains.iter().chain(strokes).flatten().copied(), size);
    let renderer = Renderer::new(size.0, size.1)?;
    // Overlays are in pixels; any view works.
    let unit = Aabb {
        min: Vec3::ZERO,
        max: Vec3::ONE,
    };
    let view = View::fit(unit, ViewDirection::Front, renderer.aspect());
    let faint = [KEY_RED[0], KEY_RED[1], KEY_RED[2], 0.35];
    let keys_faint: Vec<Overlay> = strokes
        .iter()
        .map(|s| fit.polyline(s, faint, 3.0))
        .collect();
    if gif {
        renderer.check_frames(chains.len())?;
        let frames: Result<Vec<_>> = chains
            .iter()
            .map(|c| {
                let mut list = DrawList::new();
                for k in &keys_faint {
                    list = list.overlay(k.clone());
                }
                list = list.overlay(fit.polyline(c, LINE_BLUE, 4.0));
                renderer.render(&list, &view)
            })
            .collect();
        return encode_gif(&frames?, fps);
    }
    let mut list = DrawList::new();
    let n = chains.len().max(1) as f32;
    for (i, c) in chains.iter().enumerate() {
        let a = 0.15 + 0.6 * (i as f32 / n);
        list = list.overlay(fit.polyline(c, [LINE_BLUE[0], LINE_BLUE[1], LINE_BLUE[2], a], 1.5));
    }
    for s in strokes {
        list = list.overlay(fit.polyline(s, KEY_RED, 3.5));
    }
    encode_png(&renderer.render(&list, &view)?)
}
