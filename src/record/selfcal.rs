//! The recording of `rinscope selfcal`: the IMU turning through the sequence (its true attitude,
//! 1 Hz), each parameter's estimate minus the truth inside its ±3σ band (one view per parameter,
//! in tabs), the observability timeline: each group's σ_k/σ_0 on a log10 axis with the moves
//! marked, so a reader sees which move makes which parameter observable, and what it buys: the
//! same IMU free-inertial afterwards, one plot per motion.

use nalgebra::UnitQuaternion;
use rerun::RecordingStreamResult;
use rerun::blueprint::components::ContainerKind;

use super::blueprint::{self, Node};
use super::palette::{self, rgb};
use super::{APPLICATION_ID, Stream, TIMELINE, to_rerun_quaternion};
use crate::calib::selfcal::{HistoryRow, ParamKind};
use crate::calib::selfcal_table::{ShaftSample, TableStates};
use crate::ins::trace::NavSample;
use crate::math::rotvec;
use crate::math::units::ARCSEC_PER_RAD;

/// What the recording shows.
pub struct SelfcalView<'a> {
    /// Scenario name and the sequence's.
    pub title: String,
    /// The result as a document (markdown), narrow enough for the viewer's text panel.
    pub document: &'a str,
    /// The filter's history (1 Hz).
    pub history: &'a [HistoryRow],
    /// Every parameter's name (the IMU's 21, then the table's).
    pub names: Vec<String>,
    /// The prior 1σ, SI.
    pub prior: Vec<f64>,
    /// The true parameters, SI (None: a log with no truth).
    pub truth: Option<Vec<f64>>,
    /// The starts of the moves, s.
    pub move_starts_s: &'a [f64],
    /// The IMU's attitude C_s^n, 1 Hz.
    pub attitude: &'a [(f64, UnitQuaternion<f64>)],
    /// The table's states and its encoders, 1 Hz (None: the IMU alone).
    pub tables: Option<TableGhosts<'a>>,
    /// What it buys: free-inertial runs (at rest and modulated × none, estimated, true).
    pub navigation: Vec<NavLine<'a>>,
}

/// Where each table puts the IMU, drawn beside it: the encoders' readings through the exact chain of
/// the nominal table, of the table as the filter estimates it at each second, and of the true
/// table (the reference: the IMU's own axes; on a log, with no truth, the final estimate).
pub struct TableGhosts<'a> {
    /// The table's states (the last of [`SelfcalView::names`]).
    pub states: &'a TableStates,
    /// The encoders, 1 Hz.
    pub shafts: &'a [ShaftSample],
}

/// How far the drawing turns the ghosts at most: the nominal table's largest error is magnified to
/// about this, rad (15°: seen at a glance, the axes still told apart).
const GHOST_DRAWN_RAD: f64 = 15.0 * std::f64::consts::PI / 180.0;

/// One free-inertial run of what the calibration buys.
pub struct NavLine<'a> {
    /// "at rest", "16-position": one plot each.
    pub motion: &'a str,
    /// "none", "estimated", "true": one line each, in the same colour in every plot.
    pub compensation: &'a str,
    /// Its errors.
    pub trace: &'a crate::ins::trace::NavTrace,
}

/// The groups of parameters, one plot each: the group's name ([`crate::calib::selfcal::Kind::group`]),
/// the entity's, and the plot's title (short enough for a third of the plots' width at 1600×1000).
const GROUPS: [(&str, &str, &str); 5] = [
    ("gyro bias", "gyro_bias", "gyro bias: log10 σ/σ0"),
    ("gyro scale and misalignment", "gyro_gain", "gyro Kg: log10 σ/σ0"),
    ("accelerometer bias", "accel_bias", "accel bias: log10 σ/σ0"),
    ("accelerometer scale and misalignment", "accel_gain", "accel Ka: log10 σ/σ0"),
    ("table", "table", "table (encoders): log10 σ/σ0"),
];

/// The axes a parameter's name ends in (`bg_y`, `Kg_yx`), in the order of their line colours in
/// [`palette::colors::DISTINCT`]: an axis, or a diagonal of K (a scale factor), in that axis's
/// colour, as the IMU's axes in 3D; the misalignments in colours of their own.
const LINE_AXES: [&[&str]; 9] =
    [&["x", "xx"], &["y", "yy"], &["z", "zz"], &["xy"], &["xz"], &["yz"], &["yx"], &["zx"], &["zy"]];

