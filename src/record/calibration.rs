//! The recording of `rinscope calibrate`: the table turning in 3D with the estimated swing cones as
//! white ghosts over the true ones (converging as the filter does), each state's estimate with its
//! ±3σ band beside the true value, and the attitude error before and after compensation.

use nalgebra::Vector3;
use rerun::RecordingStreamResult;
use rerun::blueprint::components::ContainerKind;

use super::blueprint::{self, Node};
use super::palette::{albedo, p3, rgb, rgba};
use super::scene::{cone, ring_radius};
use super::{CustomLayout, Recorder, Stream, TIMELINE};
use crate::calib::report::Report;
use crate::calib::{Calibration, Param};
use crate::math::rotvec;
use crate::math::units::{ARCSEC_PER_RAD, fmt_angle};
use crate::scenario::Params;
use crate::sim::ERROR_AXES;

const GHOST: [u8; 3] = [245, 245, 245];
const STATE_COLORS: [[u8; 3]; 5] = [[250, 200, 60], [120, 120, 120], [120, 120, 120], [90, 220, 120], [90, 160, 250]];
const ERROR_COLORS: [[u8; 3]; 3] = [[230, 76, 60], [250, 200, 60], [90, 160, 250]];
const STATE_NAMES: [&str; 5] = ["static KF", "+3σ", "−3σ", "true", "exact LSQ (final)"];
const ERROR_NAMES: [&str; 3] = ["before (no swing/η model)", "after: static KF", "after: exact LSQ"];

/// The validation run's attitude errors (pitch, roll, heading, rad) at the kept instants: before,
/// after the filter's compensation, after the least squares'.
pub type ErrorTraces = crate::calib::Thinned<Vec<[f64; 3]>>;

