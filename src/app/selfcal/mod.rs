//! `rinscope selfcal`: the scenario's table turns its IMU through a calibration sequence, the
//! simulated IMU (with the scenario's errors) feeds the self-calibration filter
//! ([`crate::calib::selfcal`]), and the estimates are compared with the drawn truth; the plan (what
//! the sequence can see) is computed before, on the sequence's noise-free motion; a Monte Carlo
//! over random IMUs checks the reported 1σ against the spread.

mod command;
mod log;
mod montecarlo;
mod tables;
pub use command::{SelfcalInput, SelfcalReport, SelfcalRequest, execute};
pub use log::{LOG_ALIGN_S, run_log};
pub use montecarlo::{McRun, MonteCarlo, ShardFile, merge_shards, monte_carlo, monte_carlo_runs};
use tables::head;
pub use tables::{estimates_document, estimates_table, monte_carlo_table, table, target};

use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Result, anyhow, bail};
use rayon::prelude::*;

use crate::calib::selfcal::{self, Config, Estimate, ImuErrors, Kind, SelfCal, Sequence, TableConfig};
use crate::calib::selfcal_table::TableStates;
use crate::ins::sensor::ImuErrorSpec;
use crate::ins::truth::TruthImu;
use crate::model::earth::Earth;
use crate::model::scheme::AxisValues;
use crate::model::scheme::Scheme;
use crate::scenario::Params;
use crate::sim::{Model, TableParams};

/// Where the sequence comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SequenceChoice {
    /// A built-in.
    BuiltIn(Sequence),
    /// The scenario's own indexed `[scheme]`, for `simulation.duration_s`.
    Scenario,
}

impl SequenceChoice {
    /// A sequence by its name (`dual-axis-29`, `positions-19`, `azimuth-only`) or `scenario`.
    ///
    /// # Errors
    /// Any other name, with the list.
    pub fn parse(name: &str) -> std::result::Result<Self, String> {
        match name {
            "scenario" => Ok(Self::Scenario),
            name => Sequence::named(name).map(Self::BuiltIn).ok_or_else(|| {
                let names: Vec<&str> = Sequence::ALL.iter().map(|(_, n)| *n).collect();
                format!("{name}: not a sequence; use one of {names:?} or \"scenario\"")
            }),
        }
    }
}

/// How many random IMUs a self-calibration's Monte Carlo may take (`--monte-carlo`): a spread
/// needs two.
pub const MONTE_CARLO_RUNS: std::ops::RangeInclusive<u64> = 2..=10_000;

/// Checks the hours of free-inertial comparison asked for (`--navigate-hours`: 0 skips it).
///
/// # Errors
/// Not finite, negative, or over 720 h.
pub fn check_navigate_hours(hours: f64) -> std::result::Result<f64, String> {
    crate::io::validity::check_number(hours, &NAVIGATE_HOURS)
}

/// The free-inertial comparison's length, h: 0 (skip) to 30 days.
pub const NAVIGATE_HOURS: crate::io::validity::Range =
    crate::io::validity::Range::closed(0.0, 720.0, "h", "a navigation time (0 skips it)");

/// What the documents say of their numbers' units.
pub const JSON_UNITS: &str = "SI (rad/s, m/s², dimensionless gains)";

/// A simulated self-calibration, whole: the plan, the estimate, the Monte Carlo and the
/// free-inertial comparison, with the table the terminal prints ([`calibrate`]).
pub struct Report {
    /// The setup.
    pub setup: Setup,
    /// The plan: what the sequence's noise-free motion lets the filter see.
    pub plan: selfcal::Observability,
    /// The estimate of the scenario's IMU.
    pub outcome: Outcome,
    /// The Monte Carlo, if asked for.
    pub monte_carlo: Option<MonteCarlo>,
    /// The free-inertial comparison (empty if not asked for).
    pub navigation: Vec<NavRow>,
    /// The result as the terminal prints it.
    pub table: String,
    /// The result as the recording's document shows it (markdown).
    pub document: String,
}

