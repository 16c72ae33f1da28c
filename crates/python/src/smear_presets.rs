//! `toonkit.smear.presets()`, `toonkit.smear.parameters()`, `toonkit.smear.preset_function()`
//! and the style file writer: the smear crate's one definition of presets, defaults and ranges
//! ([`smear::ElongatePreset`], [`smear::PARAMETERS`]) handed to Python front ends (the Blender
//! panel builds its sliders and presets from them), and styles written as TOML by the crate
//! (`Style::to_toml_string`) through `tkio::save`, never by a front end.

use std::path::PathBuf;

use pyo3::prelude::*;
use serde_json::json;
use smear::{ElongatePreset, Param, Style, PARAMETERS};

use crate::errors::{at, io_error, value_error};

/// The elongation presets as JSON: name, one-line doc, parameters read, default function.
#[pyfunction(name = "smear_presets")]
pub(crate) fn presets() -> String {
    let list: Vec<_> = ElongatePreset::ALL
        .iter()
        .map(|p| {
            json!({
                "name": p.name(),
                "doc": p.doc(),
                "parameters": p.parameters(),
                "default": *p == ElongatePreset::default(),
                "function": p.default_function(),
            })
        })
        .collect();
    serde_json::Value::Array(list).to_string()
}

/// The parameter table as JSON: name, default, min, max, integer, doc.
#[pyfunction(name = "smear_parameters")]
pub(crate) fn parameters() -> String {
    serde_json::to_string(PARAMETERS).unwrap_or_else(|_| "[]".into())
}

/// A preset's function as JSON (`signed=False`: without its own δ± restriction).
#[pyfunction(name = "smear_preset_function")]
#[pyo3(signature = (name, beta_max, kappa, signed=true))]
pub(crate) fn preset_function(
    name: &str,
    beta_max: f32,
    kappa: f32,
    signed: bool,
) -> PyResult<String> {
    let preset = ElongatePreset::from_name(name).ok_or_else(|| {
        let names: Vec<_> = ElongatePreset::ALL.iter().map(|p| p.name()).collect();
        value_error(format!(
            "preset {name:?}: not a smear preset (one of {})",
            names.join(", ")
        ))
    })?;
    let spec = if signed {
        preset.function(Param::Constant(beta_max), Param::Constant(kappa))
    } else {
        smear::FunctionSpec::stages(preset.unsigned_stages(beta_max, kappa))
    };
    serde_json::to_string(&spec).map_err(|e| value_error(format!("preset {name}: {e}")))
}

/// A style (JSON text) checked and written as the TOML the CLI's `--style` reads, atomically.
#[pyfunction(name = "smear_save_style")]
pub(crate) fn save_style(py: Python<'_>, path: PathBuf, style_json: &str) -> PyResult<PathBuf> {
    let text = style_toml(style_json)?;
    let p = path.clone();
    py.detach(move || tkio::save(&p, &tkio::Output::Text(&text)))
        .map_err(io_error)?;
    Ok(path)
}

/// A style (JSON text) checked and as TOML text.
#[pyfunction(name = "smear_style_toml")]
pub(crate) fn style_toml(style_json: &str) -> PyResult<String> {
    let style: Style =
        serde_json::from_str(style_json).map_err(|e| value_error(format!("style: {e}")))?;
    style.validate().map_err(|e| value_error(at("style", e)))?;
    style
        .to_toml_string()
        .map_err(|e| value_error(at("style", e)))
}
