//! rinscope's Python bindings (the `rinscope._rinscope` module): conversions only. Every
//! computation is the rinscope library's; this crate turns TOML, JSON and arrays into its types,
//! runs it on a worker thread while the caller's thread watches for Ctrl-C, and hands the results
//! back as JSON and Arrow IPC streams (which `rinscope/__init__.py` makes into dicts and pandas
//! DataFrames).

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use serde::Serialize;

use rinscope::app::allan::AllanRequest;
use rinscope::calib::MonteCarloConfig;

use rinscope::app::outputs::RecordingRequest;
use rinscope::record::export::Table;
use rinscope::record::sink::{self, SinkRequest};
use rinscope::scenario::{self, Params, logset, presets};

/// What went wrong, as the Python exception it becomes.
enum Failure {
    /// Bad input (a config key, a column, a value out of range): ValueError.
    Input(String),
    /// A file that cannot be written: OSError.
    Output(String),
    /// Anything else: RuntimeError.
    Run(String),
    /// Stopped (Ctrl-C) before there was anything to return: KeyboardInterrupt.
    Interrupted(String),
}

impl From<Failure> for PyErr {
    fn from(f: Failure) -> Self {
        match f {
            Failure::Input(m) => PyValueError::new_err(m),
            Failure::Output(m) => PyOSError::new_err(m),
            Failure::Run(m) => PyRuntimeError::new_err(m),
            Failure::Interrupted(m) => PyKeyboardInterrupt::new_err(m),
        }
    }
}

/// A command owner's failure (`rinscope::app`), as the exception its kind says.
impl From<rinscope::app::failure::Failure> for Failure {
    fn from(f: rinscope::app::failure::Failure) -> Self {
        use rinscope::app::failure::FailureKind;
        match f.kind {
            FailureKind::Input => Self::Input(f.message),
            FailureKind::Output => Self::Output(f.message),
            FailureKind::Run => Self::Run(f.message),
            FailureKind::Interrupted => Self::Interrupted(f.message),
        }
    }
}

impl From<sink::SinkError> for Failure {
    fn from(e: sink::SinkError) -> Self {
        match e {
            sink::SinkError::Interrupted(m) => Self::Interrupted(m),
            sink::SinkError::Write(_) | sink::SinkError::File(_) | sink::SinkError::ExportWrite(_) => {
                Self::Output(e.to_string())
            }
            sink::SinkError::Rerun(_) | sink::SinkError::FiguresWrite(_) => Self::Run(e.to_string()),
            _ => Self::Input(e.to_string()),
        }
    }
}

/// A scenario's TOML text parsed and validated, the error as `rinscope check-config` says it.
fn parse(toml: &str, origin: &str) -> Result<Params, Failure> {
    scenario::parse(toml, origin).map_err(|e| Failure::Input(format!("config error: {e}")))
}

/// Runs `work` on a thread of its own with a stop flag, the GIL released; the caller's thread
/// wakes every 50 ms to let Python handle signals. Ctrl-C (KeyboardInterrupt) sets the flag, waits
/// for the work to finish what it has (a recording then ends complete up to that moment, as the
/// command's does) and raises.
fn interruptible<T: Send>(py: Python<'_>, work: impl FnOnce(&Arc<AtomicBool>) -> T + Send) -> PyResult<T> {
    use crossbeam_channel::RecvTimeoutError;
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = crossbeam_channel::bounded(1);
    std::thread::scope(|s| {
        let flag = Arc::clone(&stop);
        s.spawn(move || tx.send(work(&flag)).ok());
        loop {
            match py.detach(|| rx.recv_timeout(Duration::from_millis(50))) {
                Ok(v) => return Ok(v),
                Err(RecvTimeoutError::Timeout) => {
                    if let Err(e) = py.check_signals() {
                        stop.store(true, Ordering::SeqCst);
                        py.detach(|| rx.recv()).ok();
                        return Err(e);
                    }
                }
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(PyRuntimeError::new_err(
                        "rinscope: the work ended without a result (see the panic message on stderr)",
                    ));
                }
            }
        }
    })
}

