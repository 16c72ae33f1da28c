//! Motion lines (Section 4.3, SMEAR Eq. 13): tubes traced along the trajectories of surface seeds.

use anim::{Curves, Mesh};
use rayon::prelude::*;

use super::inputs::{check_frame, check_step, held_frame};
use super::tube::{sweep, Ring};
use super::{EffectInputs, Stylize, DEFAULT_FRAME_STEP};
use crate::{Param, Result, SmearError};

/// Default number of sides of a line's tube.
pub const DEFAULT_LINE_SIDES: usize = 6;
/// Default number of rings along a line.
pub const DEFAULT_LINE_SAMPLES: usize = 16;

/// The stylization functions of motion lines; each sees the seed's inputs with `t ∈ [0, 1]`
/// the position along the line (0 at the surface end) — `t` is 0 for `length`.
#[derive(Clone, Copy)]
pub struct LineStyle<'s> {
    /// τ = S_L(x) (SMEAR Eq. 13): signed length in frames along the trajectory, like β in
    /// Section 4.1 (τ < 0 traces the past, τ > 0 the future; the paper's example
    /// S_L(δ; τ_max) = δ·τ_max makes trailing seeds trail). τ = 0 draws nothing.
    pub length: &'s dyn Stylize,
    /// Tube radius in scene units along the line.
    pub thickness: &'s dyn Stylize,
    /// Opacity in [0, 1] along the line (e.g. `1 − t`: fading out, Fig. 15).
    pub opacity: &'s dyn Stylize,
}

impl std::fmt::Debug for LineStyle<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("LineStyle { .. }")
    }
}

/// Options of [`motion_lines`] / [`motion_lines_frame`]. `gap`, `min_speed` and `count` may
/// be keyframed (Section 5.1).
#[derive(Debug, Clone, PartialEq)]
pub struct LineOptions {
    /// Sides of each tube (≥ 3).
    pub sides: usize,
    /// Rings along each line (≥ 2).
    pub samples: usize,
    /// Gap between the surface and the line, in frames along the trajectory (Fig. 15: seeds
    /// displaced along their trajectory). Lines not longer than the gap are not drawn.
    pub gap: Param,
    /// Speed threshold v_min (units per frame): seeds slower than it draw no line — the
    /// Heaviside factor H(‖v‖ − v_min) of Section 5.2.
    pub min_speed: Param,
    /// How many of the seeds may draw a line at each frame (rounded); `None` = all. The
    /// subset is a fixed pseudo-random ranking of the seeds, so raising the count adds lines
    /// and lowering it removes some without the others jumping.
    pub count: Option<Param>,
    /// Only trace the past (τ clamped to ≤ 0, the δ⁻ = min(δ, 0) of Fig. 15).
    pub past_only: bool,
    /// Frame step: 2 = "on twos" (τ scaled by 2, drawings held; Section 5.2).
    pub step: usize,
    /// RGB colour of the lines (alpha comes from [`LineStyle::opacity`]).
    pub color: [Param; 3],
}

impl Default for LineOptions {
    fn default() -> Self {
        LineOptions {
            sides: DEFAULT_LINE_SIDES,
            samples: DEFAULT_LINE_SAMPLES,
            gap: Param::Constant(0.0),
            min_speed: Param::Constant(0.0),
            count: None,
            past_only: false,
            step: DEFAULT_FRAME_STEP,
            color: [0.05, 0.05, 0.05].map(Param::Constant),
        }
    }
}

/// The motion lines of one frame: one tube mesh (positions, triangles, RGBA vertex colours)
/// holding every visible line. Reusable across frames to avoid reallocating.
#[derive(Debug, Clone)]
pub struct LineFrame {
    /// All tubes of the frame; empty when no line is visible.
    pub mesh: Mesh,
    /// Number of lines drawn.
    pub lines: usize,
    /// Summed length of the lines drawn, along their centres (scene units).
    pub length: f32,
    /// The same lines as curves: each tube's centre line, its diameter and colour per ring
    /// (for scene files that draw curves, USD's `BasisCurves`).
    pub curves: Curves,
    rings: Vec<Ring>,
}

impl Default for LineFrame {
    fn default() -> Self {
        LineFrame {
            mesh: Mesh::new("motion_lines", Vec::new(), Vec::new()),
            lines: 0,
            length: 0.0,
            curves: Curves::default(),
            rings: Vec::new(),
        }
    }
}

