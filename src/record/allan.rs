//! The recording of `rinscope allan`: one log-log Allan plot per axis (gyros above, accelerometers
//! below), the fitted slope lines of the IEEE terms over the data, the configured truth dotted, the
//! coefficients as a table. Rerun plots against a timeline and has no logarithmic axis, so the
//! curves are logged as log10 values on a timeline `log10_tau_s` whose "seconds" are log10(τ / 1 s),
//! and the entity paths and the documents say so. `--export` writes the curves and the fits as
//! tables ([`export`]).

use rerun::blueprint::components::ContainerKind;
use rerun::{RecordingStreamResult, TimeColumn};

use super::blueprint::{self, LegendCorner, Node};
use super::export::Exporter;
use super::palette::rgb;
use super::{APPLICATION_ID, Stream};
use crate::ins::allan::{Channel, ImuAllan, Sensor};
use crate::io::LogError;
use crate::math::allan::TERMS;
use crate::math::allan::estimators::Estimator;

/// The x axis: a duration timeline whose value in seconds is log10(τ / 1 s).
pub const LOG10_TAU_TIMELINE: &str = "log10_tau_s";

const MEASURED: [u8; 3] = [235, 235, 235];
const CONFIDENCE: [u8; 3] = [120, 120, 120];
const TRUTH: [u8; 3] = [80, 220, 230];
/// Q, N, B, K, R.
const TERM_COLORS: [[u8; 3]; 5] = [[200, 110, 240], [80, 140, 250], [60, 200, 90], [240, 80, 80], [240, 220, 60]];

/// Points per decade of the drawn lines (fit, slope lines, truth).
const LINE_POINTS_PER_DECADE: f64 = 20.0;

/// The channel's entity: `allan/gyro_x`, `allan/clock_<column>` (the column name reduced to
/// letters, digits and `_`).
fn path(c: &Channel) -> String {
    let label: String =
        c.label.chars().map(|ch| if ch.is_ascii_alphanumeric() || ch == '_' { ch } else { '_' }).collect();
    format!("allan/{}_{label}", c.sensor.name())
}

/// Colours of the other estimators' curves, in `Estimator::ALL` order.
const ESTIMATOR_COLORS: [[u8; 3]; 7] = [
    [250, 160, 60],
    [235, 235, 235],
    [90, 200, 250],
    [250, 120, 200],
    [150, 230, 120],
    [200, 160, 250],
    [250, 210, 90],
];

/// One curve on the log10 τ timeline.
fn send(
    stream: &Stream,
    entity: &str,
    log10_tau: &[f64],
    log10_value: &[f64],
    drawn: &mut Vec<(f64, f64)>,
) -> RecordingStreamResult<()> {
    drawn.extend(log10_tau.iter().copied().zip(log10_value.iter().copied()));
    let time = TimeColumn::new_duration_secs(LOG10_TAU_TIMELINE, log10_tau.iter().copied());
    stream.rec().send_columns(
        entity,
        [time],
        rerun::Scalars::new(log10_value.iter().copied()).columns(std::iter::repeat_n(1, log10_tau.len()))?,
    )?;
    Ok(())
}

fn line_style(stream: &Stream, entity: &str, color: [u8; 3], width: f32, name: &str) -> RecordingStreamResult<()> {
    stream.rec().log_static(
        entity,
        &rerun::SeriesLines::new().with_colors([rgb(color)]).with_widths([width]).with_names([name]),
    )
}

/// A dense log-spaced grid over [lo, hi] (log10 values).
fn grid(lo: f64, hi: f64) -> Vec<f64> {
    let n = (((hi - lo) * LINE_POINTS_PER_DECADE).ceil() as usize).max(1);
    (0..=n).map(|i| lo + (hi - lo) * i as f64 / n as f64).collect()
}

