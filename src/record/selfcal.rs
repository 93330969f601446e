//! The recording of `rinscope selfcal`: the IMU turning through the sequence (its true attitude,
//! 1 Hz), each parameter's estimate minus the truth inside its ±3σ band (one view per parameter,
//! in tabs), and the observability timeline: each group's σ_k/σ_0 on a log10 axis with the moves
//! marked, so a reader sees which move makes which parameter observable.

use nalgebra::UnitQuaternion;
use rerun::blueprint::components::ContainerKind;
use rerun::RecordingStreamResult;

use super::layout::{self, Node};
use super::palette::{self, rgb};
use super::{to_rerun_quaternion, Stream, APPLICATION_ID, TIMELINE};
use crate::ins::selfcal::{param, HistoryRow, N_PARAMS};

/// What the recording shows.
pub struct SelfcalView<'a> {
    /// Scenario name and the sequence's.
    pub title: String,
    /// The result as the terminal prints it.
    pub table: &'a str,
    /// The filter's history (1 Hz).
    pub history: &'a [HistoryRow],
    /// The prior 1σ, SI.
    pub prior: &'a [f64; N_PARAMS],
    /// The true parameters, SI (None: a log with no truth).
    pub truth: Option<[f64; N_PARAMS]>,
    /// The starts of the moves, s.
    pub move_starts_s: &'a [f64],
    /// The IMU's attitude C_s^n, 1 Hz.
    pub attitude: &'a [(f64, UnitQuaternion<f64>)],
    /// What it buys: free-inertial runs (at rest and modulated × none, estimated, true).
    pub navigation: Vec<&'a crate::ins::trace::NavTrace>,
}

const GROUPS: [(&str, &str); 4] = [("gyro bias", "gyro_bias"), ("gyro scale and misalignment", "gyro_gain"), ("accelerometer bias", "accel_bias"), ("accelerometer scale and misalignment", "accel_gain")];
/// The lines of a group's plot, with the names its title gives them (a legend would cover the curves).
const LINE_COLORS: [(&str, [u8; 3]); 9] = [
    ("red", [230, 90, 90]),
    ("green", [90, 200, 90]),
    ("blue", [90, 140, 240]),
    ("orange", [240, 160, 40]),
    ("purple", [200, 90, 230]),
    ("cyan", [60, 200, 200]),
    ("yellow", [250, 200, 60]),
    ("grey", [160, 160, 160]),
    ("pink", [240, 120, 180]),
];

