//! The only module that talks to Rerun: the entity tree of the gimbal chain, the time series, the
//! documents and the blueprint. It turns [`StepOutput`]s into Rerun calls.
//!
//! Layout of a recording (see docs/recording.md):
//! - `world/vehicle/base/<axis>_mount/<axis>/…/imu`: the chain as `Transform3D`s (errors exaggerated);
//! - `attitude_error_arcsec/{pitch,roll,heading}`: three series each (uncompensated, compensated, closed form);
//! - `gimbal_angle_deg` (one series per axis), `vehicle_attitude_deg` (pitch, roll, heading),
//!   `swing_arcsec/<axis>` (the swing rotation vector's two components);
//! - a replay: the INS's own solution (`ins/body_attitude_deg`, `ins/velocity_enu_mps`, ...); a
//!   strapdown replay nothing of a table, its axes at `world/ins_body` (`rows`, `body_view`);
//!
//! Series that share a plot share an entity (one `Scalars` of several values per row): a third of
//! the time and row-id columns of one entity per line.
//! - `docs/scenario` (markdown), `docs/config` (the resolved TOML), `events` (text log).

use nalgebra::{UnitQuaternion, Vector3};
use rerun::{RecordingStream, RecordingStreamResult, TimeColumn};

use layout::Node;

pub mod allan;
mod blueprint;
mod body_view;
pub mod calibration;
mod cone;
mod drawing;
pub mod export;
pub mod figures;
mod ins_view;
mod layout;
mod live;
pub use live::LiveOutput;
mod frames;
pub mod modulation;
mod palette;
pub mod read;
use frames::Frames;
mod rows;
mod scene;
pub mod selfcal;
pub mod sink;
pub mod tpr;

pub use drawing::drawing_factors;
use drawing::{floored_peak, own_factors};

use crate::ins::pipeline::InsView;
use crate::math::rotvec;
use crate::math::units::ARCSEC_PER_RAD;
use crate::model::gimbal::{Chain, ClassFactors, ErrorRotations, TableErrors};
use crate::scenario::Params;
use crate::sim::{ERROR_AXES, StepOutput};
use export::SharedExporter;
use ins_view::InsLayout;
use rows::Series;
pub use rows::Solution;
use scene::ChainPaths;

/// A recording stream and, with `--export`, the tables its series also go to: what the commands
/// hand from the sinks to the recorders (the rest of the crate names Rerun's types only here).
#[derive(Clone)]
pub struct Stream {
    rec: RecordingStream,
    export: Option<SharedExporter>,
    /// A replay's t = 0 on the IMU file's clock, s (its series then also go on [`FILE_CLOCK_TIMELINE`]).
    file_clock_s: Option<f64>,
}

impl Stream {
    /// A stream into `rec`, its series also into `export`.
    #[must_use]
    pub(crate) fn new(rec: RecordingStream, export: Option<SharedExporter>) -> Self {
        Self { rec, export, file_clock_s: None }
    }

    /// A replay's t = 0 on the IMU file's clock, s (see [`Recorder::set_file_clock`]).
    fn set_file_clock(&mut self, t0_file_s: f64) {
        self.file_clock_s = Some(t0_file_s);
        if let Some(export) = &self.export {
            export.lock().unwrap_or_else(std::sync::PoisonError::into_inner).set_file_clock(t0_file_s);
        }
    }

    /// The time columns of rows at `times` (s on [`TIMELINE`]): that timeline, and a replay's file clock.
    pub(crate) fn time_columns(&self, times: &[f64]) -> Vec<TimeColumn> {
        let mut columns = vec![TimeColumn::new_duration_secs(TIMELINE, times.iter().copied())];
        if let Some(t0) = self.file_clock_s {
            columns.push(TimeColumn::new_duration_secs(FILE_CLOCK_TIMELINE, times.iter().map(|t| t0 + t)));
        }
        columns
    }

    /// The Rerun stream.
    pub(crate) fn rec(&self) -> &RecordingStream {
        &self.rec
    }

    /// Whether its series also go to export tables.
    pub(crate) fn exports(&self) -> bool {
        self.export.is_some()
    }