/// Logs one channel's plot; returns the ranges its view shows (with room for the legend).
fn log_channel(stream: &Stream, c: &Channel, ci_sigma: f64) -> RecordingStreamResult<PlotRange> {
    let base = path(c);
    let u = c.sensor.adev_unit();
    let lg = |v: f64| (v / u.si).log10();
    let Some(r) = &c.report else {
        let mut drawn = Vec::new();
        log_curves(stream, c, &base, |e| !e.is_of_phase(), &mut drawn)?;
        return Ok(range_of(&drawn));
    };
    let keep: Vec<usize> = (0..r.taus_s.len()).filter(|&j| r.adev_si[j] > 0.0).collect();
    if keep.is_empty() {
        return Ok(PlotRange { x: (-3.0, 3.0), y: (-1.0, 1.0), legend: LegendCorner::RightBottom });
    }
    let x: Vec<f64> = keep.iter().map(|&j| r.taus_s[j].log10()).collect();
    let y: Vec<f64> = keep.iter().map(|&j| lg(r.adev_si[j])).collect();
    let dir = format!("{base}/log10_adev_{}", u.key);
    let mut drawn = Vec::new();
    let measured = format!("{dir}/measured");
    stream.rec().log_static(
        measured.as_str(),
        &rerun::SeriesLines::new().with_colors([rgb(MEASURED)]).with_widths([2.0]).with_names(["ADEV (measured)"]),
    )?;
    stream.rec().log_static(
        measured.as_str(),
        &rerun::SeriesPoints::new()
            .with_colors([rgb(MEASURED)])
            .with_marker_sizes([2.5])
            .with_names(["ADEV (measured)"]),
    )?;
    send(stream, &measured, &x, &y, &mut drawn)?;
    let (mut y_min, mut y_max) = (f64::INFINITY, f64::NEG_INFINITY);
    for (name, bound, sign) in [("ci_upper", &r.adev_upper_si, "+"), ("ci_lower", &r.adev_lower_si, "−")] {
        let e = format!("{dir}/{name}");
        line_style(stream, &e, CONFIDENCE, 1.0, &format!("{sign}{ci_sigma}σ bound"))?;
        let yb: Vec<f64> = keep.iter().map(|&j| lg(bound[j].max(f64::MIN_POSITIVE))).collect();
        for v in &yb {
            (y_min, y_max) = (y_min.min(*v), y_max.max(*v));
        }
        send(stream, &e, &x, &yb, &mut drawn)?;
    }
    let (x_lo, x_hi) = (x[0], x[x.len() - 1]);
    let (y_lo, y_hi) = (y_min - 0.3, y_max + 0.3);
    let dense = grid(x_lo, x_hi);
    let fit = &r.fit;
    for term in TERMS {
        let est = fit.get(term);
        if !est.significant {
            continue;
        }
        // The term's line log10 σ = log10 √(a c²) + (p/2) log10 τ, where the term makes at least
        // a tenth of the fitted variance, inside the plot.
        let (p, a0) = (f64::from(term.exponent()) / 2.0, lg(term.avar(est.value, 1.0).sqrt()));
        let share = |lt: f64| term.avar(est.value, 10f64.powf(lt)) / fit.avar(10f64.powf(lt));
        let pts: Vec<(f64, f64)> = dense
            .iter()
            .filter(|lt| share(**lt) >= 0.1)
            .map(|lt| (*lt, a0 + p * lt))
            .filter(|(_, v)| (y_lo..=y_hi).contains(v))
            .collect();
        if pts.len() < 2 {
            continue;
        }
        let e = format!("{dir}/slope_{}", term.letter());
        let unit = c.sensor.unit(term);
        let label = format!(
            "{} {} {} ({})",
            term.letter(),
            crate::ins::allan::sig(est.value / unit.si, 3),
            unit.text,
            term.slope_text()
        );
        line_style(stream, &e, TERM_COLORS[term as usize], 1.5, &label)?;
        let (xs, ys): (Vec<f64>, Vec<f64>) = pts.into_iter().unzip();
        send(stream, &e, &xs, &ys, &mut drawn)?;
    }
    if let Some(t) = c.truth {
        let e = format!("{dir}/configured");
        stream.rec().log_static(
            e.as_str(),
            &rerun::SeriesPoints::new()
                .with_colors([rgb(TRUTH)])
                .with_marker_sizes([1.2])
                .with_markers([rerun::components::MarkerShape::Circle])
                .with_names(["configured"]),
        )?;
        let yt: Vec<f64> = dense.iter().map(|lt| lg(t.avar(10f64.powf(*lt)).sqrt().max(f64::MIN_POSITIVE))).collect();
        for v in &yt {
            (y_min, y_max) = (y_min.min(*v), y_max.max(*v));
        }
        send(stream, &e, &dense, &yt, &mut drawn)?;
    }
    log_curves(stream, c, &base, |e| !e.is_of_phase(), &mut drawn)?;
    let x_hi = drawn.iter().map(|p| p.0).fold(x_hi, f64::max);
    Ok(plot_range(&drawn, (x_lo, x_hi)))
}

