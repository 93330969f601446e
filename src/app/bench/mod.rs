//! `rinscope bench`: simulation speed without recording, and a full recorded run's speed and size;
//! `bench --peer pyins` (peer.rs) against another INS.

pub mod allantools;
mod command;
mod logs;
pub mod peer;

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use serde::Serialize;

pub use command::{BenchReport, BenchRequest, Benchmark, execute};

use crate::record::sink::{self, SinkRequest};
use crate::scenario::presets;
use crate::sim::{DemodState, step};

/// One number of `rinscope bench`, as `bench --json` writes it: a change is compared against the
/// last run figure by figure (names are stable; the printed lines say the same in prose).
#[derive(Debug, Clone, Serialize)]
pub struct Figure {
    /// What was measured, e.g. `"INS pipeline/pure-coning (100 Hz, 5 algorithms)"`.
    pub name: String,
    /// The figure: the median of the repetitions where there are several.
    pub value: f64,
    /// Its unit, e.g. `"M samples/s"`, `"s"`, `"MB/h"`.
    pub unit: &'static str,
    /// The best repetition, where there are several (this VM's timings vary by 2x).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub best: Option<f64>,
}

/// The figures of one `rinscope bench` run, in the order printed.
#[derive(Debug, Default, Serialize)]
pub struct Figures {
    /// rinscope's version.
    pub version: &'static str,
    /// Cores this process could use.
    pub threads: usize,
    /// Every figure.
    pub figures: Vec<Figure>,
}

impl Figures {
    fn new() -> Self {
        Self {
            version: env!("CARGO_PKG_VERSION"),
            threads: std::thread::available_parallelism().map_or(1, std::num::NonZero::get),
            figures: Vec::new(),
        }
    }

    fn add(&mut self, name: impl Into<String>, value: f64, unit: &'static str) {
        self.figures.push(Figure { name: name.into(), value, unit, best: None });
    }

    /// A rate in millions per second from the best and median repetition (per second).
    fn rate(&mut self, name: impl Into<String>, best: f64, median: f64, unit: &'static str) {
        self.figures.push(Figure { name: name.into(), value: median / 1e6, unit, best: Some(best / 1e6) });
    }
}

/// Peak resident memory of this process, bytes (Linux; 0 elsewhere).
#[must_use]
pub fn peak_rss_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
        })
        .map_or(0, |kb| kb * 1024)
}

/// CPU time (user + system) of this process's children that have ended and been waited for, s:
/// `cutime` + `cstime` of `/proc/self/stat` (proc(5)), in the kernel's user-visible clock ticks,
/// 100 per second on Linux; 0 where there is no such file. The difference across a child's
/// `Command::output` is that child's CPU time, every thread of it, to 10 ms.
pub(crate) fn children_cpu_s() -> f64 {
    const TICKS_PER_S: f64 = 100.0;
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else { return 0.0 };
    // The command name (field 2) is in parentheses and may hold spaces: fields from the 3rd on
    // follow its last ')'. cutime and cstime are fields 16 and 17.
    let fields: Vec<&str> = stat.rsplit_once(')').map_or(Vec::new(), |(_, rest)| rest.split_whitespace().collect());
    let ticks = |field: usize| fields.get(field - 3).and_then(|f| f.parse::<u64>().ok()).unwrap_or(0);
    (ticks(16) + ticks(17)) as f64 / TICKS_PER_S
}

/// An error once `stop` is set (a signal): the benchmarks end between two measurements (each at
/// most a few seconds), as every command does.
fn check(stop: &AtomicBool) -> anyhow::Result<()> {
    anyhow::ensure!(!stop.load(std::sync::atomic::Ordering::SeqCst), "interrupted");
    Ok(())
}

/// The benchmark sections, in the order they run (`bench --only`).
pub const SECTIONS: [&str; 9] =
    ["simulation", "strapdown", "pipeline", "navigation", "logs", "recorded", "calibration", "allan", "selfcal"];