    /// Sends `width` series of `path` (values row-major, one row per time) to Rerun, and to the
    /// export tables with the series' `names` and the unit `path` states.
    pub(crate) fn send_series(
        &self,
        path: &str,
        names: &[String],
        times: &[f64],
        values: Vec<f64>,
        width: usize,
    ) -> RecordingStreamResult<()> {
        // A log10 plot is a picture of a series exported in its own unit, not a measurement.
        if let Some(export) = self.export.as_ref().filter(|_| !is_log_plot(path)) {
            let unit = export::unit_of(path).unwrap_or("1");
            let mut e = export.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            e.write(path, unit, names, times, &values);
        }
        self.rec.send_columns(
            path,
            self.time_columns(times),
            rerun::Scalars::new(values).columns(std::iter::repeat_n(width, times.len()))?,
        )?;
        Ok(())
    }

    /// Marks events on the plot of `plot_path` where they happen: ▼ markers named `label` at
    /// `times`, at height `y` (the top of the plot's data, or 0 when it is not known yet), in the
    /// child entity `<plot>/<slug>` the plot's view includes. Not exported (not a measurement).
    pub(crate) fn mark_events(
        &self,
        plot_path: &str,
        slug: &str,
        label: &str,
        times: &[f64],
        y: f64,
    ) -> RecordingStreamResult<()> {
        let path = format!("{plot_path}/{slug}");
        self.rec.log_static(
            path.as_str(),
            &rerun::SeriesPoints::new()
                .with_markers([rerun::components::MarkerShape::Down])
                .with_marker_sizes([7.0])
                .with_colors([palette::rgb(palette::colors::EVENT)])
                .with_names([label]),
        )?;
        self.rec.send_columns(
            path,
            self.time_columns(times),
            rerun::Scalars::new(vec![y; times.len()]).columns_of_unit_batches()?,
        )?;
        Ok(())
    }
}

/// Whether `path` is a log10 picture of another series (`…_log10_<unit>`): drawn, not exported.
fn is_log_plot(path: &str) -> bool {
    path.rsplit('/').next().is_some_and(|leaf| leaf.contains("_log10_") || leaf.starts_with("log10_"))
}

/// What a failed Rerun call returns.
pub type RecordError = rerun::RecordingStreamError;

/// Application id of every rinscope recording (the viewer keys layouts by it).
pub const APPLICATION_ID: &str = "rinscope";

/// Name of the timeline every temporal value is logged on, seconds of simulated time (a replay:
/// seconds after its start).
pub const TIMELINE: &str = "sim_time";

/// A replay's second timeline: the same instants on the IMU file's own clock, s.
pub const FILE_CLOCK_TIMELINE: &str = "file_clock";

/// What a replayed log has; it decides what its recording holds (and so its layout).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReplayKind {
    /// A turntable; false: a strapdown IMU, and nothing of a table is recorded (no gimbals, no
    /// table errors, no swing): its axes, the INS's attitude and navigation.
    pub table: bool,
    /// A reference attitude: the INS's attitude errors are plotted against it.
    pub reference: bool,
}

/// Rows buffered per series before one `send_columns` call.
const SERIES_CHUNK_ROWS: usize = 8192;

/// Chunks sent before waiting for the sinks (see [`Recorder::throttle`]); ~2-4 MB of data.
const MAX_CHUNKS_IN_FLIGHT: usize = 24;

/// Nominal quaternion (w, i, j, k) to Rerun's (x, y, z, w): the one place this reordering happens.
#[must_use]
pub fn to_rerun_quaternion(q: &UnitQuaternion<f64>) -> rerun::Quaternion {
    rerun::Quaternion::from_xyzw([q.i as f32, q.j as f32, q.k as f32, q.w as f32])
}

