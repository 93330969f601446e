//! Layer 7, the only module that talks to Rerun. A [`Recorder`] is a composition of views, each
//! owning its entities: the table's scene (`scene.rs`, `world/vehicle/…`), a strapdown IMU's body
//! (`body_view.rs`), pure coning's cone (`cone.rs`), the INS's trace, dial and gyro window
//! (`ins_view.rs`), every time series (`plots/`: which series exist, their rows, styles and
//! extents); it sends the documents (`documents.rs`) and the layout (`layout.rs`, built of the
//! blueprint primitives in `blueprint.rs`) itself. Commands with their own recordings (allan,
//! calibration, selfcal, tpr, modulation) use the same primitives.
//!
//! Layout of a recording (see docs/recording.md):
//! - `world/vehicle/base/<axis>_mount/<axis>/…/imu`: the chain as `Transform3D`s (errors exaggerated);
//! - `attitude_error_arcsec/{pitch,roll,heading}`: three series each (uncompensated, compensated, closed form);
//! - `gimbal_angle_deg` (one series per axis), `vehicle_attitude_deg` (pitch, roll, heading),
//!   `swing_arcsec/<axis>` (the swing rotation vector's two components);
//! - a replay: the INS's own solution (`ins/body_attitude_deg`, `ins/velocity_enu_mps`, ...); a
//!   strapdown replay nothing of a table, its axes at `world/ins_body` (`plots/series.rs`, `body_view.rs`);
//!
//! Series that share a plot share an entity (one `Scalars` of several values per row): a third of
//! the time and row-id columns of one entity per line.
//! - `docs/scenario` (markdown), `docs/config` (the resolved TOML), `events` (text log).

use nalgebra::UnitQuaternion;
use rerun::{RecordingStream, RecordingStreamResult, TimeColumn};

use blueprint::Node;

pub mod allan;
mod blueprint;
mod body_view;
pub mod budget;
pub mod calibration;
mod cone;
mod documents;
mod drawing;
pub mod export;
pub mod figures;
mod ins_view;
mod layout;
mod live;
pub mod modulation;
mod palette;
pub(crate) mod plots;
pub mod read;
mod scene;
pub mod schemes;
pub mod selfcal;
pub mod sink;
pub mod tpr;

pub use drawing::drawing_factors;
use drawing::{floored_peak, own_factors};
pub use live::LiveOutput;
pub use plots::Solution;

