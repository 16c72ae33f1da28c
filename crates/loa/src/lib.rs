//! Dynamic lines of action from sketched keystrokes — Guay, Ronfard, Gleicher, Cani,
//! "Adding dynamics to sketch-based character animations", SBIM 2015 (LoA).
//!
//! Two whole jobs, each one call on in-memory data with a serde options struct:
//!
//! * [`line()`] — keystrokes ([`Keystrokes`], from JSON or SVG text) → the dynamic line
//!   ([`Line`]: one chain per frame, fitted keys, re-targeting report). Options:
//!   [`LineOptions`].
//! * [`animate()`] — a [`Character`](animate::Character) (skeleton + initial pose, e.g.
//!   [`Character::from_scene`](animate::Character::from_scene)) and a [`Line`] → the 3D motion
//!   ([`Motion`](animate::Motion), with its [`AnimateReport`](animate::AnimateReport)).
//!   Options: [`AnimateOptions`](animate::AnimateOptions). [`Motion::to_scene`](animate::Motion::to_scene)
//!   puts the motion back into the character's scene for writing.
//!
//! * [`job`] — the scene-level job every front end calls: a character scene and keystrokes
//!   → line → motion → the character holding the motion, saved as `.glb`/`.bvh` through
//!   `tkio` ([`job::animate_scene`], options [`job::SceneOptions`]).
//!
//! The crate computes on in-memory data; only [`job`] reads and writes files, through `tkio`.
//!
//! # Paper map
//!
//! | paper | item |
//! |---|---|
//! | §3.1, LoA Eq. 1 (chain fit) | [`fit_chain`], [`fit_keystrokes`], [`FitResidual`] |
//! | §3.1 end (geometric in-betweens) | [`interpolate_hermite`], [`HermiteLine`] |
//! | §3.2 elastic chain | [`ElasticChain`], [`simulate`] |
//! | §3.2, LoA Eq. 2 (closest simulated frame `t*`) | [`closest_frame`], [`Retarget`], [`interpolate_physics`] |
//! | §5 drag-to-wobble | [`wobble()`], [`Wobble`] |
//! | §4, LoA Eq. 3 (E_ẋ smoothness) + E_x, E_∂ (shape matching) | [`animate::animate`], [`animate::Weights`] |
//! | §4 dynamic bone sets Ω(t) = Ω(t_k) ∩ Ω(t_k+1) | [`animate::BoneSetKey`], [`animate::BoneSet`] |
//! | §4 motion reduction (2N − 1 Hermite nodes) | [`animate::Reduction`] |
//! | §4.1 E_twist, E_⊥ (contacts) | [`animate::TwistKey`], [`animate::ContactKey`] |
//!
//! # Parameters
//!
//! The keystrokes stay at the frames the animator put them on; the parameters shape the
//! motion between them (`docs/loa-timing.md`, which also says why they hold on any
//! keystrokes):
//!
//! * **stiffness** `k` (1/s², per keystroke, range [`STIFFNESS_RANGE`] 5–100): how soon the
//!   line reaches the next pose and how fast it swings in the settle (both scale with `√k`:
//!   the elastic chain's natural frequency along the key-to-key change). Strictly earlier
//!   arrival and a strictly higher settle frequency for every larger `k`.
//! * **damping** `ζ` (per keystroke, range [`DAMPING_RANGE`] 0.05–0.5): how far the line
//!   swings past the next pose before landing on it (the dominant mode's overshoot
//!   `exp(−πζ/√(1−ζ²))`, less where the interval is too short to take a large swing back) and
//!   how soon the swings die out. Strictly less overshoot for every larger `ζ`.
//! * Both hold on 256 seeded random keystroke sequences (`tests/monotone.rs`); whip.json's
//!   overshoot at ζ = 0.05 / 0.1 / 0.25 / 0.5 and k = 100 is 0.270 / 0.269 / 0.235 / 0.074
//!   of the change.
//! * Values outside the ranges are rejected ([`LoaError::OutOfRange`], naming the range).
//! * **settle** ([`PhysicsOptions::settle`], default one key interval): follow-through frames
//!   after the last keystroke, ending on it at rest. A keystroke repeated at a later frame is a moving hold.
//! * No setting in those ranges moves any chain point more than 15 % of the line's length in
//!   one frame (the approach is capped at [`MAX_FRAME_MOTION`] and the shape scaled down as
//!   needed): worst 12.5 % on the random sequences, 14.0 % on `jump.json`, whose own
//!   keystrokes are that far apart.
//!
//! # SPEC decisions (where toonkit departs from or adds to the paper)
//!
//! * **Timing** (LoA §3.2, LoA Eq. 2): the paper re-times the simulated frames `0..=t*` onto the
//!   whole keyframe interval; what the animator sees then depends on which simulated frame
//!   LoA Eq. 2 picks, and neither slider is monotone. toonkit splits each interval's angles
//!   into the *progress* along the key-to-key change — the elastic chain reduced to that one
//!   degree of freedom (Rayleigh–Ritz), a damped oscillator released toward the next pose and
//!   landed on it by a window — and the *shape*: the paper's simulation on the same time
//!   scale with its component along the change removed (anticipation, overlap,
//!   follow-through) and LoA Eq. 2's correction blended in. The root and lengths follow
//!   their Hermite curves in real time. It reports LoA Eq. 2's `t*` and, per interval, the
//!   arrival, overshoot, damping used and time scale ([`Retarget`]). Details and the argument
//!   for monotonicity: `docs/loa-timing.md`.
//! * **Settle and holds**: frames after the last keystroke are the dominant mode's free
//!   response to the velocity the line arrived with, faded out by a smoothstep window (ending
//!   at rest on the last keystroke); a repeated keystroke is simulated like any other
//!   interval, so the line swings through it.
//! * **Strokes** (LoA §3.1, "spatially smooth stroke"): smoothed with a Gaussian along the arc
//!   (σ = 2 % of the stroke's length by default, [`Stroke::smoothed`]); each keystroke is
//!   oriented like the previous one and a reversed one is reported ([`Line::warnings`]).
//! * **Screen map** (LoA §4): one scale for all keystrokes (least squares over the keystrokes'
//!   lengths against their bone sets' lengths), not the first keystroke's alone.
//! * **Matching a chain to the line** (LoA §4, E_loa): arc lengths along a bone set are
//!   measured in the image of the initial pose (what the planar stage can show: a bone
//!   leaning toward the camera, or RobotExpressive's short `Body → Hips` bone doubling back,
//!   covers only its image length), the screen scale is fitted to those lengths, and E_x and
//!   E_∂ are quadratures of the paper's integrals over `s` (each point and segment weighted by
//!   its share of the arc, so a short bone weighs little). A segment hanging from a branch
//!   connector's lower end (the thigh below the hip joint beside the pelvis) has no E_∂: it
//!   cannot be parallel to the line while its leg is on it. E_∂ weighs 0.05 by default
//!   ([`animate::DEFAULT_TANGENT_WEIGHT`]; at 0.5 the tangents outweighed the positions and
//!   RobotExpressive's legs hung 12 % of the line beside it).
//! * **Planar stage** (LoA §4): a continuation — a first solve holds the pelvis and chest
//!   (turn joints carrying a sideways branch) at their initial orientation (the root
//!   translates), a second frees them from that solution, so the pelvis tilts and the whole
//!   body leans with the line ([`animate::AnimateOptions::hold_pelvis`] stops after the
//!   first). The solver iterates until an accepted step gains less than
//!   [`animate::DEFAULT_TOLERANCE`] (cap [`animate::DEFAULT_MAX_ITERATIONS`]); the first,
//!   staging solve stops at the looser [`animate::STAGING_TOLERANCE`], since the second
//!   refines its solution anyway (on the bench: 33 iterations in all instead of 97, for a
//!   final energy 0.02 % lower).
//! * **Contacts** (LoA §4.1, E_⊥): the paper adds E_⊥ to one 3D solve over the whole clip;
//!   here the 3D stage solves twice — without contacts (the *free* motion, with any twists)
//!   and, from it, with every contact held on its keyed frames only (a held limb gets LoA
//!   Eq. 3's smoothness of constrained bones) — and the motion is the held one on held
//!   frames, the free one elsewhere, and around each run of held frames a blend in rotation
//!   space: the held pose's difference from the free one (per joint a rotation, plus the
//!   root offset) fades in before the run and out after it along a smoothstep, over
//!   [`animate::DEFAULT_CONTACT_RELEASE`]..=[`animate::MAX_CONTACT_RELEASE`] frames so that
//!   no joint turns more than [`animate::CONTACT_RELEASE_MAX_TURN`] per frame (or than the
//!   free motion itself). A contact the line pulls out of reach (`FootL@0..10` under
//!   `jump.json`, whose body rises 1.5 leg lengths by frame 10) thus lets go over about 20
//!   frames with joint steps ≤ 11.8° (it snapped by 42° per frame when the release was a
//!   moving target inside the solve), at the cost of the body lagging the line during the
//!   blend (6.3 % mean distance over the clip against 2.7 % without the contact). The 3D
//!   stage's pull toward the planar solution is its own weight
//!   ([`animate::Weights::spatial_regularization`]).
//! * **Cameras**: a scene camera may be perspective ([`animate::ActionCamera::from_scene`]);
//!   E_∂ then uses the projection's derivative at each segment's midpoint.
//!
//! # Example
//!
//! ```
//! use loa::animate::{AnimateOptions, Character};
//! use loa::{Keystrokes, LineOptions, Mode};
//!
//! let keys = Keystrokes::from_json_str(r#"{"keystrokes": [
//!     {"frame": 0,  "points": [[0, 0], [50, -30], [100, 0]]},
//!     {"frame": 24, "points": [[0, 0], [50, 30], [100, 0]], "damping": 0.2}
//! ]}"#)?;
//! let line = loa::line(&keys, &LineOptions::default())?;
//! // Frames 0..=24, then the default settle: one key interval (24 frames) ending at rest.
//! assert_eq!(line.animation.frames.len(), 25 + 24);
//! // The line lands on the second keystroke exactly.
//! let last = line.animation.chain_at(24).unwrap().joints();
//! let key = line.keys[1].chain.joints();
//! assert!(last.iter().zip(&key).all(|(a, b)| (*a - *b).length() < 1e-9));
//!
//! let hermite = loa::line(&keys, &LineOptions { mode: Mode::Hermite, ..Default::default() })?;
//! assert!(hermite.retargets.is_empty());
//!
//! // A 4-joint spine standing up along +Y follows the line (options as a JSON file would
//! // give them).
//! let joint = |name: &str, parent, y| anim::Joint {
//!     name: name.into(),
//!     parent,
//!     bind_local: anim::Transform::from_translation(glam::Vec3::new(0.0, y, 0.0)),
//! };
//! let skeleton = anim::Skeleton { joints: vec![
//!     joint("hips", None, 0.0), joint("spine", Some(0), 1.0),
//!     joint("chest", Some(1), 1.0), joint("head", Some(2), 1.0),
//! ] };
//! let character = Character::rest(&skeleton)?;
//! let options: AnimateOptions =
//!     serde_json::from_str(r#"{"bone_sets": [{"frame": 0, "set": "hips,head"}]}"#)?;
//! let motion = loa::animate(&character, &hermite, &options)?;
//! assert_eq!(motion.frames(), 25 + 24);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![warn(missing_docs, unreachable_pub)]