fn check(options: &LineOptions) -> Result<usize> {
    let bad = |name, reason: &str| {
        Err(SmearError::InvalidParameter {
            name,
            reason: reason.into(),
        })
    };
    if options.sides < 3 {
        return bad("line sides", "a tube needs at least 3 sides");
    }
    if options.samples < 2 {
        return bad("line samples", "a line needs at least 2 rings");
    }
    if options
        .gap
        .validate("gap", (0.0, false), (f32::MAX, false))
        .is_err()
    {
        return bad("line gap", "must be a finite number of frames ≥ 0");
    }
    if options.min_speed.validate_finite("min_speed").is_err() {
        return bad("minimum speed", "must be a finite number (units per frame)");
    }
    for (c, name) in options.color.iter().zip(["red", "green", "blue"]) {
        if c.validate(name, (0.0, false), (1.0, false)).is_err() {
            return bad("line colour", "RGB components must be numbers in [0, 1]");
        }
    }
    if let Some(c) = &options.count {
        if c.validate("count", (0.0, false), (1e9, false)).is_err() {
            return bad("line count", "must be a number of lines ≥ 0");
        }
    }
    check_step(options.step)
}

/// Rank of every seed in a fixed pseudo-random order (SplitMix64 of the index): seeds with a
/// rank below the frame's count draw.
fn seed_ranks(count: usize) -> Vec<u32> {
    let mut order: Vec<u32> = (0..count as u32).collect();
    order.sort_by_key(|&i| (anim::mix(i as u64), i));
    let mut rank = vec![0u32; count];
    for (r, &i) in order.iter().enumerate() {
        rank[i as usize] = r as u32;
    }
    rank
}

/// Traces the lines of the drawing at frame `h` into `out`.
fn trace(
    seeds: &EffectInputs<'_>,
    style: &LineStyle<'_>,
    h: usize,
    options: &LineOptions,
    ranks: &[u32],
    out: &mut LineFrame,
) {
    out.mesh.positions.clear();
    out.mesh.triangles.clear();
    out.mesh.colors = Some(out.mesh.colors.take().unwrap_or_default());
    if let Some(c) = out.mesh.colors.as_mut() {
        c.clear();
    }
    out.lines = 0;
    out.length = 0.0;
    out.curves.clear();
    let tr = seeds.trajectories();
    let scale = options.step as f32;
    let [r, g, b] = options
        .color
        .each_ref()
        .map(|c| c.at(h as f32).clamp(0.0, 1.0));
    let (gap, min_speed) = (options.gap.at(h as f32), options.min_speed.at(h as f32));
    let drawn = options
        .count
        .as_ref()
        .map_or(u32::MAX, |c| c.at(h as f32).round().max(0.0) as u32);
    for l in 0..seeds.point_count() {
        if ranks.get(l).is_some_and(|&r| r >= drawn) {
            continue;
        }
        let mut x = seeds.style_input(h, l);
        if x.speed < min_speed {
            continue;
        }
        let mut tau = scale * style.length.eval(&x);
        if options.past_only {
            tau = tau.min(0.0);
        }
        if !tau.is_finite() || tau.abs() <= gap || tau == 0.0 {
            continue;
        }
        let start = h as f32 + gap * tau.signum();
        let end = h as f32 + tau;
        out.rings.clear();
        let n = options.samples;
        for j in 0..n {
            let t = j as f32 / (n - 1) as f32;
            let center = tr.seen_from(h, l, start + (end - start) * t);
            // Beyond the clip the trajectory clamps: drop repeated points.
            if out
                .rings
                .last()
                .is_some_and(|q| q.center.distance(center) <= 1e-7)
            {
                continue;
            }
            x.t = t;
            let alpha = style.opacity.eval(&x);
            out.rings.push(Ring {
                center,
                radius: style.thickness.eval(&x),
                color: [
                    r,
                    g,
                    b,
                    if alpha.is_finite() {
                        alpha.clamp(0.0, 1.0)
                    } else {
                        0.0
                    },
                ],
            });
        }
        if sweep(&out.rings, options.sides, &mut out.mesh) {
            out.lines += 1;
            out.length += out
                .rings
                .windows(2)
                .map(|w| w[0].center.distance(w[1].center))
                .sum::<f32>();
            let rings = out.rings.iter();
            let width = |r: f32| if r.is_finite() { 2.0 * r.max(0.0) } else { 0.0 };
            out.curves
                .push(rings.map(|r| (r.center, width(r.radius), r.color)));
        }
    }
}

