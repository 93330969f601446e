//! `schemes`' one owner: rotation schemes side by side on one IMU and table — each scheme (a
//! built-in or a user's `[scheme]`) replaces the scenario's, every scheme runs with the same seeds
//! (a Monte Carlo over the IMU's error draws and noise), in parallel on every core; per scheme the
//! position error at 24 h and at the end and the peak heading error (median and range over the
//! seeds), what the scheme turns (degrees per axis) and how far it winds the cable.

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use serde::Serialize;

use super::failure::Failure;
use super::outputs::{RecordingName, RecordingRequest, check_output, finish, logged, read_small_file, write_json};
use crate::ins::budget::{self, INS_HEADING, POSITION, Selection, Trace};
use crate::record::sink::Saved;
use crate::scenario::{self, Params};

/// The built-in schemes (assets/schemes/), for a table whose axes are "outer" and "inner".
pub const BUILT_IN: [(&str, &str); 7] = [
    ("none", include_str!("../../assets/schemes/none.toml")),
    ("single-axis-4", include_str!("../../assets/schemes/single-axis-4.toml")),
    ("continuous", include_str!("../../assets/schemes/continuous.toml")),
    ("dual-axis-8", include_str!("../../assets/schemes/dual-axis-8.toml")),
    ("dual-axis-16", include_str!("../../assets/schemes/dual-axis-16.toml")),
    ("dual-axis-32", include_str!("../../assets/schemes/dual-axis-32.toml")),
    ("dual-axis-64", include_str!("../../assets/schemes/dual-axis-64.toml")),
];

/// A built-in scheme's TOML text.
#[must_use]
pub fn built_in(name: &str) -> Option<&'static str> {
    BUILT_IN.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

/// The schemes named (each a built-in's name or a file with a `[scheme]` table; none: every
/// built-in) as (label, TOML text).
///
/// # Errors
/// A name that is neither a built-in nor a readable file (the built-ins listed).
pub fn resolve(names: &[String]) -> Result<Vec<(String, String)>, Failure> {
    if names.is_empty() {
        return Ok(BUILT_IN.iter().map(|(n, t)| ((*n).to_owned(), (*t).to_owned())).collect());
    }
    names
        .iter()
        .map(|name| {
            let text = match built_in(name) {
                Some(t) => t.to_owned(),
                None if Path::new(name).exists() => read_small_file(Path::new(name), "--schemes")?,
                None => {
                    let known: Vec<&str> = BUILT_IN.iter().map(|(n, _)| *n).collect();
                    return Err(Failure::input(format!(
                        "--schemes {name}: neither a built-in scheme ({}) nor a file",
                        known.join(", ")
                    )));
                }
            };
            Ok((name.clone(), text))
        })
        .collect()
}

/// `rinscope schemes` (and Python's `schemes`).
pub struct SchemesRequest {
    /// The scenario whose IMU, table, site and duration every scheme shares.
    pub params: Params,
    /// (label, TOML text with a `[scheme]` table): the schemes compared.
    pub schemes: Vec<(String, String)>,
    /// Seeds per scheme (the scenario's and the next ones).
    pub seeds: u64,
    /// Threads (default: every core).
    pub threads: Option<usize>,
    /// `--json`.
    pub json: Option<std::path::PathBuf>,
    /// Also each scheme's error budget (the first seed): the sources it leaves unmodulated.
    pub budget: bool,
    /// Only the sources a scheme can modulate act (`ins::averaged::modulable_only`: no noise, no
    /// alignment error), so that seeds differ by the constant errors' draws alone.
    pub modulable_only: bool,
    /// Markdown put before the comparison's table in the recording's document (the designer's
    /// model ranking); None: the table alone.
    pub preface: Option<String>,
    /// Where the recording goes.
    pub recording: RecordingRequest,
}

/// A median and the range over the seeds.
#[derive(Debug, Clone, Copy, Serialize, Default)]
pub struct Spread {
    /// The median.
    pub median: f64,
    /// The smallest.
    pub min: f64,
    /// The largest.
    pub max: f64,
}

impl Spread {
    /// The median and range of the finite values of `v` (NaN when none is).
    #[must_use]
    pub fn of(mut v: Vec<f64>) -> Self {
        v.retain(|x| x.is_finite());
        if v.is_empty() {
            return Self { median: f64::NAN, min: f64::NAN, max: f64::NAN };
        }
        v.sort_by(f64::total_cmp);
        let n = v.len();
        let median = if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) };
        Self { median, min: v[0], max: v[n - 1] }
    }
}

