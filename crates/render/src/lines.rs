//! Anti-aliased overlays: polylines (round caps and joins) and dots, optionally depth-tested.
//!
//! A whole overlay is first rendered into a coverage layer keeping, per pixel, the largest
//! coverage of any of its segments, and then composited once: overlapping segments of one
//! polyline never double their opacity.

use glam::{Vec2, Vec4};

use crate::raster::Target;

/// Depth tolerance (in `[0, 1]` depth units) for depth-tested overlays, so that lines lying
/// on a surface are not hidden by it.
pub const DEFAULT_LINE_DEPTH_BIAS: f32 = 4e-3;

/// A point of an overlay in target pixels, with depth (`None`: always in front) and colour.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LinePoint {
    pub p: Vec2,
    pub depth: Option<f32>,
    pub color: Vec4,
}

/// Draws segments `(a, b)` (a dot when `a == b`) of width `width` pixels as one layer.
pub(crate) fn draw_segments(target: &mut Target, segments: &[(LinePoint, LinePoint)], width: f32) {
    let r = (width * 0.5).max(0.0);
    if segments.is_empty() || !r.is_finite() {
        return;
    }
    let (w, h) = (target.width as i64, target.height as i64);
    // Layer bounds.
    let mut lo = Vec2::splat(f32::INFINITY);
    let mut hi = Vec2::splat(f32::NEG_INFINITY);
    for (a, b) in segments {
        lo = lo.min(a.p).min(b.p);
        hi = hi.max(a.p).max(b.p);
    }
    let pad = r + 1.0;
    let x0 = ((lo.x - pad).floor() as i64).max(0);
    let y0 = ((lo.y - pad).floor() as i64).max(0);
    let x1 = ((hi.x + pad).ceil() as i64).min(w - 1);
    let y1 = ((hi.y + pad).ceil() as i64).min(h - 1);
    if x0 > x1 || y0 > y1 {
        return;
    }
    let lw = (x1 - x0 + 1) as usize;
    let lh = (y1 - y0 + 1) as usize;
    let mut cov = vec![0.0f32; lw * lh];
    let mut col = vec![Vec4::ZERO; lw * lh];
    for (a, b) in segments {
        let sx0 = ((a.p.x.min(b.p.x) - pad).floor() as i64).max(x0);
        let sy0 = ((a.p.y.min(b.p.y) - pad).floor() as i64).max(y0);
        let sx1 = ((a.p.x.max(b.p.x) + pad).ceil() as i64).min(x1);
        let sy1 = ((a.p.y.max(b.p.y) + pad).ceil() as i64).min(y1);
        let ab = b.p - a.p;
        let len2 = ab.length_squared();
        for y in sy0..=sy1 {
            for x in sx0..=sx1 {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let t = if len2 > 0.0 {
                    ((p - a.p).dot(ab) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let d = (p - (a.p + ab * t)).length();
                let c = (r + 0.5 - d).clamp(0.0, 1.0);
                if c <= 0.0 {
                    continue;
                }
                let ti = (y * w + x) as usize;
                if let (Some(za), Some(zb)) = (a.depth, b.depth) {
                    let z = za + (zb - za) * t;
                    if z > target.depth[ti] + DEFAULT_LINE_DEPTH_BIAS {
                        continue;
                    }
                }
                let li = (y - y0) as usize * lw + (x - x0) as usize;
                if c > cov[li] {
                    cov[li] = c;
                    col[li] = a.color.lerp(b.color, t);
                }
            }
        }
    }
    for yy in 0..lh {
        for xx in 0..lw {
            let li = yy * lw + xx;
            let a = (cov[li] * col[li].w).clamp(0.0, 1.0);
            if a <= 0.0 {
                continue;
            }
            let ti = ((y0 as usize + yy) * w as usize) + x0 as usize + xx;
            let d = &mut target.color[ti];
            let k = 1.0 - a;
            let c = col[li];
            *d = [
                c.x * a + d[0] * k,
                c.y * a + d[1] * k,
                c.z * a + d[2] * k,
                a + d[3] * k,
            ];
        }
    }
}
