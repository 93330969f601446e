//! A recorded run: the simulation thread steps the model and sends its outputs (the statistics'
//! samples for the plots, the scene's frames) through `feed` to the recorder (this thread), which
//! turns them into Rerun chunks. Memory stays flat: nothing holds more than one chunk of rows.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use serde::Serialize;

use crate::app::failure::Failure;
use crate::app::feed::{self, Outbox, OutputRow};
use crate::app::outputs::{RecordingName, RecordingRequest, check_output, finish, write_json};
use crate::ins::core::SampleOut;
use crate::ins::pipeline::{AttitudeOutput, InsOutputs, InsRun, InsView, InsViewer};
use crate::math::stats::RunningStat;
use crate::math::timeline::{Timeline, decimation};
use crate::math::units::ARCSEC_PER_RAD;
use crate::record::Recorder;
use crate::record::sink::OpenSinks;
use crate::scenario::Params;
use crate::sim::{DEMODULATIONS, DemodState, ERROR_AXES, ErrorStats, Model, step, step_with};

/// Summary row of the closed form minus the exact (uncompensated) error.
pub const CLOSED_FORM_DEVIATION: &str = "closed_form_minus_exact";

/// Statistics of the INS in the loop.
#[derive(Debug, Clone, Default)]
pub struct InsStats {
    /// Algorithm names, in integrator order.
    pub algorithms: Vec<String>,
    /// `[algorithm][axis]`, radians.
    pub stats: Vec<[RunningStat; 3]>,
    /// Navigation errors, when navigating.
    pub nav: Option<NavSummary>,
}

impl InsStats {
    fn add(&mut self, v: &InsView) {
        if self.stats.len() < v.errors.len() {
            self.stats.resize(v.errors.len(), [RunningStat::default(); 3]);
        }
        for (k, e) in v.errors.iter().enumerate() {
            for (a, x) in e.as_array().into_iter().enumerate() {
                self.stats[k][a].add(x);
            }
        }
        if let Some(e) = v.nav {
            self.nav = Some(NavSummary::after(self.nav, &e));
        }
    }
}

/// RMS and peak of one component, arcsec.
#[derive(Debug, Clone, Copy, Serialize, serde::Deserialize)]
pub struct RmsPeak {
    /// Root mean square, arcsec.
    pub rms_arcsec: f64,
    /// Largest absolute value, arcsec.
    pub peak_arcsec: f64,
}

/// The result of a run, as printed and as written by `--summary-json`.
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct RunSummary {
    /// Scenario name.
    pub scenario: String,
    /// Seed of the run.
    pub seed: u64,
    /// Simulated time, s.
    pub duration_s: f64,
    /// Simulation rate, Hz.
    pub step_hz: f64,
    /// Steps simulated.
    pub steps: u64,
    /// True if Ctrl-C stopped the run early (the recording holds what was simulated).
    pub interrupted: bool,
    /// Wall-clock time of the whole run, s.
    pub wall_time_s: f64,
    /// Simulation steps per wall-clock second (including recording).
    pub steps_per_second: f64,
    /// The rate the table's RMS and peak statistics (`attitude_error_arcsec`) sample its errors at,
    /// Hz: the step rate down to the motion's bandwidth (`Bandwidth::statistics_hz`). The INS's
    /// (`ins_attitude_error_arcsec`) are taken at every attitude update.
    pub statistics_hz: f64,
    /// Peak resident memory of the process, MB (when the run ends; 0 when not measured).
    pub peak_rss_mb: f64,
    /// Saved recording, if any.
    pub recording_path: Option<String>,
    /// Its size, bytes.
    pub recording_bytes: Option<u64>,
    /// `[variant][axis]`: "uncompensated" / "compensated" / "closed_form" / "closed_form_minus_exact"
    /// x "pitch" / "roll" / "heading", sampled at `statistics_hz`.
    pub attitude_error_arcsec: std::collections::BTreeMap<String, std::collections::BTreeMap<String, RmsPeak>>,
    /// With an IMU in the loop: the INS body-attitude error `[algorithm][axis]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ins_attitude_error_arcsec:
        Option<std::collections::BTreeMap<String, std::collections::BTreeMap<String, RmsPeak>>>,
    /// With navigation: radial position error, m (peak and final) and the final east/north error.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub navigation: Option<NavSummary>,
}

