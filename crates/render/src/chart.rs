//! Line charts for reports: e.g. the size-versus-error curves of a stop-motion replacement
//! library (StopShop Figs. 8/16), drawn with [`Image`] and the bitmap digits of
//! [`draw_text`] (no font files).
//!
//! Axes are labelled with integers only (the built-in font has digits only), so callers
//! choose units that make the values readable as integers (micrometres rather than
//! millimetres, for example). The x axis gets "nice" integer ticks, the y axis starts at 0.
//!
//! ```
//! use render::chart::{line_chart, Series};
//!
//! let worst = Series::solid([200, 40, 40, 255], vec![(2.0, 90.0), (4.0, 40.0), (8.0, 15.0)]);
//! let mean = Series::dashed([200, 40, 40, 255], vec![(2.0, 50.0), (4.0, 20.0), (8.0, 6.0)]);
//! let image = line_chart(&[worst, mean]).unwrap();
//! assert_eq!((image.width(), image.height()), (render::chart::WIDTH, render::chart::HEIGHT));
//! ```

use crate::{draw_text, text_size, Image, Result};

/// Image width in pixels.
pub const WIDTH: u32 = 720;
/// Image height in pixels.
pub const HEIGHT: u32 = 420;
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
/// Number of x ticks aimed at.
const X_TICKS: f64 = 8.0;
/// Width of a solid series' line in pixels.
const SOLID_WIDTH: i64 = 3;
/// Width of a dashed series' line in pixels.
const DASHED_WIDTH: i64 = 2;
/// Dash length of a dashed series in pixels.
const DASH: usize = 6;
/// Half-size of a marker square in pixels.
const MARKER: i64 = 4;

const WHITE: [u8; 4] = [255, 255, 255, 255];
const AXIS: [u8; 4] = [40, 40, 40, 255];
const GRID: [u8; 4] = [225, 225, 225, 255];

/// One polyline of a chart, in data coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// sRGB RGBA8 colour.
    pub color: [u8; 4],
    /// Points `(x, y)` in drawing order; non-finite points break no line but are skipped.
    pub points: Vec<(f64, f64)>,
    /// Dashed thinner line (`false`: solid line with a square marker at every point).
    pub dashed: bool,
}

impl Series {
    /// A solid line with markers.
    pub fn solid(color: [u8; 4], points: Vec<(f64, f64)>) -> Series {
        Series {
            color,
            points,
            dashed: false,
        }
    }

    /// A dashed line without markers.
    pub fn dashed(color: [u8; 4], points: Vec<(f64, f64)>) -> Series {
        Series {
            color,
            points,
            dashed: true,
        }
    }
}

/// A "nice" tick step (1, 2 or 5 × 10^k) giving about `ticks` intervals over `range`.
pub fn nice_step(range: f64, ticks: f64) -> f64 {
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

/// Draws `series` on one pair of axes ([`WIDTH`] × [`HEIGHT`] pixels, white background): the
/// x range spans every point, the y range runs from 0 to a tick above the largest finite y.
/// Series are drawn in order, so later ones lie on top.
///
/// # Errors
/// Only if the image cannot be allocated.
pub fn line_chart(series: &[Series]) -> Result<Image> {
    let mut img = Image::new(WIDTH, HEIGHT, WHITE)?;
    let points = series.iter().flat_map(|s| s.points.iter().copied());
    let x_min = points.clone().map(|p| p.0).reduce(f64::min).unwrap_or(1.0);
    let x_max = points
        .clone()
        .map(|p| p.0)
        .reduce(f64::max)
        .unwrap_or(1.0)
        .max(x_min + 1.0);
    let y_top = points
        .map(|p| p.1)
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    let y_step = nice_step(y_top.max(1e-9), Y_TICKS);
    let y_max = (y_top / y_step).ceil().max(1.0) * y_step;
    let (x0, x1) = (LEFT, WIDTH as i64 - PAD);
    let (y0, y1) = (HEIGHT as i64 - BOTTOM, PAD);
    let px = |x: f64| x0 as f64 + (x - x_min) / (x_max - x_min) * (x1 - x0) as f64;
    let py = |y: f64| y0 as f64 - y / y_max * (y0 - y1) as f64;

    // Grid and y ticks (integers).
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
        let (w, h) = text_size(&label, DIGIT_SCALE);
        draw_text(
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
    // x ticks (integers).
    let x_step = nice_step(x_max - x_min, X_TICKS).max(1.0).round();
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
        let (w, _) = text_size(&label, DIGIT_SCALE);
        draw_text(
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

    for s in series {
        let pts: Vec<(f64, f64)> = s.points.iter().map(|&(x, y)| (px(x), py(y))).collect();
        let (width, dash) = if s.dashed {
            (DASHED_WIDTH, Some(DASH))
        } else {
            (SOLID_WIDTH, None)
        };
        for w in pts.windows(2) {
            line(&mut img, w[0], w[1], s.color, width, dash);
        }
        if !s.dashed {
            for &(x, y) in &pts {
                dot(&mut img, x, y, MARKER, s.color);
            }
        }
    }
    Ok(img)
}

/// A filled square of half-size `r` centred at `(x, y)`, clipped.
fn dot(img: &mut Image, x: f64, y: f64, r: i64, c: [u8; 4]) {
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
    img: &mut Image,
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
    use super::*;

    #[test]
    fn nice_steps_are_1_2_5() {
        assert_eq!(nice_step(10.0, 5.0), 2.0);
        assert_eq!(nice_step(0.3, 5.0), 0.1);
        assert_eq!(nice_step(700.0, 5.0), 200.0);
        assert_eq!(nice_step(40.0, 8.0), 5.0);
    }

    #[test]
    fn series_are_drawn_in_their_colour() {
        let red = [220, 30, 30, 255];
        let img = line_chart(&[Series::solid(red, vec![(1.0, 10.0), (5.0, 2.0)])]).unwrap();
        let n = img.pixels().iter().filter(|p| **p == red).count();
        assert!(n > 200, "only {n} red pixels");
    }
}