/// The plan of `setup`: its noise-free motion through the same filter (its 1σ depend on the
/// motion only), before any IMU is drawn.
///
/// # Errors
/// Stopped, or the filter failed.
pub fn plan(setup: &Setup, seed: u64, stop: &AtomicBool) -> Result<selfcal::Observability> {
    Ok(selfcal::observability(&run_one(setup, seed, true, stop)?.estimate))
}

/// Self-calibrates `p`'s IMU on `setup` with its `plan`, then `monte_carlo` runs and
/// `navigate_hours` of free-inertial comparison (0: none).
///
/// # Errors
/// Stopped, or a run failed.
pub fn calibrate(
    p: &Params,
    setup: Setup,
    plan: selfcal::Observability,
    monte_carlo: Option<usize>,
    navigate_hours: f64,
    stop: &AtomicBool,
) -> Result<Report> {
    let outcome = run_one(&setup, p.meta.seed, false, stop)?;
    let monte_carlo = monte_carlo.map(|n| self::monte_carlo(&setup, n, p.meta.seed + 1, stop)).transpose()?;
    let navigation =
        if navigate_hours > 0.0 { navigation_comparison(p, &outcome, navigate_hours, stop)? } else { Vec::new() };
    let mut table = self::table(&setup, &outcome, &plan, monte_carlo.as_ref());
    let mut document = estimates_document(
        &head(&setup, &outcome),
        &outcome.estimate,
        Some(&outcome.all_truth(&setup)),
        &plan,
        &setup.move_starts_s,
        monte_carlo.as_ref(),
        setup.table_note.as_deref(),
    );
    if !navigation.is_empty() {
        table.push_str(&navigation_table(&navigation, navigate_hours));
        document.push_str(&format!("\n{}", navigation_document(&navigation, navigate_hours)));
    }
    Ok(Report { setup, plan, outcome, monte_carlo, navigation, table, document })
}

impl Report {
    /// The recording's view of it, titled with the scenario's name.
    #[must_use]
    pub fn view(&self, name: &str) -> crate::record::selfcal::SelfcalView<'_> {
        crate::record::selfcal::SelfcalView {
            title: format!("{name} — {}", self.setup.sequence),
            document: &self.document,
            history: &self.outcome.estimate.history,
            names: self.outcome.estimate.names(),
            prior: self.outcome.estimate.all_prior(),
            truth: Some(self.outcome.all_truth(&self.setup)),
            move_starts_s: &self.setup.move_starts_s,
            attitude: &self.outcome.attitude,
            tables: self
                .setup
                .table_states
                .as_ref()
                .map(|t| crate::record::selfcal::TableGhosts { states: &t.states, shafts: &self.outcome.shafts }),
            navigation: self
                .navigation
                .iter()
                .map(|r| crate::record::selfcal::NavLine {
                    motion: r.motion,
                    compensation: r.compensation,
                    trace: &r.trace,
                })
                .collect(),
        }
    }

    /// The document `selfcal --json` writes.
    #[must_use]
    pub fn json(&self) -> serde_json::Value {
        let e = &self.outcome.estimate;
        let mut doc = serde_json::json!({
            "sequence": self.setup.sequence,
            "parameters": e.names(),
            "units": JSON_UNITS,
            "truth": self.outcome.all_truth(&self.setup),
            "estimate": e.all_params(),
            "sigma": e.all_sigma(),
            "estimation_s": self.outcome.estimation_s,
            "observability": self.plan,
            "monte_carlo": self.monte_carlo,
            "navigation": self.navigation,
            "estimated_imu_compensation": imu_compensation(e, &self.plan.unobservable),
        });
        if let Some(table) = table_compensation(e, &self.plan.unobservable) {
            doc["estimated_compensation"] = table;
        }
        doc
    }
}