/// Runs the benchmarks (the sections in `only`; all when it is empty), prints their numbers and
/// returns them; an error as soon as `stop` is set.
pub fn run_benchmarks(steps: u64, only: &[String], stop: &AtomicBool) -> anyhow::Result<Figures> {
    let mut figs = Figures::new();
    type Section<'a> = Box<dyn FnOnce(&mut Figures) -> anyhow::Result<()> + 'a>;
    // One per SECTIONS entry, in its order (the names `--only` accepts).
    let sections: [Section<'_>; SECTIONS.len()] = [
        Box::new(|f| simulation_speed(steps, f, stop)),
        Box::new(|f| strapdown_speed(f, stop)),
        Box::new(|f| pipeline_speed(f, stop)),
        Box::new(|f| {
            navigation_speed(&crate::scenario::parse(CONING_2KHZ, "bench")?, f);
            Ok(())
        }),
        Box::new(|f| logs::log_speed(f, stop)),
        Box::new(|f| recorded_in_scratch(f, stop)),
        Box::new(|f| calibration_speed(f, stop)),
        Box::new(|f| allan_speed(f, stop)),
        Box::new(|f| selfcal_speed(f, stop)),
    ];
    for (name, run) in SECTIONS.into_iter().zip(sections) {
        check(stop)?;
        if only.is_empty() || only.iter().any(|o| o == name) {
            run(&mut figs)?;
        }
    }
    figs.add("peak resident memory", peak_rss_bytes() as f64 / 1e6, "MB");
    outln!("peak resident memory: {:.1} MB", peak_rss_bytes() as f64 / 1e6);
    Ok(figs)
}

/// Recorded runs into `dir`: every preset's hour, a 24 h INS run, the live reload latency.
fn recorded_runs(dir: &std::path::Path, figs: &mut Figures, stop: &AtomicBool) -> anyhow::Result<()> {
    // 3. Every preset for one simulated hour at its default rates, saved to a file: its speed with
    //    the recording, and the recording's size (issue 13's target: at most 30 MB per hour).
    for (name, _) in presets::PRESETS {
        check(stop)?;
        let mut p = presets::load(name)?;
        p.set_duration(3600.0);
        let path = dir.join(format!("{name}.rrd"));
        let sinks =
            sink::open(&SinkRequest { save: Some(path.clone()), ..Default::default() }, "rinscope-bench", name)?;
        let started = Instant::now();
        let summary = crate::app::run::run_recorded(&p, &sinks, stop, false)?;
        let (_, bytes) = sinks.finish()?.recording.ok_or_else(|| anyhow::anyhow!("no file written"))?;
        let secs = started.elapsed().as_secs_f64();
        std::fs::remove_file(&path).ok();
        check(stop)?;
        figs.add(format!("recorded run 1 h/{name}/wall"), secs, "s");
        figs.add(format!("recorded run 1 h/{name}/size"), bytes as f64 / 1e6, "MB/h");
        outln!(
            "recorded 1 h      {name:<32} {:6.2} MB per simulated hour (issue 33: <= 10); {} steps at {} Hz in {secs:.2} s (series {} Hz, scene {} Hz)",
            bytes as f64 / 1e6,
            summary.steps,
            p.step_hz,
            p.recording.series_hz,
            p.recording.scene_hz
        );
    }
    // 4. A 24-hour INS run at 200 Hz with navigation, recorded.
    let p = presets::load("rotation-modulation-16-position")?;
    let path = dir.join("ins24h.rrd");
    let sinks = sink::open(&SinkRequest { save: Some(path), ..Default::default() }, "rinscope-bench", "ins24h")?;
    let started = Instant::now();
    let summary = crate::app::run::run_recorded(&p, &sinks, stop, false)?;
    let (_, bytes) = sinks.finish()?.recording.ok_or_else(|| anyhow::anyhow!("no file written"))?;
    check(stop)?;
    figs.add("INS 24 h/rotation-modulation-16-position/wall", started.elapsed().as_secs_f64(), "s");
    figs.add("INS 24 h/rotation-modulation-16-position/size", bytes as f64 / 1e6, "MB");
    outln!(
        "INS 24 h          rotation-modulation-16-position: {} IMU samples at 200 Hz with navigation and recording in {:.2} s ({:.2} MB)",
        summary.steps,
        started.elapsed().as_secs_f64(),
        bytes as f64 / 1e6
    );

    // 5. Live mode's reload latency.
    live_latency(dir, figs, stop)
}

