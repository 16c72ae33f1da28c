//! Open Job Description job templates (specification `jobtemplate-2023-09`) for a manifest:
//! one step per tool, one task per shot (the task parameter `Shot`), the manifest, the output
//! folder and the `toonkit` executable as job parameters. Every task runs the same
//! idempotent command as a local batch restricted to its shot:
//! `toonkit batch MANIFEST -o OUT --shot NAME --jobs 1`, so a re-queued task skips what is done.

use std::path::Path;

use serde_json::{json, Value};

use crate::{BatchError, Manifest};

/// The job template of `manifest`, as YAML text, to be written into the folder `dir`. `out` and
/// `exe` become the defaults of the `OutputDir` and `Toonkit` job parameters (override them
/// per job, e.g. `openjd run job.yaml --job-param OutputDir=/farm/out`). OpenJD joins PATH
/// defaults to the template's folder and refuses absolute ones, so defaults are relative to `dir`.
///
/// # Errors
/// [`BatchError::Write`] when a path cannot be made absolute (no current folder).
pub fn openjd_template(
    manifest_path: &Path,
    out: &Path,
    exe: &Path,
    manifest: &Manifest,
    dir: &Path,
) -> Result<String, BatchError> {
    let absolute = |p: &Path| relative_to(dir, p);
    // Steps in the order tools first appear; shots in manifest order.
    let mut steps: Vec<(String, Vec<String>)> = Vec::new();
    for shot in &manifest.shots {
        let tool = shot
            .tool
            .split_whitespace()
            .next()
            .unwrap_or("toonkit")
            .to_string();
        match steps.iter_mut().find(|(t, _)| *t == tool) {
            Some((_, shots)) => shots.push(shot.name.clone()),
            None => steps.push((tool, vec![shot.name.clone()])),
        }
    }
    let steps: Vec<Value> = steps
        .into_iter()
        .map(|(tool, shots)| {
            json!({
                "name": tool,
                "parameterSpace": {
                    "taskParameterDefinitions": [
                        {"name": "Shot", "type": "STRING", "range": shots}
                    ]
                },
                "script": {
                    "actions": {
                        "onRun": {
                            "command": "{{Param.Toonkit}}",
                            "args": [
                                "batch", "{{Param.ManifestFile}}",
                                "--output", "{{Param.OutputDir}}",
                                "--shot", "{{Task.Param.Shot}}",
                                "--jobs", "1"
                            ]
                        }
                    }
                }
            })
        })
        .collect();
    let name = manifest_path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "batch".to_string());
    let template = json!({
        "specificationVersion": "jobtemplate-2023-09",
        "name": format!("toonkit {name}"),
        "parameterDefinitions": [
            {
                "name": "ManifestFile",
                "type": "PATH",
                "objectType": "FILE",
                "dataFlow": "IN",
                "description": "The toonkit batch manifest (shots, inputs relative to it).",
                "default": absolute(manifest_path)?
            },
            {
                "name": "OutputDir",
                "type": "PATH",
                "objectType": "DIRECTORY",
                "dataFlow": "OUT",
                "description": "Folder the shots' outputs are written to.",
                "default": absolute(out)?
            },
            {
                "name": "Toonkit",
                "type": "PATH",
                "objectType": "FILE",
                "dataFlow": "NONE",
                "description": "The toonkit executable on the workers.",
                "default": absolute(exe)?
            }
        ],
        "steps": steps
    });
    let mut text =
        String::from("# Open Job Description job template written by `toonkit batch --openjd`.\n");
    yaml(&mut text, &template, 0);
    Ok(text)
}

/// Block-style YAML of a JSON value: maps and lists indented by two spaces, every scalar
/// written as JSON (strings double-quoted, which YAML reads the same way).
fn yaml(out: &mut String, value: &Value, indent: usize) {
    let pad = " ".repeat(indent);
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                if is_block(v) {
                    out.push_str(&format!("{pad}{k}:\n"));
                    yaml(out, v, indent + 2);
                } else {
                    out.push_str(&format!("{pad}{k}: {v}\n"));
                }
            }
        }
        Value::Array(items) => {
            for item in items {
                if is_block(item) {
                    // The first line of the item goes after the dash.
                    let mut inner = String::new();
                    yaml(&mut inner, item, indent + 2);
                    let trimmed = inner.trim_start_matches(' ');
                    out.push_str(&format!("{pad}- {trimmed}"));
                } else {
                    out.push_str(&format!("{pad}- {item}\n"));
                }
            }
        }
        scalar => out.push_str(&format!("{pad}{scalar}\n")),
    }
}

/// Non-empty maps and lists are written as blocks; scalars and empty ones inline.
fn is_block(v: &Value) -> bool {
    match v {
        Value::Object(m) => !m.is_empty(),
        Value::Array(a) => !a.is_empty(),
        _ => false,
    }
}

/// `p` relative to the folder `base` (both made absolute lexically, as OpenJD joins them).
fn relative_to(base: &Path, p: &Path) -> Result<String, BatchError> {
    let absolute = |q: &Path| std::path::absolute(q).map_err(|e| tkio::IoError::io(q, e));
    let (base, p) = (absolute(base)?, absolute(p)?);
    let b: Vec<_> = base.components().collect();
    let q: Vec<_> = p.components().collect();
    let common = b.iter().zip(&q).take_while(|(x, y)| x == y).count();
    let mut rel = std::path::PathBuf::new();
    for _ in common..b.len() {
        rel.push("..");
    }
    for c in &q[common..] {
        rel.push(c);
    }
    Ok(if rel.as_os_str().is_empty() {
        ".".to_string()
    } else {
        rel.to_string_lossy().into_owned()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yaml_nests_maps_and_lists() {
        let mut out = String::new();
        yaml(
            &mut out,
            &json!({"a": [{"b": 1, "c": ["x"]}, 2], "d": "q\""}),
            0,
        );
        assert_eq!(
            out,
            "a:\n  - b: 1\n    c:\n      - \"x\"\n  - 2\nd: \"q\\\"\"\n"
        );
    }
}