/// A parameter's line colour in its group's plot: its index in [`palette::colors::DISTINCT`].
fn line_colour(name: &str) -> usize {
    let axes = name.rsplit('_').next().unwrap_or_default();
    LINE_AXES.iter().position(|names| names.contains(&axes)).unwrap_or(LINE_AXES.len() - 1)
}

/// The key of the groups' plots (their titles have no room for it, a legend would cover the lines).
fn line_key() -> String {
    let name = |k: usize| palette::colors::DISTINCT[k].0;
    let axes = (0..3).map(|k| format!("{} {}", LINE_AXES[k][0], name(k))).collect::<Vec<_>>().join(", ");
    let scale = (0..3).map(|k| format!("{} {}", LINE_AXES[k][1], name(k))).collect::<Vec<_>>().join(", ");
    let misalignment = (3..9).map(|k| format!("{} {}", LINE_AXES[k][0], name(k))).collect::<Vec<_>>().join(", ");
    format!("biases {axes} (as the IMU's axes); Kg, Ka: scale factors {scale}, misalignments {misalignment}")
}

/// Logs the self-calibration.
pub fn log(stream: &Stream, v: &SelfcalView<'_>) -> RecordingStreamResult<()> {
    let rec = stream.rec();
    rec.send_recording_name(format!("rinscope selfcal: {}", v.title))?;
    let motions = motions(&v.navigation);
    let navigation = if motions.is_empty() {
        String::new()
    } else {
        let compensations = v
            .navigation
            .iter()
            .filter(|l| l.motion == motions[0])
            .enumerate()
            .map(|(i, l)| format!("{} {}", nav_colour(i).0, l.compensation));
        format!(
            "- right column: afterwards, the same RINS free-inertial from t = 0 ({}), the radial position error in log10 metres (1 = 10 m, 4 = 10 km), and beside the table's plot the body's heading error in log10 arcsec; compensation {} (none: a raw IMU on the nominal table; estimated: this calibration's IMU and table; true: their true errors)\n",
            motions.join(", "),
            compensations.collect::<Vec<_>>().join(", ")
        )
    };
    let doc = format!(
        "# Self-calibration: {}\n\n**Plots**\n\n- top left: each parameter's 1σ over its prior σ0 in log10 (−2: a hundredfold), ▼ a move; {}\n{navigation}\
         - tabs: each estimate{} inside its ±3σ band (grey)\n{}\ndocs/selfcal.md explains the filter and the sequences.\n\n{}",
        v.title,
        line_key(),
        if v.truth.is_some() { " minus the truth" } else { "" },
        if v.tables.is_some() {
            format!(
                "- 3D: the IMU's axes where the {} table puts it, and ghosts where the nominal table (orange) and the table as estimated at the time cursor (white) put it from the same encoder readings, their errors magnified (×F in the view's title), each labelled with its true size\n",
                if v.truth.is_some() { "true" } else { "finally estimated" }
            )
        } else {
            String::new()
        },
        v.document
    );
    rec.log_static("docs/selfcal", &rerun::TextDocument::from_markdown(doc))?;
    // The IMU: a case and its axes, turned by its true attitude.
    rec.log_static(
        "world/imu/case",
        &rerun::Boxes3D::from_half_sizes([[0.25, 0.25, 0.18]]).with_colors([palette::rgba([150, 150, 160], 90)]),
    )?;
    rec.log_static(
        "world/imu/axes",
        &rerun::Arrows3D::from_vectors([[0.6, 0.0, 0.0], [0.0, 0.6, 0.0], [0.0, 0.0, 0.6]])
            .with_colors(palette::colors::SENSOR.map(rgb))
            .with_radii([0.02]),
    )?;
    rec.log_static(
        "world/imu/axes/labels",
        &rerun::Points3D::new([[0.72, 0.0, 0.0], [0.0, 0.72, 0.0], [0.0, 0.0, 0.72]])
            .with_labels(["x", "y", "z"])
            .with_colors(palette::colors::SENSOR.map(palette::label))
            .with_radii([0.002]),
    )?;
    let times: Vec<f64> = v.attitude.iter().map(|a| a.0).collect();
    if !times.is_empty() {
        rec.send_columns(
            "world/imu",
            stream.time_columns(&times),
            rerun::Transform3D::update_fields()
                .with_many_quaternion(v.attitude.iter().map(|a| to_rerun_quaternion(&a.1)))
                .columns_of_unit_batches()?,
        )?;
    }
    let ghosts = log_tables(stream, v)?;
    let t: Vec<f64> = v.history.iter().map(|r| r.t_s).collect();
    // The sequence's plots show the sequence (the free-inertial runs after it share the timeline).
    let seq_axis = blueprint::time_axis_range(0.0, t.last().copied().unwrap_or(1.0));
    let mut tabs = Vec::new();
    let mut observability = Vec::new();
    for (group, slug, title) in GROUPS {
        let members: Vec<usize> = (0..v.names.len()).filter(|&k| ParamKind::of(k).group() == group).collect();
        if members.is_empty() {
            continue;
        }
        let path = format!("selfcal/observability/{slug}/log10_sigma_ratio");
        let names: Vec<String> = members.iter().map(|&k| v.names[k].clone()).collect();
        let colors = names.iter().map(|n| rgb(palette::colors::DISTINCT[line_colour(n)].1));
        rec.log_static(path.as_str(), &rerun::SeriesLines::new().with_colors(colors).with_names(names.clone()))?;
        let values: Vec<f64> = v
            .history
            .iter()
            .flat_map(|r| members.iter().map(|&k| (r.sigma_of(k) / v.prior[k]).max(1e-12).log10()).collect::<Vec<_>>())
            .collect();
        stream.send_series(&path, &names, &t, values, members.len())?;
        stream.mark_events(&path, "moves", "moves", v.move_starts_s, 0.0)?;
        // Keyed in the document (a legend would cover the lines, the title has no room).
        observability.push(
            Node::view("TimeSeries", title, path)
                .with_property("TimeAxis", &seq_axis)
                .with_property("PlotLegend", &blueprint::no_legend()),
        );
        for &k in &members {
            let (kind, name) = (ParamKind::of(k), &v.names[k]);
            let (unit, per_si) = kind.unit();
            let path = format!("selfcal/error/{name}_{}", kind.unit_key());
            let truth = v.truth.as_ref().map_or(0.0, |t| t[k]);
            let what = if v.truth.is_some() { "estimate − true" } else { "estimate" };
            let series = [what.to_owned(), "+3σ".to_owned(), "−3σ".to_owned()];
            rec.log_static(
                path.as_str(),
                &rerun::SeriesLines::new()
                    .with_colors([rgb([250, 200, 60]), rgb([150, 150, 150]), rgb([150, 150, 150])])
                    .with_names(series.clone()),
            )?;
            let values: Vec<f64> = v
                .history
                .iter()
                .flat_map(|r| {
                    let (e, s) = ((r.estimate_of(k) - truth) * per_si, 3.0 * r.sigma_of(k) * per_si);
                    [e, s, -s]
                })
                .collect();
            stream.send_series(&path, &series, &t, values, 3)?;
            // Framed on the last tenth of the prior: the start (the prior's width) would flatten the rest.
            let last = v.history.last().map_or(1.0, |r| 3.0 * r.sigma_of(k) * per_si);
            let h = crate::math::units::nice_half_range(last.max(1e-12) * 2.0);
            tabs.push(
                Node::view("TimeSeries", format!("{name} {what} ({unit}), ±3σ grey"), path)
                    .with_property("TimeAxis", &seq_axis)
                    .with_property("PlotLegend", &blueprint::no_legend())
                    .with_property("ScalarAxis", &blueprint::symmetric_range(h)),
            );
        }
    }
    let navigation = log_navigation(stream, &v.navigation, &motions)?;
    // Gyro groups over accelerometer groups, a motion's navigation beside each row.
    let mut navigation = navigation.into_iter();
    let mut observability = observability.into_iter();
    // Three plots a row: two groups and a navigation plot; a row with one group left (the
    // table's) takes two navigation plots (the headings).
    let rows: Vec<Node> = (0..observability.len().div_ceil(2))
        .map(|_| {
            let groups: Vec<Node> = observability.by_ref().take(2).collect();
            let room = 3 - groups.len();
            Node::container(
                ContainerKind::Horizontal,
                groups.into_iter().chain(navigation.by_ref().take(room)).collect(),
                &[],
            )
        })
        .collect();
    let mut grid = Node::container(ContainerKind::Vertical, rows, &[]);
    // More motions than rows (none today): a row of their own.
    let more: Vec<Node> = navigation.collect();
    if !more.is_empty() {
        grid = Node::container(
            ContainerKind::Vertical,
            vec![grid, Node::container(ContainerKind::Horizontal, more, &[])],
            &[2.0, 1.0],
        );
    }
    let left = Node::container(
        ContainerKind::Vertical,
        vec![
            Node::view(
                "3D",
                ghosts.map_or_else(
                    || "the IMU turning through the sequence (true attitude; the grid is level)".to_owned(),
                    |f| format!("the IMU; where the nominal (orange), estimated (white) table put it ×{f}"),
                ),
                "world",
            )
            .with_property("EyeControls3D", &blueprint::eye([1.5, -1.7, 1.0], [0.0, 0.0, 0.0])),
            Node::view("TextDocument", "result", "docs/selfcal"),
        ],
        &[1.0, 1.2],
    );
    let right = Node::container(
        ContainerKind::Vertical,
        vec![grid, Node::container(ContainerKind::Tabs, tabs, &[])],
        &[1.2, 1.0],
    );
    let root = Node::container(ContainerKind::Horizontal, vec![left, right], &[1.0, 1.5]);
    blueprint::send(rec, APPLICATION_ID, &root, &blueprint::Playback { timeline: TIMELINE, speed: 60.0, follow: false })
}