/// Pure simulation: truth + encoders + three demodulations, one core, no recording. This VM's
/// timings vary by 2x from run to run (shared cores), so the best and the median of 5.
fn simulation_speed(steps: u64, figs: &mut Figures, stop: &AtomicBool) -> anyhow::Result<()> {
    for name in ["jiang2017-dual-axis", "rotary-table-2016-wobble"] {
        let p = presets::load(name)?;
        let model = p.table_model();
        let mut rates = Vec::new();
        let mut checksum = 0.0;
        for _ in 0..5 {
            check(stop)?;
            let mut state = DemodState::default();
            checksum = 0.0;
            let started = Instant::now();
            for i in 0..steps {
                // A million steps take a fraction of a second: a signal is answered within it.
                if i % (1 << 20) == 0 {
                    check(stop)?;
                }
                let out = step(&model, &mut state, i as f64 / p.step_hz);
                checksum += out.errors[0].heading_rad + out.errors[1].pitch_rad + out.errors[2].roll_rad;
            }
            rates.push(steps as f64 / started.elapsed().as_secs_f64());
        }
        rates.sort_by(f64::total_cmp);
        figs.rate(format!("simulation only/{name}"), rates[4], rates[2], "M steps/s");
        outln!(
            "simulation only   {name:<28} {steps} steps x5: best {:.2} M steps/s, median {:.2} M steps/s (all three variants; checksum {checksum:.6e})",
            rates[4] / 1e6,
            rates[2] / 1e6
        );
    }

    Ok(())
}

