//! Streaming smears (issue #22): push a frame, get its elongated in-between at once — for
//! games and real-time previews. Everything is causal: frame f's result reads frames ≤ f only.
//!
//! Per pushed frame: SMEAR Eq. 1 offsets with the centroid velocity differenced backward
//! (`c(f) − c(f−1)`), SMEAR Eq. 2 smoothing over the past half-window only
//! ([`causal_smoothing_weights`](crate::causal_smoothing_weights)), speeds by backward
//! differences, and SMEAR Eq. 10 along trajectories through the last frames kept, extrapolated
//! at constant velocity beyond the current frame (see [`Trajectories`]).
//!
//! Compared with the offline mode the smear lags: smoothed offsets trail the offline ones by
//! about N/3 frames, velocities by half a frame, and the future half of an elongation
//! (β > 0) is a straight extrapolation of the last motion, so it overshoots when the motion
//! stops or turns (an arm that stops still smears one frame past its stop).
//!
//! The stream treats the pushed points as one simple object (SMEAR Eq. 1, or the whole-body
//! mode of Fig. 14 for a skinned character); the per-bone offsets of SMEAR Eqs. 3–9 need the
//! skeleton and are offline only.

use anim::Mesh;
use glam::Vec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::plane::plane_frames;
use crate::{
    causal_smoothing_weights, Collider, FunctionSpec, Result, SmearError, SpeedUnits,
    StyleFunction, StyleInput, StyleUnits, Stylize, Trajectories, DEFAULT_SMOOTH,
    DEFAULT_STILL_TOLERANCE, STILL_ROUNDING_FACTOR,
};

/// Default number of past frames a [`Stream`] keeps for its trajectories.
pub const DEFAULT_STREAM_HISTORY: usize = 6;

/// Vertices per parallel task.
const CHUNK: usize = 1024;

/// Options of a [`Stream`] (deserializes with every field optional).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StreamOptions {
    /// Half-window N of SMEAR Eq. 2 (past half only).
    pub smooth: usize,
    /// S_E of SMEAR Eq. 10: β in frames (default S_E(δ; 1) = δ).
    pub elongate: FunctionSpec,
    /// Past frames kept: β below −(history − 1) clamps to the oldest kept frame.
    pub history: usize,
    /// A ground plane `y = ground` (a length in `speed_units`) the result never goes below
    /// (collider meshes: [`Stream::add_collider`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ground: Option<f32>,
    /// What `elongate`'s speeds and lengths and `ground` are measured in, as in a style
    /// (`docs/smear-units.md`): by default the character's size (speeds in sizes per second
    /// at `fps`, lengths in sizes); `scene` keeps scene units per frame.
    #[serde(skip_serializing_if = "SpeedUnits::is_size")]
    pub speed_units: SpeedUnits,
    /// One size unit in scene units (> 0). Without it: the bounding-box diagonal of the first
    /// pushed frame — the stream's rest pose, as for arrays without a rest.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub size_reference: Option<f32>,
    /// Frames per second of the pushed frames (size speeds are per second).
    pub fps: f32,
}

impl Default for StreamOptions {
    fn default() -> Self {
        StreamOptions {
            smooth: DEFAULT_SMOOTH,
            elongate: FunctionSpec::linear(1.0),
            history: DEFAULT_STREAM_HISTORY,
            ground: None,
            speed_units: SpeedUnits::Size,
            size_reference: None,
            fps: anim::DEFAULT_FPS,
        }
    }
}

/// A streaming smear: [`Stream::push`] one frame's positions, get its elongated in-between.
///
/// ```
/// use anim::Mesh;
/// use glam::Vec3;
/// use smear::{Stream, StreamOptions};
///
/// let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
/// let mesh = Mesh::new("tet", p.clone(), vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]);
/// let mut stream = Stream::new(&mesh, &StreamOptions::default())?;
/// for f in 0..5 {
///     let frame: Vec<Vec3> = p.iter().map(|q| *q + Vec3::X * f as f32).collect();
///     let out = stream.push(&frame)?;
///     if f == 4 {
///         assert!(out[1].x > 5.0 - 1e-3); // the leading vertex reaches ahead
///     }
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct Stream {
    triangles: Vec<[u32; 3]>,
    n: usize,
    /// The elongation as given, compiled in the stream's units at the first push.
    spec: FunctionSpec,
    units: StreamUnits,
    function: StyleFunction,
    weights: Vec<f32>,
    ground: Option<f32>,
    /// Meshes the result never enters; pushed frame f meets their frame f.
    colliders: Vec<Collider>,
    /// The last `kept` frames, oldest first, frame-major (capacity `history` frames).
    positions: Vec<Vec3>,
    kept: usize,
    history: usize,
    /// Raw offsets of the last N + 1 frames, oldest first.
    raw: Vec<f32>,
    /// Raw offsets of the last two frames (SMEAR Eq. 1 scratch, reused every push).
    pair_raw: Vec<f32>,
    /// Smoothed offsets of the current frame.
    delta: Vec<f32>,
    rest: Vec<Vec3>,
    out: Vec<Vec3>,
    pushed: usize,
    still: Option<f32>,
}

