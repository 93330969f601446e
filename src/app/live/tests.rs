//! The reload path, tested without a terminal or a viewer: a test writes the scenario file, the
//! simulation thread sees the new parameters; a broken file leaves the old ones in force.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use super::*;
use crate::scenario;
use crate::math::units::RAD_PER_ARCSEC;

const PRESET: &str = include_str!("../../../assets/scenarios/jiang2017-dual-axis.toml");

fn params() -> Params {
    scenario::parse(PRESET, "test").expect("preset parses")
}

fn edited(from: &str, to: &str) -> Params {
    assert!(PRESET.contains(from), "{from}");
    scenario::parse(&PRESET.replacen(from, to, 1), "test").expect("edited preset parses")
}

#[test]
fn apply_describes_the_change_in_words_and_swaps_the_model() {
    let mut sim = LiveSim::new(params());
    for _ in 0..100 {
        sim.step();
    }
    let changes = sim.apply(edited("swing_half_angle_arcsec = 300.0", "swing_half_angle_arcsec = 600.0")).expect("applied");
    assert_eq!(changes, vec!["inner swing half-angle 300″ → 600″".to_owned()]);
    assert!((sim.model.truth.axes[1].swing_half_angle_rad - 600.0 * RAD_PER_ARCSEC).abs() < 1e-15);
    // Same scheme: its clock is kept (no re-anchoring).
    assert_eq!(sim.model.scheme_t0_s, 0.0);
    // Applying the same parameters again changes nothing.
    assert!(sim.apply(edited("swing_half_angle_arcsec = 300.0", "swing_half_angle_arcsec = 600.0")).expect("no-op").is_empty());
}

#[test]
fn a_new_rotation_rate_starts_from_where_the_gimbals_are() {
    let mut sim = LiveSim::new(params());
    let mut last = sim.step();
    for _ in 0..999 {
        last = sim.step();
    }
    // 1000 steps at 200 Hz, 10 deg/s: the inner gimbal is near 50 deg.
    let before = last.gimbal_rad;
    sim.apply(edited("rate_deg_per_s = 10.0\n# indexed", "rate_deg_per_s = 30.0\n# indexed")).expect("applied");
    let after = sim.step();
    // Continuity: one step at 30 deg/s (0.15 deg), not a jump to 30 deg/s x 5 s.
    let jump_deg = (after.gimbal_rad[1] - before[1]).to_degrees();
    assert!((jump_deg - 0.15).abs() < 1e-6, "the gimbal moved {jump_deg} deg in one step");
}

#[test]
fn structural_changes_are_refused_and_the_old_parameters_stay() {
    let mut sim = LiveSim::new(params());
    let err = sim.apply(edited("step_hz = 200.0", "step_hz = 400.0")).expect_err("refused");
    assert!(err.contains("step_hz"), "{err}");
    let err = sim.apply(edited("name = \"inner\"\naxis = \"z\"", "name = \"inner\"\naxis = \"x\"")).expect_err("refused");
    assert!(err.contains("axes"), "{err}");
    assert_eq!(sim.params.step_hz, 200.0);
}

struct Session {
    dir: PathBuf,
    path: PathBuf,
    status: SharedStatus,
    stop: std::sync::Arc<AtomicBool>,
    events: Receiver<RecorderMsg>,
    sim: Option<std::thread::JoinHandle<LiveSim>>,
    _watcher: watch::Watcher,
}

