//! Triangle setup (transform, Lambert lighting, clipping) and z-buffered rasterization in
//! parallel row bands.
//!
//! Screen positions are snapped to 1/256 pixel and edge functions are evaluated exactly in
//! integers with the top-left fill rule, so meshes are watertight (no pixel is drawn twice
//! along a shared edge, which matters for translucent meshes). Colours are interpolated
//! perspective-correctly (attribute / w), depth linearly in screen space.

use glam::{Mat3, Vec3, Vec4, Vec4Swizzles};
use rayon::prelude::*;

use crate::draw::{MeshColors, MeshItem, Shading};
use crate::{Color, RenderError, Result, View};

/// Sub-pixel precision of snapped screen coordinates (1/256 pixel).
const SUBPIXEL: i64 = 256;
/// Guard band, in viewport half-widths: triangles reaching beyond are clipped in clip space.
const GUARD_BAND: f32 = 8.0;
/// Maximum vertices of a triangle clipped by the six planes.
const MAX_CLIPPED: usize = 9;

/// The colour and depth buffers being drawn into (linear, premultiplied alpha).
#[derive(Debug, Clone)]
pub(crate) struct Target {
    pub width: u32,
    pub height: u32,
    pub color: Vec<[f32; 4]>,
    pub depth: Vec<f32>,
}

impl Target {
    /// A cleared target; `background` is straight alpha.
    pub(crate) fn new(width: u32, height: u32, background: Color) -> Target {
        let a = background[3].clamp(0.0, 1.0);
        let pm = [background[0] * a, background[1] * a, background[2] * a, a];
        let n = width as usize * height as usize;
        Target {
            width,
            height,
            color: vec![pm; n],
            depth: vec![f32::INFINITY; n],
        }
    }
}

/// Lighting parameters shared by every mesh of a render.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Shader {
    /// Ambient term in `[0, 1]`.
    pub ambient: f32,
    /// Unit direction towards the light, camera space.
    pub light: Vec3,
    /// Drop back-facing triangles instead of lighting them from behind.
    pub cull: bool,
}

/// A set-up screen triangle.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tri {
    x: [i32; 3],
    y: [i32; 3],
    z: [f32; 3],
    inv_w: [f32; 3],
    /// Colour × 1/w per corner (straight alpha).
    col: [Vec4; 3],
    bbox: [i32; 4],
    inv_area: f32,
    /// Distance from the eye along the view axis (back-to-front sort key).
    pub key: f32,
    /// Drawn in the blending pass.
    pub translucent: bool,
}

#[derive(Debug, Clone, Copy, Default)]
struct Corner {
    clip: Vec4,
    color: Vec4,
}

/// Checks indices and attribute lengths of a mesh item.
pub(crate) fn validate(item: &MeshItem) -> Result<()> {
    let n = item.positions.len();
    for (t, tri) in item.triangles.iter().enumerate() {
        if let Some(&i) = tri.iter().find(|&&i| i as usize >= n) {
            return Err(RenderError::IndexOutOfRange {
                mesh: item.label.to_string(),
                triangle: t,
                index: i,
                vertices: n,
            });
        }
    }
    let check = |what, expected, found| {
        if expected == found {
            Ok(())
        } else {
            Err(RenderError::AttributeLength {
                mesh: item.label.to_string(),
                what,
                expected,
                found,
            })
        }
    };
    match item.colors {
        MeshColors::PerVertex(c) => check("vertex colours", n, c.len())?,
        MeshColors::PerTriangle(c) => check("triangle colours", item.triangles.len(), c.len())?,
        MeshColors::Uniform(_) => {}
    }
    if let Some(nrm) = item.normals {
        check("normals", n, nrm.len())?;
    }
    Ok(())
}

