//! The command-line flags of the loa jobs, declared in the CLI beside the loa crate's
//! options they fill: [`LineFlags`] → [`LineOptions`] (`loa line` and `loa animate`) and
//! [`MotionFlags`] → [`AnimateOptions`] (`loa animate`).

use clap::{Args, ValueEnum};
use glam::DVec3;

use ::loa::animate::{AnimateOptions, ContactKey, InitialPose};
use ::loa::{Keystrokes, LineOptions};

use super::FlagError;

/// `result`, its error named by the flag and value `at`.
fn at<T, E: std::error::Error + Send + Sync + 'static>(
    result: Result<T, E>,
    at: impl FnOnce() -> String,
) -> Result<T, FlagError> {
    result.map_err(|e| FlagError::At {
        at: at(),
        source: Box::new(e),
    })
}

/// Interpolation mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub(crate) enum ModeArg {
    /// Elastic chain simulation re-targeted onto every keystroke (anticipation, follow-through).
    #[default]
    Physics,
    /// Hermite splines of angles, lengths and root (geometric in-betweens).
    Hermite,
}

/// Line options shared by `loa line` and `loa animate`.
#[derive(Debug, Clone, Args)]
pub(crate) struct LineFlags {
    /// Interpolation mode.
    #[arg(long, value_enum, default_value_t = ModeArg::Physics)]
    pub(crate) mode: ModeArg,
    /// Frames per second (default: the keystrokes', else 24).
    #[arg(long, value_name = "FPS", allow_negative_numbers = true)]
    pub(crate) fps: Option<f32>,
    /// Integration sub-steps per frame.
    #[arg(long, default_value_t = loa::DEFAULT_SUBSTEPS)]
    pub(crate) substeps: u32,
    /// Frames simulated from each keystroke (`M`), or `gap` for the frame gap between keys.
    #[arg(long, default_value = "40")]
    pub(crate) simulated_frames: String,
    /// Rigid elements per chain (even).
    #[arg(long, default_value_t = loa::DEFAULT_ELEMENTS)]
    pub(crate) elements: usize,
    /// Follow-through after the last keystroke, ending on it at rest: a frame count (0 = end
    /// on the last keystroke), or `key` for one key interval (the last one).
    #[arg(long, default_value = "key")]
    pub(crate) settle: String,
    /// Drag-to-wobble `FRAME:S:DX,DY`: hit the line at frame FRAME, at arc-length position
    /// S (0..1), with impulse DX,DY (screen units per second). Repeatable.
    #[arg(long = "wobble", allow_hyphen_values = true)]
    pub(crate) wobbles: Vec<String>,
    /// Stroke smoothing before the fit: Gaussian σ as a fraction of the stroke's length
    /// (0 = fit the raw samples).
    #[arg(long, default_value_t = loa::DEFAULT_STROKE_SMOOTHING)]
    pub(crate) smoothing: f64,
}

impl LineFlags {
    /// The library options for keystrokes `keys`.
    ///
    /// # Errors
    /// A bad `--simulated-frames`, `--settle` or `--wobble`.
    pub(crate) fn options(&self, keys: &Keystrokes) -> Result<LineOptions, FlagError> {
        let simulated_frames = match self.simulated_frames.trim() {
            "gap" => loa::SimulatedFrames::FrameGap,
            m => loa::SimulatedFrames::Fixed(at(m.parse(), || {
                format!("--simulated-frames {m}: expected a frame count or \"gap\"")
            })?),
        };
        let settle = match self.settle.trim() {
            "key" => loa::Settle::KeyInterval,
            s => loa::Settle::Frames(at(s.parse(), || {
                format!("--settle {s}: expected a frame count or \"key\"")
            })?),
        };
        let wobbles = self
            .wobbles
            .iter()
            .map(|w| at(w.parse(), || format!("--wobble {w}")))
            .collect::<Result<_, _>>()?;
        Ok(LineOptions {
            mode: match self.mode {
                ModeArg::Physics => loa::Mode::Physics,
                ModeArg::Hermite => loa::Mode::Hermite,
            },
            elements: self.elements,
            physics: loa::PhysicsOptions {
                fps: self
                    .fps
                    .map(f64::from)
                    .or(keys.fps())
                    .unwrap_or(loa::DEFAULT_FPS),
                substeps: self.substeps,
                simulated_frames,
                settle,
                ..Default::default()
            },
            smoothing: self.smoothing,
            wobbles,
            ..Default::default()
        })
    }
}

