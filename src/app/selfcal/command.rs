//! `selfcal`'s one owner: what the command line and Python both ask for, the outputs checked up
//! front, the estimate, its document and its recording.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use super::{
    JSON_UNITS, SequenceChoice, calibrate, check_navigate_hours, estimates_document, estimates_table, plan, run_log,
    setup,
};
use crate::app::failure::Failure;
use crate::app::outputs::{RecordingName, RecordingRequest, check_output, finish, logged, read_small_file, write_json};
use crate::record::selfcal::SelfcalView;
use crate::record::sink::Saved;
use crate::scenario::Params;
use crate::scenario::logset::LogSet;

/// What `selfcal` calibrates.
pub enum SelfcalInput {
    /// A scenario's IMU on its gimbals, simulated.
    Scenario {
        /// The scenario.
        params: Box<Params>,
        /// The sequence.
        sequence: SequenceChoice,
        /// Also this many random IMUs.
        monte_carlo: Option<usize>,
        /// The free-inertial comparison's length, h (0: none).
        navigate_hours: f64,
        /// Only the plan (what the sequence can see).
        plan_only: bool,
        /// The encoders measure the table (false: the IMU alone).
        encoders: bool,
    },
    /// A log set of a sequence run on a real table.
    Log(Box<LogSet>),
    /// One shard of a scenario's Monte Carlo (a cluster's array task): its runs only, written to
    /// `--json` for [`SelfcalInput::Merge`].
    Shard {
        /// The scenario.
        params: Box<Params>,
        /// The sequence.
        sequence: SequenceChoice,
        /// The encoders measure the table.
        encoders: bool,
        /// Runs of the whole Monte Carlo.
        runs: usize,
        /// This slice of them.
        shard: crate::calib::montecarlo::Shard,
    },
    /// The shards' files of one Monte Carlo, merged.
    Merge(Vec<PathBuf>),
}

/// `rinscope selfcal` (and Python's `selfcal`).
pub struct SelfcalRequest {
    /// What to calibrate.
    pub input: SelfcalInput,
    /// The recording's sinks; `None`: no recording.
    pub recording: Option<RecordingRequest>,
    /// `--json`.
    pub json: Option<PathBuf>,
}

/// What `selfcal` reports.
pub struct SelfcalReport {
    /// The result as a user reads it (empty for a plan).
    pub text: String,
    /// The `--json` document.
    pub document: serde_json::Value,
    /// The recording kept.
    pub saved: Option<Saved>,
}

