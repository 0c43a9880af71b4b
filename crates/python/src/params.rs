//! Render parameters from Python keyword arguments, by their names in [`ppm::PARAMS`].
//!
//! The order is the command's: the preset [`RenderParams::preview`], then the scene's `[render]`
//! table, then the arguments (the command's flags). Each argument becomes the text a flag would
//! give (`True` → `on`, `0.5` → `0.5`, `"200k"` as it is) and is read by
//! [`RenderParams::set`], so the values, the ranges and the messages are the command's.

use ppm::{ParamError, ParamKind, RenderParams};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyString};
use scene::SceneDescription;

use crate::SceneError;

/// The parameters of a render of `description` with the keyword arguments `kwargs`.
///
/// # Errors
///
/// `ValueError` for an unknown name or a value that is not one of the parameter (with the
/// command's message, the flag replaced by the name), `TypeError` for a value that is neither
/// text, a number nor a bool, [`SceneError`] for a bad `[render]` table in the scene.
pub(crate) fn render_params(
    description: &SceneDescription,
    kwargs: &[(String, Bound<'_, PyAny>)],
) -> PyResult<RenderParams> {
    let mut values = Vec::with_capacity(kwargs.len());
    for (name, value) in kwargs {
        values.push((name.as_str(), value_text(name, value)?));
    }
    // The arguments alone first, as the command checks its flags before it reads the scene.
    let flagged = apply(RenderParams::preview(), &values)?;
    flagged
        .validate()
        .map_err(|e| PyValueError::new_err(param_message(&e)))?;
    let source = description.source.display();
    let base = RenderParams::preview()
        .with_scene_defaults(&description.render)
        .map_err(|e| SceneError::new_err(format!("{source}: [render] {}", param_message(&e))))?;
    let params = apply(base, &values)?;
    params
        .validate()
        .map_err(|e| PyValueError::new_err(format!("{source}: [render] {}", param_message(&e))))?;
    Ok(params)
}

fn apply(base: RenderParams, values: &[(&str, String)]) -> PyResult<RenderParams> {
    let mut params = base;
    for (name, text) in values {
        params
            .set(name, text)
            .map_err(|e| PyValueError::new_err(param_message(&e)))?;
    }
    Ok(params)
}

/// `alpha 1.5 is outside (0, 1]`: the command's message for `--alpha 1.5`, by name.
pub(crate) fn param_message(e: &ParamError) -> String {
    match e {
        ParamError::OutOfRange { name, value, range } => {
            format!("{name} {value} is outside {range}")
        }
        other => other.to_string(),
    }
}

/// The text a flag would give for `value`.
fn value_text(name: &str, value: &Bound<'_, PyAny>) -> PyResult<String> {
    if value.is_instance_of::<PyBool>() {
        let on: bool = value.extract()?;
        return Ok(if on { "on" } else { "off" }.to_owned());
    }
    if value.is_instance_of::<PyInt>() {
        // Any size: a value beyond i128 is refused by the parameter's own range.
        return Ok(value.str()?.to_string());
    }
    if value.is_instance_of::<PyFloat>() {
        let x: f64 = value.extract()?;
        // Rust's shortest round-trip form, which the parameter reads back exactly.
        return Ok(x.to_string());
    }
    if value.is_instance_of::<PyString>() {
        return value.extract();
    }
    if value.is_none() {
        return Err(PyValueError::new_err(format!(
            "{name} None is not a value: leave {name} out for its default"
        )));
    }
    Err(PyTypeError::new_err(format!(
        "{name} must be a str, int, float or bool, not {}",
        value.get_type().name()?
    )))
}

/// Every render parameter: its name, its help line, its default (as the preset has it) and,
/// for a parameter that takes one of a few words, the words.
///
/// Returns:
///     dict[str, dict]: `{name: {"help": str, "default": str, "choices": list[str], "switch": bool}}`,
///     in the order of `fppm --help`. A switch (`"switch": True`) takes a bool.
#[pyfunction]
pub(crate) fn parameters(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let preset = RenderParams::preview();
    let out = PyDict::new(py);
    for param in ppm::PARAMS {
        let entry = PyDict::new(py);
        entry.set_item("help", param.help)?;
        entry.set_item("default", param.get(&preset))?;
        let (choices, switch): (Vec<&str>, bool) = match param.kind {
            ParamKind::Value { choices, .. } => (choices.iter().map(|(w, _)| *w).collect(), false),
            ParamKind::Switch { .. } => (Vec::new(), true),
        };
        entry.set_item("choices", choices)?;
        entry.set_item("switch", switch)?;
        out.set_item(param.name, entry)?;
    }
    Ok(out)
}
