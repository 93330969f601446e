//! A recorded run: the simulation thread steps the model and sends decimated outputs through a
//! bounded channel to the recorder (this thread), which turns them into Rerun chunks. Memory stays
//! flat: nothing holds more than one chunk of rows.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use serde::Serialize;

use crate::config::Params;
use crate::record::Recorder;
use crate::sim::{step, DemodState, ErrorStats, Model, StepOutput, ERROR_AXES, VARIANTS};
use crate::sink::OpenSinks;
use crate::units::ARCSEC_PER_RAD;

/// Summary row of the closed form minus the exact (uncompensated) error.
pub const CLOSED_FORM_DEVIATION: &str = "closed_form_minus_exact";

/// Rows per message from the simulation thread to the recorder.
const BATCH_ROWS: usize = 2048;

/// Decimation of a step rate to an output rate: every `n`-th step.
#[must_use]
pub fn every_n_steps(step_hz: f64, output_hz: f64) -> u64 {
    ((step_hz / output_hz).round() as u64).max(1)
}

/// What the simulation thread sends.
enum Batch {
    Series(Vec<StepOutput>),
    Scene(Vec<StepOutput>),
}

/// RMS and peak of one component, arcsec.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct RmsPeak {
    /// Root mean square, arcsec.
    pub rms_arcsec: f64,
    /// Largest absolute value, arcsec.
    pub peak_arcsec: f64,
}

/// The result of a run, as printed and as written by `--summary-json`.
#[derive(Debug, Clone, Serialize)]
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
    /// Saved recording, if any.
    pub recording_path: Option<String>,
    /// Its size, bytes.
    pub recording_bytes: Option<u64>,
    /// `[variant][axis]`: "uncompensated" / "compensated" / "closed_form" / "closed_form_minus_exact"
    /// x "pitch" / "roll" / "heading".
    pub attitude_error_arcsec: std::collections::BTreeMap<String, std::collections::BTreeMap<String, RmsPeak>>,
}

impl RunSummary {
    fn new(p: &Params, stats: &ErrorStats, steps: u64, wall_time_s: f64, interrupted: bool) -> Self {
        let mut table = std::collections::BTreeMap::new();
        for (v, variant) in VARIANTS.iter().enumerate() {
            let mut row = std::collections::BTreeMap::new();
            for (a, axis) in ERROR_AXES.iter().enumerate() {
                let s = &stats.stats[v][a];
                row.insert((*axis).to_owned(), RmsPeak { rms_arcsec: s.rms() * ARCSEC_PER_RAD, peak_arcsec: s.peak() * ARCSEC_PER_RAD });
            }
            table.insert((*variant).to_owned(), row);
        }
        let mut row = std::collections::BTreeMap::new();
        for (a, axis) in ERROR_AXES.iter().enumerate() {
            let s = &stats.closed_form_deviation[a];
            row.insert((*axis).to_owned(), RmsPeak { rms_arcsec: s.rms() * ARCSEC_PER_RAD, peak_arcsec: s.peak() * ARCSEC_PER_RAD });
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
            recording_path: None,
            recording_bytes: None,
            attitude_error_arcsec: table,
        }
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
        s.push_str("attitude error, arcsec     pitch rms  pitch peak    roll rms   roll peak  heading rms heading peak\n");
        for variant in VARIANTS.iter().chain([&CLOSED_FORM_DEVIATION]) {
            s.push_str(&format!("{:<24}", variant.replace('_', " ")));
            for axis in ERROR_AXES {
                let v = self.get(variant, axis);
                s.push_str(&format!(" {:>11.3} {:>11.3}", v.rms_arcsec, v.peak_arcsec));
            }
            s.push('\n');
        }
        if let (Some(p), Some(b)) = (&self.recording_path, self.recording_bytes) {
            s.push_str(&format!("recording: {p} ({:.2} MB)\n", b as f64 / 1e6));
        }
        s
    }
}

