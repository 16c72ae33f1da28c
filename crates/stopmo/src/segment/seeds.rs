//! Part seeds: user seeds (triangle ids or 3D points snapped to the nearest triangle) and
//! automatic seeds.

use anim::MeshAnimation;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::error::{Result, SegmentError};
use super::problem::SegmentationProblem;

/// Geodesic radius (unit-box units) of the seed patches of [`auto_seeds`].
pub const DEFAULT_AUTO_SEED_RADIUS: f64 = 0.05;

/// Centring iterations of [`auto_seeds`].
pub const DEFAULT_AUTO_CENTERING_ITERATIONS: usize = 5;

/// Maximum number of frames sampled for the motion descriptors of [`auto_seeds`].
pub const DEFAULT_AUTO_SAMPLES: usize = 64;

/// A seed of a part: a triangle of the input mesh, or a 3D point snapped to the nearest
/// triangle of the average mesh.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Seed {
    /// Input triangle id.
    Triangle(u32),
    /// A point in model units.
    Point(Vec3),
}

/// A named part and its seeds.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PartSpec {
    /// Part name (names the output mesh).
    pub name: String,
    /// Seeds; at least one.
    pub seeds: Vec<Seed>,
}

impl PartSpec {
    /// A part from a name and seeds.
    pub fn new(name: impl Into<String>, seeds: Vec<Seed>) -> PartSpec {
        PartSpec {
            name: name.into(),
            seeds,
        }
    }
}

/// Closest point to `p` on triangle `(a, b, c)` (Ericson, Real-Time Collision Detection 5.1.5).
pub(super) fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom.abs() < 1e-300 {
        return a;
    }
    a + ab * (vb / denom) + ac * (vc / denom)
}

/// The triangle nearest to `p` (lowest id on ties); `None` without triangles.
///
/// # Performance
/// Brute force, O(k) in parallel.
pub(super) fn nearest_triangle(positions: &[Vec3], triangles: &[[u32; 3]], p: Vec3) -> Option<u32> {
    let p = p.as_dvec3();
    triangles
        .par_iter()
        .enumerate()
        .map(|(t, tri)| {
            let [a, b, c] = tri.map(|i| positions[i as usize].as_dvec3());
            (
                closest_point_on_triangle(p, a, b, c).distance_squared(p),
                t as u32,
            )
        })
        .min_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)))
        .map(|x| x.1)
}

/// Resolves every part's seeds to input triangle ids (points snap to the nearest triangle of
/// the average mesh).
///
/// # Errors
/// Fewer than 2 parts, a part without seeds, an out-of-range triangle, a non-finite point,
/// or one triangle seeding two parts.
pub fn resolve_seeds(
    anim: &MeshAnimation,
    problem: &SegmentationProblem,
    parts: &[PartSpec],
) -> Result<Vec<Vec<u32>>> {
    if parts.len() < 2 {
        return Err(SegmentError::TooFewParts(parts.len()));
    }
    let k = anim.mesh.triangle_count();
    let mut owner: Vec<Option<usize>> = vec![None; k];
    let mut out = Vec::with_capacity(parts.len());
    for (j, part) in parts.iter().enumerate() {
        if part.seeds.is_empty() {
            return Err(SegmentError::EmptyPart(part.name.clone()));
        }
        let mut tris = Vec::with_capacity(part.seeds.len());
        for seed in &part.seeds {
            let t = match *seed {
                Seed::Triangle(t) if (t as usize) < k => t,
                Seed::Triangle(t) => {
                    return Err(SegmentError::SeedOutOfRange {
                        part: part.name.clone(),
                        index: t,
                        triangles: k,
                    })
                }
                Seed::Point(p) if p.is_finite() => {
                    nearest_triangle(problem.average_positions(), &anim.mesh.triangles, p)
                        .ok_or(SegmentError::NoTriangles)?
                }
                Seed::Point(_) => return Err(SegmentError::NonFiniteSeed(part.name.clone())),
            };
            match owner[t as usize] {
                Some(o) if o != j => {
                    return Err(SegmentError::ConflictingSeeds {
                        triangle: t,
                        first: parts[o].name.clone(),
                        second: part.name.clone(),
                    })
                }
                _ => owner[t as usize] = Some(j),
            }
            if !tris.contains(&t) {
                tris.push(t);
            }
        }
        out.push(tris);
    }
    Ok(out)
}