/// One scheme's row.
#[derive(Debug, Clone, Serialize)]
pub struct SchemeRow {
    /// Its label.
    pub scheme: String,
    /// Horizontal position error at 24 h, m (absent for a shorter run).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub position_24h_m: Option<Spread>,
    /// Horizontal position error at the end, m.
    pub position_end_m: Spread,
    /// The same per seed, in the seeds' order, m.
    pub position_end_per_seed_m: Vec<f64>,
    /// Peak horizontal position error, m.
    pub position_peak_m: Spread,
    /// Peak |heading error|, arcsec.
    pub heading_peak_arcsec: Spread,
    /// Degrees each axis turns over the run (Σ|Δangle|), by axis name.
    pub turned_deg: Vec<(String, f64)>,
    /// The largest excursion of each axis from its start over the run, deg (a cable's wrap; a
    /// continuous rotation's grows without end: it needs a slip ring).
    pub wrap_deg: Vec<(String, f64)>,
    /// One period of the scheme, s (None: not periodic).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub period_s: Option<f64>,
    /// With `--budget`: the sources whose parts of the horizontal position error are largest at the
    /// end (the first seed), m — what the scheme leaves unmodulated.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub leaves: Vec<(String, f64)>,
}

/// What `schemes` reports (and `--json` writes).
#[derive(Debug, Clone, Serialize)]
pub struct SchemesReport {
    /// The scenario.
    pub scenario: String,
    /// Simulated time, s.
    pub duration_s: f64,
    /// The seeds every scheme ran with.
    pub seeds: Vec<u64>,
    /// One row per scheme, in the order asked.
    pub rows: Vec<SchemeRow>,
    /// Runs, threads, wall time.
    pub runs: usize,
    /// Threads.
    pub threads: usize,
    /// Wall time, s.
    pub wall_s: f64,
    /// Stopped early: the numbers cover the simulated part only.
    pub interrupted: bool,
    /// The recording kept (not in the JSON).
    #[serde(skip)]
    pub saved: Option<Saved>,
}

/// `params` with its `[scheme]` replaced by the one in `text` (a scheme file or a whole scenario);
/// validated as a scenario, so an axis the table lacks is named.
///
/// # Errors
/// `text` has no `[scheme]` table, or the scenario with it does not validate.
pub fn with_scheme(params: &Params, label: &str, text: &str) -> Result<Params, Failure> {
    let value: toml::Table =
        toml::from_str(text).map_err(|e| Failure::input(format!("scheme {label}: not TOML ({})", e.message())))?;
    let scheme =
        value.get("scheme").cloned().ok_or_else(|| Failure::input(format!("scheme {label}: no [scheme] table")))?;
    let mut written = params.written.clone();
    written.scheme =
        scheme.try_into().map_err(|e: toml::de::Error| Failure::input(format!("scheme {label}: {}", e.message())))?;
    let text = toml::to_string(&written)
        .map_err(|e| Failure::run(format!("schemes: the scenario cannot be written as a file ({e})")))?;
    let mut p = scenario::parse(&text, &format!("{} with the scheme {label}", params.meta.name))?;
    p.set_duration(params.duration_s);
    Ok(p)
}

/// A number per axis, by the axis's name.
type PerAxis = Vec<(String, f64)>;

/// What a scheme turns over `duration_s`: per axis the degrees turned and the largest excursion
/// from the start (sampled at 1 Hz: a direction changes only in a dwell or never, so the sum of the
/// samples' steps is the whole turn).
fn geometry(p: &Params) -> (PerAxis, PerAxis) {
    let model = p.table_model();
    let names: Vec<String> = p.table.chain.axes().iter().map(|a| a.name.clone()).collect();
    let (start, _) = model.scheme.state(0.0);
    let (mut prev, mut turned, mut wrap) = (start, vec![0.0; names.len()], vec![0.0f64; names.len()]);
    let n = p.duration_s.floor() as u64;
    for i in 1..=n {
        let (a, _) = model.scheme.state(i as f64);
        for k in 0..names.len() {
            turned[k] += (a[k] - prev[k]).abs();
            wrap[k] = wrap[k].max((a[k] - start[k]).abs());
        }
        prev = a;
    }
    let deg = |v: Vec<f64>| names.iter().cloned().zip(v.into_iter().map(f64::to_degrees)).collect();
    (deg(turned), deg(wrap))
}

/// The radial position error of a trace's row `i`, m.
fn radial(t: &Trace, i: usize) -> f64 {
    t.values[i][POSITION[0]].hypot(t.values[i][POSITION[1]])
}

