//! A tiny built-in 5×7 bitmap font for frame numbers (digits and '-').

use crate::Image;

/// Glyph width in font pixels.
pub const GLYPH_WIDTH: u32 = 5;
/// Glyph height in font pixels.
pub const GLYPH_HEIGHT: u32 = 7;

const DIGITS: [[u8; 7]; 10] = [
    [
        0b01110, 0b10001, 0b10011, 0b10101, 0b11001, 0b10001, 0b01110,
    ],
    [
        0b00100, 0b01100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110,
    ],
    [
        0b01110, 0b10001, 0b00001, 0b00010, 0b00100, 0b01000, 0b11111,
    ],
    [
        0b11111, 0b00010, 0b00100, 0b00010, 0b00001, 0b10001, 0b01110,
    ],
    [
        0b00010, 0b00110, 0b01010, 0b10010, 0b11111, 0b00010, 0b00010,
    ],
    [
        0b11111, 0b10000, 0b11110, 0b00001, 0b00001, 0b10001, 0b01110,
    ],
    [
        0b00110, 0b01000, 0b10000, 0b11110, 0b10001, 0b10001, 0b01110,
    ],
    [
        0b11111, 0b00001, 0b00010, 0b00100, 0b01000, 0b01000, 0b01000,
    ],
    [
        0b01110, 0b10001, 0b10001, 0b01110, 0b10001, 0b10001, 0b01110,
    ],
    [
        0b01110, 0b10001, 0b10001, 0b01111, 0b00001, 0b00010, 0b01100,
    ],
];
const MINUS: [u8; 7] = [0, 0, 0, 0b11111, 0, 0, 0];

fn glyph(c: char) -> Option<&'static [u8; 7]> {
    match c {
        '0'..='9' => Some(&DIGITS[c as usize - '0' as usize]),
        '-' => Some(&MINUS),
        _ => None,
    }
}

/// Size in pixels of `text` drawn at `scale` (one font pixel of spacing between glyphs).
pub fn text_size(text: &str, scale: u32) -> (u32, u32) {
    let n = text.chars().count() as u32;
    let w = if n == 0 { 0 } else { n * (GLYPH_WIDTH + 1) - 1 };
    (w * scale, GLYPH_HEIGHT * scale)
}

/// Draws `text` (digits and '-'; other characters leave a blank) with its top-left corner at
/// `(x, y)`, each font pixel a `scale × scale` block, on a `background` box with a one font
/// pixel margin (none when `background` is `None`). Clipped to the image.
pub fn draw_text(
    image: &mut Image,
    text: &str,
    x: i64,
    y: i64,
    scale: u32,
    color: [u8; 4],
    background: Option<[u8; 4]>,
) {
    let s = scale.max(1) as i64;
    let (tw, th) = text_size(text, s as u32);
    let mut fill = |x0: i64, y0: i64, w: i64, h: i64, c: [u8; 4]| {
        for yy in y0.max(0)..(y0 + h).min(image.height() as i64) {
            for xx in x0.max(0)..(x0 + w).min(image.width() as i64) {
                image.set(xx as u32, yy as u32, c);
            }
        }
    };
    if let Some(bg) = background {
        fill(x - s, y - s, tw as i64 + 2 * s, th as i64 + 2 * s, bg);
    }
    for (i, c) in text.chars().enumerate() {
        let Some(g) = glyph(c) else { continue };
        let gx = x + i as i64 * (GLYPH_WIDTH as i64 + 1) * s;
        for (row, bits) in g.iter().enumerate() {
            for col in 0..GLYPH_WIDTH as i64 {
                if bits >> (GLYPH_WIDTH as i64 - 1 - col) & 1 == 1 {
                    fill(gx + col * s, y + row as i64 * s, s, s, color);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digit_one_has_its_pixels() {
        let mut img = Image::new(12, 9, [255; 4]).unwrap();
        draw_text(&mut img, "1", 1, 1, 1, [0, 0, 0, 255], None);
        let dark = img.pixels().iter().filter(|p| p[0] == 0).count();
        // '1' has 1 + 2 + 1 + 1 + 1 + 1 + 3 = 10 set pixels.
        assert_eq!(dark, 10);
        assert_eq!(img.get(3, 1), Some([0, 0, 0, 255]));
        assert_eq!(text_size("12", 2), (22, 14));
    }
}
