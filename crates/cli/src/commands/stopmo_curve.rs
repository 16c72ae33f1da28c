//! `DIR/error_curve.png` of `toonkit stopmo library`: library size versus error (StopShop
//! Figs. 8/16), drawn with the `render` crate's image and bitmap digits (no font files).
//!
//! One colour per part (`render::categorical` in part order): a solid line for the worst
//! frame's mean position error, a dashed line for the mean over frames. The x axis is the
//! number of pieces, the y axis the error in **micrometres** at the print height (the built-in
//! font has digits only); `error_curve.csv` has the same numbers in millimetres.

use anyhow::Result;
use stopmo::library::Library;

/// Image width in pixels.
const WIDTH: u32 = 720;
/// Image height in pixels.
const HEIGHT: u32 = 420;
/// Left margin (y tick labels).
const LEFT: i64 = 80;
/// Right and top margins.
const PAD: i64 = 24;
/// Bottom margin (x tick labels).
const BOTTOM: i64 = 44;
/// Scale of the tick digits.
const DIGIT_SCALE: u32 = 2;
/// Number of y ticks aimed at.
const Y_TICKS: f64 = 5.0;

const WHITE: [u8; 4] = [255, 255, 255, 255];
const AXIS: [u8; 4] = [40, 40, 40, 255];
const GRID: [u8; 4] = [225, 225, 225, 255];

/// A "nice" tick step (1, 2 or 5 × 10^k) giving about `ticks` intervals over `range`.
fn nice_step(range: f64, ticks: f64) -> f64 {
    let raw = (range / ticks).max(f64::MIN_POSITIVE);
    let mag = 10f64.powf(raw.log10().floor());
    let m = raw / mag;
    let k = if m <= 1.0 {
        1.0
    } else if m <= 2.0 {
        2.0
    } else if m <= 5.0 {
        5.0
    } else {
        10.0
    };
    k * mag
}

