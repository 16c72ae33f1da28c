//! The scene-level job's report: what `loa animate --json` prints besides the output and the
//! total time.

use serde::Serialize;

use crate::animate::{Character, Motion, StageReport};
use crate::Line;

/// Measurements of a [`SceneMotion`](super::SceneMotion); distances in percent of the line's
/// length (the [`AnimateReport`](crate::animate::AnimateReport)'s fractions × 100).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SceneReport {
    /// Motion frames.
    pub frames: usize,
    /// Frames per second.
    pub fps: f64,
    /// Joints.
    pub joints: usize,
    /// The frames keystrokes are on.
    pub keystroke_frames: Vec<i64>,
    /// The line's warnings (reversed keystrokes).
    pub warnings: Vec<String>,
    /// Joints attached to another than their skeleton parent, `joint->parent`.
    pub attachments: Vec<String>,
    /// The planar stage's solve.
    pub planar: StageReport,
    /// The 3D stage's solve (contacts, twists).
    pub spatial: Option<StageReport>,
    /// Mean distance of the constrained points to the line.
    pub line_distance_mean_percent: f64,
    /// Its 95th percentile.
    pub line_distance_p95_percent: f64,
    /// The farthest point.
    pub line_distance_worst: WorstPercent,
    /// The joints measured.
    pub line_distance_joints: Vec<String>,
    /// Frames without a bone set (not measured).
    pub line_distance_unmeasured_frames: Vec<i64>,
    /// Largest joint rotation from one frame to the next.
    pub max_rotation_step_degrees: f64,
    /// Largest contact error, percent of the body's height.
    pub contact_error_max_percent: f64,
    /// Time of the solve.
    pub solve_seconds: f64,
}

/// The farthest constrained point from the line.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WorstPercent {
    /// Its distance, percent of the line's length.
    pub percent: f64,
    /// Its joint.
    pub joint: String,
    /// Its frame.
    pub frame: i64,
}

impl SceneReport {
    pub(super) fn new(character: &Character, line: &Line, motion: &Motion, solve: f64) -> Self {
        let rep = &motion.report;
        let names = character.joint_names();
        SceneReport {
            frames: motion.frames(),
            fps: motion.fps,
            joints: motion.joints,
            keystroke_frames: line.animation.keystroke_frames.clone(),
            warnings: line.warnings.clone(),
            attachments: character
                .attachments()
                .iter()
                .map(|&(j, p)| format!("{}->{}", names[j], names[p]))
                .collect(),
            planar: rep.planar,
            spatial: rep.spatial,
            line_distance_mean_percent: 100.0 * rep.line_distance_mean,
            line_distance_p95_percent: 100.0 * rep.line_distance_p95,
            line_distance_worst: WorstPercent {
                percent: 100.0 * rep.line_distance_worst.distance,
                joint: rep.line_distance_worst.joint.clone(),
                frame: rep.line_distance_worst.frame,
            },
            line_distance_joints: rep.measured_joints.clone(),
            line_distance_unmeasured_frames: rep.unmeasured_frames.clone(),
            max_rotation_step_degrees: rep.max_rotation_step.to_degrees(),
            contact_error_max_percent: 100.0 * rep.contact_error_max,
            solve_seconds: solve,
        }
    }
}