/// The table's states of `e` as the table part of a compensation document (`[compensation]`'s
/// keys, what `calibrate --json` writes): the folded rotations as swing cones, the encoders' scales
/// and delays; what they fold in (the other axes' non-orthogonality and encoder offsets, the IMU's
/// mounting) stated as zero, since the folded values already hold it; the installation and the
/// first encoder's offset (the base's attitude, which nothing on the table sees) left out, so the
/// table's own stand. The states in `unobservable` are zero, never a number the data did not give.
#[must_use]
pub fn table_compensation(e: &Estimate, unobservable: &[String]) -> Option<serde_json::Value> {
    let t = e.table.as_ref()?;
    let seen: Vec<f64> =
        t.params.iter().zip(t.states.names()).map(|(v, n)| if unobservable.contains(&n) { 0.0 } else { *v }).collect();
    let chain = t.states.chain();
    let mut keys = crate::scenario::compensation_keys(chain, &t.states.as_errors(&seen));
    keys.installation_x_arcsec = None;
    keys.installation_y_arcsec = None;
    keys.installation_z_arcsec = None;
    if let Some(first) = chain.axes().first()
        && let Some(a) = keys.axis.get_mut(&first.name)
    {
        a.encoder_offset_arcsec = None;
        a.non_orthogonality_arcsec = None;
    }
    serde_json::to_value(keys).ok()
}

/// The estimate `e` as the IMU part of a compensation document (`replay --compensation`): the
/// parameters in `unobservable` are left at zero, named, never compensated with a number the data
/// did not determine.
#[must_use]
pub fn imu_compensation(e: &Estimate, unobservable: &[String]) -> crate::scenario::compensation::RawImuCompensation {
    let names = selfcal::param_names();
    let seen = |v: &[f64; selfcal::N_PARAMS]| -> [f64; selfcal::N_PARAMS] {
        std::array::from_fn(|k| if unobservable.contains(&names[k]) { 0.0 } else { v[k] })
    };
    crate::scenario::compensation::RawImuCompensation::from_errors(
        &selfcal::ImuErrors::from_params(&seen(&e.params)),
        Some(&selfcal::ImuErrors::from_params(&seen(&e.sigma))),
        unobservable.to_vec(),
    )
}

/// A self-calibration set up: the table with its sequence, the IMU's errors, the filter's knowledge.
#[derive(Debug, Clone)]
pub struct Setup {
    /// The table turning through the sequence.
    pub table: TableParams,
    /// What the filter knows.
    pub config: Config,
    /// Samples in the sequence.
    pub samples: usize,
    /// The sequence's name.
    pub sequence: String,
    /// The starts of the moves, s.
    pub move_starts_s: Vec<f64>,
    /// The INS whose IMU is calibrated (its sensors generate the samples, as `export-log` does).
    pub ins: crate::ins::InsParams,
    /// The site.
    pub site: crate::model::earth::Site,
    /// The table's states the encoders measure (None: the IMU alone, `--without-encoders`).
    pub table_states: Option<TableConfig>,
    /// Why the table's errors are not estimated, if they are not.
    pub table_note: Option<String>,
}

/// One IMU's calibration.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The filter's result.
    pub estimate: Estimate,
    /// The IMU's true errors as drawn, in its own frame (the "true values" compensation).
    pub truth_drawn: ImuErrors,
    /// Wall time of the estimation alone (the filter's pushes), s.
    pub estimation_s: f64,
    /// The IMU's true attitude C_s^n once a second (the recording's 3D).
    pub attitude: Vec<(f64, nalgebra::UnitQuaternion<f64>)>,
    /// The encoders once a second (the recording's tables in 3D).
    pub shafts: Vec<ShaftSample>,
}

impl Outcome {
    /// The IMU's true errors in the accelerometer frame (what the estimates are compared with).
    #[must_use]
    pub fn truth(&self) -> ImuErrors {
        self.truth_drawn.in_accelerometer_frame()
    }

