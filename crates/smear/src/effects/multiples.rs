//! Multiple in-betweens (Section 4.2, SMEAR Eqs. 11–12): displaced copies of the whole mesh in the
//! past and future, each vertex with its own opacity.

use anim::MeshAnimation;
use glam::Vec3;
use rayon::prelude::*;

use super::inputs::{check_frame, check_step, held_frame};
use super::{EffectInputs, StyleInput, Stylize, DEFAULT_FRAME_STEP, STYLE_BLOCK};
use crate::{smoothstep, Param, Result, SmearError};

/// Default temporal spacing Δf between copies (Section 4.2's example: half a frame).
pub const DEFAULT_SPACING: f32 = 0.5;

/// Most copies on either side (a guard against a typo asking for millions of meshes).
pub(crate) const MAX_MULTIPLES: usize = 64;

/// How far apart the copies are in time.
#[derive(Debug, Clone, PartialEq)]
pub enum Spacing {
    /// Δf in frames, given directly (Fig. 10 top: Δf = 0.7, a stroboscopic effect); may be
    /// keyframed (Section 5.1), e.g. to spread the copies during the fastest frames.
    Frames(Param),
    /// Derived from the wanted number N∩ of copies overlapping between consecutive frames
    /// (Section 5.2): Δf(N∩) = 1 / (m_p + m_n + 1 − N∩), N∩ ∈ [1, m_p + m_n]; keyframeable
    /// (rounded per frame).
    Overlap(Param),
}

/// Options of [`multiples`] / [`multiples_frame`]. The copy counts, the spacing and the
/// overlap may be keyframed (Section 5.1).
#[derive(Debug, Clone, PartialEq)]
pub struct MultiplesOptions {
    /// Copies in the past, m_p (indices −m_p..−1). Keyframed, the output holds the largest
    /// count of copies and those beyond `round(m_p(f))` are transparent at frame f.
    pub past: Param,
    /// Copies in the future, m_n (indices 1..m_n); keyframeable like `past`.
    pub future: Param,
    /// Temporal spacing Δf.
    pub spacing: Spacing,
    /// Frame step: 2 = "on twos" (β_m scaled by 2, drawings held; Section 5.2).
    pub step: usize,
}

impl Default for MultiplesOptions {
    fn default() -> Self {
        MultiplesOptions {
            past: Param::Constant(1.0),
            future: Param::Constant(1.0),
            spacing: Spacing::Frames(Param::Constant(DEFAULT_SPACING)),
            step: DEFAULT_FRAME_STEP,
        }
    }
}

/// A keyframed count at `frame`, rounded (negative and NaN read 0).
fn count_at(p: &Param, frame: f32) -> usize {
    let v = p.at(frame).round();
    if v >= 1.0 {
        (v as usize).min(MAX_MULTIPLES)
    } else {
        0
    }
}

impl MultiplesOptions {
    /// The multiple indices m ∈ [−m_p, m_n], m ≠ 0 (the current frame is the mesh itself), in
    /// increasing order, for the largest keyed counts: one copy per index in the output.
    pub fn indices(&self) -> Vec<i32> {
        let largest = |p: &Param| count_at(&Param::Constant(p.max_value()), 0.0) as i32;
        let (p, n) = (largest(&self.past), largest(&self.future));
        (-p..=n).filter(|&m| m != 0).collect()
    }

    /// (m_p, m_n) at `frame`.
    pub fn counts_at(&self, frame: f32) -> (usize, usize) {
        (count_at(&self.past, frame), count_at(&self.future, frame))
    }

