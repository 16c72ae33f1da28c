//! Previews of point caches: every frame (for GIFs and contact sheets, parallel over frames)
//! and onion skins of neighbouring frames as in the smear paper's figures (Figs. 3a, 6, 7a).

use anim::MeshAnimation;
use rayon::prelude::*;

use crate::color::Color;
use crate::draw::{DrawList, MeshColors, MeshItem, Shading};
use crate::{Ghost, Image, RenderError, Renderer, Result, View};

/// Default opacity of the nearest onion-skin ghost.
pub const DEFAULT_ONION_OPACITY: f32 = 0.4;
/// Default colour of past ghosts (cool grey, linear).
pub const DEFAULT_PAST_COLOR: Color = [0.30, 0.34, 0.45, 1.0];
/// Default colour of future ghosts (warm grey, linear).
pub const DEFAULT_FUTURE_COLOR: Color = [0.45, 0.38, 0.30, 1.0];

/// Colours of an animated mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FrameColors<'a> {
    /// The mesh's own vertex colours, or the default grey.
    Mesh,
    /// One colour.
    Uniform(Color),
    /// One colour per vertex, the same for every frame.
    PerVertex(&'a [Color]),
    /// One colour per triangle (part labels), the same for every frame.
    PerTriangle(&'a [Color]),
    /// Frame-major `frames × vertices` colours (a per-frame scalar field such as motion
    /// offsets through [`crate::ColorMap`]).
    PerFrame(&'a [Color]),
}

/// Onion-skin settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OnionStyle {
    /// Ghosts before the current frame.
    pub before: usize,
    /// Ghosts after the current frame.
    pub after: usize,
    /// Opacity of the nearest ghost; ghost `d` frames away has `max × (1 − (d − 1) / k)`.
    pub max_opacity: f32,
    /// Colour of past ghosts.
    pub past_color: Color,
    /// Colour of future ghosts.
    pub future_color: Color,
}

impl OnionStyle {
    /// `k` ghosts on each side with the default colours and opacity.
    pub fn symmetric(k: usize) -> OnionStyle {
        OnionStyle {
            before: k,
            after: k,
            max_opacity: DEFAULT_ONION_OPACITY,
            past_color: DEFAULT_PAST_COLOR,
            future_color: DEFAULT_FUTURE_COLOR,
        }
    }
}

/// Opacity of a ghost `distance ≥ 1` frames away among `k` ghosts: linear from `max` (nearest)
/// down to `max / k` (farthest).
pub fn onion_opacity(distance: usize, k: usize, max: f32) -> f32 {
    if distance == 0 || distance > k {
        return 0.0;
    }
    max * (1.0 - (distance - 1) as f32 / k as f32)
}

fn check_colors(anim: &MeshAnimation, colors: &FrameColors) -> Result<()> {
    let n = anim.vertex_count();
    let (what, expected, found) = match colors {
        FrameColors::PerVertex(c) => ("vertex colours", n, c.len()),
        FrameColors::PerTriangle(c) => ("triangle colours", anim.mesh.triangle_count(), c.len()),
        FrameColors::PerFrame(c) => ("per-frame colours", n * anim.frame_count(), c.len()),
        _ => return Ok(()),
    };
    if expected != found {
        return Err(RenderError::AttributeLength {
            mesh: anim.mesh.name.clone(),
            what,
            expected,
            found,
        });
    }
    Ok(())
}

/// The mesh item of frame `f` with its colours (frame clamped to the last one).
pub fn frame_item<'a>(anim: &'a MeshAnimation, f: usize, colors: FrameColors<'a>) -> MeshItem<'a> {
    let f = f.min(anim.frame_count().saturating_sub(1));
    let item = MeshItem::from_animation(anim, f);
    let n = anim.vertex_count();
    match colors {
        FrameColors::Mesh => item,
        FrameColors::Uniform(c) => item.color(c),
        FrameColors::PerVertex(c) => item.colors(MeshColors::PerVertex(c)),
        FrameColors::PerTriangle(c) => item.colors(MeshColors::PerTriangle(c)),
        FrameColors::PerFrame(c) => match c.get(f * n..(f + 1) * n) {
            Some(slice) => item.colors(MeshColors::PerVertex(slice)),
            None => item,
        },
    }
}

impl Renderer {
    /// Renders every frame of a point cache, in parallel over frames.
    ///
    /// # Arguments
    /// * `views` — one view for all frames, or one per frame (frames past the end use the
    ///   last one); an empty slice fits an orthographic front view to the whole motion.
    /// * `shading` — [`Shading::Unlit`] shows a scalar field's colours exactly.
    ///
    /// # Errors
    /// When colours do not match the mesh, or the mesh is invalid.
    pub fn render_animation(
        &self,
        anim: &MeshAnimation,
        colors: FrameColors,
        shading: Shading,
        views: &[View],
    ) -> Result<Vec<Image>> {
        check_colors(anim, &colors)?;
        let fitted;
        let views = if views.is_empty() {
            fitted = [View::fit(
                crate::animation_bbox(anim),
                crate::ViewDirection::Front,
                self.aspect(),
            )];
            &fitted[..]
        } else {
            views
        };
        (0..anim.frame_count())
            .into_par_iter()
            .map(|f| {
                let list = DrawList::new().mesh(frame_item(anim, f, colors).shading(shading));
                self.render(&list, &views[f.min(views.len() - 1)])
            })
            .collect()
    }

    /// Renders frame `frame` of a point cache with onion skins of its neighbours: the current
    /// frame opaque in `colors`, `style.before` past and `style.after` future frames as
    /// translucent ghosts of decreasing opacity (see [`onion_opacity`]). Frames beyond the
    /// animation are skipped.
    ///
    /// # Errors
    /// When colours do not match the mesh, or the mesh is invalid.
    pub fn render_onion(
        &self,
        anim: &MeshAnimation,
        frame: usize,
        colors: FrameColors,
        shading: Shading,
        style: &OnionStyle,
        view: &View,
    ) -> Result<Image> {
        check_colors(anim, &colors)?;
        let last = anim.frame_count().saturating_sub(1);
        let frame = frame.min(last);
        let mut ghosts = Vec::new();
        // Farthest first, alternating sides, so nearer ghosts end on top.
        for d in (1..=style.before.max(style.after)).rev() {
            if d <= style.before && d <= frame {
                let item = frame_item(anim, frame - d, FrameColors::Uniform(style.past_color));
                let opacity = onion_opacity(d, style.before, style.max_opacity);
                ghosts.push(Ghost {
                    list: DrawList::new().mesh(item.shading(shading)),
                    opacity,
                });
            }
            if d <= style.after && frame + d <= last {
                let item = frame_item(anim, frame + d, FrameColors::Uniform(style.future_color));
                let opacity = onion_opacity(d, style.after, style.max_opacity);
                ghosts.push(Ghost {
                    list: DrawList::new().mesh(item.shading(shading)),
                    opacity,
                });
            }
        }
        let current = DrawList::new().mesh(frame_item(anim, frame, colors).shading(shading));
        self.render_layers(&current, &ghosts, view)
    }
}
