//! GIF previews of flipbooks (stylization results: parts with per-frame colours, motion lines
//! with per-frame topology).

use anim::{Aabb, Flipbook, FlipbookPart};
use rayon::prelude::*;

use crate::{
    animation_bbox, encode_gif, DrawList, Image, MeshColors, MeshItem, Renderer, Result, View,
    ViewDirection,
};

/// Renders every frame of `book` (every part, with its per-frame vertex colours) from a
/// three-quarter view fitted to the uncoloured point caches over the whole motion, and
/// encodes the frames as an animated GIF at the book's frame rate.
///
/// # Errors
/// An invalid image size, or an encoding error.
///
/// # Performance
/// Parallel over frames.
pub fn flipbook_gif(book: &Flipbook, width: u32, height: u32) -> Result<Vec<u8>> {
    let renderer = Renderer::new(width, height)?;
    let mut bbox = Aabb::EMPTY;
    for p in &book.parts {
        if let FlipbookPart::Animation {
            animation,
            colors: None,
        } = p
        {
            bbox = bbox.union(animation_bbox(animation));
        }
    }
    let view = View::fit(
        bbox,
        ViewDirection::ThreeQuarter,
        width as f32 / height as f32,
    );
    renderer.check_frames(book.frames)?;
    let images: Vec<Image> = (0..book.frames)
        .into_par_iter()
        .map(|f| {
            let mut list = DrawList::new();
            for p in &book.parts {
                match p {
                    FlipbookPart::Animation { animation, colors } => {
                        let n = animation.vertex_count();
                        let mut item = MeshItem::from_animation(animation, f);
                        if let Some(c) = colors {
                            item = item.colors(MeshColors::PerVertex(&c[f * n..(f + 1) * n]));
                        }
                        list = list.mesh(item);
                    }
                    FlipbookPart::Frames { meshes, .. } => {
                        if let Some(m) = meshes.get(f).filter(|m| !m.triangles.is_empty()) {
                            list = list.mesh(MeshItem::from_mesh(m));
                        }
                    }
                }
            }
            renderer.render(&list, &view)
        })
        .collect::<Result<_>>()?;
    encode_gif(&images, book.fps)
}