/// Transforms, lights and clips every triangle of a mesh into screen triangles, in parallel.
///
/// Returns the opaque and the translucent triangles, each in mesh order. Non-finite vertices
/// drop their triangles; fully transparent triangles are dropped.
pub(crate) fn setup_mesh(
    item: &MeshItem,
    view: &View,
    shader: &Shader,
    width: u32,
    height: u32,
) -> Result<(Vec<Tri>, Vec<Tri>)> {
    validate(item)?;
    let vpos: Vec<Vec3> = item
        .positions
        .par_iter()
        .map(|&p| view.view.transform_point3(p))
        .collect();
    let normals: Option<Vec<Vec3>> = match item.shading {
        Shading::Smooth => {
            let nm = Mat3::from_mat4(view.view).inverse().transpose();
            let world = match item.normals {
                Some(n) => n.to_vec(),
                None => anim::vertex_normals(item.positions, item.triangles),
            };
            Some(
                world
                    .par_iter()
                    .map(|&n| (nm * n).try_normalize().unwrap_or(Vec3::Z))
                    .collect(),
            )
        }
        _ => None,
    };
    let opacity = if item.opacity.is_nan() {
        1.0
    } else {
        item.opacity.clamp(0.0, 1.0)
    };
    let proj = view.projection;
    let tris = item
        .triangles
        .par_iter()
        .enumerate()
        .flat_map_iter(|(t, tri)| {
            let idx = tri.map(|i| i as usize);
            let p = idx.map(|i| vpos[i]);
            let mut poly = Poly::default();
            let mut key = 0.0;
            let mut translucent = false;
            if p.iter().all(|q| q.is_finite()) {
                let face = (p[1] - p[0]).cross(p[2] - p[0]);
                let to_eye = if view.perspective {
                    -(p[0] + p[1] + p[2]) / 3.0
                } else {
                    Vec3::Z
                };
                let back = face.dot(to_eye) < 0.0;
                if !(back && shader.cull) {
                    let flat = face.try_normalize().unwrap_or(Vec3::Z);
                    for k in 0..3 {
                        let base: Color = match item.colors {
                            MeshColors::Uniform(c) => c,
                            MeshColors::PerVertex(c) => c[idx[k]],
                            MeshColors::PerTriangle(c) => c[t],
                        };
                        let lit = match (&normals, item.shading) {
                            (_, Shading::Unlit) => 1.0,
                            (Some(n), _) => shader.intensity(n[idx[k]], back),
                            (None, _) => shader.intensity(flat, back),
                        };
                        let a = base[3].clamp(0.0, 1.0) * opacity;
                        translucent |= a < 1.0;
                        poly.v[k] = Corner {
                            clip: proj * p[k].extend(1.0),
                            color: Vec4::new(base[0] * lit, base[1] * lit, base[2] * lit, a),
                        };
                    }
                    poly.n = 3;
                    key = -(p[0].z + p[1].z + p[2].z) / 3.0;
                    if poly.v[..3].iter().all(|c| c.color.w <= 0.0) {
                        poly.n = 0;
                    } else {
                        poly.clip();
                    }
                }
            }
            let n = poly.n;
            (1..n.saturating_sub(1)).filter_map(move |k| {
                make_tri(
                    [poly.v[0], poly.v[k], poly.v[k + 1]],
                    width,
                    height,
                    key,
                    translucent,
                )
            })
        })
        .partition(|t| !t.translucent);
    Ok(tris)
}

impl Shader {
    /// Lambert term with ambient; back faces are lit as seen from behind (two-sided).
    #[inline]
    fn intensity(&self, n: Vec3, back: bool) -> f32 {
        let n = if back { -n } else { n };
        self.ambient + (1.0 - self.ambient) * n.dot(self.light).max(0.0)
    }
}

/// A convex polygon in clip space.
#[derive(Debug, Clone, Copy, Default)]
struct Poly {
    v: [Corner; MAX_CLIPPED],
    n: usize,
}

