//! An animated line of action and its stable JSON layout (SPEC "Output layouts").

use serde::Serialize;

use crate::Chain;

/// The line at one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimationFrame {
    /// Frame number.
    pub frame: i64,
    /// The chain at that frame.
    pub chain: Chain,
}

/// A dynamic line of action `x_dloa(s, t)`: one chain per integer frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Animation {
    /// Frames per second.
    pub fps: f64,
    /// Frames of the keystrokes.
    pub keystroke_frames: Vec<i64>,
    /// Consecutive frames from the first keystroke to the last (inclusive), plus any settle
    /// or wobble frames after it.
    pub frames: Vec<AnimationFrame>,
}

#[derive(Serialize)]
struct JsonAnimation<'a> {
    fps: f64,
    keystroke_frames: &'a [i64],
    frames: Vec<JsonFrame<'a>>,
}

#[derive(Serialize)]
struct JsonFrame<'a> {
    frame: i64,
    points: Vec<[f64; 2]>,
    angles: &'a [f64],
    lengths: &'a [f64],
}

impl Animation {
    /// Bundles frames.
    pub fn new(fps: f64, keystroke_frames: Vec<i64>, frames: Vec<AnimationFrame>) -> Self {
        Self {
            fps,
            keystroke_frames,
            frames,
        }
    }

    /// The chain at `frame`, if the animation covers it.
    pub fn chain_at(&self, frame: i64) -> Option<&Chain> {
        let first = self.frames.first()?.frame;
        let i = usize::try_from(frame.checked_sub(first)?).ok()?;
        self.frames
            .get(i)
            .filter(|f| f.frame == frame)
            .map(|f| &f.chain)
    }

    /// The stable JSON layout:
    /// `{"fps": f, "keystroke_frames": [...], "frames": [{"frame": k, "points": [[x, y], ...],
    /// "angles": [...], "lengths": [...]}]}` — `points` are the `N + 1` joint positions in the
    /// keystrokes' screen coordinates, `angles` the local angles in joint order (radians; see
    /// [`Chain`]), `lengths` the element lengths.
    pub fn to_json_string(&self) -> String {
        let json = JsonAnimation {
            fps: self.fps,
            keystroke_frames: &self.keystroke_frames,
            frames: self
                .frames
                .iter()
                .map(|f| JsonFrame {
                    frame: f.frame,
                    points: f.chain.joints().iter().map(|p| [p.x, p.y]).collect(),
                    angles: f.chain.angles(),
                    lengths: f.chain.lengths(),
                })
                .collect(),
        };
        // Serializing plain numbers and vectors cannot fail; non-finite values become null.
        serde_json::to_string(&json).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }
}