/// Where a call's recording goes: the file if `save`, and the tables in memory.
fn recording(save: Option<PathBuf>, stop: &Arc<AtomicBool>) -> RecordingRequest {
    RecordingRequest {
        sinks: SinkRequest {
            save,
            stop_on_failure: Some(Arc::clone(stop)),
            tables_in_memory: true,
            ..Default::default()
        },
        save_by_default: false,
    }
}

/// One table as an Arrow IPC stream: float64 columns named as `--export` names them, the entity in
/// the schema's metadata.
fn ipc(table: Table) -> Result<(String, String, Vec<u8>), Failure> {
    use arrow_array::{ArrayRef, Float64Array, RecordBatch};
    use arrow_schema::{DataType, Field, Schema};
    let arrow = |e: arrow_schema::ArrowError| Failure::Run(format!("arrow: {e}"));
    let fields: Vec<Field> = table.columns.iter().map(|c| Field::new(c, DataType::Float64, false)).collect();
    let metadata =
        [("rinscope.entity".to_owned(), table.entity.clone()), ("rinscope.table".to_owned(), table.name.clone())]
            .into_iter()
            .collect();
    let schema = Arc::new(Schema::new(fields).with_metadata(metadata));
    let arrays: Vec<ArrayRef> = table.values.into_iter().map(|v| Arc::new(Float64Array::from(v)) as ArrayRef).collect();
    let batch = RecordBatch::try_new(Arc::clone(&schema), arrays).map_err(arrow)?;
    let mut bytes = Vec::new();
    let mut writer = arrow_ipc::writer::StreamWriter::try_new(&mut bytes, &schema).map_err(arrow)?;
    writer.write(&batch).map_err(arrow)?;
    writer.finish().map_err(arrow)?;
    drop(writer);
    Ok((table.entity, table.name, bytes))
}

/// What a call returns to Python: a JSON document and the tables as (entity, export name, Arrow
/// IPC stream).
type Output = (String, Vec<(String, String, Vec<u8>)>);

/// [`Output`] as Python objects.
type PyOutput = (String, Vec<(String, String, Py<PyBytes>)>);

/// The JSON document and tables as Python objects.
fn to_python(py: Python<'_>, (json, tables): Output) -> PyOutput {
    (json, tables.into_iter().map(|(entity, name, bytes)| (entity, name, PyBytes::new(py, &bytes).unbind())).collect())
}

/// A call's output: its summary as JSON and the tables the sinks kept.
fn output<S: Serialize>(summary: S, saved: sink::Saved) -> Result<Output, Failure> {
    let json = serde_json::to_string(&summary).map_err(|e| Failure::Run(e.to_string()))?;
    let tables = saved.tables.into_iter().map(ipc).collect::<Result<_, _>>()?;
    Ok((json, tables))
}

/// A report of runs in parallel as the document and recording Python returns; one stopped before
/// every run was done is a KeyboardInterrupt (its numbers cover the simulated part only).
fn complete<S: Serialize>(
    report: S,
    interrupted: bool,
    saved: Option<sink::Saved>,
    command: &str,
) -> Result<Output, Failure> {
    if interrupted {
        return Err(Failure::Interrupted(format!("{command}: stopped before every run was done")));
    }
    output(report, saved.unwrap_or_default())
}

/// The presets: (name, title) pairs, in the order `rinscope scenarios` lists them.
#[pyfunction]
fn scenarios() -> Vec<(String, String)> {
    rinscope::app::inspect::scenarios()
        .into_iter()
        .map(|(name, p)| (name.to_owned(), p.map(|p| p.meta.title).unwrap_or_else(|e| format!("BROKEN: {e}"))))
        .collect()
}

/// A preset's TOML text.
#[pyfunction]
fn preset_toml(name: &str) -> PyResult<String> {
    presets::text(name).map(str::to_owned).ok_or_else(|| {
        PyValueError::new_err(format!(
            "{name:?} is not a preset; rinscope.scenarios() lists them: {}",
            presets::PRESETS.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
        ))
    })
}

