//! `budget`'s one owner: the error budget of a scenario (`ins::budget`) — the full run, the run
//! without any error source and one run per source alone, in parallel on every core — as a table,
//! JSON, a recording (and through it `--export` and `--figures`).

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use serde::Serialize;

use super::failure::Failure;
use super::outputs::{RecordingName, RecordingRequest, check_output, finish, logged, write_json};
use crate::ins::budget::{self, Budget, CHANNELS, Metrics, Selection, Setup, Source};
use crate::record::sink::Saved;
use crate::scenario::Params;

/// `rinscope budget` (and Python's `budget`).
pub struct BudgetRequest {
    /// The scenario (its duration already set).
    pub params: Params,
    /// The interval between the sampled instants, s (default: 4000 over the run, 0.1-60 s).
    pub sample_s: Option<f64>,
    /// Threads (default: every core).
    pub threads: Option<usize>,
    /// `--json`.
    pub json: Option<std::path::PathBuf>,
    /// Where the recording goes.
    pub recording: RecordingRequest,
}

/// One row of the budget: a source's part (or the baseline, the sum, the full run, the remainder).
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// The source's name, or "baseline", "sum", "full", "remainder".
    pub source: String,
    /// "imu", "table", "alignment"; or "baseline", "sum", "full", "remainder".
    pub kind: &'static str,
    /// Per computed channel (keys as [`channel_key`]): the value at the end, the peak, the RMS.
    pub channels: BTreeMap<String, Metrics>,
    /// The horizontal position error's size (its own, not additive), m — when navigating.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub radial_position_m: Option<Metrics>,
}

/// What `budget` reports (and `--json` writes).
#[derive(Debug, Clone, Serialize)]
pub struct BudgetReport {
    /// The scenario.
    pub scenario: String,
    /// Its seed (the IMU's draws, the encoders' noise).
    pub seed: u64,
    /// Simulated time, s.
    pub duration_s: f64,
    /// The sampled instants' interval, s.
    pub sample_s: f64,
    /// The channels computed, in order (keys of [`Row::channels`]).
    pub channels: Vec<String>,
    /// One row per source, largest first (by the headline channel), then baseline, sum, full and
    /// remainder.
    pub rows: Vec<Row>,
    /// Per channel: peak |full − (baseline + Σ parts)| / peak |full|.
    pub relative_remainder: BTreeMap<String, f64>,
    /// The channel the rows are ordered by.
    pub headline: String,
    /// Simulations run (sources + 2).
    pub runs: usize,
    /// Threads they ran on.
    pub threads: usize,
    /// Wall time of all of them, s.
    pub wall_s: f64,
    /// Stopped early: every number covers the simulated part only.
    pub interrupted: bool,
    /// The recording kept (not in the JSON).
    #[serde(skip)]
    pub saved: Option<Saved>,
}

/// The JSON / export key of channel `c` ([`budget::Channel::key`]).
#[must_use]
pub fn channel_key(c: usize) -> String {
    CHANNELS[c].key()
}

fn kind(s: &Source) -> &'static str {
    match s {
        Source::Imu(_) => "imu",
        Source::Table(_) => "table",
        Source::Alignment => "alignment",
    }
}

/// The default interval of the sampled instants: 4000 over the run, between one step and 60 s.
#[must_use]
pub fn default_sample_s(duration_s: f64, step_hz: f64) -> f64 {
    (duration_s / 4000.0).clamp(1.0 / step_hz, 60.0).max(1.0 / step_hz)
}

/// The setup every run of `params` shares.
#[must_use]
pub fn setup(params: &Params, sample_s: f64) -> Setup {
    Setup {
        table: params.table.clone(),
        ins: params.ins.clone(),
        site: params.site,
        seed: params.meta.seed,
        timeline: params.timeline(),
        sample_s,
    }
}