/// Logs the self-calibration.
pub fn log(stream: &Stream, v: &SelfcalView<'_>) -> RecordingStreamResult<()> {
    let rec = stream.rec();
    rec.send_recording_name(format!("rinscope selfcal: {}", v.title))?;
    let doc = format!(
        "# Self-calibration: {}\n\n```\n{}```\n\nLeft: the IMU turning through the sequence. Right: each group's 1σ over its prior (log10: −2 is a hundredfold), \
         the moves marked ▼; in the tabs, each estimate minus the truth with its ±3σ band. docs/selfcal.md explains the filter and the sequences.\n",
        v.title, v.table
    );
    rec.log_static("docs/selfcal", &rerun::TextDocument::from_markdown(doc))?;
    // The IMU: a case and its axes, turned by its true attitude.
    rec.log_static("world/imu/case", &rerun::Boxes3D::from_half_sizes([[0.25, 0.25, 0.18]]).with_colors([palette::rgba([150, 150, 160], 90)]))?;
    rec.log_static(
        "world/imu/axes",
        &rerun::Arrows3D::from_vectors([[0.6, 0.0, 0.0], [0.0, 0.6, 0.0], [0.0, 0.0, 0.6]]).with_colors(palette::colors::SENSOR.map(rgb)).with_radii([0.02]),
    )?;
    rec.log_static(
        "world/imu/axes/labels",
        &rerun::Points3D::new([[0.72, 0.0, 0.0], [0.0, 0.72, 0.0], [0.0, 0.0, 0.72]]).with_labels(["x", "y", "z"]).with_colors(palette::colors::SENSOR.map(palette::label)).with_radii([0.002]),
    )?;
    let times: Vec<f64> = v.attitude.iter().map(|a| a.0).collect();
    if !times.is_empty() {
    rec.send_columns(
        "world/imu",
        stream.time_columns(&times),
        rerun::Transform3D::update_fields().with_many_quaternion(v.attitude.iter().map(|a| to_rerun_quaternion(&a.1))).columns_of_unit_batches()?,
    )?;
    }
    let t: Vec<f64> = v.history.iter().map(|r| r.t_s).collect();
    // The sequence's plots show the sequence (the free-inertial runs after it share the timeline).
    let seq_axis = layout::time_axis_range(0.0, t.last().copied().unwrap_or(1.0));
    let mut tabs = Vec::new();
    let mut timeline = Vec::new();
    for (group, slug) in GROUPS {
        let members: Vec<usize> = (0..N_PARAMS).filter(|&k| param(k).0.group() == group).collect();
        let path = format!("selfcal/observability/{slug}/log10_sigma_ratio");
        let names: Vec<String> = members.iter().map(|&k| param(k).1).collect();
        rec.log_static(path.as_str(), &rerun::SeriesLines::new().with_colors((0..members.len()).map(|i| rgb(LINE_COLORS[i % 9].1))).with_names(names.clone()))?;
        let values: Vec<f64> = v.history.iter().flat_map(|r| members.iter().map(|&k| (r.sigma[k] / v.prior[k]).max(1e-12).log10()).collect::<Vec<_>>()).collect();
        stream.send_series(&path, &names, &t, values, members.len())?;
        stream.mark_events(&path, "moves", "moves", v.move_starts_s, 0.0)?;
        let key = names.iter().enumerate().map(|(i, n)| format!("{} {n}", LINE_COLORS[i % 9].0)).collect::<Vec<_>>().join(" · ");
        timeline.push(
            Node::view("TimeSeries", format!("{group}: log10 σ/σ0 — {key} · ▼ moves"), path)
                .with_property("TimeAxis", &seq_axis)
                .with_property("PlotLegend", &layout::no_legend()),
        );
        for &k in &members {
            let (kind, name) = param(k);
            let (unit, per_si) = kind.unit();
            let path = format!("selfcal/error/{name}_{}", kind.unit_key());
            let truth = v.truth.map_or(0.0, |t| t[k]);
            let what = if v.truth.is_some() { "estimate − true" } else { "estimate" };
            let series = [what.to_owned(), "+3σ".to_owned(), "−3σ".to_owned()];
            rec.log_static(path.as_str(), &rerun::SeriesLines::new().with_colors([rgb([250, 200, 60]), rgb([150, 150, 150]), rgb([150, 150, 150])]).with_names(series.clone()))?;
            let values: Vec<f64> = v.history.iter().flat_map(|r| {
                let (e, s) = ((r.estimate[k] - truth) * per_si, 3.0 * r.sigma[k] * per_si);
                [e, s, -s]
            }).collect();
            stream.send_series(&path, &series, &t, values, 3)?;
            // Framed on the last tenth of the prior: the start (the prior's width) would flatten the rest.
            let last = v.history.last().map_or(1.0, |r| 3.0 * r.sigma[k] * per_si);
            let h = crate::math::units::nice_half_range(last.max(1e-12) * 2.0);
            tabs.push(
                Node::view("TimeSeries", format!("{name} {what} ({unit}), ±3σ grey"), path)
                    .with_property("TimeAxis", &seq_axis)
                    .with_property("PlotLegend", &layout::no_legend())
                    .with_property("ScalarAxis", &layout::symmetric_range(h)),
            );
        }
    }
    if !v.navigation.is_empty() {
        // On its own timeline (hours of navigation after the calibration, not the sequence's time).
        let path = "selfcal/navigation/radial_position_error_log10_m";
        let names: Vec<String> = v.navigation.iter().map(|t| t.label.clone()).collect();
        let colors = [[230, 90, 90], [250, 200, 60], [90, 200, 90], [230, 150, 150], [250, 230, 150], [160, 230, 160]];
        rec.log_static(path, &rerun::SeriesLines::new().with_colors(colors.iter().take(names.len()).map(|c| rgb(*c))).with_names(names.clone()))?;
        let n = v.navigation.iter().map(|t| t.samples.len()).min().unwrap_or(0);
        let times: Vec<f64> = v.navigation[0].samples.iter().take(n).map(|s| s.t_s).collect();
        let values: Vec<f64> = (0..n).flat_map(|i| v.navigation.iter().map(move |t| t.samples[i].position_m[2].max(1e-3).log10())).collect();
        rec.send_columns(path, stream.time_columns(&times), rerun::Scalars::new(values).columns(std::iter::repeat_n(names.len(), n))?)?;
        timeline.push(
            Node::view("TimeSeries", "afterwards, free-inertial from t = 0: radial position error, log10 of metres (1 = 10 m, 4 = 10 km)", path)
                .with_property("TimeAxis", &layout::whole_run_time_axis()),
        );
    }
    let left = Node::container(ContainerKind::Vertical, vec![Node::view("3D", "the IMU turning through the sequence (true attitude; the grid is level)", "world").with_property("EyeControls3D", &layout::eye([1.5, -1.7, 1.0], [0.0, 0.0, 0.0])), Node::view("TextDocument", "result", "docs/selfcal")], &[1.0, 1.2]);
    let right = Node::container(
        ContainerKind::Vertical,
        vec![Node::container(ContainerKind::Grid, timeline, &[]), Node::container(ContainerKind::Tabs, tabs, &[])],
        &[1.2, 1.0],
    );
    let root = Node::container(ContainerKind::Horizontal, vec![left, right], &[1.0, 1.5]);
    layout::send(rec, APPLICATION_ID, &root, &layout::Playback { timeline: TIMELINE, speed: 60.0, follow: false })
}