/// Streams a run into a Rerun recording.
pub struct Recorder {
    rec: RecordingStream,
    /// The same stream, with the export tables.
    stream: Stream,
    chain: Chain,
    /// The true errors (the swing plots, the labels).
    truth: TableErrors,
    /// The true errors exaggerated for drawing.
    drawing: ErrorRotations,
    /// The drawing factor of each error class ([`drawing_factors`]).
    factors: ClassFactors,
    paths: ChainPaths,
    axis_names: Vec<String>,
    series: Vec<Series>,
    series_t: Vec<f64>,
    scene_t: Vec<f64>,
    scene_vehicle: Vec<rerun::Quaternion>,
    scene_gimbals: Vec<Vec<rerun::Quaternion>>,
    /// Pure coning: the body axis on its magnified cone, beside the table.
    cone: Option<cone::ConeGizmo>,
    /// Chunks sent since the sinks last caught up.
    chunks_in_flight: usize,
    /// Live mode (geometry on the timeline instead of static), and what this recorder feeds.
    live: Option<LiveOutput>,
    /// A live session's parameters in force (its final layout is framed on them).
    live_params: Option<Box<Params>>,
    /// The last frame sent of each moving transform (vehicle, then gimbals): a transform that has
    /// not moved since is not sent again (a vehicle at rest, a gimbal the scheme holds still).
    last_motion: Vec<Option<rerun::Quaternion>>,
    /// A replayed log (None: a simulation): what it has decides the series and the scene.
    replay: Option<ReplayKind>,
    /// With an IMU in the loop.
    ins: Option<InsLayout>,
    /// A strapdown IMU: its (body) axes at the INS's attitude, instead of a table.
    body: Option<body_view::BodyScene>,
    /// Unit of the attitude-error plots.
    error_unit: crate::math::units::AngleUnit,
    /// Symmetric half-ranges of the error plots once known (table per axis, in `error_unit`; INS
    /// per axis, arcsec).
    ranges: Option<PlotRanges>,
    /// The command's own panels, kept for when the layout is sent again.
    custom: Option<CustomLayout>,
    /// Each series' extent (the plots framed on their data).
    frames: Frames,
}

/// The error plots' symmetric ranges, from a run's peaks (see [`crate::math::units::nice_half_range`]).
#[derive(Debug, Clone, Copy)]
pub struct PlotRanges {
    /// Largest uncompensated error per axis (pitch, roll, heading), rad.
    pub table_peak_rad: [f64; 3],
    /// Largest INS error per axis over every algorithm, rad.
    pub ins_peak_rad: Option<[f64; 3]>,
    /// Largest closed form − exact per axis, rad.
    pub closed_form_peak_rad: [f64; 3],
}

/// The closed form − exact plot's entity.
pub const CLOSED_FORM_PATH: &str = "closed_form_minus_exact_arcsec";

/// The attitude-error entity of `axis` in `unit` (`attitude_error_deg/pitch`).
#[must_use]
pub fn error_path(unit: crate::math::units::AngleUnit, axis: &str) -> String {
    format!("attitude_error_{}/{axis}", unit.suffix())
}

/// What a command adds to the standard layout.
#[derive(Clone)]
pub(crate) struct CustomLayout {
    /// The right column (replaces the error plots).
    pub right: Node,
    /// Document tabs shown before the scenario's.
    pub docs: Vec<Node>,
}

impl Recorder {
    /// Logs everything static (documents, styles, geometry, blueprint) and prepares the buffers.
    pub fn new(stream: Stream, params: &Params) -> RecordingStreamResult<Self> {
        Self::build(stream, params, None, None)
    }

    /// A recorder whose layout has `custom.right` as its right column and `custom.docs` as extra
    /// document tabs (commands that add their own panels to the table's 3D scene).
    pub(crate) fn with_layout(stream: Stream, params: &Params, custom: CustomLayout) -> RecordingStreamResult<Self> {
        Self::build(stream, params, None, Some(custom))
    }

    fn build(
        stream: Stream,
        params: &Params,
        live: Option<LiveOutput>,
        custom: Option<CustomLayout>,
    ) -> RecordingStreamResult<Self> {
        Self::build_with(stream, params, live, None, custom)
    }

