//! Whole-scene previews for `toonkit render`: a sampled scene (every mesh object, every
//! frame) to PNG or GIF bytes, optionally coloured by a per-frame scalar field and
//! onion-skinned.

use anim::{Aabb, SampledScene};
use rayon::prelude::*;

use crate::animation::{onion_opacity, OnionStyle};
use crate::draw::{DrawList, MeshColors, MeshItem, Shading};
use crate::{
    animation_bbox, encode_gif, encode_png, Color, ColorMap, Ghost, Image, RenderError,
    RenderOptions, Renderer, Result, View, ViewDirection,
};

/// Default preview size in pixels.
pub const DEFAULT_PREVIEW_SIZE: (u32, u32) = (400, 400);

/// Where a preview looks from.
#[derive(Debug, Clone, PartialEq)]
pub enum ViewSpec {
    /// Orthographic, fitted to the whole motion, from a direction.
    Direction(ViewDirection),
    /// The scene camera of this name (animated cameras follow the frame).
    Camera(String),
    /// Orthographic from a direction, following the subject at a constant scale
    /// ([`follow_views`](crate::follow_views)): for characters travelling across the scene.
    Follow(ViewDirection),
}

/// Output encoding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// One frame as PNG.
    Png,
    /// Every frame as a looping GIF.
    Gif,
    /// A contact sheet PNG: every `every`-th frame (from 0) on a grid of `columns` columns
    /// (0 = square-ish), each cell labelled with its frame number.
    Sheet {
        /// Frame stride (0 counts as 1).
        every: usize,
        /// Columns (0 picks ⌈√cells⌉).
        columns: usize,
    },
}

/// What `toonkit render` asks for.
#[derive(Debug, Clone, PartialEq)]
pub struct PreviewOptions<'a> {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The view.
    pub view: ViewSpec,
    /// Frame of a PNG (ignored for GIFs, which show every frame).
    pub frame: usize,
    /// Ghost frames on each side (0: no onion skin).
    pub onion: usize,
    /// A scalar per vertex per frame (frame-major, vertices in object order as
    /// [`SampledScene::merged`] concatenates them) and its colour map.
    pub scalar: Option<(&'a [f32], ColorMap)>,
    /// PNG or GIF.
    pub format: OutputFormat,
    /// GIF playback rate; `None` uses the scene's rate.
    pub fps: Option<f32>,
    /// Supersampling per axis.
    pub supersample: u32,
}

impl Default for PreviewOptions<'_> {
    fn default() -> Self {
        PreviewOptions {
            width: DEFAULT_PREVIEW_SIZE.0,
            height: DEFAULT_PREVIEW_SIZE.1,
            view: ViewSpec::Direction(ViewDirection::ThreeQuarter),
            frame: 0,
            onion: 0,
            scalar: None,
            format: OutputFormat::Png,
            fps: None,
            supersample: 2,
        }
    }
}