/// Validates a scenario's TOML text (`origin` names it in messages); returns the resolved TOML
/// (every default filled in). The error names the key, value and unit as the command does.
#[pyfunction]
#[pyo3(signature = (toml, origin="python"))]
fn check(toml: &str, origin: &str) -> PyResult<String> {
    Ok(parse(toml, origin)?.resolved_toml)
}

/// TOML text as JSON (for the dict-like Scenario); a syntax error is a ValueError.
#[pyfunction]
fn toml_to_json(text: &str) -> PyResult<String> {
    let value: toml::Value = toml::from_str(text)
        .map_err(|e| PyValueError::new_err(format!("config error: {}", rinscope::scenario::parse_message(&e))))?;
    serde_json::to_string(&value).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// JSON (a Scenario's dict) as TOML text; a value TOML cannot hold (null, a mixed array) is a ValueError.
#[pyfunction]
fn json_to_toml(json: &str) -> PyResult<String> {
    let value: toml::Value =
        serde_json::from_str(json).map_err(|e| PyValueError::new_err(format!("not a TOML document: {e}")))?;
    toml::to_string(&value).map_err(|e| PyValueError::new_err(format!("not a TOML document: {e}")))
}

/// `duration_s` checked as `--duration-s` is.
fn set_duration(params: &mut Params, duration_s: Option<f64>) -> Result<(), Failure> {
    if let Some(d) = duration_s {
        params.set_duration(scenario::check_duration(d).map_err(|e| Failure::Input(format!("duration_s {e}")))?);
    }
    Ok(())
}

/// The library's run of `params` into the sinks of a call (the recording if `save`, the tables in
/// memory), finished: what `run` converts, and what `_time_run` times.
fn run_to_sinks(
    params: Params,
    save: Option<PathBuf>,
    compensation: Option<(String, String)>,
    stop: &Arc<AtomicBool>,
) -> Result<(rinscope::app::run::RunSummary, sink::Saved), Failure> {
    use rinscope::app::run::{RunRequest, execute};
    let report = execute(
        &RunRequest { params, recording: recording(save, stop), summary_json: None, progress: false, compensation },
        stop,
    )?;
    Ok((report.summary, report.saved))
}

/// The reference of the overhead benchmark (python/benchmarks/overhead.py): `repeats` runs of a
/// scenario through the library, each timed in Rust from its TOML text to its finished tables
/// (parse, simulate, tables kept in memory), without any conversion for Python; seconds each.
#[pyfunction]
fn _time_run(py: Python<'_>, toml: &str, duration_s: Option<f64>, repeats: usize) -> PyResult<Vec<f64>> {
    py.detach(|| {
        let stop = Arc::new(AtomicBool::new(false));
        (0..repeats)
            .map(|_| {
                let started = std::time::Instant::now();
                let mut params = parse(toml, "the scenario")?;
                set_duration(&mut params, duration_s)?;
                let (_, saved) = run_to_sinks(params, None, None, &stop)?;
                std::hint::black_box(saved.tables.len());
                Ok(started.elapsed().as_secs_f64())
            })
            .collect::<Result<Vec<f64>, Failure>>()
    })
    .map_err(PyErr::from)
}

/// Runs a scenario (its TOML text) for `duration_s` (None: its own), saving the recording to
/// `save` if given, compensated with `compensation` (a compensation document's text, as
/// `run --compensation`): the summary (as `run --summary-json` writes it) and every series as a table.
#[pyfunction]
#[pyo3(signature = (toml, duration_s=None, save=None, compensation=None))]
fn run(
    py: Python<'_>,
    toml: &str,
    duration_s: Option<f64>,
    save: Option<PathBuf>,
    compensation: Option<&str>,
) -> PyResult<PyOutput> {
    let mut params = parse(toml, "the scenario")?;
    set_duration(&mut params, duration_s)?;
    let compensation = compensation.map(|text| (text.to_owned(), "compensation".to_owned()));
    let out = interruptible(py, move |stop| -> Result<Output, Failure> {
        let (summary, saved) = run_to_sinks(params, save, compensation, stop)?;
        output(summary, saved)
    })??;
    Ok(to_python(py, out))
}

/// Replays the log set in `dir` (its own compensation, or `compensation`: a `calibrate` JSON's
/// text), saving to `save` if given: the summary and every series as a table.
#[pyfunction]
#[pyo3(signature = (dir, save=None, compensation=None))]
fn replay(py: Python<'_>, dir: PathBuf, save: Option<PathBuf>, compensation: Option<&str>) -> PyResult<PyOutput> {
    use rinscope::app::replay::{ReplayRequest, execute};
    let log = logset::load(&dir).map_err(|e| Failure::Input(e.to_string()))?;
    let compensation = compensation.map(|text| (text.to_owned(), "compensation".to_owned()));
    let out = interruptible(py, move |stop| -> Result<Output, Failure> {
        let report = execute(
            &ReplayRequest { log, compensation, recording: recording(save, stop), summary_json: None },
            stop,
            None,
        )?;
        output(report.summary, report.saved)
    })??;
    Ok(to_python(py, out))
}

/// Calibrates the table of a scenario (its TOML text) or of the log set in `log_dir`: the report
/// with the least-squares compensation (as `calibrate --json` writes it) and every series.
#[pyfunction]
#[pyo3(signature = (toml=None, log_dir=None, save=None))]
fn calibrate(
    py: Python<'_>,
    toml: Option<&str>,
    log_dir: Option<PathBuf>,
    save: Option<PathBuf>,
) -> PyResult<PyOutput> {
    use rinscope::app::calibrate::{CalibrateInput, CalibrateRequest, execute};
    let input = match (toml, log_dir) {
        (Some(toml), None) => CalibrateInput::Scenario(Box::new(parse(toml, "the scenario")?)),
        (None, Some(dir)) => {
            CalibrateInput::Log(Box::new(logset::load(&dir).map_err(|e| Failure::Input(e.to_string()))?))
        }
        _ => return Err(PyValueError::new_err("calibrate: give a scenario or log_dir (one of them)")),
    };
    let out = interruptible(py, move |stop| -> Result<Output, Failure> {
        let report = execute(&CalibrateRequest { input, recording: Some(recording(save, stop)), json: None }, stop)?;
        output(report.document, report.saved.unwrap_or_default())
    })??;
    Ok(to_python(py, out))
}

/// Little-endian float64 bytes as values.
fn floats(bytes: &[u8], what: &str) -> Result<Vec<f64>, Failure> {
    if bytes.len() % 8 != 0 {
        return Err(Failure::Input(format!("{what}: {} bytes is not a whole number of float64 values", bytes.len())));
    }
    Ok(bytes.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8]))).collect())
}