    fn build_with(
        stream: Stream,
        params: &Params,
        live: Option<LiveOutput>,
        replay: Option<ReplayKind>,
        custom: Option<CustomLayout>,
    ) -> RecordingStreamResult<Self> {
        let rec = stream.rec.clone();
        let chain = params.table.chain.clone();
        let factors = drawing_factors(&params.table.truth, params.recording.exaggeration);
        let drawing = chain.error_rotations(&params.table.truth.exaggerated(&factors));
        let axis_names: Vec<String> = params.table.chain.axes().iter().map(|a| a.name.clone()).collect();
        let paths = ChainPaths::new(&axis_names);
        let unit = params.recording.error_unit;
        let mut series = rows::table_series(&chain, replay, unit);
        let ins = rows::ins_layout(params, replay, &mut series);
        // A strapdown IMU: its axes are drawn as the body, nothing of the stand-in table.
        let body = replay.filter(|k| !k.table).map(|k| body_view::BodyScene::new(k.reference));
        let n = if body.is_some() { 0 } else { axis_names.len() };
        let mut me = Self {
            rec,
            stream,
            chain,
            truth: params.table.truth.clone(),
            drawing,
            factors,
            paths,
            axis_names,
            series,
            series_t: Vec::new(),
            scene_t: Vec::new(),
            scene_vehicle: Vec::new(),
            scene_gimbals: vec![Vec::new(); n],
            cone: None,
            chunks_in_flight: 0,
            live,
            live_params: live.map(|_| Box::new(params.clone())),
            last_motion: vec![None; 1 + n],
            replay,
            ins,
            body,
            error_unit: unit,
            ranges: None,
            custom: custom.clone(),
            frames: Frames::default(),
        };
        me.log_once(params)?;
        me.log_ins_once()?;
        if let Some(c) = params.table.vehicle.pure_coning().filter(|c| c.half_angle_rad > 0.0) {
            me.cone = Some(cone::ConeGizmo::new(&me.rec, c.half_angle_rad, me.geometry_at(0.0))?);
        }
        me.log_error_geometry(params, me.geometry_at(0.0))?;
        me.send_blueprint(params, custom)?;
        let started = if live.is_some() {
            // A live session has no length of its own: it runs until it is stopped.
            format!(
                "live session started: {} at {} Hz, seed {} (it runs until stopped)",
                params.meta.name, params.step_hz, params.meta.seed
            )
        } else {
            format!(
                "run started: {} ({} s at {} Hz, seed {})",
                params.meta.name, params.duration_s, params.step_hz, params.meta.seed
            )
        };
        me.event(0.0, &started, "INFO")?;
        Ok(me)
    }

    /// A recorder for a replayed log of `kind`: through a table, the same scene and plots as a run,
    /// the demodulations named for what they are (the nominal and the compensated table, against
    /// the log's reference); a strapdown IMU, its axes at the INS's attitude and the INS's plots
    /// only. Both add the INS's own solution (attitude, velocity, position).
    pub fn new_replay(stream: Stream, params: &Params, kind: ReplayKind) -> RecordingStreamResult<Self> {
        Self::build_with(stream, params, None, Some(kind), None)
    }

    /// A replay's t = 0 on the IMU file's own clock, s: the series also go on the timeline
    /// [`FILE_CLOCK_TIMELINE`], and the export tables get a `t_file_s` column. Call it before the
    /// first row.
    pub fn set_file_clock(&mut self, t0_file_s: f64) -> RecordingStreamResult<()> {
        self.stream.set_file_clock(t0_file_s);
        self.event(0.0, &format!("t = 0 is {t0_file_s:.6} s on the IMU file's clock (the timeline `{FILE_CLOCK_TIMELINE}` shows the file's times; the export has them as t_file_s)"), "INFO")
    }

    fn geometry_at(&self, t_s: f64) -> Option<f64> {
        self.live.map(|_| t_s)
    }

    /// Sends the layout again for `params` (a replay knows its length only at the end).
    pub fn resend_layout(&self, params: &Params) -> RecordingStreamResult<()> {
        self.send_blueprint(params, self.custom.clone())
    }

    /// Frames the error plots on the run's peaks (symmetric, labelled ticks) and sends the layout
    /// again: noise of 1e-5″ on a compensated line does not fill a plot and look like a drift.
    pub fn frame_plots(&mut self, params: &Params, ranges: PlotRanges) -> RecordingStreamResult<()> {
        // Every row out first: the plots framed on their data take the whole extent.
        self.flush_series()?;
        self.ranges = Some(ranges);
        self.mark_moves(params, &ranges)?;
        self.send_blueprint(params, self.custom.clone())
    }