impl Stream {
    /// A stream for `mesh`'s topology (its positions are not used).
    ///
    /// # Errors
    /// A style function that does not compile; `history` below 2.
    pub fn new(mesh: &Mesh, options: &StreamOptions) -> Result<Stream> {
        let units = StreamUnits::new(options)?;
        let function = options
            .elongate
            .compile()
            .map_err(|e| SmearError::InvalidParameter {
                name: "elongate",
                reason: e.to_string(),
            })?;
        crate::options::check_smooth(options.smooth)?;
        if options.history < 2 {
            return Err(SmearError::InvalidParameter {
                name: "history",
                reason: format!("keep at least 2 frames, got {}", options.history),
            });
        }
        let n = mesh.vertex_count();
        Ok(Stream {
            triangles: mesh.triangles.clone(),
            n,
            spec: options.elongate.clone(),
            units,
            function,
            weights: causal_smoothing_weights(options.smooth),
            ground: options.ground.filter(|g| g.is_finite()),
            colliders: Vec::new(),
            positions: Vec::with_capacity(options.history * n),
            kept: 0,
            history: options.history,
            raw: Vec::with_capacity((options.smooth + 1) * n),
            pair_raw: vec![0.0; 2 * n],
            delta: vec![0.0; n],
            rest: Vec::new(),
            out: vec![Vec3::ZERO; n],
            pushed: 0,
            still: None,
        })
    }

    /// Adds a mesh the results never enter (issue #22, as
    /// [`Prepared::add_collider`](crate::Prepared::add_collider) offline): a displacement
    /// stops where its trajectory enters it and what is inside is pushed out. The `f`-th
    /// pushed frame (from 0) meets the collider's frame f (its last frame after its end).
    pub fn add_collider(&mut self, collider: Collider) {
        self.colliders.push(collider);
    }

    /// Frames pushed so far.
    pub fn frames_pushed(&self) -> usize {
        self.pushed
    }

    /// Smoothed motion offsets of the last pushed frame.
    pub fn offsets(&self) -> &[f32] {
        &self.delta
    }

