//! Registration keys and embossed piece IDs on the shared back surface.
//!
//! Keys: smooth domes raised out of the back surface (into the armature/head the pieces seat
//! on, which carries the matching dimples). Every seam the part shares with a neighbour gets
//! [`KeyOptions::per_seam`] keys (default 2) just inside it, as far apart along it as the
//! back allows, so the two sides of a seam are held where they meet; farthest-point sampling
//! then adds keys up to [`KeyOptions::count`] (at least three, not collinear: a piece pressed
//! onto its seat can neither slide nor turn, all six degrees of freedom fixed). Every piece of
//! a part has the same keys. IDs: the piece's ID raised out of the back surface as a height
//! field of a text bitmap (the caller renders the glyphs), at the back vertex farthest from
//! the boundary and the keys, readable from behind. Both only move back-surface vertices
//! along the smoothed inward direction, outward from the solid, so the wall never gets
//! thinner.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::back_surface::PartShell;
use super::error::{LibraryError, Result};

/// Keys per part (at least; seam keys may add more).
pub const DEFAULT_KEY_COUNT: usize = 3;
/// Keys along every seam, on each side.
pub const DEFAULT_KEYS_PER_SEAM: usize = 2;
/// Key radius as a fraction of the print height (clamped to 0.75–4 mm).
pub const KEY_RADIUS_PER_HEIGHT: f64 = 0.035;
/// Key height as a fraction of its radius.
pub const KEY_HEIGHT_PER_RADIUS: f64 = 0.5;
/// How much nearer another boundary may be than the seam where a seam's keys go (key
/// radii): the strict band first, then the loose ones.
const SEAM_BAND_MARGINS: [f32; 3] = [0.25, 1.0, 2.0];
/// Where a seam's keys may go, tried in order until one fits: the band (index into
/// [`SEAM_BAND_MARGINS`]) and how far apart keys stay (key radii; two radii apart, two domes
/// just touch).
const SEAM_KEY_TRIES: [(usize, f32); 4] = [(0, 2.5), (1, 2.5), (1, 2.0), (2, 2.0)];
/// Relief of an embossed ID in millimetres.
pub const DEFAULT_ID_RELIEF_MM: f64 = 0.4;

/// Registration keys (millimetres).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct KeyOptions {
    /// Number of keys per part at least (0 disables them; 3 not collinear fix all six
    /// degrees of freedom).
    pub count: usize,
    /// Keys just inside every seam shared with another part (on each side of the seam).
    pub per_seam: usize,
    /// Dome radius.
    pub radius_mm: f64,
    /// Dome height.
    pub height_mm: f64,
}

impl Default for KeyOptions {
    fn default() -> Self {
        KeyOptions::for_print_height(super::fabricate::DEFAULT_PRINT_HEIGHT_MM)
    }
}

impl KeyOptions {
    /// Keys sized from the print height.
    pub fn for_print_height(height_mm: f64) -> KeyOptions {
        let r = (height_mm * KEY_RADIUS_PER_HEIGHT).clamp(0.75, 4.0);
        KeyOptions {
            count: DEFAULT_KEY_COUNT,
            per_seam: DEFAULT_KEYS_PER_SEAM,
            radius_mm: r,
            height_mm: r * KEY_HEIGHT_PER_RADIUS,
        }
    }
}

/// One registration key (millimetres).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Key {
    /// Centre on the back surface before the dome was raised.
    pub center: [f32; 3],
    /// Direction the dome rises (out of the back surface).
    pub direction: [f32; 3],
    /// Radius.
    pub radius_mm: f32,
    /// Height.
    pub height_mm: f32,
    /// The seam it registers (index into the `seams` given to [`PartShell::add_seam_keys`]),
    /// `None` for the keys that only complete the part's registration.
    pub seam: Option<usize>,
}

/// A text bitmap: `pixels[row * width + column]`, row 0 at the top.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Bitmap {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Ink per pixel, row-major.
    pub pixels: Vec<bool>,
}

impl Bitmap {
    /// Bilinear ink coverage in [0, 1] at continuous pixel coordinates (0 outside).
    fn coverage(&self, x: f32, y: f32) -> f32 {
        let ink = |c: i64, r: i64| -> f32 {
            if c < 0 || r < 0 || c as usize >= self.width || r as usize >= self.height {
                0.0
            } else {
                f32::from(u8::from(self.pixels[r as usize * self.width + c as usize]))
            }
        };
        let (fx, fy) = (x - 0.5, y - 0.5);
        let (c, r) = (fx.floor() as i64, fy.floor() as i64);
        let (tx, ty) = (fx - fx.floor(), fy - fy.floor());
        let top = ink(c, r) * (1.0 - tx) + ink(c + 1, r) * tx;
        let bottom = ink(c, r + 1) * (1.0 - tx) + ink(c + 1, r + 1) * tx;
        top * (1.0 - ty) + bottom * ty
    }
}

/// Distance of every back vertex to the nearest of `points` (Euclidean).
fn distances(back: &[Vec3], points: &[Vec3]) -> Vec<f32> {
    back.iter()
        .map(|p| {
            points
                .iter()
                .map(|q| p.distance(*q))
                .fold(f32::INFINITY, f32::min)
        })
        .collect()
}

