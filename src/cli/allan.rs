//! `rinscope allan`: the Allan deviation of a static IMU log, simulated from a scenario or read
//! from a log set, with the IEEE coefficients fitted (docs/allan.md).

use super::commands::{print_saved, print_tables};
use super::{AllanArgs, Failure};
use crate::app::allan::{self, AllanCommand, AllanExport, AllanRequest, AllanSource};
use crate::app::terminate::stop_flag;
use crate::io::Col;
use crate::io::imu::series::{Sampling, SeriesColumn};
use crate::io::imu::units::{Quantity, unit_named};
use crate::math::allan::TauSpacing;
use crate::math::allan::estimators::Estimator;
use crate::scenario::logset;

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

/// `rinscope allan`.
pub(super) fn allan(args: &AllanArgs) -> Result<(), Failure> {
    if args.errors_only && args.dir.is_some() {
        return Err(Failure::input(
            "allan: --errors-only needs the truth, which only a simulation has (give --scenario or --config)",
        ));
    }
    let spacing = match (&args.taus, args.per_decade) {
        (Some(t), _) => parse_taus(t)?,
        (None, Some(n)) => {
            parse_taus(&n.to_string()).map_err(|e| Failure::input(e.message.replace("--taus", "--per-decade")))?
        }
        (None, None) => TauSpacing::Octave,
    };
    let analysis = AllanRequest {
        spacing,
        estimators: parse_estimators(&args.estimator)?,
        decimate: args.decimate,
        ci_sigma: args.ci_sigma,
        errors_only: args.errors_only,
    };
    let source = match (&args.dir, &args.series) {
        (_, Some(file)) => {
            let columns = args
                .column
                .iter()
                .map(|c| SeriesColumn::parse(c).map_err(|e| Failure::input(format!("allan: {e}"))))
                .collect::<Result<Vec<_>, _>>()?;
            let sampling = match (&args.time_column, args.rate_hz) {
                (Some(t), _) => {
                    let (col, unit) = t.rsplit_once(':').map_or((t.as_str(), "s"), |(c, u)| (c, u));
                    let unit = unit_named(unit).filter(|u| u.quantity == Quantity::Time).ok_or_else(|| {
                        Failure::input(format!(
                            "allan: --time-column {t:?}: {unit:?} is not a unit of time (s, ms, us, ns)"
                        ))
                    })?;
                    Sampling::TimeColumn(
                        col.parse::<usize>().map_or_else(|_| Col::Name(col.to_owned()), Col::Index),
                        unit,
                    )
                }
                (None, Some(hz)) => Sampling::RateHz(hz),
                (None, None) => {
                    return Err(Failure::input(
                        "allan: --series needs the sampling: --rate-hz HZ or --time-column COLUMN[:UNIT]",
                    ));
                }
            };
            AllanSource::Series(file.clone(), columns, sampling, args.column.join(", "))
        }
        (Some(dir), None) => AllanSource::Log(Box::new(logset::load_imu(dir)?)),
        (None, None) => {
            let mut params = args.source.load(DEFAULT_SCENARIO)?;
            if let Some(d) = args.duration_s {
                params.set_duration(d); // held to `scenario::DURATION` by the parser
            }
            AllanSource::Scenario(Box::new(params))
        }
    };
    let recording = if args.no_recording { None } else { Some(args.sinks.recording()?) };
    let command = AllanCommand {
        source,
        analysis,
        recording,
        export: args.sinks.export_request()?.map(|(dir, format)| AllanExport::Dir(dir, format)),
        json: args.json.clone(),
    };
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
    let report = allan::execute(command, &stop_flag(), &progress);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let report = report?;
    out!("{}", report.result.text());
    outln!(
        "({:.1} s gathering the samples, {:.2} s for the analysis)",
        report.result.gather_s,
        report.result.analysis_s
    );
    print_tables(&report.exported);
    if let Some(saved) = &report.saved {
        print_saved(saved);
    }
    if report.interrupted {
        return Err(Failure::interrupted("the analysis above is of the part of the log gathered before the stop"));
    }
    Ok(())
}
