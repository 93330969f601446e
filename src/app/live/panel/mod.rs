//! The terminal control panel of `rinscope live`: one slider per parameter a user would turn.
//! Moving a slider writes the scenario file (the watcher then reloads it), so the panel and a text
//! editor drive the same path. State and key handling are plain data, testable without a terminal.

use ratatui::Frame;
use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::layout::{Constraint, Layout};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph, Wrap};

use super::Status;
use super::edit::{KeyPath, Scalar};
use crate::scenario::{self, RawConfig};

/// One control.
#[derive(Debug, Clone, PartialEq)]
pub enum Control {
    /// A number.
    Slider {
        /// What the user reads.
        label: String,
        /// The config keys it writes (usually one; "all move rates" writes every step's).
        keys: Vec<KeyPath>,
        /// Unit shown after the value.
        unit: &'static str,
        /// Range.
        min: f64,
        /// Range.
        max: f64,
        /// Fine step (linear), or factor per step (logarithmic).
        step: f64,
        /// Logarithmic slider (speed, exaggeration).
        log: bool,
        /// Current value.
        value: f64,
        /// Value when the panel opened (`r` resets to it).
        initial: f64,
    },
    /// On / off.
    Toggle {
        /// What the user reads.
        label: String,
        /// The config key it writes.
        key: KeyPath,
        /// Current value.
        value: bool,
        /// Value when the panel opened.
        initial: bool,
    },
}

impl Control {
    /// What the user reads.
    #[must_use]
    pub fn label(&self) -> &str {
        match self {
            Self::Slider { label, .. } | Self::Toggle { label, .. } => label,
        }
    }
}

/// What a key press asks for.
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    /// Nothing to write.
    None,
    /// Leave the session.
    Quit,
    /// Write these values to the config file.
    Set(Vec<(KeyPath, Scalar)>),
}

/// The panel's state.
#[derive(Debug, Clone)]
pub struct Panel {
    /// Controls in display order.
    pub controls: Vec<Control>,
    /// Index of the selected control.
    pub selected: usize,
    /// Show the long help.
    pub show_help: bool,
    /// First line.
    pub title: String,
    /// The table's axis names, in `[[turntable.axis]]` order (the compensation's keys name them).
    axis_names: Vec<String>,
}

/// The one-line key help.
pub const HELP: &str = "↑↓ select  ←→ adjust  Shift+←→/PgUp/PgDn ×10  Home/End min/max  0 zero  r reset  Space toggle  c calibrate now  ? help (Esc closes)  q quit";

/// The per-axis table errors `[compensation.axis.NAME]` can hold.
const COMPENSATED_AXIS_FIELDS: [&str; 6] = [
    "swing_half_angle_arcsec",
    "swing_phase_deg",
    "non_orthogonality_arcsec",
    "encoder_offset_arcsec",
    "encoder_scale_ppm",
    "encoder_delay_ms",
];

fn slider(label: String, key: &str, unit: &'static str, range: (f64, f64), step: f64) -> Control {
    slider_of(label, vec![KeyPath::parse(key)], unit, range, step)
}

/// A linear slider that writes every one of `keys` (one value for several axes).
fn slider_of(label: String, keys: Vec<KeyPath>, unit: &'static str, (min, max): (f64, f64), step: f64) -> Control {
    Control::Slider { label, keys, unit, min, max, step, log: false, value: 0.0, initial: 0.0 }
}