/// The motion lines of one frame (Section 4.3): seed ℓ's line runs along its trajectory from
/// time `f + gap·sign(τ)` to `f + τ`, with `τ_ℓ(f) = step · S_L(x_ℓ(f))` (SMEAR Eq. 13), sampled at
/// `samples` rings whose radius and opacity are `style.thickness` / `style.opacity` at
/// `t = j / (samples − 1)`. Seeds slower than `min_speed`, τ = 0 or non-finite, and still
/// trajectories draw nothing.
///
/// # Arguments
/// * `seeds` — the seeds' inputs, from [`EffectInputs::at_surface_points`] with offsets
///   evaluated at the seeds ([`OffsetSolver::surface_offsets`](crate::OffsetSolver::surface_offsets)).
/// * `out` — overwritten; reuse it across frames to avoid reallocating.
///
/// # Errors
/// [`SmearError::InvalidParameter`] for a bad frame or option (see [`LineOptions`]).
///
/// # Performance
/// Sequential over lines; no allocation once `out` has grown to size (a keyframed `count`
/// ranks the seeds once per call: O(K log K)).
pub fn motion_lines_frame(
    seeds: &EffectInputs<'_>,
    style: &LineStyle<'_>,
    frame: usize,
    options: &LineOptions,
    out: &mut LineFrame,
) -> Result<()> {
    let step = check(options)?;
    check_frame(frame, seeds.frame_count())?;
    let ranks = ranks_for(seeds, options);
    trace(seeds, style, held_frame(frame, step), options, &ranks, out);
    Ok(())
}

/// The motion lines of every frame (see [`motion_lines_frame`]).
///
/// # Errors
/// As [`motion_lines_frame`].
///
/// # Performance
/// Parallel over frames.
pub fn motion_lines(
    seeds: &EffectInputs<'_>,
    style: &LineStyle<'_>,
    options: &LineOptions,
) -> Result<Vec<LineFrame>> {
    let step = check(options)?;
    let ranks = ranks_for(seeds, options);
    Ok((0..seeds.frame_count())
        .into_par_iter()
        .map(|f| {
            let mut out = LineFrame::default();
            trace(seeds, style, held_frame(f, step), options, &ranks, &mut out);
            out
        })
        .collect())
}