impl PartShell {
    fn boundary_points(&self) -> Vec<Vec3> {
        let back = self.back();
        let mut pts: Vec<Vec3> = self
            .boundary_edges()
            .iter()
            .map(|&(a, _)| back[a as usize])
            .collect();
        pts.dedup();
        pts
    }

    /// Raises the registration keys on the back surface (shared by every piece of the part):
    /// farthest-point sampling among back vertices at least a key diameter from the
    /// boundary, starting from the one farthest from it. A part with seams uses
    /// [`PartShell::add_seam_keys`].
    ///
    /// # Errors
    /// [`LibraryError::InvalidParameter`] for non-finite or negative sizes.
    pub fn add_keys(&mut self, opts: &KeyOptions) -> Result<Vec<Key>> {
        self.add_seam_keys(opts, &[])
    }

    /// Raises the registration keys: [`KeyOptions::per_seam`] keys just inside every seam
    /// (`seams[i]` lists the shell vertices of seam `i`, see [`PartShell::seam_vertices`]),
    /// spread along it, then farthest-point samples up to [`KeyOptions::count`]. Keys stay
    /// 1.5 radii from the boundary and 2.5 radii from each other.
    ///
    /// # Errors
    /// [`LibraryError::InvalidParameter`] for non-finite or negative sizes.
    pub fn add_seam_keys(&mut self, opts: &KeyOptions, seams: &[Vec<u32>]) -> Result<Vec<Key>> {
        if !(opts.radius_mm.is_finite()
            && opts.radius_mm > 0.0
            && opts.height_mm.is_finite()
            && opts.height_mm >= 0.0)
        {
            return Err(LibraryError::InvalidParameter(format!(
                "key radius must be > 0 and height >= 0 mm, got {} and {}",
                opts.radius_mm, opts.height_mm
            )));
        }
        let (r, h) = (opts.radius_mm as f32, opts.height_mm as f32);
        let n = self.back().len();
        let from_boundary = distances(self.back(), &self.boundary_points());
        let allowed: Vec<bool> = (0..n).map(|v| from_boundary[v] >= 1.5 * r).collect();
        let mut keys: Vec<Key> = Vec::new();
        let mut centres: Vec<Vec3> = Vec::new();
        let key_at = |v: usize, seam: Option<usize>| Key {
            center: self.back()[v].to_array(),
            direction: (-self.direction(v)).to_array(),
            radius_mm: r,
            height_mm: h,
            seam,
        };
        if opts.count > 0 {
            for (i, seam) in seams.iter().enumerate() {
                let pts: Vec<Vec3> = seam
                    .iter()
                    .filter_map(|&v| self.back().get(v as usize).copied())
                    .collect();
                if pts.is_empty() {
                    continue;
                }
                // A band just inside the seam: the seam is the nearest boundary (within
                // `margin` radii).
                let from_seam = distances(self.back(), &pts);
                let band = |margin: f32| -> Vec<usize> {
                    (0..n)
                        .filter(|&v| allowed[v] && from_seam[v] <= from_boundary[v] + margin * r)
                        .filter(|&v| from_seam[v] <= 3.0 * r)
                        .collect()
                };
                let bands = SEAM_BAND_MARGINS.map(band);
                let before = keys.len();
                for _ in 0..opts.per_seam {
                    let near = distances(self.back(), &centres);
                    // Farthest from the keys already placed (the first: from the seam's
                    // centroid, i.e. towards one end), preferring the inner edge of the band.
                    let anchor = pts.iter().copied().sum::<Vec3>() / pts.len() as f32;
                    let pick = |band: &[usize], spacing: f32| {
                        band.iter()
                            .copied()
                            .filter(|&v| near[v] >= spacing * r)
                            .max_by(|&a, &b| {
                                let s = |v: usize| {
                                    let d = if centres.is_empty() {
                                        self.back()[v].distance(anchor)
                                    } else {
                                        near[v]
                                    };
                                    d - (from_seam[v] - 2.0 * r).abs()
                                };
                                s(a).total_cmp(&s(b))
                            })
                    };
                    // A short seam between two others (three automatic parts on the face:
                    // 15 mm) has room for one key in the strict band: nearer the seams it
                    // meets, then closer together, before it gets fewer keys.
                    let best = SEAM_KEY_TRIES
                        .iter()
                        .find_map(|&(b, spacing)| pick(&bands[b], spacing));
                    let Some(v) = best else { break };
                    keys.push(key_at(v, Some(i)));
                    centres.push(self.back()[v]);
                }
                if opts.per_seam >= 2 && keys.len() - before < 2 {
                    if let Some(pair) = self.spaced_pair(&bands, &centres[..before], r) {
                        keys.truncate(before);
                        centres.truncate(before);
                        for v in pair {
                            keys.push(key_at(v, Some(i)));
                            centres.push(self.back()[v]);
                        }
                    }
                }
            }
        }
        while keys.len() < opts.count {
            let from_keys = distances(self.back(), &centres);
            let best = (0..n).filter(|&v| allowed[v]).max_by(|&a, &b| {
                let s = |v: usize| from_keys[v].min(4.0 * from_boundary[v]);
                s(a).total_cmp(&s(b))
            });
            let Some(v) = best else { break };
            if from_keys[v] < 2.5 * r {
                break;
            }
            keys.push(key_at(v, None));
            centres.push(self.back()[v]);
        }
        for key in &keys {
            let c = Vec3::from_array(key.center);
            self.displace_back(|v, p| {
                let d = p.distance(c) / r;
                if d >= 1.0 || v.is_boundary {
                    0.0
                } else {
                    h * (1.0 - d * d).powi(2)
                }
            });
        }
        Ok(keys)
    }

