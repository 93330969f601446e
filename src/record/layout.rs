//! The layout a run's recording opens with: the 3D scene and its documents on the left, the error
//! plots on the right (the INS's when it is in the loop, the table-only ones in tabs; a replay
//! without a reference leads with the INS's own solution). Only entities the recording has are
//! laid out.

use rerun::RecordingStreamResult;
use rerun::blueprint::components::ContainerKind;

use super::blueprint::{self, Node};
use super::plots::Quantity;
use super::plots::coning::CONING_LOG_PATH;
use super::plots::series as rows;
use super::{APPLICATION_ID, CustomLayout, Recorder, TIMELINE};
use crate::scenario::Params;
use crate::sim::ERROR_AXES;

impl Recorder {
    pub(crate) fn send_blueprint(&self, p: &Params, custom: Option<CustomLayout>) -> RecordingStreamResult<()> {
        let plot = |name: String, origin: &str| {
            Node::view("TimeSeries", name, origin).with_property("TimeAxis", &blueprint::whole_run_time_axis())
        };
        let unit = self.error_unit();
        // Symmetric ranges once the run's peaks are known, with labelled ticks.
        let framed = |node: Node, peak: Option<f64>| match peak {
            Some(p) if p > 0.0 => {
                let h = crate::math::units::nice_half_range(p);
                node.with_property("ScalarAxis", &blueprint::symmetric_range(h))
            }
            _ => node,
        };
        let table_peak = |a: usize| self.ranges.map(|r| super::floored_peak(r.table_peak_rad, a) * unit.per_rad());
        // The legend would sit over the data: the title says which line is which.
        let key = match self.replay {
            None => "red: uncompensated, blue: closed form, green: compensated",
            Some(k) if k.reference => "red: nominal table, green: compensated",
            Some(_) => "nominal − compensated table",
        };
        let error_view = |a: usize, axis: &str| {
            framed(
                plot(format!("{axis} error ({}) — {key}", unit.suffix()), &super::error_path(unit, axis)),
                table_peak(a),
            )
            .with_property("PlotLegend", &blueprint::no_legend())
        };
        let x = p.recording.exaggeration;
        let own = self.table.as_ref().map(|t| super::own_factors(&t.factors, x)).unwrap_or_default();
        let scale = if own.is_empty() { format!("errors ×{x}") } else { format!("errors ×{x}, {}", own.join(", ")) };
        let scene = match (&self.body, &self.ins) {
            (Some(_), _) => Node::view(
                "3D",
                format!(
                    "3D: the IMU (body) axes at the INS attitude{}",
                    if self.replay.is_some_and(|k| k.reference) { "; grey: the reference" } else { "" }
                ),
                "world",
            )
            .with_property("EyeControls3D", &blueprint::eye([2.4, -2.6, 1.5], [0.0, 0.1, -0.1])),
            // With an INS, the trace stands beside the table: step back to frame both.
            (None, Some(_)) => Node::view("3D", format!("3D: gimbal chain ({scale})"), "world")
                .with_property("EyeControls3D", &blueprint::eye([3.6, -1.7, 1.5], [0.7, 0.7, -0.3])),
            (None, None) => Node::view("3D", format!("3D: gimbal chain ({scale})"), "world")
                .with_property("EyeControls3D", &blueprint::eye([2.6, -1.1, 0.95], [0.0, 0.1, -0.2])),
        };
        let (custom_right, mut doc_tabs) = match custom {
            Some(c) => (Some(c.right), c.docs),
            None => (None, Vec::new()),
        };
        doc_tabs.extend([
            Node::view("TextDocument", "scenario", "docs/scenario"),
            Node::view("TextDocument", "config", "docs/config"),
            Node::view("TextLog", "events", "events"),
        ]);
        let docs = Node::container(ContainerKind::Tabs, doc_tabs, &[]);
        let left = Node::container(ContainerKind::Vertical, vec![scene, docs], &[3.0, 1.3]);
        let mut more = Vec::new();
        if self.plots.has(super::CLOSED_FORM_PATH) {
            let peak = self.ranges.map(|r| {
                r.closed_form_peak_rad.iter().fold(0.0_f64, |m, x| m.max(*x)) * crate::math::units::ARCSEC_PER_RAD
            });
            more.push(
                framed(
                    plot(
                        "closed form − exact (arcsec) — red pitch, green roll, blue heading".into(),
                        super::CLOSED_FORM_PATH,
                    ),
                    peak,
                )
                .with_property("PlotLegend", &blueprint::no_legend()),
            );
        }
        for (title, path) in
            [("gimbal angles (deg)", "gimbal_angle_deg"), ("vehicle attitude (deg)", "vehicle_attitude_deg")]
        {
            if self.plots.has(path) {
                more.push(plot(title.into(), path));
            }
        }
        if self.plots.any(|q| matches!(q, Quantity::Swing(_))) {
            more.push(plot("swing angles (arcsec)".into(), "swing_arcsec"));
        }
        let has_table_errors = self.plots.has(&super::error_path(unit, "pitch"));
        let right = match (self.plots.ins.as_ref().zip(self.ins.as_ref()), custom_right) {
            (_, Some(right)) => right,
            (None, None) => {
                let more = Node::container(ContainerKind::Tabs, more, &[]);
                Node::container(
                    ContainerKind::Vertical,
                    vec![error_view(0, "pitch"), error_view(1, "roll"), error_view(2, "heading"), more],
                    &[],
                )
            }
            (Some((layout, signal)), None) => {
                // The INS leads (its errors, else its own solution); the turntable-only (ideal-INS)
                // plots go into the tabs.
                let ins_peak = |a: usize| {
                    self.ranges
                        .and_then(|r| r.ins_peak_rad)
                        .map(|p| super::floored_peak(p, a) * crate::math::units::ARCSEC_PER_RAD)
                };
                // The legend would sit over the data: the first plot's title gives each
                // algorithm's colour (short, so that it is not cut), the others refer to it.
                let algorithm_key = layout
                    .algorithms
                    .iter()
                    .map(|a| format!("{} {}", super::palette::colors::algorithm_colour_name(a), short_name(a)))
                    .collect::<Vec<_>>()
                    .join(" · ");
                let ins_view = |a: usize, axis: &str| {
                    let title = match (a, layout.algorithms.len()) {
                        (_, 1) => format!("INS {axis} error (arcsec)"),
                        (0, _) => format!("INS {axis} error (arcsec) — {algorithm_key}"),
                        _ => format!("INS {axis} error (arcsec), colours as above"),
                    };
                    framed(plot(title, &format!("ins/attitude_error_arcsec/{axis}")), ins_peak(a))
                        .with_property("PlotLegend", &blueprint::no_legend())
                };
                // A replay's own solution, keyed in the titles (a legend would cover the curves).
                let primary = layout.algorithms.first().map_or("", String::as_str);
                let solution: Vec<Node> = [
                    (
                        rows::BODY_ATTITUDE_PATH,
                        format!("INS body attitude (deg), {primary} — red pitch, green roll, blue heading"),
                    ),
                    (
                        rows::VELOCITY_PATH,
                        format!(
                            "INS velocity (m/s) — red east, green north{}",
                            if self.plots.names(rows::VELOCITY_PATH).len() > 2 { ", blue up" } else { "" }
                        ),
                    ),
                    (rows::POSITION_PATH, "INS position from the start (m) — red east, green north".to_owned()),
                    (rows::LAT_LON_PATH, "INS latitude, longitude (deg) — red latitude, green longitude".to_owned()),
                    (rows::HEIGHT_PATH, "INS height (m)".to_owned()),
                ]
                .into_iter()
                .filter(|(path, _)| self.plots.has(path))
                .map(|(path, title)| plot(title, path).with_property("PlotLegend", &blueprint::no_legend()))
                .collect();
                let (lead, mut tabs): (Vec<Node>, Vec<Node>) = if layout.errors {
                    (vec![ins_view(0, "pitch"), ins_view(1, "roll"), ins_view(2, "heading")], solution)
                } else if has_table_errors {
                    (vec![error_view(0, "pitch"), error_view(1, "roll"), error_view(2, "heading")], solution)
                } else {
                    // A strapdown IMU without a reference: its attitude, velocity and position lead.
                    let mut s = solution;
                    let rest = s.split_off(s.len().min(3));
                    (s, rest)
                };
                if let Some(rates) = layout.coning.as_ref().map(|l| &l.rates) {
                    // Whole decades, from a tenth of the run (the lines' left part is their steep
                    // start) to the end, of the slowest to the fastest analytic drift.
                    let logs = rates.iter().filter(|r| **r > 0.0).map(|r| (r * p.duration_s).log10());
                    let (lo, hi) = logs.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
                    let view = plot(
                        "coning drift: log10 |heading error in ″|, thick measured, thin analytic rate × t".to_owned(),
                        CONING_LOG_PATH,
                    )
                    .with_property("PlotLegend", &blueprint::no_legend());
                    // Once measured lines exist, their whole extent (their steep start too: no
                    // fixed range hides a series); before, the analytic lines'.
                    // (A viewer watching live fits it itself: the session has no length to frame on.)
                    let range = if self.live.is_some_and(super::LiveOutput::watched) {
                        None
                    } else {
                        self.plots
                            .data_range(CONING_LOG_PATH)
                            .or_else(|| lo.is_finite().then(|| ((lo - 1.0).floor(), hi.ceil())))
                    };
                    tabs.push(match range {
                        Some((a, b)) => view.with_property("ScalarAxis", &blueprint::scalar_range(a, b)),
                        None => view,
                    });
                }
                if self.plots.has("ins/position_error_m") {
                    // Keyed in the titles: a legend would cover the curves.
                    tabs.push(
                        plot("position error (m) — red east, green north, blue radial".into(), "ins/position_error_m")
                            .with_property("PlotLegend", &blueprint::no_legend()),
                    );
                    tabs.push(
                        plot("velocity error (m/s) — red east, green north, blue up".into(), "ins/velocity_error_mps")
                            .with_property("PlotLegend", &blueprint::no_legend()),
                    );
                }
                let window = |name: &str, origin: &str| {
                    Node::view("TimeSeries", name, origin)
                        .with_property("TimeAxis", &blueprint::window_time_axis(signal.signal_window_s))
                };
                // Keyed in the title: a legend would sit over the signal.
                // Framed on the window's peak once the run is over (labelled ticks, like the errors).
                let peaks = signal.signal_peak_deg_per_s;
                let gyro = |name: String, origin: &str, k: usize| {
                    framed(window(&name, origin), self.ranges.map(|_| peaks[k]))
                        .with_property("PlotLegend", &blueprint::no_legend())
                };
                let first = format!("the first {} s", signal.signal_window_s);
                tabs.push(gyro(
                    format!("gyro raw (deg/s), {first} — red x, green y, blue z"),
                    super::ins_view::GYRO_RAW_PATH,
                    0,
                ));
                if signal.fir_taps.len() > 1 {
                    tabs.push(gyro(
                        format!("gyro after FIR (deg/s), {first} — red x, green y, blue z"),
                        super::ins_view::GYRO_FILTERED_PATH,
                        1,
                    ));
                    tabs.push(Node::view("2D", "FIR response (x: Hz, y: −5·dB)", "ins/fir_response"));
                }
                if has_table_errors && layout.errors {
                    for (a, axis) in ERROR_AXES.iter().enumerate() {
                        tabs.push(framed(
                            plot(format!("table only: {axis} ({})", unit.suffix()), &super::error_path(unit, axis)),
                            table_peak(a),
                        ));
                    }
                }
                tabs.append(&mut more);
                let mut column = lead;
                column.push(Node::container(ContainerKind::Tabs, tabs, &[]));
                Node::container(ContainerKind::Vertical, column, &[])
            }
        };
        let mut root = Node::container(ContainerKind::Horizontal, vec![left, right], &[1.1, 1.0]);
        if self.live == Some(super::LiveOutput::File) {
            // A saved session's plots framed on its data, as a run's are (a viewer watching live
            // fits each plot's value axis to the data as they arrive: no range is sent to it).
            root.fit_plots_without_range(&|origin| self.plots.data_range(origin));
        }
        // Play a whole run in about a minute; a live session follows the newest data.
        let speed = if self.live.is_some() { 1.0 } else { (p.duration_s / 60.0).max(1.0).round() };
        blueprint::send(
            self.stream.rec(),
            APPLICATION_ID,
            &root,
            &blueprint::Playback { timeline: TIMELINE, speed, follow: self.live.is_some() || p.recording.open_at_end },
        )
    }
}

/// A coning algorithm's name as a colour key spells it (short enough that a plot title holds five):
/// "single-sample" → "single", "two-sample" → "two", "two-sample-p1" → "p1", "three-sample" → "three".
fn short_name(name: &str) -> String {
    name.strip_prefix("two-sample-").map_or_else(|| name.replace("-sample", ""), str::to_owned)
}