/// Automatic seeds for `n` parts (the paper leaves seeds to a user click).
///
/// Method: every triangle gets a motion descriptor — the trajectory of its centroid's
/// displacement from the average, sampled at up to [`DEFAULT_AUTO_SAMPLES`] evenly spaced
/// frames, in unit-box units. The first seed is the triangle that moves most (largest RMS
/// displacement); each next seed is chosen by farthest-point sampling in the combined
/// distance `sqrt(g² + r²)`, where `g` is the geodesic distance to a chosen seed divided by
/// the largest geodesic distance from the first seed, and `r` the RMS difference of the
/// trajectories divided by the largest RMS displacement. Seeds thus land on regions that are
/// both far apart and move differently; the graph cut (StopShop Eqs. 1–3) then places the
/// boundaries where motion is lowest. Deterministic (ties → lowest triangle id).
///
/// A few Lloyd-style iterations then cluster the triangles by that distance and move every
/// seed to the centre of its cluster (the triangle geodesically farthest from the cluster's
/// border), so seeds sit inside regions rather than on their extremes. Every seed is then
/// grown into a patch of geodesic radius [`DEFAULT_AUTO_SEED_RADIUS`].
///
/// # Returns
/// One seed patch per part (`n ≥ 2`, at most the triangle count).
pub fn auto_seeds(
    anim: &MeshAnimation,
    problem: &SegmentationProblem,
    n: usize,
) -> Result<Vec<Vec<u32>>> {
    let k = problem.triangle_count();
    if n < 2 {
        return Err(SegmentError::TooFewParts(n));
    }
    if n > k {
        return Err(SegmentError::Parameter(format!(
            "{n} parts but only {k} triangles"
        )));
    }
    let frames = anim.frame_count();
    let samples = frames.clamp(1, DEFAULT_AUTO_SAMPLES);
    let frame_ids: Vec<usize> = (0..samples).map(|i| i * frames / samples).collect();
    let tris = &anim.mesh.triangles;
    let avg = problem.average_positions();
    let scale = problem.scale();
    // Trajectories, triangle-major: samples × 3 values per triangle.
    let traj: Vec<Vec<DVec3>> = tris
        .par_iter()
        .map(|t| {
            let c_avg: DVec3 = t.iter().map(|&i| avg[i as usize].as_dvec3()).sum::<DVec3>() / 3.0;
            frame_ids
                .iter()
                .map(|&f| {
                    let x = anim.frame(f);
                    let c: DVec3 = t.iter().map(|&i| x[i as usize].as_dvec3()).sum::<DVec3>() / 3.0;
                    (c - c_avg) * scale
                })
                .collect()
        })
        .collect();
    let rms = |a: &[DVec3], b: Option<&[DVec3]>| -> f64 {
        let s: f64 = match b {
            Some(b) => a.iter().zip(b).map(|(x, y)| x.distance_squared(*y)).sum(),
            None => a.iter().map(|x| x.length_squared()).sum(),
        };
        (s / a.len().max(1) as f64).sqrt()
    };
    let motion: Vec<f64> = traj.par_iter().map(|t| rms(t, None)).collect();
    let first = (0..k).fold(0, |b, t| if motion[t] > motion[b] { t } else { b });
    let max_motion = motion[first].max(1e-300);
    let mut seeds = vec![first as u32];
    let g0 = problem.geodesic_distances(&[first as u32]);
    let max_g = g0.iter().copied().fold(0.0f64, f64::max).max(1e-300);
    let combined = |g: &[f64], s: usize| -> Vec<f64> {
        (0..k)
            .into_par_iter()
            .map(|t| {
                let r = rms(&traj[t], Some(&traj[s])) / max_motion;
                ((g[t] / max_g).powi(2) + r * r).sqrt()
            })
            .collect()
    };
    let mut dmin = combined(&g0, first);
    while seeds.len() < n {
        let mut next = (0..k).fold(0, |b, t| if dmin[t] > dmin[b] { t } else { b });
        if seeds.contains(&(next as u32)) {
            // Every triangle coincides with a seed (e.g. a still, tiny mesh).
            next = (0..k)
                .find(|t| !seeds.contains(&(*t as u32)))
                .unwrap_or(next);
        }
        seeds.push(next as u32);
        let g = problem.geodesic_distances(&[next as u32]);
        let d = combined(&g, next);
        dmin.iter_mut().zip(&d).for_each(|(a, b)| *a = a.min(*b));
    }
    // Lloyd-style centring: cluster the triangles by the combined distance, then move every
    // seed to the centre of its cluster (the triangle farthest from the cluster's border).
    for _ in 0..DEFAULT_AUTO_CENTERING_ITERATIONS {
        let ds: Vec<Vec<f64>> = seeds
            .iter()
            .map(|&s| combined(&problem.geodesic_distances(&[s]), s as usize))
            .collect();
        let assign: Vec<usize> = (0..k)
            .map(|t| (0..n).fold(0, |b, j| if ds[j][t] < ds[b][t] { j } else { b }))
            .collect();
        let mut border: Vec<u32> = Vec::new();
        for e in &problem.topology.dual {
            if assign[e.a as usize] != assign[e.b as usize] {
                border.push(e.a);
                border.push(e.b);
            }
        }
        if border.is_empty() {
            break;
        }
        let depth = problem.geodesic_distances(&border);
        let mut centre: Vec<Option<usize>> = vec![None; n];
        for t in 0..k {
            let c = &mut centre[assign[t]];
            if c.is_none_or(|b| depth[t] > depth[b]) {
                *c = Some(t);
            }
        }
        let moved: Vec<u32> = (0..n)
            .map(|j| centre[j].map_or(seeds[j], |t| t as u32))
            .collect();
        let mut unique = moved.clone();
        unique.sort_unstable();
        unique.dedup();
        if moved == seeds || unique.len() < n {
            break;
        }
        seeds = moved;
    }
    // Grow every seed into a small patch (geodesic radius DEFAULT_AUTO_SEED_RADIUS in the
    // unit box, triangles nearer to another seed excluded): a single triangle is so cheap to
    // cut around that StopShop Eq. 1 may confine a part to it.
    let dists: Vec<Vec<f64>> = seeds
        .iter()
        .map(|&s| problem.geodesic_distances(&[s]))
        .collect();
    let mut patches: Vec<Vec<u32>> = seeds.iter().map(|&s| vec![s]).collect();
    for t in 0..k {
        if seeds.contains(&(t as u32)) {
            continue;
        }
        let mut order: Vec<(f64, usize)> = (0..n).map(|j| (dists[j][t], j)).collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        if order[0].0 <= DEFAULT_AUTO_SEED_RADIUS && order[0].0 < order[1].0 {
            patches[order[0].1].push(t as u32);
        }
    }
    Ok(patches)
}
