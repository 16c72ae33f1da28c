//! Per-frame targets of the matching: which chain points and bones are constrained at each
//! frame (Ω(t) = Ω(t_k) ∩ Ω(t_k+1) between keys), where on the moving line they go (by arc
//! length), and the 3D twist and contact targets.

use glam::{DQuat, DVec2, DVec3};

use super::bones::{Chain3, ChainPoint};
use super::camera::{ActionCamera, ScreenMap};
use super::rig::{Rig, WorldPose};
use super::terms::{exp, point_position};
use crate::Animation;

/// A chain point pulled toward the line (E_x).
#[derive(Debug, Clone, Copy)]
pub(crate) struct PointTarget {
    pub point: ChainPoint,
    pub target: DVec2,
    /// Quadrature weight of the point in E_loa's integral over `s` (its share of the
    /// constrained arc length; mean 1 over a frame's points).
    pub weight: f64,
}

/// A rigid segment whose projected direction follows the line's tangent (E_∂).
#[derive(Debug, Clone, Copy)]
pub(crate) struct SegmentTarget {
    pub a: ChainPoint,
    pub b: ChainPoint,
    /// Unit tangent of the line between the two points' arc lengths.
    pub tangent: DVec2,
    /// 1 / the segment's image length in the initial pose (invariant under the planar
    /// stage's rotations about the view axis, so a foreshortened bone can still match the
    /// tangent exactly).
    pub inv_length: f64,
    /// Quadrature weight of the segment in E_loa's integral over `s` (its share of the
    /// constrained arc length; mean 1 over a frame's segments).
    pub weight: f64,
}

/// A world orientation target of a joint (twist cans, contact orientations).
#[derive(Debug, Clone, Copy)]
pub(crate) struct OrientTarget {
    pub joint: usize,
    pub rotation: DQuat,
}

/// A contact: position and orientation of a joint.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ContactTarget {
    pub joint: usize,
    pub position: DVec3,
    pub rotation: DQuat,
}

/// Everything constraining one frame.
#[derive(Debug, Clone, Default)]
pub(crate) struct FrameTargets {
    pub points: Vec<PointTarget>,
    pub segments: Vec<SegmentTarget>,
    /// Bones in Ω(t) (the joint rotating each constrained segment), for LoA Eq. 3.
    pub bones: Vec<usize>,
    pub twists: Vec<OrientTarget>,
    pub contacts: Vec<ContactTarget>,
    /// Line length in image units (for reporting distances relative to it).
    pub line_length: f64,
}

/// The line at one frame in image coordinates, with cumulative arc lengths.
#[derive(Debug, Clone)]
pub(crate) struct ImageLine {
    pub points: Vec<DVec2>,
    cumulative: Vec<f64>,
}

impl ImageLine {
    pub(super) fn new(points: Vec<DVec2>) -> ImageLine {
        let mut cumulative = Vec::with_capacity(points.len());
        let mut s = 0.0;
        for (i, p) in points.iter().enumerate() {
            if i > 0 {
                s += (*p - points[i - 1]).length();
            }
            cumulative.push(s);
        }
        ImageLine { points, cumulative }
    }

    pub(super) fn length(&self) -> f64 {
        self.cumulative.last().copied().unwrap_or(0.0)
    }

    /// The point at normalized arc length `u ∈ [0, 1]`.
    pub(super) fn at(&self, u: f64) -> DVec2 {
        let total = self.length();
        if self.points.is_empty() {
            return DVec2::ZERO;
        }
        if total <= 0.0 {
            return self.points[0];
        }
        let s = u.clamp(0.0, 1.0) * total;
        let k = self
            .cumulative
            .partition_point(|&c| c <= s)
            .clamp(1, self.points.len() - 1);
        let (s0, s1) = (self.cumulative[k - 1], self.cumulative[k]);
        let t = if s1 > s0 { (s - s0) / (s1 - s0) } else { 0.0 };
        self.points[k - 1].lerp(self.points[k], t)
    }
}

/// The line of every frame mapped onto the image plane.
pub(crate) fn image_lines(line: &Animation, map: &ScreenMap) -> Vec<ImageLine> {
    line.frames
        .iter()
        .map(|f| ImageLine::new(f.chain.joints().into_iter().map(|p| map.map(p)).collect()))
        .collect()
}

