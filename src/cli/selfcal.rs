//! `rinscope selfcal`: the IMU's self-calibration on its own gimbals, simulated or from a log set
//! (the orchestration is `app::selfcal`, the estimator `ins::selfcal`).

use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

use super::commands::{check_output_dir, default_recording, open_sinks, print_saved, write_json};
use super::{Failure, SelfcalArgs};
use crate::app::terminate::stop_flag;

/// `rinscope selfcal`.
pub(super) fn selfcal(args: &SelfcalArgs) -> Result<(), Failure> {
    use crate::app::selfcal::{self as sc, SequenceChoice};
    if let Some(dir) = &args.log {
        return selfcal_log(args, dir);
    }
    // Every argument is checked before anything runs.
    sc::check_navigate_hours(args.navigate_hours).map_err(|e| Failure::input(format!("--navigate-hours {e}")))?;
    let params = args.source.load("selfcal-nav-grade")?;
    check_output_dir("--json", args.json.as_deref())?;
    let choice = SequenceChoice::parse(&args.sequence).map_err(|e| Failure::input(format!("--sequence {e}")))?;
    let setup = sc::setup(&params, choice).map_err(|e| Failure::input(format!("{e:#}")))?;
    let stop = stop_flag();
    let interrupted = |e: anyhow::Error| if stop.load(Ordering::SeqCst) { Failure::interrupted("nothing was estimated") } else { Failure::run(format!("selfcal: {e:#}")) };
    let plan = sc::plan(&setup, params.meta.seed, &stop).map_err(interrupted)?;
    if args.plan || !plan.unobservable.is_empty() || !plan.weak.is_empty() {
        let list = |v: &Vec<String>| if v.is_empty() { "none".to_owned() } else { v.join(", ") };
        errln!("rinscope selfcal: plan for {}: not observable: {}; weakly observable: {}", setup.sequence, list(&plan.unobservable), list(&plan.weak));
        for a in &plan.aliased {
            errln!("rinscope selfcal: aliased: {a}");
        }
    }
    if args.plan {
        if let Some(path) = &args.json {
            write_json("--json", path, &serde_json::json!({ "sequence": setup.sequence, "observability": plan }))?;
        }
        return Ok(());
    }
    let sinks = if args.no_recording {
        None
    } else {
        let request = args.sinks.request(default_recording(&format!("{}-selfcal", params.meta.name)))?;
        Some(open_sinks(request, &format!("{}-selfcal-seed{}", params.meta.name, params.meta.seed))?)
    };
    // The IMU's calibration, the Monte Carlo and the free-inertial comparison; on a failure the
    // recording is abandoned once, whichever step failed.
    let report = match sc::calibrate(&params, setup, plan, args.monte_carlo.map(|n| n as usize), args.navigate_hours, &stop) {
        Ok(r) => r,
        Err(e) => {
            if let Some(s) = sinks {
                s.abandon();
            }
            return Err(interrupted(e));
        }
    };
    out!("{}", report.table);
    if let Some(sinks) = sinks {
        record(sinks, &report.view(&params.meta.name))?;
    }
    if let Some(path) = &args.json {
        write_json("--json", path, &report.json())?;
    }
    Ok(())
}

/// `rinscope selfcal --log DIR`.
fn selfcal_log(args: &SelfcalArgs, dir: &Path) -> Result<(), Failure> {
    use crate::app::selfcal as sc;
    let log = crate::scenario::logset::load(dir)?;
    check_output_dir("--json", args.json.as_deref())?;
    let stop = stop_flag();
    let (estimate, estimation_s) = sc::run_log(&log, &stop).map_err(|e| if stop.load(Ordering::SeqCst) { Failure::interrupted("nothing was estimated") } else { Failure::input(format!("selfcal --log: {e:#}")) })?;
    let seen = crate::ins::selfcal::observability(&estimate);
    let hours = estimate.history.last().map_or(0.0, |r| r.t_s) / 3600.0;
    let head = format!("self-calibration of the log set {}: {hours:.2} h at {:.0} Hz; estimated in {estimation_s:.2} s (no truth: a log)", dir.display(), log.imu.rate_hz);
    let table = sc::estimates_table(format!("{head}\n\n"), &estimate, None, &seen, &[], None);
    out!("{table}");
    if let Some(path) = &args.json {
        let names = crate::ins::selfcal::param_names();
        write_json("--json", path, &serde_json::json!({ "log": dir.display().to_string(), "parameters": names, "units": sc::JSON_UNITS, "estimate": estimate.params, "sigma": estimate.sigma, "estimation_s": estimation_s, "observability": seen }))?;
    }
    if !args.no_recording {
        let sinks = open_sinks(args.sinks.request(PathBuf::from("recordings").join(format!("{}-selfcal.rrd", log.name)))?, &format!("{}-selfcal", log.name))?;
        let view = crate::record::selfcal::SelfcalView {
            title: format!("log set {}", log.name),
            document: &sc::estimates_document(&head, &estimate, None, &seen, &[], None),
            history: &estimate.history,
            prior: &estimate.prior,
            truth: None,
            move_starts_s: &[],
            attitude: &[],
            navigation: Vec::new(),
        };
        record(sinks, &view)?;
    }
    Ok(())
}

/// Logs `view` into `sinks` and says where the recording is; on a failure the partial file goes.
fn record(sinks: crate::record::sink::OpenSinks, view: &crate::record::selfcal::SelfcalView<'_>) -> Result<(), Failure> {
    if let Err(e) = crate::record::selfcal::log(&sinks.stream(), view) {
        sinks.abandon();
        return Err(Failure::run(format!("rerun: {e}")));
    }
    print_saved(&sinks.finish()?)
}