use crate::ins::pipeline::InsView;
use crate::math::units::ARCSEC_PER_RAD;
use crate::scenario::Params;
use crate::sim::{ERROR_AXES, StepOutput};
use body_view::BodyScene;
use cone::ConeGizmo;
use export::SharedExporter;
use ins_view::InsScene;
use plots::Plots;
use scene::TableScene;

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
        self.export_series(path, names, times, &values);
        self.plot_series(path, times, values, width)
    }

    /// Writes rows of the series `path` (its lines `names`, values row-major, one row per time) to
    /// the export tables, in the unit `path` states; nothing without `--export`.
    pub(crate) fn export_series(&self, path: &str, names: &[String], times: &[f64], values: &[f64]) {
        // A log10 plot is a picture of a series exported in its own unit, not a measurement.
        if let Some(export) = self.export.as_ref().filter(|_| !is_log_plot(path)) {
            let unit = export::unit_of(path).unwrap_or("1");
            let mut e = export.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            e.write(path, unit, names, times, values);
        }
    }

    /// Sends rows of `width` series of `path` (values row-major, one row per time) to Rerun only.
    pub(crate) fn plot_series(
        &self,
        path: &str,
        times: &[f64],
        values: Vec<f64>,
        width: usize,
    ) -> RecordingStreamResult<()> {
        self.rec.send_columns(
            path,
            self.time_columns(times),
            rerun::Scalars::new(values).columns(std::iter::repeat_n(width, times.len()))?,
        )?;
        Ok(())
    }

    /// Logs `arch` at `path`: static in a plain run (`at = None`), at simulated time `at` in live mode,
    /// where a reload can change it and the saved session must show the history.
    pub(crate) fn put(
        &self,
        at: Option<f64>,
        path: impl Into<rerun::EntityPath>,
        arch: &dyn rerun::AsComponents,
    ) -> RecordingStreamResult<()> {
        match at {
            None => self.rec.log_static(path, arch),
            Some(t) => {
                self.rec.set_duration_secs(TIMELINE, t);
                self.rec.log(path, arch)
            }
        }
    }

    /// Removes what `put` drew at `path` (live mode: an error set back to zero).
    pub(crate) fn clear(&self, at: Option<f64>, path: impl Into<rerun::EntityPath>) -> RecordingStreamResult<()> {
        match at {
            None => Ok(()),
            Some(t) => {
                self.rec.set_duration_secs(TIMELINE, t);
                self.rec.log(path, &rerun::Clear::recursive())
            }
        }
    }

    /// Text labels at points (Points3D with tiny dots): labels sit exactly where they belong.
    pub(crate) fn label(&self, at: Option<f64>, path: &str, items: &[([f32; 3], &str)]) -> RecordingStreamResult<()> {
        self.put(
            at,
            path,
            &rerun::Points3D::new(items.iter().map(|(p, _)| *p))
                .with_labels(items.iter().map(|(_, t)| *t))
                .with_radii([0.002])
                .with_colors([palette::label([230, 230, 230])]),
        )
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

/// Streams a run into a Rerun recording: a composition of views, each owning its entities —
/// the table's scene ([`TableScene`]) or a strapdown IMU's body ([`BodyScene`]), pure coning's
/// cone ([`ConeGizmo`]), the INS's trace, dial and gyro window ([`InsScene`]), every time series
/// ([`Plots`]) — plus the documents and the layout, which it sends itself.
pub struct Recorder {
    /// The stream, with the export tables.
    stream: Stream,
    /// The table (None for a strapdown IMU).
    table: Option<TableScene>,
    /// A strapdown IMU: its (body) axes at the INS's attitude, instead of a table.
    body: Option<BodyScene>,
    /// Pure coning: the body axis on its magnified cone, beside the table.
    cone: Option<ConeGizmo>,
    /// With an IMU in the loop.
    ins: Option<InsScene>,
    plots: Plots,
    /// The buffered scene frames' times, s.
    scene_t: Vec<f64>,
    /// Chunks sent since the sinks last caught up, and in all.
    chunks_in_flight: usize,
    chunks_sent: u64,
    /// Live mode (geometry on the timeline instead of static), and what this recorder feeds.
    live: Option<LiveOutput>,
    /// A live session's parameters in force (its final layout is framed on them).
    live_params: Option<Box<Params>>,
    /// A replayed log (None: a simulation): what it has decides the series and the scene.
    replay: Option<ReplayKind>,
    /// Symmetric half-ranges of the error plots once known (table per axis, in the plots' error
    /// unit; INS per axis, arcsec).
    ranges: Option<PlotRanges>,
    /// The command's own panels, kept for when the layout is sent again.
    custom: Option<CustomLayout>,
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
        Self::build(stream, params, None, None, None)
    }

    /// A recorder whose layout has `custom.right` as its right column and `custom.docs` as extra
    /// document tabs (commands that add their own panels to the table's 3D scene).
    pub(crate) fn with_layout(stream: Stream, params: &Params, custom: CustomLayout) -> RecordingStreamResult<Self> {
        Self::build(stream, params, None, None, Some(custom))
    }

    /// A recorder for a replayed log of `kind`: through a table, the same scene and plots as a run,
    /// the demodulations named for what they are (the nominal and the compensated table, against
    /// the log's reference); a strapdown IMU, its axes at the INS's attitude and the INS's plots
    /// only. Both add the INS's own solution (attitude, velocity, position).
    pub fn new_replay(stream: Stream, params: &Params, kind: ReplayKind) -> RecordingStreamResult<Self> {
        Self::build(stream, params, None, Some(kind), None)
    }

    fn build(
        stream: Stream,
        params: &Params,
        live: Option<LiveOutput>,
        replay: Option<ReplayKind>,
        custom: Option<CustomLayout>,
    ) -> RecordingStreamResult<Self> {
        let plots = Plots::new(params, replay, stream.exports());
        let ins = plots.ins.as_ref().and_then(|series| InsScene::new(params, replay, series));
        // A strapdown IMU: its axes are drawn as the body, nothing of the stand-in table.
        let body = replay.filter(|k| !k.table).map(|k| BodyScene::new(k.reference));
        let mut me = Self {
            table: body.is_none().then(|| TableScene::new(params)),
            body,
            cone: None,
            ins,
            plots,
            scene_t: Vec::new(),
            chunks_in_flight: 0,
            chunks_sent: 0,
            live,
            live_params: live.map(|_| Box::new(params.clone())),
            replay,
            ranges: None,
            custom: custom.clone(),
            stream,
        };
        me.log_once(params)?;
        let at = me.geometry_at(0.0);
        if let Some(c) = params.table.vehicle.pure_coning().filter(|c| c.half_angle_rad > 0.0) {
            me.cone = Some(ConeGizmo::new(me.stream.rec(), c.half_angle_rad, at)?);
        }
        me.log_errors(params, at, true)?;
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

    /// Logs what never changes during a run: the recording's name and properties, the plots'
    /// styles, the world's axes and compass, and each view's fixed parts.
    fn log_once(&self, p: &Params) -> RecordingStreamResult<()> {
        let rec = self.stream.rec();
        rec.send_recording_name(format!("rinscope: {}", p.meta.name))?;
        rec.send_property(
            "rinscope",
            &rerun::AnyValues::default()
                .with_component::<rerun::components::Text>("scenario", [p.meta.name.clone()])
                .with_component::<rerun::components::Text>("seed", [p.meta.seed.to_string()])
                .with_component::<rerun::components::Text>("version", [env!("CARGO_PKG_VERSION").to_owned()]),
        )?;
        self.plots.log_styles(&self.stream)?;
        rec.log_static("world", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
        // East and North on the floor: under the table's deck, or just under a strapdown IMU's case.
        let floor = if self.body.is_some() { -0.4 } else { -1.4 };
        rec.log_static(
            "world/compass",
            &rerun::Arrows3D::from_vectors([[1.6, 0.0, 0.0], [0.0, 1.6, 0.0]])
                .with_origins([[0.0, 0.0, floor]; 2])
                .with_colors([palette::rgba([120, 120, 120], 160); 2])
                .with_radii([0.006]),
        )?;
        self.stream.label(None, "world/compass/labels", &[([1.7, 0.0, floor], "E"), ([0.0, 1.7, floor], "N")])?;
        if let Some(body) = &self.body {
            body.log_static(&self.stream)?;
        }
        if let Some(table) = &self.table {
            table.log_static(&self.stream)?;
        }
        if let Some(ins) = &self.ins {
            ins.log_static(&self.stream)?;
        }
        Ok(())
    }

    /// Everything that depends on the error values (in live mode at `at` on the timeline): the
    /// documents and, with `table`, the table's error geometry.
    fn log_errors(&self, p: &Params, at: Option<f64>, table: bool) -> RecordingStreamResult<()> {
        documents::log_documents(&self.stream, p, self.replay, at)?;
        match &self.table {
            Some(scene) if table => scene.log_errors(&self.stream, p, at),
            _ => Ok(()),
        }
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

    /// A replay's length known from its file before its first row: the plots' buckets sized for
    /// it (`params`' series rate), as a run's are for its duration.
    pub fn set_run_length(&mut self, params: &Params) {
        self.plots.set_series_hz(params.recording.series_hz);
    }

    /// Sends the layout again for `params` (a replay knows its exact length only at the end).
    pub fn resend_layout(&self, params: &Params) -> RecordingStreamResult<()> {
        self.send_blueprint(params, self.custom.clone())
    }

    /// Fits the error plots to the run's peaks (symmetric, labelled ticks) and sends the layout
    /// again: noise of 1e-5″ on a compensated line does not fill a plot and look like a drift.
    pub fn fit_plots(&mut self, params: &Params, ranges: PlotRanges) -> RecordingStreamResult<()> {
        // Every row out first: the plots fitted to their data take the whole extent.
        self.plots.close_buckets();
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
        let unit = self.error_unit();
        for (a, axis) in ERROR_AXES.iter().enumerate() {
            let y = top(ranges.table_peak_rad, a, unit.per_rad());
            if self.plots.has(&error_path(unit, axis)) {
                self.stream.mark_events(&error_path(unit, axis), "moves", "scheme moves", &starts, y)?;
            }
            if let Some(ins) = ranges.ins_peak_rad.filter(|_| self.ins_errors()) {
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

    /// Whether the INS's attitude errors are plotted.
    fn ins_errors(&self) -> bool {
        self.plots.ins.as_ref().is_some_and(|l| l.errors)
    }

    /// The error plots' unit.
    #[must_use]
    pub fn error_unit(&self) -> crate::math::units::AngleUnit {
        self.plots.error_unit()
    }

    /// Sends every buffered row now (live mode: low latency over large chunks; the plots' open
    /// buckets too: a live session's rows are a bucket each, and waiting for the next would delay
    /// every row by one).
    pub fn flush_now(&mut self) -> RecordingStreamResult<()> {
        self.plots.close_buckets();
        self.flush_signal()?;
        self.flush_series()?;
        self.flush_scene()
    }

    /// The table's view (None for a strapdown IMU): a command's own drawings beside its parts.
    pub(crate) fn table_scene(&self) -> Option<&TableScene> {
        self.table.as_ref()
    }

    /// Sends the buffered gyro samples of the signal window.
    pub(crate) fn flush_signal(&mut self) -> RecordingStreamResult<()> {
        match self.ins.as_mut() {
            Some(ins) => ins.flush_signal(&self.stream),
            None => Ok(()),
        }
    }

    /// The underlying stream (for flushing and sinks).
    #[must_use]
    pub fn stream(&self) -> &Stream {
        &self.stream
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
        self.plots.push(out, ins, solution);
        if self.plots.buffered() >= SERIES_CHUNK_ROWS {
            self.flush_series()?;
        }
        Ok(())
    }

    /// Buffers one raw and filtered gyro sample (the signal window at the IMU rate).
    pub fn push_signal(&mut self, s: &crate::ins::core::SampleOut) -> RecordingStreamResult<()> {
        match self.ins.as_mut() {
            Some(ins) => ins.push_signal(s, &self.stream),
            None => Ok(()),
        }
    }

    /// Buffers one scene frame; sends a chunk when the buffer is full.
    pub fn push_scene(&mut self, out: &StepOutput) -> RecordingStreamResult<()> {
        self.push_scene_row(out, None)
    }

    /// Buffers one scene frame with, if any, the INS trace (true and computed IMU axes, the
    /// computed one's error exaggerated).
    pub fn push_scene_row(&mut self, out: &StepOutput, ins: Option<&InsView>) -> RecordingStreamResult<()> {
        self.scene_t.push(out.t_s);
        if let Some(body) = self.body.as_mut() {
            body.push(ins);
        }
        if let Some(table) = self.table.as_mut() {
            table.push(out);
        }
        if let Some(c) = self.cone.as_mut() {
            c.push(&out.n_from_b);
        }
        if let Some(view) = self.ins.as_mut().filter(|v| v.in_scene()) {
            view.push_scene(out.t_s, ins);
            if view.dial_buffered() >= SERIES_CHUNK_ROWS {
                let sent = view.flush_dial(&self.stream)?;
                self.throttle(sent);
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
        self.chunks_sent += chunks as u64;
        if self.chunks_in_flight >= MAX_CHUNKS_IN_FLIGHT {
            // A sink that cannot flush (a viewer gone away) must not stop the run; data keeps flowing
            // to the other sinks.
            let _ = self.stream.rec().flush_with_timeout(std::time::Duration::from_secs(2));
            self.chunks_in_flight = 0;
        }
    }

    /// Sends the buffered time-series rows.
    pub fn flush_series(&mut self) -> RecordingStreamResult<()> {
        self.flush_series_with(None)
    }

    fn flush_series_with(&mut self, hold: Option<std::time::Duration>) -> RecordingStreamResult<()> {
        // The dial's needles turn with the errors: they go out with the plots (and when their own
        // buffer is full, `push_scene_row`: a long run's series chunks are far apart).
        if let Some(ins) = self.ins.as_mut() {
            let sent = ins.flush_dial(&self.stream)?;
            self.throttle(sent);
        }
        let newest = self.plots.newest();
        let sent = self.plots.flush(&self.stream, hold)?;
        self.throttle(sent);
        match (self.live, newest) {
            (Some(out), Some(t)) if out.watched() => self.plots.hold_extents(&self.stream, t),
            _ => Ok(()),
        }
    }

    /// Sends the buffered scene frames.
    pub fn flush_scene(&mut self) -> RecordingStreamResult<()> {
        self.flush_scene_with(true)
    }

    /// `newest`: also the INS trace's newest computed axes where they moved less than the eye sees.
    fn flush_scene_with(&mut self, newest: bool) -> RecordingStreamResult<()> {
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
            sent += body.flush(&self.stream, &times)?;
        }
        if let Some(table) = self.table.as_mut() {
            sent += table.flush(&self.stream, &times)?;
        }
        if let Some(ins) = self.ins.as_mut() {
            sent += ins.flush_scene(&self.stream, &times, newest)?;
        }
        self.throttle(sent);
        Ok(())
    }

    /// A text-log entry at simulated time `t_s`.
    pub fn event(&self, t_s: f64, text: &str, level: &str) -> RecordingStreamResult<()> {
        let rec = self.stream.rec();
        rec.set_duration_secs(TIMELINE, t_s);
        if let Some(t0) = self.stream.file_clock_s {
            rec.set_duration_secs(FILE_CLOCK_TIMELINE, t0 + t_s);
        }
        rec.log("events", &rerun::TextLog::new(text).with_level(level))
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