/// The ranges of a plot that shows `drawn` (at least a decade of τ).
fn range_of(drawn: &[(f64, f64)]) -> PlotRange {
    if drawn.is_empty() {
        return PlotRange { x: (-3.0, 3.0), y: (-1.0, 1.0), legend: LegendCorner::RightBottom };
    }
    let (lo, hi) = drawn.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.0), hi.max(p.0)));
    plot_range(drawn, (lo, hi.max(lo + 1.0)))
}

/// Logs the curves of `c.curves` that `keep` selects under `base`, each with its bounds, in its
/// estimator's colour.
fn log_curves(
    stream: &Stream,
    c: &Channel,
    base: &str,
    keep: impl Fn(Estimator) -> bool,
    drawn: &mut Vec<(f64, f64)>,
) -> RecordingStreamResult<()> {
    for k in c.curves.iter().filter(|k| keep(k.estimator)) {
        let u = c.sensor.deviation_unit(k.estimator);
        let js: Vec<usize> = (0..k.dev.len()).filter(|&j| k.dev[j] > 0.0).collect();
        if js.is_empty() {
            continue;
        }
        let color = ESTIMATOR_COLORS[Estimator::ALL.iter().position(|e| *e == k.estimator).unwrap_or(0)];
        let name = k.estimator.name();
        let dir = format!("{base}/log10_{name}{}", if u.key == "frac" { String::new() } else { format!("_{}", u.key) });
        let x: Vec<f64> = js.iter().map(|&j| k.taus_s[j].log10()).collect();
        let e = format!("{dir}/measured");
        stream.rec().log_static(
            e.as_str(),
            &rerun::SeriesLines::new().with_colors([rgb(color)]).with_widths([1.5]).with_names([name.to_uppercase()]),
        )?;
        stream.rec().log_static(
            e.as_str(),
            &rerun::SeriesPoints::new()
                .with_colors([rgb(color)])
                .with_marker_sizes([2.5])
                .with_names([name.to_uppercase()]),
        )?;
        send(stream, &e, &x, &js.iter().map(|&j| (k.dev[j] / u.si).log10()).collect::<Vec<_>>(), drawn)?;
        for (side, bound) in [("ci_upper", &k.upper), ("ci_lower", &k.lower)] {
            let e = format!("{dir}/{side}");
            line_style(stream, &e, color.map(|v| v / 2 + 40), 1.0, &format!("{} bound", name.to_uppercase()))?;
            send(
                stream,
                &e,
                &x,
                &js.iter().map(|&j| (bound[j].max(f64::MIN_POSITIVE) / u.si).log10()).collect::<Vec<_>>(),
                drawn,
            )?;
        }
    }
    Ok(())
}