/// The colour of a motion's `i`-th run (none, estimated, true: red, green, blue, as uncompensated,
/// compensated and the closed form in a run's plots).
fn nav_colour(i: usize) -> (&'static str, [u8; 3]) {
    palette::colors::DISTINCT[i % 3]
}

/// The motions of the navigation runs, in order.
fn motions<'a>(lines: &[NavLine<'a>]) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for l in lines {
        if !out.contains(&l.motion) {
            out.push(l.motion);
        }
    }
    out
}

/// What the calibration buys: one plot per motion of its runs' radial position errors (log10 m),
/// the compensations in the same colours in each, on one value range (so that the plots compare);
/// then one per motion of the body's heading error (log10 arcsec: what the table's compensation and
/// the gyros' leave in the attitude the RINS reports — the nominal table's arcminutes and the
/// compensated runs' arcseconds on one axis). On the sequence's timeline from t = 0, for the whole
/// run (hours of navigation, not the sequence).
fn log_navigation(stream: &Stream, lines: &[NavLine<'_>], motions: &[&str]) -> RecordingStreamResult<Vec<Node>> {
    let radial = |s: &NavSample| s.position_m[2].max(1e-3).log10();
    let heading = |s: &NavSample| s.heading_arcsec.abs().max(0.1).log10();
    // From the first hundredth of the run on (the lines' steep start from 0 m would set the range).
    let end_s = lines.iter().filter_map(|l| l.trace.samples.last()).map(|s| s.t_s).fold(0.0, f64::max);
    let range = |f: &dyn Fn(&NavSample) -> f64| {
        lines
            .iter()
            .flat_map(|l| &l.trace.samples)
            .filter(|s| s.t_s >= 0.01 * end_s)
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| (lo.min(y), hi.max(y)))
    };
    let mut plots = Vec::new();
    for (slug, title, value) in [
        ("radial_position_error_log10_m", "log10 error (m)", &radial as &dyn Fn(&NavSample) -> f64),
        ("heading_error_log10_arcsec", "log10 |heading error| (″)", &heading),
    ] {
        let (lo, hi) = range(value);
        for motion in motions {
            let runs: Vec<&NavLine<'_>> = lines.iter().filter(|l| l.motion == *motion).collect();
            let path = format!("selfcal/navigation/{}/{slug}", motion.replace([' ', '-'], "_"));
            let names: Vec<String> = runs.iter().map(|l| l.compensation.to_owned()).collect();
            let colors = (0..runs.len()).map(|i| rgb(nav_colour(i).1));
            stream
                .rec()
                .log_static(path.as_str(), &rerun::SeriesLines::new().with_colors(colors).with_names(names.clone()))?;
            let n = runs.iter().map(|l| l.trace.samples.len()).min().unwrap_or(0);
            let times: Vec<f64> = runs[0].trace.samples.iter().take(n).map(|s| s.t_s).collect();
            let values: Vec<f64> = (0..n).flat_map(|i| runs.iter().map(move |l| value(&l.trace.samples[i]))).collect();
            stream.rec().send_columns(
                path.as_str(),
                stream.time_columns(&times),
                rerun::Scalars::new(values).columns(std::iter::repeat_n(names.len(), n))?,
            )?;
            let mut plot = Node::view("TimeSeries", format!("{motion}: {title}"), path)
                .with_property("TimeAxis", &blueprint::whole_run_time_axis())
                // Below the lines once they have left 0: the legend covers none of them.
                .with_property("PlotLegend", &blueprint::legend_at(blueprint::LegendCorner::RightBottom));
            if lo.is_finite() {
                // A whole decade of room under the lowest value, for the legend.
                plot = plot.with_property("ScalarAxis", &blueprint::scalar_range(lo.floor() - 1.0, hi.ceil()));
            }
            plots.push(plot);
        }
    }
    Ok(plots)
}

