//! Contact sheets: frames laid out on a grid, optionally numbered.

use crate::font::{draw_text, text_size};
use crate::{Image, RenderError, Result};

/// Default gap between cells in pixels.
pub const DEFAULT_SHEET_GAP: u32 = 4;

/// Layout of a contact sheet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SheetOptions {
    /// Columns; 0 picks `ceil(sqrt(n))`.
    pub columns: usize,
    /// Gap between cells and around the sheet, in pixels.
    pub gap: u32,
    /// Sheet background (sRGB).
    pub background: [u8; 4],
    /// Label colour (sRGB).
    pub label_color: [u8; 4],
}

impl Default for SheetOptions {
    fn default() -> Self {
        SheetOptions {
            columns: 0,
            gap: DEFAULT_SHEET_GAP,
            background: [255, 255, 255, 255],
            label_color: [40, 40, 40, 255],
        }
    }
}

/// Lays `images` (all of one size) out row by row on a grid.
///
/// # Arguments
/// * `labels` — a number per image (frame numbers), drawn with the built-in 5×7 font in the
///   top-left corner of each cell; ignored unless it has one entry per image.
///
/// # Errors
/// [`RenderError::NoFrames`] for no image, [`RenderError::SizeMismatch`] for mixed sizes,
/// [`RenderError::InvalidSize`] when the sheet would be too large.
pub fn contact_sheet(
    images: &[Image],
    labels: Option<&[usize]>,
    options: &SheetOptions,
) -> Result<Image> {
    let first = images.first().ok_or(RenderError::NoFrames)?;
    let (w, h) = (first.width(), first.height());
    for (i, im) in images.iter().enumerate() {
        if (im.width(), im.height()) != (w, h) {
            return Err(RenderError::SizeMismatch {
                index: i,
                width: w,
                height: h,
                found_w: im.width(),
                found_h: im.height(),
            });
        }
    }
    let n = images.len();
    let cols = match options.columns {
        0 => (n as f64).sqrt().ceil() as usize,
        c => c.min(n),
    };
    let rows = n.div_ceil(cols);
    let g = options.gap as u64;
    let sw = cols as u64 * (w as u64 + g) + g;
    let sh = rows as u64 * (h as u64 + g) + g;
    let mut sheet = Image::new(
        u32::try_from(sw).unwrap_or(u32::MAX),
        u32::try_from(sh).unwrap_or(u32::MAX),
        options.background,
    )?;
    let scale = (h / 80).clamp(1, 4);
    for (i, im) in images.iter().enumerate() {
        let x = g + (i % cols) as u64 * (w as u64 + g);
        let y = g + (i / cols) as u64 * (h as u64 + g);
        sheet.blit(im, x as i64, y as i64);
        if let Some(l) = labels.filter(|l| l.len() == n) {
            let text = l[i].to_string();
            let (_, th) = text_size(&text, scale);
            if th + 2 * scale <= h {
                let (tx, ty) = (x as i64 + 2 * scale as i64, y as i64 + 2 * scale as i64);
                draw_text(
                    &mut sheet,
                    &text,
                    tx,
                    ty,
                    scale,
                    options.label_color,
                    Some(options.background),
                );
            }
        }
    }
    Ok(sheet)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sheet_grid_layout() {
        let imgs: Vec<Image> = (0..5u8)
            .map(|i| Image::new(10, 8, [i * 40, 0, 0, 255]).unwrap())
            .collect();
        let s = contact_sheet(&imgs, None, &SheetOptions::default()).unwrap();
        // 3 columns × 2 rows with 4-pixel gaps.
        assert_eq!((s.width(), s.height()), (3 * 14 + 4, 2 * 12 + 4));
        assert_eq!(s.get(4 + 14 + 5, 4 + 12 + 3), Some([160, 0, 0, 255]));
        assert_eq!(s.get(4 + 28 + 5, 4 + 12 + 3), Some([255; 4]));
    }

    #[test]
    fn labels_are_drawn() {
        let imgs = vec![Image::new(40, 40, [0, 0, 255, 255]).unwrap(); 2];
        let plain = contact_sheet(&imgs, None, &SheetOptions::default()).unwrap();
        let lab = contact_sheet(&imgs, Some(&[7, 12]), &SheetOptions::default()).unwrap();
        let d = plain.compare(&lab, 0).unwrap();
        assert!(d.differing > 20, "{d:?}");
    }
}