impl Poly {
    /// Sutherland–Hodgman against near, far and the guard band.
    fn clip(&mut self) {
        let g = GUARD_BAND;
        let planes = [
            Vec4::new(0.0, 0.0, 1.0, 1.0),
            Vec4::new(0.0, 0.0, -1.0, 1.0),
            Vec4::new(1.0, 0.0, 0.0, g),
            Vec4::new(-1.0, 0.0, 0.0, g),
            Vec4::new(0.0, 1.0, 0.0, g),
            Vec4::new(0.0, -1.0, 0.0, g),
        ];
        for plane in planes {
            if self.n == 0 {
                return;
            }
            let d: [f32; MAX_CLIPPED] = std::array::from_fn(|i| {
                if i < self.n {
                    plane.dot(self.v[i].clip)
                } else {
                    0.0
                }
            });
            if d[..self.n].iter().all(|&x| x >= 0.0) {
                continue;
            }
            let mut out = Poly::default();
            for i in 0..self.n {
                let j = (i + 1) % self.n;
                let (a, b) = (self.v[i], self.v[j]);
                if d[i] >= 0.0 && out.n < MAX_CLIPPED {
                    out.v[out.n] = a;
                    out.n += 1;
                }
                if (d[i] >= 0.0) != (d[j] >= 0.0) && out.n < MAX_CLIPPED {
                    let t = d[i] / (d[i] - d[j]);
                    out.v[out.n] = Corner {
                        clip: a.clip.lerp(b.clip, t),
                        color: a.color.lerp(b.color, t),
                    };
                    out.n += 1;
                }
            }
            *self = out;
        }
    }
}

fn make_tri(c: [Corner; 3], width: u32, height: u32, key: f32, translucent: bool) -> Option<Tri> {
    let (w, h) = (width as f32, height as f32);
    let mut x = [0i64; 3];
    let mut y = [0i64; 3];
    let mut z = [0f32; 3];
    let mut inv_w = [0f32; 3];
    let mut col = [Vec4::ZERO; 3];
    for k in 0..3 {
        let iw = 1.0 / c[k].clip.w;
        if !iw.is_finite() || iw <= 0.0 {
            return None;
        }
        let n = c[k].clip.xyz() * iw;
        x[k] = ((n.x * 0.5 + 0.5) * w * SUBPIXEL as f32).round() as i64;
        y[k] = ((0.5 - n.y * 0.5) * h * SUBPIXEL as f32).round() as i64;
        z[k] = n.z * 0.5 + 0.5;
        inv_w[k] = iw;
        col[k] = c[k].color * iw;
    }
    let mut area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
    if area == 0 {
        return None;
    }
    if area < 0 {
        x.swap(1, 2);
        y.swap(1, 2);
        z.swap(1, 2);
        inv_w.swap(1, 2);
        col.swap(1, 2);
        area = -area;
    }
    let half = SUBPIXEL / 2;
    let (minx, maxx) = (x.iter().min()?, x.iter().max()?);
    let (miny, maxy) = (y.iter().min()?, y.iter().max()?);
    let x0 = ((minx - half + SUBPIXEL - 1).div_euclid(SUBPIXEL)).max(0);
    let x1 = ((maxx - half).div_euclid(SUBPIXEL)).min(width as i64 - 1);
    let y0 = ((miny - half + SUBPIXEL - 1).div_euclid(SUBPIXEL)).max(0);
    let y1 = ((maxy - half).div_euclid(SUBPIXEL)).min(height as i64 - 1);
    if x0 > x1 || y0 > y1 {
        return None;
    }
    Some(Tri {
        x: x.map(|v| v as i32),
        y: y.map(|v| v as i32),
        z,
        inv_w,
        col,
        bbox: [x0 as i32, y0 as i32, x1 as i32, y1 as i32],
        inv_area: 1.0 / area as f32,
        key,
        translucent,
    })
}

/// Rows per band for a target of this height: about four bands per thread.
fn band_height(height: u32) -> usize {
    let bands = rayon::current_num_threads().max(1) * 4;
    (height as usize).div_ceil(bands).max(8)
}

/// Draws triangles in order into the target. Opaque triangles write depth; with `blend` the
/// triangles are composited "over" (premultiplied) after the depth test, without writing
/// depth. Parallel over row bands; the result does not depend on the number of threads.
pub(crate) fn rasterize(target: &mut Target, tris: &[Tri], blend: bool) {
    if tris.is_empty() {
        return;
    }
    let w = target.width as usize;
    let bh = band_height(target.height);
    let nb = (target.height as usize).div_ceil(bh);
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); nb];
    for (i, t) in tris.iter().enumerate() {
        for b in bins
            .iter_mut()
            .take(t.bbox[3] as usize / bh + 1)
            .skip(t.bbox[1] as usize / bh)
        {
            b.push(i as u32);
        }
    }
    target
        .color
        .par_chunks_mut(w * bh)
        .zip(target.depth.par_chunks_mut(w * bh))
        .zip(bins.par_iter())
        .enumerate()
        .for_each(|(b, ((color, depth), bin))| {
            let row0 = (b * bh) as i32;
            let row1 = row0 + (color.len() / w) as i32 - 1;
            for &i in bin {
                draw_tri(&tris[i as usize], color, depth, w, row0, row1, blend);
            }
        });
}