/// The tables in 3D ([`TableGhosts`]): two ghosts of the IMU's axes under `world/imu`, turned by
/// where the nominal and the estimated table put the IMU relative to the reference table, magnified.
/// Returns the magnification (None: nothing drawn).
fn log_tables(stream: &Stream, v: &SelfcalView<'_>) -> RecordingStreamResult<Option<f64>> {
    let Some(g) = &v.tables else { return Ok(None) };
    let (n, last) = (g.states.len(), v.history.last());
    let Some(last) = last.filter(|_| !g.shafts.is_empty() && n > 0 && v.names.len() >= n) else { return Ok(None) };
    let first = v.names.len() - n;
    let reference: Vec<f64> = match &v.truth {
        Some(t) => t[first..].to_vec(),
        None => (0..n).map(|j| last.estimate_of(first + j)).collect(),
    };
    let nominal = vec![0.0; n];
    // Each second: the reference table's C_s^b and each ghost's rotation from it, sensor axes.
    let rows: Vec<(f64, [nalgebra::Vector3<f64>; 2])> = g
        .shafts
        .iter()
        .map(|s| {
            let row = &v.history[v.history.partition_point(|r| r.t_s <= s.t_s).saturating_sub(1)];
            let estimated: Vec<f64> = (0..n).map(|j| row.estimate_of(first + j)).collect();
            (s.t_s, [g.states.offset(&reference, &nominal, s), g.states.offset(&reference, &estimated, s)])
        })
        .collect();
    let largest = rows.iter().map(|r| r.1[0].norm()).fold(0.0, f64::max);
    if largest <= 0.0 {
        return Ok(None);
    }
    let factor = crate::math::units::nice_at_most(GHOST_DRAWN_RAD / largest);
    let rec = stream.rec();
    let times: Vec<f64> = rows.iter().map(|r| r.0).collect();
    for (i, (name, what)) in
        [("nominal_table", "nominal table"), ("estimated_table", "estimated table")].into_iter().enumerate()
    {
        let path = format!("world/imu/{name}");
        // Orange and white: apart from the IMU's own red, green and blue axes (white as
        // `calibrate`'s estimated cones).
        let colour = [palette::colors::DISTINCT[3].1, palette::colors::DISTINCT[8].1][i];
        rec.log_static(
            format!("{path}/axes"),
            &rerun::Arrows3D::from_vectors([[0.5, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.5]])
                .with_colors([rgb(colour)])
                .with_radii([0.008]),
        )?;
        rec.send_columns(
            path.as_str(),
            stream.time_columns(&times),
            rerun::Transform3D::update_fields()
                .with_many_quaternion(rows.iter().map(|r| to_rerun_quaternion(&rotvec::exp(&(r.1[i] * factor)))))
                .columns_of_unit_batches()?,
        )?;
        // Its true size, beside the IMU (the two labels one above the other, clear of its axes).
        let labels = rows.iter().map(|r| format!("{what}: {:.1}″", r.1[i].norm() * ARCSEC_PER_RAD));
        let tip = [0.25, -0.55, 0.5 - 0.14 * i as f32];
        rec.log_static(
            format!("{path}/axes/size"),
            &rerun::Points3D::new([tip]).with_radii([0.002]).with_colors([palette::label(colour)]),
        )?;
        rec.send_columns(
            format!("{path}/axes/size"),
            stream.time_columns(&times),
            rerun::Points3D::update_fields().with_labels(labels).columns_of_unit_batches()?,
        )?;
    }
    Ok(Some(factor))
}