/// Runs `f` in a scratch folder `rinscope-NAME-PID` under the temporary directory, removed however
/// it ends: returned, failed, or the process ended early (a second signal, a closed stdout: it is
/// registered with [`crate::io::files::remove_unfinished`]). With `RINSCOPE_BENCH_KEEP=DIR` in the
/// environment, the folder is `DIR/NAME` and kept (the inputs, to profile one process of a bench).
pub(crate) fn in_scratch<T>(name: &str, f: impl FnOnce(&std::path::Path) -> anyhow::Result<T>) -> anyhow::Result<T> {
    if let Some(keep) = std::env::var_os("RINSCOPE_BENCH_KEEP") {
        let dir = std::path::PathBuf::from(keep).join(name);
        std::fs::create_dir_all(&dir)?;
        return f(&dir);
    }
    let dir = std::env::temp_dir().join(format!("rinscope-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    crate::io::files::unfinished_dir(&dir);
    let result = f(&dir);
    std::fs::remove_dir_all(&dir).ok();
    crate::io::files::finished_dir(&dir);
    result
}

/// The recorded runs, with their files in a scratch folder.
fn recorded_in_scratch(figs: &mut Figures, stop: &AtomicBool) -> anyhow::Result<()> {
    in_scratch("bench", |dir| recorded_runs(dir, figs, stop))
}

/// Strapdown attitude update alone: samples per second through each algorithm (one core).
fn strapdown_speed(figs: &mut Figures, stop: &AtomicBool) -> anyhow::Result<()> {
    use crate::ins::coning::Algorithm;
    use crate::ins::strapdown::AttitudeIntegrator;
    use crate::math::frames::Rot;
    use nalgebra::Vector3;
    // A realistic stream: pure coning increments at 2 kHz, precomputed so that only the update is timed.
    let n = 4096usize;
    let samples: Vec<Vector3<f64>> = (0..n)
        .map(|i| {
            let (t0, t1) = (i as f64 / 2000.0, (i + 1) as f64 / 2000.0);
            let w = std::f64::consts::TAU * 5.0;
            let a = 0.01f64;
            Vector3::new(
                a.sin() * ((w * t1).cos() - (w * t0).cos()),
                a.sin() * ((w * t1).sin() - (w * t0).sin()),
                -2.0 * (0.5 * a).sin().powi(2) * w / 2000.0,
            )
        })
        .collect();
    let zeta = Vector3::new(0.0, 3e-8, 4e-8);
    for alg in Algorithm::ALL {
        check(stop)?;
        let mut best = 0.0f64;
        for _ in 0..5 {
            let mut integ = AttitudeIntegrator::new(alg, Rot::identity());
            let reps = 4000;
            let started = Instant::now();
            for _ in 0..reps {
                for s in &samples {
                    std::hint::black_box(integ.push(*s, &zeta));
                }
            }
            best = best.max((reps * n) as f64 / started.elapsed().as_secs_f64());
            std::hint::black_box(integ.n_from_s);
        }
        figs.add(format!("strapdown update/{}", alg.name()), best / 1e6, "M samples/s");
        outln!("strapdown update  {:<28} best of 5: {:.1} M samples/s (one core)", alg.name(), best / 1e6);
    }
    Ok(())
}

/// A 2 kHz, 1° / 1 Hz pure-coning IMU with Earth rate at latitude 34° (the stream of `bench --peer
/// pyins`), error-free, navigating.
const CONING_2KHZ: &str = "[scenario]\nname = \"bench-coning-2khz\"\ntitle = \"1 deg / 1 Hz coning at 2 kHz, 34 deg N\"\nseed = 0\n\
[simulation]\nduration_s = 1000.0\nstep_hz = 2000.0\n[site]\nlatitude_deg = 34.0\n\
[vehicle]\nconing_half_angle_deg = 1.0\nconing_frequency_hz = 1.0\n\
[turntable]\n[[turntable.axis]]\nname = \"mount\"\naxis = \"z\"\n[scheme]\nkind = \"static\"\n[imu]\n[navigation]\n";

/// Runs `chunk` (which does 10 000 samples) until at least 0.3 s have passed, five times: the best and
/// the median rate, samples/s (this VM's timings vary from run to run).
fn best_and_median(mut chunk: impl FnMut()) -> (f64, f64) {
    let mut rates = Vec::new();
    for _ in 0..5 {
        let started = Instant::now();
        let mut n = 0u64;
        while started.elapsed().as_secs_f64() < 0.3 {
            chunk();
            n += 10_000;
        }
        rates.push(n as f64 / started.elapsed().as_secs_f64());
    }
    rates.sort_by(f64::total_cmp);
    (rates[4], rates[2])
}

/// The whole INS pipeline (truth, IMU errors, strapdown, navigation, demodulation at 100 Hz), the exact
/// IMU truth alone on the same motion (so that its share of the pipeline's time can be stated), and
/// attitude + navigation alone on precomputed increments.
fn pipeline_speed(figs: &mut Figures, stop: &AtomicBool) -> anyhow::Result<()> {
    use crate::ins::truth::TruthImu;
    use crate::model::earth::Earth;
    let jiang = format!(
        "{}\n[imu]\npreset = \"jiang2017-table1\"\n[navigation]\n",
        crate::scenario::presets::text("jiang2017-dual-axis").unwrap_or_default()
    );
    let cases = [
        ("jiang2017-dual-axis + table-1 IMU", crate::scenario::parse(&jiang, "bench")?),
        ("coning 1 deg/1 Hz + Earth rate, 2 kHz, 34 N", crate::scenario::parse(CONING_2KHZ, "bench")?),
        ("pure-coning (100 Hz, 5 algorithms)", presets::load("pure-coning")?),
        ("rotation-modulation-16-position", presets::load("rotation-modulation-16-position")?),
        ("li2014-wobble-1 (2 kHz, dither, FIR)", presets::load("li2014-wobble-1")?),
    ];
    for (name, p) in &cases {
        check(stop)?;
        let mut ins = p.ins_run().ok_or_else(|| anyhow::anyhow!("no [imu]"))?;
        let every = (p.step_hz / 100.0).round().max(1.0) as u64;
        let mut i = 0u64;
        let (best, median) = best_and_median(|| {
            for _ in 0..10_000 {
                let s = ins.step();
                if s.updated && i.is_multiple_of(every) {
                    std::hint::black_box(ins.errors_view(s.t_s));
                }
                i += 1;
            }
        });
        let mut truth = TruthImu::new(p.table_model(), Earth::at(p.site), 0.0);
        let mut j = 0u64;
        let (truth_best, truth_median) = best_and_median(|| {
            for _ in 0..10_000 {
                j += 1;
                std::hint::black_box(truth.increments(j as f64 / p.step_hz));
            }
        });
        figs.rate(format!("INS pipeline/{name}"), best, median, "M samples/s");
        figs.rate(format!("IMU truth only/{name}"), truth_best, truth_median, "M samples/s");
        figs.add(format!("IMU truth share/{name}"), 100.0 * median / truth_median, "%");
        outln!(
            "INS pipeline      {name:<44} best {:.2} M samples/s, median {:.2} (truth + IMU + strapdown + navigation + demodulation)",
            best / 1e6,
            median / 1e6
        );
        outln!(
            "IMU truth only    {name:<44} best {:.2} M samples/s, median {:.2}: {:.0} % of the pipeline's time (medians)",
            truth_best / 1e6,
            truth_median / 1e6,
            100.0 * median / truth_median
        );
    }
    Ok(())
}

/// Attitude + navigation (the navigation computer: attitude algorithm, velocity and position) fed
/// precomputed increments of the 2 kHz coning stream: what pyins' bare kernel is timed on.
fn navigation_speed(p: &crate::scenario::Params, figs: &mut Figures) {
    use crate::ins::core::InsCore;
    use crate::ins::truth::TruthImu;
    use crate::model::earth::Earth;
    let Some(cfg) = p.ins.as_ref() else { return };
    let mut truth = TruthImu::new(p.table_model(), Earth::at(p.site), 0.0);
    // 32 cone periods, replayed cyclically: the stream stays that of a vehicle at rest.
    let samples: Vec<_> = (1..=64_000u32).map(|i| truth.increments(f64::from(i) / p.step_hz)).collect();
    let start = truth.eval(0.0).n_from_s;
    let mut core = InsCore::new(cfg, p.site, start, &[]);
    let mut k = 0usize;
    let h = 1.0 / p.step_hz;
    let (best, median) = best_and_median(|| {
        for _ in 0..10_000 {
            let (g, a) = samples[k % 64_000];
            k += 1;
            std::hint::black_box(core.push(k as f64 * h, g, a));
        }
    });
    figs.rate("attitude + nav/coning 1 deg/1 Hz + Earth rate, 2 kHz, 34 N", best, median, "M samples/s");
    outln!(
        "attitude + nav    {:<44} best {:.2} M samples/s, median {:.2} (precomputed increments, {})",
        "coning 1 deg/1 Hz + Earth rate, 2 kHz, 34 N",
        best / 1e6,
        median / 1e6,
        cfg.algorithm.name()
    );
}

/// Live mode: from the moment a save starts to the moment the simulation thread runs on the new
/// parameters, over 60 saves (half in place, half by rename), with a session running in real time.
fn live_latency(dir: &std::path::Path, figs: &mut Figures, interrupt: &AtomicBool) -> anyhow::Result<()> {
    use crate::app::live::{self, edit};
    let path = dir.join("live.toml");
    let text = crate::scenario::presets::text("jiang2017-dual-axis").ok_or_else(|| anyhow::anyhow!("preset"))?;
    std::fs::write(&path, text)?;
    let params = crate::scenario::load_file(&path)?;
    let status = live::new_status(&params, 1.0);
    let stop = std::sync::Arc::new(AtomicBool::new(false));
    let opts = live::LiveOptions {
        config_path: path.clone(),
        speed: Some(1.0),
        duration_s: None,
        panel: false,
        log_to_stderr: false,
        page_url: None,
    };
    let rec_path = dir.join("live.rrd");
    let sinks = sink::open(&SinkRequest { save: Some(rec_path), ..Default::default() }, "rinscope-bench", "live")?;
    let session = {
        let (status, stop) = (status.clone(), stop.clone());
        let outputs = live::Outputs { viewer: None, file: Some(sinks.stream()), history: None };
        std::thread::spawn(move || live::run_session_with_status(&opts, params, outputs, &stop, &status))
    };
    std::thread::sleep(std::time::Duration::from_millis(300));
    let mut latencies = Vec::new();
    for i in 0..60 {
        if interrupt.load(std::sync::atomic::Ordering::SeqCst) {
            break;
        }
        let generation = live::snapshot(&status).generation;
        let value = 300.0 + f64::from(i % 2 + 1) * 10.0 * f64::from(i + 1);
        let started = Instant::now();
        if i % 2 == 0 {
            let new = edit::set_in_text(
                text,
                &edit::KeyPath::parse("turntable.axis[1].swing_half_angle_arcsec"),
                edit::float(value),
            )
            .map_err(anyhow::Error::msg)?;
            std::fs::write(&path, new)?; // truncate and write in place
        } else {
            edit::set_in_file(
                &path,
                &edit::KeyPath::parse("turntable.axis[1].swing_half_angle_arcsec"),
                edit::float(value),
            )?; // by rename
        }
        while live::snapshot(&status).generation == generation {
            anyhow::ensure!(started.elapsed().as_secs() < 5, "save {i} was not applied within 5 s");
            std::thread::sleep(std::time::Duration::from_micros(200));
        }
        latencies.push(started.elapsed().as_secs_f64() * 1e3);
        std::thread::sleep(std::time::Duration::from_millis(120));
    }
    stop.store(true, std::sync::atomic::Ordering::SeqCst);
    session.join().map_err(|_| anyhow::anyhow!("live session panicked"))??;
    sinks.finish()?;
    check(interrupt)?;
    let mut sorted = latencies.clone();
    sorted.sort_by(f64::total_cmp);
    figs.add("live reload/median", sorted[sorted.len() / 2], "ms");
    figs.add("live reload/p95", live::p95(&latencies), "ms");
    figs.add("live reload/max", sorted[sorted.len() - 1], "ms");
    outln!(
        "live reload       save -> applied over {} saves: median {:.1} ms, p95 {:.1} ms, max {:.1} ms (debounce {} ms included)",
        sorted.len(),
        sorted[sorted.len() / 2],
        live::p95(&latencies),
        sorted[sorted.len() - 1],
        live::watch::DEBOUNCE.as_millis()
    );
    Ok(())
}

/// Issue targets for calibration and resets: one static calibration (200 s at 200 Hz, KF and exact
/// least squares), 500 Monte Carlo calibrations on all cores (target < 10 s on 2 cores), the 30 h
/// twice-position-fix comparison ("seconds, not minutes").
/// Issue 23's targets: a 2 h sequence at 200 Hz estimated in under 3 s on one core (the filter
/// alone: the simulated IMU is generated in the same loop but not counted), 100 Monte Carlo
/// self-calibrations (simulation included) in under a minute on two cores.
fn selfcal_speed(figs: &mut Figures, stop: &AtomicBool) -> anyhow::Result<()> {
    use crate::app::selfcal::{SequenceChoice, monte_carlo, run_one, setup};
    let p = presets::load("selfcal-nav-grade")?;
    let s = setup(&p, SequenceChoice::BuiltIn(crate::calib::selfcal::Sequence::DualAxis29), true)?;
    let hours = s.samples as f64 * s.config.h / 3600.0;
    let started = Instant::now();
    let one = run_one(&s, p.meta.seed, false, stop)?;
    let whole = started.elapsed().as_secs_f64();
    figs.add("selfcal/estimation per 2 h at 200 Hz", one.estimation_s * 2.0 / hours, "s");
    outln!(
        "selfcal           {}: {hours:.2} h at 200 Hz estimated in {:.2} s (= {:.2} s per 2 h; target < 3), {whole:.2} s with the IMU's simulation",
        s.sequence,
        one.estimation_s,
        one.estimation_s * 2.0 / hours
    );
    let mc = monte_carlo(&s, 100, p.meta.seed + 1, stop)?;
    figs.add("selfcal/100 Monte Carlo runs", mc.wall_s, "s");
    outln!(
        "selfcal MC        100 IMUs ({hours:.2} h each, simulated and estimated) in {:.1} s on {} threads (target < 60 s on 2)",
        mc.wall_s,
        rayon::current_num_threads()
    );
    Ok(())
}

fn calibration_speed(figs: &mut Figures, stop: &AtomicBool) -> anyhow::Result<()> {
    let p = presets::load("jiang2017-calibration")?;
    let started = Instant::now();
    let outcome = crate::app::calibrate::calibrate_scenario(&p, false, stop)?;
    check(stop)?;
    figs.add("calibration/jiang2017-calibration", started.elapsed().as_secs_f64(), "s");
    outln!(
        "calibration       jiang2017-calibration: 200 s at 200 Hz, static KF + exact least squares + validation run in {:.2} s ({} measurements)",
        started.elapsed().as_secs_f64(),
        outcome.data.samples.len()
    );
    let started = Instant::now();
    let mc = crate::app::calibrate::monte_carlo(&p, 500, &|| {}, stop)?;
    check(stop)?;
    figs.add("Monte Carlo/500 calibrations", started.elapsed().as_secs_f64(), "s");
    outln!(
        "Monte Carlo       jiang2017-calibration: {} calibrations in {:.2} s on {} threads",
        mc.runs,
        started.elapsed().as_secs_f64(),
        mc.threads
    );
    let p = presets::load("zheng2016-tpr")?;
    let r = crate::app::tpr::compare_resets(&p, 600.0, stop)?;
    check(stop)?;
    figs.add("TPR vs reset/zheng2016-tpr", r.wall_s, "s");
    outln!(
        "TPR vs reset      zheng2016-tpr: {:.0} h at {:.0} Hz, three branches after the fork, in {:.2} s",
        p.duration_s / 3600.0,
        p.step_hz,
        r.wall_s
    );
    Ok(())
}

/// Issue 15's target: the Allan analysis (overlapping ADEV at octave cluster times, EDF, confidence
/// intervals, the NNLS fit and the slope readings) of 10 h at 200 Hz, 6 channels, under 2 s on one
/// core; and the simulation of `static-imu-10h` that feeds it (truth, sensor errors with the flicker
/// bank and the rate random walk, the six cumulative sums), which `rinscope allan` runs first.
fn allan_speed(figs: &mut Figures, stop: &AtomicBool) -> anyhow::Result<()> {
    use crate::app::allan::{AllanRequest, simulate};
    use crate::ins::allan::analyze_imu;
    use crate::math::allan::{AllanOptions, Phase, TauSpacing};
    use rand::SeedableRng;
    use rand_distr::Distribution;
    let n = 7_200_000usize;
    // White noise with a random walk: the analysis does the same work whatever the signal.
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(15);
    let phases: Vec<Phase> = (0..6)
        .map(|_| {
            let mut p = Phase::with_capacity(n);
            let mut walk = 0.0;
            for _ in 0..n {
                let (a, b): (f64, f64) =
                    (rand_distr::StandardNormal.sample(&mut rng), rand_distr::StandardNormal.sample(&mut rng));
                walk += 1e-4 * b;
                p.push(1e-6 * a + 1e-6 * walk);
            }
            p
        })
        .collect();
    for (label, spacing) in [("octaves", TauSpacing::Octave), ("10 per decade", TauSpacing::PerDecade(10))] {
        let opts = AllanOptions { spacing, ..AllanOptions::default() };
        let mut best = f64::INFINITY;
        let mut taus = 0;
        for _ in 0..3 {
            let started = Instant::now();
            let channels =
                analyze_imu(&phases, 0.005, &opts, &[crate::math::allan::estimators::Estimator::Oadev], None, false)?;
            best = best.min(started.elapsed().as_secs_f64());
            taus = channels[0].report.as_ref().map_or(0, |r| r.taus_s.len());
        }
        figs.add(format!("Allan analysis/10 h, 6 channels, {label}"), best, "s");
        outln!(
            "Allan analysis    10 h at 200 Hz, 6 channels x {n} samples, {label} ({taus} cluster times), one core: best of 3 {best:.2} s (target < 2 s)"
        );
    }
    let p = presets::load("static-imu-10h")?;
    let started = Instant::now();
    let r = simulate(&p, &AllanRequest::default(), stop, &|_| {})?;
    check(stop)?;
    figs.add("Allan static-imu-10h/simulation", r.gather_s, "s");
    figs.add("Allan static-imu-10h/analysis", r.analysis_s, "s");
    outln!(
        "Allan static-imu-10h: 10 h at 200 Hz simulated (truth + sensor errors, 6 cumulative sums) in {:.2} s, analysed on all cores in {:.2} s ({:.2} s in all)",
        r.gather_s,
        r.analysis_s,
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    /// The INS figures of `rinscope bench` alone, for working on the INS's speed:
    /// `cargo test --release --lib -- --ignored ins_figures --nocapture`.
    #[test]
    #[ignore = "a benchmark, not a test"]
    fn ins_figures() -> anyhow::Result<()> {
        let mut figs = super::Figures::new();
        let stop = super::AtomicBool::new(false);
        super::strapdown_speed(&mut figs, &stop)?;
        super::pipeline_speed(&mut figs, &stop)
    }

    /// A child's CPU time as the bench reads it (`children_cpu_s` before and after) against the
    /// child's own account: a shell that spins, then prints its user and system time with the
    /// POSIX `times` builtin (the shell's times(2), on its side of the process boundary). Both
    /// count in 10 ms ticks: they agree to two ticks.
    #[test]
    fn a_childs_cpu_time_is_what_the_child_itself_reports() {
        let before = super::children_cpu_s();
        let out = std::process::Command::new("sh")
            .args(["-c", "i=0; while [ $i -lt 300000 ]; do i=$((i+1)); done; times"])
            .output()
            .expect("sh runs");
        let measured = super::children_cpu_s() - before;
        let text = String::from_utf8_lossy(&out.stdout);
        // "0m0.41s 0m0.00s" (dash) or "0m0.410000s 0m0.001000s" (bash): minutes and seconds.
        let seconds = |f: &str| -> f64 {
            let (m, s) = f.trim_end_matches('s').split_once('m').expect("XmY.Ys");
            m.parse::<f64>().expect("minutes") * 60.0 + s.parse::<f64>().expect("seconds")
        };
        let own: f64 = text.lines().next().expect("times' first line").split_whitespace().take(2).map(seconds).sum();
        assert!(own > 0.05, "the loop spun {own} s of CPU: too little to compare ({text:?})");
        assert!((measured - own).abs() <= 0.025, "children_cpu_s read {measured} s; the shell reported {own} s");
    }
}
