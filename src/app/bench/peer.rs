//! `rinscope bench --peer pyins`: `rinscope replay` against pyins (python-ins 1.0.1), the strapdown
//! INS of the Python ecosystem, on the same 2 kHz `.npy` streams, whole processes alternated.
//!
//! The streams come from `assets/bench/pyins/make_stream.py` (numpy only, closed-form increments of a
//! static and a coning IMU at latitude 34°, with Earth rate), so neither side's own truth model
//! is the input. Each round runs, one after the other: `rinscope replay` of the stream as a log set
//! (whole process: reading, navigation, the recording written), pyins' bare navigation kernel and
//! its full pipeline (`assets/bench/pyins/pyins_bench.py`; both time their own region, imports and
//! JIT excluded, which favours pyins), and `rinscope run` of the same motion as a scenario (whole
//! process: its own exact IMU truth, the INS, the table's statistics, the recording). Ratios are taken within a round (the three processes ran
//! within seconds of each other on a shared machine) and reported as median and range over rounds.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, anyhow, bail, ensure};
use serde::Serialize;
use serde_json::Value;

const MAKE_STREAM: &str = include_str!("../../../assets/bench/pyins/make_stream.py");
const PYINS_BENCH: &str = include_str!("../../../assets/bench/pyins/pyins_bench.py");

/// What `bench --peer pyins` runs.
#[derive(Debug, Clone)]
pub struct PeerOptions {
    /// The Python interpreter that has `python-ins==1.0.1` (and numpy).
    pub python: PathBuf,
    /// Alternated rounds per stream.
    pub rounds: usize,
    /// Samples per stream (2 M: 1000 s at 2 kHz).
    pub samples: u64,
}

/// An error once `stop` is set: the comparison ends between two processes.
fn check(stop: &std::sync::atomic::AtomicBool) -> anyhow::Result<()> {
    ensure!(!stop.load(std::sync::atomic::Ordering::SeqCst), "interrupted");
    Ok(())
}

/// One process's numbers in one round.
#[derive(Debug, Clone, Serialize)]
pub struct Timing {
    /// Wall time of the whole process, s.
    pub process_s: f64,
    /// The time the tool reports for its own timed region, s (rinscope: the replay loop).
    pub region_s: f64,
    /// Peak resident memory, MB.
    pub peak_rss_mb: f64,
    /// CPU time of the whole process (user + system, all its threads), s; 0 for a region timed in
    /// this process. Over `process_s`, the cores it kept busy: a process that saturates the machine
    /// gets faster only with less CPU.
    pub cpu_s: f64,
}

/// Median and range over the rounds.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Spread {
    /// Median.
    pub median: f64,
    /// Smallest.
    pub min: f64,
    /// Largest.
    pub max: f64,
}

impl Spread {
    pub(crate) fn of(mut v: Vec<f64>) -> Self {
        v.sort_by(f64::total_cmp);
        let n = v.len();
        let median = if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) };
        Self { median, min: v[0], max: v[n - 1] }
    }
}

/// A final navigation state in one convention: roll, pitch, heading (deg), latitude, longitude (deg),
/// height (m), velocity ENU (m/s).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct State {
    /// Roll, pitch, heading, deg.
    pub rph_deg: [f64; 3],
    /// Latitude, longitude, deg; height, m.
    pub lla: [f64; 3],
    /// Velocity East, North, Up, m/s.
    pub vel_enu_mps: [f64; 3],
}

impl State {
    /// Attitude difference per axis, arcsec (heading wrapped), and horizontal/vertical position
    /// difference, m.
    fn minus(&self, o: &Self) -> Difference {
        let d = |a: f64, b: f64| (a - b + 540.0).rem_euclid(360.0) - 180.0;
        let lat = self.lla[0].to_radians();
        let north = (self.lla[0] - o.lla[0]).to_radians() * 6_371_000.0;
        let east = (self.lla[1] - o.lla[1]).to_radians() * 6_371_000.0 * lat.cos();
        Difference {
            attitude_arcsec: [0, 1, 2].map(|i| d(self.rph_deg[i], o.rph_deg[i]) * 3600.0),
            horizontal_m: north.hypot(east),
            height_m: self.lla[2] - o.lla[2],
            velocity_mps: [0, 1, 2].map(|i| self.vel_enu_mps[i] - o.vel_enu_mps[i]),
        }
    }
}

