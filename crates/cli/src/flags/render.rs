//! The command-line flags of a preview, declared in the CLI beside the render crate's
//! [`PreviewOptions`]: frame, onion skins, colouring, view, size, supersampling and the
//! contact sheet of `toonkit render`.

use std::path::Path;

use clap::{Args, ValueEnum};

use ::render::{parse_size, ColorMap, OutputFormat, PreviewOptions, ViewSpec};

/// What the surface colour shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub(crate) enum ColorArg {
    /// The meshes' own vertex colours, or grey.
    #[default]
    None,
    /// Smear motion offsets (Basset et al. 2024, SMEAR Eqs. 1–9): red leads, blue trails.
    Offsets,
    /// Vertex speed (units per frame), normalized by its maximum over the clip.
    Speed,
}

/// The preview flags of `toonkit render`.
#[derive(Debug, Clone, Args)]
pub(crate) struct PreviewFlags {
    /// Frame of a PNG (0-based; default: the first).
    #[arg(long, value_name = "N")]
    pub(crate) frame: Option<usize>,
    /// Onion skin: ghosts of this many neighbouring frames on each side.
    #[arg(long, default_value_t = 0)]
    pub(crate) onion: usize,
    /// Surface colouring.
    #[arg(long, value_enum, default_value_t = ColorArg::None)]
    pub(crate) color: ColorArg,
    /// View: front, back, side, top, three-quarter (orthographic, fitted to the whole
    /// motion), follow or follow:DIRECTION (same scale, tracking a travelling subject) or camera:NAME
    /// (a scene camera).
    #[arg(long, default_value = "three-quarter")]
    pub(crate) view: String,
    /// Image size, WxH.
    #[arg(long, default_value = "400x400")]
    pub(crate) size: String,
    /// Supersampling per axis (1 = none, up to 4).
    #[arg(long, default_value_t = 2)]
    pub(crate) supersample: u32,
    /// Write a contact sheet (`.png`): frames 0, N, 2N, … on a grid, numbered.
    #[arg(long)]
    pub(crate) sheet: bool,
    /// Frame stride N of the contact sheet (default: about 16 cells).
    #[arg(long, requires = "sheet")]
    pub(crate) every: Option<usize>,
    /// Columns of the contact sheet (default: square-ish).
    #[arg(long, requires = "sheet", default_value_t = 0)]
    pub(crate) columns: usize,
}

/// The preview flags, checked before anything is read.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct CheckedPreview {
    /// PNG or GIF, from the output's extension.
    pub(crate) format: OutputFormat,
    /// Where the preview looks from.
    pub(crate) view: ViewSpec,
    /// Image width and height in pixels.
    pub(crate) size: (u32, u32),
}

impl PreviewFlags {
    /// Checks the flags and the `output` extension, before any input is read.
    ///
    /// # Errors
    /// One line naming the flag or the output: unknown extension, view or size, or a
    /// contact sheet that is not a `.png`.
    pub(crate) fn check(&self, output: &Path) -> Result<CheckedPreview, String> {
        let Some(format) = OutputFormat::from_extension(output) else {
            return Err(format!(
                "{}: unknown output extension (use {})",
                output.display(),
                OutputFormat::list()
            ));
        };
        let view = (self.view.parse()).map_err(|e| format!("--view {}: {e}", self.view))?;
        let Some(size) = parse_size(&self.size) else {
            return Err(format!(
                "--size {}: expected WIDTHxHEIGHT, e.g. 400x400",
                self.size
            ));
        };
        if self.sheet && format != OutputFormat::Png {
            return Err(format!(
                "{}: a contact sheet is written as .png",
                output.display()
            ));
        }
        Ok(CheckedPreview { format, view, size })
    }

    /// The preview options of a clip of `clip_frames` frames at `fps`, coloured by `scalar`.
    ///
    /// # Errors
    /// `--every 0`.
    pub(crate) fn options<'a>(
        &self,
        checked: CheckedPreview,
        clip_frames: usize,
        fps: f32,
        scalar: Option<(&'a [f32], ColorMap)>,
    ) -> Result<PreviewOptions<'a>, String> {
        let format = match (self.sheet, self.every) {
            (false, _) => checked.format,
            (true, Some(0)) => return Err("--every must be ≥ 1".into()),
            (true, every) => OutputFormat::Sheet {
                every: every.unwrap_or(clip_frames.div_ceil(16)),
                columns: self.columns,
            },
        };
        Ok(PreviewOptions {
            width: checked.size.0,
            height: checked.size.1,
            view: checked.view,
            frame: self.frame.unwrap_or(0),
            onion: self.onion,
            scalar,
            format,
            fps: Some(fps),
            supersample: self.supersample,
        })
    }
}
