//! PNG and animated GIF encoding to bytes (this crate never touches files), PNG decoding for
//! reference images.

use std::collections::BTreeSet;

use rayon::prelude::*;

use crate::{Image, RenderError, Result};

/// NeuQuant sampling factor for GIF palettes (1 = best, 30 = fastest).
pub const DEFAULT_GIF_SAMPLE_FACTOR: i32 = 10;
/// At most this many pixels (spread evenly over all frames) train the shared GIF palette.
const GIF_TRAINING_PIXELS: usize = 262_144;

/// Encodes an image as an 8-bit RGBA PNG.
///
/// # Errors
/// [`RenderError::Png`] if the encoder fails (it does not on valid images).
pub fn encode_png(image: &Image) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, image.width(), image.height());
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        let mut w = enc
            .write_header()
            .map_err(|e| RenderError::Png(e.to_string()))?;
        w.write_image_data(image.as_bytes())
            .map_err(|e| RenderError::Png(e.to_string()))?;
        w.finish().map_err(|e| RenderError::Png(e.to_string()))?;
    }
    Ok(out)
}

/// Decodes a PNG (any colour type, 8 or 16 bits; palette and grey are expanded) to RGBA8.
///
/// # Errors
/// [`RenderError::Png`] on malformed data, [`RenderError::InvalidSize`] on a huge image.
pub fn decode_png(bytes: &[u8]) -> Result<Image> {
    let err = |e: png::DecodingError| RenderError::Png(e.to_string());
    let mut dec = png::Decoder::new(std::io::Cursor::new(bytes));
    dec.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = dec.read_info().map_err(err)?;
    let (w, h) = (reader.info().width, reader.info().height);
    crate::image::check_size(w, h)?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| RenderError::Png("image too large".into()))?;
    let mut buf = vec![0u8; size];
    let info = reader.next_frame(&mut buf).map_err(err)?;
    let data = &buf[..info.buffer_size()];
    let stride = info.line_size;
    let mut px = Vec::with_capacity(w as usize * h as usize);
    for y in 0..h as usize {
        let row = &data[y * stride..];
        for x in 0..w as usize {
            px.push(match info.color_type {
                png::ColorType::Rgba => {
                    [row[4 * x], row[4 * x + 1], row[4 * x + 2], row[4 * x + 3]]
                }
                png::ColorType::Rgb => [row[3 * x], row[3 * x + 1], row[3 * x + 2], 255],
                png::ColorType::GrayscaleAlpha => {
                    [row[2 * x], row[2 * x], row[2 * x], row[2 * x + 1]]
                }
                png::ColorType::Grayscale => [row[x], row[x], row[x], 255],
                png::ColorType::Indexed => {
                    return Err(RenderError::Png("palette PNG was not expanded".into()))
                }
            });
        }
    }
    Image::from_pixels(w, h, px)
}

/// Encodes frames as a looping animated GIF with one shared palette.
///
/// The palette is exact when all frames together use at most 256 colours; otherwise it is
/// trained by NeuQuant on pixels sampled evenly from all frames (deterministic), and every
/// frame is mapped to it in parallel. Alpha is dropped (pixels are taken as opaque); render
/// with an opaque background.
///
/// # Arguments
/// * `frames` — images of one size (at most 65535 pixels a side).
/// * `fps` — playback rate; GIF delays are whole centiseconds (at least 2), so the played
///   rate is `100 / round(100 / fps)`.
///
/// # Errors
/// [`RenderError::NoFrames`], [`RenderError::InvalidFps`], [`RenderError::SizeMismatch`], or
/// [`RenderError::Gif`] for a side over 65535 pixels.
pub fn encode_gif(frames: &[Image], fps: f32) -> Result<Vec<u8>> {
    let first = frames.first().ok_or(RenderError::NoFrames)?;
    if !(fps.is_finite() && fps > 0.0) {
        return Err(RenderError::InvalidFps(fps));
    }
    let (w, h) = (first.width(), first.height());
    for (i, f) in frames.iter().enumerate() {
        if (f.width(), f.height()) != (w, h) {
            return Err(RenderError::SizeMismatch {
                index: i,
                width: w,
                height: h,
                found_w: f.width(),
                found_h: f.height(),
            });
        }
    }
    let (gw, gh) = match (u16::try_from(w), u16::try_from(h)) {
        (Ok(a), Ok(b)) => (a, b),
        _ => {
            return Err(RenderError::Gif(format!(
                "{w}x{h} exceeds 65535 pixels a side"
            )))
        }
    };
    let palette = Palette::build(frames);
    let indexed: Vec<Vec<u8>> = frames
        .par_iter()
        .map(|f| f.pixels().iter().map(|p| palette.index(*p)).collect())
        .collect();
    let delay = ((100.0 / fps).round() as u16).max(2);
    let gif_err = |e: gif::EncodingError| RenderError::Gif(e.to_string());
    let mut out = Vec::new();
    {
        let mut enc = gif::Encoder::new(&mut out, gw, gh, &palette.rgb).map_err(gif_err)?;
        enc.set_repeat(gif::Repeat::Infinite).map_err(gif_err)?;
        for px in indexed {
            let mut frame = gif::Frame::from_indexed_pixels(gw, gh, px, None);
            frame.delay = delay;
            enc.write_frame(&frame).map_err(gif_err)?;
        }
    }
    Ok(out)
}