/// Navigation errors of a run.
#[derive(Debug, Clone, Copy, Serialize, serde::Deserialize)]
pub struct NavSummary {
    /// Largest radial position error, m.
    pub peak_radial_m: f64,
    /// Radial position error at the end, m.
    pub final_radial_m: f64,
    /// East position error at the end, m.
    pub final_east_m: f64,
    /// North position error at the end, m.
    pub final_north_m: f64,
}

impl NavSummary {
    /// The summary `previous` (None: none yet) with the navigation errors `e` of the next update.
    pub(crate) fn after(previous: Option<Self>, e: &crate::ins::core::NavError) -> Self {
        Self {
            peak_radial_m: previous.map_or(0.0, |n| n.peak_radial_m).max(e.radial_m),
            final_radial_m: e.radial_m,
            final_east_m: e.east_m,
            final_north_m: e.north_m,
        }
    }
}

impl RunSummary {
    fn new(p: &Params, stats: &ErrorStats, steps: u64, wall_time_s: f64, interrupted: bool) -> Self {
        let mut table = std::collections::BTreeMap::new();
        for (v, variant) in DEMODULATIONS.iter().enumerate() {
            let mut row = std::collections::BTreeMap::new();
            for (a, axis) in ERROR_AXES.iter().enumerate() {
                let s = &stats.stats[v][a];
                row.insert(
                    (*axis).to_owned(),
                    RmsPeak { rms_arcsec: s.rms() * ARCSEC_PER_RAD, peak_arcsec: s.peak() * ARCSEC_PER_RAD },
                );
            }
            table.insert((*variant).to_owned(), row);
        }
        let mut row = std::collections::BTreeMap::new();
        for (a, axis) in ERROR_AXES.iter().enumerate() {
            let s = &stats.closed_form_deviation[a];
            row.insert(
                (*axis).to_owned(),
                RmsPeak { rms_arcsec: s.rms() * ARCSEC_PER_RAD, peak_arcsec: s.peak() * ARCSEC_PER_RAD },
            );
        }
        table.insert(CLOSED_FORM_DEVIATION.to_owned(), row);
        Self {
            scenario: p.meta.name.clone(),
            seed: p.meta.seed,
            duration_s: steps.saturating_sub(1) as f64 / p.step_hz,
            step_hz: p.step_hz,
            steps,
            interrupted,
            wall_time_s,
            steps_per_second: steps as f64 / wall_time_s.max(1e-9),
            statistics_hz: p.step_hz / p.statistics_every() as f64,
            peak_rss_mb: 0.0,
            recording_path: None,
            recording_bytes: None,
            attitude_error_arcsec: table,
            ins_attitude_error_arcsec: None,
            navigation: None,
        }
    }

    fn with_ins(mut self, ins: &InsStats) -> Self {
        if ins.algorithms.is_empty() {
            return self;
        }
        let mut table = std::collections::BTreeMap::new();
        for (k, name) in ins.algorithms.iter().enumerate() {
            let mut row = std::collections::BTreeMap::new();
            for (a, axis) in ERROR_AXES.iter().enumerate() {
                let s = ins.stats.get(k).map_or(RunningStat::default(), |s| s[a]);
                row.insert(
                    (*axis).to_owned(),
                    RmsPeak { rms_arcsec: s.rms() * ARCSEC_PER_RAD, peak_arcsec: s.peak() * ARCSEC_PER_RAD },
                );
            }
            table.insert(name.clone(), row);
        }
        self.ins_attitude_error_arcsec = Some(table);
        self.navigation = ins.nav;
        self
    }

    /// RMS and peak of one variant and axis.
    #[must_use]
    pub fn get(&self, variant: &str, axis: &str) -> RmsPeak {
        self.attitude_error_arcsec[variant][axis]
    }