    /// Every true value in [`Estimate::names`]'s order: the IMU's (accelerometer frame), then the
    /// table's folded as the filter sees it ([`TableStates::truth`]).
    #[must_use]
    pub fn all_truth(&self, s: &Setup) -> Vec<f64> {
        let mut v = self.truth().to_params().to_vec();
        if let Some(t) = &s.table_states {
            v.extend(t.states.truth(&s.table.truth, &self.truth_drawn.accelerometer_frame_rotation()));
        }
        v
    }
}

/// The table's states of `table` with its encoders' noise as the datasheet (None, and why, if
/// its chain has none the encoders can measure).
#[must_use]
pub fn table_config(
    chain: &crate::model::gimbal::Chain,
    stated: &crate::model::gimbal::TableErrors,
) -> (Option<TableConfig>, Option<String>) {
    match TableStates::new(chain) {
        Ok(states) => (
            Some(TableConfig {
                states,
                encoder_sigma_rad: stated.axes.iter().map(|a| a.encoder_noise_rad).collect(),
                linearized_at: Vec::new(),
            }),
            None,
        ),
        Err(e) => (None, Some(e)),
    }
}

/// Sets up the self-calibration of `p`'s IMU on `p`'s dual-axis table.
///
/// # Errors
/// No `[imu]`, a table that is not dual-axis, a scenario scheme that is not indexed or does not
/// start at rest.
pub fn setup(p: &Params, choice: SequenceChoice, encoders: bool) -> Result<Setup> {
    let ins = p
        .ins
        .as_ref()
        .ok_or_else(|| anyhow!("{}: selfcal needs an [imu] section (the IMU to calibrate)", p.meta.name))?;
    let mut table = p.table.clone();
    let (scheme, duration_s, name) = match choice {
        SequenceChoice::BuiltIn(s) => {
            if table.chain.axes().len() != 2 {
                bail!(
                    "{}: the built-in sequences are for a dual-axis table (outer, then inner carrying the IMU about its z); this table has {} axes — use --sequence scenario with an indexed [scheme]",
                    p.meta.name,
                    table.chain.axes().len()
                );
            }
            (s.scheme(), s.duration_s(), s.name().to_owned())
        }
        SequenceChoice::Scenario => {
            if table.scheme.steps().is_empty() {
                bail!(
                    "{}: --sequence scenario needs an indexed [scheme] (kind = \"indexed\" with [[scheme.step]])",
                    p.meta.name
                );
            }
            (table.scheme.clone(), p.duration_s, format!("{}'s [scheme]", p.meta.name))
        }
    };
    let move_starts_s = scheme.move_starts_s(duration_s, 10_000);
    let first_move = move_starts_s.first().copied().unwrap_or(duration_s);
    if first_move < 60.0 {
        bail!(
            "{name}: the first move starts at {first_move:.1} s; the IMU must rest at least 60 s first (its coarse alignment)"
        );
    }
    table.scheme = scheme;
    let h = 1.0 / p.step_hz;
    let config = Config::for_datasheet(
        &ins.errors,
        h,
        Earth::at(p.site),
        (first_move.min(selfcal::INITIAL_DWELL_S) / h).round() as usize,
    );
    let (table_states, table_note) = if encoders {
        table_config(&table.chain, &table.truth)
    } else {
        (None, Some("--without-encoders: the IMU alone, from its own navigation".to_owned()))
    };
    Ok(Setup {
        table_states,
        table_note,
        table,
        config,
        samples: (duration_s / h).round() as usize,
        sequence: name,
        move_starts_s,
        ins: ins.clone(),
        site: p.site,
    })
}

