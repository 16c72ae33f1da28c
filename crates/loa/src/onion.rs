//! Onion-skinned SVG of an animated line, in the style of the paper's Fig. 3: every frame in
//! blue (later frames more opaque), keystrokes in red.

use std::fmt::Write;

use glam::DVec2;

use crate::{Animation, Keystrokes};

/// Width in pixels of the SVG canvas (the height follows the drawing's aspect ratio).
pub const DEFAULT_SVG_WIDTH: f64 = 800.0;

fn polyline(out: &mut String, points: &[DVec2], style: &str) {
    let coords: Vec<String> = points
        .iter()
        .map(|p| format!("{:.3},{:.3}", p.x, p.y))
        .collect();
    let _ = writeln!(
        out,
        r#"  <polyline points="{}" {style}/>"#,
        coords.join(" ")
    );
}

/// Renders all frames onion-skinned. When `strokes` is given, the drawn keystrokes are added
/// as thin dashed red lines under the fitted red keystroke chains.
pub fn to_svg_string(animation: &Animation, strokes: Option<&Keystrokes>) -> String {
    let frames: Vec<(i64, Vec<DVec2>)> = animation
        .frames
        .iter()
        .map(|f| (f.frame, f.chain.joints()))
        .collect();
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    let stroke_points = strokes.map(|k| k.keys().iter().flat_map(|k| k.stroke.points().iter()));
    for p in frames
        .iter()
        .flat_map(|(_, p)| p.iter())
        .chain(stroke_points.into_iter().flatten())
    {
        if p.is_finite() {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
    }
    if !(lo.is_finite() && hi.is_finite()) {
        lo = DVec2::ZERO;
        hi = DVec2::ONE;
    }
    let size = (hi - lo).max(DVec2::splat(1e-9));
    let margin = 0.05 * size.max_element();
    let (lo, size) = (lo - DVec2::splat(margin), size + DVec2::splat(2.0 * margin));
    let width = DEFAULT_SVG_WIDTH;
    let height = (width * size.y / size.x).clamp(50.0, 4.0 * width);
    let line = size.max_element() / 400.0;
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="{:.3} {:.3} {:.3} {:.3}" fill="none" stroke-linecap="round" stroke-linejoin="round">"#,
        lo.x, lo.y, size.x, size.y
    );
    let _ = writeln!(
        out,
        r#"  <rect x="{:.3}" y="{:.3}" width="{:.3}" height="{:.3}" fill="white" stroke="none"/>"#,
        lo.x, lo.y, size.x, size.y
    );
    if let Some(keys) = strokes {
        for k in keys.keys() {
            polyline(
                &mut out,
                k.stroke.points(),
                &format!(
                    r##"stroke="#e88" stroke-width="{:.4}" stroke-dasharray="{:.4}" data-frame="{}""##,
                    line,
                    4.0 * line,
                    k.frame
                ),
            );
        }
    }
    let count = frames.len().max(2) as f64;
    for (i, (frame, points)) in frames.iter().enumerate() {
        if animation.keystroke_frames.contains(frame) {
            continue;
        }
        let opacity = 0.15 + 0.55 * i as f64 / (count - 1.0);
        polyline(
            &mut out,
            points,
            &format!(
                r##"stroke="#2a5bd7" stroke-opacity="{opacity:.3}" stroke-width="{line:.4}" data-frame="{frame}""##
            ),
        );
    }
    for (frame, points) in frames
        .iter()
        .filter(|(f, _)| animation.keystroke_frames.contains(f))
    {
        polyline(
            &mut out,
            points,
            &format!(
                r##"stroke="#d62728" stroke-width="{:.4}" data-frame="{frame}""##,
                2.5 * line
            ),
        );
    }
    out.push_str("</svg>\n");
    out
}