/// The view's ranges and the legend's corner: the first corner (bottom right, bottom left, top
/// right, top left) whose 30 % × 48 % box holds no drawn point; if every one does (a V-shaped curve
/// fills them all), room on the right of the data (at most 30 % more: the axis keeps its ticks),
/// else below it.
fn plot_range(drawn: &[(f64, f64)], x: (f64, f64)) -> PlotRange {
    let y = drawn.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (_, v)| (lo.min(*v), hi.max(*v)));
    let sx = (x.1 - x.0).max(1e-3);
    let sy = (y.1 - y.0).max(0.5);
    let y_r = (y.0 - 0.04 * sy, y.1 + 0.04 * sy);
    let free = |x_r: (f64, f64), y_r: (f64, f64), right: bool, bottom: bool| {
        !drawn.iter().any(|(px, py)| {
            let (nx, ny) = ((px - x_r.0) / (x_r.1 - x_r.0), (py - y_r.0) / (y_r.1 - y_r.0));
            (if right { nx > 0.68 } else { nx < 0.32 }) && (if bottom { ny < 0.52 } else { ny > 0.48 })
        })
    };
    let x_r = (x.0 - 0.02 * sx, x.1 + 0.02 * sx);
    let corners = [
        (true, true, LegendCorner::RightBottom),
        (false, true, LegendCorner::LeftBottom),
        (true, false, LegendCorner::RightTop),
        (false, false, LegendCorner::LeftTop),
    ];
    if let Some((_, _, corner)) = corners.iter().find(|(r, b, _)| free(x_r, y_r, *r, *b)) {
        return PlotRange { x: x_r, y: y_r, legend: *corner };
    }
    let wide = (x_r.0, x.1 + 0.3 * sx);
    if free(wide, y_r, true, true) {
        return PlotRange { x: wide, y: y_r, legend: LegendCorner::RightBottom };
    }
    PlotRange { x: wide, y: (y.0 - 0.8 * sy, y_r.1), legend: LegendCorner::RightBottom }
}

/// A log-log plot of `entity` showing `range`.
fn plot_view(title: String, entity: String, range: &PlotRange) -> Node {
    Node::view("TimeSeries", title, entity)
        .with_property("TimeAxis", &blueprint::time_axis_range(range.x.0, range.x.1))
        .with_property("ScalarAxis", &blueprint::scalar_range(range.y.0, range.y.1))
        .with_property("PlotLegend", &blueprint::legend_at(range.legend))
}

/// What a plot shows, log10 units, and where its legend goes.
struct PlotRange {
    x: (f64, f64),
    y: (f64, f64),
    legend: LegendCorner,
}

fn about(r: &ImuAllan, description: &str) -> String {
    let terms: String = TERMS
        .iter()
        .map(|t| {
            format!(
                "| {} | {} / {} | {} |\n",
                t.letter(),
                crate::ins::allan::Sensor::Gyro.term_name(*t),
                crate::ins::allan::Sensor::Accel.term_name(*t),
                t.slope_text()
            )
        })
        .collect();
    let mut notes: String = r.notes.iter().map(|n| format!("\n*Note:* {n}\n")).collect();
    // A fit is a claim: where the data contradict a term or every IEEE combination, said here too.
    for c in &r.channels {
        if let Some(rep) = &c.report {
            for w in &rep.fit_contradictions {
                notes += &format!("\n**WARNING** {}: {} (χ²/dof {:.3})\n", c.name(), w.text(), rep.fit_chi2_per_dof);
            }
        }
    }
    format!(
        "# Allan deviation\n\n{}\n{notes}\n**How to read the plots.** Rerun has no logarithmic axis, so both axes carry **log10 values**: \
         the horizontal axis is the timeline `{LOG10_TAU_TIMELINE}`, whose \"seconds\" are **log10(τ / 1 s)** (−2 is 10 ms, 0 is \
         1 s, 3 is 1000 s); the vertical axis is log10 of the Allan deviation of the rate, in **log10(°/h)** for gyros and \
         **log10(µg)** for accelerometers (0 is 1 °/h or 1 µg, −1 is 0.1). A power law σ = c·τ^s is a straight line of slope s:\n\n\
         | term | gyro / accelerometer | slope |\n|---|---|---|\n{terms}\n\
         White: the measured overlapping ADEV; grey: its ±{}σ confidence bounds (χ² with the equivalent degrees of freedom of \
         NIST SP 1065); coloured: the slope line of each term the fit found, labelled with its coefficient and drawn where \
         it makes at least a tenth of the fitted variance, and only for the terms the fit found (a term the data contradict is not drawn); \
         cyan dots: the exact ADEV of the configured noise (when it is known). The flat floor of B is at 0.664·B. Other \
         estimators asked for with `--estimator` (MDEV, HDEV, TOTDEV, ...) are drawn in their own colours with their bounds \
         (EDF by Greenhall & Riley for the noise type identified at each τ); TDEV, a deviation of the phase, has its own plot.\n\n{}\n",
        r.heading(),
        r.ci_sigma,
        description.trim()
    )
}

