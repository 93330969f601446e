//! `rinscope live`: the simulation paced to the wall clock, streamed to a viewer, with the scenario
//! file watched and reloaded between steps, and a terminal panel of sliders that edits that file.
//!
//! Threads: config watcher → (channel) → simulation → (channel) → recorder; the main thread runs the
//! panel. Sliders and a text editor drive the same path: both write the file, the watcher reloads it.

mod command;
pub mod edit;
pub mod panel;
mod session;
pub mod watch;
pub mod web;

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, Sender};

use crate::ins::pipeline::InsView;
use crate::math::timeline::decimation;
use crate::record::{LiveOutput, Recorder, Stream};
use crate::scenario::{Params, RawConfig};
use crate::sim::StepOutput;
pub use command::{LiveReport, LiveRequest, SPEED, execute};
pub use session::{LiveSim, describe_changes};
use watch::WatchEvent;

/// Scene frames per wall-clock second streamed in live mode.
pub const SCENE_WALL_HZ: f64 = 30.0;
/// Series rows per wall-clock second streamed in live mode (at most).
pub const SERIES_WALL_HZ: f64 = 100.0;
/// Series rows per simulated second streamed in live mode (at most): a live session has no length
/// for the recording's default (3000 envelope buckets over the run: 25 Hz for the 120-s pure-coning
/// preset, where a software-rendered web viewer fell seconds behind within 100 s); at 10 Hz, the
/// rate issue 30's class measurements were made at, it keeps up (tests/web).
pub const SERIES_SIM_HZ: f64 = 10.0;
/// At most this many steps between two looks at the reload channel (~10 ms of work).
const MAX_STEPS_PER_SLICE: u64 = 20_000;

/// What the panel and the terminal see of the session.
#[derive(Debug, Clone)]
pub struct Status {
    /// Simulated time, s.
    pub sim_t_s: f64,
    /// Current speed factor.
    pub speed: f64,
    /// The configuration in force (bumped `generation` when it changes).
    pub resolved: RawConfig,
    /// Incremented at every applied reload.
    pub generation: u64,
    /// The last reload message.
    pub message: String,
    /// Save-to-applied latency of every applied reload, ms.
    pub latencies_ms: Vec<f64>,
    /// False once the simulation has ended.
    pub running: bool,
    /// RMS and peak of the errors since the parameters last changed.
    pub errors: crate::sim::ErrorStats,
}

/// Shared status.
pub type SharedStatus = Arc<Mutex<Status>>;

/// A consistent copy of the status.
#[must_use]
pub fn snapshot(status: &SharedStatus) -> Status {
    lock(status).clone()
}

/// What the simulation sends to the recorder.
pub enum RecorderMsg {
    /// Rows for the time series.
    Series(Vec<(StepOutput, Option<InsView>)>),
    /// Scene frames.
    Scene(Vec<(StepOutput, Option<InsView>)>),
    /// The IMU samples of the signal window (the first seconds' gyro plots).
    Signal(Vec<crate::ins::core::SampleOut>),
    /// New parameters from simulated time `t_s`.
    Reconfigure {
        /// When.
        t_s: f64,
        /// The parameters now in force.
        params: Box<Params>,
    },
    /// A text-log entry.
    Event {
        /// When.
        t_s: f64,
        /// What.
        text: String,
        /// "INFO", "WARN", "ERROR".
        level: &'static str,
    },
}

fn lock(status: &SharedStatus) -> std::sync::MutexGuard<'_, Status> {
    // A poisoned lock only means another thread panicked mid-update; the data is still usable.
    status.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Paces `sim` to the wall clock, applies reloads between steps, streams decimated outputs to `out`.
