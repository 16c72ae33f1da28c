//! The renderer: options, the opaque → translucent → edges → overlays pipeline, and layered
//! (onion-skin) rendering.

use glam::{Vec2, Vec3, Vec4};
use rayon::prelude::*;

use crate::color::{lut_encode, srgb_lut, Color};
use crate::draw::{Coords, DrawList, EdgeMode, MeshItem, OverlayKind};
use crate::image::check_size;
use crate::lines::{draw_segments, LinePoint};
use crate::raster::{rasterize, setup_mesh, validate, Shader, Target, Tri};
use crate::{Image, Result, View};

/// Default background: opaque white (linear).
pub const DEFAULT_BACKGROUND: Color = [1.0, 1.0, 1.0, 1.0];
/// Default ambient light fraction.
pub const DEFAULT_AMBIENT: f32 = 0.28;
/// Default light direction in camera space (a headlight slightly above-left of the eye).
pub const DEFAULT_LIGHT: Vec3 = Vec3::new(-0.25, 0.35, 1.0);
/// Default supersampling factor per axis (2 → 4 samples per pixel).
pub const DEFAULT_SUPERSAMPLE: u32 = 1;
/// Largest supersampling factor per axis.
pub const MAX_SUPERSAMPLE: u32 = 4;

/// Renderer settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderOptions {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Background colour (linear, straight alpha; alpha 0 gives a transparent PNG).
    pub background: Color,
    /// Ambient fraction of the Lambert lighting, `[0, 1]`.
    pub ambient: f32,
    /// Direction towards the light in camera space (+Z points at the viewer).
    pub light: Vec3,
    /// Drop back faces instead of lighting them from behind (two-sided lighting).
    pub cull_back_faces: bool,
    /// Supersampling per axis, `1..=MAX_SUPERSAMPLE` (anti-aliasing of mesh edges).
    pub supersample: u32,
}

impl RenderOptions {
    /// Default options for an image size.
    pub fn new(width: u32, height: u32) -> RenderOptions {
        RenderOptions {
            width,
            height,
            background: DEFAULT_BACKGROUND,
            ambient: DEFAULT_AMBIENT,
            light: DEFAULT_LIGHT,
            cull_back_faces: false,
            supersample: DEFAULT_SUPERSAMPLE,
        }
    }
}

/// One layer of an onion-skinned image: a frame drawn as a translucent ghost.
#[derive(Debug, Clone, PartialEq)]
pub struct Ghost<'a> {
    /// What the ghost shows.
    pub list: DrawList<'a>,
    /// Ghost opacity in `[0, 1]`.
    pub opacity: f32,
}

/// A headless software renderer of a fixed image size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Renderer {
    options: RenderOptions,
}

impl Renderer {
    /// A renderer with default options.
    ///
    /// # Errors
    /// [`crate::RenderError::InvalidSize`] for a zero or oversized image.
    pub fn new(width: u32, height: u32) -> Result<Renderer> {
        Renderer::with_options(RenderOptions::new(width, height))
    }

    /// A renderer with explicit options (ambient clamped to `[0, 1]`, supersampling to
    /// `1..=MAX_SUPERSAMPLE`, a zero or non-finite light to [`DEFAULT_LIGHT`]).
    ///
    /// # Errors
    /// [`crate::RenderError::InvalidSize`] for a zero or oversized image (after
    /// supersampling).
    pub fn with_options(mut options: RenderOptions) -> Result<Renderer> {
        options.supersample = options.supersample.clamp(1, MAX_SUPERSAMPLE);
        options.ambient = if options.ambient.is_finite() {
            options.ambient.clamp(0.0, 1.0)
        } else {
            DEFAULT_AMBIENT
        };
        options.light = options
            .light
            .try_normalize()
            .unwrap_or(DEFAULT_LIGHT.normalize());
        check_size(options.width, options.height)?;
        let s = options.supersample;
        if check_size(options.width * s, options.height * s).is_err() {
            // The size asked for, and the largest side the supersampling leaves room for.
            return Err(crate::RenderError::InvalidSize {
                width: options.width,
                height: options.height,
                max: crate::MAX_IMAGE_SIZE / s,
            });
        }
        Ok(Renderer { options })
    }

    /// Checks that `frames` pictures of this renderer's size fit the pixel budget
    /// ([`anim::budget::DEFAULT_MAX_PIXELS`]) before they are drawn.
    ///
    /// # Errors
    /// [`crate::RenderError::OverBudget`].
    pub fn check_frames(&self, frames: usize) -> Result<()> {
        crate::image::check_pixels(self.options.width, self.options.height, frames)
    }