impl Session {
    fn start(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("rinscope-live-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let path = dir.join("scenario.toml");
        std::fs::write(&path, PRESET).expect("write");
        let p = params();
        let status = new_status(&p, 50.0);
        let stop = std::sync::Arc::new(AtomicBool::new(false));
        let (reload_tx, reload_rx) = crossbeam_channel::unbounded();
        let watcher = watch::watch(&path, PRESET.to_owned(), reload_tx).expect("watch");
        let (out_tx, out_rx) = crossbeam_channel::unbounded();
        let (st, sp) = (status.clone(), stop.clone());
        let sim = std::thread::spawn(move || sim_loop(LiveSim::new(p), &reload_rx, &out_tx, &st, &sp, None, false));
        Self { dir, path, status, stop, events: out_rx, sim: Some(sim), _watcher: watcher }
    }

    /// Waits until the status message satisfies `pred` (collecting recorder events meanwhile).
    fn wait_for(&self, what: &str, pred: impl Fn(&Status) -> bool) -> Status {
        let deadline = Instant::now() + Duration::from_secs(5);
        loop {
            while self.events.try_recv().is_ok() {}
            let s = lock(&self.status).clone();
            if pred(&s) {
                return s;
            }
            assert!(Instant::now() < deadline, "timed out waiting for {what}; last message: {}", s.message);
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    fn finish(mut self) -> LiveSim {
        self.stop.store(true, Ordering::SeqCst);
        let sim = self.sim.take().expect("running").join().expect("sim thread");
        std::fs::remove_dir_all(&self.dir).ok();
        sim
    }
}

#[test]
fn saves_in_place_by_rename_and_with_errors_reach_the_simulation_thread() {
    let s = Session::start("reload");
    // 1. Truncate-and-write, as many editors do.
    std::fs::write(&s.path, PRESET.replacen("swing_half_angle_arcsec = 300.0", "swing_half_angle_arcsec = 450.0", 1)).expect("write");
    let st = s.wait_for("the first reload", |st| st.generation == 1);
    assert!(st.message.contains("inner swing half-angle 300″ → 450″"), "{}", st.message);
    assert_eq!(st.resolved.turntable.axis[1].swing_half_angle_arcsec, 450.0);

    // 2. A broken value: reported once, old parameters stay in force.
    std::fs::write(&s.path, PRESET.replacen("swing_half_angle_arcsec = 300.0", "swing_half_angle_arcsec = -5", 1)).expect("write");
    let st = s.wait_for("the error report", |st| st.message.contains("config error"));
    assert!(st.message.contains("swing_half_angle_arcsec") && st.message.contains("-5 arcsec"), "{}", st.message);
    assert_eq!(st.generation, 1, "not applied");
    assert_eq!(st.resolved.turntable.axis[1].swing_half_angle_arcsec, 450.0);

    // 3. Save by rename (vim, VS Code): a new inode replaces the file.
    let tmp = s.dir.join("scenario.toml.swp");
    std::fs::write(&tmp, PRESET.replacen("non_orthogonality_arcsec = 20.0", "non_orthogonality_arcsec = 60.0", 1)).expect("write");
    std::fs::rename(&tmp, &s.path).expect("rename");
    let st = s.wait_for("the rename reload", |st| st.generation == 2);
    assert!(st.message.contains("inner non-orthogonality 20″ → 60″"), "{}", st.message);
    // The rename also put the swing back to 300″ (the new file has the preset's value).
    assert_eq!(st.resolved.turntable.axis[1].swing_half_angle_arcsec, 300.0);

    // 4. Deleted, then back.
    std::fs::remove_file(&s.path).expect("remove");
    s.wait_for("the deletion report", |st| st.message.contains("deleted"));
    std::fs::write(&s.path, PRESET.replacen("swing_half_angle_arcsec = 600.0", "swing_half_angle_arcsec = 900.0", 1)).expect("write");
    let st = s.wait_for("the reload after the return", |st| st.generation == 3);
    assert!(st.message.contains("outer swing half-angle 600″ → 900″"), "{}", st.message);

    // The latency of every applied reload was measured.
    assert_eq!(st.latencies_ms.len(), 3);
    let sim = s.finish();
    assert!((sim.model.truth.axes[0].swing_half_angle_rad - 900.0 * RAD_PER_ARCSEC).abs() < 1e-15);
}

#[test]
fn the_slider_path_writes_the_file_and_the_watcher_applies_it() {
    let s = Session::start("slider");
    let p = params();
    let mut panel = panel::Panel::new(&p.resolved, "t".into());
    // Select the inner swing half-angle and press → three times.
    panel.selected = panel
        .controls
        .iter()
        .position(|c| matches!(c, panel::Control::Slider { label, .. } if label == "inner swing half-angle"))
        .expect("slider");
    for _ in 0..3 {
        if let panel::Action::Set(writes) = panel.handle(ratatui::crossterm::event::KeyEvent::from(ratatui::crossterm::event::KeyCode::Right)) {
            for (k, v) in writes {
                edit::set_in_file(&s.path, &k, v.to_value()).expect("write");
            }
        }
    }
    let st = s.wait_for("the slider's value", |st| st.resolved.turntable.axis[1].swing_half_angle_arcsec == 330.0);
    // The file kept its comments.
    let text = std::fs::read_to_string(&s.path).expect("read");
    assert!(text.contains("swing_half_angle_arcsec = 330.0 # α1 — Table 2: 5′"), "comment kept");
    assert!(st.generation >= 1);
    s.finish();
}

#[test]
fn calibrate_now_freezes_the_compensation_and_a_later_change_shows_in_the_compensated_curve() {
    use super::panel::{Action, Panel};
    use crate::math::units::ARCSEC_PER_RAD;
    // The worst compensated RMS over the three axes, arcsec, in the 20 s after `after` replaces `before`.
    let compensated_after = |before: &str, after: &str| -> f64 {
        let mut sim = LiveSim::new(scenario::parse(before, "before").expect("parses"));
        for _ in 0..200 {
            sim.step();
        }
        assert!(!sim.apply(scenario::parse(after, "after").expect("parses")).expect("applied").is_empty());
        for _ in 0..4000 {
            sim.step();
        }
        (0..3).map(|a| sim.since_change.stats[1][a].rms()).fold(0.0, f64::max) * ARCSEC_PER_RAD
    };
    let wider = |t: &str| t.replacen("swing_half_angle_arcsec = 300.0", "swing_half_angle_arcsec = 600.0", 1);
    // Before "calibrate now" the compensation follows the truth: the compensated curve stays at zero.
    let follows = compensated_after(PRESET, &wider(PRESET));
    assert!(follows < 0.01, "compensation following the truth leaves {follows}″");
    // "Calibrate now": the panel's writes, applied to the file's text as the panel applies them.
    let mut panel = Panel::new(&params().resolved, "t".into());
    let Action::Set(writes) = panel.calibrate_now() else { panic!("calibrate now writes") };
    assert!(writes.iter().any(|(k, _)| k.to_string() == "compensation.axis.inner.swing_half_angle_arcsec"), "{writes:?}");
    let mut calibrated = PRESET.to_owned();
    for (k, v) in &writes {
        calibrated = edit::set_in_text(&calibrated, k, v.to_value()).expect("written");
    }
    let frozen = scenario::parse(&calibrated, "calibrated").expect("a valid scenario");
    assert_eq!(frozen.resolved.compensation.axis.get("inner").and_then(|a| a.swing_half_angle_arcsec), Some(300.0));
    // The inner cone then doubles: the frozen compensation no longer matches, and the compensated
    // curve shows it (the inner swing's 300″ of extra cone moves the attitude by tens of arcsec).
    let shown = compensated_after(&calibrated, &wider(&calibrated));
    assert!(shown > 10.0, "after calibrate now, a wider cone leaves only {shown}″ in the compensated curve");
}