/// A resolved chain with its points' normalized arc lengths, measured in the image of the
/// initial pose: the planar stage turns bones about the view axis, which keeps their image
/// lengths, so the chain can only ever cover the line with its image lengths (a bone leaning
/// toward the camera, or a short bone doubling back like RobotExpressive's `Body → Hips`,
/// counts for what it shows).
#[derive(Debug, Clone)]
pub(crate) struct KeyChain {
    pub points: Vec<ChainPoint>,
    pub u: Vec<f64>,
    /// Points with a position term (all but the lower end of a branch connector).
    pub matched: Vec<bool>,
    /// Segments that are branch connectors (see [`KeyChain::new`]).
    pub connector: Vec<bool>,
    pub seg_length: Vec<f64>,
    /// The joint rotating segment `i` (points `i`, `i + 1`).
    pub seg_bone: Vec<usize>,
    pub length: f64,
}

impl KeyChain {
    pub(super) fn new(rig: &Rig, w: &WorldPose, camera: &ActionCamera, chain: &Chain3) -> KeyChain {
        let points = chain.points();
        let pos: Vec<DVec2> = points
            .iter()
            .map(|&p| camera.project(point_position(rig, w, p)))
            .collect();
        let seg_length: Vec<f64> = pos.windows(2).map(|s| (s[1] - s[0]).length()).collect();
        // The branch connector: where the path turns from going up the tree to going down
        // (a pelvis or shoulder girdle), the segment climbing into the turn joint is a
        // sideways jog that no line can follow. It gets no arc length, no tangent term, and
        // its lower end no position term.
        let parent_of = |a: ChainPoint, b: ChainPoint| match (a, b) {
            (ChainPoint::Joint(a), ChainPoint::Joint(b)) => rig.parent[b] == Some(a),
            _ => false,
        };
        let mut connector = vec![false; seg_length.len()];
        for i in 1..points.len().saturating_sub(1) {
            if parent_of(points[i], points[i - 1]) && parent_of(points[i], points[i + 1]) {
                connector[i - 1] = true;
            }
        }
        let mut matched = vec![true; points.len()];
        for (i, c) in connector.iter().enumerate() {
            if *c {
                matched[i] = false;
            }
        }
        let arc = |i: usize| if connector[i] { 0.0 } else { seg_length[i] };
        let length: f64 = (0..seg_length.len()).map(arc).sum();
        let mut u = Vec::with_capacity(points.len());
        let mut s = 0.0;
        u.push(0.0);
        for i in 0..seg_length.len() {
            s += arc(i);
            u.push(if length > 0.0 { s / length } else { 0.0 });
        }
        let seg_bone = points
            .windows(2)
            .map(|s| match (s[0], s[1]) {
                (_, ChainPoint::Tip(j)) | (ChainPoint::Tip(j), _) => j,
                (ChainPoint::Joint(a), ChainPoint::Joint(b)) => {
                    if rig.parent[b] == Some(a) {
                        a
                    } else {
                        b
                    }
                }
            })
            .collect();
        KeyChain {
            points,
            u,
            matched,
            connector,
            seg_length,
            seg_bone,
            length,
        }
    }

    fn index(&self, p: ChainPoint) -> Option<usize> {
        self.points.iter().position(|&x| x == p)
    }
}

