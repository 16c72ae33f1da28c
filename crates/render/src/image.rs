//! RGBA8 images (sRGB-encoded, straight alpha) and their comparison.

use crate::{RenderError, Result};

/// Largest allowed side of an image in pixels.
pub const MAX_IMAGE_SIZE: u32 = 16_384;

/// An 8-bit RGBA image, sRGB-encoded with straight (not premultiplied) alpha, rows top to
/// bottom.
#[derive(Clone, PartialEq, Eq)]
pub struct Image {
    width: u32,
    height: u32,
    pixels: Vec<[u8; 4]>,
}

impl std::fmt::Debug for Image {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Image({}x{})", self.width, self.height)
    }
}

/// Checks an image size against [`MAX_IMAGE_SIZE`].
pub(crate) fn check_size(width: u32, height: u32) -> Result<()> {
    if width == 0 || height == 0 || width > MAX_IMAGE_SIZE || height > MAX_IMAGE_SIZE {
        return Err(RenderError::InvalidSize {
            width,
            height,
            max: MAX_IMAGE_SIZE,
        });
    }
    Ok(())
}

/// Checks that `frames` pictures of `width × height` (kept together until a GIF or a sheet is
/// encoded) fit the pixel budget, before any is drawn.
pub(crate) fn check_pixels(width: u32, height: u32, frames: usize) -> Result<()> {
    let asked = anim::budget::product(&[width as u64, height as u64, frames as u64]);
    anim::check_budget(
        "width × height × frames",
        asked,
        // The job budget at the bytes a pixel costs ([`anim::budget::DEFAULT_MAX_PIXELS`]
        // by default).
        anim::budget::max_job_bytes() / anim::budget::PIXEL_BYTES,
        &format!("{frames} frames of {width}x{height}: ask for a smaller --size or fewer frames"),
    )?;
    Ok(())
}

impl Image {
    /// An image filled with one colour.
    ///
    /// # Errors
    /// [`RenderError::InvalidSize`] when a side is 0 or above [`MAX_IMAGE_SIZE`].
    pub fn new(width: u32, height: u32, fill: [u8; 4]) -> Result<Image> {
        check_size(width, height)?;
        Ok(Image {
            width,
            height,
            pixels: vec![fill; width as usize * height as usize],
        })
    }

    /// An image from row-major pixels.
    ///
    /// # Errors
    /// [`RenderError::InvalidSize`] for a bad size, [`RenderError::SizeMismatch`] when the
    /// pixel count is not `width × height`.
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<[u8; 4]>) -> Result<Image> {
        check_size(width, height)?;
        if pixels.len() != width as usize * height as usize {
            return Err(RenderError::SizeMismatch {
                index: 0,
                width,
                height,
                found_w: pixels.len() as u32,
                found_h: 1,
            });
        }
        Ok(Image {
            width,
            height,
            pixels,
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Row-major pixels.
    pub fn pixels(&self) -> &[[u8; 4]] {
        &self.pixels
    }

    /// Row-major pixels, mutable.
    pub fn pixels_mut(&mut self) -> &mut [[u8; 4]] {
        &mut self.pixels
    }

    /// The pixels as a flat `RGBARGBA…` byte slice.
    pub fn as_bytes(&self) -> &[u8] {
        self.pixels.as_flattened()
    }

    /// Pixel at `(x, y)`, `None` outside the image.
    pub fn get(&self, x: u32, y: u32) -> Option<[u8; 4]> {
        (x < self.width && y < self.height)
            .then(|| self.pixels[y as usize * self.width as usize + x as usize])
    }

    /// Sets the pixel at `(x, y)`; ignored outside the image.
    pub fn set(&mut self, x: u32, y: u32, c: [u8; 4]) {
        if x < self.width && y < self.height {
            self.pixels[y as usize * self.width as usize + x as usize] = c;
        }
    }

    /// Copies `src` with its top-left corner at `(x, y)` (clipped to this image).
    pub fn blit(&mut self, src: &Image, x: i64, y: i64) {
        for sy in 0..src.height as i64 {
            let dy = y + sy;
            if dy < 0 || dy >= self.height as i64 {
                continue;
            }
            for sx in 0..src.width as i64 {
                let dx = x + sx;
                if dx < 0 || dx >= self.width as i64 {
                    continue;
                }
                self.pixels[(dy * self.width as i64 + dx) as usize] =
                    src.pixels[(sy * src.width as i64 + sx) as usize];
            }
        }
    }

    /// Per-pixel comparison with another image of the same size.
    ///
    /// A pixel differs when any channel differs by more than `tolerance`.
    ///
    /// # Errors
    /// [`RenderError::SizeMismatch`] when the sizes differ.
    pub fn compare(&self, other: &Image, tolerance: u8) -> Result<ImageDiff> {
        if (self.width, self.height) != (other.width, other.height) {
            return Err(RenderError::SizeMismatch {
                index: 1,
                width: self.width,
                height: self.height,
                found_w: other.width,
                found_h: other.height,
            });
        }
        let mut differing = 0;
        let mut max_channel_diff = 0u8;
        for (a, b) in self.pixels.iter().zip(&other.pixels) {
            let d = (0..4).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0);
            max_channel_diff = max_channel_diff.max(d);
            if d > tolerance {
                differing += 1;
            }
        }
        Ok(ImageDiff {
            differing,
            fraction: differing as f64 / self.pixels.len() as f64,
            max_channel_diff,
        })
    }
}

/// Result of [`Image::compare`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageDiff {
    /// Pixels with a channel difference above the tolerance.
    pub differing: usize,
    /// `differing / pixel count`.
    pub fraction: f64,
    /// Largest channel difference over all pixels.
    pub max_channel_diff: u8,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_size_is_an_error() {
        assert!(matches!(
            Image::new(0, 4, [0; 4]),
            Err(RenderError::InvalidSize { .. })
        ));
    }

    #[test]
    fn compare_counts_pixels_over_tolerance() {
        let a = Image::new(4, 4, [10, 10, 10, 255]).unwrap();
        let mut b = a.clone();
        b.set(0, 0, [13, 10, 10, 255]);
        b.set(1, 0, [11, 10, 10, 255]);
        let d = a.compare(&b, 2).unwrap();
        assert_eq!(d.differing, 1);
        assert_eq!(d.max_channel_diff, 3);
        assert!((d.fraction - 1.0 / 16.0).abs() < 1e-12);
    }

    #[test]
    fn blit_clips() {
        let mut a = Image::new(3, 3, [0; 4]).unwrap();
        let b = Image::new(2, 2, [9; 4]).unwrap();
        a.blit(&b, 2, -1);
        assert_eq!(a.get(2, 0), Some([9; 4]));
        assert_eq!(a.get(1, 0), Some([0; 4]));
        assert_eq!(a.pixels().iter().filter(|p| p[0] == 9).count(), 1);
    }
}