/// The difference of two final states.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Difference {
    /// Roll, pitch, heading, arcsec.
    pub attitude_arcsec: [f64; 3],
    /// Horizontal position, m (spherical Earth, 6371 km: a difference of metres, not a geodesy).
    pub horizontal_m: f64,
    /// Height, m.
    pub height_m: f64,
    /// Velocity East, North, Up, m/s.
    pub velocity_mps: [f64; 3],
}

/// The comparison on one stream.
#[derive(Debug, Clone, Serialize)]
pub struct StreamReport {
    /// "static" or "coning".
    pub stream: String,
    /// Samples in the stream.
    pub samples: u64,
    /// The `rinscope replay` processes, one per round.
    pub rinscope: Vec<Timing>,
    /// pyins' bare kernel processes.
    pub pyins_kernel: Vec<Timing>,
    /// pyins' full pipeline processes.
    pub pyins_pipeline: Vec<Timing>,
    /// `rinscope run` of the same motion (whole process: the exact IMU truth generated, the INS,
    /// the table's error statistics, the recording written), one per round.
    pub rinscope_run: Vec<Timing>,
    /// pyins kernel region / `rinscope run` whole process, per round.
    pub ratio_run_kernel: Spread,
    /// On the coning stream: `rinscope run --scenario pure-coning` for as many samples at its
    /// 100 Hz (five algorithms, each one's exact error at every sample), whole process, per round.
    pub rinscope_pure_coning: Vec<Timing>,
    /// pyins kernel region / that process, per round (None on the static stream).
    pub ratio_pure_coning_kernel: Option<Spread>,
    /// rinscope's INS pipeline on the same motion, timed in this process (the exact IMU truth,
    /// sensor model, strapdown, navigation and the error views at 100 Hz, as `rinscope bench`'s
    /// "INS pipeline" line; no statistics at every update, no recording), one per round.
    pub rinscope_pipeline: Vec<Timing>,
    /// pyins kernel region / rinscope pipeline region, per round: the INS pipeline with its own
    /// IMU truth against the bare kernel handed increments.
    pub ratio_pipeline_kernel: Spread,
    /// pyins kernel region / rinscope whole process, per round.
    pub ratio_kernel: Spread,
    /// pyins pipeline region / rinscope whole process, per round.
    pub ratio_pipeline: Spread,
    /// pyins pipeline whole process / rinscope whole process, per round.
    pub ratio_pipeline_process: Spread,
    /// The exact final state (the generator's closed form).
    pub truth: State,
    /// rinscope's final state.
    pub rinscope_final: State,
    /// pyins' final state (kernel; its pipeline integrates the same increments).
    pub pyins_final: State,
    /// rinscope − truth.
    pub rinscope_error: Difference,
    /// pyins − truth.
    pub pyins_error: Difference,
    /// rinscope − pyins.
    pub agreement: Difference,
}

/// Runs the comparison on the static and the coning stream in a scratch folder.
pub fn compare(opts: &PeerOptions, stop: &std::sync::atomic::AtomicBool) -> anyhow::Result<Vec<StreamReport>> {
    ensure!(opts.rounds >= 1, "--rounds must be at least 1");
    check_python(&opts.python)?;
    super::in_scratch("peer", |dir| {
        std::fs::write(dir.join("make_stream.py"), MAKE_STREAM)?;
        std::fs::write(dir.join("pyins_bench.py"), PYINS_BENCH)?;
        let mut reports = Vec::new();
        for kind in ["static", "coning"] {
            reports.push(compare_stream(opts, dir, kind, stop)?);
        }
        Ok(reports)
    })
}