#[inline]
fn is_top_left(dx: i64, dy: i64) -> bool {
    (dy == 0 && dx > 0) || dy < 0
}

#[inline]
fn draw_tri(
    t: &Tri,
    color: &mut [[f32; 4]],
    depth: &mut [f32],
    w: usize,
    r0: i32,
    r1: i32,
    blend: bool,
) {
    let ys = t.bbox[1].max(r0);
    let ye = t.bbox[3].min(r1);
    if ys > ye {
        return;
    }
    let (tx, ty) = (t.x.map(i64::from), t.y.map(i64::from));
    // Edge k is opposite vertex k: from v[k+1] to v[k+2]. A pixel is inside when
    // e_k >= need_k for all k (need 1 on edges that are not top-left: the fill rule).
    let mut dx = [0i64; 3];
    let mut dy = [0i64; 3];
    let mut need = [0i64; 3];
    for k in 0..3 {
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        dx[k] = tx[b] - tx[a];
        dy[k] = ty[b] - ty[a];
        need[k] = if is_top_left(dx[k], dy[k]) { 0 } else { 1 };
    }
    let half = SUBPIXEL / 2;
    let (bx0, bx1) = (t.bbox[0], t.bbox[2]);
    let px0 = bx0 as i64 * SUBPIXEL + half;
    let last = (bx1 - bx0) as i64;
    for yy in ys..=ye {
        let py = yy as i64 * SUBPIXEL + half;
        // Span of pixel offsets i in [lo, hi] where every edge function is inside.
        let (mut lo, mut hi) = (0i64, last);
        let mut e = [0i64; 3];
        for k in 0..3 {
            let a = (k + 1) % 3;
            e[k] = dx[k] * (py - ty[a]) - dy[k] * (px0 - tx[a]);
            let step = -dy[k] * SUBPIXEL;
            let m = need[k] - e[k];
            if step > 0 {
                lo = lo.max(m.div_euclid(step) + (m.rem_euclid(step) != 0) as i64);
            } else if step < 0 {
                hi = hi.min((-m).div_euclid(-step));
            } else if m > 0 {
                hi = -1;
            }
        }
        if lo > hi {
            continue;
        }
        let row = (yy - r0) as usize * w + bx0 as usize;
        let mut ef = [0f32; 3];
        let mut sf = [0f32; 3];
        for k in 0..3 {
            ef[k] = (e[k] - dy[k] * SUBPIXEL * lo) as f32 * t.inv_area;
            sf[k] = (-dy[k] * SUBPIXEL) as f32 * t.inv_area;
        }
        for i in lo..=hi {
            let f = (i - lo) as f32;
            let l = [ef[0] + sf[0] * f, ef[1] + sf[1] * f, ef[2] + sf[2] * f];
            let z = l[0] * t.z[0] + l[1] * t.z[1] + l[2] * t.z[2];
            let idx = row + i as usize;
            if z < depth[idx] {
                let q = l[0] * t.inv_w[0] + l[1] * t.inv_w[1] + l[2] * t.inv_w[2];
                let c = (t.col[0] * l[0] + t.col[1] * l[1] + t.col[2] * l[2]) * (1.0 / q);
                if blend {
                    let a = c.w.clamp(0.0, 1.0);
                    let d = &mut color[idx];
                    let k = 1.0 - a;
                    *d = [
                        c.x * a + d[0] * k,
                        c.y * a + d[1] * k,
                        c.z * a + d[2] * k,
                        a + d[3] * k,
                    ];
                } else {
                    color[idx] = [c.x, c.y, c.z, 1.0];
                    depth[idx] = z;
                }
            }
        }
    }
}
