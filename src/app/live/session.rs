//! The simulation of a live session: the turntable step whose parameters can be replaced between
//! two steps, and the words that say what a reload changed.

use crate::ins::pipeline::{InsRun, InsView};
use crate::model::scheme::AxisValues;
use crate::scenario::{self, Params, RawConfig};
use crate::sim::{DemodState, ErrorStats, Model, StepOutput, step};

/// The simulation of a live session: a [`Model`] that can be replaced between two steps.
pub struct LiveSim {
    /// The parameters in force.
    pub params: Params,
    /// Their model (with the scheme re-anchored at the last scheme change).
    pub model: Model,
    state: DemodState,
    step_index: u64,
    /// RMS and peak over the session.
    pub stats: ErrorStats,
    /// RMS and peak since the parameters last changed (what the panel shows).
    pub since_change: ErrorStats,
    last_gimbal_rad: AxisValues,
    /// The INS in the loop (a scenario with `[imu]`): one IMU sample per step, as `run` does.
    ins: Option<InsRun>,
    /// The instant of the INS's latest attitude update.
    ins_update_s: Option<f64>,
    /// The IMU samples of the signal window (the first seconds' raw and filtered gyro plots) not
    /// yet handed to the recorder.
    signal: Vec<crate::ins::core::SampleOut>,
    /// The step rate in force, Hz, and the instant and step from which it counts.
    step_hz: f64,
    rate_since: (f64, u64),
    /// A new step rate waiting for the INS to finish its updates in progress.
    pending_rate_hz: Option<f64>,
}

impl LiveSim {
    /// Starts at t = 0.
    #[must_use]
    pub fn new(params: Params) -> Self {
        let model = params.table_model();
        let last_gimbal_rad = model.scheme.state(0.0).0;
        let ins = params.ins_run();
        let step_hz = params.step_hz;
        Self {
            params,
            model,
            state: DemodState::default(),
            step_index: 0,
            stats: ErrorStats::default(),
            since_change: ErrorStats::default(),
            last_gimbal_rad,
            ins,
            ins_update_s: None,
            signal: Vec::new(),
            step_hz,
            rate_since: (0.0, 0),
            pending_rate_hz: None,
        }
    }

    /// Simulated time of the next step, s.
    #[must_use]
    pub fn t_s(&self) -> f64 {
        self.rate_since.0 + (self.step_index - self.rate_since.1) as f64 / self.step_hz
    }

    /// The step rate in force, Hz (a new one applies once the INS is between two updates).
    #[must_use]
    pub fn step_hz(&self) -> f64 {
        self.step_hz
    }

    /// Number of steps taken.
    #[must_use]
    pub fn steps(&self) -> u64 {
        self.step_index
    }

    /// One step.
    pub fn step(&mut self) -> StepOutput {
        let t = self.t_s();
        if let Some(ins) = self.ins.as_mut() {
            let s = ins.step();
            if s.updated {
                self.ins_update_s = Some(s.t_s);
            }
            if s.t_s <= ins.config().signal_window_s {
                self.signal.push(s);
            }
        }
        let out = step(&self.model, &mut self.state, t);
        self.stats.add(&out);
        self.since_change.add(&out);
        self.last_gimbal_rad = out.gimbal_rad;
        self.step_index += 1;
        if let Some(hz) = self.pending_rate_hz
            && self.ins.as_ref().is_none_or(InsRun::between_updates)
        {
            self.switch_rate(hz);
        }
        out
    }

    /// From the next step on, the table and the INS step at `hz`; each algorithm goes on from its
    /// attitude ([`InsRun::at_rate`], whose conditions `apply` checked).
    fn switch_rate(&mut self, hz: f64) {
        self.rate_since = (self.t_s(), self.step_index);
        self.step_hz = hz;
        self.pending_rate_hz = None;
        let cfg = self.params.ins.clone();
        if let (Some(ins), Some(cfg)) = (self.ins.as_mut(), cfg)
            && let Ok(next) = ins.at_rate(&cfg)
        {
            *ins = next;
        }
    }

    /// The signal window's samples since the last call.
    pub fn take_signal(&mut self) -> Vec<crate::ins::core::SampleOut> {
        std::mem::take(&mut self.signal)
    }