impl Panel {
    /// The controls for a configuration: those that act on it. The table's errors where there is a
    /// table to speak of (a scheme that turns it, or errors already set); the cone's half-angle and
    /// frequency (a wobble's amplitude and frequency) where the body cones; the IMU's sample rate
    /// where the INS can change it running; each attitude algorithm's visibility where several run.
    #[must_use]
    pub fn new(raw: &RawConfig, title: String) -> Self {
        let mut controls = Vec::new();
        let turns = raw.scheme.kind != "static";
        let t = &raw.turntable;
        let has_errors = [
            t.installation_x_arcsec,
            t.installation_y_arcsec,
            t.installation_z_arcsec,
            t.imu_mount_x_arcsec,
            t.imu_mount_y_arcsec,
            t.imu_mount_z_arcsec,
        ]
        .into_iter()
        .chain(t.axis.iter().flat_map(|a| {
            [
                a.swing_half_angle_arcsec,
                a.non_orthogonality_arcsec,
                a.encoder_offset_arcsec,
                a.encoder_scale_ppm,
                a.encoder_delay_ms,
                a.encoder_noise_arcsec,
            ]
        }))
        .any(|x| x != 0.0);
        if turns || has_errors {
            Self::table_controls(raw, turns, &mut controls);
        }
        Self::motion_controls(raw, &mut controls);
        match raw.scheme.kind.as_str() {
            "continuous" => {
                for (j, r) in raw.scheme.rate.iter().enumerate() {
                    controls.push(slider(
                        format!("{} rotation rate", r.axis),
                        &format!("scheme.rate[{j}].rate_deg_per_s"),
                        "°/s",
                        (-60.0, 60.0),
                        1.0,
                    ));
                }
            }
            "indexed" => controls.push(Control::Slider {
                label: "move rate (all steps)".into(),
                keys: (0..raw.scheme.step.len())
                    .map(|j| KeyPath::parse(&format!("scheme.step[{j}].rate_deg_per_s")))
                    .collect(),
                unit: "°/s",
                min: 1.0,
                max: 60.0,
                step: 1.0,
                log: false,
                value: 0.0,
                initial: 0.0,
            }),
            _ => {}
        }
        let log = |label: &str, key: &str, (min, max): (f64, f64)| Control::Slider {
            label: label.into(),
            keys: vec![KeyPath::parse(key)],
            unit: "×",
            min,
            max,
            step: 0.0, // the 1-2-5 ladder (`ladder`)
            log: true,
            value: 1.0,
            initial: 1.0,
        };
        controls.push(log("speed (× real time)", "live.speed", (0.1, 1000.0)));
        // The table's drawing factor and its compensation act where its errors do (a coning
        // lesson's INS trace and dial take a factor of their own, from the analytic drift).
        if turns || has_errors {
            controls.push(log("3D exaggeration", "recording.exaggeration", (1.0, 10_000.0)));
            controls.push(Control::Toggle {
                label: "compensation".into(),
                key: KeyPath::parse("compensation.enabled"),
                value: true,
                initial: true,
            });
        }
        let axis_names = raw.turntable.axis.iter().map(|a| a.name.clone()).collect();
        let mut panel = Self { controls, selected: 0, show_help: false, title, axis_names };
        panel.sync(raw);
        for c in &mut panel.controls {
            match c {
                Control::Slider { value, initial, .. } => *initial = *value,
                Control::Toggle { value, initial, .. } => *initial = *value,
            }
        }
        panel
    }

    /// Per axis its swing, non-orthogonality and encoder errors (scale and delay only when the
    /// table turns: a still axis reads no scale or delay), then installation and IMU mounting.
    fn table_controls(raw: &RawConfig, turns: bool, controls: &mut Vec<Control>) {
        for (i, a) in raw.turntable.axis.iter().enumerate() {
            let n = &a.name;
            let k = |f: &str| format!("turntable.axis[{i}].{f}");
            controls.push(slider(
                format!("{n} swing half-angle"),
                &k("swing_half_angle_arcsec"),
                "″",
                (0.0, 3600.0),
                10.0,
            ));
            controls.push(slider(format!("{n} swing phase"), &k("swing_phase_deg"), "°", (-180.0, 180.0), 5.0));
            if i > 0 {
                controls.push(slider(
                    format!("{n} non-orthogonality"),
                    &k("non_orthogonality_arcsec"),
                    "″",
                    (-600.0, 600.0),
                    5.0,
                ));
            }
            controls.push(slider(
                format!("{n} encoder offset"),
                &k("encoder_offset_arcsec"),
                "″",
                (-600.0, 600.0),
                5.0,
            ));
            if turns {
                controls.push(slider(
                    format!("{n} encoder scale"),
                    &k("encoder_scale_ppm"),
                    " ppm",
                    (-1000.0, 1000.0),
                    10.0,
                ));
                controls.push(slider(format!("{n} encoder delay"), &k("encoder_delay_ms"), " ms", (0.0, 50.0), 0.5));
            }
            controls.push(slider(format!("{n} encoder noise"), &k("encoder_noise_arcsec"), "″ 1σ", (0.0, 60.0), 1.0));
        }
        for about in ["x", "y", "z"] {
            controls.push(slider(
                format!("installation about {about}"),
                &format!("turntable.installation_{about}_arcsec"),
                "″",
                (-1800.0, 1800.0),
                10.0,
            ));
        }
        for about in ["x", "y", "z"] {
            controls.push(slider(
                format!("IMU mounting about {about}"),
                &format!("turntable.imu_mount_{about}_arcsec"),
                "″",
                (-1800.0, 1800.0),
                10.0,
            ));
        }
    }