    /// The end-of-run table.
    #[must_use]
    pub fn table(&self) -> String {
        let mut s = String::new();
        s.push_str(&format!(
            "{} — {:.1} s simulated, {} steps at {} Hz, {:.2} s wall ({:.2} M steps/s){}\n",
            self.scenario,
            self.duration_s,
            self.steps,
            self.step_hz,
            self.wall_time_s,
            self.steps_per_second / 1e6,
            if self.interrupted { " — INTERRUPTED" } else { "" }
        ));
        s.push_str(
            "attitude error, arcsec     pitch rms  pitch peak    roll rms   roll peak  heading rms heading peak\n",
        );
        for variant in DEMODULATIONS.iter().chain([&CLOSED_FORM_DEVIATION]) {
            s.push_str(&format!("{:<24}", variant.replace('_', " ")));
            for axis in ERROR_AXES {
                let v = self.get(variant, axis);
                s.push_str(&format!(" {:>11.3} {:>11.3}", v.rms_arcsec, v.peak_arcsec));
            }
            s.push('\n');
        }
        if let Some(ins) = &self.ins_attitude_error_arcsec {
            s.push_str("INS attitude error, arcsec\n");
            for (name, row) in ins {
                s.push_str(&format!("{:<24}", format!("  {name}")));
                for axis in ERROR_AXES {
                    let v = row[axis];
                    s.push_str(&format!(" {:>11.3} {:>11.3}", v.rms_arcsec, v.peak_arcsec));
                }
                s.push('\n');
            }
        }
        if let Some(n) = &self.navigation {
            s.push_str(&format!(
                "navigation: radial position error peak {:.1} m, final {:.1} m (east {:.1} m, north {:.1} m)\n",
                n.peak_radial_m, n.final_radial_m, n.final_east_m, n.final_north_m
            ));
        }
        if let (Some(p), Some(b)) = (&self.recording_path, self.recording_bytes) {
            s.push_str(&format!("recording: {p} ({:.2} MB)\n", b as f64 / 1e6));
        }
        s
    }
}

/// Simulates `params`, streaming to `sinks`; Ctrl-C (`stop`) ends the run early and keeps what was
/// simulated. Returns the summary; the sinks stay open (the caller finishes or abandons them).
pub fn run_recorded(
    params: &Params,
    sinks: &OpenSinks,
    stop: &AtomicBool,
    progress: bool,
) -> anyhow::Result<RunSummary> {
    record_run(Recorder::new(sinks.stream(), params)?, params, stop, progress)
}

/// Simulates `params` into `recorder` (whose layout the caller chose), ends it with the run's
/// events and flushes it.
pub fn record_run(
    mut recorder: Recorder,
    params: &Params,
    stop: &AtomicBool,
    progress: bool,
) -> anyhow::Result<RunSummary> {
    let started = Instant::now();
    let model = params.table_model();
    let timeline = params.timeline();
    let steps = timeline.instants();
    let scene_every = decimation(params.step_hz, params.recording.scene_hz);
    let stats_every = params.statistics_every();

    let bar = if progress && steps > 2_000_000 {
        let bar = indicatif::ProgressBar::new(steps);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{spinner} simulating [{bar:40}] {percent}% ({eta} left)")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        Some(bar)
    } else {
        None
    };

    let (tx, rx) = feed::channel();
    let (stats, ins_stats, done, interrupted) =
        std::thread::scope(|scope| -> anyhow::Result<(ErrorStats, InsStats, u64, bool)> {
            let sim = scope.spawn(|| {
                let ctx =
                    Producer { model: &model, params, stop, bar: bar.as_ref(), tx: &tx, scene_every, stats_every };
                let r = if params.ins.is_some() { ctx.run_ins(&timeline) } else { ctx.run_ideal(&timeline) };
                drop(tx);
                r
            });
            let result = feed::consume(&mut recorder, rx);
            let r = sim.join().map_err(|_| anyhow::anyhow!("simulation thread panicked"))?;
            result?;
            Ok(r)
        })?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }

    let summary =
        RunSummary::new(params, &stats, done, started.elapsed().as_secs_f64(), interrupted).with_ins(&ins_stats);
    let t_end = timeline.t_s(done.saturating_sub(1));
    let end_text = if interrupted {
        format!("run interrupted by the user at {t_end:.3} s; the recording holds everything simulated until then")
    } else {
        format!("run finished at {t_end:.3} s")
    };
    recorder.event(t_end, &end_text, if interrupted { "WARN" } else { "INFO" })?;
    recorder.event(t_end, &format!("summary:\n{}", summary.table()), "INFO")?;
    if !recorder.is_live() {
        // The plots framed on what the run reached (the layout is sent again).
        let peak = |s: &[RunningStat; 3]| [s[0].peak(), s[1].peak(), s[2].peak()];
        let ranges = crate::record::PlotRanges {
            table_peak_rad: peak(&stats.stats[0]),
            // Every algorithm's line must fit (a comparison's largest is the point of the plot).
            ins_peak_rad: (!ins_stats.stats.is_empty()).then(|| {
                ins_stats
                    .stats
                    .iter()
                    .map(peak)
                    .fold([0.0_f64; 3], |m, p| [m[0].max(p[0]), m[1].max(p[1]), m[2].max(p[2])])
            }),
            closed_form_peak_rad: peak(&stats.closed_form_deviation),
        };
        recorder.fit_plots(params, ranges)?;
    }
    recorder.finish()?;
    Ok(summary)
}