/// The Allan analysis of arrays: `specs` one `NAME:KIND[:UNIT]` per column (as `allan --column`),
/// `columns` each column's little-endian float64 bytes, sampled at `rate_hz` or at `time_s`
/// (float64 bytes, s). The analysis as `allan --json` writes it, and the curves and fits as tables
/// (as `allan --export` writes them); the recording saved to `save` if given.
#[pyfunction]
#[pyo3(signature = (specs, columns, rate_hz=None, time_s=None, taus="octave", estimators="oadev", ci_sigma=1.0, decimate=1, save=None, description=None))]
#[allow(clippy::too_many_arguments)]
fn allan(
    py: Python<'_>,
    specs: Vec<String>,
    columns: Vec<Vec<u8>>,
    rate_hz: Option<f64>,
    time_s: Option<Vec<u8>>,
    taus: &str,
    estimators: &str,
    ci_sigma: f64,
    decimate: usize,
    save: Option<PathBuf>,
    description: Option<String>,
) -> PyResult<PyOutput> {
    use rinscope::app::allan::{options, parse_estimators, parse_taus};
    let spacing = parse_taus(taus).map_err(|e| Failure::Input(format!("allan: taus {e}")))?;
    let estimators = parse_estimators(estimators).map_err(|e| Failure::Input(format!("allan: estimators {e}")))?;
    let request = AllanRequest { spacing, estimators, decimate, ci_sigma, errors_only: false };
    options(&request).map_err(|e| {
        Failure::Input(format!(
            "allan: {}",
            e.to_string().replace("--ci-sigma", "ci_sigma").replace("--decimate", "decimate")
        ))
    })?;
    let specs: Vec<_> = specs
        .iter()
        .map(|s| rinscope::io::imu::series::SeriesColumn::parse(s).map_err(|e| Failure::Input(format!("allan: {e}"))))
        .collect::<Result<_, _>>()?;
    if specs.len() != columns.len() {
        return Err(PyValueError::new_err(format!(
            "allan: {} column specs for {} columns",
            specs.len(),
            columns.len()
        )));
    }
    let values: Vec<Vec<f64>> =
        columns.iter().zip(&specs).map(|(b, s)| floats(b, &s.col.to_string())).collect::<Result<_, _>>()?;
    let times = time_s.map(|b| floats(&b, "time_s")).transpose()?;
    let out = interruptible(py, |stop| -> Result<Output, Failure> {
        use rinscope::app::allan::{AllanCommand, AllanExport, AllanSource, execute};
        let data = rinscope::io::imu::series::series_in_memory(&specs, values, rate_hz, times.as_deref())
            .map_err(|e| Failure::Input(format!("allan: {e}")))?;
        let description = description.unwrap_or_else(|| "Arrays analysed from Python.".to_owned());
        let command = AllanCommand {
            source: AllanSource::Arrays(Box::new(data), description),
            analysis: request,
            recording: save.map(|path| RecordingRequest {
                sinks: SinkRequest { save: Some(path), stop_on_failure: Some(Arc::clone(stop)), ..Default::default() },
                save_by_default: false,
            }),
            export: Some(AllanExport::Memory),
            json: None,
        };
        let report = execute(command, stop, &|_| {})?;
        Ok((report.result.json().to_string(), report.tables.into_iter().map(ipc).collect::<Result<_, _>>()?))
    })??;
    Ok(to_python(py, out))
}