    /// The coning lesson's controls: the cone (or the wobble, all its axes at once), the IMU's
    /// sample rate where the INS can change it running (no FIR, no decimation, no navigation),
    /// and which algorithms are shown where several run.
    fn motion_controls(raw: &RawConfig, controls: &mut Vec<Control>) {
        let v = &raw.vehicle;
        let cones = v.coning_half_angle_deg != 0.0 && v.coning_frequency_hz != 0.0;
        if cones {
            controls.push(slider("cone half-angle".into(), "vehicle.coning_half_angle_deg", "°", (0.0, 10.0), 0.1));
            controls.push(slider("cone frequency".into(), "vehicle.coning_frequency_hz", " Hz", (0.1, 50.0), 0.1));
        }
        if !v.wobble.is_empty() {
            let all = |field: &str| {
                (0..v.wobble.len()).map(|j| KeyPath::parse(&format!("vehicle.wobble[{j}].{field}"))).collect::<Vec<_>>()
            };
            let many = |label: &str, keys, unit, range, step| slider_of(label.into(), keys, unit, range, step);
            controls.push(many("wobble amplitude (every axis)", all("amplitude_deg"), "°", (0.0, 20.0), 0.5));
            controls.push(many("wobble frequency (every axis)", all("frequency_hz"), " Hz", (0.1, 20.0), 0.1));
        }
        let Some(imu) = &raw.imu else { return };
        // The validated INS says what the file's keys and its preset make of it.
        let ins = scenario::from_raw(raw.clone(), "the panel").ok().and_then(|p| p.ins);
        let plain = ins.is_some_and(|cfg| cfg.fir_taps.len() <= 1 && cfg.decimation == 1 && cfg.navigation.is_none());
        if (cones || !v.wobble.is_empty()) && plain {
            controls.push(Control::Slider {
                label: "IMU sample rate".into(),
                keys: vec![KeyPath::parse("simulation.step_hz")],
                unit: " Hz",
                min: 10.0,
                max: 2000.0,
                step: 0.0, // the 1-2-5 ladder (`ladder`)
                log: true,
                value: 100.0,
                initial: 100.0,
            });
        }
        if imu.compare == Some(true) {
            for a in crate::ins::coning::Algorithm::ALL {
                let key = KeyPath::parse(&format!("recording.show.{}", a.name()));
                controls.push(Control::Toggle { label: format!("show {}", a.name()), key, value: true, initial: true });
            }
        }
    }

    /// Takes the values of a configuration (after a reload: the file may have been edited elsewhere).
    pub fn sync(&mut self, raw: &RawConfig) {
        let flat = scenario::flatten(raw);
        for c in &mut self.controls {
            match c {
                Control::Slider { keys, value, min, max, .. } => {
                    if let Some(v) =
                        keys.first().and_then(|k| flat.get(&k.to_string())).and_then(|s| s.parse::<f64>().ok())
                    {
                        *value = v;
                        *min = min.min(v);
                        *max = max.max(v);
                    }
                }
                Control::Toggle { key, value, .. } => {
                    if let Some(v) = flat.get(&key.to_string()).and_then(|s| s.parse::<bool>().ok()) {
                        *value = v;
                    }
                }
            }
        }
    }

    /// Shows the speed actually in force (a `--speed` given on the command line wins over the file
    /// until the file's value changes).
    pub fn show_speed(&mut self, speed: f64) {
        for c in &mut self.controls {
            if let Control::Slider { keys, value, .. } = c
                && keys.first().is_some_and(|k| k.to_string() == "live.speed")
            {
                *value = speed;
            }
        }
    }