/// Calibrates one IMU drawn with `seed` (`ideal`: no errors and no noise, the plan's run).
///
/// # Errors
/// Interrupted, or an alignment that failed.
pub fn run_one(s: &Setup, seed: u64, ideal: bool, stop: &AtomicBool) -> Result<Outcome> {
    // The samples come from the INS pipeline's own IMU (the one `export-log` writes): a log set
    // exported from the same scenario holds exactly these increments.
    let mut cfg = s.ins.clone();
    if ideal {
        cfg.errors = ImuErrorSpec::default();
    }
    cfg.navigation = None;
    // The plan's motion is noise-free: the encoders' too.
    let mut table = s.table.clone();
    if ideal {
        for a in &mut table.truth.axes {
            a.encoder_noise_rad = 0.0;
        }
    }
    let per_second = (1.0 / s.config.h).round().max(1.0) as usize;
    let encoders = s.table_states.is_some();
    // The IMU's true attitude once a second (the last pass's: every pass is the same IMU).
    let attitude = std::rc::Rc::new(std::cell::RefCell::new(Vec::new()));
    let truth_drawn = std::cell::Cell::new(None);
    let open = || {
        let mut ins = crate::ins::pipeline::InsRun::new(&cfg, s.site, seed, Model::new(&table, seed));
        truth_drawn.set(Some(ins.drawn_imu_errors()));
        let seen = std::rc::Rc::clone(&attitude);
        seen.borrow_mut().clear();
        let mut sample = move |k: usize| {
            let (t1, g, a) = ins.next_measurement();
            if (k + 1).is_multiple_of(per_second) {
                seen.borrow_mut().push((t1, *ins.true_n_from_s(t1).quaternion()));
            }
            ((g, a), encoders.then(|| crate::sim::encoder_readings(ins.model(), t1)))
        };
        let align: Vec<_> = (0..s.config.align_samples).map(&mut sample).collect();
        Ok((align, (s.config.align_samples..s.samples).map(move |k| Ok(sample(k)))))
    };
    let Estimation { estimate, estimation_s, shafts } = estimate(s.config, s.table_states.clone(), open, stop)?;
    let attitude = attitude.take();
    let truth_drawn = truth_drawn.take().ok_or_else(|| anyhow!("no sample was drawn"))?;
    Ok(Outcome { estimate, truth_drawn, estimation_s, attitude, shafts })
}

/// One sample: its increments and, with a table, the encoders' readings at its end, rad.
pub type Reading = (crate::ins::align::Increment, Option<AxisValues>);

pub use crate::calib::selfcal_table::ShaftSample;

/// What [`estimate`] gives: the filter's result, its own wall time and the encoders once a second.
pub struct Estimation {
    /// The filter's result.
    pub estimate: Estimate,
    /// The estimation's own wall time (the samples' production is not counted), s.
    pub estimation_s: f64,
    /// The encoders once a second (empty without a table).
    pub shafts: Vec<ShaftSample>,
}

/// The filter on the samples `open` gives (the first ones at rest, then the rest); with a table,
/// twice: the second pass linearizes the table's states about the first's result
/// ([`TableConfig::linearized_at`]).
///
/// # Errors
/// Interrupted, an alignment that failed, or a sample `open` could not give.
pub fn estimate<I: Iterator<Item = Result<Reading>>>(
    config: Config,
    table: Option<TableConfig>,
    mut open: impl FnMut() -> Result<(Vec<Reading>, I)>,
    stop: &AtomicBool,
) -> Result<Estimation> {
    let (align, rest) = open()?;
    let first = one_pass(config, table.clone(), &align, rest, stop)?;
    let (Some(mut table), Some(found)) = (table, first.estimate.table.as_ref()) else { return Ok(first) };
    table.linearized_at.clone_from(&found.params);
    let (align, rest) = open()?;
    let second = one_pass(config, Some(table), &align, rest, stop)?;
    Ok(Estimation { estimation_s: first.estimation_s + second.estimation_s, ..second })
}

