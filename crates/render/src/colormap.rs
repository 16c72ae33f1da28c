//! Scalar fields → colours: the smear paper's red/white/blue motion-offset map, a sequential
//! map for magnitudes, and a categorical palette for part labels.

use crate::color::{srgb8_to_linear, Color};

/// sRGB anchor of the diverging map at +1 (red).
pub const DIVERGING_POSITIVE: [u8; 3] = [202, 0, 32];
/// sRGB anchor of the diverging map at 0 (white).
pub const DIVERGING_ZERO: [u8; 3] = [255, 255, 255];
/// sRGB anchor of the diverging map at −1 (blue).
pub const DIVERGING_NEGATIVE: [u8; 3] = [5, 113, 176];

/// sRGB anchors of the sequential map (viridis, evenly spaced on `[0, 1]`).
const SEQUENTIAL: [[u8; 3]; 5] = [
    [68, 1, 84],
    [59, 82, 139],
    [33, 145, 140],
    [94, 201, 98],
    [253, 231, 37],
];

/// sRGB categorical palette (Tableau 10), cycled for more labels.
pub const CATEGORICAL: [[u8; 3]; 10] = [
    [78, 121, 167],
    [242, 142, 43],
    [225, 87, 89],
    [118, 183, 178],
    [89, 161, 79],
    [237, 201, 72],
    [176, 122, 161],
    [255, 157, 167],
    [156, 117, 95],
    [186, 176, 172],
];

/// A scalar-to-colour map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColorMap {
    /// Values in `[−1, 1]`: blue (−1) → white (0) → red (+1), as the smear paper paints
    /// motion offsets (Fig. 3: "positive (resp. negative) motion offsets are painted red
    /// (resp. blue)").
    Diverging,
    /// Values in `[0, 1]`: dark purple → yellow (viridis), for magnitudes such as speed.
    Sequential,
}

fn lerp_srgb(a: [u8; 3], b: [u8; 3], t: f32) -> Color {
    let c = |i: usize| {
        let v = a[i] as f32 + (b[i] as f32 - a[i] as f32) * t;
        srgb_f(v / 255.0)
    };
    [c(0), c(1), c(2), 1.0]
}

/// sRGB component in `[0, 1]` → linear.
fn srgb_f(x: f32) -> f32 {
    if x <= 0.040_45 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

impl ColorMap {
    /// Colour (linear RGBA, opaque) of one value. Values are clamped to the map's range; NaN
    /// maps to the neutral colour (white for [`ColorMap::Diverging`], the low end for
    /// [`ColorMap::Sequential`]). Interpolation is done in sRGB space so that the ramps look
    /// even.
    pub fn map(self, v: f32) -> Color {
        match self {
            ColorMap::Diverging => {
                let v = if v.is_nan() { 0.0 } else { v.clamp(-1.0, 1.0) };
                if v >= 0.0 {
                    lerp_srgb(DIVERGING_ZERO, DIVERGING_POSITIVE, v)
                } else {
                    lerp_srgb(DIVERGING_ZERO, DIVERGING_NEGATIVE, -v)
                }
            }
            ColorMap::Sequential => {
                let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
                let s = v * (SEQUENTIAL.len() - 1) as f32;
                let i = (s as usize).min(SEQUENTIAL.len() - 2);
                lerp_srgb(SEQUENTIAL[i], SEQUENTIAL[i + 1], s - i as f32)
            }
        }
    }

    /// Colours of many values (one per vertex, say), in parallel-friendly order.
    pub fn colors(self, values: &[f32]) -> Vec<Color> {
        values.iter().map(|&v| self.map(v)).collect()
    }
}

/// Colour of categorical label `i` (cycling through [`CATEGORICAL`]).
pub fn categorical(i: usize) -> Color {
    let [r, g, b] = CATEGORICAL[i % CATEGORICAL.len()];
    [
        srgb8_to_linear(r),
        srgb8_to_linear(g),
        srgb8_to_linear(b),
        1.0,
    ]
}

/// Scales magnitudes into `[0, 1]` by their maximum (all zeros when the maximum is 0 or
/// not finite), ready for [`ColorMap::Sequential`].
pub fn normalize_by_max(values: &[f32]) -> Vec<f32> {
    let m = values
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0f32, |a, v| a.max(v.abs()));
    if m > 0.0 {
        values
            .iter()
            .map(|v| if v.is_finite() { v.abs() / m } else { 0.0 })
            .collect()
    } else {
        vec![0.0; values.len()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::to_srgb8;

    #[test]
    fn diverging_offsets_red_white_blue() {
        assert_eq!(to_srgb8(ColorMap::Diverging.map(1.0)), [202, 0, 32, 255]);
        assert_eq!(to_srgb8(ColorMap::Diverging.map(0.0)), [255, 255, 255, 255]);
        assert_eq!(to_srgb8(ColorMap::Diverging.map(-1.0)), [5, 113, 176, 255]);
        assert_eq!(to_srgb8(ColorMap::Diverging.map(7.0)), [202, 0, 32, 255]);
        assert_eq!(
            to_srgb8(ColorMap::Diverging.map(f32::NAN)),
            [255, 255, 255, 255]
        );
        // Half-way to red: sRGB midpoint of white and red.
        let h = to_srgb8(ColorMap::Diverging.map(0.5));
        for (c, want) in h.iter().zip([228.5, 127.5, 143.5, 255.0]) {
            assert!((*c as f32 - want).abs() <= 0.5, "{h:?}");
        }
    }

    #[test]
    fn sequential_is_monotone_in_lightness() {
        let lum = |c: Color| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
        let l: Vec<f32> = (0..=10)
            .map(|i| lum(ColorMap::Sequential.map(i as f32 / 10.0)))
            .collect();
        assert!(l.windows(2).all(|w| w[1] > w[0]), "{l:?}");
    }

    #[test]
    fn categorical_cycles_and_differs() {
        assert_eq!(categorical(0), categorical(10));
        assert_ne!(categorical(0), categorical(1));
        assert_eq!(normalize_by_max(&[0.0, -2.0, 1.0]), vec![0.0, 1.0, 0.5]);
        assert_eq!(normalize_by_max(&[0.0, f32::NAN]), vec![0.0, 0.0]);
    }
}