/// Plots the size-versus-error curves of every part that has one; PNG bytes.
///
/// # Errors
/// Only if the image cannot be allocated or encoded.
pub(super) fn plot(lib: &Library) -> Result<Vec<u8>> {
    let mut img = render::Image::new(WIDTH, HEIGHT, WHITE)?;
    let um = lib.mm_per_unit * 1000.0;
    let points: Vec<(usize, f64, f64)> = lib
        .parts
        .iter()
        .flat_map(|p| {
            p.curve
                .iter()
                .map(|c| (c.pieces, c.worst_frame_error * um, c.mean_error * um))
        })
        .collect();
    let x_min = points.iter().map(|p| p.0).min().unwrap_or(1) as f64;
    let x_max = (points.iter().map(|p| p.0).max().unwrap_or(1) as f64).max(x_min + 1.0);
    let y_top = points
        .iter()
        .map(|p| p.1.max(p.2))
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    let y_step = nice_step(y_top.max(1e-9), Y_TICKS);
    let y_max = (y_top / y_step).ceil().max(1.0) * y_step;
    let (x0, x1) = (LEFT, WIDTH as i64 - PAD);
    let (y0, y1) = (HEIGHT as i64 - BOTTOM, PAD);
    let px = |x: f64| x0 as f64 + (x - x_min) / (x_max - x_min) * (x1 - x0) as f64;
    let py = |y: f64| y0 as f64 - y / y_max * (y0 - y1) as f64;

    // Grid and y ticks (integer micrometres, or more digits-only precision when tiny).
    let mut t = 0.0;
    while t <= y_max + 0.5 * y_step {
        let y = py(t).round() as i64;
        line(
            &mut img,
            (x0 as f64, y as f64),
            (x1 as f64, y as f64),
            GRID,
            1,
            None,
        );
        let label = format!("{}", t.round() as i64);
        let (w, h) = render::text_size(&label, DIGIT_SCALE);
        render::draw_text(
            &mut img,
            &label,
            x0 - 8 - w as i64,
            y - h as i64 / 2,
            DIGIT_SCALE,
            AXIS,
            None,
        );
        t += y_step;
    }
    // x ticks (integer piece counts).
    let x_step = nice_step(x_max - x_min, 8.0).max(1.0).round();
    let mut t = (x_min / x_step).ceil() * x_step;
    while t <= x_max {
        let x = px(t).round() as i64;
        line(
            &mut img,
            (x as f64, y0 as f64),
            (x as f64, y0 as f64 + 6.0),
            AXIS,
            1,
            None,
        );
        let label = format!("{}", t as i64);
        let (w, _) = render::text_size(&label, DIGIT_SCALE);
        render::draw_text(
            &mut img,
            &label,
            x - w as i64 / 2,
            y0 + 12,
            DIGIT_SCALE,
            AXIS,
            None,
        );
        t += x_step;
    }
    line(
        &mut img,
        (x0 as f64, y0 as f64),
        (x1 as f64, y0 as f64),
        AXIS,
        2,
        None,
    );
    line(
        &mut img,
        (x0 as f64, y0 as f64),
        (x0 as f64, y1 as f64),
        AXIS,
        2,
        None,
    );

    for (i, part) in lib.parts.iter().enumerate() {
        let color = render::to_srgb8(render::categorical(i));
        let worst: Vec<(f64, f64)> = part
            .curve
            .iter()
            .map(|c| (px(c.pieces as f64), py(c.worst_frame_error * um)))
            .collect();
        let mean: Vec<(f64, f64)> = part
            .curve
            .iter()
            .map(|c| (px(c.pieces as f64), py(c.mean_error * um)))
            .collect();
        for w in worst.windows(2) {
            line(&mut img, w[0], w[1], color, 3, None);
        }
        for w in mean.windows(2) {
            line(&mut img, w[0], w[1], color, 2, Some(6));
        }
        for &(x, y) in &worst {
            dot(&mut img, x, y, 4, color);
        }
    }
    Ok(render::encode_png(&img)?)
}

/// A filled square of half-size `r` centred at `(x, y)`, clipped.
fn dot(img: &mut render::Image, x: f64, y: f64, r: i64, c: [u8; 4]) {
    let (cx, cy) = (x.round() as i64, y.round() as i64);
    for yy in cy - r..=cy + r {
        for xx in cx - r..=cx + r {
            if xx >= 0 && yy >= 0 {
                img.set(xx as u32, yy as u32, c);
            }
        }
    }
}

/// A line of `width` pixels from `a` to `b` (dashed with `dash`-pixel dashes), clipped.
fn line(
    img: &mut render::Image,
    a: (f64, f64),
    b: (f64, f64),
    c: [u8; 4],
    width: i64,
    dash: Option<usize>,
) {
    if !(a.0.is_finite() && a.1.is_finite() && b.0.is_finite() && b.1.is_finite()) {
        return;
    }
    let steps = (b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil().max(1.0) as usize;
    let lo = -(width - 1) / 2;
    for s in 0..=steps {
        if dash.is_some_and(|d| (s / d) % 2 == 1) {
            continue;
        }
        let t = s as f64 / steps as f64;
        let x = (a.0 + t * (b.0 - a.0)).round() as i64;
        let y = (a.1 + t * (b.1 - a.1)).round() as i64;
        for dy in lo..lo + width {
            for dx in lo..lo + width {
                let (xx, yy) = (x + dx, y + dy);
                if xx >= 0 && yy >= 0 {
                    img.set(xx as u32, yy as u32, c);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::nice_step;

    #[test]
    fn nice_steps_are_1_2_5() {
        assert_eq!(nice_step(10.0, 5.0), 2.0);
        assert_eq!(nice_step(0.3, 5.0), 0.1);
        assert_eq!(nice_step(700.0, 5.0), 200.0);
        assert_eq!(nice_step(40.0, 8.0), 5.0);
    }
}