    /// Pushes the positions of the next frame and returns its elongated in-between.
    ///
    /// # Errors
    /// [`SmearError::InvalidParameter`] when `positions` does not have one point per vertex;
    /// [`SmearError::Style`] ([`crate::StyleError::NotFinite`]) when the elongation expression
    /// was NaN or infinite at a vertex of this frame (the frame is pushed all the same).
    ///
    /// # Performance
    /// O(vertices × (history + N)) memory moves, SMEAR Eq. 1 on two frames, and one S_E
    /// evaluation and Catmull-Rom point per vertex (parallel over vertices).
    pub fn push(&mut self, positions: &[Vec3]) -> Result<&[Vec3]> {
        let n = self.n;
        if positions.len() != n {
            return Err(SmearError::InvalidParameter {
                name: "positions",
                reason: format!("expected {n} points, got {}", positions.len()),
            });
        }
        if self.pushed == 0 {
            self.rest = positions.to_vec();
            self.still = Some(still_tolerance(positions));
            self.start(positions)?;
        }
        if self.kept == self.history {
            self.positions.copy_within(n.., 0);
            self.positions.truncate((self.kept - 1) * n);
            self.kept -= 1;
        }
        self.positions.extend_from_slice(positions);
        self.kept += 1;
        let now = self.kept - 1;
        // SMEAR Eq. 1 on the last two frames, differenced backward.
        let tol = self.still.expect("set on the first push");
        self.pair_raw.fill(0.0);
        if now > 0 {
            let pair = &self.positions[(now - 1) * n..(now + 1) * n];
            plane_frames(
                pair,
                2,
                n,
                &self.triangles,
                tol,
                true,
                None,
                &mut self.pair_raw,
            );
        }
        let taps = self.weights.len();
        if self.raw.len() == taps * n {
            self.raw.copy_within(n.., 0);
            self.raw.truncate((taps - 1) * n);
        }
        self.raw.extend_from_slice(&self.pair_raw[n..]);
        // SMEAR Eq. 2, past half: frames before the first clamp to it.
        let have = self.raw.len() / n.max(1);
        for (i, d) in self.delta.iter_mut().enumerate() {
            let mut acc = 0.0f32;
            for (k, w) in self.weights.iter().enumerate() {
                let back = taps - 1 - k;
                let row = have.saturating_sub(1 + back);
                acc += w * self.raw[row * n + i];
            }
            *d = acc;
        }
        let tr = Trajectories::new(&self.positions, self.kept, n)?
            .shaped(true, self.ground, None)
            .with_colliders(&self.colliders)
            .with_collider_frames_from(self.pushed - now);
        let (delta, rest, frame) = (&self.delta, &self.rest, self.pushed as f32);
        let function = &self.function;
        let current = &self.positions[now * n..];
        let previous = &self.positions[now.saturating_sub(1) * n..];
        self.out
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(c, dst)| {
                for (k, o) in dst.iter_mut().enumerate() {
                    let i = c * CHUNK + k;
                    let velocity = if now == 0 {
                        Vec3::ZERO
                    } else {
                        current[i] - previous[i]
                    };
                    let x = StyleInput {
                        delta: delta[i],
                        speed: velocity.length(),
                        velocity,
                        weight: 1.0,
                        rest: rest[i],
                        frame,
                        m: 0.0,
                        t: 0.0,
                        vertex: i as u32,
                    };
                    *o = tr.displaced(now, i, function.eval(&x));
                }
            });
        self.pushed += 1;
        // The frame is pushed (the stream stays usable); an expression that was NaN or
        // infinite at some vertex is reported with the frame and the vertex.
        self.function.check_finite("vertex")?;
        Ok(&self.out)
    }

    /// The first frame fixes the size unit: the elongation and the ground are compiled into
    /// scene units once (`docs/smear-units.md`).
    fn start(&mut self, first: &[Vec3]) -> Result<()> {
        let Some(units) = self.units.resolve(first) else {
            return Ok(());
        };
        self.function =
            self.spec
                .compile_in(&units, 1.0)
                .map_err(|e| SmearError::InvalidParameter {
                    name: "elongate",
                    reason: e.to_string(),
                })?;
        self.ground = self.ground.map(|g| units.length_to_scene(g));
        Ok(())
    }
}

/// A stream's units before its first frame: scene units, or sizes per second at `fps` with
/// the size given or to be measured on the first frame.
#[derive(Debug, Clone, Copy)]
enum StreamUnits {
    Scene,
    Size { size: Option<f32>, fps: f32 },
}

impl StreamUnits {
    fn new(options: &StreamOptions) -> Result<StreamUnits> {
        if options.speed_units == SpeedUnits::Scene {
            return Ok(StreamUnits::Scene);
        }
        if !(options.fps.is_finite() && options.fps > 0.0) {
            return Err(SmearError::InvalidParameter {
                name: "fps",
                reason: format!("give a frame rate > 0, got {}", options.fps),
            });
        }
        if let Some(s) = options.size_reference {
            if !(s.is_finite() && s > 0.0) {
                return Err(SmearError::InvalidParameter {
                    name: "size_reference",
                    reason: format!("a size reference length must be > 0, got {s}"),
                });
            }
        }
        Ok(StreamUnits::Size {
            size: options.size_reference,
            fps: options.fps,
        })
    }

    /// The conversion for a stream whose first frame is `first`; `None` in scene units.
    fn resolve(&self, first: &[Vec3]) -> Option<StyleUnits> {
        match *self {
            StreamUnits::Scene => None,
            StreamUnits::Size { size, fps } => {
                let size = size.unwrap_or_else(|| anim::Aabb::from_points(first).diagonal());
                Some(StyleUnits::size(size as f64, fps as f64))
            }
        }
    }
}

/// The still threshold of the solver (SPEC.md) for a stream, from its first frame.
fn still_tolerance(p: &[Vec3]) -> f32 {
    let b = anim::Aabb::from_points(p);
    let scale = if b.is_empty() {
        0.0
    } else {
        b.min.abs().max(b.max.abs()).max_element()
    };
    (DEFAULT_STILL_TOLERANCE * b.diagonal()).max(STILL_ROUNDING_FACTOR * scale)
}