fn check_python(python: &Path) -> anyhow::Result<()> {
    let out = Command::new(python)
        .args(["-c", "import importlib.metadata as m; print(m.version('python-ins'))"])
        .output()
        .with_context(|| format!("cannot run the Python interpreter {} (give one with --python)", python.display()))?;
    let version = String::from_utf8_lossy(&out.stdout).trim().to_owned();
    if !out.status.success() {
        bail!(
            "{} has no pyins: install it with `{} -m pip install python-ins==1.0.1` (assets/bench/pyins/requirements-lock.txt has the versions measured)",
            python.display(),
            python.display()
        );
    }
    if version != "1.0.1" {
        errln!("note: {} has python-ins {version}; the numbers in docs/benchmarks.md are for 1.0.1", python.display());
    }
    Ok(())
}

fn compare_stream(
    opts: &PeerOptions,
    dir: &Path,
    kind: &str,
    stop: &std::sync::atomic::AtomicBool,
) -> anyhow::Result<StreamReport> {
    let stream = dir.join(format!("{kind}.npy"));
    let out = Command::new(&opts.python)
        .arg(dir.join("make_stream.py"))
        .arg(kind)
        .arg(&stream)
        .arg("--n")
        .arg(opts.samples.to_string())
        .output()?;
    ensure!(out.status.success(), "make_stream.py {kind} failed: {}", String::from_utf8_lossy(&out.stderr));
    let meta: Value = serde_json::from_str(&std::fs::read_to_string(dir.join(format!("{kind}.json")))?)?;
    let num = |v: &Value, what: &str| v.as_f64().ok_or_else(|| anyhow!("make_stream.py's sidecar lacks {what}"));
    let triple = |v: &Value, what: &str| -> anyhow::Result<[f64; 3]> {
        Ok([num(&v[0], what)?, num(&v[1], what)?, num(&v[2], what)?])
    };
    let (rate, lat) = (num(&meta["rate_hz"], "rate_hz")?, num(&meta["initial"]["lla"][0], "initial.lla")?);
    let rph0 = triple(&meta["initial"]["rph"], "initial.rph")?;
    let truth = State {
        rph_deg: triple(&meta["truth_final"]["rph"], "truth_final.rph")?,
        lla: triple(&meta["truth_final"]["lla"], "truth_final.lla")?,
        vel_enu_mps: triple(&meta["truth_final"]["vel_enu"], "truth_final.vel_enu")?,
    };

    let logs = dir.join(format!("{kind}-log"));
    write_log_set(&logs, &stream, rate, lat, kind, &meta)?;
    let scenario = dir.join(format!("{kind}-scenario.toml"));
    std::fs::write(&scenario, simulated(kind, opts.samples as f64 / rate, rate, lat, &meta)?)?;

    let pipeline_params =
        crate::scenario::parse(&std::fs::read_to_string(&scenario)?, "bench").map_err(|e| anyhow!("{e}"))?;
    let mut rounds: Vec<[Timing; 5]> = Vec::new();
    let mut pure = Vec::new();
    let (mut ours, mut theirs) = (None, None);
    let args_pyins = |mode: &str| -> Vec<String> {
        let mut a = vec![
            dir.join("pyins_bench.py").display().to_string(),
            mode.to_owned(),
            stream.display().to_string(),
            "--rph".to_owned(),
        ];
        a.extend(rph0.iter().map(|x| x.to_string()));
        a.push("--lla".to_owned());
        a.extend([lat, 0.0, 0.0].iter().map(|x| x.to_string()));
        a
    };
    for round in 0..opts.rounds {
        check(stop)?;
        errln!("peer pyins: {kind} stream, round {} of {}", round + 1, opts.rounds);
        let (r, state) = run_rinscope(&logs)?;
        let (k, kstate) = run_pyins(&opts.python, &args_pyins("kernel"))?;
        let (p, _) = run_pyins(&opts.python, &args_pyins("pipeline"))?;
        let s = run_simulated(&scenario)?;
        let q = time_pipeline(&pipeline_params, opts.samples)?;
        if kind == "coning" {
            pure.push(run_pure_coning(dir, opts.samples)?);
        }
        ours = Some(state);
        theirs = Some(kstate);
        rounds.push([r, k, p, s, q]);
    }
    let (ours, theirs) = (ours.ok_or_else(|| anyhow!("no round ran"))?, theirs.ok_or_else(|| anyhow!("no round ran"))?);
    let ratio = |f: &dyn Fn(&[Timing; 5]) -> f64| Spread::of(rounds.iter().map(f).collect());
    Ok(StreamReport {
        stream: kind.to_owned(),
        samples: opts.samples,
        ratio_kernel: ratio(&|r| r[1].region_s / r[0].process_s),
        ratio_pipeline: ratio(&|r| r[2].region_s / r[0].process_s),
        ratio_pipeline_process: ratio(&|r| r[2].process_s / r[0].process_s),
        ratio_run_kernel: ratio(&|r| r[1].region_s / r[3].process_s),
        ratio_pure_coning_kernel: (!pure.is_empty())
            .then(|| Spread::of(rounds.iter().zip(&pure).map(|(r, p)| r[1].region_s / p.process_s).collect())),
        rinscope_pure_coning: pure,
        rinscope_run: rounds.iter().map(|r| r[3].clone()).collect(),
        ratio_pipeline_kernel: ratio(&|r| r[1].region_s / r[4].region_s),
        rinscope_pipeline: rounds.iter().map(|r| r[4].clone()).collect(),
        rinscope: rounds.iter().map(|r| r[0].clone()).collect(),
        pyins_kernel: rounds.iter().map(|r| r[1].clone()).collect(),
        pyins_pipeline: rounds.iter().map(|r| r[2].clone()).collect(),
        rinscope_error: ours.minus(&truth),
        pyins_error: theirs.minus(&truth),
        agreement: ours.minus(&theirs),
        truth,
        rinscope_final: ours,
        pyins_final: theirs,
    })
}