/// Renders a sampled scene to PNG or GIF bytes.
///
/// # Errors
/// [`RenderError::FrameOutOfRange`] for a PNG frame past the end,
/// [`RenderError::CameraNotFound`] for an unknown camera, [`RenderError::AttributeLength`]
/// when the scalar field does not have `frames × vertices` values, and the errors of the
/// renderer and encoders.
///
/// # Performance
/// GIF frames are rendered in parallel.
pub fn preview_scene(scene: &SampledScene, options: &PreviewOptions) -> Result<Vec<u8>> {
    let frames = scene.frame_count.max(1);
    let mut ro = RenderOptions::new(options.width, options.height);
    ro.supersample = options.supersample;
    let renderer = Renderer::with_options(ro)?;
    let colors = scalar_colors(scene, options)?;
    let camera = match &options.view {
        ViewSpec::Camera(name) => Some(scene.cameras.iter().find(|c| &c.name == name).ok_or_else(
            || {
                RenderError::CameraNotFound {
                    name: name.clone(),
                    available: scene
                        .cameras
                        .iter()
                        .map(|c| c.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                }
            },
        )?),
        ViewSpec::Direction(_) | ViewSpec::Follow(_) => None,
    };
    let fitted: Vec<View> = match &options.view {
        ViewSpec::Direction(d) => {
            let b = scene
                .objects
                .iter()
                .fold(Aabb::EMPTY, |b, o| b.union(animation_bbox(&o.animation)));
            vec![View::fit(b, *d, renderer.aspect())]
        }
        ViewSpec::Follow(d) => {
            let parts: Vec<&anim::MeshAnimation> =
                scene.objects.iter().map(|o| &o.animation).collect();
            crate::follow_views(
                &parts,
                *d,
                renderer.aspect(),
                crate::DEFAULT_FOLLOW_SMOOTHING,
            )
        }
        ViewSpec::Camera(_) => Vec::new(),
    };
    let view_of = |f: usize| match camera {
        Some(c) => View::camera(c, f, renderer.aspect()),
        // One fitted view, or one per frame when following.
        None => fitted[f.min(fitted.len() - 1)],
    };
    let draw = |f: usize| -> Result<Image> {
        let list = scene_list(scene, f, colors.as_deref(), None);
        let style = OnionStyle::symmetric(options.onion);
        let mut ghosts = Vec::new();
        for d in (1..=options.onion).rev() {
            let o = onion_opacity(d, options.onion, style.max_opacity);
            if d <= f {
                ghosts.push(Ghost {
                    list: scene_list(scene, f - d, None, Some(style.past_color)),
                    opacity: o,
                });
            }
            if f + d < frames {
                ghosts.push(Ghost {
                    list: scene_list(scene, f + d, None, Some(style.future_color)),
                    opacity: o,
                });
            }
        }
        renderer.render_layers(&list, &ghosts, &view_of(f))
    };
    match options.format {
        OutputFormat::Png => {
            if options.frame >= frames {
                return Err(RenderError::FrameOutOfRange {
                    frame: options.frame,
                    frames,
                });
            }
            encode_png(&draw(options.frame)?)
        }
        OutputFormat::Gif => {
            renderer.check_frames(frames)?;
            let images: Vec<Image> = (0..frames)
                .into_par_iter()
                .map(draw)
                .collect::<Result<_>>()?;
            encode_gif(&images, options.fps.unwrap_or(scene.fps))
        }
        OutputFormat::Sheet { every, columns } => {
            let picked: Vec<usize> = (0..frames).step_by(every.max(1)).collect();
            renderer.check_frames(picked.len())?;
            let images: Vec<Image> = picked.par_iter().map(|&f| draw(f)).collect::<Result<_>>()?;
            let sheet = crate::contact_sheet(
                &images,
                Some(&picked),
                &crate::SheetOptions {
                    columns,
                    ..Default::default()
                },
            )?;
            encode_png(&sheet)
        }
    }
}

/// Colours of the scalar field, frame-major over the concatenated vertices.
fn scalar_colors(scene: &SampledScene, options: &PreviewOptions) -> Result<Option<Vec<Color>>> {
    let Some((values, map)) = options.scalar else {
        return Ok(None);
    };
    let expected = scene.frame_count.max(1) * scene.vertex_count();
    if values.len() != expected {
        return Err(RenderError::AttributeLength {
            mesh: "scene".into(),
            what: "scalar field (frames × vertices)",
            expected,
            found: values.len(),
        });
    }
    Ok(Some(values.par_iter().map(|&v| map.map(v)).collect()))
}

/// Every object of frame `f`: scalar colours, a uniform tint, or the meshes' own colours.
fn scene_list<'a>(
    scene: &'a SampledScene,
    f: usize,
    colors: Option<&'a [Color]>,
    tint: Option<Color>,
) -> DrawList<'a> {
    let total = scene.vertex_count();
    let mut offset = 0;
    let mut list = DrawList::new();
    for o in &scene.objects {
        let n = o.animation.vertex_count();
        let mut item = MeshItem::from_animation(&o.animation, f).shading(Shading::Smooth);
        if let Some(c) = colors {
            let start = f.min(scene.frame_count.max(1) - 1) * total + offset;
            if let Some(s) = c.get(start..start + n) {
                item = item.colors(MeshColors::PerVertex(s));
            }
        }
        if let Some(t) = tint {
            item = item.color(t);
        }
        list.meshes.push(item);
        offset += n;
    }
    list
}