/// The simulation thread's side of a recorded run.
struct Producer<'a> {
    model: &'a Model,
    params: &'a Params,
    stop: &'a AtomicBool,
    bar: Option<&'a indicatif::ProgressBar>,
    tx: &'a crossbeam_channel::Sender<feed::Batch>,
    scene_every: u64,
    /// Steps between two statistics samples (`Params::statistics_every`): the samples the
    /// summary's statistics take are the rows the plots' envelopes and the export get.
    stats_every: u64,
}

impl Producer<'_> {
    fn check(&self, i: u64) -> bool {
        if let Some(b) = self.bar {
            b.set_position(i);
        }
        self.stop.load(Ordering::Relaxed)
    }

    /// The IMU attitude is exact: one core step per instant.
    fn run_ideal(&self, timeline: &Timeline) -> (ErrorStats, InsStats, u64, bool) {
        let mut state = DemodState::default();
        let mut stats = ErrorStats::default();
        let mut out = Outbox::new(self.tx);
        let (mut done, mut interrupted) = (0, false);
        // Whether the previous instant was computed (else the delay correction is fed its reading).
        let mut stepped = false;
        for i in 0..timeline.instants() {
            if i % 65_536 == 0 && self.check(i) {
                interrupted = true;
                break;
            }
            done = i + 1;
            // The last steps too: a drift's final value is often its peak.
            let want_stats = i % self.stats_every == 0 || i.saturating_add(self.stats_every) >= timeline.instants();
            let want_scene = i % self.scene_every == 0;
            let wanted = want_stats || want_scene;
            let stepped_last = std::mem::replace(&mut stepped, wanted);
            if !wanted {
                continue;
            }
            if i > 0 && !stepped_last {
                state.observe(self.model, timeline.t_s(i - 1));
            }
            let o = step(self.model, &mut state, timeline.t_s(i));
            if want_stats {
                stats.add(&o);
            }
            if want_stats && !out.series(OutputRow { core: o, ins: None, solution: None }) {
                done = i;
                break;
            }
            if want_scene && !out.scene(OutputRow { core: o, ins: None, solution: None }) {
                done = i;
                break;
            }
        }
        out.close();
        (stats, InsStats::default(), done, interrupted)
    }

    /// An IMU in the loop: one IMU sample per step; outputs at the attitude updates closest to the
    /// recording rates; the INS's statistics at every update, the table's at the updates closest
    /// to the statistics rate.
    fn run_ins(&self, timeline: &Timeline) -> (ErrorStats, InsStats, u64, bool) {
        let Some(ins_params) = &self.params.ins else {
            return self.run_ideal(timeline);
        };
        let mut ins = InsRun::new(ins_params, self.params.site, self.params.meta.seed, self.model.clone());
        let ins_stats = InsStats {
            algorithms: ins.algorithms().iter().map(|a| a.name().to_owned()).collect(),
            ..InsStats::default()
        };
        // The INS's errors, the table's demodulations and the statistics on a thread of their own:
        // the simulation (truth, sensors, the computer) hands each update's outputs on, as the
        // recorder's thread takes the rows (a third of the simulation's time was the errors').
        let viewer = ins.viewer();
        let (tx, rx) = crossbeam_channel::bounded::<Batch>(feed::STAGE_BATCHES);
        std::thread::scope(|scope| {
            let views = scope.spawn(move || self.view_updates(viewer, ins_stats, &rx));
            let (done, interrupted) = self.simulate(&mut ins, timeline, &tx);
            drop(tx);
            let (stats, ins_stats, stopped_at) = views.join().unwrap_or_else(|p| std::panic::resume_unwind(p));
            // A signal the statistics' thread saw ends the run where it did, which may be behind
            // the simulation.
            match stopped_at {
                Some(done) => (stats, ins_stats, done, true),
                None => (stats, ins_stats, done, interrupted),
            }
        })
    }

    /// The simulation's side of [`Self::run_ins`]: one IMU sample per step; the outputs of every
    /// attitude update to `tx`, marked for the statistics and the scene at the updates closest to
    /// their rates; the gyro signal's first samples. Returns (instants done, interrupted).
    fn simulate(&self, ins: &mut InsRun, timeline: &Timeline, tx: &crossbeam_channel::Sender<Batch>) -> (u64, bool) {
        const UPDATES_PER_BATCH: usize = 512;
        let algorithms = ins.algorithms().len();
        let new_batch = || Batch {
            updates: Vec::with_capacity(UPDATES_PER_BATCH),
            attitudes: Vec::with_capacity(UPDATES_PER_BATCH * algorithms),
            done: 0,
        };
        let window = ins.config().signal_window_s;
        let (mut done, mut interrupted) = (1, false);
        let (mut next_scene, mut next_stats) = (0u64, 0u64);
        let mut batch = new_batch();
        for i in 1..=timeline.intervals() {
            if i % 65_536 == 0 && self.check(i) {
                interrupted = true;
                break;
            }
            let s = ins.step();
            if s.t_s <= window {
                batch.updates.push(Update::Signal(s));
            }
            done = i + 1;
            if s.updated {
                // Statistics not at the recorded rows (a peak between two rows, or in the last rows
                // of a growing drift, is not missed): the INS's errors at every update (their
                // bandwidth is the algorithms', not the motion's), the table's at the statistics
                // rate (Bandwidth::statistics_hz). The true IMU attitude only for the scene.
                let want_scene = i >= next_scene;
                let want_stats = i >= next_stats || i.saturating_add(self.stats_every) > timeline.intervals();
                if want_scene {
                    next_scene = i.saturating_add(self.scene_every);
                }
                if want_stats {
                    next_stats = i.saturating_add(self.stats_every);
                }
                let outputs = ins.outputs(s.t_s, want_scene, &mut batch.attitudes);
                batch.updates.push(Update::Output { outputs, want_stats, want_scene });
            }
            if batch.updates.len() >= UPDATES_PER_BATCH {
                batch.done = done;
                if tx.send(std::mem::replace(&mut batch, new_batch())).is_err() {
                    // The statistics' thread stopped: a signal, or the recorder failed (it reports why).
                    return (done, interrupted);
                }
            }
        }
        batch.done = done;
        let _ = tx.send(batch);
        (done, interrupted)
    }

    /// The statistics' side of [`Self::run_ins`]: each update's INS errors (`viewer`) into
    /// `ins_stats`; at the marked ones the table's step into the run's statistics, and the rows to
    /// the recorder. A signal (`stop`) ends it at its next batch, the batches still queued left.
    /// Returns (the table's statistics, the INS's, the instants done when a signal stopped it).
    fn view_updates(
        &self,
        mut viewer: InsViewer,
        mut ins_stats: InsStats,
        rx: &crossbeam_channel::Receiver<Batch>,
    ) -> (ErrorStats, InsStats, Option<u64>) {
        let mut state = DemodState::default();
        let mut stats = ErrorStats::default();
        let mut out = Outbox::new(self.tx);
        // The latest attitude update: its instant and whether its step was computed.
        let mut last_update: Option<(f64, bool)> = None;
        let (mut done, mut stopped_at) = (1, None);
        'batches: for batch in rx {
            if self.stop.load(Ordering::Relaxed) {
                stopped_at = Some(done);
                break;
            }
            done = batch.done;
            // By reference: moving each update out of the batch copied its outputs (2 % of the CPU).
            let mut attitudes = batch.attitudes.as_slice();
            for update in &batch.updates {
                let (outputs, want_stats, want_scene) = match update {
                    Update::Signal(s) if out.signal(*s) => continue,
                    Update::Signal(_) => break 'batches,
                    Update::Output { outputs, want_stats, want_scene } => (outputs, *want_stats, *want_scene),
                };
                let (these, rest) = attitudes.split_at(viewer.algorithms());
                attitudes = rest;
                let view = viewer.view(outputs, these);
                ins_stats.add(&view);
                let wanted = want_stats || want_scene;
                // The previous update's instant, for the delay correction when it was not computed.
                let previous_update = last_update.replace((outputs.t_s(), wanted));
                if !wanted {
                    continue;
                }
                if let Some((t_prev, false)) = previous_update {
                    state.observe(self.model, t_prev);
                }
                let truth = viewer.truth_at(self.model, outputs.t_s());
                let core = step_with(self.model, &mut state, outputs.t_s(), truth);
                if want_stats {
                    stats.add(&core);
                    if !out.series(OutputRow { core, ins: Some(view.clone()), solution: None }) {
                        break 'batches;
                    }
                }
                if want_scene && !out.scene(OutputRow { core, ins: Some(view), solution: None }) {
                    break 'batches;
                }
            }
        }
        out.close();
        (stats, ins_stats, stopped_at)
    }
}

