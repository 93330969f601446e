//! The only module that talks to Rerun: the entity tree of the gimbal chain, the time series, the
//! documents and the blueprint. It turns [`StepOutput`]s into Rerun calls.
//!
//! Layout of a recording (see docs/recording.md):
//! - `world/vehicle/base/<axis>_mount/<axis>/…/imu`: the chain as `Transform3D`s (errors exaggerated);
//! - `attitude_error_arcsec/{pitch,roll,heading}`: three series each (uncompensated, compensated, closed form);
//! - `gimbal_angle_deg` (one series per axis), `vehicle_attitude_deg` (pitch, roll, heading),
//!   `swing_arcsec/<axis>` (the swing rotation vector's two components);
//!
//! Series that share a plot share an entity (one `Scalars` of several values per row): a third of
//! the time and row-id columns of one entity per line.
//! - `docs/scenario` (markdown), `docs/config` (the resolved TOML), `events` (text log).

use nalgebra::{UnitQuaternion, Vector3};
use rerun::blueprint::components::ContainerKind;
use rerun::{RecordingStream, RecordingStreamResult, TimeColumn};

use layout::Node;

pub mod calibration;
mod layout;
pub mod modulation;
pub mod tpr;
pub mod read;

use crate::config::Params;
use crate::ins::pipeline::{InsView, SampleOut};
use crate::sim::{Model, StepOutput, ERROR_AXES, VARIANTS};
use crate::units::{fmt_angle, ARCSEC_PER_RAD, DEG_PER_RAD};

/// Application id of every rinscope recording (the viewer keys layouts by it).
pub const APPLICATION_ID: &str = "rinscope";

/// Name of the timeline every temporal value is logged on, seconds of simulated time.
pub const TIMELINE: &str = "sim_time";

/// Rows buffered per series before one `send_columns` call.
const SERIES_CHUNK_ROWS: usize = 4096;

/// Chunks sent before waiting for the sinks (see [`Recorder::throttle`]); ~2-4 MB of data.
const MAX_CHUNKS_IN_FLIGHT: usize = 48;

/// Nominal quaternion (w, i, j, k) to Rerun's (x, y, z, w): the one place this reordering happens.
#[must_use]
pub fn to_rerun_quaternion(q: &UnitQuaternion<f64>) -> rerun::Quaternion {
    rerun::Quaternion::from_xyzw([q.i as f32, q.j as f32, q.k as f32, q.w as f32])
}

fn p3(v: Vector3<f64>) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

/// Display colours, one place.
mod palette {
    pub const VARIANT: [[u8; 3]; 3] = [[230, 76, 60], [46, 170, 90], [70, 130, 240]];
    pub const AXES: [[u8; 3]; 3] = [[240, 160, 40], [200, 90, 230], [60, 200, 200]];
    pub const EULER: [[u8; 3]; 3] = [[230, 90, 90], [90, 200, 90], [90, 140, 240]];
    pub const NOMINAL: [u8; 3] = [150, 150, 150];
    pub const SENSOR: [[u8; 3]; 3] = [[235, 50, 50], [50, 200, 50], [60, 110, 255]];
    pub const ALGORITHMS: [[u8; 3]; 5] = [[250, 200, 60], [230, 76, 60], [46, 170, 90], [70, 130, 240], [200, 90, 230]];
}

fn rgb(c: [u8; 3]) -> rerun::Color {
    rerun::Color::from_rgb(c[0], c[1], c[2])
}

fn rgba(c: [u8; 3], a: u8) -> rerun::Color {
    rerun::Color::from_unmultiplied_rgba(c[0], c[1], c[2], a)
}

fn albedo(c: [u8; 3], a: u8) -> rerun::datatypes::Rgba32 {
    rerun::datatypes::Rgba32::from_unmultiplied_rgba(c[0], c[1], c[2], a)
}

/// One entity of `width` plotted series, buffered row-major.
struct Series {
    path: String,
    width: usize,
    values: Vec<f64>,
}

impl Series {
    fn new(path: String, width: usize) -> Self {
        Self { path, width, values: Vec::new() }
    }
}

/// Entity paths of the chain.
#[derive(Debug, Clone)]
struct ChainPaths {
    vehicle: String,
    base: String,
    /// `<axis>_mount` per axis.
    mounts: Vec<String>,
    /// `<axis>` per axis (the rotor).
    gimbals: Vec<String>,
    imu: String,
}

impl ChainPaths {
    fn new(names: &[String]) -> Self {
        let vehicle = "world/vehicle".to_owned();
        let base = format!("{vehicle}/base");
        let mut parent = base.clone();
        let (mut mounts, mut gimbals) = (Vec::new(), Vec::new());
        for name in names {
            let mount = format!("{parent}/{name}_mount");
            let gimbal = format!("{mount}/{name}");
            mounts.push(mount);
            gimbals.push(gimbal.clone());
            parent = gimbal;
        }
        let imu = format!("{parent}/imu");
        Self { vehicle, base, mounts, gimbals, imu }
    }
}