/// Ω(t) and the line targets of frame `f` (index from the first keystroke), given the key
/// chains (one per keystroke) and the keystroke frame offsets.
pub(crate) fn line_targets(
    keys: &[KeyChain],
    key_offsets: &[usize],
    f: usize,
    line: &ImageLine,
    out: &mut FrameTargets,
) {
    out.points.clear();
    out.segments.clear();
    out.bones.clear();
    out.line_length = line.length();
    // Interval [k, k + 1] containing f; at a keystroke, its own set.
    let k = key_offsets.partition_point(|&o| o <= f).saturating_sub(1);
    let at_key = key_offsets.get(k) == Some(&f) || k + 1 >= keys.len();
    let (a, b, alpha) = if at_key {
        (&keys[k], &keys[k], 0.0)
    } else {
        let (o0, o1) = (key_offsets[k], key_offsets[k + 1]);
        (
            &keys[k],
            &keys[k + 1],
            (f - o0) as f64 / (o1 - o0).max(1) as f64,
        )
    };
    let u_of = |i: usize| -> Option<f64> {
        let p = a.points[i];
        let j = b.index(p)?;
        Some(a.u[i] * (1.0 - alpha) + b.u[j] * alpha)
    };
    let matched = |i: usize| a.matched[i] && b.index(a.points[i]).is_some_and(|j| b.matched[j]);
    for i in 0..a.points.len() {
        if !matched(i) {
            continue;
        }
        if let Some(u) = u_of(i) {
            out.points.push(PointTarget {
                point: a.points[i],
                target: line.at(u),
                weight: u,
            });
        }
    }
    quadrature(out.points.iter_mut().map(|p| &mut p.weight), true);
    for i in 0..a.points.len().saturating_sub(1) {
        let (p, q) = (a.points[i], a.points[i + 1]);
        // The segment must be consecutive in both chains.
        let consecutive = match (b.index(p), b.index(q)) {
            (Some(x), Some(y)) => x.abs_diff(y) == 1,
            _ => false,
        };
        // A segment ending on a branch connector's lower end (a hip joint beside the
        // pelvis) hangs off the line by the connector's width: only its points are matched.
        if !consecutive
            || a.seg_length[i] <= 1e-6 * a.length
            || a.connector[i]
            || !matched(i)
            || !matched(i + 1)
        {
            continue;
        }
        let (Some(u0), Some(u1)) = (u_of(i), u_of(i + 1)) else {
            continue;
        };
        let chord = line.at(u1) - line.at(u0);
        let Some(tangent) = chord.try_normalize() else {
            continue;
        };
        out.segments.push(SegmentTarget {
            a: p,
            b: q,
            tangent,
            inv_length: 1.0 / a.seg_length[i],
            weight: (u1 - u0).abs(),
        });
        if !out.bones.contains(&a.seg_bone[i]) {
            out.bones.push(a.seg_bone[i]);
        }
    }
    quadrature(out.segments.iter_mut().map(|g| &mut g.weight), false);
}

/// Turns arc-length positions (`points`: the points' `u`, in chain order) or spans (segments)
/// into quadrature weights of E_loa's integral over `s` (LoA §4): a point gets half the arc
/// to each neighbour (trapezoid rule), a segment its own span; scaled to mean 1 so the
/// weights `w_x`, `w_∂` keep their per-point meaning. Degenerate spans (all zero) give 1.
fn quadrature<'a>(values: impl Iterator<Item = &'a mut f64>, points: bool) {
    let mut v: Vec<&mut f64> = values.collect();
    let n = v.len();
    if n == 0 {
        return;
    }
    let w: Vec<f64> = if points {
        let u: Vec<f64> = v.iter().map(|x| **x).collect();
        (0..n)
            .map(|i| {
                let lo = if i > 0 { u[i - 1] } else { u[i] };
                let hi = if i + 1 < n { u[i + 1] } else { u[i] };
                0.5 * (hi - lo).abs()
            })
            .collect()
    } else {
        v.iter().map(|x| **x).collect()
    };
    let total: f64 = w.iter().sum();
    for (x, wi) in v.iter_mut().zip(&w) {
        **x = if total > 0.0 {
            wi * n as f64 / total
        } else {
            1.0
        };
    }
}

/// Direction of a joint's bone (towards its children's average, or its tip), unit.
pub(crate) fn bone_direction(rig: &Rig, w: &WorldPose, j: usize) -> DVec3 {
    let kids = &rig.children[j];
    let tip = if kids.is_empty() {
        w.tip(rig, j)
    } else {
        kids.iter().map(|&c| w.position[c]).sum::<DVec3>() / kids.len() as f64
    };
    (tip - w.position[j])
        .try_normalize()
        .unwrap_or_else(|| w.rotation[j] * DVec3::Y)
}

/// Twist "can" target: the stage-1 orientation turned by `angle` about the bone's own axis.
pub(crate) fn twist_target(rig: &Rig, w: &WorldPose, j: usize, angle: f64) -> DQuat {
    exp(bone_direction(rig, w, j) * angle) * w.rotation[j]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadrature_weights_are_arc_shares_with_mean_one() {
        // Points at u = 0, 0.1, 0.5, 1: trapezoid shares 0.05, 0.25, 0.45, 0.25.
        let mut u = [0.0, 0.1, 0.5, 1.0];
        quadrature(u.iter_mut(), true);
        for (w, e) in u.iter().zip([0.2, 1.0, 1.8, 1.0]) {
            assert!((w - e).abs() < 1e-12, "{u:?}");
        }
        // Segments spanning 0.1 and 0.3 of the arc.
        let mut s = [0.1, 0.3];
        quadrature(s.iter_mut(), false);
        assert!(
            (s[0] - 0.5).abs() < 1e-12 && (s[1] - 1.5).abs() < 1e-12,
            "{s:?}"
        );
    }
}
