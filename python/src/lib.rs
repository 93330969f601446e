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

/// Runs a scenario (its TOML text) for `duration_s` (None: its own), saving the recording to
/// `save`; the run's summary as JSON (the `--summary-json` of `rinscope run`). The GIL is released
/// while it runs; Ctrl-C is not yet wired to the stop flag.
#[pyfunction]
#[pyo3(signature = (toml, save, duration_s=None))]
fn run_summary(py: Python<'_>, toml: &str, save: std::path::PathBuf, duration_s: Option<f64>) -> PyResult<String> {
    let mut params = rinscope::scenario::parse(toml, "python").map_err(|e| PyValueError::new_err(format!("config error: {e}")))?;
    if let Some(d) = duration_s {
        if !(d.is_finite() && d > 0.0 && d <= rinscope::scenario::MAX_DURATION_S) {
            return Err(PyValueError::new_err(format!("duration_s {d} s: must be > 0 and at most {} s", rinscope::scenario::MAX_DURATION_S)));
        }
        params.set_duration(d);
    }
    py.detach(|| {
        let request = rinscope::record::sink::SinkRequest { save: Some(save), ..Default::default() };
        let sinks = rinscope::record::sink::open(&request, rinscope::record::APPLICATION_ID, &params.meta.name).map_err(|e| e.to_string())?;
        let stop = std::sync::atomic::AtomicBool::new(false);
        let summary = match rinscope::app::run::run_recorded(&params, &sinks, &stop, false) {
            Ok(s) => s,
            Err(e) => {
                sinks.abandon();
                return Err(format!("{e:#}"));
            }
        };
        sinks.finish().map_err(|e| e.to_string())?;
        serde_json::to_string(&summary).map_err(|e| e.to_string())
    })
    .map_err(pyo3::exceptions::PyRuntimeError::new_err)
}

#[pymodule]
fn _rinscope(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(scenarios, m)?)?;
    m.add_function(wrap_pyfunction!(preset_toml, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(run_summary, m)?)?;
    Ok(())
}