/// The stream as a log set: npy7 increments in RFU, the navigation free in height (as pyins), the
/// two-sample coning algorithm (pyins' "increment" integration uses the same previous-sample
/// correction), no FIR, and the exact start attitude of the generator at the end of the pre-roll.
fn write_log_set(dir: &Path, stream: &Path, rate: f64, lat: f64, kind: &str, meta: &Value) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir)?;
    std::fs::write(
        dir.join("table.toml"),
        format!(
            "[site]\nlatitude_deg = {lat}\n\n[turntable]\n[[turntable.axis]]\nname = \"table\"\naxis = \"z\"\n\n[imu]\nalgorithm = \"two-sample-p1\"\n\n[navigation]\nvertical = \"free\"\n"
        ),
    )?;
    let manifest = |q: [f64; 4]| {
        format!(
            "[log]\nname = \"pyins-{kind}\"\ndescription = \"make_stream.py {kind}: {rate} Hz at latitude {lat} deg (the pyins benchmark stream)\"\n\n[imu]\nfile = {:?}\nlayout = \"npy7\"\nkind = \"increments\"\nrate_hz = {rate}\nframe = \"rfu\"\ntime = \"s\"\n\n[initial]\nimu_quaternion_wxyz = [{}, {}, {}, {}]\n",
            stream.display().to_string(),
            q[0],
            q[1],
            q[2],
            q[3]
        )
    };
    std::fs::write(dir.join("log.toml"), manifest([1.0, 0.0, 0.0, 0.0]))?;
    let log = crate::scenario::logset::load(dir).map_err(|e| anyhow!("{e}"))?;
    let t = crate::ins::core::InsCore::pre_roll_samples(&log.table.ins) as f64 / rate;
    // make_stream.py's attitude: C_b^n = K(t) = (cos a/2, sin a/2 cos wt, sin a/2 sin wt, 0) for the
    // cone, the identity at rest; the replay starts at the end of its pre-roll, t.
    let q = if kind == "coning" {
        let a = meta["alpha_deg"].as_f64().ok_or_else(|| anyhow!("sidecar lacks alpha_deg"))?.to_radians();
        let w = std::f64::consts::TAU * meta["freq_hz"].as_f64().ok_or_else(|| anyhow!("sidecar lacks freq_hz"))?;
        [(0.5 * a).cos(), (0.5 * a).sin() * (w * t).cos(), (0.5 * a).sin() * (w * t).sin(), 0.0]
    } else {
        [1.0, 0.0, 0.0, 0.0]
    };
    std::fs::write(dir.join("log.toml"), manifest(q))?;
    Ok(())
}