/// The Monte Carlo of a calibration scenario (its TOML text): `runs` calibrations on every core;
/// the summary (as `montecarlo --json` writes it) with each run's estimation errors under "runs".
#[pyfunction]
#[pyo3(signature = (toml, runs=None, eta_measured_sigma_arcsec=None))]
fn montecarlo(
    py: Python<'_>,
    toml: &str,
    runs: Option<usize>,
    eta_measured_sigma_arcsec: Option<f64>,
) -> PyResult<String> {
    use rinscope::app::montecarlo::{MonteCarloRequest, execute};
    use rinscope::calib::montecarlo::Shard;
    let mut params = parse(toml, "the scenario")?;
    if let Some(s) = eta_measured_sigma_arcsec {
        params
            .calibration
            .montecarlo
            .set_eta_measured_sigma_arcsec(s)
            .map_err(|e| PyValueError::new_err(format!("eta_measured_sigma_arcsec {e}")))?;
    }
    let runs = MonteCarloConfig::check_runs(runs.unwrap_or(params.calibration.montecarlo.runs as usize))
        .map_err(|e| PyValueError::new_err(format!("runs {e}")))?;
    let request = MonteCarloRequest { params, runs: Some(runs), shard: Shard::WHOLE, json: None };
    let json = interruptible(py, move |stop| -> Result<String, Failure> {
        let report = execute(&request, stop, &|| ())?;
        if report.interrupted() {
            return Err(Failure::Interrupted(format!(
                "montecarlo: stopped after {} of {runs} runs",
                report.done.len()
            )));
        }
        let mut value = serde_json::to_value(&report.summary).map_err(|e| Failure::Run(e.to_string()))?;
        value["runs"] = serde_json::to_value(&report.done).map_err(|e| Failure::Run(e.to_string()))?;
        Ok(value.to_string())
    })??;
    Ok(json)
}