/// Simulates `params`, streaming to `sinks`; Ctrl-C (`stop`) ends the run early and keeps what was
/// simulated. Returns the summary and the still-open sinks (the caller finishes or abandons them).
pub fn run_recorded(params: &Params, sinks: &OpenSinks, stop: &AtomicBool, progress: bool) -> anyhow::Result<RunSummary> {
    let started = Instant::now();
    let model = Model::new(params);
    let mut recorder = Recorder::new(sinks.rec.clone(), params)?;
    let steps = params.steps();
    let series_every = every_n_steps(params.step_hz, params.recording.series_hz);
    let scene_every = every_n_steps(params.step_hz, params.recording.scene_hz);
    let step_hz = params.step_hz;

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

    let (tx, rx) = crossbeam_channel::bounded::<Batch>(8);
    let (stats, done, interrupted) = std::thread::scope(|scope| -> anyhow::Result<(ErrorStats, u64, bool)> {
        let sim = scope.spawn(|| {
            let mut state = DemodState::default();
            let mut stats = ErrorStats::default();
            let mut series = Vec::with_capacity(BATCH_ROWS);
            let mut scene = Vec::with_capacity(BATCH_ROWS);
            let mut done = 0;
            let mut interrupted = false;
            for i in 0..steps {
                if i % 65_536 == 0 {
                    if stop.load(Ordering::Relaxed) {
                        interrupted = true;
                        break;
                    }
                    if let Some(b) = &bar {
                        b.set_position(i);
                    }
                }
                let out = step(&model, &mut state, i as f64 / step_hz);
                stats.add(&out);
                if i % series_every == 0 {
                    series.push(out);
                    if series.len() == BATCH_ROWS && tx.send(Batch::Series(std::mem::replace(&mut series, Vec::with_capacity(BATCH_ROWS)))).is_err() {
                        break;
                    }
                }
                if i % scene_every == 0 {
                    scene.push(out);
                    if scene.len() == BATCH_ROWS && tx.send(Batch::Scene(std::mem::replace(&mut scene, Vec::with_capacity(BATCH_ROWS)))).is_err() {
                        break;
                    }
                }
                done = i + 1;
            }
            // A closed receiver means the recorder failed; it reports the error itself.
            let _ = tx.send(Batch::Series(series));
            let _ = tx.send(Batch::Scene(scene));
            drop(tx);
            (stats, done, interrupted)
        });
        let mut result = Ok(());
        for batch in &rx {
            let r = match batch {
                Batch::Series(rows) => rows.iter().try_for_each(|o| recorder.push_series(o)),
                Batch::Scene(rows) => rows.iter().try_for_each(|o| recorder.push_scene(o)),
            };
            if let Err(e) = r {
                result = Err(e);
                break;
            }
        }
        drop(rx);
        let (stats, done, interrupted) = sim.join().map_err(|_| anyhow::anyhow!("simulation thread panicked"))?;
        result?;
        Ok((stats, done, interrupted))
    })?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }

    let summary = RunSummary::new(params, &stats, done, started.elapsed().as_secs_f64(), interrupted);
    let t_end = done.saturating_sub(1) as f64 / step_hz;
    let end_text = if interrupted {
        format!("run interrupted by the user at {t_end:.3} s; the recording holds everything simulated until then")
    } else {
        format!("run finished at {t_end:.3} s")
    };
    recorder.event(t_end, &end_text, if interrupted { "WARN" } else { "INFO" })?;
    recorder.event(t_end, &format!("summary:\n{}", summary.table()), "INFO")?;
    recorder.finish()?;
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimation_rounds_to_whole_steps() {
        assert_eq!(every_n_steps(200.0, 100.0), 2);
        assert_eq!(every_n_steps(200.0, 25.0), 8);
        assert_eq!(every_n_steps(200.0, 30.0), 7);
        assert_eq!(every_n_steps(200.0, 500.0), 1);
    }
}
