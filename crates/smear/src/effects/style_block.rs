//! A run of points of one frame as a stylization function reads it in bulk
//! ([`Stylize::eval_block`](super::Stylize::eval_block)): the offsets and painted weights as
//! the slices they are stored in, the speeds computed for the run only when a function asks
//! for them. Evaluating stage by stage over a run instead of point by point lets the effects
//! skip what a style does not read (a linear S_E reads δ alone) and keeps the loops free of
//! per-point dispatch (docs/studio.md, "Whole clips").

use glam::Vec3;

use super::{EffectInputs, StyleInput};

/// The most points of one [`StyleBlock`] the effects hand to a stylization function at once:
/// their values and speeds fit in a few KiB of stack, and a run is long enough that what is
/// looked up once per run (the style's keyframed parameters, the velocity's frames) costs
/// nothing per point.
pub const STYLE_BLOCK: usize = 256;

/// Points `start..start + len` of frame `frame` of an [`EffectInputs`], with the multiple index
/// `m` every point of the run shares (the points are vertices: line position `t` 0).
/// [`StyleBlock::input`] is the [`StyleInput`] of one point, exactly as
/// [`EffectInputs::style_input`] builds it.
#[derive(Debug, Clone, Copy)]
pub struct StyleBlock<'a> {
    inputs: &'a EffectInputs<'a>,
    frame: usize,
    start: usize,
    len: usize,
    m: f32,
}

impl<'a> StyleBlock<'a> {
    /// The run `start..start + len` of frame `frame` (`m` 0). Panics when the run is
    /// outside the inputs' points or `frame` outside their frames.
    pub(crate) fn new(
        inputs: &'a EffectInputs<'a>,
        frame: usize,
        start: usize,
        len: usize,
    ) -> Self {
        assert!(
            frame < inputs.frame_count() && start + len <= inputs.point_count(),
            "style block {start}..{} of frame {frame} outside {} points × {} frames",
            start + len,
            inputs.point_count(),
            inputs.frame_count()
        );
        StyleBlock {
            inputs,
            frame,
            start,
            len,
            m: 0.0,
        }
    }

    /// Points `from..from + len` of this run as a run of their own (the same `m`).
    /// Panics when they are not inside this run.
    pub fn part(&self, from: usize, len: usize) -> Self {
        assert!(
            from + len <= self.len,
            "part {from}..{} of a run of {}",
            from + len,
            self.len
        );
        StyleBlock {
            start: self.start + from,
            len,
            ..*self
        }
    }

    /// The same run with multiple index `m` (SMEAR Eq. 12).
    pub fn with_m(self, m: f32) -> Self {
        StyleBlock { m, ..self }
    }

    /// Number of points of the run.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the run has no point.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The frame, as [`StyleInput::frame`] holds it.
    pub fn frame(&self) -> f32 {
        self.frame as f32
    }

    /// The multiple index every point of the run shares.
    pub fn m(&self) -> f32 {
        self.m
    }

    /// The motion offsets δ of the run.
    pub fn deltas(&self) -> &'a [f32] {
        let k = self.frame * self.inputs.point_count() + self.start;
        &self.inputs.offsets().values()[k..k + self.len]
    }

    /// The painted weights of the run, `None` when there are none (every weight 1).
    pub fn weights(&self) -> Option<&'a [f32]> {
        self.inputs
            .weights()
            .map(|w| &w[self.start..self.start + self.len])
    }

    /// The rest positions of the run (frame 0, as noise reads them).
    pub fn rest(&self) -> &'a [Vec3] {
        &self.inputs.positions()[self.start..self.start + self.len]
    }

    /// Writes the speeds of the run into `out` (`out.len()` = [`StyleBlock::len`]): those of
    /// [`EffectInputs::style_input`], bit for bit.
    pub fn speeds(&self, out: &mut [f32]) {
        assert_eq!(out.len(), self.len, "one speed per point of the run");
        self.inputs.run_speeds(self.frame, self.start, out);
    }

    /// The stylization inputs of point `k` of the run (`k < len`).
    pub fn input(&self, k: usize) -> StyleInput {
        debug_assert!(k < self.len);
        StyleInput {
            m: self.m,
            ..self.inputs.style_input(self.frame, self.start + k)
        }
    }
}

#[cfg(test)]
mod tests {
    use anim::MeshAnimation;
    use glam::{Mat4, Quat, Vec3};

    use super::*;
    use crate::effects::test_util::{ball, camera};
    use crate::velocity::CameraSpace;
    use crate::{FunctionSpec, MotionOffsets, Param, Stage, Stylize};