    /// The options in force.
    pub fn options(&self) -> &RenderOptions {
        &self.options
    }

    /// Width / height of the image.
    pub fn aspect(&self) -> f32 {
        self.options.width as f32 / self.options.height as f32
    }

    fn shader(&self) -> Shader {
        Shader {
            ambient: self.options.ambient,
            light: self.options.light,
            cull: self.options.cull_back_faces,
        }
    }

    fn target(&self, background: Color) -> Target {
        let s = self.options.supersample;
        Target::new(self.options.width * s, self.options.height * s, background)
    }

    /// Renders a draw list: opaque triangles with the z-buffer, then translucent ones back to
    /// front, then edge overlays, then the list's overlays in order.
    ///
    /// # Errors
    /// When a mesh has an out-of-range index or an attribute of the wrong length.
    ///
    /// # Performance
    /// Triangle setup is parallel over triangles, rasterization over row bands: a
    /// 14k-triangle mesh at 400×400 takes a few milliseconds on two cores.
    pub fn render(&self, list: &DrawList, view: &View) -> Result<Image> {
        let mut t = self.target(self.options.background);
        self.draw_meshes(&mut t, list, view)?;
        self.draw_overlays(&mut t, list, view);
        Ok(self.resolve(&t))
    }

    /// Renders `current` with `ghosts` (neighbouring frames) as translucent solids beneath it:
    /// each ghost is rendered on its own (so it hides its own back side) and composited with
    /// its opacity wherever `current` has no opaque surface, so the current frame always reads
    /// clearly (as onion skins do in animation packages). Ghosts are composited in the given
    /// order (pass the farthest in time first). The overlays of `current` are drawn last;
    /// ghosts' overlays are ignored.
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn render_layers(
        &self,
        current: &DrawList,
        ghosts: &[Ghost],
        view: &View,
    ) -> Result<Image> {
        let mut t = self.target(self.options.background);
        self.draw_meshes(&mut t, current, view)?;
        let layers: Vec<Target> = ghosts
            .par_iter()
            .map(|g| {
                let mut gt = self.target([0.0; 4]);
                self.draw_meshes(&mut gt, &g.list, view).map(|_| gt)
            })
            .collect::<Result<_>>()?;
        for (g, gt) in ghosts.iter().zip(&layers) {
            let o = if g.opacity.is_nan() {
                0.0
            } else {
                g.opacity.clamp(0.0, 1.0)
            };
            t.color
                .par_iter_mut()
                .zip(&t.depth)
                .zip(gt.color.par_iter().zip(&gt.depth))
                .for_each(|((d, &dz), (s, &sz))| {
                    if dz.is_infinite() && (sz.is_finite() || s[3] > 0.0) {
                        let a = s[3] * o;
                        let k = 1.0 - a;
                        *d = [
                            s[0] * o + d[0] * k,
                            s[1] * o + d[1] * k,
                            s[2] * o + d[2] * k,
                            a + d[3] * k,
                        ];
                    }
                });
        }
        self.draw_overlays(&mut t, current, view);
        Ok(self.resolve(&t))
    }

    fn draw_meshes(&self, t: &mut Target, list: &DrawList, view: &View) -> Result<()> {
        let shader = self.shader();
        let mut opaque: Vec<Tri> = Vec::new();
        let mut translucent: Vec<Tri> = Vec::new();
        for m in &list.meshes {
            let (o, tr) = setup_mesh(m, view, &shader, t.width, t.height)?;
            if opaque.is_empty() {
                opaque = o;
            } else {
                opaque.extend(o);
            }
            translucent.extend(tr);
        }
        rasterize(t, &opaque, false);
        translucent.sort_by(|a, b| b.key.total_cmp(&a.key));
        rasterize(t, &translucent, true);
        for m in &list.meshes {
            if let Some(style) = m.edges {
                let segs = edge_segments(m, style.mode, style.color, view, t.width, t.height);
                draw_segments(t, &segs, style.width * self.options.supersample as f32);
            }
        }
        Ok(())
    }

