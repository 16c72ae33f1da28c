//! The contract between the effects (Section 4) and the stylization functions (paper G3,
//! S_E / S_M / S_L): the inputs a function may read and the trait it implements.

use super::StyleBlock;

/// Everything a stylization function (paper G3, S_E / S_M / S_L) may read at one vertex or
/// motion-line sample. Unused inputs are 0.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StyleInput {
    /// Motion offset δ ∈ [−1, 1] (Section 3).
    pub delta: f32,
    /// Speed |v| in units per frame (central differences).
    pub speed: f32,
    /// Velocity vector (units per frame).
    pub velocity: glam::Vec3,
    /// Painted weight (vertex attribute / weight group), 1 when none.
    pub weight: f32,
    /// Position in the rest (first) frame, for noise.
    pub rest: glam::Vec3,
    /// Frame index (as f32; fractional for on-twos etc.).
    pub frame: f32,
    /// Multiple index m (negative = past copies, positive = future), 0 otherwise.
    pub m: f32,
    /// Position along a motion line t ∈ [0, 1] (0 at the surface), 0 otherwise.
    pub t: f32,
    /// Index of the vertex (or motion line) evaluated: where a user expression that is not
    /// finite is reported.
    pub vertex: u32,
}

/// A stylization function: maps the inputs at one vertex to a scalar (β for elongation,
/// opacity for multiples, τ / thickness / opacity for lines). Must be pure and thread-safe.
pub trait Stylize: Send + Sync {
    /// Evaluates the function at one vertex / sample.
    fn eval(&self, x: &StyleInput) -> f32;

    /// Evaluates the function at every point of a run, `out[k]` for [`StyleBlock::input`]`(k)`
    /// (`out.len()` = the run's length). Must give the values of [`Stylize::eval`] bit for
    /// bit; the default calls it point by point, a function that can work over the run's
    /// slices at once (the preset chains) overrides it.
    fn eval_block(&self, block: &StyleBlock<'_>, out: &mut [f32]) {
        for (k, o) in out.iter_mut().enumerate() {
            *o = self.eval(&block.input(k));
        }
    }
}

impl<F: Fn(&StyleInput) -> f32 + Send + Sync> Stylize for F {
    fn eval(&self, x: &StyleInput) -> f32 {
        self(x)
    }
}