/// Logs the analysis with its documents and a layout; `description` explains the source (markdown).
pub fn log(stream: &Stream, r: &ImuAllan, description: &str) -> RecordingStreamResult<()> {
    let rec = stream.rec();
    rec.send_recording_name(format!("rinscope allan: {}", r.source))?;
    rec.log_static("docs/allan", &rerun::TextDocument::from_markdown(about(r, description)))?;
    for sensor in Sensor::ALL.into_iter().filter(|s| r.channels.iter().any(|c| c.sensor == *s && c.report.is_some())) {
        rec.log_static(
            format!("docs/coefficients_{}", sensor.name()),
            &rerun::TextDocument::from_markdown(r.markdown(sensor)),
        )?;
    }
    // One plot per channel of the rate deviations; TDEV (of the phase, another unit) beside it.
    let mut views: Vec<(Sensor, Node)> = Vec::new();
    for c in &r.channels {
        let range = log_channel(stream, c, r.ci_sigma)?;
        let u = c.sensor.adev_unit();
        let unit =
            if u.text.is_empty() { "log10 fractional frequency".to_owned() } else { format!("log10 {}", u.text) };
        let what = if c.report.is_some() { "ADEV" } else { "deviation" };
        views.push((
            c.sensor,
            plot_view(
                format!("{}: log10 {what} [{unit}] vs log10 τ — the axis's \"+1s\" is τ = 10 s", c.name()),
                path(c),
                &range,
            ),
        ));
        if c.curves.iter().any(|k| k.estimator.is_of_phase()) {
            let base = format!("{}_tdev", path(c));
            let mut drawn = Vec::new();
            log_curves(stream, c, &base, Estimator::is_of_phase, &mut drawn)?;
            let pu = c.sensor.phase_unit();
            views.push((
                c.sensor,
                plot_view(
                    format!("{}: log10 TDEV [log10 {}] vs log10 τ — the axis's \"+1s\" is τ = 10 s", c.name(), pu.text),
                    base,
                    &range_of(&drawn),
                ),
            ));
        }
    }
    let mut rows: Vec<Node> = Vec::new();
    for sensor in Sensor::ALL {
        let these: Vec<Node> = views.iter().filter(|(s, _)| *s == sensor).map(|(_, v)| v.clone()).collect();
        if !these.is_empty() {
            rows.push(Node::container(ContainerKind::Horizontal, these, &[]));
        }
    }
    let mut tabs: Vec<Node> = Sensor::ALL
        .iter()
        .filter(|s| r.channels.iter().any(|c| c.sensor == **s && c.report.is_some()))
        .map(|s| {
            Node::view("TextDocument", format!("{} coefficients", s.name()), format!("docs/coefficients_{}", s.name()))
        })
        .collect();
    tabs.push(Node::view("TextDocument", "how to read the plots", "docs/allan"));
    let mut shares: Vec<f32> = vec![1.0; rows.len()];
    rows.push(Node::container(ContainerKind::Tabs, tabs, &[]));
    shares.push(0.62);
    let root = Node::container(ContainerKind::Vertical, rows, &shares);
    blueprint::send(
        rec,
        APPLICATION_ID,
        &root,
        &blueprint::Playback { timeline: LOG10_TAU_TIMELINE, speed: 1.0, follow: true },
    )
}