/// What the simulation hands the statistics' thread: updates in order, their algorithms' outputs
/// one after the other ([`Producer::run_ins`]).
struct Batch {
    updates: Vec<Update>,
    attitudes: Vec<AttitudeOutput>,
    /// The instants done when it was sent: where a run that stops after it ended.
    done: u64,
}

/// What the simulation hands the statistics' thread, in order ([`Producer::run_ins`]).
enum Update {
    /// A sample of the gyro signal's first seconds.
    Signal(SampleOut),
    /// An attitude update's outputs, and whether the statistics and the scene take its instant.
    Output { outputs: InsOutputs, want_stats: bool, want_scene: bool },
}

/// `rinscope run` (and Python's `run`): the scenario and where its outputs go.
pub struct RunRequest {
    /// The scenario.
    pub params: Params,
    /// The recording's sinks.
    pub recording: RecordingRequest,
    /// `--summary-json`.
    pub summary_json: Option<std::path::PathBuf>,
    /// A progress bar on a terminal's stderr.
    pub progress: bool,
    /// `--compensation`: a compensation document (`calibrate --json`, `selfcal --json`) the
    /// computer applies, the table's part and the IMU's: its text and where it came from.
    pub compensation: Option<(String, String)>,
}

/// What `run` reports: the summary (its recording's path and size filled in) and what was kept.
pub struct RunReport {
    /// The summary, as `--summary-json` writes it.
    pub summary: RunSummary,
    /// The recording, tables and figures kept.
    pub saved: crate::record::sink::Saved,
}