    fn draw_overlays(&self, t: &mut Target, list: &DrawList, view: &View) {
        let s = self.options.supersample as f32;
        for o in &list.overlays {
            let pts: Vec<Option<LinePoint>> = (0..o.coords.len())
                .map(|i| {
                    let c = o.color_at(i);
                    let color = Vec4::new(c[0], c[1], c[2], c[3]);
                    match &o.coords {
                        Coords::Pixel(p) => {
                            let p = p[i] * s;
                            p.is_finite().then_some(LinePoint {
                                p,
                                depth: None,
                                color,
                            })
                        }
                        Coords::World(p) => view.project(p[i], t.width, t.height).and_then(|q| {
                            let depth = o.depth_test.then_some(q.z);
                            q.is_finite().then_some(LinePoint {
                                p: q.truncate(),
                                depth,
                                color,
                            })
                        }),
                    }
                })
                .collect();
            let segs: Vec<(LinePoint, LinePoint)> = match o.kind {
                OverlayKind::Points => pts.iter().flatten().map(|p| (*p, *p)).collect(),
                OverlayKind::Polyline if pts.len() == 1 => {
                    pts.iter().flatten().map(|p| (*p, *p)).collect()
                }
                OverlayKind::Polyline => pts
                    .windows(2)
                    .filter_map(|w| Some((w[0]?, w[1]?)))
                    .collect(),
            };
            draw_segments(t, &segs, o.width * s);
        }
    }

    /// Downsamples the supersampled target and converts it to sRGB with straight alpha.
    fn resolve(&self, t: &Target) -> Image {
        let s = self.options.supersample as usize;
        let (w, h) = (self.options.width as usize, self.options.height as usize);
        let tw = t.width as usize;
        let inv = 1.0 / (s * s) as f32;
        let lut = srgb_lut();
        let mut px = vec![[0u8; 4]; w * h];
        px.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let mut acc = [0.0f32; 4];
                for sy in 0..s {
                    let base = (y * s + sy) * tw + x * s;
                    for c in &t.color[base..base + s] {
                        for k in 0..4 {
                            acc[k] += c[k];
                        }
                    }
                }
                let a = acc[3] * inv;
                let un = if a > 0.0 { inv / a } else { 0.0 };
                *out = [
                    lut_encode(lut, acc[0] * un),
                    lut_encode(lut, acc[1] * un),
                    lut_encode(lut, acc[2] * un),
                    (a.clamp(0.0, 1.0) * 255.0 + 0.5) as u8,
                ];
            }
        });
        Image::from_pixels(self.options.width, self.options.height, px)
            .expect("size checked at construction")
    }
}

/// Screen segments of a mesh's wireframe or silhouette edges, depth-tested.
fn edge_segments(
    m: &MeshItem,
    mode: EdgeMode,
    color: Color,
    view: &View,
    width: u32,
    height: u32,
) -> Vec<(LinePoint, LinePoint)> {
    if validate(m).is_err() {
        return Vec::new();
    }
    let color = Vec4::from_array(color);
    let proj: Vec<Option<LinePoint>> = m
        .positions
        .iter()
        .map(|&p| {
            view.project(p, width, height)
                .filter(|q| q.is_finite())
                .map(|q| LinePoint {
                    p: Vec2::new(q.x, q.y),
                    depth: Some(q.z),
                    color,
                })
        })
        .collect();
    // (lo, hi, facing) per triangle edge, sorted to group shared edges deterministically.
    let mut edges: Vec<(u32, u32, bool)> = Vec::with_capacity(m.triangles.len() * 3);
    for tri in m.triangles {
        let p = tri.map(|i| view.view.transform_point3(m.positions[i as usize]));
        let face = (p[1] - p[0]).cross(p[2] - p[0]);
        let to_eye = if view.perspective {
            -(p[0] + p[1] + p[2]) / 3.0
        } else {
            Vec3::Z
        };
        let front = face.dot(to_eye) >= 0.0;
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b), front));
        }
    }
    edges.sort_unstable();
    let mut segs = Vec::new();
    let mut i = 0;
    while i < edges.len() {
        let (a, b, _) = edges[i];
        let mut j = i;
        let (mut fronts, mut count) = (0, 0);
        while j < edges.len() && edges[j].0 == a && edges[j].1 == b {
            fronts += edges[j].2 as usize;
            count += 1;
            j += 1;
        }
        let keep = match mode {
            EdgeMode::Wireframe => true,
            EdgeMode::Silhouette => count == 1 || (fronts > 0 && fronts < count),
        };
        if keep {
            if let (Some(pa), Some(pb)) = (proj[a as usize], proj[b as usize]) {
                segs.push((pa, pb));
            }
        }
        i = j;
    }
    segs
}