/// A scenario (its TOML text) over a grid: `vary` pairs of a scenario key and its values, `seeds`
/// consecutive seeds at every point, every point a whole run without a recording, in parallel on
/// `threads` (None: every core): the document `sweep --json` writes.
#[pyfunction]
#[pyo3(signature = (toml, vary, seeds=1, duration_s=None, threads=None))]
fn sweep(
    py: Python<'_>,
    toml: &str,
    vary: Vec<(String, Vec<f64>)>,
    seeds: u64,
    duration_s: Option<f64>,
    threads: Option<usize>,
) -> PyResult<String> {
    use rinscope::app::sweep::{SweepRequest, execute};
    let params = parse(toml, "the scenario")?;
    if seeds == 0 || threads == Some(0) {
        return Err(PyValueError::new_err("sweep: seeds and threads must be at least 1"));
    }
    for (key, values) in &vary {
        if values.is_empty() || values.iter().any(|v| !v.is_finite()) {
            return Err(PyValueError::new_err(format!("sweep: {key}: give finite values, at least one")));
        }
    }
    let duration_s = duration_s
        .map(|d| scenario::check_duration(d).map_err(|e| PyValueError::new_err(format!("duration_s {e}"))))
        .transpose()?;
    let request = SweepRequest {
        params,
        vary,
        seeds,
        duration_s,
        threads,
        json: None,
        shard: rinscope::calib::montecarlo::Shard::WHOLE,
    };
    let json = interruptible(py, move |stop| -> Result<String, Failure> {
        let report = execute(&request, stop)?;
        if report.interrupted {
            return Err(Failure::Interrupted(format!(
                "sweep: stopped after {} of {} runs",
                report.points.len(),
                report.planned
            )));
        }
        serde_json::to_string(&report).map_err(|e| Failure::Run(e.to_string()))
    })??;
    Ok(json)
}

/// The error budget of a scenario (its TOML text) over `hours` (default: its own duration): the
/// document `budget --json` writes and every channel's table (each source's part, the full run, the
/// baseline and their sum), the recording saved to `save` if given.
#[pyfunction]
#[pyo3(signature = (toml, hours=None, sample_s=None, threads=None, save=None))]
fn budget(
    py: Python<'_>,
    toml: &str,
    hours: Option<f64>,
    sample_s: Option<f64>,
    threads: Option<usize>,
    save: Option<PathBuf>,
) -> PyResult<PyOutput> {
    use rinscope::app::budget::{BudgetRequest, execute};
    let mut params = parse(toml, "the scenario")?;
    if let Some(h) = hours {
        set_duration(&mut params, Some(h * 3600.0))?;
    }
    if threads == Some(0) || sample_s.is_some_and(|s| !(s.is_finite() && s > 0.0)) {
        return Err(PyValueError::new_err("budget: threads at least 1, sample_s a positive number of seconds"));
    }
    let out = interruptible(py, move |stop| -> Result<Output, Failure> {
        let request = BudgetRequest { params, sample_s, threads, json: None, recording: recording(save, stop) };
        let mut report = execute(&request, stop)?;
        let (interrupted, saved) = (report.interrupted, report.saved.take());
        complete(report, interrupted, saved, "budget")
    })??;
    Ok(to_python(py, out))
}