/// `selfcal`'s one owner.
///
/// # Errors
/// Bad input, an output that cannot be written, a stop before anything was estimated.
pub fn execute(req: &SelfcalRequest, stop: &AtomicBool) -> Result<SelfcalReport, Failure> {
    check_output("--json", req.json.as_deref())?;
    let interrupted = |command: &str, e: anyhow::Error| {
        if stop.load(Ordering::SeqCst) {
            Failure::interrupted("nothing was estimated")
        } else {
            Failure::run(format!("{command}: {e:#}"))
        }
    };
    let (text, document, view_of) = match &req.input {
        SelfcalInput::Shard { params, sequence, encoders, runs, shard } => {
            if req.json.is_none() {
                return Err(Failure::input("--shard writes its runs to the file --json names: give --json FILE"));
            }
            let setup = setup(params, *sequence, *encoders).map_err(|e| Failure::input(format!("{e:#}")))?;
            let done = super::monte_carlo_runs(&setup, *runs, params.meta.seed + 1, *shard, stop)
                .map_err(|e| interrupted("selfcal", e))?;
            let parameters = crate::calib::selfcal::names_with(setup.table_states.as_ref().map(|t| &t.states));
            let file = super::ShardFile {
                shard: *shard,
                scenario: params.meta.name.clone(),
                seed: params.meta.seed,
                sequence: setup.sequence.clone(),
                runs_requested: *runs,
                parameters,
                runs: done,
            };
            let text = format!(
                "selfcal Monte Carlo shard {}/{}: {} of {} runs of {} on {}\n",
                shard.index,
                shard.count,
                file.runs.len(),
                runs,
                file.scenario,
                file.sequence
            );
            let document = serde_json::to_value(&file).map_err(|e| Failure::run(format!("selfcal: {e}")))?;
            (text, document, None)
        }
        SelfcalInput::Merge(files) => {
            let mut shards = Vec::new();
            for f in files {
                let text = read_small_file(f, "shard file")?;
                shards.push(serde_json::from_str::<super::ShardFile>(&text).map_err(|e| {
                    Failure::input(format!(
                        "{}: not a shard file of `rinscope selfcal --monte-carlo N --shard K/M --json` ({e})",
                        f.display()
                    ))
                })?);
            }
            let (mc, first) =
                super::merge_shards(&shards).map_err(|e| Failure::input(format!("selfcal --merge: {e:#}")))?;
            let text = format!(
                "{} on {} (seed {}):\n{}",
                first.scenario,
                first.sequence,
                first.seed,
                super::monte_carlo_table(&first.parameters, &mc)
            );
            let document = serde_json::json!({ "scenario": first.scenario, "seed": first.seed, "sequence": first.sequence, "parameters": first.parameters, "units": JSON_UNITS, "monte_carlo": mc });
            (text, document, None)
        }
        SelfcalInput::Scenario { params, sequence, monte_carlo, navigate_hours, plan_only, encoders } => {
            check_navigate_hours(*navigate_hours).map_err(|e| Failure::input(format!("--navigate-hours {e}")))?;
            let setup = setup(params, *sequence, *encoders).map_err(|e| Failure::input(format!("{e:#}")))?;
            let plan = plan(&setup, params.meta.seed, stop).map_err(|e| interrupted("selfcal", e))?;
            if *plan_only || !plan.unobservable.is_empty() || !plan.weak.is_empty() {
                let list = |v: &Vec<String>| if v.is_empty() { "none".to_owned() } else { v.join(", ") };
                errln!(
                    "rinscope selfcal: plan for {}: not observable: {}; weakly observable: {}",
                    setup.sequence,
                    list(&plan.unobservable),
                    list(&plan.weak)
                );
                for a in &plan.aliased {
                    errln!("rinscope selfcal: aliased: {a}");
                }
            }
            if *plan_only {
                let document = serde_json::json!({ "sequence": setup.sequence, "observability": plan });
                if let Some(path) = &req.json {
                    write_json("--json", path, &document)?;
                }
                return Ok(SelfcalReport { text: String::new(), document, saved: None });
            }
            let sinks = req
                .recording
                .as_ref()
                .map(|r| {
                    r.open(RecordingName {
                        name: &params.meta.name,
                        kind: Some("selfcal"),
                        seed: Some(params.meta.seed),
                    })
                })
                .transpose()?;
            // The IMU's calibration, the Monte Carlo and the free-inertial comparison; on a
            // failure the sinks are dropped unfinished (abandoned).
            let report = calibrate(params, setup, plan, *monte_carlo, *navigate_hours, stop)
                .map_err(|e| interrupted("selfcal", e))?;
            let saved = match sinks {
                Some(s) => {
                    logged(crate::record::selfcal::log(&s.stream(), &report.view(&params.meta.name)))?;
                    Some(finish(s)?)
                }
                None => None,
            };
            (report.table.clone(), report.json(), saved)
        }
        SelfcalInput::Log(log) => {
            let sinks = req
                .recording
                .as_ref()
                .map(|r| r.open(RecordingName { name: &log.name, kind: Some("selfcal"), seed: None }))
                .transpose()?;
            let super::Estimation { estimate, estimation_s, shafts } = run_log(log, stop).map_err(|e| {
                if stop.load(Ordering::SeqCst) {
                    Failure::interrupted("nothing was estimated")
                } else {
                    Failure::input(format!("selfcal --log: {e:#}"))
                }
            })?;
            let seen = crate::calib::selfcal::observability(&estimate);
            let hours = estimate.history.last().map_or(0.0, |r| r.t_s) / 3600.0;
            let head = format!(
                "self-calibration of the log set {}: {hours:.2} h at {:.0} Hz; estimated in {estimation_s:.2} s (no truth: a log)",
                log.dir.display(),
                log.imu.rate_hz
            );
            let text = estimates_table(format!("{head}\n\n"), &estimate, None, &seen, &[], None, None);
            let names = estimate.names();
            // A parameter the log's motion does not separate is reported as not observable: no
            // estimate, no 1σ (null), never the prior's number or the noise's.
            let hidden = |k: usize| seen.unobservable.contains(&names[k]);
            let shown =
                |v: &[f64]| -> Vec<Option<f64>> { (0..v.len()).map(|k| (!hidden(k)).then_some(v[k])).collect() };
            let mut document = serde_json::json!({ "log": log.dir.display().to_string(), "parameters": names, "units": JSON_UNITS, "estimate": shown(&estimate.all_params()), "sigma": shown(&estimate.all_sigma()), "estimation_s": estimation_s, "observability": seen, "estimated_imu_compensation": super::imu_compensation(&estimate, &seen.unobservable) });
            if let Some(table) = super::table_compensation(&estimate, &seen.unobservable) {
                document["estimated_compensation"] = table;
            }
            // The table's states, if its encoders were read (the recording draws the tables).
            let states = estimate
                .table
                .as_ref()
                .and_then(|_| crate::calib::selfcal_table::TableStates::new(&log.table.chain).ok());
            let saved = match sinks {
                Some(s) => {
                    let view = SelfcalView {
                        title: format!("log set {}", log.name),
                        document: &estimates_document(&head, &estimate, None, &seen, &[], None, None),
                        history: &estimate.history,
                        names: estimate.names(),
                        prior: estimate.all_prior(),
                        truth: None,
                        move_starts_s: &[],
                        attitude: &[],
                        tables: states
                            .as_ref()
                            .map(|states| crate::record::selfcal::TableGhosts { states, shafts: &shafts }),
                        navigation: Vec::new(),
                    };
                    logged(crate::record::selfcal::log(&s.stream(), &view))?;
                    Some(finish(s)?)
                }
                None => None,
            };
            (text, document, saved)
        }
    };
    if let Some(path) = &req.json {
        write_json("--json", path, &document)?;
    }
    Ok(SelfcalReport { text, document, saved: view_of })
}