/// The motion options of `loa animate`: bone sets, action plane, contacts, twists, the
/// initial pose and the solver's iteration cap.
#[derive(Debug, Clone, Args)]
pub(crate) struct MotionFlags {
    /// Bone set at a keystroke frame: a preset found by joint names (right-leg-spine-head,
    /// left-leg-spine-head, arm-spine, left-arm-spine, arms, legs, full-body, and for a raised
    /// arm right-leg-spine-arm, left-leg-spine-arm), one found from the hierarchy for any
    /// names (foot-head, spine-head) or comma-separated joint names, then `@FRAME`. Repeat for
    /// changing sets.
    #[arg(long = "bones")]
    pub(crate) bones: Vec<String>,
    /// Action-plane normal `x,y,z` (default: the view direction).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) plane_normal: Option<String>,
    /// Contact: `JOINT@FRAME` (hold where it is), `JOINT@FRAME:x,y,z`, or `JOINT@A..B`.
    #[arg(long = "contact")]
    pub(crate) contacts: Vec<String>,
    /// Twist: `JOINT@FRAME:DEGREES` about the bone's own axis.
    #[arg(long = "twist", allow_hyphen_values = true)]
    pub(crate) twists: Vec<String>,
    /// Initial pose: `rest`, or `CLIP@FRAME` (a frame of one of the file's clips).
    #[arg(long, default_value = "rest")]
    pub(crate) pose: String,
    /// Cap on solver iterations per stage.
    #[arg(long, default_value_t = loa::animate::DEFAULT_MAX_ITERATIONS)]
    pub(crate) iterations: usize,
}

impl MotionFlags {
    /// The library options (no camera: that needs the character's scene).
    ///
    /// # Errors
    /// A bad `--bones`, `--contact`, `--twist` or `--plane-normal`.
    pub(crate) fn options(&self) -> Result<AnimateOptions, FlagError> {
        let bone_sets = self
            .bones
            .iter()
            .map(|b| at(b.parse(), || format!("--bones {b}")))
            .collect::<Result<_, _>>()?;
        let mut contacts = Vec::new();
        for c in &self.contacts {
            contacts.extend(at(ContactKey::parse_all(c), || format!("--contact {c}"))?);
        }
        let twists = self
            .twists
            .iter()
            .map(|t| at(t.parse(), || format!("--twist {t}")))
            .collect::<Result<_, _>>()?;
        Ok(AnimateOptions {
            bone_sets,
            contacts,
            twists,
            plane_normal: self.plane_normal.as_deref().map(parse_vec3).transpose()?,
            max_iterations: self.iterations,
            ..Default::default()
        })
    }

    /// `--pose`.
    ///
    /// # Errors
    /// Neither `rest` nor `CLIP@FRAME`.
    pub(crate) fn pose(&self) -> Result<InitialPose, FlagError> {
        at(self.pose.parse(), || format!("--pose {}", self.pose))
    }
}

fn parse_vec3(s: &str) -> Result<DVec3, FlagError> {
    let v: Vec<f64> = at(
        s.split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<_, _>>(),
        || format!("--plane-normal {s}: expected x,y,z"),
    )?;
    if v.len() != 3 {
        return Err(FlagError::Flag(format!(
            "--plane-normal {s}: expected three numbers x,y,z"
        )));
    }
    Ok(DVec3::new(v[0], v[1], v[2]))
}
