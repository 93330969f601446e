//! `allan`'s one owner: what the command line asks for (a scenario simulated, a log set, a
//! series file), the outputs checked up front, the analysis, its document, tables and recording.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use super::{AllanRequest, analyze_series, check_scenario, log_set, options, series, simulate};
use crate::app::failure::Failure;
use crate::app::outputs::{RecordingName, RecordingRequest, check_output, finish, logged, write_json};
use crate::ins::allan::ImuAllan;
use crate::io::imu::series::{Sampling, SeriesColumn};
use crate::record::export::{ExportFormat, Exporter, Table};
use crate::record::sink::Saved;
use crate::scenario::Params;
use crate::scenario::logset::LogSet;

/// What `allan` analyses.
pub enum AllanSource {
    /// A log set's IMU file.
    Log(Box<LogSet>),
    /// A scenario's static IMU, simulated.
    Scenario(Box<Params>),
    /// Any table file's columns (and how they were given, for the recording's description).
    Series(PathBuf, Vec<SeriesColumn>, Sampling, String),
    /// Columns already in memory (Python's arrays), with the recording's description.
    Arrays(Box<crate::io::imu::series::Series>, String),
}

/// Where `allan`'s tables go.
pub enum AllanExport {
    /// `--export DIR`: files of `format`.
    Dir(PathBuf, ExportFormat),
    /// Kept in memory and returned in the report (Python's DataFrames).
    Memory,
}

/// `rinscope allan`.
pub struct AllanCommand {
    /// What to analyse.
    pub source: AllanSource,
    /// How (estimators, cluster times, decimation, confidence).
    pub analysis: AllanRequest,
    /// The recording's sinks (its `export` is ignored: the curves are exported as tables of
    /// their own); `None`: no recording.
    pub recording: Option<RecordingRequest>,
    /// The curves and the fits as tables.
    pub export: Option<AllanExport>,
    /// `--json`.
    pub json: Option<PathBuf>,
}

/// What `allan` reports.
pub struct AllanReport {
    /// The analysis.
    pub result: ImuAllan,
    /// The tables `--export` wrote.
    pub exported: Vec<PathBuf>,
    /// The tables kept in memory ([`AllanExport::Memory`]).
    pub tables: Vec<Table>,
    /// The recording kept.
    pub saved: Option<Saved>,
    /// Stopped early: the analysis is of the part gathered before the stop.
    pub interrupted: bool,
}

/// `allan`'s one owner. `progress` is told how many samples were gathered so far.
///
/// # Errors
/// Bad input or data, an output that cannot be written.
pub fn execute(req: AllanCommand, stop: &AtomicBool, progress: &dyn Fn(u64)) -> Result<AllanReport, Failure> {
    check_output("--json", req.json.as_deref())?;
    options(&req.analysis)?;
    let (name, description) = match &req.source {
        AllanSource::Series(file, _, _, given) => (
            file.file_stem().map_or_else(|| "series".to_owned(), |s| s.to_string_lossy().into_owned()),
            format!("Series `{}`, columns {given}.", file.display()),
        ),
        AllanSource::Log(log) => (log.name.clone(), log.description.clone()),
        AllanSource::Arrays(_, description) => ("arrays".to_owned(), description.clone()),
        AllanSource::Scenario(p) => {
            check_scenario(p)?;
            (p.meta.name.clone(), format!("*{}*\n\n{}", p.meta.title, p.meta.description))
        }
    };
    let mut exporter = match &req.export {
        None => None,
        Some(AllanExport::Dir(dir, format)) => {
            Some(Exporter::new(dir, *format).map_err(|e| Failure::input(format!("--export {}: {e}", dir.display())))?)
        }
        Some(AllanExport::Memory) => Some(Exporter::in_memory()),
    };
    let sinks = match &req.recording {
        None => None,
        Some(r) => {
            let mut r = r.clone();
            r.sinks.export = None;
            Some(r.open(RecordingName { name: &name, kind: Some("allan"), seed: None })?)
        }
    };
    let result = match req.source {
        AllanSource::Arrays(data, _) => analyze_series(*data, "arrays from Python", &req.analysis, 0.0),
        AllanSource::Log(log) => {
            errln!("rinscope: reading {} ...", log.imu.path.display());
            log_set(&log, &req.analysis, stop, progress)
        }
        AllanSource::Series(file, columns, sampling, _) => {
            errln!("rinscope: reading {} ...", file.display());
            series(&file, &columns, &sampling, &req.analysis, stop)
        }
        AllanSource::Scenario(p) => {
            errln!(
                "rinscope: simulating {:.2} h of {} at {} Hz, then the Allan analysis of 6 channels ...",
                p.duration_s / 3600.0,
                p.meta.name,
                p.step_hz
            );
            simulate(&p, &req.analysis, stop, progress)
        }
    }?;
    if let Some(path) = &req.json {
        write_json("--json", path, &result.json())?;
    }
    let (exported, tables) = match exporter.as_mut() {
        Some(e) => {
            let done = crate::record::allan::export(e, &result)
                .and_then(|()| e.finish())
                .map_err(|e| Failure::run(format!("--export: {e}")))?;
            (done.files, done.tables)
        }
        None => (Vec::new(), Vec::new()),
    };
    let saved = match sinks {
        Some(s) => {
            logged(crate::record::allan::log(&s.stream(), &result, &description))?;
            Some(finish(s)?)
        }
        None => None,
    };
    let interrupted = result.interrupted || stop.load(Ordering::SeqCst);
    Ok(AllanReport { result, exported, tables, saved, interrupted })
}