/// `allan --export`: per channel (`allan__gyro_x`, ...) its curve against `tau_s` — the Allan
/// deviation, its lower and upper confidence bounds, the fitted model's deviation (and the
/// configured noise's when known) in the sensor's unit (°/h, µg), the equivalent degrees of
/// freedom and the number of second differences; per sensor (`allan__gyro_fit`, ...) one row per
/// axis (`axis` 0, 1, 2 = x, y, z) of the fitted coefficients with their 1σ in their conventional
/// units and whether the fit found each (`found` 1 or 0: a dropped term's value is 0 and its 1σ
/// the detection limit), and the fit's χ²/dof.
///
/// # Errors
/// A table that cannot be written.
pub fn export(exporter: &mut Exporter, r: &ImuAllan) -> Result<(), LogError> {
    for c in &r.channels {
        for k in &c.curves {
            let u = c.sensor.deviation_unit(k.estimator);
            let columns: Vec<String> = [
                "tau_s".to_owned(),
                "m".to_owned(),
                format!("dev_{}", u.key),
                format!("lower_{}", u.key),
                format!("upper_{}", u.key),
                "edf".to_owned(),
                "alpha".to_owned(),
                "alpha_identified".to_owned(),
                "terms_count".to_owned(),
            ]
            .into();
            let rows: Vec<Vec<f64>> = (0..k.m.len())
                .map(|j| {
                    vec![
                        k.taus_s[j],
                        k.m[j] as f64,
                        k.dev[j] / u.si,
                        k.lower[j] / u.si,
                        k.upper[j] / u.si,
                        k.edf[j],
                        f64::from(k.alpha[j]),
                        f64::from(u8::from(k.alpha_identified[j])),
                        k.n_terms[j] as f64,
                    ]
                })
                .collect();
            exporter.write_table(&format!("{}_{}", path(c), k.estimator.name()), &columns, &rows)?;
        }
        let u = c.sensor.adev_unit();
        let Some(rep) = &c.report else { continue };
        let mut columns: Vec<String> = ["tau_s", "adev", "adev_lower", "adev_upper", "fit_adev"]
            .iter()
            .enumerate()
            .map(|(i, n)| if i == 0 { (*n).to_owned() } else { format!("{n}_{}", u.key) })
            .collect();
        columns.extend(["edf".to_owned(), "second_differences_count".to_owned()]);
        if c.truth.is_some() {
            columns.push(format!("configured_adev_{}", u.key));
        }
        let rows: Vec<Vec<f64>> = (0..rep.taus_s.len())
            .map(|j| {
                let tau = rep.taus_s[j];
                let mut row = vec![
                    tau,
                    rep.adev_si[j] / u.si,
                    rep.adev_lower_si[j] / u.si,
                    rep.adev_upper_si[j] / u.si,
                    rep.fit.avar(tau).sqrt() / u.si,
                    rep.edf[j],
                    rep.n_terms[j] as f64,
                ];
                if let Some(t) = c.truth {
                    row.push(t.avar(tau).sqrt() / u.si);
                }
                row
            })
            .collect();
        exporter.write_table(&path(c), &columns, &rows)?;
    }
    for sensor in Sensor::ALL {
        let chans: Vec<(usize, &Channel, &crate::math::allan::AllanReport)> = r
            .channels
            .iter()
            .filter(|c| c.sensor == sensor)
            .enumerate()
            .filter_map(|(i, c)| c.report.as_ref().map(|rep| (i, c, rep)))
            .collect();
        if chans.is_empty() {
            continue;
        }
        let mut columns = vec!["axis".to_owned()];
        for term in TERMS {
            let (letter, unit) = (term.letter().to_lowercase(), sensor.unit(term).key);
            columns.extend([format!("{letter}_{unit}"), format!("{letter}_sigma_{unit}"), format!("{letter}_found")]);
        }
        columns.push("fit_chi2_per_dof".to_owned());
        let rows: Vec<Vec<f64>> = chans
            .iter()
            .map(|(i, c, rep)| {
                let mut row = vec![*i as f64];
                for term in TERMS {
                    let e = c.fitted(term);
                    row.extend([e.value, e.sigma, f64::from(u8::from(e.significant))]);
                }
                row.push(rep.fit_chi2_per_dof);
                row
            })
            .collect();
        exporter.write_table(&format!("allan/{}_fit", sensor.name()), &columns, &rows)?;
    }
    Ok(())
}