/// Streams a run into a Rerun recording.
pub struct Recorder {
    rec: RecordingStream,
    model: Model,
    paths: ChainPaths,
    axis_names: Vec<String>,
    series: Vec<Series>,
    series_t: Vec<f64>,
    scene_t: Vec<f64>,
    scene_vehicle: Vec<rerun::Quaternion>,
    scene_gimbals: Vec<Vec<rerun::Quaternion>>,
    /// Chunks sent since the sinks last caught up.
    chunks_in_flight: usize,
    /// Live mode: geometry on the timeline instead of static.
    live: bool,
    /// With an IMU in the loop.
    ins: Option<InsLayout>,
}

/// What a run with an IMU in the loop adds to the recording.
struct InsLayout {
    algorithms: Vec<String>,
    nav: bool,
    /// Index in `Recorder::series` of the first INS entity.
    first_series: usize,
    signal_t: Vec<f64>,
    raw: Vec<f64>,
    filtered: Vec<f64>,
    trace_true: Vec<rerun::Quaternion>,
    trace_ins: Vec<rerun::Quaternion>,
    exaggeration: f64,
    fir_taps: Vec<f64>,
    rate_hz: f64,
    signal_window_s: f64,
}

/// What a command adds to the standard layout.
pub(crate) struct CustomLayout {
    /// The right column (replaces the error plots).
    pub right: Node,
    /// Document tabs shown before the scenario's.
    pub docs: Vec<Node>,
}

/// Where the INS trace (true and computed IMU axes) is drawn, beside the table.
const TRACE_OFFSET: [f32; 3] = [1.3, 1.3, -0.5];

impl Recorder {
    /// Logs everything static (documents, styles, geometry, blueprint) and prepares the buffers.
    pub fn new(rec: RecordingStream, params: &Params) -> RecordingStreamResult<Self> {
        Self::build(rec, params, false, None)
    }

    /// A recorder whose layout has `custom.right` as its right column and `custom.docs` as extra
    /// document tabs (commands that add their own panels to the table's 3D scene).
    pub(crate) fn with_layout(rec: RecordingStream, params: &Params, custom: CustomLayout) -> RecordingStreamResult<Self> {
        Self::build(rec, params, false, Some(custom))
    }

    fn build(rec: RecordingStream, params: &Params, live: bool, custom: Option<CustomLayout>) -> RecordingStreamResult<Self> {
        let model = Model::new(params);
        let axis_names: Vec<String> = params.chain.axes().iter().map(|a| a.name.clone()).collect();
        let paths = ChainPaths::new(&axis_names);
        let n = axis_names.len();
        let mut series: Vec<Series> = ERROR_AXES.iter().map(|axis| Series::new(format!("attitude_error_arcsec/{axis}"), VARIANTS.len())).collect();
        series.push(Series::new("gimbal_angle_deg".into(), n));
        series.push(Series::new("vehicle_attitude_deg".into(), 3));
        for name in &axis_names {
            series.push(Series::new(format!("swing_arcsec/{name}"), 2));
        }
        let ins = params.ins.as_ref().map(|cfg| {
            let algorithms: Vec<String> = if cfg.compare {
                std::iter::once(cfg.algorithm).chain(crate::ins::coning::Algorithm::ALL.into_iter().filter(|a| *a != cfg.algorithm)).map(|a| a.name().to_owned()).collect()
            } else {
                vec![cfg.algorithm.name().to_owned()]
            };
            let first_series = series.len();
            for axis in ERROR_AXES {
                series.push(Series::new(format!("ins/attitude_error_arcsec/{axis}"), algorithms.len()));
            }
            if cfg.navigation.is_some() {
                series.push(Series::new("ins/position_error_m".into(), 3));
                series.push(Series::new("ins/velocity_error_mps".into(), 3));
            }
            InsLayout {
                algorithms,
                nav: cfg.navigation.is_some(),
                first_series,
                signal_t: Vec::new(),
                raw: Vec::new(),
                filtered: Vec::new(),
                trace_true: Vec::new(),
                trace_ins: Vec::new(),
                exaggeration: params.recording.exaggeration,
                fir_taps: cfg.fir_taps.clone(),
                rate_hz: params.step_hz,
                signal_window_s: cfg.signal_window_s.max(0.01),
            }
        });
        let me = Self {
            rec,
            model,
            paths,
            axis_names,
            series,
            series_t: Vec::new(),
            scene_t: Vec::new(),
            scene_vehicle: Vec::new(),
            scene_gimbals: vec![Vec::new(); n],
            chunks_in_flight: 0,
            live,
            ins,
        };
        me.log_once(params)?;
        me.log_ins_once()?;
        me.log_error_geometry(params, me.geometry_at(0.0))?;
        me.send_blueprint(params, custom)?;
        me.event(0.0, &format!("run started: {} ({} s at {} Hz, seed {})", params.meta.name, params.duration_s, params.step_hz, params.meta.seed), "INFO")?;
        Ok(me)
    }

    /// A recorder for live mode: everything that a reload can change is logged on the timeline.
    pub fn new_live(rec: RecordingStream, params: &Params) -> RecordingStreamResult<Self> {
        Self::build(rec, params, true, None)
    }

    fn geometry_at(&self, t_s: f64) -> Option<f64> {
        self.live.then_some(t_s)
    }

    /// Live mode: new parameters apply from simulated time `t_s` on (buffered rows go out first).
    pub fn reconfigure(&mut self, t_s: f64, model: Model, params: &Params) -> RecordingStreamResult<()> {
        self.flush_now()?;
        self.model = model;
        self.log_error_geometry(params, self.geometry_at(t_s))
    }

