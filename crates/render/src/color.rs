//! Linear RGBA colours and sRGB conversion.

use std::sync::OnceLock;

/// A linear-light RGBA colour with straight alpha, components in `[0, 1]` (the convention of
/// `anim::Mesh::colors`).
pub type Color = [f32; 4];

/// Size of the linear → sRGB lookup table (error below 0.25 of an 8-bit step).
const LUT_SIZE: usize = 16_384;

/// sRGB transfer function, `x` in `[0, 1]`.
fn encode(x: f32) -> f32 {
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// The linear → sRGB table (for hot loops: fetch once, then [`lut_encode`]).
pub(crate) fn srgb_lut() -> &'static [u8] {
    static LUT: OnceLock<Vec<u8>> = OnceLock::new();
    LUT.get_or_init(|| {
        (0..LUT_SIZE)
            .map(|i| (encode(i as f32 / (LUT_SIZE - 1) as f32) * 255.0 + 0.5) as u8)
            .collect()
    })
}

/// Linear value → 8-bit sRGB (clamped; NaN gives 0).
#[inline]
pub fn linear_to_srgb8(x: f32) -> u8 {
    lut_encode(srgb_lut(), x)
}

/// Linear value → 8-bit sRGB through a table from [`srgb_lut`].
#[inline]
pub(crate) fn lut_encode(lut: &[u8], x: f32) -> u8 {
    let i = (x.clamp(0.0, 1.0) * (LUT_SIZE - 1) as f32 + 0.5) as usize;
    lut[i.min(LUT_SIZE - 1)]
}

/// 8-bit sRGB → linear value.
#[inline]
pub fn srgb8_to_linear(c: u8) -> f32 {
    let x = c as f32 / 255.0;
    if x <= 0.040_45 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// A linear colour from 8-bit sRGB components and an alpha in `[0, 1]`.
pub fn srgb(r: u8, g: u8, b: u8, alpha: f32) -> Color {
    [
        srgb8_to_linear(r),
        srgb8_to_linear(g),
        srgb8_to_linear(b),
        alpha,
    ]
}

/// A linear colour → 8-bit sRGB pixel (alpha stored linearly).
pub fn to_srgb8(c: Color) -> [u8; 4] {
    [
        linear_to_srgb8(c[0]),
        linear_to_srgb8(c[1]),
        linear_to_srgb8(c[2]),
        (c[3].clamp(0.0, 1.0) * 255.0 + 0.5) as u8,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip_is_exact_on_8_bits() {
        for c in 0..=255u8 {
            assert_eq!(linear_to_srgb8(srgb8_to_linear(c)), c, "value {c}");
        }
    }

    #[test]
    fn mid_grey_is_188() {
        // 50 % linear light is sRGB 188 (0.7354 × 255).
        assert_eq!(linear_to_srgb8(0.5), 188);
        assert_eq!(linear_to_srgb8(f32::NAN), 0);
    }
}