/// The stream's motion as a scenario, for `rinscope run` to generate its own exact IMU truth: the
/// same rate, latitude, cone, start attitude convention and navigation settings as the log set.
fn simulated(kind: &str, duration_s: f64, rate: f64, lat: f64, meta: &Value) -> anyhow::Result<String> {
    let vehicle = if kind == "coning" {
        let a = meta["alpha_deg"].as_f64().ok_or_else(|| anyhow!("sidecar lacks alpha_deg"))?;
        let f = meta["freq_hz"].as_f64().ok_or_else(|| anyhow!("sidecar lacks freq_hz"))?;
        format!("[vehicle]\nconing_half_angle_deg = {a}\nconing_frequency_hz = {f}\n")
    } else {
        String::new()
    };
    Ok(format!(
        "[scenario]\nname = \"pyins-{kind}-simulated\"\ntitle = \"make_stream.py {kind}, simulated by rinscope\"\nseed = 0\n\
         [simulation]\nduration_s = {duration_s}\nstep_hz = {rate}\n[site]\nlatitude_deg = {lat}\n{vehicle}\
         [turntable]\n[[turntable.axis]]\nname = \"table\"\naxis = \"z\"\n[scheme]\nkind = \"static\"\n\
         [imu]\nalgorithm = \"two-sample-p1\"\n[navigation]\nvertical = \"free\"\n"
    ))
}

/// The INS pipeline over `samples` samples of `p`, in this process: what `rinscope bench` times
/// as "INS pipeline" (the error views at 100 Hz).
fn time_pipeline(p: &crate::scenario::Params, samples: u64) -> anyhow::Result<Timing> {
    let mut ins = p.ins_run().ok_or_else(|| anyhow!("the scenario has no [imu]"))?;
    let every = (p.step_hz / 100.0).round().max(1.0) as u64;
    let started = Instant::now();
    for i in 0..samples {
        let s = ins.step();
        if s.updated && i.is_multiple_of(every) {
            std::hint::black_box(ins.errors_view(s.t_s));
        }
    }
    let region_s = started.elapsed().as_secs_f64();
    Ok(Timing {
        process_s: region_s,
        region_s,
        peak_rss_mb: crate::app::bench::peak_rss_bytes() as f64 / 1e6,
        cpu_s: 0.0,
    })
}

/// This rinscope as a whole process: `command` on `input`, saving beside `stem`, its summary JSON
/// read back. Returns the wall time of the process and the summary.
fn run_self(command: &str, input: &[&std::ffi::OsStr], stem: &Path) -> anyhow::Result<(f64, f64, Value)> {
    let json = stem.with_extension("json");
    let cpu_before = super::children_cpu_s();
    let started = Instant::now();
    let out = Command::new(std::env::current_exe()?)
        .arg(command)
        .args(input)
        .arg("--save")
        .arg(stem.with_extension("rrd"))
        .arg("--summary-json")
        .arg(&json)
        .output()?;
    let process_s = started.elapsed().as_secs_f64();
    let cpu_s = super::children_cpu_s() - cpu_before;
    ensure!(out.status.success(), "rinscope {command} failed: {}", String::from_utf8_lossy(&out.stderr));
    Ok((process_s, cpu_s, serde_json::from_str(&std::fs::read_to_string(&json)?)?))
}