    /// Sends every buffered row now (live mode: low latency over large chunks).
    pub fn flush_now(&mut self) -> RecordingStreamResult<()> {
        self.flush_series()?;
        self.flush_scene()
    }

    /// The underlying stream (for flushing and sinks).
    #[must_use]
    pub fn stream(&self) -> &RecordingStream {
        &self.rec
    }

    /// Logs what never changes during a run: names, properties, series styles and the fixed geometry.
    fn log_once(&self, p: &Params) -> RecordingStreamResult<()> {
        let rec = &self.rec;
        rec.send_recording_name(format!("rinscope: {}", p.meta.name))?;
        rec.send_property(
            "rinscope",
            &rerun::AnyValues::default()
                .with_component::<rerun::components::Text>("scenario", [p.meta.name.clone()])
                .with_component::<rerun::components::Text>("seed", [p.meta.seed.to_string()])
                .with_component::<rerun::components::Text>("version", [env!("CARGO_PKG_VERSION").to_owned()]),
        )?;

        // Series styles, once.
        let variant_names: Vec<String> = VARIANTS.iter().map(|v| v.replace('_', " ")).collect();
        for axis in ERROR_AXES {
            rec.log_static(
                format!("attitude_error_arcsec/{axis}"),
                &rerun::SeriesLines::new()
                    .with_colors(palette::VARIANT.map(rgb))
                    .with_names(variant_names.clone())
                    .with_widths([3.0, 1.5, 1.0]),
            )?;
        }
        rec.log_static(
            "vehicle_attitude_deg",
            &rerun::SeriesLines::new().with_colors(palette::EULER.map(rgb)).with_names(ERROR_AXES),
        )?;
        let n = self.axis_names.len();
        rec.log_static(
            "gimbal_angle_deg",
            &rerun::SeriesLines::new().with_colors(palette::AXES[..n].iter().map(|c| rgb(*c))).with_names(self.axis_names.clone()),
        )?;
        for (k, name) in self.axis_names.iter().enumerate() {
            let g = &self.model.chain.axes()[k];
            let light = palette::AXES[k].map(|c| c / 2 + 60);
            rec.log_static(
                format!("swing_arcsec/{name}"),
                &rerun::SeriesLines::new()
                    .with_colors([rgb(palette::AXES[k]), rgb(light)])
                    .with_names([format!("{name} swing about {}", axis_letter(&g.e1)), format!("{name} swing about {}", axis_letter(&g.e2))]),
            )?;
        }

        rec.log_static("world", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
        rec.log_static(
            "world/compass",
            &rerun::Arrows3D::from_vectors([[1.6, 0.0, 0.0], [0.0, 1.6, 0.0]])
                .with_origins([[0.0, 0.0, -1.4]; 2])
                .with_colors([rgba([120, 120, 120], 160); 2])
                .with_radii([0.006]),
        )?;
        self.label(None, "world/compass/labels", &[([1.7, 0.0, -1.4], "E"), ([0.0, 1.7, -1.4], "N")])?;
        // Vehicle: a deck plate under the table and the body axes.
        rec.log_static(
            format!("{}/deck", self.paths.vehicle),
            &rerun::Boxes3D::from_centers_and_half_sizes([[0.0, 0.0, -1.35]], [[0.9, 1.2, 0.03]])
                .with_colors([rgba([110, 110, 120], 200)])
                .with_fill_mode(rerun::FillMode::Solid),
        )?;
        rec.log_static(
            format!("{}/body_axes", self.paths.vehicle),
            &rerun::Arrows3D::from_vectors([[0.5, 0.0, 0.0], [0.0, 0.9, 0.0], [0.0, 0.0, 0.4]])
                .with_origins([[0.0, 0.0, -1.3]; 3])
                .with_colors([rgba([200, 200, 200], 200); 3])
                .with_radii([0.01]),
        )?;
        let n = self.axis_names.len();
        let axes = self.model.chain.axes();
        for k in 0..n {
            let g = &axes[k];
            let radius = ring_radius(k, n);
            let half = radius * 1.25;
            let color = palette::AXES[k];
            // Nominal axis (grey) in the mount frame; the rotor's own axis (coloured) in the rotor frame.
            rec.log_static(
                format!("{}/nominal_axis", self.paths.mounts[k]),
                &rerun::LineStrips3D::new([[p3(-g.axis * half), p3(g.axis * half)]]).with_colors([rgb(palette::NOMINAL)]).with_radii([0.006]),
            )?;
            rec.log_static(
                format!("{}/actual_axis", self.paths.gimbals[k]),
                &rerun::LineStrips3D::new([[p3(-g.axis * half * 1.05), p3(g.axis * half * 1.05)]]).with_colors([rgb(color)]).with_radii([0.012]),
            )?;
            // Ring of this gimbal: through its own axis and the next one; the last is a platform.
            rec.log_static(
                format!("{}/ring", self.paths.gimbals[k]),
                &rerun::LineStrips3D::new(ring(axes, k, radius)).with_colors([rgb(color)]).with_radii([0.02]),
            )?;
        }
        // The IMU: a box and its three sensor axes.
        rec.log_static(
            format!("{}/case", self.paths.imu),
            &rerun::Boxes3D::from_half_sizes([[0.22, 0.22, 0.16]]).with_colors([rgba([200, 200, 210], 90)]).with_fill_mode(rerun::FillMode::Solid),
        )?;
        rec.log_static(
            format!("{}/sensor_axes", self.paths.imu),
            &rerun::Arrows3D::from_vectors([[0.45, 0.0, 0.0], [0.0, 0.45, 0.0], [0.0, 0.0, 0.45]])
                .with_colors(palette::SENSOR.map(rgb))
                .with_labels(["x_s", "y_s", "z_s"])
                .with_radii([0.015]),
        )?;
        Ok(())
    }

    /// Logs `arch` at `path`: static in a plain run (`at = None`), at simulated time `at` in live mode,
    /// where a reload can change it and the saved session must show the history.
    fn put(&self, at: Option<f64>, path: impl Into<rerun::EntityPath>, arch: &dyn rerun::AsComponents) -> RecordingStreamResult<()> {
        match at {
            None => self.rec.log_static(path, arch),
            Some(t) => {
                self.rec.set_duration_secs(TIMELINE, t);
                self.rec.log(path, arch)
            }
        }
    }

    /// Removes what `put` drew at `path` (live mode: an error set back to zero).
    fn clear(&self, at: Option<f64>, path: impl Into<rerun::EntityPath>) -> RecordingStreamResult<()> {
        match at {
            None => Ok(()),
            Some(t) => {
                self.rec.set_duration_secs(TIMELINE, t);
                self.rec.log(path, &rerun::Clear::recursive())
            }
        }
    }

    /// Text labels at points (Points3D with tiny dots): labels sit exactly where they belong.
    fn label(&self, at: Option<f64>, path: &str, items: &[([f32; 3], &str)]) -> RecordingStreamResult<()> {
        self.put(
            at,
            path,
            &rerun::Points3D::new(items.iter().map(|(p, _)| *p))
                .with_labels(items.iter().map(|(_, t)| *t))
                .with_radii([0.002])
                .with_colors([rgb([230, 230, 230])]),
        )
    }

    /// Everything that depends on the error values: the documents, the exaggerated base, mount and
    /// IMU transforms, the swing cones and the wedges.
    fn log_error_geometry(&self, p: &Params, at: Option<f64>) -> RecordingStreamResult<()> {
        // Documents: the scenario explains itself; the resolved config makes the run reproducible.
        let mut doc = format!("# {}\n\n*{}*\n\n{}\n", p.meta.name, p.meta.title, p.meta.description.trim());
        doc.push_str(&format!(
            "\n---\nError angles in the 3D view are drawn **×{}**. Plots: red = uncompensated (nominal table model), \
             green = compensated (`[compensation]` parameters), blue = closed form (first-order theory, docs/closed-form.md). \
             Seed {}.\n",
            p.recording.exaggeration, p.meta.seed
        ));
        self.put(at, "docs/scenario", &rerun::TextDocument::from_markdown(doc))?;
        self.put(at, "docs/config", &rerun::TextDocument::from_markdown(format!("```toml\n{}\n```\n", p.resolved_toml)))?;

        let x = p.recording.exaggeration;
        self.label(at, "world/legend", &[([0.0, 0.0, 1.45], format!("error angles drawn ×{x}").as_str())])?;
        let draw = self.model.drawing_links(&self.model.scheme.state(0.0).0);
        let t = |q: &UnitQuaternion<f64>| rerun::Transform3D::from_rotation(to_rerun_quaternion(q));
        self.put(at, self.paths.base.as_str(), &t(&draw.base))?;
        for k in 0..self.axis_names.len() {
            self.put(at, self.paths.mounts[k].as_str(), &t(&draw.mount[k]))?;
        }
        self.put(at, self.paths.imu.as_str(), &t(&draw.imu))?;

        let n = self.axis_names.len();
        let axes = self.model.chain.axes();
        let drawing = p.truth.exaggerated(x);
        // Installation: a wedge in the body between the ideal first axis and the tilted one.
        let first_tilted = draw.base * axes[0].axis;
        let installation = p.truth.installation_rad.norm() * ARCSEC_PER_RAD;
        self.log_wedge(at, &format!("{}/installation", self.paths.vehicle), axes[0].axis, first_tilted, 1.5, installation, x, "installation")?;
        for (k, g) in axes.iter().enumerate() {
            let half = ring_radius(k, n) * 1.25;
            let color = palette::AXES[k];
            // Swing cone: a translucent double cone of half-angle α·x around the nominal axis, with rims.
            let alpha = drawing.axes[k].swing_half_angle_rad;
            let cone_path = format!("{}/swing_cone", self.paths.mounts[k]);
            if alpha > 0.0 {
                let (mesh, rims) = cone(g.axis, g.e1, g.e2, alpha, half);
                self.put(at, cone_path.as_str(), &rerun::Mesh3D::new(mesh.0).with_triangle_indices(mesh.1).with_albedo_factor(albedo(color, 60)))?;
                self.put(at, format!("{cone_path}/rims"), &rerun::LineStrips3D::new(rims).with_colors([rgba(color, 200)]).with_radii([0.004]))?;
                let tip = -g.axis * half - g.e1 * (half * alpha.tan());
                let text = format!(
                    "{} swing α = {}, φ = {:.1}°",
                    g.name,
                    fmt_angle(p.truth.axes[k].swing_half_angle_rad),
                    p.truth.axes[k].swing_phase_rad * DEG_PER_RAD
                );
                self.label(at, &format!("{cone_path}/label"), &[(p3(tip), text.as_str())])?;
            } else {
                self.clear(at, cone_path.as_str())?;
            }
            // Non-orthogonality: a wedge, in the previous rotor, between the normal to the previous
            // axis and this axis.
            if k > 0 {
                let tilted = draw.mount[k] * g.axis;
                let eta_arcsec = p.truth.axes[k].non_orthogonality_rad * ARCSEC_PER_RAD;
                self.log_wedge(at, &format!("{}/non_orthogonality", self.paths.gimbals[k - 1]), g.axis, tilted, half, eta_arcsec, x, "η non-orthogonality")?;
            }
        }
        Ok(())
    }

    /// A translucent wedge from `ideal` to `tilted` (both unit, same frame) with a label.
    #[allow(clippy::too_many_arguments)]
    fn log_wedge(&self, at: Option<f64>, path: &str, ideal: Vector3<f64>, tilted: Vector3<f64>, length: f64, true_arcsec: f64, x: f64, what: &str) -> RecordingStreamResult<()> {
        if true_arcsec == 0.0 {
            return self.clear(at, path);
        }
        let mut positions = vec![[0.0f32; 3]];
        let steps = 16;
        for i in 0..=steps {
            let s = i as f64 / steps as f64;
            positions.push(p3(((1.0 - s) * ideal + s * tilted).normalize() * length));
        }
        let triangles: Vec<[u32; 3]> = (1..=steps as u32).map(|i| [0, i, i + 1]).collect();
        self.put(at, format!("{path}/wedge"), &rerun::Mesh3D::new(positions).with_triangle_indices(triangles).with_albedo_factor(albedo([255, 200, 60], 110)))?;
        self.put(
            at,
            format!("{path}/edges"),
            &rerun::LineStrips3D::new([[[0.0, 0.0, 0.0], p3(ideal * length)], [[0.0, 0.0, 0.0], p3(tilted * length)]])
                .with_colors([rgb([255, 255, 255]), rgb([255, 200, 60])])
                .with_radii([0.004]),
        )?;
        let text = format!("{what} {} (drawn ×{x})", fmt_angle(true_arcsec / ARCSEC_PER_RAD));
        self.label(at, &format!("{path}/label"), &[(p3(tilted * length * 1.08), text.as_str())])
    }

    fn send_blueprint(&self, p: &Params, custom: Option<CustomLayout>) -> RecordingStreamResult<()> {
        let plot = |name: String, origin: &str| Node::view("TimeSeries", name, origin).with_property("TimeAxis", &layout::whole_run_time_axis());
        let error_view = |axis: &str| plot(format!("{axis} error (arcsec)"), &format!("attitude_error_arcsec/{axis}"));
        let scene = Node::view("3D", format!("3D: gimbal chain (errors ×{})", p.recording.exaggeration), "world")
            .with_property(
                "EyeControls3D",
                // With an INS, the trace stands beside the table: step back to frame both.
                &if self.ins.is_some() { layout::eye([3.6, -1.7, 1.5], [0.7, 0.7, -0.3]) } else { layout::eye([2.6, -1.1, 0.95], [0.0, 0.1, -0.2]) },
            );
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
        let mut more = vec![
            plot("gimbal angles (deg)".into(), "gimbal_angle_deg"),
            plot("vehicle attitude (deg)".into(), "vehicle_attitude_deg"),
            plot("swing angles (arcsec)".into(), "swing_arcsec"),
        ];
        let right = match (&self.ins, custom_right) {
            (_, Some(right)) => right,
            (None, None) => {
                let more = Node::container(ContainerKind::Tabs, more, &[]);
                Node::container(ContainerKind::Vertical, vec![error_view("pitch"), error_view("roll"), error_view("heading"), more], &[])
            }
            (Some(layout), None) => {
                // The INS in the loop leads; the turntable-only (ideal-INS) plots go into the tabs.
                let ins_view = |axis: &str| plot(format!("INS {axis} error (arcsec)"), &format!("ins/attitude_error_arcsec/{axis}"));
                let mut tabs = Vec::new();
                if layout.nav {
                    tabs.push(plot("position error (m)".into(), "ins/position_error_m"));
                    tabs.push(plot("velocity error (m/s)".into(), "ins/velocity_error_mps"));
                }
                let window = |name: &str, origin: &str| Node::view("TimeSeries", name, origin).with_property("TimeAxis", &layout::window_time_axis(layout.signal_window_s));
                tabs.push(window("gyro raw (deg/s)", "ins/gyro_raw_deg_per_s"));
                tabs.push(window("gyro after FIR (deg/s)", "ins/gyro_filtered_deg_per_s"));
                if layout.fir_taps.len() > 1 {
                    tabs.push(Node::view("2D", "FIR response (x: Hz, y: −5·dB)", "ins/fir_response"));
                }
                for axis in ERROR_AXES {
                    tabs.push(plot(format!("table only: {axis} (arcsec)"), &format!("attitude_error_arcsec/{axis}")));
                }
                tabs.append(&mut more);
                Node::container(ContainerKind::Vertical, vec![ins_view("pitch"), ins_view("roll"), ins_view("heading"), Node::container(ContainerKind::Tabs, tabs, &[])], &[])
            }
        };
        let root = Node::container(ContainerKind::Horizontal, vec![left, right], &[1.1, 1.0]);
        // Play a whole run in about a minute; a live session follows the newest data.
        let speed = if self.live { 1.0 } else { (p.duration_s / 60.0).max(1.0).round() };
        layout::send(&self.rec, APPLICATION_ID, &root, &layout::Playback { timeline: TIMELINE, speed, follow: self.live })
    }

    /// Buffers one time-series row; sends a chunk when the buffer is full.
    pub fn push_series(&mut self, out: &StepOutput) -> RecordingStreamResult<()> {
        self.push_row(out, None)
    }

    /// Buffers one row: the turntable-only variants and, with an IMU in the loop, the INS's view.
    pub fn push_row(&mut self, out: &StepOutput, ins: Option<&InsView>) -> RecordingStreamResult<()> {
        for a in 0..3 {
            for e in &out.errors {
                self.series[a].values.push(e.as_array()[a] * ARCSEC_PER_RAD);
            }
        }
        let n = self.axis_names.len();
        self.series[3].values.extend(out.gimbal_rad[..n].iter().map(|x| x * DEG_PER_RAD));
        self.series[4].values.extend([out.attitude.pitch_rad, out.attitude.roll_rad, out.attitude.heading_rad].map(|x| x * DEG_PER_RAD));
        for k in 0..n {
            let g = &self.model.chain.axes()[k];
            let s = self.model.chain.swing_vector(k, &self.model.truth.axes[k], out.gimbal_rad[k]);
            self.series[5 + k].values.extend([s.dot(&g.e1) * ARCSEC_PER_RAD, s.dot(&g.e2) * ARCSEC_PER_RAD]);
        }
        if let Some(layout) = &self.ins {
            let i0 = layout.first_series;
            let width = layout.algorithms.len();
            for a in 0..3 {
                let values = &mut self.series[i0 + a].values;
                match ins {
                    Some(v) => values.extend(v.errors.iter().map(|e| e.as_array()[a] * ARCSEC_PER_RAD)),
                    None => values.extend(std::iter::repeat_n(f64::NAN, width)),
                }
            }
            if layout.nav {
                let (pos, vel) = ins.and_then(|v| v.nav).unwrap_or((Vector3::repeat(f64::NAN), Vector3::repeat(f64::NAN)));
                self.series[i0 + 3].values.extend([pos.x, pos.y, pos.z]);
                self.series[i0 + 4].values.extend([vel.x, vel.y, vel.z]);
            }
        }
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
        let links = self.model.drawing_links(&out.gimbal_rad);
        self.scene_t.push(out.t_s);
        self.scene_vehicle.push(to_rerun_quaternion(&out.n_from_b));
        for (k, col) in self.scene_gimbals.iter_mut().enumerate() {
            col.push(to_rerun_quaternion(&links.gimbal[k]));
        }
        if let Some(layout) = self.ins.as_mut() {
            let (t, c) = ins.map_or((UnitQuaternion::identity(), UnitQuaternion::identity()), |v| (v.imu_true, v.imu_ins));
            let err = (c * t.inverse()).scaled_axis() * layout.exaggeration;
            layout.trace_true.push(to_rerun_quaternion(&t));
            layout.trace_ins.push(to_rerun_quaternion(&(UnitQuaternion::from_scaled_axis(err) * t)));
        }
        if self.scene_t.len() >= SERIES_CHUNK_ROWS {
            self.flush_scene()?;
        }
        Ok(())
    }

    /// Buffers one raw and filtered gyro sample (the signal window at the IMU rate).
    pub fn push_signal(&mut self, s: &SampleOut) -> RecordingStreamResult<()> {
        let Some(layout) = self.ins.as_mut() else { return Ok(()) };
        layout.signal_t.push(s.t_s);
        layout.raw.extend(s.raw_rate_s.iter().map(|x| x * DEG_PER_RAD));
        layout.filtered.extend(s.filtered_rate_s.iter().map(|x| x * DEG_PER_RAD));
        if layout.signal_t.len() >= SERIES_CHUNK_ROWS {
            self.flush_signal()?;
        }
        Ok(())
    }

    fn flush_signal(&mut self) -> RecordingStreamResult<()> {
        let Some(layout) = self.ins.as_mut() else { return Ok(()) };
        if layout.signal_t.is_empty() {
            return Ok(());
        }
        let times = std::mem::take(&mut layout.signal_t);
        for (path, values) in [("ins/gyro_raw_deg_per_s", std::mem::take(&mut layout.raw)), ("ins/gyro_filtered_deg_per_s", std::mem::take(&mut layout.filtered))] {
            let time = TimeColumn::new_duration_secs(TIMELINE, times.iter().copied());
            self.rec.send_columns(path, [time], rerun::Scalars::new(values).columns(std::iter::repeat_n(3, times.len()))?)?;
        }
        Ok(())
    }

    /// Static parts of an INS run: series styles, the FIR's amplitude response, the trace's axes.
    fn log_ins_once(&self) -> RecordingStreamResult<()> {
        let Some(layout) = &self.ins else { return Ok(()) };
        let rec = &self.rec;
        let algo_colors: Vec<rerun::Color> = (0..layout.algorithms.len()).map(|k| rgb(palette::ALGORITHMS[k % palette::ALGORITHMS.len()])).collect();
        for axis in ERROR_AXES {
            rec.log_static(
                format!("ins/attitude_error_arcsec/{axis}"),
                &rerun::SeriesLines::new().with_colors(algo_colors.clone()).with_names(layout.algorithms.clone()),
            )?;
        }
        let enu = ["east", "north"];
        rec.log_static("ins/position_error_m", &rerun::SeriesLines::new().with_colors(palette::EULER.map(rgb)).with_names([enu[0], enu[1], "radial"]))?;
        rec.log_static("ins/velocity_error_mps", &rerun::SeriesLines::new().with_colors(palette::EULER.map(rgb)).with_names([enu[0], enu[1], "up"]))?;
        for path in ["ins/gyro_raw_deg_per_s", "ins/gyro_filtered_deg_per_s"] {
            rec.log_static(path, &rerun::SeriesLines::new().with_colors(palette::SENSOR.map(rgb)).with_names(["gyro x", "gyro y", "gyro z"]))?;
        }
        // FIR amplitude response, dB, drawn in a 2D view: x = frequency (Hz), y = 5 × dB (so that
        // 0..-150 dB spans a readable height next to 0..1000 Hz).
        if layout.fir_taps.len() > 1 {
            let fir = crate::ins::fir::Fir::new(&layout.fir_taps);
            let nyquist = 0.5 * layout.rate_hz;
            let curve: Vec<[f32; 2]> = (0..=1000)
                .map(|i| {
                    let f = nyquist * f64::from(i) / 1000.0;
                    let db = (20.0 * fir.amplitude(f, layout.rate_hz).log10()).max(-160.0);
                    [f as f32, (-5.0 * db) as f32]
                })
                .collect();
            rec.log_static("ins/fir_response/curve", &rerun::LineStrips2D::new([curve]).with_colors([rgb([90, 200, 250])]).with_radii([1.5]))?;
            let mut grid = Vec::new();
            for db in [0.0f32, -50.0, -100.0, -150.0] {
                grid.push(vec![[0.0, -5.0 * db], [nyquist as f32, -5.0 * db]]);
            }
            rec.log_static("ins/fir_response/grid", &rerun::LineStrips2D::new(grid).with_colors([rgba([120, 120, 120], 120)]).with_radii([0.8]).with_labels(["0 dB", "-50 dB", "-100 dB", "-150 dB"]))?;
            let tones: Vec<[f32; 2]> = [335.4f64, 375.5, 425.7]
                .iter()
                .filter(|f| **f < nyquist)
                .map(|f| [*f as f32, (-5.0 * (20.0 * fir.amplitude(*f, layout.rate_hz).log10()).max(-160.0)) as f32])
                .collect();
            let labels: Vec<String> = [335.4f64, 375.5, 425.7].iter().filter(|f| **f < nyquist).map(|f| format!("{f} Hz dither")).collect();
            rec.log_static("ins/fir_response/dither", &rerun::Points2D::new(tones).with_labels(labels).with_radii([6.0]).with_colors([rgb([240, 90, 90])]))?;
        }
        // The INS trace: true IMU axes (grey) and computed (coloured, error ×N), beside the table.
        let ins_label = format!("INS IMU axes (error ×{})", layout.exaggeration);
        for (path, colors, label) in [("world/ins_trace/true", [[170, 170, 170]; 3], "true IMU axes"), ("world/ins_trace/ins", palette::SENSOR, ins_label.as_str())] {
            rec.log_static(path, &rerun::Transform3D::from_translation(TRACE_OFFSET))?;
            rec.log_static(
                format!("{path}/axes"),
                &rerun::Arrows3D::from_vectors([[0.6, 0.0, 0.0], [0.0, 0.6, 0.0], [0.0, 0.0, 0.6]]).with_colors(colors.map(rgb)).with_radii([0.012]),
            )?;
            let at = if path.ends_with("true") { [0.0f32, 0.0, -0.2] } else { [0.0f32, 0.0, 0.75] };
            rec.log_static(format!("{path}/label"), &rerun::Points3D::new([at]).with_labels([label]).with_radii([0.002]))?;
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
        if self.series_t.is_empty() {
            return Ok(());
        }
        self.throttle(self.series.len());
        let times = std::mem::take(&mut self.series_t);
        for s in &mut self.series {
            let values = std::mem::take(&mut s.values);
            debug_assert_eq!(values.len(), s.width * times.len());
            let time = TimeColumn::new_duration_secs(TIMELINE, times.iter().copied());
            self.rec.send_columns(s.path.as_str(), [time], rerun::Scalars::new(values).columns(std::iter::repeat_n(s.width, times.len()))?)?;
        }
        Ok(())
    }

    /// Sends the buffered scene frames.
    pub fn flush_scene(&mut self) -> RecordingStreamResult<()> {
        if self.scene_t.is_empty() {
            return Ok(());
        }
        self.throttle(1 + self.scene_gimbals.len());
        let times = std::mem::take(&mut self.scene_t);
        let time = || TimeColumn::new_duration_secs(TIMELINE, times.iter().copied());
        let vehicle = std::mem::take(&mut self.scene_vehicle);
        self.rec.send_columns(
            self.paths.vehicle.as_str(),
            [time()],
            rerun::Transform3D::update_fields().with_many_quaternion(vehicle).columns_of_unit_batches()?,
        )?;
        for k in 0..self.scene_gimbals.len() {
            let q = std::mem::take(&mut self.scene_gimbals[k]);
            self.rec.send_columns(
                self.paths.gimbals[k].as_str(),
                [time()],
                rerun::Transform3D::update_fields().with_many_quaternion(q).columns_of_unit_batches()?,
            )?;
        }
        if let Some(layout) = self.ins.as_mut() {
            for (path, q) in [("world/ins_trace/true", std::mem::take(&mut layout.trace_true)), ("world/ins_trace/ins", std::mem::take(&mut layout.trace_ins))] {
                let n = q.len();
                self.rec.send_columns(
                    path,
                    [time()],
                    rerun::Transform3D::update_fields()
                        .with_many_translation(std::iter::repeat_n(TRACE_OFFSET, n))
                        .with_many_quaternion(q)
                        .columns_of_unit_batches()?,
                )?;
            }
        }
        Ok(())
    }

    /// A text-log entry at simulated time `t_s`.
    pub fn event(&self, t_s: f64, text: &str, level: &str) -> RecordingStreamResult<()> {
        self.rec.set_duration_secs(TIMELINE, t_s);
        self.rec.log("events", &rerun::TextLog::new(text).with_level(level))
    }

    /// Sends everything still buffered.
    pub fn finish(&mut self) -> RecordingStreamResult<()> {
        self.flush_signal()?;
        self.flush_series()?;
        self.flush_scene()
    }
}

/// "x", "y" or "z" for a coordinate unit vector.
fn axis_letter(v: &Vector3<f64>) -> &'static str {
    let a = v.abs();
    if a.x >= a.y && a.x >= a.z {
        "x"
    } else if a.y >= a.z {
        "y"
    } else {
        "z"
    }
}

/// Ring radius of gimbal k of n: nested, outer first.
fn ring_radius(k: usize, n: usize) -> f64 {
    let radii: [f64; 3] = [1.0, 0.75, 0.52];
    radii[3 - n + k].max(0.5)
}

/// Polylines of gimbal k's ring: a circle through its axis and the next axis (with bearing stubs),
/// or, for the last gimbal, a platform circle with spokes so that its rotation shows.
fn ring(axes: &[crate::gimbal::AxisGeometry], k: usize, radius: f64) -> Vec<Vec<[f32; 3]>> {
    let g = &axes[k];
    let (u, w) = if k + 1 < axes.len() { (g.axis, axes[k + 1].axis) } else { (g.e1, g.e2) };
    let circle: Vec<[f32; 3]> = (0..=96)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / 96.0;
            p3((u * t.cos() + w * t.sin()) * radius)
        })
        .collect();
    let mut strips = vec![circle];
    if k + 1 == axes.len() {
        for j in 0..4 {
            let t = std::f64::consts::FRAC_PI_2 * j as f64;
            strips.push(vec![[0.0; 3], p3((u * t.cos() + w * t.sin()) * radius)]);
        }
        // A marker notch at e1 so the sense of rotation reads at a glance.
        strips.push(vec![p3(u * radius * 1.12 + w * 0.05), p3(u * radius * 1.12 - w * 0.05), p3(u * radius * 0.95), p3(u * radius * 1.12 + w * 0.05)]);
    }
    strips
}