/// `run`'s one owner: the outputs checked, the simulation streamed to its sinks, the summary.
///
/// # Errors
/// A sink or output that cannot be opened or written; nothing kept the data.
pub fn execute(req: &RunRequest, stop: &AtomicBool) -> Result<RunReport, Failure> {
    // The summary file is checked before anything runs, so a typo costs nothing.
    check_output("--summary-json", req.summary_json.as_deref())?;
    let mut compensated = None;
    if let Some((text, origin)) = &req.compensation {
        let mut p = req.params.clone();
        for note in crate::scenario::compensation::apply_to_scenario(&mut p, text, origin)? {
            errln!("rinscope run: {note}");
        }
        compensated = Some(p);
    }
    let params = compensated.as_ref().unwrap_or(&req.params);
    let sinks =
        req.recording.open(RecordingName { name: &params.meta.name, kind: None, seed: Some(params.meta.seed) })?;
    let mut summary = run_recorded(params, &sinks, stop, req.progress)?;
    let saved = finish(sinks)?;
    (summary.recording_path, summary.recording_bytes) = saved.recording_fields();
    summary.peak_rss_mb = crate::app::bench::peak_rss_bytes() as f64 / 1e6;
    if let Some(path) = &req.summary_json {
        write_json("--summary-json", path, &summary)?;
    }
    Ok(RunReport { summary, saved })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::stats::RunningStat;
    use crate::record::sink::{self, SinkRequest};
    use crate::scenario::presets;

    /// A run's statistics against statistics at every attitude update, computed here independently
    /// by the pipeline's own loop, on Li et al. 2014's 2 Hz three-axis wobble at 2 kHz with its Table 4
    /// IMU: the INS's errors (sampled at every update) are the same numbers; the table's errors,
    /// sampled at `Bandwidth::statistics_hz` (every 4th step here), read every peak to the 1e-4 that
    /// rate promises.
    #[test]
    fn statistics_at_the_statistics_rate_read_the_peaks_of_every_update_to_1e_4() -> anyhow::Result<()> {
        let mut p = presets::load("li2014-wobble-2")?;
        p.set_duration(20.0);
        assert_eq!(p.statistics_every(), 4, "2 Hz wobble: 500 Hz statistics at a 2000 Hz IMU");
        let dir = std::env::temp_dir().join(format!("rinscope-stats-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        let sinks =
            sink::open(&SinkRequest { save: Some(dir.join("s.rrd")), ..Default::default() }, "rinscope-test", "stats")?;
        let summary = run_recorded(&p, &sinks, &AtomicBool::new(false), false)?;
        sinks.finish()?;
        std::fs::remove_dir_all(&dir).ok();
        assert!((summary.statistics_hz - 500.0).abs() < 1e-9);

        let ins_params = p.ins.as_ref().expect("[imu]");
        let mut ins = InsRun::new(ins_params, p.site, p.meta.seed, p.table_model());
        let names: Vec<String> = ins.algorithms().iter().map(|a| a.name().to_owned()).collect();
        let model = p.table_model();
        let mut state = DemodState::default();
        let mut table = ErrorStats::default();
        let mut every: Vec<[RunningStat; 3]> = vec![Default::default(); names.len()];
        for _ in 1..=p.timeline().intervals() {
            let s = ins.step();
            if s.updated {
                table.add(&step(&model, &mut state, s.t_s));
                for (k, e) in ins.view(s.t_s).errors.iter().enumerate() {
                    for (a, x) in e.as_array().into_iter().enumerate() {
                        every[k][a].add(x);
                    }
                }
            }
        }
        let close = |what: &str, sampled: f64, all: f64, tolerance: f64| {
            assert!(
                sampled <= all * (1.0 + 1e-12) && sampled >= all * (1.0 - tolerance),
                "{what}: {sampled} in the run, {all} at every update"
            );
        };
        let ins_summary = summary.ins_attitude_error_arcsec.as_ref().expect("INS statistics");
        for (k, name) in names.iter().enumerate() {
            for (a, axis) in ERROR_AXES.iter().enumerate() {
                close(
                    &format!("{name} {axis}"),
                    ins_summary[name][*axis].peak_arcsec,
                    every[k][a].peak() * ARCSEC_PER_RAD,
                    1e-12,
                );
            }
        }
        for (v, variant) in DEMODULATIONS.iter().enumerate() {
            for (a, axis) in ERROR_AXES.iter().enumerate() {
                close(
                    &format!("{variant} {axis}"),
                    summary.attitude_error_arcsec[*variant][*axis].peak_arcsec,
                    table.stats[v][a].peak() * ARCSEC_PER_RAD,
                    1e-4,
                );
            }
        }
        Ok(())
    }
}