/// The timing fields of a summary.
fn timing((process_s, cpu_s, s): &(f64, f64, Value)) -> anyhow::Result<Timing> {
    let num = |k: &str| s[k].as_f64().ok_or_else(|| anyhow!("the summary lacks {k}"));
    Ok(Timing { process_s: *process_s, region_s: num("wall_time_s")?, peak_rss_mb: num("peak_rss_mb")?, cpu_s: *cpu_s })
}

/// `rinscope run --scenario pure-coning` for `samples` samples at its 100 Hz, whole process.
fn run_pure_coning(dir: &Path, samples: u64) -> anyhow::Result<Timing> {
    let duration = format!("{}", samples as f64 / 100.0);
    let args = ["--scenario".as_ref(), "pure-coning".as_ref(), "--duration-s".as_ref(), duration.as_ref()];
    timing(&run_self("run", &args, &dir.join("pure-coning"))?)
}

/// `rinscope run` of a scenario, whole process.
fn run_simulated(scenario: &Path) -> anyhow::Result<Timing> {
    timing(&run_self("run", &["--config".as_ref(), scenario.as_os_str()], scenario)?)
}

fn run_rinscope(logs: &Path) -> anyhow::Result<(Timing, State)> {
    let done = run_self("replay", &[logs.as_os_str()], &logs.join("replay"))?;
    let f = &done.2["final_state"];
    let num =
        |v: &Value| v.as_f64().ok_or_else(|| anyhow!("replay summary lacks a final state (is the navigation on?)"));
    let state = State {
        rph_deg: [num(&f["imu_roll_deg"])?, num(&f["imu_pitch_deg"])?, num(&f["imu_heading_deg"])?],
        lla: [num(&f["latitude_deg"])?, num(&f["longitude_deg"])?, num(&f["height_m"])?],
        vel_enu_mps: [
            num(&f["velocity_enu_mps"][0])?,
            num(&f["velocity_enu_mps"][1])?,
            num(&f["velocity_enu_mps"][2])?,
        ],
    };
    Ok((timing(&done)?, state))
}

fn run_pyins(python: &Path, args: &[String]) -> anyhow::Result<(Timing, State)> {
    let cpu_before = super::children_cpu_s();
    let started = Instant::now();
    let out = Command::new(python).args(args).output()?;
    let process_s = started.elapsed().as_secs_f64();
    let cpu_s = super::children_cpu_s() - cpu_before;
    ensure!(out.status.success(), "pyins_bench.py {} failed: {}", args[1], String::from_utf8_lossy(&out.stderr));
    let line = String::from_utf8_lossy(&out.stdout);
    let v: Value = serde_json::from_str(line.lines().last().unwrap_or_default()).context("pyins_bench.py's output")?;
    let num = |k: &str| v[k].as_f64().ok_or_else(|| anyhow!("pyins_bench.py's output lacks {k}"));
    let state = State {
        rph_deg: [num("roll_deg")?, num("pitch_deg")?, num("heading_deg")?],
        lla: [num("lat_deg")?, num("lon_deg")?, num("height_m")?],
        vel_enu_mps: [num("vel_east")?, num("vel_north")?, num("vel_up")?],
    };
    Ok((Timing { process_s, region_s: num("seconds")?, peak_rss_mb: num("peak_rss_mb")?, cpu_s }, state))
}