/// A double cone of half-angle `alpha` around `axis` (length `half` each way): mesh and rim circles.
#[allow(clippy::type_complexity)]
fn cone(axis: Vector3<f64>, e1: Vector3<f64>, e2: Vector3<f64>, alpha: f64, half: f64) -> ((Vec<[f32; 3]>, Vec<[u32; 3]>), Vec<Vec<[f32; 3]>>) {
    let segments = 48u32;
    let r = half * alpha.tan();
    let mut positions = vec![[0.0f32; 3]];
    let mut rims = Vec::new();
    for sign in [1.0, -1.0] {
        let mut rim = Vec::new();
        for i in 0..=segments {
            let t = std::f64::consts::TAU * f64::from(i) / f64::from(segments);
            let p = p3(axis * half * sign + (e1 * t.cos() + e2 * t.sin()) * r);
            if i < segments {
                positions.push(p);
            }
            rim.push(p);
        }
        rims.push(rim);
    }
    let mut triangles = Vec::new();
    for nappe in 0..2u32 {
        let base = 1 + nappe * segments;
        for i in 0..segments {
            triangles.push([0, base + i, base + (i + 1) % segments]);
        }
    }
    ((positions, triangles), rims)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternion_reordering_puts_w_last() {
        // nalgebra stores (w, i, j, k); Rerun wants (x, y, z, w).
        let q = UnitQuaternion::from_scaled_axis(Vector3::new(0.1, 0.2, 0.3));
        let r = to_rerun_quaternion(&q);
        assert_eq!(r.0, [q.i as f32, q.j as f32, q.k as f32, q.w as f32]);
    }

    #[test]
    fn chain_paths_nest_outer_to_inner() {
        let p = ChainPaths::new(&["outer".into(), "inner".into()]);
        assert_eq!(p.gimbals[1], "world/vehicle/base/outer_mount/outer/inner_mount/inner");
        assert_eq!(p.imu, "world/vehicle/base/outer_mount/outer/inner_mount/inner/imu");
    }
}