    /// The indexed scheme's moves marked on the error plots, near the top of each framed range
    /// (a long run's hundreds of moves would be a comb: then none).
    fn mark_moves(&self, params: &Params, ranges: &PlotRanges) -> RecordingStreamResult<()> {
        const MOST: usize = 200;
        let starts = params.table.scheme.move_starts_s(params.duration_s, MOST + 1);
        if starts.is_empty() || starts.len() > MOST {
            return Ok(());
        }
        let top = |peaks: [f64; 3], a: usize, per_rad: f64| {
            let p = floored_peak(peaks, a) * per_rad;
            if p > 0.0 { 1.1 * crate::math::units::nice_half_range(p) } else { 0.0 }
        };
        for (a, axis) in ERROR_AXES.iter().enumerate() {
            let y = top(ranges.table_peak_rad, a, self.error_unit.per_rad());
            if self.has_series(&error_path(self.error_unit, axis)) {
                self.stream.mark_events(&error_path(self.error_unit, axis), "moves", "scheme moves", &starts, y)?;
            }
            if let Some(ins) = ranges.ins_peak_rad.filter(|_| self.ins.as_ref().is_some_and(|l| l.errors)) {
                self.stream.mark_events(
                    &format!("ins/attitude_error_arcsec/{axis}"),
                    "moves",
                    "scheme moves",
                    &starts,
                    top(ins, a, ARCSEC_PER_RAD),
                )?;
            }
        }
        Ok(())
    }

    /// The error plots' unit.
    #[must_use]
    pub fn error_unit(&self) -> crate::math::units::AngleUnit {
        self.error_unit
    }

    /// Sends every buffered row now (live mode: low latency over large chunks).
    pub fn flush_now(&mut self) -> RecordingStreamResult<()> {
        self.flush_signal()?;
        self.flush_series()?;
        self.flush_scene()
    }

    /// The underlying stream (for flushing and sinks).
    #[must_use]
    pub fn stream(&self) -> &Stream {
        &self.stream
    }

    /// The line names of the series at `path` (its legend).
    pub(crate) fn series_names(&self, path: &str) -> Vec<String> {
        self.series.iter().find(|s| s.path == path).map(|s| s.names.clone()).unwrap_or_default()
    }

    /// Buffers one time-series row; sends a chunk when the buffer is full.
    pub fn push_series(&mut self, out: &StepOutput) -> RecordingStreamResult<()> {
        self.push_row(out, None)
    }

    /// Buffers one row: the turntable-only variants and, with an IMU in the loop, the INS's view.
    pub fn push_row(&mut self, out: &StepOutput, ins: Option<&InsView>) -> RecordingStreamResult<()> {
        self.push_row_with(out, ins, None)
    }

    /// Buffers one row of a replay: the table's step (if it has a table), the INS's view and its
    /// own solution.
    pub fn push_replay_row(
        &mut self,
        out: &StepOutput,
        ins: &InsView,
        solution: &Solution,
    ) -> RecordingStreamResult<()> {
        self.push_row_with(out, Some(ins), Some(solution))
    }

    fn push_row_with(
        &mut self,
        out: &StepOutput,
        ins: Option<&InsView>,
        solution: Option<&Solution>,
    ) -> RecordingStreamResult<()> {
        self.push_values(out, ins, solution);
        self.series_t.push(out.t_s);
        if self.series_t.len() >= SERIES_CHUNK_ROWS {
            self.flush_series()?;
        }
        Ok(())
    }

    /// Buffers one scene frame; sends a chunk when the buffer is full.
    pub fn push_scene(&mut self, out: &StepOutput) -> RecordingStreamResult<()> {
        self.push_scene_row(out, None)
    }