/// Returns when `stop` is set, `duration_s` is reached, or the recorder went away.
pub fn sim_loop(
    mut sim: LiveSim,
    reloads: &Receiver<WatchEvent>,
    out: &Sender<RecorderMsg>,
    status: &SharedStatus,
    stop: &AtomicBool,
    duration_s: Option<f64>,
    log_to_stderr: bool,
) -> LiveSim {
    let mut speed = lock(status).speed;
    let mut anchor = (Instant::now(), 0.0f64);
    let decimation = |speed: f64, p: &Params| {
        let scene = decimation(p.step_hz, (SCENE_WALL_HZ / speed).min(p.step_hz));
        let series = decimation(p.step_hz, p.recording.series_hz.min(SERIES_SIM_HZ))
            .max(decimation(p.step_hz, (SERIES_WALL_HZ / speed).min(p.step_hz)));
        (scene, series)
    };
    let (mut scene_every, mut series_every) = decimation(speed, &sim.params);
    let mut pending: Option<WatchEvent> = None;
    let say = |text: String, level: &'static str, t_s: f64| {
        if log_to_stderr {
            errln!("rinscope live: {text}");
        }
        lock(status).message = text.clone();
        out.send(RecorderMsg::Event { t_s, text, level }).is_ok()
    };
    loop {
        if stop.load(Ordering::Relaxed) {
            break;
        }
        // Reloads, between two steps.
        while let Some(ev) = pending.take().or_else(|| reloads.try_recv().ok()) {
            let t = sim.t_s();
            match ev {
                WatchEvent::Loaded { params, seen_at } => {
                    let new_speed = params.live_speed;
                    let speed_changed = new_speed != sim.params.live_speed;
                    match sim.apply(*params) {
                        Ok(changes) if changes.is_empty() => {}
                        Ok(changes) => {
                            let latency_ms = seen_at.elapsed().as_secs_f64() * 1e3;
                            if speed_changed {
                                speed = new_speed;
                                anchor = (Instant::now(), t);
                            }
                            (scene_every, series_every) = decimation(speed, &sim.params);
                            {
                                let mut s = lock(status);
                                s.resolved = sim.params.resolved.clone();
                                s.generation += 1;
                                s.speed = speed;
                                s.latencies_ms.push(latency_ms);
                            }
                            if out
                                .send(RecorderMsg::Reconfigure { t_s: t, params: Box::new(sim.params.clone()) })
                                .is_err()
                            {
                                return sim;
                            }
                            say(
                                format!(
                                    "reloaded at t = {t:.2} s ({latency_ms:.0} ms after the save): {}",
                                    changes.join("; ")
                                ),
                                "INFO",
                                t,
                            );
                        }
                        Err(why) => {
                            say(format!("not applied: {why}"), "WARN", t);
                        }
                    }
                }
                WatchEvent::Invalid { message, .. } => {
                    say(format!("config error, keeping the last good parameters: {message}"), "ERROR", t);
                }
                WatchEvent::Deleted => {
                    say(
                        "the config file was deleted; keeping the last parameters and waiting for it to come back"
                            .into(),
                        "WARN",
                        t,
                    );
                }
                WatchEvent::Restored => {
                    say("the config file is back".into(), "INFO", t);
                }
            }
        }

        // Catch up with the wall clock (bounded, so reloads are seen within ~10 ms).
        let mut target = anchor.1 + anchor.0.elapsed().as_secs_f64() * speed;
        if let Some(d) = duration_s {
            target = target.min(d);
        }
        let (mut series, mut scene) = (Vec::new(), Vec::new());
        let mut n = 0;
        while sim.t_s() <= target && n < MAX_STEPS_PER_SLICE {
            let i = sim.steps();
            let o = sim.step();
            if i.is_multiple_of(series_every) {
                series.push((o, sim.ins_view(false)));
            }
            if i.is_multiple_of(scene_every) {
                scene.push((o, sim.ins_view(true)));
            }
            n += 1;
        }
        let signal = sim.take_signal();
        if !signal.is_empty() && out.send(RecorderMsg::Signal(signal)).is_err() {
            return sim;
        }
        if !series.is_empty() && out.send(RecorderMsg::Series(series)).is_err() {
            return sim;
        }
        if !scene.is_empty() && out.send(RecorderMsg::Scene(scene)).is_err() {
            return sim;
        }
        {
            let mut s = lock(status);
            s.sim_t_s = sim.t_s();
            s.errors = sim.since_change;
        }
        if duration_s.is_some_and(|d| sim.t_s() > d) {
            break;
        }
        if n < MAX_STEPS_PER_SLICE {
            // Ahead of the clock: sleep until the next step is due, waking at once for a reload.
            let wait = ((sim.t_s() - target) / speed).clamp(0.0, 0.005);
            if let Ok(ev) = reloads.recv_timeout(Duration::from_secs_f64(wait)) {
                pending = Some(ev);
            }
        }
    }
    let t = sim.t_s();
    let _ = out.send(RecorderMsg::Event { t_s: t, text: format!("live session ended at t = {t:.2} s"), level: "INFO" });
    lock(status).running = false;
    sim
}