/// Writes the calibration's recording into `rec`: layout, documents, the filter over time, the
/// before/after errors and the ghost cones. Returns the table's recorder, into which the caller
/// streams the table's motion (as in any run) and finishes.
pub fn log(
    stream: Stream,
    params: &Params,
    cal: &Calibration,
    report: &Report,
    traces: &ErrorTraces,
) -> RecordingStreamResult<Recorder> {
    let chain = &params.table.chain;
    let set = &cal.set;
    let table: Vec<(usize, Param)> = set.params.iter().copied().enumerate().filter(|(_, p)| p.is_table()).collect();
    let plot = |name: String, origin: String| {
        Node::view("TimeSeries", name, origin).with_property("TimeAxis", &blueprint::whole_run_time_axis())
    };
    // Each state's plot is framed on where the filter ends: the final estimate ± 4 × its 3σ band
    // (at least ±1″), widened to include the true value; the prior's ±3σ start falls off the top.
    let truth = set.values(&params.table.truth);
    let states: Vec<Node> = table
        .iter()
        .map(|(i, p)| {
            let (x, sd, t) =
                (cal.kf.theta[*i] * ARCSEC_PER_RAD, cal.kf.sigma(*i) * ARCSEC_PER_RAD, truth[*i] * ARCSEC_PER_RAD);
            // On the viewer's power-of-ten grid: a centre on a tick and ±1.25 × a 1-2-3 half range,
            // so that the plot labels 3-7 ticks (blueprint::symmetric_range).
            let h = crate::math::units::nice_half_range((12.0 * sd).max(1.0).max(1.5 * (x - t).abs()));
            let tick = 10f64.powf(h.log10().floor());
            let centre = (x / tick).round() * tick;
            // The key is in the calibration document (the grid's cells are too narrow for it).
            plot(format!("{} (″)", p.label(chain)), format!("calibration/state_arcsec/{}", p.key(chain)))
                .with_property("ScalarAxis", &blueprint::scalar_range(centre - 1.25 * h, centre + 1.25 * h))
                .with_property("PlotLegend", &blueprint::no_legend())
        })
        .collect();
    // Keyed in the title (a legend would cover the first trough); KF wide under LSQ thin, since
    // the two compensations are nearly the same line.
    let errors: Vec<Node> = ERROR_AXES
        .iter()
        .map(|a| {
            plot(
                format!("{a} error (″) — red before, yellow (wide) after static KF, blue after exact LSQ"),
                format!("calibration/error_arcsec/{a}"),
            )
            .with_property("PlotLegend", &blueprint::no_legend())
        })
        .collect();
    let right = Node::container(
        ContainerKind::Vertical,
        vec![Node::container(ContainerKind::Grid, states, &[]), Node::container(ContainerKind::Tabs, errors, &[])],
        &[1.6, 1.0],
    );
    let custom = CustomLayout { right, docs: vec![Node::view("TextDocument", "calibration", "docs/calibration")] };
    // The table scene of the ideal demodulation; the INS is the calibration's business here.
    let mut drawing = params.clone();
    drawing.ins = None;
    let recorder = Recorder::with_layout(stream, &drawing, custom)?;
    let stream = recorder.stream().clone();
    let rec = stream.rec().clone();

    rec.log_static(
        "docs/calibration",
        &rerun::TextDocument::from_markdown(format!(
            "# Calibration\n\nWhite: the cones and rotor axes as estimated, converging on the coloured true ones \
             (errors drawn ×{}). Plots: each state's static-Kalman-filter estimate (yellow) with the filter's own ±3σ band (grey) \
             about it, the true value (green) and the exact least-squares result (blue). The band covers the noise, not the \
             bias of the paper's linearised model: where that bias is larger the true value lies outside it (x2 here); the \
             exact least squares has no such bias. docs/calibration.md explains the model.\n\n{}\
             The whole report as the terminal prints it:\n\n```\n{}```\n",
            params.recording.exaggeration,
            report.markdown(),
            report.text()
        )),
    )?;

    // Styles.
    for (_, p) in &table {
        rec.log_static(
            format!("calibration/state_arcsec/{}", p.key(chain)),
            &rerun::SeriesLines::new()
                .with_colors(STATE_COLORS.map(rgb))
                .with_names(STATE_NAMES)
                .with_widths([2.5, 1.0, 1.0, 1.5, 1.5]),
        )?;
    }
    for a in ERROR_AXES {
        rec.log_static(
            format!("calibration/error_arcsec/{a}"),
            &rerun::SeriesLines::new()
                .with_colors(ERROR_COLORS.map(rgb))
                .with_names(ERROR_NAMES)
                .with_widths([1.5, 4.0, 1.5]),
        )?;
    }

    // The filter over time.
    let times: Vec<f64> = cal.history.iter().map(|s| s.t_s).collect();
    for (i, p) in &table {
        let mut values = Vec::with_capacity(5 * times.len());
        for s in &cal.history {
            let (x, sd) = (s.theta[*i] * ARCSEC_PER_RAD, s.sigma[*i] * ARCSEC_PER_RAD);
            values.extend([
                x,
                x + 3.0 * sd,
                x - 3.0 * sd,
                truth[*i] * ARCSEC_PER_RAD,
                cal.nls.theta[*i] * ARCSEC_PER_RAD,
            ]);
        }
        stream.send_series(
            &format!("calibration/state_arcsec/{}", p.key(chain)),
            &STATE_NAMES.map(String::from),
            &times,
            values,
            5,
        )?;
    }

    // Before / after (the trace is kept at the series rate, thinned over long tests).
    for (a, name) in ERROR_AXES.iter().enumerate() {
        let values: Vec<f64> =
            traces.rows.iter().flat_map(|row| row.iter().map(move |e| e[a] * ARCSEC_PER_RAD)).collect();
        stream.send_series(
            &format!("calibration/error_arcsec/{name}"),
            &ERROR_NAMES.map(String::from),
            &traces.t_s,
            values,
            3,
        )?;
    }

    // Ghost cones and estimated rotor axes, once per second of the test.
    // The ghosts stand in the table's scene, beside its true cones and axes.
    let Some(scene) = recorder.table_scene() else { return Ok(recorder) };
    let x = scene.factors.swing; // the swing cones' drawing factor (drawing_factors)
    let n = chain.axes().len();
    // Once a second, and at most GHOST_FRAMES times over the test (a mesh each: a 100-h test must
    // not write 360 000 of them).
    const GHOST_FRAMES: f64 = 400.0;
    let every_s = (params.duration_s / GHOST_FRAMES).max(1.0);
    let mut next = 0.0;
    let last = cal.history.len().saturating_sub(1);
    for (j, s) in cal.history.iter().enumerate() {
        if s.t_s < next && j != last {
            continue;
        }
        next = (s.t_s / every_s).floor() * every_s + every_s;
        rec.set_duration_secs(TIMELINE, s.t_s);
        let est = set.errors(&s.theta, &params.table.compensation);
        for k in 0..n {
            let (Some(ic), Some(is)) = (set.index(Param::SwingCos(k)), set.index(Param::SwingSin(k))) else {
                continue;
            };
            let g = &chain.axes()[k];
            let half = ring_radius(k, n) * 1.25;
            let alpha = est.axes[k].swing_half_angle_rad;
            // A ghost appears once its estimate stands out of its noise (α ≥ 3σ): in the first
            // seconds the prior's wide estimates drew a tangle of cones.
            if alpha < 3.0 * s.sigma[ic].hypot(s.sigma[is]) && j != last {
                continue;
            }
            let (mesh, rims) = cone(g.axis, g.e1, g.e2, alpha * x, half * 1.02);
            let mount = &scene.paths.mounts[k];
            rec.log(
                format!("{mount}/estimated_cone"),
                &rerun::Mesh3D::new(mesh.0).with_triangle_indices(mesh.1).with_albedo_factor(albedo(GHOST, 35)),
            )?;
            rec.log(
                format!("{mount}/estimated_cone/rims"),
                &rerun::LineStrips3D::new(rims).with_colors([rgba(GHOST, 230)]).with_radii([0.003]),
            )?;
            // The estimated rotor axis, drawn in the (truly tilted) rotor frame: W_trueᵀ W_est a.
            let w_true = rotvec::exp(&(chain.swing_vector(k, &params.table.truth.axes[k], 0.0) * x));
            let w_est = rotvec::exp(&(chain.swing_vector(k, &est.axes[k], 0.0) * x));
            let dir: Vector3<f64> = (w_true.inverse() * w_est) * g.axis;
            rec.log(
                format!("{}/estimated_axis", scene.paths.gimbals[k]),
                &rerun::LineStrips3D::new([[p3(-dir * half * 1.1), p3(dir * half * 1.1)]])
                    .with_colors([rgb(GHOST)])
                    .with_radii([0.006]),
            )?;
            // At the true cone's label's end (the other end carries the η label), across the rim
            // from it.
            let tip = -g.axis * half * 1.05 + g.e1 * (half * (alpha * x).tan() + 0.18);
            // What the data do not determine is said where the number is shown.
            let undetermined =
                |what: &str| report.angles.iter().any(|r| r.key == format!("{}.{what}", g.name) && !r.flag.is_empty());
            let note = match (undetermined("swing_half_angle"), undetermined("swing_phase")) {
                (true, _) => " (not determined by the data)",
                (false, true) => " (φ not determined by the data)",
                _ => "",
            };
            let label = format!(
                "estimate: α = {}, φ = {:.2}°{note}",
                fmt_angle(alpha),
                est.axes[k].swing_phase_rad.to_degrees()
            );
            rec.log(
                format!("{mount}/estimated_cone/label"),
                &rerun::Points3D::new([p3(tip)])
                    .with_labels([label])
                    .with_radii([0.002])
                    .with_colors([super::palette::label(GHOST)]),
            )?;
        }
    }

    Ok(recorder)
}