/// The comparison as text.
#[must_use]
pub fn text(reports: &[StreamReport]) -> String {
    let mut s = String::new();
    let spread = |v: Vec<f64>| Spread::of(v);
    for r in reports {
        let line = |name: &str, t: &[Timing], region: &str| {
            let p = spread(t.iter().map(|x| x.process_s).collect());
            let g = spread(t.iter().map(|x| x.region_s).collect());
            let m = spread(t.iter().map(|x| x.peak_rss_mb).collect());
            let c = spread(t.iter().map(|x| x.cpu_s).collect());
            let cores = spread(t.iter().map(|x| x.cpu_s / x.process_s.max(1e-9)).collect());
            format!(
                "  {name:<16} whole process {:.2} s [{:.2}, {:.2}]   {region} {:.2} s [{:.2}, {:.2}]   peak RSS {:.0} MB   CPU {:.2} s ({:.1} cores busy)\n",
                p.median, p.min, p.max, g.median, g.min, g.max, m.max, c.median, cores.median
            )
        };
        s.push_str(&format!(
            "peer pyins 1.0.1  {} stream, {} samples at 2 kHz, {} alternated rounds (median [min, max])\n",
            r.stream,
            r.samples,
            r.rinscope.len()
        ));
        s.push_str(&line("rinscope replay", &r.rinscope, "replay loop "));
        s.push_str(&line("pyins kernel", &r.pyins_kernel, "kernel      "));
        s.push_str(&line("pyins pipeline", &r.pyins_pipeline, "pipeline    "));
        s.push_str(&line("rinscope run", &r.rinscope_run, "run loop    "));
        if !r.rinscope_pure_coning.is_empty() {
            s.push_str(&line("rinscope coning5", &r.rinscope_pure_coning, "run loop    "));
        }
        let q = spread(r.rinscope_pipeline.iter().map(|x| x.region_s).collect());
        s.push_str(&format!(
            "  {:<16} in this process                 pipeline     {:.2} s [{:.2}, {:.2}]\n",
            "rinscope INS", q.median, q.min, q.max
        ));
        let ratio = |x: Spread| format!("{:.1}x [{:.1}, {:.1}]", x.median, x.min, x.max);
        s.push_str(&format!(
            "  speed: pyins kernel / rinscope replay process {} (issue 33: >= 5x); pyins pipeline / rinscope replay process {} (target >= 10x); whole processes {}\n",
            ratio(r.ratio_kernel),
            ratio(r.ratio_pipeline),
            ratio(r.ratio_pipeline_process)
        ));
        s.push_str(&format!(
            "  speed: pyins kernel / rinscope INS pipeline with its own exact IMU truth {} (issue 13: >= 3x); / rinscope run process (+ error statistics at every update, the table, the recording) {} (issue 33: >= 3x)\n",
            ratio(r.ratio_pipeline_kernel),
            ratio(r.ratio_run_kernel)
        ));
        if let Some(x) = r.ratio_pure_coning_kernel {
            s.push_str(&format!(
                "  speed: pyins kernel / rinscope run --scenario pure-coning process ({} samples at 100 Hz, five algorithms, each one's exact error at every sample: `rinscope coning5`) {} (issue 33: >= 1.5x)\n",
                r.samples,
                ratio(x)
            ));
        }
        let diff = |d: &Difference| {
            format!(
                "roll {:+.2e}″ pitch {:+.2e}″ heading {:+.2e}″, horizontal {:.2e} m, height {:+.2e} m, velocity ENU [{:+.1e}, {:+.1e}, {:+.1e}] m/s",
                d.attitude_arcsec[0],
                d.attitude_arcsec[1],
                d.attitude_arcsec[2],
                d.horizontal_m,
                d.height_m,
                d.velocity_mps[0],
                d.velocity_mps[1],
                d.velocity_mps[2]
            )
        };
        s.push_str(&format!("  final state, rinscope − truth: {}\n", diff(&r.rinscope_error)));
        s.push_str(&format!("  final state, pyins − truth:    {}\n", diff(&r.pyins_error)));
        s.push_str(&format!("  final state, rinscope − pyins: {}\n", diff(&r.agreement)));
    }
    s
}