/// Every run of the budget of `setup` in parallel on `threads` (0: every core); `done(label)` after
/// each. Returns the budget and the threads used.
///
/// # Errors
/// A thread pool that cannot start.
pub fn compute(
    setup: &Setup,
    threads: usize,
    stop: &AtomicBool,
    done: &(dyn Fn(&str) + Sync),
) -> Result<(Budget, usize), Failure> {
    use rayon::prelude::*;
    let sources = budget::sources(&setup.table, setup.ins.as_ref());
    let mut selections = vec![Selection::All, Selection::Nothing];
    selections.extend(sources.iter().map(|s| Selection::Only(*s)));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Failure::run(format!("budget: no thread pool ({e})")))?;
    let keep_going = || !stop.load(Ordering::Relaxed);
    let names: Vec<String> = setup.table.chain.axes().iter().map(|a| a.name.clone()).collect();
    let mut traces: Vec<budget::Trace> = pool.install(|| {
        selections
            .par_iter()
            .map(|sel| {
                let t = budget::simulate(setup, *sel, &keep_going);
                done(&match sel {
                    Selection::All => "the full run".to_owned(),
                    Selection::Nothing => "the run without errors".to_owned(),
                    Selection::Only(s) => s.name(&names),
                });
                t
            })
            .collect()
    });
    let alone = sources.into_iter().zip(traces.split_off(2)).collect();
    let baseline = traces.pop().unwrap_or_default();
    let full = traces.pop().unwrap_or_default();
    Ok((budget::assemble(full, baseline, alone), pool.current_num_threads()))
}

/// The channels computed (not NaN) in `b`.
fn computed(b: &Budget) -> Vec<usize> {
    (0..CHANNELS.len()).filter(|&c| b.full.values.first().is_some_and(|r| r[c].is_finite())).collect()
}

/// The row of one part.
fn row(source: String, kind: &'static str, part: &budget::Part, channels: &[usize]) -> Row {
    let navigating = channels.contains(&budget::POSITION[0]);
    Row {
        source,
        kind,
        channels: channels.iter().map(|&c| (channel_key(c), part.metrics(c))).collect(),
        radial_position_m: navigating.then(|| part.radial_metrics()),
    }
}

/// `budget`'s one owner: every run in parallel, the report, its JSON and recording.
///
/// # Errors
/// An output that cannot be written, a sample interval out of range, a recording that fails.
pub fn execute(req: &BudgetRequest, stop: &AtomicBool) -> Result<BudgetReport, Failure> {
    check_output("--json", req.json.as_deref())?;
    let p = &req.params;
    let sample_s = req.sample_s.unwrap_or_else(|| default_sample_s(p.duration_s, p.step_hz));
    if !(sample_s.is_finite() && sample_s >= 1.0 / p.step_hz && sample_s <= p.duration_s.max(1.0 / p.step_hz)) {
        return Err(Failure::input(format!(
            "--sample-s {sample_s}: between one step ({} s) and the run's duration ({} s)",
            1.0 / p.step_hz,
            p.duration_s
        )));
    }
    let sinks =
        req.recording.open(RecordingName { name: &p.meta.name, kind: Some("budget"), seed: Some(p.meta.seed) })?;
    let setup = setup(p, sample_s);
    let n = budget::sources(&setup.table, setup.ins.as_ref()).len();
    errln!(
        "rinscope: error budget of {}: {} simulations of {:.1} h ({n} sources alone, the full run, the run without errors)...",
        p.meta.name,
        n + 2,
        p.duration_s / 3600.0
    );
    let started = Instant::now();
    let finished = std::sync::atomic::AtomicUsize::new(0);
    let (b, threads) = compute(&setup, req.threads.unwrap_or(0), stop, &|label| {
        let k = finished.fetch_add(1, Ordering::Relaxed) + 1;
        errln!("rinscope: [{k}/{}] {label} ({:.1} s)", n + 2, started.elapsed().as_secs_f64());
    })?;
    let wall_s = started.elapsed().as_secs_f64();
    let interrupted = stop.load(Ordering::SeqCst);
    let mut report = report(p, sample_s, &b, n + 2, threads, wall_s, interrupted);
    let names: Vec<String> = b.parts.iter().map(|(s, _)| s.name(&axis_names(p))).collect();
    let drawn = b.moving_channels();
    let rank = Budget::headline(&drawn).map_or_else(|| (0..b.parts.len()).collect(), |h| b.ranked(h));
    logged(crate::record::budget::log(&sinks.stream(), p, &b, &names, &rank, &drawn, &report.short_text()))?;
    if let Some(path) = &req.json {
        write_json("--json", path, &report)?;
    }
    report.saved = Some(finish(sinks)?);
    Ok(report)
}