    /// Checks the counts and the spacing at every key.
    ///
    /// # Errors
    /// [`SmearError::InvalidParameter`] for counts outside [0, 64], no copy at
    /// all, a non-finite Δf or a bad keyframe curve.
    pub fn check(&self) -> Result<()> {
        let bad = |name: &'static str, e: crate::StyleError| SmearError::InvalidParameter {
            name,
            reason: e.to_string(),
        };
        let range = ((0.0, false), (MAX_MULTIPLES as f32, false));
        self.past
            .validate("past", range.0, range.1)
            .map_err(|e| bad("past", e))?;
        self.future
            .validate("future", range.0, range.1)
            .map_err(|e| bad("future", e))?;
        if self.indices().is_empty() {
            return Err(SmearError::InvalidParameter {
                name: "past/future",
                reason: "m_p and m_n are both 0: there is no copy to draw".into(),
            });
        }
        match &self.spacing {
            Spacing::Frames(df) => {
                df.validate_finite("spacing")
                    .map_err(|e| SmearError::InvalidParameter {
                        name: "spacing",
                        reason: format!("Δf must be a finite number of frames ({e})"),
                    })
            }
            Spacing::Overlap(n) => n
                .validate("overlap", (1.0, false), (2.0 * MAX_MULTIPLES as f32, false))
                .map_err(|e| bad("overlap", e)),
        }
    }

    /// Δf in frames at `frame` (keyframes interpolate; 0 when no copy shows at that frame).
    ///
    /// # Errors
    /// As [`MultiplesOptions::check`], or N∩ outside [1, m_p + m_n] at that frame.
    pub fn spacing_at(&self, frame: f32) -> Result<f32> {
        self.check()?;
        match &self.spacing {
            Spacing::Frames(df) => Ok(df.at(frame)),
            Spacing::Overlap(n) => {
                let (p, f) = self.counts_at(frame);
                if p + f == 0 {
                    return Ok(0.0);
                }
                let n = n.at(frame).round().max(0.0) as usize;
                overlap_spacing(p, f, n).map_err(|e| match e {
                    SmearError::InvalidParameter { name, reason } => SmearError::InvalidParameter {
                        name,
                        reason: format!("{reason} at frame {frame}"),
                    },
                    e => e,
                })
            }
        }
    }
}

/// Section 5.2: the spacing Δf(N∩) = 1 / (m_p + m_n + 1 − N∩) for which N∩ copies overlap
/// between consecutive frames (retinal persistence).
///
/// # Errors
/// [`SmearError::InvalidParameter`] unless 1 ≤ N∩ ≤ m_p + m_n.
pub fn overlap_spacing(past: usize, future: usize, overlap: usize) -> Result<f32> {
    let total = past + future;
    if overlap == 0 || overlap > total {
        return Err(SmearError::InvalidParameter {
            name: "overlap",
            reason: format!(
                "N∩ must be in [1, m_p + m_n] = [1, {total}], got {overlap}{}",
                if total == 0 { " (no copies)" } else { "" }
            ),
        });
    }
    Ok(1.0 / (total + 1 - overlap) as f32)
}

/// SMEAR Eq. 12: `S_M(δ, m; m_max) = H(δm) · S((|δ| − δ_m) / (1 − δ_m))`, `δ_m = (|m| − 1) / m_max`,
/// with H the Heaviside step (H(0) = 0) and S the smoothstep. Past copies (m < 0) show only
/// trailing vertices (δ < 0), future copies only leading ones.
///
/// When δ_m ≥ 1 (|m| > m_max) the gradient degenerates to its limit, a step at |δ| = 1.
/// Non-finite inputs give 0.
pub fn multiple_opacity(delta: f32, m: f32, m_max: f32) -> f32 {
    let side = delta * m;
    if side.is_nan() || side <= 0.0 || !m_max.is_finite() || m_max <= 0.0 {
        return 0.0;
    }
    let dm = (m.abs() - 1.0) / m_max;
    let a = delta.abs();
    if dm >= 1.0 {
        return if a >= 1.0 { 1.0 } else { 0.0 };
    }
    smoothstep((a - dm) / (1.0 - dm))
}

/// SMEAR Eq. 12 as a stylization function S_M(δ, m; m_max).
pub fn eq12_opacity(m_max: f32) -> impl Stylize + Copy {
    move |x: &StyleInput| multiple_opacity(x.delta, x.m, m_max)
}

/// The copies of one multiple index over the whole clip.
#[derive(Debug, Clone)]
pub struct MultipleCopy {
    /// The index m (negative = past).
    pub m: i32,
    /// Its displacement β_m = m·Δf at frame 0 (before the frame-step scaling; a keyframed
    /// Δf changes it per frame).
    pub beta: f32,
    /// The copy at every frame (same mesh and topology as the input).
    pub animation: MeshAnimation,
    /// Opacity α_{i,m}(f) ∈ [0, 1] per frame and vertex (frame-major), SMEAR Eq. 11.
    pub alpha: Vec<f32>,
}