/// `schemes`' one owner.
///
/// # Errors
/// A scheme that does not fit the table, a scenario without navigation, an output that cannot be
/// written, a recording that fails.
pub fn execute(req: &SchemesRequest, stop: &AtomicBool) -> Result<SchemesReport, Failure> {
    use rayon::prelude::*;
    check_output("--json", req.json.as_deref())?;
    let base = &req.params;
    if base.ins.as_ref().is_none_or(|i| i.navigation.is_none()) {
        return Err(Failure::input(format!(
            "schemes: {} has no [imu] with [navigation]: there is no position error to compare (try budget-dual-axis-16)",
            base.meta.name
        )));
    }
    if req.schemes.is_empty() || req.seeds == 0 {
        return Err(Failure::input("schemes: give at least one scheme and one seed"));
    }
    let mut params: Vec<Params> =
        req.schemes.iter().map(|(label, text)| with_scheme(base, label, text)).collect::<Result<_, _>>()?;
    if req.modulable_only {
        for p in &mut params {
            p.ins = p.ins.as_ref().map(crate::ins::averaged::modulable_only);
        }
    }
    let sinks = req.recording.open(RecordingName {
        name: &base.meta.name,
        kind: Some("schemes"),
        seed: Some(base.meta.seed),
    })?;
    let seeds: Vec<u64> = (0..req.seeds).map(|k| base.meta.seed.wrapping_add(k)).collect();
    let runs: Vec<(usize, u64)> = (0..params.len()).flat_map(|s| seeds.iter().map(move |&seed| (s, seed))).collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(req.threads.unwrap_or(0))
        .build()
        .map_err(|e| Failure::run(format!("schemes: no thread pool ({e})")))?;
    let sample_s = super::budget::default_sample_s(base.duration_s, base.step_hz).max(1.0);
    errln!(
        "rinscope: {} schemes × {} seeds, {:.1} h each, on {} threads...",
        params.len(),
        seeds.len(),
        base.duration_s / 3600.0,
        pool.current_num_threads()
    );
    let started = Instant::now();
    let finished = std::sync::atomic::AtomicUsize::new(0);
    let keep_going = || !stop.load(Ordering::Relaxed);
    let traces: Vec<Trace> = pool.install(|| {
        runs.par_iter()
            .map(|&(s, seed)| {
                let mut p = params[s].clone();
                p.meta.seed = seed;
                let t = budget::simulate(&super::budget::setup(&p, sample_s), Selection::All, &keep_going);
                let k = finished.fetch_add(1, Ordering::Relaxed) + 1;
                errln!(
                    "rinscope: [{k}/{}] {} seed {seed} ({:.1} s)",
                    runs.len(),
                    req.schemes[s].0,
                    started.elapsed().as_secs_f64()
                );
                t
            })
            .collect()
    });
    let n = traces.iter().map(|t| t.t_s.len()).min().unwrap_or(0);
    let day = (n > 0 && traces[0].t_s[n - 1] >= 86_400.0 - 1.0)
        .then(|| traces[0].t_s[..n].iter().position(|t| *t >= 86_400.0 - 1e-6).unwrap_or(n - 1));
    let mut rows = Vec::new();
    for (s, p) in params.iter().enumerate() {
        let mine: Vec<&Trace> = runs.iter().zip(&traces).filter(|((k, _), _)| *k == s).map(|(_, t)| t).collect();
        let per = |f: &dyn Fn(&Trace) -> f64| Spread::of(mine.iter().map(|t| f(t)).collect());
        let (turned_deg, wrap_deg) = geometry(p);
        let leaves = if req.budget && !stop.load(Ordering::Relaxed) {
            let (b, _) =
                super::budget::compute(&super::budget::setup(p, sample_s), req.threads.unwrap_or(0), stop, &|_| {})?;
            let names: Vec<String> = p.table.chain.axes().iter().map(|a| a.name.clone()).collect();
            let end = |k: usize| {
                let v = b.parts[k].1.values.last().copied().unwrap_or([f64::NAN; budget::CHANNELS.len()]);
                v[POSITION[0]].hypot(v[POSITION[1]])
            };
            let mut order: Vec<usize> = (0..b.parts.len()).collect();
            order.sort_by(|x, y| end(*y).total_cmp(&end(*x)));
            order.into_iter().take(3).map(|k| (b.parts[k].0.name(&names), end(k))).collect()
        } else {
            Vec::new()
        };
        errln!("rinscope: {} done", req.schemes[s].0);
        rows.push(SchemeRow {
            scheme: req.schemes[s].0.clone(),
            position_24h_m: day.map(|i| per(&|t| radial(t, i))),
            position_end_m: per(&|t| if n > 0 { radial(t, n - 1) } else { f64::NAN }),
            position_end_per_seed_m: mine.iter().map(|t| if n > 0 { radial(t, n - 1) } else { f64::NAN }).collect(),
            position_peak_m: per(&|t| (0..n).map(|i| radial(t, i)).fold(0.0, f64::max)),
            heading_peak_arcsec: per(&|t| (0..n).map(|i| t.values[i][INS_HEADING].abs()).fold(0.0, f64::max)),
            turned_deg,
            wrap_deg,
            period_s: Some(p.table.scheme.period_s()).filter(|x| *x > 0.0),
            leaves,
        });
    }
    // Wall time to here: the runs and, with --budget, each scheme's budget.
    let wall_s = started.elapsed().as_secs_f64();
    let interrupted = stop.load(Ordering::SeqCst);
    let mut report = SchemesReport {
        scenario: base.meta.name.clone(),
        duration_s: if n > 0 { traces[0].t_s[n - 1] } else { 0.0 },
        seeds,
        rows,
        runs: runs.len(),
        threads: pool.current_num_threads(),
        wall_s,
        interrupted,
        saved: None,
    };
    // The recording: each scheme's first seed, its radial position and heading errors over time.
    let labels: Vec<String> = req.schemes.iter().map(|(l, _)| l.clone()).collect();
    let first: Vec<&Trace> = (0..params.len()).map(|s| &traces[s * report.seeds.len()]).collect();
    logged(crate::record::schemes::log(
        &sinks.stream(),
        &labels,
        &first,
        n,
        &report.short_text(),
        req.preface.as_deref(),
    ))?;
    if let Some(path) = &req.json {
        write_json("--json", path, &report)?;
    }
    report.saved = Some(finish(sinks)?);
    Ok(report)
}