    /// Two keys for a short seam crowded by another seam's keys, where the greedy first key
    /// left no room for a second (three automatic parts on the ICT face, the 15 mm seam
    /// between the nose-and-eyes part and a cheek, once the back there moved by a few tenths
    /// of a millimetre): the farthest-apart pair of the loosest band's vertices that keeps
    /// the loosest spacing from each other and from the keys `placed` already.
    fn spaced_pair(&self, bands: &[Vec<usize>], placed: &[Vec3], r: f32) -> Option<[usize; 2]> {
        let (loosest, spacing) = *SEAM_KEY_TRIES.last()?;
        let near = distances(self.back(), placed);
        let band: Vec<usize> = bands
            .get(loosest)?
            .iter()
            .copied()
            .filter(|&v| near[v] >= spacing * r)
            .collect();
        let mut best: Option<(f32, [usize; 2])> = None;
        for (k, &a) in band.iter().enumerate() {
            for &b in &band[k + 1..] {
                let d = self.back()[a].distance(self.back()[b]);
                if d >= spacing * r && best.is_none_or(|x| d > x.0) {
                    best = Some((d, [a, b]));
                }
            }
        }
        best.map(|b| b.1)
    }

    /// Piece `piece` closed onto the back surface with `id` raised `relief_mm` out of the
    /// back, glyph pixels `pixel_mm` wide, centred at the back vertex farthest from the
    /// boundary and from `keys`.
    ///
    /// # Errors
    /// As [`PartShell::solid`]; [`LibraryError::InvalidParameter`] for non-positive sizes.
    pub fn solid_with_id(
        &self,
        piece: &[Vec3],
        name: &str,
        id: &Bitmap,
        pixel_mm: f64,
        relief_mm: f64,
        keys: &[Key],
    ) -> Result<anim::Mesh> {
        self.solid_with_id_at(piece, name, id, (pixel_mm, relief_mm), self.id_frame(keys))
    }

    /// [`PartShell::solid_with_id`] with the ID's centre and reading frame given
    /// ([`PartShell::id_frame`] of the keys, the same for every piece of the part: found
    /// once), and its pixel width and relief as `(pixel_mm, relief_mm)`.
    ///
    /// # Errors
    /// As [`PartShell::solid_with_id`].
    pub fn solid_with_id_at(
        &self,
        piece: &[Vec3],
        name: &str,
        id: &Bitmap,
        (pixel_mm, relief_mm): (f64, f64),
        (c, u, w): (Vec3, Vec3, Vec3),
    ) -> Result<anim::Mesh> {
        if !(pixel_mm.is_finite() && pixel_mm > 0.0 && relief_mm.is_finite() && relief_mm >= 0.0) {
            return Err(LibraryError::InvalidParameter(format!(
                "ID pixel must be > 0 and relief >= 0 mm, got {pixel_mm} and {relief_mm}"
            )));
        }
        let mut shell = self.clone();
        if id.width > 0 && id.height > 0 && relief_mm > 0.0 {
            let px = pixel_mm as f32;
            let (half_w, half_h) = (id.width as f32 * px / 2.0, id.height as f32 * px / 2.0);
            let relief = relief_mm as f32;
            shell.displace_back(|v, p| {
                if v.is_boundary {
                    return 0.0;
                }
                let q = p - c;
                let (x, y) = (q.dot(u) + half_w, half_h - q.dot(w));
                relief * id.coverage(x / px, y / px)
            });
        }
        shell.solid(piece, name)
    }

    /// Centre and reading frame (right, up) of the ID on the back surface, seen from behind.
    pub fn id_frame(&self, keys: &[Key]) -> (Vec3, Vec3, Vec3) {
        let back = self.back();
        let from_boundary = distances(back, &self.boundary_points());
        let centres: Vec<Vec3> = keys.iter().map(|k| Vec3::from_array(k.center)).collect();
        let from_keys = distances(back, &centres);
        let v = (0..back.len())
            .max_by(|&a, &b| {
                let s = |v: usize| from_boundary[v].min(from_keys[v]);
                s(a).total_cmp(&s(b))
            })
            .unwrap_or(0);
        let n = self.direction(v); // inward: the reader looks along it from behind
        let up = (Vec3::Y - n * n.dot(Vec3::Y))
            .try_normalize()
            .unwrap_or_else(|| n.any_orthonormal_vector());
        let right = n.cross(up);
        (back[v], right, up)
    }
}