/// Rotation schemes side by side on a scenario (its TOML text) over `hours` (default: its own
/// duration): `schemes` names built-ins or files with a `[scheme]` (none: every built-in), run on
/// `seeds` seeds each; the document `schemes --json` writes and the recording's series.
#[pyfunction]
#[pyo3(signature = (toml, schemes=Vec::new(), hours=None, seeds=4, budget=false, modulable_only=false, threads=None, save=None))]
#[allow(clippy::too_many_arguments)]
fn schemes(
    py: Python<'_>,
    toml: &str,
    schemes: Vec<String>,
    hours: Option<f64>,
    seeds: u64,
    budget: bool,
    modulable_only: bool,
    threads: Option<usize>,
    save: Option<PathBuf>,
) -> PyResult<PyOutput> {
    use rinscope::app::schemes::{SchemesRequest, execute, resolve};
    let mut params = parse(toml, "the scenario")?;
    if let Some(h) = hours {
        set_duration(&mut params, Some(h * 3600.0))?;
    }
    if threads == Some(0) || seeds == 0 {
        return Err(PyValueError::new_err("schemes: seeds and threads at least 1"));
    }
    let schemes = resolve(&schemes).map_err(Failure::from)?;
    let out = interruptible(py, move |stop| -> Result<Output, Failure> {
        let request = SchemesRequest {
            params,
            schemes,
            seeds,
            threads,
            json: None,
            budget,
            modulable_only,
            preface: None,
            recording: recording(save, stop),
        };
        let mut report = execute(&request, stop)?;
        let (interrupted, saved) = (report.interrupted, report.saved.take());
        complete(report, interrupted, saved, "schemes")
    })??;
    Ok(to_python(py, out))
}

/// The rotation-scheme designer on a scenario (its TOML text): `candidates` sequences drawn under
/// the constraints (`axes`, `moves`, `angles_deg`, `rates_deg_per_s`, `dwells_s`, `max_wrap_deg`),
/// ranked by the averaged model with the built-ins, the best `confirm` simulated on `seeds` seeds;
/// the document `design --json` writes (the designed `[scheme]` under each ranked row's "scheme").
#[pyfunction]
#[pyo3(signature = (toml, hours=None, axes=Vec::new(), moves=vec![8, 16, 32], angles_deg=vec![180.0], rates_deg_per_s=Vec::new(), dwells_s=Vec::new(), max_wrap_deg=360.0, candidates=1000, refine=300, confirm=4, seeds=4, threads=None, save=None))]
#[allow(clippy::too_many_arguments)]
fn design(
    py: Python<'_>,
    toml: &str,
    hours: Option<f64>,
    axes: Vec<String>,
    moves: Vec<usize>,
    angles_deg: Vec<f64>,
    rates_deg_per_s: Vec<f64>,
    dwells_s: Vec<f64>,
    max_wrap_deg: f64,
    candidates: usize,
    refine: usize,
    confirm: usize,
    seeds: u64,
    threads: Option<usize>,
    save: Option<PathBuf>,
) -> PyResult<PyOutput> {
    use rinscope::app::design::{DesignRequest, DesignSpace, execute};
    let mut params = parse(toml, "the scenario")?;
    if let Some(h) = hours {
        set_duration(&mut params, Some(h * 3600.0))?;
    }
    if threads == Some(0) || seeds == 0 || candidates == 0 || confirm == 0 {
        return Err(PyValueError::new_err("design: candidates, confirm, seeds and threads at least 1"));
    }
    let space = DesignSpace { axes, steps: moves, angles_deg, rates_deg_per_s, dwells_s, max_wrap_deg };
    let out = interruptible(py, move |stop| -> Result<Output, Failure> {
        let request = DesignRequest {
            params,
            space,
            candidates,
            refine,
            confirm,
            seeds,
            threads,
            json: None,
            save_scheme: None,
            recording: recording(save, stop),
        };
        let mut report = execute(&request, stop)?;
        let (interrupted, saved) = (report.interrupted, report.saved.take());
        complete(report, interrupted, saved, "design")
    })??;
    Ok(to_python(py, out))
}