pub mod animate;
mod animation;
mod chain;
mod dynamics;
mod error;
mod fit;
mod hermite;
pub mod job;
mod keypose;
mod keystroke;
mod linalg;
mod line;
mod mode;
mod onion;
mod physics;
pub mod preview;
mod progress;
mod retarget;
mod stroke;
pub mod svg;
mod timing;
mod wobble;

pub use animation::{Animation, AnimationFrame};
pub use chain::Chain;
pub use dynamics::ElasticChain;
pub use error::{LoaError, StrokeError};
pub use fit::{fit_chain, ChainFit, FitResidual, DEFAULT_ELEMENTS};
pub use hermite::{interpolate_hermite, HermiteLine, HermiteTrack};
pub use keypose::{fit_keystrokes, KeyPose};
pub use keystroke::{
    Keystroke, Keystrokes, DAMPING_RANGE, DEFAULT_DAMPING, DEFAULT_FPS, DEFAULT_STIFFNESS,
    MAX_FRAME_SPAN, MIN_RELATIVE_STROKE_LENGTH, STIFFNESS_RANGE,
};
pub use onion::{to_svg_string, DEFAULT_SVG_WIDTH};
pub use physics::{
    simulate, PhysicsAnimation, PhysicsOptions, Retarget, Settle, SimulatedFrames, Simulation,
    DEFAULT_SIMULATED_FRAMES, DEFAULT_SUBSTEPS, MAX_SIMULATED_STEPS,
};
pub use progress::MAX_FRAME_MOTION;
pub use retarget::{closest_frame, Blend};
pub use stroke::{Stroke, DEFAULT_STROKE_SMOOTHING, SMOOTHING_SAMPLES};
pub use timing::interpolate_physics;
pub use wobble::{wobble, Wobble, MAX_SETTLE_SECONDS, SETTLE_TOLERANCE};

pub use line::{line, Line, LineOptions, Mode};

/// Synthesizes the 3D character motion that follows `line` (LoA Section 4 and 4.1): the
/// whole job of `loa animate`, with the bone sets, contacts and twists in `options`. See
/// [`animate::animate`] for the details.
///
/// # Errors
/// Unknown joints or presets, keys outside the line's frames, a zero plane normal.
pub fn animate(
    character: &animate::Character,
    line: &Line,
    options: &animate::AnimateOptions,
) -> Result<animate::Motion, animate::AnimateError> {
    animate::animate(character, &line.animation, &[], &[], &[], options)
}
