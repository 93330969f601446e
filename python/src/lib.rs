//! rinscope's Python bindings: conversions only; every computation is the library's.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// The presets: (name, title) pairs.
#[pyfunction]
fn scenarios() -> Vec<(String, String)> {
    rinscope::scenario::presets::PRESETS
        .iter()
        .map(|(name, _)| {
            let title = rinscope::scenario::presets::load(name).map(|p| p.meta.title).unwrap_or_default();
            ((*name).to_owned(), title)
        })
        .collect()
}

/// A preset's TOML text.
#[pyfunction]
fn preset_toml(name: &str) -> PyResult<String> {
    rinscope::scenario::presets::text(name).map(str::to_owned).ok_or_else(|| PyValueError::new_err(format!("{name}: not a preset")))
}

/// Validates a scenario's TOML text; the error names the key, value and unit as the command does.
#[pyfunction]
fn check(toml: &str) -> PyResult<String> {
    rinscope::scenario::parse(toml, "python").map(|p| p.resolved_toml).map_err(|e| PyValueError::new_err(format!("config error: {e}")))
}

#[pymodule]
fn _rinscope(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(scenarios, m)?)?;
    m.add_function(wrap_pyfunction!(preset_toml, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    Ok(())
}