impl SchemesReport {
    /// A scheme's position error at the end per seed, m (empty: no such scheme).
    #[must_use]
    pub fn per_seed_end_m(&self, label: &str) -> Vec<f64> {
        self.rows.iter().find(|r| r.scheme == label).map_or_else(Vec::new, |r| r.position_end_per_seed_m.clone())
    }

    /// The table the recording's side panel shows: per scheme the medians over the seeds.
    #[must_use]
    pub fn short_text(&self) -> String {
        let mut s = format!("{:<14} {:>9} {:>9} {:>9}\n", "median of", "pos 24h m", "pos end m", "hdg pk ″");
        for r in &self.rows {
            s.push_str(&format!(
                "{:<14} {:>9} {:>9} {:>9}\n",
                r.scheme,
                r.position_24h_m.as_ref().map_or_else(|| "—".into(), |x| num(x.median)),
                num(r.position_end_m.median),
                num(r.heading_peak_arcsec.median)
            ));
        }
        s
    }

    /// The table a terminal shows.
    #[must_use]
    pub fn text(&self) -> String {
        let mut s = format!(
            "rotation schemes on {}, {:.1} h, {} seeds each (median [min, max]) — {} runs on {} threads, {:.1} s{}\n",
            self.scenario,
            self.duration_s / 3600.0,
            self.seeds.len(),
            self.runs,
            self.threads,
            self.wall_s,
            if self.interrupted { " — INTERRUPTED: over the simulated part only" } else { "" }
        );
        let spread = |x: &Spread| format!("{} [{}, {}]", num(x.median), num(x.min), num(x.max));
        let names: Vec<&str> =
            self.rows.first().map(|r| r.turned_deg.iter().map(|(n, _)| n.as_str()).collect()).unwrap_or_default();
        let axes = |v: &[(String, f64)]| v.iter().map(|(_, x)| format!("{x:.0}")).collect::<Vec<_>>().join(" / ");
        s.push_str(&format!(
            "{:<14} {:>24} {:>24} {:>22} {:>20} {:>14}\n",
            "scheme",
            "position at 24 h (m)",
            "position at end (m)",
            "peak heading (″)",
            format!("turned {} (deg)", names.join("/")),
            "cable wrap (°)"
        ));
        for r in &self.rows {
            s.push_str(&format!(
                "{:<14} {:>24} {:>24} {:>22} {:>20} {:>14}\n",
                r.scheme,
                r.position_24h_m.as_ref().map_or_else(|| "—".into(), spread),
                spread(&r.position_end_m),
                spread(&r.heading_peak_arcsec),
                axes(&r.turned_deg),
                axes(&r.wrap_deg)
            ));
        }
        if self.rows.iter().any(|r| !r.leaves.is_empty()) {
            s.push_str("what each leaves (the largest parts of the position error at the end, first seed, m):\n");
            for r in &self.rows {
                let parts: Vec<String> = r.leaves.iter().map(|(n, x)| format!("{n} {}", num(*x))).collect();
                s.push_str(&format!("  {:<14} {}\n", r.scheme, parts.join(", ")));
            }
        }
        s
    }
}

/// A number for the table: three significant digits or so.
fn num(x: f64) -> String {
    if !x.is_finite() {
        "—".into()
    } else if x.abs() >= 100.0 {
        format!("{x:.0}")
    } else if x.abs() >= 1.0 {
        format!("{x:.1}")
    } else {
        format!("{x:.3}")
    }
}