/// A shared GIF palette: exact (sorted colours) or NeuQuant-trained.
struct Palette {
    rgb: Vec<u8>,
    exact: Option<Vec<[u8; 3]>>,
    quant: Option<color_quant::NeuQuant>,
}

impl Palette {
    fn build(frames: &[Image]) -> Palette {
        let mut colors = BTreeSet::new();
        'scan: for f in frames {
            for p in f.pixels() {
                colors.insert([p[0], p[1], p[2]]);
                if colors.len() > 256 {
                    break 'scan;
                }
            }
        }
        if colors.len() <= 256 {
            let exact: Vec<[u8; 3]> = colors.into_iter().collect();
            let rgb = exact.iter().flatten().copied().collect();
            return Palette {
                rgb,
                exact: Some(exact),
                quant: None,
            };
        }
        let total: usize = frames.iter().map(|f| f.pixels().len()).sum();
        let step = total.div_ceil(GIF_TRAINING_PIXELS).max(1);
        let mut sample = Vec::with_capacity(4 * (total / step + 1));
        for (i, p) in frames.iter().flat_map(|f| f.pixels()).enumerate() {
            if i % step == 0 {
                sample.extend_from_slice(&[p[0], p[1], p[2], 255]);
            }
        }
        let nq = color_quant::NeuQuant::new(DEFAULT_GIF_SAMPLE_FACTOR, 256, &sample);
        Palette {
            rgb: nq.color_map_rgb(),
            exact: None,
            quant: Some(nq),
        }
    }

    fn index(&self, p: [u8; 4]) -> u8 {
        match (&self.exact, &self.quant) {
            (Some(e), _) => e.binary_search(&[p[0], p[1], p[2]]).unwrap_or(0) as u8,
            (None, Some(q)) => q.index_of(&[p[0], p[1], p[2], 255]) as u8,
            (None, None) => 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_round_trip() {
        let mut img = Image::new(5, 3, [10, 20, 30, 255]).unwrap();
        img.set(4, 2, [200, 0, 7, 128]);
        let back = decode_png(&encode_png(&img).unwrap()).unwrap();
        assert_eq!(back, img);
    }

    #[test]
    fn gif_with_few_colours_is_exact() {
        let a = Image::new(4, 4, [255, 0, 0, 255]).unwrap();
        let mut b = a.clone();
        b.set(1, 1, [0, 0, 255, 255]);
        let bytes = encode_gif(&[a, b], 12.0).unwrap();
        let mut opts = gif::DecodeOptions::new();
        opts.set_color_output(gif::ColorOutput::RGBA);
        let mut dec = opts.read_info(std::io::Cursor::new(&bytes)).unwrap();
        let mut n = 0;
        let mut last = Vec::new();
        while let Some(f) = dec.read_next_frame().unwrap() {
            assert_eq!(f.delay, 8);
            last = f.buffer.to_vec();
            n += 1;
        }
        assert_eq!(n, 2);
        assert_eq!(&last[0..4], &[255, 0, 0, 255]);
        assert_eq!(&last[20..24], &[0, 0, 255, 255]);
    }

    #[test]
    fn gif_rejects_bad_input() {
        assert!(matches!(encode_gif(&[], 24.0), Err(RenderError::NoFrames)));
        let a = Image::new(2, 2, [0; 4]).unwrap();
        let b = Image::new(3, 2, [0; 4]).unwrap();
        assert!(matches!(
            encode_gif(std::slice::from_ref(&a), 0.0),
            Err(RenderError::InvalidFps(_))
        ));
        assert!(matches!(
            encode_gif(&[a, b], 24.0),
            Err(RenderError::SizeMismatch { index: 1, .. })
        ));
    }
}