fn axis_names(p: &Params) -> Vec<String> {
    p.table.chain.axes().iter().map(|a| a.name.clone()).collect()
}

/// The report of budget `b` of `p`.
#[must_use]
pub fn report(
    p: &Params,
    sample_s: f64,
    b: &Budget,
    runs: usize,
    threads: usize,
    wall_s: f64,
    interrupted: bool,
) -> BudgetReport {
    let channels = computed(b);
    // The rows ordered by the quantity a user looks at first.
    let headline = Budget::headline(&b.moving_channels()).or_else(|| Budget::headline(&channels)).unwrap_or(0);
    let names = axis_names(p);
    let mut rows: Vec<Row> = b
        .ranked(headline)
        .into_iter()
        .map(|k| {
            let (s, part) = &b.parts[k];
            row(s.name(&names), kind(s), part, &channels)
        })
        .collect();
    rows.push(row("baseline (no source)".into(), "baseline", &b.baseline, &channels));
    rows.push(row("baseline + Σ parts".into(), "sum", &b.sum, &channels));
    rows.push(row("full run".into(), "full", &b.full, &channels));
    rows.push(row("remainder (full − sum)".into(), "remainder", &b.remainder, &channels));
    BudgetReport {
        scenario: p.meta.name.clone(),
        seed: p.meta.seed,
        duration_s: b.t_s.last().copied().unwrap_or(0.0),
        sample_s,
        channels: channels.iter().map(|&c| channel_key(c)).collect(),
        relative_remainder: channels.iter().map(|&c| (channel_key(c), b.relative_remainder(c))).collect(),
        headline: if headline == budget::POSITION[0] { "radial_position_m".into() } else { channel_key(headline) },
        rows,
        runs,
        threads,
        wall_s,
        interrupted,
        saved: None,
    }
}

use crate::ins::budget::ROUNDING;

impl BudgetReport {
    /// The table a terminal shows: per row the peak of each channel that is not zero to rounding
    /// (the JSON has every channel's value at the end, peak and RMS), the remainder's share under it.
    #[must_use]
    pub fn text(&self) -> String {
        let mut s = format!(
            "error budget of {} (seed {}), {:.2} h, sampled every {:.3} s — {} simulations on {} threads, {:.1} s{}\n",
            self.scenario,
            self.seed,
            self.duration_s / 3600.0,
            self.sample_s,
            self.runs,
            self.threads,
            self.wall_s,
            if self.interrupted { " — INTERRUPTED: over the simulated part only" } else { "" }
        );
        let full = self.rows.iter().find(|r| r.kind == "full");
        let shown = |key: &str| full.and_then(|r| r.channels.get(key)).is_some_and(|m| m.peak >= ROUNDING);
        let cols: Vec<(usize, &str)> = self
            .channels
            .iter()
            .filter(|k| shown(k))
            .filter_map(|k| (0..CHANNELS.len()).find(|&c| channel_key(c) == *k).map(|c| (c, k.as_str())))
            .collect();
        let hidden: Vec<String> = self
            .channels
            .iter()
            .filter(|k| !shown(k))
            .filter_map(|k| (0..CHANNELS.len()).find(|&c| channel_key(c) == *k))
            .map(|c| format!("{} {}", CHANNELS[c].group, CHANNELS[c].component))
            .collect();
        let group = |c: usize| match CHANNELS[c].group {
            "INS attitude" => "INS",
            "table, uncompensated" => "table unc.",
            "table, compensated" => "table comp.",
            g => g,
        };
        let unit = |c: usize| match CHANNELS[c].unit {
            "arcsec" => "″",
            u => u,
        };
        let radial = self.rows.first().is_some_and(|r| r.radial_position_m.is_some());
        let (mut top, mut bottom) = (format!("{:<32}", "peak |error|"), format!("{:<32}", "source"));
        for (c, _) in &cols {
            top.push_str(&format!(" {:>11}", group(*c)));
            bottom.push_str(&format!(" {:>11}", format!("{} {}", CHANNELS[*c].component, unit(*c))));
        }
        if radial {
            top.push_str(&format!(" {:>11}", "position"));
            bottom.push_str(&format!(" {:>11}", "|h| m"));
        }
        s.push_str(&format!("{top}\n{bottom}\n"));
        for r in &self.rows {
            if r.kind == "baseline" {
                s.push_str(&"-".repeat(32 + 12 * (cols.len() + usize::from(radial))));
                s.push('\n');
            }
            let name: String = r.source.chars().take(32).collect();
            s.push_str(&format!("{name:<32}"));
            for (_, key) in &cols {
                s.push_str(&format!(" {:>11}", number(r.channels.get(*key).map_or(f64::NAN, |m| m.peak))));
            }
            if let Some(m) = r.radial_position_m {
                s.push_str(&format!(" {:>11}", number(m.peak)));
            }
            s.push('\n');
        }
        s.push_str(&format!("{:<32}", "remainder / full"));
        for (_, key) in &cols {
            let v = self.relative_remainder.get(*key).copied().unwrap_or(f64::NAN);
            s.push_str(&format!(" {:>11}", if v.is_nan() { "—".to_owned() } else { format!("{:.1e}", v) }));
        }
        s.push('\n');
        if !hidden.is_empty() {
            s.push_str(&format!("zero to rounding (< {ROUNDING:e}), not shown: {}\n", hidden.join(", ")));
        }
        s
    }
}

