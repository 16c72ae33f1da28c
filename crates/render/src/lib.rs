//! # toonkit-render
//!
//! A headless software rasterizer for toonkit previews: smear frames coloured by motion
//! offset, stop-motion parts by label, lines of action over a character, and `toonkit demo`.
//!
//! * [`Renderer`] draws a [`DrawList`] — [`MeshItem`]s (vertex / triangle / uniform colours,
//!   Lambert lighting from a camera-attached light plus ambient, two-sided, z-buffered, with
//!   translucent meshes blended back to front, optional wireframe or silhouette edges) and
//!   anti-aliased [`Overlay`]s (polylines and points in pixel or world coordinates) — through
//!   a [`View`]: an orthographic fit to a bounding box from a [`ViewDirection`], or a scene
//!   [`anim::Camera`].
//! * [`ColorMap`] turns scalar fields into colours: the smear paper's blue/white/red map for
//!   motion offsets in `[−1, 1]`, a sequential map for magnitudes; [`categorical`] for labels.
//! * [`Renderer::render_onion`] and [`Renderer::render_layers`] draw onion skins;
//!   [`Renderer::render_animation`] renders all frames in parallel; [`contact_sheet`] lays
//!   frames out on a grid with frame numbers.
//! * [`encode_png`] and [`encode_gif`] return bytes; this crate never touches files.
//! * [`preview_scene`] does all of it for a sampled scene (what `toonkit render` calls);
//!   [`line_preview`] and [`rig_preview`] draw a line of action alone or over a character
//!   (what `toonkit loa` calls).
//!
//! Colours are linear RGBA ([`Color`]); images are sRGB RGBA8 ([`Image`]).
//!
//! ```
//! use render::{encode_png, ColorMap, DrawList, MeshColors, MeshItem, Renderer, View, ViewDirection};
//! use glam::Vec3;
//!
//! let positions = [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
//! let triangles = [[0u32, 1, 2]];
//! let offsets = [-1.0, 0.0, 1.0];
//! let colors = ColorMap::Diverging.colors(&offsets);
//! let list = DrawList::new().mesh(MeshItem::new(&positions, &triangles).colors(MeshColors::PerVertex(&colors)));
//! let renderer = Renderer::new(64, 64).unwrap();
//! let view = View::fit(list.bbox(), ViewDirection::Front, renderer.aspect());
//! let image = renderer.render(&list, &view).unwrap();
//! let png = encode_png(&image).unwrap();
//! assert!(png.starts_with(b"\x89PNG"));
//! ```

#![warn(missing_docs, unreachable_pub)]

mod animation;
pub mod chart;
mod color;
mod colormap;
mod draw;
mod encode;
mod error;
mod flipbook;
mod follow;
mod font;
mod image;
mod line_preview;
mod lines;
mod offsets;
mod preview;
mod raster;
mod renderer;
mod rig_preview;
mod sheet;
mod spec;
mod view;

pub use animation::{
    frame_item, onion_opacity, FrameColors, OnionStyle, DEFAULT_FUTURE_COLOR,
    DEFAULT_ONION_OPACITY, DEFAULT_PAST_COLOR,
};
pub use color::{linear_to_srgb8, srgb, srgb8_to_linear, to_srgb8, Color};
pub use colormap::{
    categorical, normalize_by_max, ColorMap, CATEGORICAL, DIVERGING_NEGATIVE, DIVERGING_POSITIVE,
    DIVERGING_ZERO,
};
pub use draw::{
    Coords, DrawList, EdgeMode, EdgeStyle, MeshColors, MeshItem, Overlay, OverlayKind, Shading,
    DEFAULT_MESH_COLOR,
};
pub use encode::{decode_png, encode_gif, encode_png, DEFAULT_GIF_SAMPLE_FACTOR};
pub use error::{RenderError, Result};
pub use flipbook::flipbook_gif;
pub use follow::{follow_views, DEFAULT_FOLLOW_SMOOTHING};
pub use font::{draw_text, text_size, GLYPH_HEIGHT, GLYPH_WIDTH};
pub use image::{Image, ImageDiff, MAX_IMAGE_SIZE};
pub use line_preview::{line_preview, DEFAULT_LINE_PREVIEW_SIZE};
pub use lines::DEFAULT_LINE_DEPTH_BIAS;
pub use offsets::{offset_colors, offset_rgba};
pub use preview::{preview_scene, OutputFormat, PreviewOptions, ViewSpec, DEFAULT_PREVIEW_SIZE};
pub use renderer::{
    Ghost, RenderOptions, Renderer, DEFAULT_AMBIENT, DEFAULT_BACKGROUND, DEFAULT_LIGHT,
    DEFAULT_SUPERSAMPLE, MAX_SUPERSAMPLE,
};
pub use rig_preview::{rig_preview, RigPreview, RigView, ViewAxes, DEFAULT_RIG_PREVIEW_SIZE};
pub use sheet::{contact_sheet, SheetOptions, DEFAULT_SHEET_GAP};
pub use spec::parse_size;
pub use view::{animation_bbox, View, ViewDirection, DEFAULT_FIT_MARGIN};