    /// Buffers one scene frame with, if any, the INS trace (true and computed IMU axes, the
    /// computed one's error exaggerated).
    pub fn push_scene_row(&mut self, out: &StepOutput, ins: Option<&InsView>) -> RecordingStreamResult<()> {
        self.scene_t.push(out.t_s);
        match self.body.as_mut() {
            Some(body) => body.push(ins),
            None => {
                let links = self.chain.link_rotations(&self.drawing, &out.gimbal_rad);
                self.scene_vehicle.push(to_rerun_quaternion(out.n_from_b.quaternion()));
                for (k, col) in self.scene_gimbals.iter_mut().enumerate() {
                    col.push(to_rerun_quaternion(&links.gimbal[k]));
                }
            }
        }
        if let Some(c) = self.cone.as_mut() {
            c.push(&out.n_from_b);
        }
        if let Some(layout) = self.ins.as_mut().filter(|l| l.trace || l.dial_shown()) {
            // Without an INS view (or without its truth) the trace stands still at the identity.
            if layout.trace {
                let (t, c) = ins
                    .and_then(|v| Some((*v.imu_true?.quaternion(), *v.imu_ins.quaternion())))
                    .unwrap_or((UnitQuaternion::identity(), UnitQuaternion::identity()));
                let err = rotvec::log(&(c * t.inverse())) * layout.exaggeration;
                let ins_q = rotvec::exp(&err) * t;
                // The true axes, then the computed ones, as arrows in the trace's (unturned) frame.
                for q in [t, ins_q] {
                    for axis in [Vector3::x(), Vector3::y(), Vector3::z()] {
                        let v = q * (axis * ins_view::TRACE_AXIS_LENGTH);
                        layout.trace_axes.push([v.x as f32, v.y as f32, v.z as f32]);
                    }
                }
            }
            // The needles turn clockwise by the size of each algorithm's attitude error (whichever
            // axis it is on: heading for a cone about z, pitch for Li et al. 2014's wobble), ×N.
            let due = layout.dial_shown() && out.t_s >= layout.dial_next_t;
            if due {
                layout.dial_t.push(out.t_s);
                layout.dial_next_t = out.t_s + 1.0 / ins_view::DIAL_HZ - 1e-9;
                for (k, name) in layout.algorithms.iter().enumerate() {
                    let size = ins
                        .and_then(|v| v.errors.get(k))
                        .filter(|_| !layout.hidden.contains(name))
                        .map_or(0.0, |e| e.as_array().iter().map(|x| x * x).sum::<f64>().sqrt());
                    layout.dial.push(ins_view::needle(-size * layout.exaggeration));
                }
            }
        }
        if self.scene_t.len() >= SERIES_CHUNK_ROWS {
            self.flush_scene()?;
        }
        Ok(())
    }

    /// Back-pressure: Rerun's queue from `send_columns` to the sinks is unbounded, so a simulation
    /// faster than the file writer (or a slow viewer connection) would grow memory with the run's
    /// length. Every few dozen chunks we wait for the sinks to catch up: memory stays flat.
    fn throttle(&mut self, chunks: usize) {
        self.chunks_in_flight += chunks;
        if self.chunks_in_flight >= MAX_CHUNKS_IN_FLIGHT {
            // A sink that cannot flush (a viewer gone away) must not stop the run; data keeps flowing
            // to the other sinks.
            let _ = self.rec.flush_with_timeout(std::time::Duration::from_secs(2));
            self.chunks_in_flight = 0;
        }
    }

    /// Sends the buffered time-series rows.
    pub fn flush_series(&mut self) -> RecordingStreamResult<()> {
        self.flush_series_with(None)
    }

    fn flush_series_with(&mut self, hold: Option<std::time::Duration>) -> RecordingStreamResult<()> {
        self.flush_dial()?;
        if self.series_t.is_empty() {
            return Ok(());
        }
        let hold = hold.filter(|_| !self.stream.exports());
        let times = std::mem::take(&mut self.series_t);
        let now = std::time::Instant::now();
        let mut sent = 0;
        for s in &mut self.series {
            let values = std::mem::take(&mut s.values);
            let width = s.width();
            debug_assert_eq!(values.len(), width * times.len());
            self.frames.observe(&s.path, &values);
            let last_row = values.len().checked_sub(width).map(|i| values[i..].to_vec()).unwrap_or_default();
            let (t, v) = match (hold, &s.last_sent) {
                (Some(hold), Some((row, at))) if values.chunks(width).all(|r| rows::same_row(r, row)) => {
                    if now.duration_since(*at) < hold {
                        s.held_until_s = times.last().copied();
                        continue;
                    }
                    (vec![times[times.len() - 1]], last_row.clone())
                }
                // After rows held back, the newest of them first: the line stays flat up to it
                // instead of sloping from the last row sent to the first new one.
                (_, Some((row, _))) if s.held_until_s.is_some() => {
                    let held = s.held_until_s.unwrap_or_default();
                    (
                        std::iter::once(held).chain(times.iter().copied()).collect(),
                        row.iter().copied().chain(values).collect(),
                    )
                }
                _ => (times.clone(), values),
            };
            s.held_until_s = None;
            self.stream.send_series(&s.path, &s.names, &t, v, width)?;
            s.last_sent = Some((last_row, now));
            sent += 1;
        }
        self.throttle(sent);
        match (self.live, times.last()) {
            (Some(out), Some(&t)) if out.watched() => self.hold_live_frames(t),
            _ => Ok(()),
        }
    }