/// The seed ranks when a count is set (none otherwise: every seed draws).
fn ranks_for(seeds: &EffectInputs<'_>, options: &LineOptions) -> Vec<u32> {
    match options.count {
        Some(_) => seed_ranks(seeds.point_count()),
        None => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::test_util::translating_ball;
    use crate::effects::{sample_surface, StyleInput};
    use crate::{OffsetOptions, OffsetSolver};

    fn seeds_of(anim: &anim::MeshAnimation, count: usize) -> EffectInputs<'static> {
        let solver = OffsetSolver::from_animation(anim, &OffsetOptions::default(), &[]).unwrap();
        let pts = sample_surface(anim.frame(0), &anim.mesh.triangles, count, 3);
        let off = solver.surface_offsets(0, &pts).unwrap();
        EffectInputs::at_surface_points(anim, &pts, off).unwrap()
    }

    #[test]
    fn fig3e_line_length_is_tau_max_at_unit_offset() {
        // S_L(δ; τ_max) = δ·τ_max on a ball moving 0.5 per frame: a seed with |δ| = 1 traces
        // τ_max frames, i.e. 0.5·τ_max units (straight trajectory).
        let anim = translating_ball(30, 0.5);
        let seeds = seeds_of(&anim, 400);
        let tau_max = 4.0;
        let length = move |x: &StyleInput| x.delta * tau_max;
        let thin = |_: &StyleInput| 0.01;
        let fade = |x: &StyleInput| 1.0 - x.t;
        let style = LineStyle {
            length: &length,
            thickness: &thin,
            opacity: &fade,
        };
        let opts = LineOptions::default();
        let f = 15;
        let mut out = LineFrame::default();
        motion_lines_frame(&seeds, &style, f, &opts, &mut out).unwrap();
        // The most trailing seed: its line spans |δ|·τ_max·0.5 along −X.
        let d = seeds.offsets().frame(f);
        let (l, dl) = d
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .map(|(l, v)| (l, *v))
            .unwrap();
        assert!(dl < -0.95, "most trailing seed has δ = {dl}");
        let tr = seeds.trajectories();
        let (p0, p1) = (tr.at(l, f as f32), tr.at(l, f as f32 + dl * tau_max));
        assert!(((p0 - p1).length() - 0.5 * tau_max * dl.abs()).abs() < 1e-4);
        // The mesh's extent behind the ball reaches τ_max frames back (up to the tube radius).
        let min_x = out
            .mesh
            .positions
            .iter()
            .map(|p| p.x)
            .fold(f32::MAX, f32::min);
        let ball_min = anim.frame(f).iter().map(|p| p.x).fold(f32::MAX, f32::min);
        let reach = ball_min - min_x;
        assert!(
            (reach - 0.5 * tau_max).abs() < 0.06,
            "lines reach {reach} behind the ball"
        );
        assert!(out.lines > 300 && out.lines <= 400, "{} lines", out.lines);
        let per_line = opts.samples * opts.sides;
        // Rings plus the two cap centres of each line.
        assert_eq!(out.mesh.positions.len(), out.lines * (per_line + 2));
        // Opacity fades from 1 at the surface to 0 at the end.
        let c = out.mesh.colors.as_ref().unwrap();
        assert_eq!((c[0][3], c[per_line - 1][3]), (1.0, 0.0));
    }

    #[test]
    fn zero_length_slow_seeds_and_past_only_draw_less() {
        let anim = translating_ball(12, 0.5);
        let seeds = seeds_of(&anim, 100);
        let length = |x: &StyleInput| x.delta * 3.0;
        let zero = |_: &StyleInput| 0.0;
        let one = |_: &StyleInput| 1.0;
        let thin = |_: &StyleInput| 0.02;
        let mut style = LineStyle {
            length: &zero,
            thickness: &thin,
            opacity: &one,
        };
        let opts = LineOptions::default();
        let all = motion_lines(&seeds, &style, &opts).unwrap();
        assert!(all
            .iter()
            .all(|fr| fr.lines == 0 && fr.mesh.positions.is_empty()));
        style.length = &length;
        let signed = motion_lines(&seeds, &style, &opts).unwrap()[6].lines;
        let past = LineOptions {
            past_only: true,
            ..opts.clone()
        };
        let trailing = motion_lines(&seeds, &style, &past).unwrap()[6].lines;
        let n_trailing = seeds
            .offsets()
            .frame(6)
            .iter()
            .filter(|d| **d < 0.0)
            .count();
        assert_eq!(trailing, n_trailing);
        assert!(signed > trailing);
        let slow = LineOptions {
            min_speed: 0.6.into(),
            ..opts.clone()
        };
        assert_eq!(motion_lines(&seeds, &style, &slow).unwrap()[6].lines, 0);
        let gap = LineOptions {
            gap: 1.5.into(),
            ..opts.clone()
        };
        let with_gap = motion_lines(&seeds, &style, &gap).unwrap()[6].lines;
        let longer = seeds
            .offsets()
            .frame(6)
            .iter()
            .filter(|d| d.abs() * 3.0 > 1.5)
            .count();
        assert_eq!(with_gap, longer);
        let bad = LineOptions {
            sides: 2,
            ..opts.clone()
        };
        assert!(motion_lines(&seeds, &style, &bad).is_err());
        // Still clip: no line.
        let still = translating_ball(5, 0.0);
        let seeds = seeds_of(&still, 10);
        let big = |_: &StyleInput| 2.0;
        style.length = &big;
        assert!(motion_lines(&seeds, &style, &opts)
            .unwrap()
            .iter()
            .all(|fr| fr.lines == 0));
    }

    #[test]
    fn keyframed_count_gap_and_threshold_change_lines_per_frame() {
        // Section 5.1: every parameter may be keyframed. Count ramps 0 → 40 over frames
        // 2..10: the drawn lines grow with it and keep the lines already drawn.
        let anim = translating_ball(14, 0.5);
        let seeds = seeds_of(&anim, 60);
        let length = |x: &StyleInput| x.delta.abs() * 3.0;
        let thin = |_: &StyleInput| 0.02;
        let one = |_: &StyleInput| 1.0;
        let style = LineStyle {
            length: &length,
            thickness: &thin,
            opacity: &one,
        };
        let ramp = LineOptions {
            count: Some("2:0,10:40".parse().unwrap()),
            ..LineOptions::default()
        };
        let frames = motion_lines(&seeds, &style, &ramp).unwrap();
        let all = motion_lines(&seeds, &style, &LineOptions::default()).unwrap();
        assert_eq!(frames[1].lines, 0);
        assert_eq!(frames[6].lines, 20.min(all[6].lines));
        assert_eq!(frames[12].lines, 40.min(all[12].lines));
        assert!(frames[4].lines < frames[6].lines && frames[6].lines < frames[8].lines);
        // The 20 lines of frame 6 are among the 40 of frame 12 (same ranking, same seeds).
        let ranks = seed_ranks(60);
        assert_eq!(ranks.iter().filter(|&&r| r < 20).count(), 20);
        // A gap keyed from 0 to 10 frames: no line is longer than 3 frames, so none draws
        // once the gap passes 3.
        let gap = LineOptions {
            gap: Param::Curve(vec![[0.0, 0.0], [10.0, 10.0]]),
            ..LineOptions::default()
        };
        let g = motion_lines(&seeds, &style, &gap).unwrap();
        assert!(
            g[1].lines > 0 && g[5].lines == 0,
            "{} {}",
            g[1].lines,
            g[5].lines
        );
        // A threshold above the speed from frame 8 on.
        let slow = LineOptions {
            min_speed: Param::Curve(vec![[7.0, 0.0], [8.0, 1.0]]),
            ..LineOptions::default()
        };
        let t = motion_lines(&seeds, &style, &slow).unwrap();
        assert!(t[6].lines > 0 && t[9].lines == 0);
        let bad = LineOptions {
            count: Some(Param::Constant(-1.0)),
            ..LineOptions::default()
        };
        assert!(motion_lines(&seeds, &style, &bad).is_err());
    }
}