    /// The INS's errors at its latest attitude update (with the true IMU attitude for the scene),
    /// None without an IMU in the loop or before its first update.
    pub fn ins_view(&mut self, with_truth: bool) -> Option<InsView> {
        let (ins, t) = (self.ins.as_mut()?, self.ins_update_s?);
        Some(if with_truth { ins.view(t) } else { ins.errors_view(t) })
    }

    /// Replaces the parameters between two steps. Returns what changed, in words (empty: nothing did);
    /// refuses changes the running session cannot take (the old parameters stay in force).
    pub fn apply(&mut self, new: Params) -> Result<Vec<String>, String> {
        let old = &self.params;
        let axes = |p: &Params| p.table.chain.axes().iter().map(|a| (a.name.clone(), a.axis)).collect::<Vec<_>>();
        if axes(old) != axes(&new) {
            return Err("the turntable's axes (names, number or directions) cannot change in a running session; restart `rinscope live`".into());
        }
        let rate_changed = old.step_hz != new.step_hz;
        if rate_changed && let Some(cfg) = &new.ins {
            let why = if cfg.fir_taps.len() > 1 || cfg.decimation != 1 {
                Some("its IMU has a FIR or a decimation, whose state is in samples of the old rate")
            } else if cfg.navigation.is_some() {
                Some("its INS navigates, and the navigation's state is in samples of the old rate")
            } else {
                None
            };
            if let Some(why) = why {
                return Err(format!(
                    "simulation.step_hz cannot change in this running session ({} Hz -> {} Hz): {why}; restart `rinscope live`",
                    old.step_hz, new.step_hz
                ));
            }
        }
        let changes = describe_changes(&old.written, &new.written);
        if changes.is_empty() {
            return Ok(changes);
        }
        let (a, b) = (scenario::flatten(&old.written), scenario::flatten(&new.written));
        let instrument = |k: &String| k.starts_with("imu.") || k.starts_with("navigation.");
        // (What the INS computes from the step rate — its sample period — follows the rate below.)
        if let Some(key) = a.keys().chain(b.keys()).filter(|k| instrument(k)).find(|k| a.get(*k) != b.get(*k)) {
            return Err(format!(
                "{key} cannot change in a running session (the INS has been integrating with the old one); restart `rinscope live`"
            ));
        }
        let mut model = new.table_model();
        // The body goes on from where it is (a changed cone or wobble ramps, its phase kept).
        model.vehicle = model.vehicle.continuing_from(&self.model.vehicle, self.t_s());
        let initial_changed = old
            .resolved
            .turntable
            .axis
            .iter()
            .zip(&new.resolved.turntable.axis)
            .any(|(a, b)| a.initial_angle_deg != b.initial_angle_deg);
        if old.resolved.scheme == new.resolved.scheme && !initial_changed {
            // Same motion: keep its clock, so nothing jumps.
            model.scheme = self.model.scheme.clone();
            model.scheme_t0_s = self.model.scheme_t0_s;
        } else {
            // A new motion starts from where the gimbals were at the last step, at that step's time.
            model.scheme = new.table.scheme.with_initial(&self.last_gimbal_rad);
            model.scheme_t0_s = self.t_s() - 1.0 / self.step_hz;
        }
        if let Some(ins) = self.ins.as_mut() {
            ins.replace_model(model.clone());
        }
        self.model = model;
        if rate_changed {
            // Once the INS has finished the updates in progress (at most a few samples).
            self.pending_rate_hz = Some(new.step_hz);
        }
        // The IMU compensation (`live --compensation`) is the session's, not the file's: it stays.
        let mut new = new;
        if let (Some(n), Some(o)) = (new.ins.as_mut(), self.params.ins.as_ref()) {
            n.imu_compensation = o.imu_compensation;
        }
        self.params = new;
        self.since_change = ErrorStats::default();
        Ok(changes)
    }
}