/// How often, at most, the recorder hands the 3D scene's buffered frames to viewers: 4 times a
/// second; the plots, which a user reads rather than watches move, twice.
pub const SCENE_FLUSH: Duration = Duration::from_millis(250);
/// Same for the plots.
pub const SERIES_FLUSH: Duration = Duration::from_millis(500);
/// The chunks a second the viewers' stream carries for the scene and for the plots, at most:
/// every flush is a chunk per moving entity, and a web viewer drawing without a GPU ingests what
/// arrives for 10 ms of each frame (Rerun 0.36's `receive_messages`), some 14 chunks a frame: at
/// 1.4 frames a second (headless Chromium on 2 cores, `tests/web/latency.py`, a slow hour) about
/// 20 chunks a second. Pure coning at 12 + 6 a second sent 23 a second (five moving entities
/// every 0.42 s, its plots every 1.2 s): that viewer fell behind by 2-4 s at each reload and
/// never caught up (14 s behind after a minute). Now its four moving entities go out every
/// 0.44 s and its six moving plots every 3 s, about 13 chunks a second.
/// A scene of many moving parts (or many plots) is flushed less often instead ([`Cadence`]).
pub const SCENE_CHUNKS_PER_S: f64 = 9.0;
/// Same for the plots, which a user reads rather than watches move.
pub const SERIES_CHUNKS_PER_S: f64 = 2.0;
/// The longest the scene and the plots wait between two flushes.
const SCENE_FLUSH_MAX: Duration = Duration::from_secs(1);
const SERIES_FLUSH_MAX: Duration = Duration::from_secs(3);
/// How long after a reload the viewers get what the new parameters did (a few steps of it).
const RELOAD_FLUSH: Duration = Duration::from_millis(60);
/// A plot whose rows repeat its last one (a zero error, a vehicle at rest) sends its newest row
/// to viewers this often, not at every flush ([`Recorder::flush_series_held`]): twice the plots'
/// longest wait.
pub const SERIES_HOLD: Duration = Duration::from_secs(6);

/// A request for the session so far as one recording (the class page's `/history.rrd`), answered
/// by the recorder thread with the `.rrd` bytes or why not.
pub struct HistoryRequest {
    /// Where the answer goes.
    pub reply: tokio::sync::oneshot::Sender<Result<Vec<u8>, String>>,
}

/// The session kept compact in memory for viewers that open it late (`--serve-web`).
pub struct History {
    /// Its stream.
    pub stream: Stream,
    /// What it holds.
    pub store: crate::record::sink::HistoryStore,
    /// Requests for it (the class page's).
    pub requests: Receiver<HistoryRequest>,
}

/// Where a live session's data goes.
pub struct Outputs {
    /// Viewers (spawned, connected or served): small chunks, sent every [`SCENE_FLUSH`] / [`SERIES_FLUSH`].
    pub viewer: Option<Stream>,
    /// The saved file: full-size chunks like a plain run, so the file stays compact and its footer
    /// (chunk manifest, kept in memory until the file closes) small — an hour-long session stays flat.
    pub file: Option<Stream>,
    /// The session so far for late viewers (full-size chunks, flushed when asked for).
    pub history: Option<History>,
}