/// One pass of the filter.
fn one_pass(
    config: Config,
    table: Option<TableConfig>,
    align: &[Reading],
    rest: impl Iterator<Item = Result<Reading>>,
    stop: &AtomicBool,
) -> Result<Estimation> {
    let increments: Vec<_> = align.iter().map(|r| r.0).collect();
    let mut filter = SelfCal::new(config, table, &increments).ok_or_else(|| {
        anyhow!(
            "the coarse alignment on the first {:.0} s failed (no Earth-rate signature)",
            align.len() as f64 * config.h
        )
    })?;
    let mut estimation = std::time::Duration::ZERO;
    let started = std::time::Instant::now();
    let push = |filter: &mut SelfCal, (m, readings): &Reading| match readings {
        Some(r) => filter.push_with_encoders(m, r),
        None => filter.push(m),
    };
    for m in align {
        push(&mut filter, m);
    }
    estimation += started.elapsed();
    // The encoders once a second, for the recording (outside the estimation's time).
    let per_second = (1.0 / config.h).round().max(1.0) as usize;
    let mut shafts = Vec::new();
    let (mut k, mut previous) = (0_usize, None::<AxisValues>);
    let mut see = |readings: &Option<AxisValues>| {
        k += 1;
        if let Some(r) = readings {
            if k.is_multiple_of(per_second)
                && let Some(p) = previous
            {
                let rates = std::array::from_fn(|i| (r[i] - p[i]) / config.h);
                shafts.push(ShaftSample { t_s: k as f64 * config.h, readings: *r, rates });
            }
            previous = Some(*r);
        }
    };
    align.iter().for_each(|m| see(&m.1));
    let mut buffer = Vec::with_capacity(8192);
    let mut rest = rest.peekable();
    while rest.peek().is_some() {
        if stop.load(Ordering::Relaxed) {
            bail!("interrupted");
        }
        buffer.clear();
        for m in rest.by_ref().take(8192) {
            buffer.push(m?);
        }
        let started = std::time::Instant::now();
        for m in &buffer {
            push(&mut filter, m);
        }
        estimation += started.elapsed();
        buffer.iter().for_each(|m| see(&m.1));
    }
    Ok(Estimation { estimate: filter.finish(), estimation_s: estimation.as_secs_f64(), shafts })
}

/// One free-inertial run of the comparison.
#[derive(Debug, Clone, serde::Serialize)]
pub struct NavRow {
    /// "at rest" or "16-position".
    pub motion: &'static str,
    /// "none", "estimated", "true".
    pub compensation: &'static str,
    /// Largest horizontal position error, m.
    pub peak_radial_m: f64,
    /// At the end, m.
    pub final_radial_m: f64,
    /// Largest heading error, arcsec.
    pub peak_heading_arcsec: f64,
    /// The sampled errors (the recording's curves).
    #[serde(skip)]
    pub trace: crate::ins::trace::NavTrace,
}