/// Human-readable differences between two resolved configs, e.g. `inner swing half-angle 300″ → 600″`.
#[must_use]
pub fn describe_changes(old: &RawConfig, new: &RawConfig) -> Vec<String> {
    let (a, b) = (scenario::flatten(old), scenario::flatten(new));
    let mut keys: Vec<&String> = a.keys().chain(b.keys()).collect();
    keys.sort();
    keys.dedup();
    let mut out = Vec::new();
    for key in keys {
        let (x, y) = (a.get(key), b.get(key));
        if x == y {
            continue;
        }
        if key.ends_with(".description") {
            out.push("scenario description edited".to_owned());
            continue;
        }
        let unit = unit_of(key);
        let show =
            |v: Option<&String>| v.map_or_else(|| "(unset)".to_owned(), |v| format!("{}{unit}", pretty_value(v)));
        out.push(format!("{} {} → {}", label_of(key, new), show(x), show(y)));
    }
    out
}

fn pretty_value(v: &str) -> String {
    match v.parse::<f64>() {
        Ok(x) if x.fract() == 0.0 && x.abs() < 1e15 => format!("{x:.0}"),
        Ok(x) => format!("{}", (x * 1e6).round() / 1e6),
        Err(_) => v.trim_matches('"').to_owned(),
    }
}

fn unit_of(key: &str) -> &'static str {
    let leaf = key.rsplit('.').next().unwrap_or(key);
    for (suffix, unit) in [
        ("_arcsec", "″"),
        ("_deg_per_s2", "°/s²"),
        ("_deg_per_s", "°/s"),
        ("_deg", "°"),
        ("_ppm", " ppm"),
        ("_ms", " ms"),
        ("_hz", " Hz"),
        ("_s", " s"),
        ("_m", " m"),
    ] {
        if leaf.ends_with(suffix) {
            return unit;
        }
    }
    if leaf == "speed" || leaf == "exaggeration" { "×" } else { "" }
}

/// `turntable.axis[1].swing_half_angle_arcsec` → `inner swing half-angle`.
fn label_of(key: &str, raw: &RawConfig) -> String {
    let parts: Vec<&str> = key.split('.').collect();
    let leaf = parts.last().copied().unwrap_or(key);
    let mut name = leaf.to_owned();
    for suffix in ["_arcsec", "_deg_per_s2", "_deg_per_s", "_deg", "_ppm", "_ms", "_hz", "_s", "_m"] {
        if let Some(stripped) = name.strip_suffix(suffix) {
            name = stripped.to_owned();
            break;
        }
    }
    let name = name
        .replace('_', " ")
        .replace("swing half angle", "swing half-angle")
        .replace("non orthogonality", "non-orthogonality");
    let index = |p: &str| p.split_once('[').and_then(|(_, r)| r.trim_end_matches(']').parse::<usize>().ok());
    match parts.as_slice() {
        ["turntable", ax, _] if ax.starts_with("axis[") => {
            let axis = index(ax).and_then(|i| raw.turntable.axis.get(i)).map_or("axis", |a| a.name.as_str());
            format!("{axis} {name}")
        }
        ["turntable", _] => name,
        ["compensation", "axis", axis, _] => format!("compensation: {axis} {name}"),
        ["compensation", _] => format!("compensation: {name}"),
        ["scheme", r, _] if r.starts_with("rate[") => {
            let axis = index(r).and_then(|i| raw.scheme.rate.get(i)).map_or("axis", |x| x.axis.as_str());
            format!("{axis} rotation {name}")
        }
        ["scheme", s, _] if s.starts_with("step[") => format!("scheme step {} {name}", index(s).map_or(0, |i| i + 1)),
        // The panel's words for the coning lesson's controls.
        ["vehicle", "coning_half_angle_deg"] => "cone half-angle".to_owned(),
        ["vehicle", "coning_frequency_hz"] => "cone frequency".to_owned(),
        ["vehicle", w, _] if w.starts_with("wobble[") => {
            let wobble = index(w).and_then(|i| raw.vehicle.wobble.get(i)).map_or("", |w| w.angle.as_str());
            format!("{wobble} wobble {name}")
        }
        ["simulation", "step_hz"] => "IMU sample rate (step rate)".to_owned(),
        ["recording", "show", algorithm] => format!("show {algorithm}"),
        _ => key.to_owned(),
    }
}