fn clamp_alpha(a: f32) -> f32 {
    if a.is_finite() {
        a.clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Writes copy `m`'s positions and opacities of the drawing at frame `h`.
#[allow(clippy::too_many_arguments)]
fn fill(
    inputs: &EffectInputs<'_>,
    style: &dyn Stylize,
    h: usize,
    m: i32,
    beta: f32,
    (past, future): (usize, usize),
    pos: &mut [Vec3],
    alpha: &mut [f32],
) {
    let tr = inputs.trajectories();
    // A copy beyond this frame's (keyframed) counts stays in place, transparent.
    let shown = if m < 0 {
        m.unsigned_abs() as usize <= past
    } else {
        m as usize <= future
    };
    if !shown {
        let n = inputs.point_count();
        alpha.fill(0.0);
        pos.copy_from_slice(&inputs.positions()[h * n..(h + 1) * n]);
        return;
    }
    // S_M over runs of points (`Stylize::eval_block`), then each point's opacity.
    for (k, alpha) in alpha.chunks_mut(STYLE_BLOCK).enumerate() {
        let block = inputs
            .style_block(h, k * STYLE_BLOCK, alpha.len())
            .with_m(m as f32);
        style.eval_block(&block, alpha);
        alpha.iter_mut().for_each(|a| *a = clamp_alpha(*a));
    }
    // Every point moves by the same β: a point with a twin on the same arcs is its copy.
    let twins = inputs.twins();
    for i in 0..pos.len() {
        let t = twins.map_or(i, |t| t[i] as usize);
        pos[i] = if t < i && tr.same_arcs(i, t) {
            pos[t]
        } else {
            tr.displaced(h, i, beta)
        };
    }
}

/// The multiple in-betweens of one frame (for interactive scrubbing): copy `k` (in
/// [`MultiplesOptions::indices`] order) is written to `positions[k·n..(k+1)·n]` and its
/// opacities to `alpha[k·n..(k+1)·n]`, with `n` the point count.
///
/// Every vertex of copy m moves by the same β_m(f) = step · m·Δf (Section 4.2); its opacity is
/// `α_{i,m}(f) = S_M(x_i(f))` (SMEAR Eq. 11) with `x.m = m`, clamped to [0, 1] (non-finite → 0).
///
/// # Errors
/// [`SmearError::InvalidParameter`] for a bad spacing, step, frame or buffer length.
///
/// # Performance
/// Allocates only the list of indices; parallel over copies.
pub fn multiples_frame(
    inputs: &EffectInputs<'_>,
    style: &dyn Stylize,
    frame: usize,
    options: &MultiplesOptions,
    positions: &mut [Vec3],
    alpha: &mut [f32],
) -> Result<()> {
    let step = check_step(options.step)?;
    check_frame(frame, inputs.frame_count())?;
    let h = held_frame(frame, step);
    let df = options.spacing_at(h as f32)?;
    let counts = options.counts_at(h as f32);
    let n = inputs.point_count();
    let ms = options.indices();
    let want = ms.len() * n;
    if positions.len() != want || alpha.len() != want {
        return Err(SmearError::InvalidParameter {
            name: "output buffers",
            reason: format!(
                "expected {want} positions and opacities ({} copies × {n}), got {} and {}",
                ms.len(),
                positions.len(),
                alpha.len()
            ),
        });
    }
    if n == 0 {
        return Ok(());
    }
    positions
        .par_chunks_mut(n)
        .zip(alpha.par_chunks_mut(n))
        .zip(ms.par_iter())
        .for_each(|((p, a), &m)| {
            let beta = step as f32 * m as f32 * df;
            fill(inputs, style, h, m, beta, counts, p, a)
        });
    Ok(())
}

/// The multiple in-betweens of the whole clip: one [`MultipleCopy`] per index m ≠ 0 (past
/// first), each a full animation with per-frame vertex opacities, ready to be written next to
/// the original as alpha-blended flipbooks.
///
/// # Errors
/// As [`multiples_frame`], or when `inputs` are surface points (no mesh to copy).
///
/// # Performance
/// Parallel over frames; allocates only the outputs (copies × frames × vertices).
pub fn multiples(
    inputs: &EffectInputs<'_>,
    style: &dyn Stylize,
    options: &MultiplesOptions,
) -> Result<Vec<MultipleCopy>> {
    let step = check_step(options.step)?;
    let anim = inputs.animation()?;
    let (frames, n) = (inputs.frame_count(), inputs.point_count());
    // Δf and copy counts of every held drawing, checked once.
    let spacing = (0..frames)
        .map(|f| options.spacing_at(held_frame(f, step) as f32))
        .collect::<Result<Vec<f32>>>()?;
    let counts: Vec<(usize, usize)> = (0..frames)
        .map(|f| options.counts_at(held_frame(f, step) as f32))
        .collect();
    let df0 = options.spacing_at(0.0)?;
    options
        .indices()
        .into_iter()
        .map(|m| {
            let beta = m as f32 * df0;
            let mut pos = vec![Vec3::ZERO; frames * n];
            let mut alpha = vec![0.0f32; frames * n];
            if n > 0 {
                pos.par_chunks_mut(n)
                    .zip(alpha.par_chunks_mut(n))
                    .enumerate()
                    .for_each(|(f, (p, a))| {
                        fill(
                            inputs,
                            style,
                            held_frame(f, step),
                            m,
                            step as f32 * m as f32 * spacing[f],
                            counts[f],
                            p,
                            a,
                        )
                    });
            }
            let mut mesh = anim.mesh.clone();
            // `robot_past2`, `robot_future1`: readable, and valid USD/glTF names as they are.
            let side = if m < 0 { "past" } else { "future" };
            mesh.name = format!("{}_{side}{}", anim.mesh.name, m.unsigned_abs());
            let mut copy = MeshAnimation::new(mesh, anim.fps, pos)
                .map_err(|e| SmearError::InvalidScene(e.to_string()))?;
            copy.start_time = anim.start_time;
            Ok(MultipleCopy {
                m,
                beta,
                animation: copy,
                alpha,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::test_util::translating_ball;
    use crate::{mesh_offsets, OffsetOptions};

    #[test]
    fn fig10_overlap_two_gives_unit_spacing() {
        // Section 5.2 / Fig. 10 bottom: m_p = m_n = 1, N∩ = 2 → Δf = 1; Fig. 1: m_p = 2,
        // m_n = 1, N∩ = 1 → Δf = 1/3; Fig. 15: m_p = 4, m_n = 0, N∩ = 1 → Δf = 1/4.
        assert_eq!(overlap_spacing(1, 1, 2).unwrap(), 1.0);
        assert!((overlap_spacing(2, 1, 1).unwrap() - 1.0 / 3.0).abs() < 1e-7);
        assert_eq!(overlap_spacing(4, 0, 1).unwrap(), 0.25);
        assert!(overlap_spacing(1, 1, 3).is_err());
        assert!(overlap_spacing(0, 0, 1).is_err());
        let o = MultiplesOptions {
            past: 2.0.into(),
            future: 1.0.into(),
            ..Default::default()
        };
        assert_eq!(o.indices(), [-2, -1, 1]);
    }

    #[test]
    fn eq12_hides_leading_vertices_in_past_copies() {
        assert_eq!(multiple_opacity(0.8, -1.0, 1.0), 0.0);
        assert_eq!(multiple_opacity(-0.8, 1.0, 1.0), 0.0);
        assert_eq!(multiple_opacity(0.0, 1.0, 1.0), 0.0);
        // m = ±1: δ_m = 0 → S(|δ|).
        assert!((multiple_opacity(-0.5, -1.0, 2.0) - 0.5).abs() < 1e-6);
        assert_eq!(multiple_opacity(1.0, 1.0, 2.0), 1.0);
        // m = 2, m_max = 2: δ_m = 0.5, the gradient starts at |δ| = 0.5.
        assert_eq!(multiple_opacity(0.5, 2.0, 2.0), 0.0);
        assert!((multiple_opacity(0.75, 2.0, 2.0) - 0.5).abs() < 1e-6);
        // |m| > m_max: the limit step.
        assert_eq!(multiple_opacity(0.99, 2.0, 1.0), 0.0);
        assert_eq!(multiple_opacity(-1.0, -2.0, 1.0), 1.0);
        assert_eq!(multiple_opacity(f32::NAN, 1.0, 1.0), 0.0);
    }

    #[test]
    fn fig10_copies_sit_on_neighbour_frames() {
        let anim = translating_ball(7, 1.0);
        let delta = mesh_offsets(&anim, &OffsetOptions::default()).unwrap();
        let inputs = EffectInputs::new(&anim, &delta).unwrap();
        let opts = MultiplesOptions {
            past: 1.0.into(),
            future: 1.0.into(),
            spacing: Spacing::Overlap(2.0.into()),
            step: 1,
        };
        let copies = multiples(&inputs, &eq12_opacity(1.0), &opts).unwrap();
        assert_eq!(copies.iter().map(|c| c.m).collect::<Vec<_>>(), [-1, 1]);
        let names: Vec<&str> = copies
            .iter()
            .map(|c| c.animation.mesh.name.as_str())
            .collect();
        assert_eq!(names, ["ball_past1", "ball_future1"]);
        let f = 3;
        for c in &copies {
            let there = anim.frame((f as i32 + c.m) as usize);
            let err = c
                .animation
                .frame(f)
                .iter()
                .zip(there)
                .map(|(a, b)| (*a - *b).length())
                .fold(0.0f32, f32::max);
            assert!(err < 1e-5, "copy {} off by {err}", c.m);
            // Past copy: only trailing vertices (δ < 0) are visible, and the trailing pole
            // (δ = −1) is opaque.
            let n = anim.vertex_count();
            let (d, a) = (delta.frame(f), &c.alpha[f * n..(f + 1) * n]);
            let visible_wrong_side = d
                .iter()
                .zip(a)
                .filter(|(d, a)| **a > 0.0 && **d * c.m as f32 <= 0.0)
                .count();
            assert_eq!(visible_wrong_side, 0);
            let pole = d
                .iter()
                .enumerate()
                .max_by(|x, y| (x.1 * c.m as f32).total_cmp(&(y.1 * c.m as f32)))
                .unwrap()
                .0;
            assert!((a[pole] - 1.0).abs() < 1e-5);
        }
        // Per-frame entry point agrees.
        let n = anim.vertex_count();
        let (mut p, mut a) = (vec![Vec3::ZERO; 2 * n], vec![0.0; 2 * n]);
        multiples_frame(&inputs, &eq12_opacity(1.0), f, &opts, &mut p, &mut a).unwrap();
        assert_eq!(&p[n..], copies[1].animation.frame(f));
        assert_eq!(&a[..n], &copies[0].alpha[f * n..(f + 1) * n]);
    }

    #[test]
    fn keyframed_copy_counts_fade_copies_in_and_overlap_follows() {
        // Section 5.1: m_p keyed 0 → 2 over frames 0..4, N∩ = 1: the output holds two past
        // copies; at frame 0 both are transparent, at frame 2 one shows (Δf = 1/(1+1−1) = 1),
        // from frame 4 both (Δf = 1/(2+1−1) = 1/2).
        let anim = translating_ball(7, 1.0);
        let delta = mesh_offsets(&anim, &OffsetOptions::default()).unwrap();
        let inputs = EffectInputs::new(&anim, &delta).unwrap();
        let opts = MultiplesOptions {
            past: Param::Curve(vec![[0.0, 0.0], [4.0, 2.0]]),
            future: 0.0.into(),
            spacing: Spacing::Overlap(1.0.into()),
            step: 1,
        };
        assert_eq!(opts.indices(), [-2, -1]);
        assert_eq!(opts.spacing_at(0.0).unwrap(), 0.0);
        assert_eq!(opts.spacing_at(2.0).unwrap(), 1.0);
        assert_eq!(opts.spacing_at(5.0).unwrap(), 0.5);
        let copies = multiples(&inputs, &eq12_opacity(2.0), &opts).unwrap();
        let n = anim.vertex_count();
        let shown =
            |c: &MultipleCopy, f: usize| c.alpha[f * n..(f + 1) * n].iter().any(|a| *a > 0.0);
        let (far, near) = (&copies[0], &copies[1]);
        assert!(!shown(far, 0) && !shown(near, 0));
        assert!(!shown(far, 2) && shown(near, 2));
        assert!(shown(far, 5) && shown(near, 5));
        // The near copy sits Δf = 1 frame back at frame 2, 1/2 at frame 5 (1 unit per frame).
        let back = |f: usize| anim.frame(f)[0].x - near.animation.frame(f)[0].x;
        assert!((back(2) - 1.0).abs() < 1e-4 && (back(5) - 0.5).abs() < 1e-4);
        let none = MultiplesOptions {
            past: 0.0.into(),
            future: 0.0.into(),
            ..Default::default()
        };
        assert!(none.check().is_err());
        let too_many = MultiplesOptions {
            past: 1.0.into(),
            future: 1.0.into(),
            spacing: Spacing::Overlap(3.0.into()),
            step: 1,
        };
        let e = too_many.spacing_at(1.0).unwrap_err().to_string();
        assert!(e.contains("N∩") && e.contains("frame 1"), "{e}");
    }
}
