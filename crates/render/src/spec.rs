//! Views, sizes and output formats from their names, as a user types them (`three-quarter`,
//! `follow:side`, `camera:Cam`, `400x400`, `out.gif`).

use std::path::Path;
use std::str::FromStr;

use crate::{OutputFormat, ViewDirection, ViewSpec};

impl FromStr for ViewDirection {
    type Err = String;

    /// `front`, `back`, `side`, `top` or `three-quarter` (`3/4`).
    fn from_str(d: &str) -> Result<ViewDirection, String> {
        Ok(match d {
            "front" => ViewDirection::Front,
            "back" => ViewDirection::Back,
            "side" => ViewDirection::Side,
            "top" => ViewDirection::Top,
            "three-quarter" | "3/4" => ViewDirection::ThreeQuarter,
            _ => return Err(VIEW_NAMES.into()),
        })
    }
}

/// What [`ViewSpec::from_str`] accepts.
const VIEW_NAMES: &str =
    "expected front, back, side, top, three-quarter, follow[:DIRECTION] or camera:NAME";

impl FromStr for ViewSpec {
    type Err = String;

    /// A direction, `follow[:DIRECTION]` or `camera:NAME`.
    fn from_str(s: &str) -> Result<ViewSpec, String> {
        if let Some(name) = s.strip_prefix("camera:") {
            return Ok(ViewSpec::Camera(name.to_string()));
        }
        match s.strip_prefix("follow") {
            Some("") => Ok(ViewSpec::Follow(ViewDirection::ThreeQuarter)),
            Some(rest) if rest.starts_with(':') => Ok(ViewSpec::Follow(rest[1..].parse()?)),
            _ => Ok(ViewSpec::Direction(s.parse()?)),
        }
    }
}

/// An image size `WIDTHxHEIGHT` (both > 0), e.g. `400x400`.
pub fn parse_size(s: &str) -> Option<(u32, u32)> {
    let (w, h) = s.split_once(['x', 'X'])?;
    let (w, h) = (w.trim().parse().ok()?, h.trim().parse().ok()?);
    (w > 0 && h > 0).then_some((w, h))
}

impl OutputFormat {
    /// The extensions of image outputs ([`OutputFormat::from_extension`]), in the order
    /// messages list them.
    pub const EXTENSIONS: [&'static str; 2] = ["png", "gif"];

    /// The image extensions as a message lists them: ".png or .gif".
    pub fn list() -> String {
        let dotted: Vec<String> = Self::EXTENSIONS.iter().map(|e| format!(".{e}")).collect();
        dotted.join(" or ")
    }

    /// The format of a `.png` or `.gif` file (any case).
    pub fn from_extension(path: &Path) -> Option<OutputFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "png" => Some(OutputFormat::Png),
            "gif" => Some(OutputFormat::Gif),
            _ => None,
        }
    }

    /// Frames an image of this format shows of a clip of `clip_frames` frames.
    pub fn frames(self, clip_frames: usize) -> usize {
        match self {
            OutputFormat::Png => 1,
            OutputFormat::Gif => clip_frames,
            OutputFormat::Sheet { every, .. } => clip_frames.div_ceil(every.max(1)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_views_sizes_and_formats() {
        assert_eq!(parse_size("320x200"), Some((320, 200)));
        assert!(parse_size("0x10").is_none());
        assert!(parse_size("big").is_none());
        let view = |s: &str| s.parse::<ViewSpec>();
        assert_eq!(view("camera:Cam"), Ok(ViewSpec::Camera("Cam".into())));
        assert_eq!(view("top"), Ok(ViewSpec::Direction(ViewDirection::Top)));
        assert!(view("diagonal").is_err());
        assert_eq!(
            view("follow"),
            Ok(ViewSpec::Follow(ViewDirection::ThreeQuarter))
        );
        assert_eq!(
            view("follow:side"),
            Ok(ViewSpec::Follow(ViewDirection::Side))
        );
        assert!(view("follow:up").is_err());
        assert!(view("followme").is_err());
        assert!(OutputFormat::from_extension(Path::new("a.jpg")).is_none());
        assert_eq!(
            OutputFormat::from_extension(Path::new("a.GIF")),
            Some(OutputFormat::Gif)
        );
        let sheet = OutputFormat::Sheet {
            every: 4,
            columns: 0,
        };
        assert_eq!(sheet.frames(10), 3);
    }
}