    /// Sends the buffered scene frames. A transform that has not moved since the frame last sent
    /// of it is not sent again (a vehicle at rest, a gimbal the scheme holds still).
    pub fn flush_scene(&mut self) -> RecordingStreamResult<()> {
        if self.scene_t.is_empty() {
            return Ok(());
        }
        let times = std::mem::take(&mut self.scene_t);
        let mut sent = 0;
        if let Some(c) = self.cone.as_mut() {
            c.flush(&self.stream, &times)?;
            sent += 1;
        }
        if let Some(body) = self.body.as_mut() {
            body.flush(&self.stream, &times)?;
            sent += 1;
        }
        let motion = std::iter::once((self.paths.vehicle.as_str(), std::mem::take(&mut self.scene_vehicle))).chain(
            self.paths.gimbals.iter().map(String::as_str).zip(self.scene_gimbals.iter_mut().map(std::mem::take)),
        );
        for ((path, q), last) in motion.zip(self.last_motion.iter_mut()) {
            let Some(newest) = q.last().copied() else { continue };
            if q.iter().all(|x| Some(*x) == *last) {
                continue;
            }
            *last = Some(newest);
            self.rec.send_columns(
                path,
                self.stream.time_columns(&times),
                rerun::Transform3D::update_fields().with_many_quaternion(q).columns_of_unit_batches()?,
            )?;
            sent += 1;
        }
        if let Some(layout) = self.ins.as_mut() {
            let trace = std::mem::take(&mut layout.trace_axes);
            if !trace.is_empty() {
                debug_assert_eq!(trace.len(), 6 * times.len());
                self.rec.send_columns(
                    ins_view::TRACE_AXES_PATH,
                    self.stream.time_columns(&times),
                    rerun::Arrows3D::update_fields()
                        .with_vectors(trace)
                        .columns(std::iter::repeat_n(6, times.len()))?,
                )?;
                sent += 1;
            }
        }
        self.throttle(sent);
        Ok(())
    }

    /// Sends the drift dial's buffered frames (with the plots: the needles turn with the errors).
    fn flush_dial(&mut self) -> RecordingStreamResult<()> {
        let Some(layout) = self.ins.as_mut() else { return Ok(()) };
        let dial_t = std::mem::take(&mut layout.dial_t);
        let needles = std::mem::take(&mut layout.dial);
        if dial_t.is_empty() {
            return Ok(());
        }
        let k = layout.algorithms.len();
        self.rec.send_columns(
            ins_view::DIAL_NEEDLES_PATH,
            self.stream.time_columns(&dial_t),
            rerun::Arrows3D::update_fields().with_vectors(needles).columns(std::iter::repeat_n(k, dial_t.len()))?,
        )?;
        self.throttle(1);
        Ok(())
    }

    /// A text-log entry at simulated time `t_s`.
    pub fn event(&self, t_s: f64, text: &str, level: &str) -> RecordingStreamResult<()> {
        self.rec.set_duration_secs(TIMELINE, t_s);
        if let Some(t0) = self.stream.file_clock_s {
            self.rec.set_duration_secs(FILE_CLOCK_TIMELINE, t0 + t_s);
        }
        self.rec.log("events", &rerun::TextLog::new(text).with_level(level))
    }

    /// Sends everything still buffered; a saved live session's layout again, every plot framed on
    /// its data (as a run's).
    pub fn finish(&mut self) -> RecordingStreamResult<()> {
        self.flush_now()?;
        match (&self.live, &self.live_params) {
            (Some(LiveOutput::File), Some(p)) => self.send_blueprint(&p.clone(), self.custom.clone()),
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests;
