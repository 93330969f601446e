//! `rinscope allan`: the Allan deviation of a static IMU log, simulated from a scenario or read
//! from a log set, with the IEEE coefficients fitted (docs/allan.md).

use std::sync::atomic::Ordering;

use super::commands::{check_output_dir, default_recording, open_sinks, print_saved, print_tables, write_json};
use super::{AllanArgs, Failure};
use crate::app::allan::{self, AllanRequest, AllanRunError};
use crate::app::terminate::stop_flag;
use crate::record::export::Exporter;
use crate::io::series::{Sampling, SeriesColumn};
use crate::io::units::{unit_named, Quantity};
use crate::io::Col;
use crate::math::allan::estimators::Estimator;
use crate::math::allan::TauSpacing;
use crate::scenario::{self, logset};
use std::path::PathBuf;

/// `--taus`.
fn parse_taus(text: &str) -> Result<TauSpacing, Failure> {
    allan::parse_taus(text).map_err(|e| Failure::input(format!("allan: --taus {e}")))
}

/// `--estimator`.
fn parse_estimators(text: &str) -> Result<Vec<Estimator>, Failure> {
    allan::parse_estimators(text).map_err(|e| Failure::input(format!("allan: --estimator {e}")))
}

/// The preset `rinscope allan` simulates when given neither a log set nor a scenario.
const DEFAULT_SCENARIO: &str = "static-imu-10h";

impl From<AllanRunError> for Failure {
    fn from(e: AllanRunError) -> Self {
        match e {
            // Every channel error is of the data: too few samples, a non-finite value, a bad rate.
            AllanRunError::Config(_) | AllanRunError::Data(_) | AllanRunError::Analysis(_) => Self::input(format!("allan: {e}")),
            AllanRunError::Interrupted(_) => Self::interrupted(format!("allan: {e}")),
        }
    }
}

/// `rinscope allan`.
pub(super) fn allan(args: &AllanArgs) -> Result<(), Failure> {
    check_output_dir("--json", args.json.as_deref())?;
    if args.errors_only && args.dir.is_some() {
        return Err(Failure::input("allan: --errors-only needs the truth, which only a simulation has (give --scenario or --config)"));
    }
    let spacing = match (&args.taus, args.per_decade) {
        (Some(t), _) => parse_taus(t)?,
        (None, Some(n)) => parse_taus(&n.to_string()).map_err(|e| Failure::input(e.message.replace("--taus", "--per-decade")))?,
        (None, None) => TauSpacing::Octave,
    };
    let request = AllanRequest { spacing, estimators: parse_estimators(&args.estimator)?, decimate: args.decimate, ci_sigma: args.ci_sigma, errors_only: args.errors_only };
    allan::options(&request)?;
    enum Source {
        Log(Box<logset::LogSet>),
        Scenario(Box<scenario::Params>),
        Series(PathBuf, Vec<SeriesColumn>, Sampling),
    }
    let (source, name, description) = match (&args.dir, &args.series) {
        (_, Some(file)) => {
            let columns = args.column.iter().map(|c| SeriesColumn::parse(c).map_err(|e| Failure::input(format!("allan: {e}")))).collect::<Result<Vec<_>, _>>()?;
            let sampling = match (&args.time_column, args.rate_hz) {
                (Some(t), _) => {
                    let (col, unit) = t.rsplit_once(':').map_or((t.as_str(), "s"), |(c, u)| (c, u));
                    let unit = unit_named(unit).filter(|u| u.quantity == Quantity::Time).ok_or_else(|| Failure::input(format!("allan: --time-column {t:?}: {unit:?} is not a unit of time (s, ms, us, ns)")))?;
                    Sampling::TimeColumn(col.parse::<usize>().map_or_else(|_| Col::Name(col.to_owned()), Col::Index), unit)
                }
                (None, Some(hz)) => Sampling::RateHz(hz),
                (None, None) => return Err(Failure::input("allan: --series needs the sampling: --rate-hz HZ or --time-column COLUMN[:UNIT]")),
            };
            let stem = file.file_stem().map_or_else(|| "series".to_owned(), |s| s.to_string_lossy().into_owned());
            let description = format!("Series `{}`, columns {}.", file.display(), args.column.join(", "));
            (Source::Series(file.clone(), columns, sampling), stem, description)
        }
        (Some(dir), None) => {
            let log = logset::load_imu(dir)?;
            let (name, description) = (log.name.clone(), log.description.clone());
            (Source::Log(Box::new(log)), name, description)
        }
        (None, None) => {
            let mut params = args.source.load(DEFAULT_SCENARIO)?;
            if let Some(d) = args.duration_s {
                params.set_duration(super::commands::duration_flag(d)?);
            }
            allan::check_scenario(&params)?;
            let (name, description) = (params.meta.name.clone(), format!("*{}*\n\n{}", params.meta.title, params.meta.description));
            (Source::Scenario(Box::new(params)), name, description)
        }
    };
    // --export: the curves and the fits as tables (written here, not from the recording's series).
    let mut exporter = match args.sinks.export_request()? {
        None => None,
        Some((dir, format)) => Some(Exporter::new(&dir, format).map_err(|e| Failure::input(format!("--export {}: {e}", dir.display())))?),
    };
    let sinks = if args.no_recording {
        None
    } else {
        let mut request = args.sinks.request(default_recording(&format!("{name}-allan")))?;
        request.export = None;
        Some(open_sinks(request, &format!("{name}-allan"))?)
    };
    let stop = stop_flag();
    let bar = std::io::IsTerminal::is_terminal(&std::io::stderr()).then(|| {
        let bar = indicatif::ProgressBar::new_spinner();
        bar.enable_steady_tick(std::time::Duration::from_millis(200));
        bar
    });
    let progress = |n: u64| {
        if let Some(b) = &bar {
            b.set_message(format!("{:.2} M samples gathered", n as f64 / 1e6));
        }
    };
    let result = match &source {
        Source::Log(log) => {
            errln!("rinscope: reading {} ...", log.imu.path.display());
            allan::log_set(log, &request, &stop, &progress)
        }
        Source::Series(file, columns, sampling) => {
            errln!("rinscope: reading {} ...", file.display());
            allan::series(file, columns, sampling, &request, &stop)
        }
        Source::Scenario(p) => {
            errln!("rinscope: simulating {:.2} h of {} at {} Hz, then the Allan analysis of 6 channels ...", p.duration_s / 3600.0, p.meta.name, p.step_hz);
            allan::simulate(p, &request, &stop, &progress)
        }
    };
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let result = match result {
        Ok(r) => r,
        Err(e) => {
            if let Some(s) = sinks {
                s.abandon();
            }
            return Err(e.into());
        }
    };
    out!("{}", result.text());
    outln!("({:.1} s gathering the samples, {:.2} s for the analysis)", result.gather_s, result.analysis_s);
    if let Some(path) = &args.json {
        write_json("--json", path, &result.json())?;
    }
    if let Some(e) = exporter.as_mut() {
        let written = crate::record::allan::export(e, &result).and_then(|()| e.finish()).map_err(|e| Failure::run(format!("--export: {e}")))?.files;
        print_tables(&written);
    }
    if let Some(sinks) = sinks {
        if let Err(e) = crate::record::allan::log(&sinks.stream(), &result, &description) {
            sinks.abandon();
            return Err(Failure::run(format!("rerun: {e}")));
        }
        print_saved(&sinks.finish()?)?;
    }
    if result.interrupted || stop.load(Ordering::SeqCst) {
        return Err(Failure::interrupted("the analysis above is of the part of the log gathered before the stop"));
    }
    Ok(())
}