/// Turns [`RecorderMsg`]s into Rerun calls until the channel closes. `viewer` flushes on a timer,
/// `file` only when its chunks are full, `history` when a late viewer asks for it.
pub fn recorder_loop(
    mut viewer: Option<Recorder>,
    mut file: Option<Recorder>,
    mut history: Option<(Recorder, History)>,
    msgs: &Receiver<RecorderMsg>,
) -> anyhow::Result<()> {
    let mut scene = Cadence::new(SCENE_FLUSH, SCENE_FLUSH_MAX, SCENE_CHUNKS_PER_S);
    let mut series = Cadence::new(SERIES_FLUSH, SERIES_FLUSH_MAX, SERIES_CHUNKS_PER_S);
    // After a reload, the first moments of the new parameters go out at once (a teacher waits for
    // them), not at the next tick.
    let mut soon: Option<Instant> = None;
    loop {
        let wait = soon.map_or(SCENE_FLUSH / 2, |at| at.saturating_duration_since(Instant::now()).min(SCENE_FLUSH / 2));
        let msg = match msgs.recv_timeout(wait) {
            Ok(m) => Some(m),
            Err(crossbeam_channel::RecvTimeoutError::Timeout) => None,
            Err(crossbeam_channel::RecvTimeoutError::Disconnected) => break,
        };
        if let Some(msg) = &msg {
            for recorder in viewer.iter_mut().chain(file.iter_mut()).chain(history.iter_mut().map(|(r, _)| r)) {
                match msg {
                    RecorderMsg::Series(rows) => {
                        rows.iter().try_for_each(|(r, ins)| recorder.push_row(r, ins.as_ref()))?
                    }
                    RecorderMsg::Scene(rows) => {
                        rows.iter().try_for_each(|(r, ins)| recorder.push_scene_row(r, ins.as_ref()))?
                    }
                    RecorderMsg::Signal(samples) => samples.iter().try_for_each(|s| recorder.push_signal(s))?,
                    RecorderMsg::Reconfigure { t_s, params } => recorder.reconfigure(*t_s, params)?,
                    RecorderMsg::Event { t_s, text, level } => recorder.event(*t_s, text, level)?,
                }
            }
        }
        if matches!(msg, Some(RecorderMsg::Reconfigure { .. })) {
            soon = Some(Instant::now() + RELOAD_FLUSH);
        }
        if let Some(v) = viewer.as_mut() {
            let reloaded = soon.is_some_and(|at| Instant::now() >= at);
            if reloaded {
                soon = None;
            }
            if reloaded || scene.due() {
                let before = v.chunks_sent();
                v.flush_scene_held()?;
                scene.flushed(v.chunks_sent() - before);
            }
            if reloaded || series.due() {
                let before = v.chunks_sent();
                v.flush_signal()?;
                v.flush_series_held(SERIES_HOLD)?;
                series.flushed(v.chunks_sent() - before);
            }
        }
        if let Some((recorder, h)) = history.as_mut() {
            while let Ok(request) = h.requests.try_recv() {
                // Everything buffered first: the late viewer gets the session up to now.
                let answer = recorder.flush_now().map_err(|e| e.to_string()).and_then(|()| h.store.rrd_bytes());
                request.reply.send(answer).ok();
            }
        }
    }
    for recorder in viewer.iter_mut().chain(file.iter_mut()).chain(history.iter_mut().map(|(r, _)| r)) {
        recorder.finish()?;
    }
    Ok(())
}

/// When the viewers' next flush of the scene or of the plots is due: at least `every` after the
/// last, later when the last sent more chunks than `per_s` allows (never later than `longest`).
struct Cadence {
    every: Duration,
    longest: Duration,
    per_s: f64,
    wait: Duration,
    last: Instant,
}

impl Cadence {
    fn new(every: Duration, longest: Duration, per_s: f64) -> Self {
        Self { every, longest, per_s, wait: every, last: Instant::now() }
    }

    fn due(&self) -> bool {
        self.last.elapsed() >= self.wait
    }

    /// A flush sent `chunks`: the next waits long enough to keep their rate.
    fn flushed(&mut self, chunks: u64) {
        self.wait = Duration::from_secs_f64(chunks as f64 / self.per_s).clamp(self.every, self.longest);
        self.last = Instant::now();
    }
}