/// Self-calibrates the IMU of a scenario (its TOML text) on its own gimbals through `sequence`
/// (`dual-axis-29`, `positions-19`, `azimuth-only`, `scenario`), with `monte_carlo` runs and
/// `navigate_hours` of free-inertial comparison (0: none): the document `selfcal --json` writes
/// (with the printed table under "table") and the recording's series.
#[pyfunction]
#[pyo3(signature = (toml, sequence="dual-axis-29", monte_carlo=None, navigate_hours=24.0, save=None))]
fn selfcal(
    py: Python<'_>,
    toml: &str,
    sequence: &str,
    monte_carlo: Option<usize>,
    navigate_hours: f64,
    save: Option<PathBuf>,
) -> PyResult<PyOutput> {
    use rinscope::app::selfcal::{self as sc, SelfcalInput, SelfcalRequest, SequenceChoice, execute};
    let params = parse(toml, "the scenario")?;
    sc::check_navigate_hours(navigate_hours).map_err(|e| PyValueError::new_err(format!("navigate_hours {e}")))?;
    if let Some(n) = monte_carlo.filter(|n| !sc::MONTE_CARLO_RUNS.contains(&(*n as u64))) {
        let (lo, hi) = (sc::MONTE_CARLO_RUNS.start(), sc::MONTE_CARLO_RUNS.end());
        return Err(PyValueError::new_err(format!(
            "monte_carlo {n}: must be {lo} ..= {hi} runs (or None), as --monte-carlo"
        )));
    }
    let sequence = SequenceChoice::parse(sequence).map_err(|e| PyValueError::new_err(format!("sequence {e}")))?;
    let input = SelfcalInput::Scenario {
        params: Box::new(params),
        sequence,
        monte_carlo,
        navigate_hours,
        plan_only: false,
        encoders: true,
    };
    let out = interruptible(py, move |stop| -> Result<Output, Failure> {
        let report = execute(&SelfcalRequest { input, recording: Some(recording(save, stop)), json: None }, stop)?;
        let mut json = report.document;
        json["table"] = serde_json::Value::String(report.text);
        output(json, report.saved.unwrap_or_default())
    })??;
    Ok(to_python(py, out))
}

/// Writes `text` to `path` as every output of the library is written (`PATH.partial`, renamed when
/// complete; a FIFO, a device, a folder or a missing folder refused): OSError naming the path.
#[pyfunction]
fn write_atomically(path: PathBuf, text: &str) -> PyResult<()> {
    rinscope::io::files::write_atomically(&path, text.as_bytes()).map_err(|e| PyOSError::new_err(e.to_string()))
}

/// Checks that a saved recording is complete (header, footer, checksum).
#[pyfunction]
fn verify_recording(path: PathBuf) -> PyResult<()> {
    sink::verify_recording(&path).map_err(PyValueError::new_err)
}

/// The `rinscope` command itself on `argv` (the program's name first); its exit code. Runs with
/// the GIL released, and with the command's own signal handling (the caller resets Python's).
#[pyfunction]
fn cli(py: Python<'_>, argv: Vec<String>) -> u8 {
    py.detach(|| rinscope::cli::main_with(argv))
}

#[pymodule]
fn _rinscope(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("RERUN_VERSION", "0.36.3")?;
    m.add("VERSION", env!("CARGO_PKG_VERSION"))?;
    m.add("DEFAULT_SCENARIO", presets::DEFAULT_SCENARIO)?;
    // The presets' names without loading them (scenarios() validates each for its title).
    m.add("PRESETS", presets::PRESETS.iter().map(|(name, _)| *name).collect::<Vec<_>>())?;
    m.add_function(wrap_pyfunction!(scenarios, m)?)?;
    m.add_function(wrap_pyfunction!(preset_toml, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(toml_to_json, m)?)?;
    m.add_function(wrap_pyfunction!(json_to_toml, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(replay, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(allan, m)?)?;
    m.add_function(wrap_pyfunction!(montecarlo, m)?)?;
    m.add_function(wrap_pyfunction!(selfcal, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(budget, m)?)?;
    m.add_function(wrap_pyfunction!(schemes, m)?)?;
    m.add_function(wrap_pyfunction!(design, m)?)?;
    m.add_function(wrap_pyfunction!(verify_recording, m)?)?;
    m.add_function(wrap_pyfunction!(write_atomically, m)?)?;
    m.add_function(wrap_pyfunction!(cli, m)?)?;
    m.add_function(wrap_pyfunction!(_time_run, m)?)?;
    Ok(())
}