    /// Handles one key press.
    pub fn handle(&mut self, key: KeyEvent) -> Action {
        let n = self.controls.len();
        let coarse = key.modifiers.contains(KeyModifiers::SHIFT);
        match key.code {
            KeyCode::Char('c') if key.modifiers.contains(KeyModifiers::CONTROL) => Action::Quit,
            KeyCode::Char('q') => Action::Quit,
            // Esc closes the help; it never ends a session by accident.
            KeyCode::Esc => {
                self.show_help = false;
                Action::None
            }
            KeyCode::Up | KeyCode::Char('k') => {
                self.selected = (self.selected + n - 1) % n;
                Action::None
            }
            KeyCode::Down | KeyCode::Char('j') | KeyCode::Tab => {
                self.selected = (self.selected + 1) % n;
                Action::None
            }
            KeyCode::Char('?') => {
                self.show_help = !self.show_help;
                Action::None
            }
            KeyCode::Left | KeyCode::Char('h') => self.nudge(-1.0, coarse),
            KeyCode::Right | KeyCode::Char('l') => self.nudge(1.0, coarse),
            KeyCode::Char('H') => self.nudge(-1.0, true),
            KeyCode::Char('L') => self.nudge(1.0, true),
            KeyCode::PageDown => self.nudge(-1.0, true),
            KeyCode::PageUp => self.nudge(1.0, true),
            KeyCode::Home => self.set_selected(|_, min, _| min),
            KeyCode::End => self.set_selected(|_, _, max| max),
            KeyCode::Char('0') => self.set_selected(|v, min, max| if (min..=max).contains(&0.0) { 0.0 } else { v }),
            KeyCode::Char('r') => self.reset_selected(),
            KeyCode::Char(' ') | KeyCode::Enter => self.toggle_selected(),
            KeyCode::Char('c') => self.calibrate_now(),
            _ => Action::None,
        }
    }

    /// Sets control `index` to `value` (a number for a slider, 0 or 1 for a toggle), as a slider
    /// move would: within the control's range, on its step grid. What the class page sends.
    ///
    /// # Errors
    /// No such control, a value that is not a finite number, or outside the range (named with the
    /// control, its unit and its range).
    pub fn set_control(&mut self, index: usize, value: f64) -> Result<Action, String> {
        let Some(control) = self.controls.get(index) else {
            return Err(format!("no control {index} (there are {})", self.controls.len()));
        };
        if !value.is_finite() {
            return Err(format!("{}: {value} is not a finite number", control.label()));
        }
        match control {
            Control::Slider { label, unit, min, max, .. } if !(*min..=*max).contains(&value) => {
                Err(format!("{label}: {value}{unit} is outside {}{unit} ..= {}{unit}", trim(*min), trim(*max)))
            }
            Control::Slider { .. } => {
                self.selected = index;
                Ok(self.set_selected(|_, _, _| value))
            }
            Control::Toggle { label, value: on, .. } => match value {
                v if v == 0.0 || v == 1.0 => {
                    self.selected = index;
                    Ok(if (v == 1.0) == *on { Action::None } else { self.toggle_selected() })
                }
                _ => Err(format!("{label}: {value} is neither 0 (off) nor 1 (on)")),
            },
        }
    }

    /// "Calibrate now": the compensation frozen at the table's current errors — every table error
    /// the sliders show written into `[compensation]` (per axis into `[compensation.axis.NAME]`),
    /// and the compensation switched on. Until then the compensation follows the truth (a key left
    /// out of `[compensation]` takes the true value), so the compensated curve is zero; after it,
    /// a slider moved shows what a table that changed since its calibration does.
    #[must_use]
    pub fn calibrate_now(&mut self) -> Action {
        let mut writes = Vec::new();
        for c in &self.controls {
            let Control::Slider { keys, value, .. } = c else { continue };
            for key in keys {
                let k = key.to_string();
                let target = if let Some(rest) = k.strip_prefix("turntable.axis[") {
                    let (index, field) = rest.split_once("].").unwrap_or_default();
                    match (
                        index.parse::<usize>().ok().and_then(|i| self.axis_names.get(i)),
                        COMPENSATED_AXIS_FIELDS.contains(&field),
                    ) {
                        (Some(name), true) => Some(format!("compensation.axis.{name}.{field}")),
                        _ => None,
                    }
                } else {
                    k.strip_prefix("turntable.").map(|field| format!("compensation.{field}"))
                };
                if let Some(t) = target {
                    writes.push((KeyPath::parse(&t), Scalar::Float(*value)));
                }
            }
        }
        for c in &mut self.controls {
            if let Control::Toggle { key, value, .. } = c
                && key.to_string() == "compensation.enabled"
            {
                *value = true;
                writes.push((key.clone(), Scalar::Bool(true)));
            }
        }
        Action::Set(writes)
    }

