//! Manifests and the command line of each output.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::BatchError;

/// A manifest: the shots to make.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// The shots, in order.
    #[serde(rename = "shot", default)]
    pub shots: Vec<Shot>,
}

/// One shot of a manifest.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Shot {
    /// Unique name: stamp file name and OpenJD task value.
    pub name: String,
    /// The toonkit command words (`convert`, `smear elongate`, …).
    pub tool: String,
    /// Input file, relative to the manifest's folder.
    pub input: PathBuf,
    /// Clip to sample (`--clip`).
    #[serde(default)]
    pub clip: Option<String>,
    /// Style file (`--style`), relative to the manifest's folder.
    #[serde(default)]
    pub style: Option<PathBuf>,
    /// More options, `--name value` each (`true`: bare flag, `false`: left out, arrays
    /// comma-joined).
    #[serde(default)]
    pub options: BTreeMap<String, toml::Value>,
    /// Output files, relative to OUT; the command runs once per output.
    pub outputs: Vec<PathBuf>,
}

/// How a tool takes its output file (the front end knows its commands).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToolOutput {
    /// No such tool.
    Unknown,
    /// The tool writes no output file.
    NoOutput,
    /// `toonkit TOOL IN OUT`.
    Positional,
    /// `toonkit TOOL IN -o OUT`.
    Option,
}

#[cfg(feature = "clap")]
impl ToolOutput {
    /// How the command `words` (subcommand names under `root`) takes its output file, read
    /// from the parser itself: an argument with id `output`, positional or not. `root` must be
    /// built ([`clap::Command::build`]) when its subcommands define their flags lazily.
    pub fn of(root: &clap::Command, words: &[&str]) -> ToolOutput {
        let mut command = root;
        for w in words {
            match command.find_subcommand(w) {
                Some(c) => command = c,
                None => return ToolOutput::Unknown,
            }
        }
        let output = command.get_arguments().find(|a| a.get_id() == "output");
        match output.map(|a| a.is_positional()) {
            Some(true) => ToolOutput::Positional,
            Some(false) => ToolOutput::Option,
            None => ToolOutput::NoOutput,
        }
    }
}

/// Reads and checks a manifest (unique, file-safe names; outputs listed).
///
/// # Errors
/// [`BatchError::Read`] when the file cannot be read, [`BatchError::Invalid`] naming it
/// otherwise.
pub fn read_manifest(path: &Path) -> Result<Manifest, BatchError> {
    let text = std::fs::read_to_string(path).map_err(|source| BatchError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    Manifest::parse(&text, path)
}

/// The folder relative paths of a manifest start from.
pub fn manifest_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

impl Manifest {
    /// Parses and checks manifest text (errors name the file `manifest`).
    ///
    /// # Errors
    /// [`BatchError::Invalid`].
    pub fn from_toml_str(text: &str) -> Result<Manifest, BatchError> {
        Manifest::parse(text, Path::new("manifest"))
    }

    fn parse(text: &str, path: &Path) -> Result<Manifest, BatchError> {
        let bad = |m: String| BatchError::invalid(path, m);
        let manifest: Manifest = toml::from_str(text).map_err(|e| {
            let msg = e.to_string().replace('\n', " ");
            bad(format!("invalid manifest: {}", msg.trim()))
        })?;
        if manifest.shots.is_empty() {
            return Err(bad("the manifest lists no [[shot]]".into()));
        }
        let mut seen = BTreeSet::new();
        for s in &manifest.shots {
            let ok = !s.name.is_empty()
                && s.name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || "_.-".contains(c))
                && !s.name.starts_with('.');
            if !ok {
                return Err(bad(format!(
                    "shot name '{}' must be letters, digits, '_', '.', '-'",
                    s.name
                )));
            }
            if !seen.insert(&s.name) {
                return Err(bad(format!("shot '{}' is listed twice", s.name)));
            }
            if s.outputs.is_empty() {
                return Err(bad(format!("shot '{}' lists no outputs", s.name)));
            }
            if let Some(o) = s.outputs.iter().find(|o| !inside_output_folder(o)) {
                return Err(bad(format!(
                    "shot '{}': output {} must stay inside the output folder: name it relative to \
                     OUT, without .. or a leading /",
                    s.name,
                    o.display()
                )));
            }
            if s.tool.split_whitespace().next() == Some("batch") {
                return Err(bad(format!("shot '{}' cannot run a batch", s.name)));
            }
        }
        Ok(manifest)
    }
}

impl Shot {
    /// The `toonkit` argument vector (program name first) making `output` of the shot;
    /// `base` is the manifest's folder, `tool` says how a command (its words) takes its
    /// output.
    ///
    /// # Errors
    /// [`BatchError::Invalid`] for an unknown tool or one that writes no file.
    pub fn command_line(
        &self,
        base: &Path,
        output: &Path,
        tool: impl Fn(&[&str]) -> ToolOutput,
    ) -> Result<Vec<String>, BatchError> {
        let words: Vec<&str> = self.tool.split_whitespace().collect();
        let shot = |m: String| BatchError::invalid(Path::new(&format!("shot '{}'", self.name)), m);
        let positional_output = match tool(&words) {
            ToolOutput::Unknown => return Err(shot(format!("unknown tool '{}'", self.tool))),
            ToolOutput::NoOutput => {
                return Err(shot(format!("'{}' writes no output file", self.tool)))
            }
            ToolOutput::Positional => true,
            ToolOutput::Option => false,
        };
        let text = |p: &Path| p.to_string_lossy().into_owned();
        let mut argv = vec!["toonkit".to_string()];
        argv.extend(words.iter().map(|w| w.to_string()));
        argv.push(text(&base.join(&self.input)));
        if positional_output {
            argv.push(text(output));
        }
        if let Some(clip) = &self.clip {
            argv.extend(["--clip".to_string(), clip.clone()]);
        }
        if let Some(style) = &self.style {
            argv.extend(["--style".to_string(), text(&base.join(style))]);
        }
        for (name, value) in &self.options {
            let flag = format!("--{name}");
            match value {
                toml::Value::Boolean(true) => argv.push(flag),
                toml::Value::Boolean(false) => {}
                toml::Value::String(s) => argv.extend([flag, s.clone()]),
                toml::Value::Array(items) => {
                    let items: Vec<String> = items.iter().map(scalar).collect();
                    argv.extend([flag, items.join(",")]);
                }
                other => argv.extend([flag, scalar(other)]),
            }
        }
        if !positional_output {
            argv.extend(["-o".to_string(), text(output)]);
        }
        Ok(argv)
    }
}

/// Whether `output` names a file inside the output folder: relative, plain names only.
fn inside_output_folder(output: &Path) -> bool {
    output.file_name().is_some()
        && output.components().all(|c| {
            matches!(
                c,
                std::path::Component::Normal(_) | std::path::Component::CurDir
            )
        })
}

fn scalar(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}