impl BudgetReport {
    /// The table the recording's document shows (narrow: a side panel): per source the headline
    /// quantities' peaks — the INS's heading and the horizontal position's size, or without an INS
    /// the uncompensated table's heading.
    #[must_use]
    pub fn short_text(&self) -> String {
        let full = self.rows.iter().find(|r| r.kind == "full");
        let moving = |key: &str| full.and_then(|r| r.channels.get(key)).is_some_and(|m| m.peak >= ROUNDING);
        let keys = [channel_key(budget::INS_HEADING), channel_key(budget::TABLE_HEADING)];
        let ins = moving(&keys[0]);
        // The table's column where the INS's is not (the side panel holds three numbers).
        let table = !ins && moving(&keys[1]);
        let radial = full.is_some_and(|r| r.radial_position_m.is_some());
        let mut s = format!("{:<28}", "peak of each part");
        if ins {
            s.push_str(&format!(" {:>10}", "heading ″"));
        }
        if radial {
            s.push_str(&format!(" {:>10}", "|pos| m"));
        }
        if table {
            s.push_str(&format!(" {:>10}", "table hdg″"));
        }
        s.push('\n');
        for r in &self.rows {
            let name: String = r.source.chars().take(28).collect();
            s.push_str(&format!("{name:<28}"));
            if ins {
                s.push_str(&format!(" {:>10}", short(r.channels.get(&keys[0]).map_or(f64::NAN, |m| m.peak))));
            }
            if let Some(m) = r.radial_position_m {
                s.push_str(&format!(" {:>10}", short(m.peak)));
            }
            if table {
                s.push_str(&format!(" {:>10}", short(r.channels.get(&keys[1]).map_or(f64::NAN, |m| m.peak))));
            }
            s.push('\n');
        }
        s
    }
}

/// A number in a width of 10 (3 significant digits).
fn short(x: f64) -> String {
    if x.is_nan() {
        "—".into()
    } else if x.abs() < ROUNDING {
        "0".into()
    } else if (1e-2..1e5).contains(&x.abs()) {
        format!("{:.4}", x).chars().take(7).collect::<String>().trim_end_matches('.').to_owned()
    } else {
        format!("{x:.2e}")
    }
}

/// A number in a width of 11: fixed where it reads, scientific where it would not, 0 below rounding.
fn number(x: f64) -> String {
    if x.is_nan() {
        "—".into()
    } else if x.abs() < ROUNDING {
        "0".into()
    } else if (1e-2..1e5).contains(&x.abs()) {
        format!("{x:.4}")
    } else {
        format!("{x:.3e}")
    }
}