    fn nudge(&mut self, direction: f64, coarse: bool) -> Action {
        let Some(Control::Slider { step, log, .. }) = self.controls.get(self.selected) else {
            return self.toggle_selected();
        };
        let (step, log) = (*step, *log);
        let times = if coarse { 10.0 } else { 1.0 };
        // Logarithmic sliders walk 1, 2, 5, 10, 20, ... (coarse: a decade), so the file gets round values.
        self.set_selected(|v, _, _| {
            if log {
                if coarse { ladder(v * 10f64.powf(direction * 0.999), 0.0) } else { ladder(v, direction) }
            } else {
                v + direction * step * times
            }
        })
    }

    fn set_selected(&mut self, f: impl Fn(f64, f64, f64) -> f64) -> Action {
        let Some(Control::Slider { keys, value, min, max, step, log, .. }) = self.controls.get_mut(self.selected)
        else {
            return Action::None;
        };
        // Land on the control's grid (the step, or 1-2-5 for a logarithmic slider), whoever set it
        // (a key, the class page): repeated presses do not accumulate rounding noise, and the file
        // only ever gets values a slider can show.
        let v = f(*value, *min, *max).clamp(*min, *max);
        let v = if *log { ladder(v, 0.0) } else { (v / *step).round() * *step }.clamp(*min, *max);
        if (v - *value).abs() < 1e-12 {
            return Action::None;
        }
        *value = v;
        Action::Set(keys.iter().map(|k| (k.clone(), Scalar::Float(v))).collect())
    }

    fn reset_selected(&mut self) -> Action {
        match self.controls.get(self.selected) {
            Some(Control::Slider { initial, .. }) => {
                let i = *initial;
                self.set_selected(|_, _, _| i)
            }
            Some(Control::Toggle { initial, value, .. }) if initial != value => self.toggle_selected(),
            _ => Action::None,
        }
    }

    fn toggle_selected(&mut self) -> Action {
        let Some(Control::Toggle { key, value, .. }) = self.controls.get_mut(self.selected) else {
            return Action::None;
        };
        *value = !*value;
        Action::Set(vec![(key.clone(), Scalar::Bool(*value))])
    }