/// Where a preset's editable copy lives: `rinscope-live/<name>.toml` in the working directory.
#[must_use]
pub fn preset_copy_path(name: &str) -> PathBuf {
    PathBuf::from("rinscope-live").join(format!("{name}.toml"))
}

/// Makes the editable copy of a preset (kept if it already exists: it holds the user's edits).
pub fn ensure_preset_copy(name: &str) -> anyhow::Result<(PathBuf, bool)> {
    let path = preset_copy_path(name);
    if path.exists() {
        return Ok((path, false));
    }
    let text = crate::scenario::presets::text(name).ok_or_else(|| anyhow::anyhow!("no preset named {name}"))?;
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    crate::io::files::write_atomically(&path, text.as_bytes())?;
    Ok((path, true))
}

/// Summary of a finished session.
#[derive(Debug, Clone)]
pub struct LiveSummary {
    /// Simulated time, s.
    pub sim_t_s: f64,
    /// Steps.
    pub steps: u64,
    /// Save-to-applied latencies of the reloads, ms.
    pub latencies_ms: Vec<f64>,
}

/// 95th percentile of `values` (nearest rank); 0 for none.
#[must_use]
pub fn p95(values: &[f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let rank = ((0.95 * v.len() as f64).ceil() as usize).clamp(1, v.len());
    v[rank - 1]
}

/// Builds the shared status for a session starting with `params`.
#[must_use]
pub fn new_status(params: &Params, speed: f64) -> SharedStatus {
    Arc::new(Mutex::new(Status {
        sim_t_s: 0.0,
        speed,
        resolved: params.resolved.clone(),
        generation: 0,
        message: String::new(),
        latencies_ms: Vec::new(),
        running: true,
        errors: crate::sim::ErrorStats::default(),
    }))
}

/// Reads the config text that the watcher will compare saves against (opened by the rule for
/// every input, [`crate::io::files::open_input`]).
pub fn read_text(path: &Path) -> std::io::Result<String> {
    use std::io::Read as _;
    let mut text = String::new();
    crate::io::files::open_input(path)?.read_to_string(&mut text)?;
    Ok(text)
}

/// How a live session runs.
#[derive(Debug, Clone)]
pub struct LiveOptions {
    /// The watched scenario file.
    pub config_path: PathBuf,
    /// Initial speed (overrides `[live] speed` until the file's value changes).
    pub speed: Option<f64>,
    /// Stop after this much simulated time (None: until the user quits).
    pub duration_s: Option<f64>,
    /// Show the terminal panel (needs a terminal).
    pub panel: bool,
    /// Without a panel: print reloads and errors to stderr.
    pub log_to_stderr: bool,
    /// The class page's URL (`--serve-web`), shown in the panel all the time.
    pub page_url: Option<String>,
}

/// Restores the terminal when dropped (normal exit, error or panic unwinding).
struct TerminalGuard;

impl Drop for TerminalGuard {
    fn drop(&mut self) {
        ratatui::restore();
    }
}

/// Runs a live session streaming into `rec` until the user quits, `stop` is set or the duration
/// is reached. The caller owns the sinks (and finishes the saved file afterwards).
pub fn run_session(
    opts: &LiveOptions,
    params: Params,
    outputs: Outputs,
    stop: &Arc<AtomicBool>,
) -> anyhow::Result<LiveSummary> {
    let status = new_status(&params, opts.speed.unwrap_or(params.live_speed));
    run_session_with_status(opts, params, outputs, stop, &status)
}

/// [`run_session`] reporting into a status the caller can watch (benchmarks, tests).
pub fn run_session_with_status(
    opts: &LiveOptions,
    params: Params,
    outputs: Outputs,
    stop: &Arc<AtomicBool>,
    status: &SharedStatus,
) -> anyhow::Result<LiveSummary> {
    let text = read_text(&opts.config_path)?;
    let (reload_tx, reload_rx) = crossbeam_channel::unbounded();
    let _watcher = watch::watch(&opts.config_path, text, reload_tx)
        .map_err(|e| anyhow::anyhow!("cannot watch {}: {e}", opts.config_path.display()))?;
    let viewer = outputs.viewer.map(|rec| Recorder::new_live(rec, &params, LiveOutput::Viewer)).transpose()?;
    let file = outputs.file.map(|rec| Recorder::new_live(rec, &params, LiveOutput::File)).transpose()?;
    let history = match outputs.history {
        Some(h) => Some((Recorder::new_live(h.stream.clone(), &params, LiveOutput::History)?, h)),
        None => None,
    };
    // Bounded: a recorder that falls behind slows the simulation instead of growing memory.
    let (out_tx, out_rx) = crossbeam_channel::bounded::<RecorderMsg>(64);
    let title = match &opts.page_url {
        Some(url) => format!("rinscope live — {} — class page: {url}", params.meta.name),
        None => format!("rinscope live — {} — {}", params.meta.name, params.meta.title),
    };
    let resolved = params.resolved.clone();

    let recorder_thread = std::thread::Builder::new()
        .name("recorder".into())
        .spawn(move || recorder_loop(viewer, file, history, &out_rx))?;
    let sim_thread = {
        let (status, stop) = (status.clone(), stop.clone());
        let (duration, log) = (opts.duration_s, opts.log_to_stderr && !opts.panel);
        std::thread::Builder::new()
            .name("simulation".into())
            .spawn(move || sim_loop(LiveSim::new(params), &reload_rx, &out_tx, &status, &stop, duration, log))?
    };

    let panel_result = if opts.panel { panel_loop(&opts.config_path, &resolved, title, status, stop) } else { Ok(()) };
    if panel_result.is_err() {
        stop.store(true, Ordering::SeqCst);
    }
    let sim = sim_thread.join().map_err(|_| anyhow::anyhow!("the simulation thread panicked"))?;
    let recorded = recorder_thread.join().map_err(|_| anyhow::anyhow!("the recorder thread panicked"))?;
    panel_result?;
    recorded?;
    let latencies_ms = lock(status).latencies_ms.clone();
    Ok(LiveSummary { sim_t_s: sim.t_s(), steps: sim.steps(), latencies_ms })
}

/// The panel on this thread: draw, read keys, write the config file for every slider move.
fn panel_loop(
    path: &Path,
    resolved: &RawConfig,
    title: String,
    status: &SharedStatus,
    stop: &AtomicBool,
) -> anyhow::Result<()> {
    use ratatui::crossterm::event::{self, Event, KeyEventKind};
    let mut terminal = ratatui::try_init()?;
    let _guard = TerminalGuard;
    let mut panel = panel::Panel::new(resolved, title);
    let shown_path = path.display().to_string();
    let mut seen_generation = 0;
    let mut last_write = Instant::now() - Duration::from_secs(10);
    loop {
        let st = lock(status).clone();
        // Follow edits made elsewhere, but not while the user is still moving a slider (the reload of
        // an older value would pull the slider back).
        if last_write.elapsed() > Duration::from_millis(400) {
            if st.generation != seen_generation {
                panel.sync(&st.resolved);
                seen_generation = st.generation;
            }
            panel.show_speed(st.speed);
        }
        terminal.draw(|f| panel.render(f, &st, &shown_path))?;
        if !st.running || stop.load(Ordering::Relaxed) {
            break;
        }
        if event::poll(Duration::from_millis(50))?
            && let Event::Key(key) = event::read()?
        {
            if key.kind != KeyEventKind::Press {
                continue;
            }
            match panel.handle(key) {
                panel::Action::Quit => {
                    stop.store(true, Ordering::SeqCst);
                    break;
                }
                panel::Action::Set(writes) => {
                    last_write = Instant::now();
                    let writes: Vec<_> = writes.into_iter().map(|(k, v)| (k, v.to_value())).collect();
                    if let Err(e) = edit::set_many_in_file(path, &writes) {
                        lock(status).message = format!("slider not written: {e}");
                    }
                }
                panel::Action::None => {}
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