/// What the calibration buys: the same IMU (the scenario's seed) navigating `hours` free-inertial,
/// at rest and under the 16-position modulation, with no compensation, with the estimates and
/// with its true errors — six runs in parallel. Each run starts aligned in the frame its
/// compensated IMU measures in (a compensation in the accelerometer frame turns the IMU frame by
/// the ρ of [`ImuErrors::in_accelerometer_frame`]; the INS's own alignment would find that frame).
///
/// # Errors
/// A preset that does not load, or a run thread that panicked.
pub fn navigation_comparison(p: &Params, o: &Outcome, hours: f64, stop: &AtomicBool) -> Result<Vec<NavRow>> {
    let modulation = crate::scenario::presets::load("rotation-modulation-16-position")?;
    let navigation = modulation.ins.as_ref().and_then(|i| i.navigation);
    let estimated = ImuErrors::from_params(&o.estimate.params);
    // ρ: the accelerometer frame seen from the IMU's (what the estimates are expressed in).
    let rho = o.truth_drawn.accelerometer_frame_rotation();
    let mut cases = Vec::new();
    for (motion, scheme) in
        [("at rest", Scheme::continuous(vec![0.0; 2], vec![0.0; 2])), ("16-position", modulation.table.scheme.clone())]
    {
        let mut q = p.clone();
        q.table.scheme = scheme;
        q.set_duration(hours * 3600.0);
        let Some(ins) = q.ins.as_mut() else { bail!("{}: no [imu]", p.meta.name) };
        ins.navigation = navigation;
        // The estimated compensation's run starts in the accelerometer frame: ρ turned into n.
        let c0 = TruthImu::new(q.table_model(), Earth::at(q.site), 0.0).eval(0.0).n_from_s;
        let turned = -(c0.quaternion() * rho);
        for (name, comp) in [("none", None), ("estimated", Some(estimated)), ("true", Some(o.truth_drawn))] {
            let mut case = q.clone();
            match name {
                // The whole RINS uncompensated: a raw IMU on the nominal table.
                "none" => {
                    case.table.compensation = crate::model::gimbal::TableErrors::zero(case.table.chain.axes().len())
                }
                // The estimates of both, in the accelerometer triad's frame (the table's folded
                // with the table's own installation and first encoder's offset, which it cannot see).
                "estimated" => {
                    if let Some(t) = &o.estimate.table {
                        let mut folded = t.states.as_errors(&t.params);
                        folded.installation_rad = case.table.compensation.installation_rad;
                        if let (Some(f), Some(own)) = (folded.axes.first_mut(), case.table.compensation.axes.first()) {
                            f.encoder_offset_rad = own.encoder_offset_rad;
                        }
                        case.table.compensation = folded;
                    }
                    if let Some(ins) = case.ins.as_mut() {
                        ins.initial_error_rad = turned;
                    }
                }
                // The truth of both, in the IMU's own frame: the table's true errors (the
                // scenario's compensation is its truth unless it says otherwise) and the drawn IMU.
                _ => {}
            }
            cases.push((motion, name, case, comp));
        }
    }
    let sample_s = (hours * 3600.0 / 2000.0).max(1.0);
    let rows: Vec<NavRow> = cases
        .par_iter()
        .map(|(motion, name, q, comp)| {
            let trace = crate::app::modulation::simulate(q, &format!("{motion}, {name}"), sample_s, stop, *comp);
            let last = trace.samples.last().copied().unwrap_or_default();
            NavRow {
                motion,
                compensation: name,
                peak_radial_m: trace.peak_radial_m(),
                final_radial_m: last.position_m[2],
                peak_heading_arcsec: trace.peak_heading_arcsec(),
                trace,
            }
        })
        .collect();
    if stop.load(Ordering::SeqCst) {
        bail!("interrupted");
    }
    Ok(rows)
}

/// The comparison as the terminal prints it.
#[must_use]
pub fn navigation_table(rows: &[NavRow], hours: f64) -> String {
    let mut s = format!(
        "\nwhat it buys: {hours:.0} h free-inertial, the same IMU\n  {:<13} {:<13} {:>16} {:>16} {:>18}\n",
        "motion", "compensation", "peak radial (m)", "final radial (m)", "peak heading (″)"
    );
    for r in rows {
        s.push_str(&format!(
            "  {:<13} {:<13} {:>16.1} {:>16.1} {:>18.2}\n",
            r.motion, r.compensation, r.peak_radial_m, r.final_radial_m, r.peak_heading_arcsec
        ));
    }
    s
}

/// The comparison as the recording's document shows it (markdown; the table narrower than the
/// terminal's, as [`estimates_document`]'s).
#[must_use]
pub fn navigation_document(rows: &[NavRow], hours: f64) -> String {
    let mut s = format!(
        "What it buys: {hours:.0} h free-inertial, the same IMU — the radial position error (peak, final) and the peak heading error.\n\n```\n{:<11} {:<12} {:>9} {:>9} {:>11}\n",
        "motion", "compensation", "peak (m)", "final (m)", "heading (″)"
    );
    for r in rows {
        s.push_str(&format!(
            "{:<11} {:<12} {:>9.1} {:>9.1} {:>11.2}\n",
            r.motion, r.compensation, r.peak_radial_m, r.final_radial_m, r.peak_heading_arcsec
        ));
    }
    s.push_str("```\n");
    s
}