    /// Draws the panel.
    pub fn render(&self, frame: &mut Frame<'_>, status: &Status, config_path: &str) {
        let [top, list, bottom] = Layout::vertical([
            Constraint::Length(2),
            Constraint::Min(3),
            Constraint::Length(if self.show_help { 15 } else { 9 }),
        ])
        .areas(frame.area());
        let head = vec![
            Line::from(Span::styled(self.title.clone(), Style::default().add_modifier(Modifier::BOLD))),
            Line::from(format!(
                "sim t = {:.1} s   speed ×{}   config {config_path}",
                status.sim_t_s,
                trim(status.speed)
            )),
        ];
        frame.render_widget(Paragraph::new(head), top);

        let width = usize::from(list.width.saturating_sub(2));
        let bar_width = width.saturating_sub(28 + 14 + 4).clamp(6, 40);
        let lines: Vec<Line<'_>> = self
            .controls
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let selected = i == self.selected;
                let style = if selected {
                    Style::default().fg(Color::Yellow).add_modifier(Modifier::BOLD)
                } else {
                    Style::default()
                };
                let marker = if selected { "▶ " } else { "  " };
                let (label, bar, value) = match c {
                    Control::Slider { label, unit, min, max, value, log, .. } => {
                        let frac = if *log {
                            (value.ln() - min.ln()) / (max.ln() - min.ln())
                        } else {
                            (value - min) / (max - min)
                        };
                        let filled = ((frac.clamp(0.0, 1.0)) * bar_width as f64).round() as usize;
                        (
                            label.as_str(),
                            format!("[{}{}]", "█".repeat(filled), "·".repeat(bar_width - filled)),
                            format!("{}{unit}", trim(*value)),
                        )
                    }
                    Control::Toggle { label, value, .. } => {
                        (label.as_str(), format!("[{}]", if *value { " on " } else { " off" }), String::new())
                    }
                };
                Line::from(vec![
                    Span::styled(format!("{marker}{label:<28}"), style),
                    Span::raw(bar),
                    Span::styled(format!(" {value:>12}"), style),
                ])
            })
            .collect();
        frame.render_widget(
            Paragraph::new(lines)
                .block(Block::default().borders(Borders::ALL).title(" parameters (write the config file) ")),
            list,
        );

        let p95 = super::p95(&status.latencies_ms);
        let mut foot = Vec::new();
        if let Some(Control::Slider { min, max, step, log, unit, .. }) = self.controls.get(self.selected) {
            let steps = if *log { "steps 1-2-5".to_owned() } else { format!("step {}{unit}", trim(*step)) };
            foot.push(Line::from(Span::styled(
                format!("selected: range {} … {}{unit}, {steps}", trim(*min), trim(*max)),
                Style::default().fg(Color::Yellow),
            )));
        }
        foot.push(error_line(status));
        foot.extend([
            Line::from(format!("last: {}", if status.message.is_empty() { "—" } else { &status.message })),
            Line::from(format!("reloads: {}   save → applied p95 {:.0} ms", status.latencies_ms.len(), p95)),
            Line::from(Span::styled(HELP, Style::default().fg(Color::DarkGray))),
        ]);
        if self.show_help {
            foot.push(Line::from("Every slider writes its key into the config file (comments and layout kept);"));
            foot.push(Line::from("the file watcher reloads it exactly as when you save from an editor. Editing the"));
            foot.push(Line::from("file by hand moves the sliders. Bad values are reported and the old ones kept."));
            foot.push(Line::from(
                "c (calibrate now) freezes [compensation] at the table's current errors: move a slider after it",
            ));
            foot.push(Line::from(
                "to see what a table that changed since its calibration does to the compensated curve.",
            ));
            foot.push(Line::from(
                "q or Ctrl-C ends the session (a --save recording is completed); Esc closes this help.",
            ));
        }
        frame.render_widget(Paragraph::new(foot).wrap(Wrap { trim: true }), bottom);
    }
}

/// The attitude error since the parameters last changed: RMS / peak per axis of the uncompensated
/// and the compensated table, arcsec.
fn error_line(status: &Status) -> Line<'static> {
    use crate::math::units::ARCSEC_PER_RAD;
    let variant = |v: usize| {
        crate::sim::ERROR_AXES
            .iter()
            .enumerate()
            .map(|(a, axis)| {
                let s = &status.errors.stats[v][a];
                format!("{axis} {}/{}", trim(s.rms() * ARCSEC_PER_RAD), trim(s.peak() * ARCSEC_PER_RAD))
            })
            .collect::<Vec<_>>()
            .join("  ")
    };
    Line::from(format!(
        "error since the last change, RMS/peak ″ — uncompensated: {}   compensated: {}",
        variant(0),
        variant(1)
    ))
}

/// The next value of the 1-2-5 ladder after `v` in `direction` (+1 up, −1 down; 0: the nearest).
fn ladder(v: f64, direction: f64) -> f64 {
    if !(v > 0.0 && v.is_finite()) {
        return 1.0;
    }
    use crate::math::units::{nice_at_least, nice_at_most};
    // A rung within 1e-9 of `v` is `v` itself: the next one is strictly beyond it.
    if direction > 0.0 {
        nice_at_least(v * (1.0 + 1e-9))
    } else if direction < 0.0 {
        nice_at_most(v * (1.0 - 1e-9))
    } else {
        let (up, down) = (nice_at_least(v), nice_at_most(v));
        if (up / v).ln() < (v / down).ln() { up } else { down }
    }
}

/// 600 → "600", 0.5 → "0.5", 1.953125 → "1.95".
fn trim(x: f64) -> String {
    if x.fract().abs() < 1e-9 {
        format!("{x:.0}")
    } else if x.abs() >= 10.0 {
        format!("{x:.1}")
    } else {
        format!("{x:.2}")
    }
}

#[cfg(test)]
mod tests;