    /// A ball of 1,162 vertices turning faster and faster about Y while it drifts along X:
    /// every vertex has its own speed, some vertices none at the first frame.
    fn spinning_ball(frames: usize) -> MeshAnimation {
        let mesh = ball(1.0, 30, 40);
        let pos = (0..frames)
            .flat_map(|f| {
                let turn = Quat::from_rotation_y(0.02 * (f * f) as f32);
                let shift = Vec3::X * (0.3 * f as f32);
                let p = mesh.positions.clone();
                p.into_iter().map(move |q| turn * q + shift)
            })
            .collect();
        MeshAnimation::new(mesh, 24.0, pos).unwrap()
    }

    /// Offsets in [−1, 1] with zeros (a past-only chain's untouched values) and ±1.
    fn offsets(frames: usize, n: usize) -> MotionOffsets {
        let values = (0..frames * n)
            .map(|k| match k % 11 {
                0 => 0.0,
                1 => 1.0,
                2 => -1.0,
                _ => ((k as f32) * 0.618).sin(),
            })
            .collect();
        MotionOffsets::new(frames, n, values).unwrap()
    }

    /// Every kind of stage, keyframed parameters among them, and an expression.
    fn functions() -> Vec<FunctionSpec> {
        let curve = Param::Curve(vec![[0.0, 0.5], [6.0, 3.0]]);
        let mut noise = FunctionSpec::noise(9.0, curve.clone());
        noise.stages.insert(0, Stage::Weight);
        vec![
            FunctionSpec::linear(2.5),
            FunctionSpec::speed(curve.clone()),
            noise,
            FunctionSpec::multiples(2.0),
            FunctionSpec::stages(vec![
                Stage::Warp {
                    s: 0.5.into(),
                    p: curve_in(0.2, 0.8),
                },
                Stage::Future,
                Stage::Threshold {
                    min_speed: 0.4.into(),
                },
                Stage::Scale { by: 1e30.into() },
                Stage::Scale { by: 1e30.into() },
            ]),
            FunctionSpec::stages(vec![
                Stage::Past,
                Stage::Speed,
                Stage::Fade,
                Stage::Multiples { m_max: curve },
            ]),
            FunctionSpec::stages(vec![Stage::Set { value: 0.25.into() }, Stage::Speed]),
            FunctionSpec::expr("b * speed * delta + m", &[("b", 3.0.into())]),
        ]
    }

    fn curve_in(from: f32, to: f32) -> Param {
        Param::Curve(vec![[0.0, from], [6.0, to]])
    }

    #[test]
    fn runs_give_the_values_of_each_point() {
        // Whatever the run (across STYLE_BLOCK boundaries, short, empty) and wherever the
        // velocities come from, a run's values are those of its points one by one, bit for bit.
        let anim = spinning_ball(7);
        let n = anim.vertex_count();
        let delta = offsets(7, n);
        let weights: Vec<f32> = (0..n).map(|i| (i % 5) as f32 / 4.0).collect();
        let buffered = EffectInputs::new(&anim, &delta)
            .unwrap()
            .with_weights(weights.clone())
            .unwrap();
        let prepared =
            EffectInputs::from_prepared(&anim, &delta, (None, false), Some(weights.clone()));
        let unweighted = EffectInputs::new(&anim, &delta).unwrap();
        // A camera turning and dollying: velocities in its space, read past-only too.
        let camera = camera(
            (0..7)
                .map(|f| {
                    Mat4::from_rotation_translation(
                        Quat::from_rotation_z(0.1 * f as f32),
                        Vec3::new(0.5 * f as f32, 0.0, 3.0),
                    )
                })
                .collect(),
        );
        let space = CameraSpace::new(&camera, 7);
        let filmed = EffectInputs::from_prepared(&anim, &delta, (Some(&space), true), None);
        let causal = EffectInputs::new(&anim, &delta).unwrap().with_causal(true);
        let mut compared = 0;
        for inputs in [&buffered, &prepared, &unweighted, &filmed, &causal] {
            for spec in functions() {
                let function = spec.compile().unwrap();
                for f in [0, 3, 6] {
                    for (start, len, m) in
                        [(0, n, -1.0), (100, 600, 2.0), (n - 3, 3, 1.0), (5, 0, 0.0)]
                    {
                        let block = inputs.style_block(f, start, len).with_m(m);
                        let mut out = vec![f32::NAN; len];
                        function.eval_block(&block, &mut out);
                        for (k, v) in out.iter().enumerate() {
                            let x = StyleInput {
                                m,
                                ..inputs.style_input(f, start + k)
                            };
                            assert_eq!(x, block.input(k));
                            let one = function.eval(&x);
                            assert_eq!(
                                v.to_bits(),
                                one.to_bits(),
                                "{spec:?} frame {f} point {}",
                                start + k
                            );
                            compared += 1;
                        }
                    }
                }
            }
        }
        assert!(compared > 100_000, "{compared}");
    }
}
