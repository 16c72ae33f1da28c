//! Completion stamps: a shot whose outputs exist and whose inputs and options hash as
//! recorded in `OUT/.toonkit-batch/<shot>.json` is done. The stamp is written (atomically)
//! only after all of the shot's outputs, so a re-run after a crash or a kill redoes only what
//! is missing.
//!
//! Inputs are every file the shot read, not only those the manifest names: the external
//! buffers of a `.gltf`, the implicit rest `.obj` of a point cache, option files such as
//! `collider = "floor.obj"`, style files (recorded by [`tkio::ReadScope`] while the shot ran).
//! Outputs are hashed too, so an output edited or replaced since is made again.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::{BatchError, Shot, ToolOutput};

/// Folder (inside OUT) of the per-shot stamps.
pub const STAMP_DIR: &str = ".toonkit-batch";

/// The stamp of a completed shot.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Stamp {
    /// Shot name.
    pub shot: String,
    /// [`Stamp::hash`] of the shot when it was made.
    pub hash: String,
    /// `(output, size in bytes, content hash)` of every declared output.
    pub outputs: Vec<(PathBuf, u64, String)>,
    /// `(file, content hash)` of every file the shot read (relative to the manifest's folder
    /// when inside it).
    #[serde(default)]
    pub inputs: Vec<(PathBuf, String)>,
}

/// The content hash of a file (XXH3-128, hex), or `None` when it cannot be read.
fn file_hash(path: &Path) -> Option<String> {
    let bytes = std::fs::read(path).ok()?;
    Some(format!("{:032x}", twox_hash::XxHash3_128::oneshot(&bytes)))
}

impl Stamp {
    /// The hash of everything that decides a shot's outputs: toonkit's version, the command
    /// lines (with OUT left out, so a moved folder still matches), the input and style bytes.
    ///
    /// # Errors
    /// [`BatchError::Input`] when the input or style cannot be read; the errors of
    /// [`Shot::command_line`].
    pub fn hash(
        shot: &Shot,
        base: &Path,
        tool: &dyn Fn(&[&str]) -> ToolOutput,
    ) -> Result<String, BatchError> {
        let mut buf = Vec::new();
        buf.extend_from_slice(env!("CARGO_PKG_VERSION").as_bytes());
        for o in &shot.outputs {
            for a in shot.command_line(base, &Path::new("{OUT}").join(o), tool)? {
                buf.extend_from_slice(a.as_bytes());
                buf.push(0);
            }
        }
        for file in std::iter::once(&shot.input).chain(shot.style.as_ref()) {
            let path = base.join(file);
            let bytes =
                std::fs::read(&path).map_err(|source| BatchError::Input { path, source })?;
            buf.extend_from_slice(&twox_hash::XxHash3_128::oneshot(&bytes).to_le_bytes());
        }
        Ok(format!("{:032x}", twox_hash::XxHash3_128::oneshot(&buf)))
    }

    /// The stamp file of a shot under the output folder `out`.
    pub fn path(out: &Path, shot: &Shot) -> PathBuf {
        out.join(STAMP_DIR).join(format!("{}.json", shot.name))
    }

    /// The stamp of the shot's outputs as they are on disk, if they all exist, with the
    /// files `read` (paths relative to `base` or absolute) as they are now (`None` when one
    /// is gone).
    pub fn current(
        shot: &Shot,
        out: &Path,
        hash: &str,
        base: &Path,
        read: &[PathBuf],
    ) -> Option<Stamp> {
        let outputs = shot
            .outputs
            .iter()
            .map(|o| {
                let p = out.join(o);
                Some((o.clone(), std::fs::metadata(&p).ok()?.len(), file_hash(&p)?))
            })
            .collect::<Option<Vec<_>>>()?;
        let inputs = read
            .iter()
            .map(|r| Some((r.clone(), file_hash(&base.join(r))?)))
            .collect::<Option<Vec<_>>>()?;
        Some(Stamp {
            shot: shot.name.clone(),
            hash: hash.to_string(),
            outputs,
            inputs,
        })
    }

    /// The stamp recorded for the shot, if any (an unreadable one counts as none).
    pub fn recorded(shot: &Shot, out: &Path) -> Option<Stamp> {
        let bytes = std::fs::read(Stamp::path(out, shot)).ok()?;
        serde_json::from_slice(&bytes).ok()
    }

    /// Whether the shot is done: its recorded stamp matches its outputs on disk, the files
    /// it read and `hash`.
    pub fn is_done(shot: &Shot, out: &Path, hash: &str, base: &Path) -> bool {
        let Some(recorded) = Stamp::recorded(shot, out) else {
            return false;
        };
        let read: Vec<PathBuf> = recorded.inputs.iter().map(|(p, _)| p.clone()).collect();
        Some(recorded) == Stamp::current(shot, out, hash, base, &read)
    }

    /// Records the shot as done (after all its outputs are written).
    ///
    /// # Errors
    /// [`BatchError::Invalid`] when a declared output was not written; [`BatchError::Write`]
    /// when the stamp cannot be written.
    /// `read` is every file the shot read (made relative to `base` here when inside it).
    pub fn write_done(
        shot: &Shot,
        out: &Path,
        hash: &str,
        base: &Path,
        read: &[PathBuf],
    ) -> Result<(), BatchError> {
        let read: Vec<PathBuf> = read
            .iter()
            .map(|r| {
                r.strip_prefix(base)
                    .map_or_else(|_| r.clone(), Path::to_path_buf)
            })
            .collect();
        let stamp = Stamp::current(shot, out, hash, base, &read).ok_or_else(|| {
            BatchError::invalid(
                Path::new(&format!("shot '{}'", shot.name)),
                "a declared output was not written (or an input vanished while it ran)",
            )
        })?;
        let text = serde_json::to_string_pretty(&stamp).unwrap_or_default();
        tkio::save(&Stamp::path(out, shot), &tkio::Output::Text(&text))?;
        Ok(())
    }
}
