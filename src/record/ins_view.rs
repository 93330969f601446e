//! What a run with the INS in the loop adds to a recording beside its plots: the raw and filtered
//! gyro signals of the first moments, the FIR's amplitude response, the drift dial and the trace
//! of the true and computed IMU axes beside the table.

use nalgebra::{UnitQuaternion, Vector3};
use rerun::RecordingStreamResult;

use super::palette::{colors, rgb, rgba};
use super::plots::InsSeries;
use super::{ReplayKind, SERIES_CHUNK_ROWS, Stream};
use crate::ins::core::SampleOut;
use crate::ins::pipeline::InsView;
use crate::math::rotvec;
use crate::math::units::{ARCSEC_PER_RAD, DEG_PER_RAD};
use crate::scenario::Params;

/// The INS's view in the 3D scene and beside it: the trace of the true and computed IMU axes, the
/// drift dial, the FIR's amplitude response and the raw and filtered gyro signals of the first
/// moments. It owns those entities.
pub(crate) struct InsScene {
    pub(crate) algorithms: Vec<String>,
    /// The algorithms not shown (`[recording.show]`), by name: their needles stand at zero.
    pub(crate) hidden: Vec<String>,
    /// The trace of the true and computed IMU axes beside the table (not for a strapdown IMU).
    trace: bool,
    signal_t: Vec<f64>,
    raw: Vec<f64>,
    filtered: Vec<f64>,
    /// Per buffered scene frame, the true IMU attitude (the trace's moving frame).
    trace_imu: Vec<rerun::Quaternion>,
    /// The computed axes' attitude (the error ×N turning the true attitude): the frames where the
    /// true attitude moved or the error's drawing moved by more than [`TRACE_DEAD_BAND_RAD`] since
    /// the last buffered, and when.
    trace_computed: Vec<rerun::Quaternion>,
    trace_computed_t: Vec<f64>,
    /// The last true attitude and drawn error buffered, and the newest computed axes not buffered.
    trace_last: Option<(rerun::Quaternion, UnitQuaternion<f64>)>,
    trace_computed_pending: Option<(f64, UnitQuaternion<f64>)>,
    /// The last true attitude sent (a table that stands still sends nothing).
    trace_imu_last: Option<rerun::Quaternion>,
    pub(crate) exaggeration: f64,
    pub(crate) fir_taps: Vec<f64>,
    rate_hz: f64,
    pub(crate) signal_window_s: f64,
    /// Largest |rate| in the raw and the filtered gyro window, deg/s (their plots' framing).
    pub(crate) signal_peak_deg_per_s: [f64; 2],
    /// With two algorithms or more and their errors recorded: the drift dial, a needle per algorithm.
    dial_on: bool,
    /// Per buffered dial frame (at most [`DIAL_HZ`]: the errors grow slowly; at the scene's rate
    /// the dial would add 13 MB/h), each algorithm's needle.
    dial: Vec<[f32; 3]>,
    /// The dial's frame times, s, and the time of the next.
    dial_t: Vec<f64>,
    dial_next_t: f64,
}

impl InsScene {
    /// The INS's view of a run of `params` (`replay`: of a replayed log of that kind), whose plots
    /// are `plots` (the algorithms, whether their errors are recorded, pure coning's lines).
    pub(crate) fn new(params: &Params, replay: Option<ReplayKind>, plots: &InsSeries) -> Option<Self> {
        let cfg = params.ins.as_ref()?;
        // The INS trace and the drift dial draw the INS's error ×N: where the largest error of
        // the run is known in advance (pure coning: the analytic drifts), N is lowered to the
        // largest 1-2-5 factor that keeps it under 150°, so the picture never wraps round.
        let exaggeration = plots.coning.as_ref().map_or(params.recording.exaggeration, |lines| {
            let worst_rad = lines.rates.iter().fold(0.0_f64, |m, r| m.max(*r)) * params.duration_s / ARCSEC_PER_RAD;
            let limit = 150.0 * crate::math::units::RAD_PER_DEG;
            if worst_rad * params.recording.exaggeration <= limit {
                return params.recording.exaggeration;
            }
            crate::math::units::nice_at_most(limit / worst_rad).max(1e-3)
        });
        Some(Self {
            algorithms: plots.algorithms.clone(),
            hidden: plots.hidden.clone(),
            // A strapdown IMU's axes are drawn as the body (`body_view`), not as a trace beside a table.
            trace: replay.is_none_or(|k| k.table),
            signal_t: Vec::new(),
            raw: Vec::new(),
            filtered: Vec::new(),
            trace_imu: Vec::new(),
            trace_computed: Vec::new(),
            trace_computed_t: Vec::new(),
            trace_last: None,
            trace_computed_pending: None,
            trace_imu_last: None,
            // The dial turns by the errors: none without them.
            dial_on: plots.algorithms.len() >= 2 && plots.errors,
            dial: Vec::new(),
            dial_t: Vec::new(),
            dial_next_t: f64::NEG_INFINITY,
            exaggeration,
            fir_taps: cfg.fir_taps.clone(),
            rate_hz: params.step_hz,
            signal_window_s: cfg.signal_window_s.max(0.01),
            signal_peak_deg_per_s: [0.0; 2],
        })
    }

    /// Whether anything of it moves with the scene (the trace, the dial).
    pub(crate) fn in_scene(&self) -> bool {
        self.trace || self.dial_on
    }

    /// Buffers one scene frame: the trace's true and computed axes (without an INS view, or
    /// without its truth, it stands still at the identity) and, when due, the dial's needles.
    pub(crate) fn push_scene(&mut self, t_s: f64, ins: Option<&InsView>) {
        if self.trace {
            let (t, c) = ins
                .and_then(|v| Some((*v.imu_true?.quaternion(), *v.imu_ins.quaternion())))
                .unwrap_or((UnitQuaternion::identity(), UnitQuaternion::identity()));
            let err = rotvec::log(&(c * t.inverse())) * self.exaggeration;
            // The computed axes are exp(err)·t: the exaggerated error in the navigation frame
            // turning the true attitude, one entity (a viewer's stream carries a chunk per moving
            // entity). The error moves slowly: a table standing still sends its computed axes only
            // when their drawing moved by more than the eye sees (and the newest at a full flush).
            let true_q = super::to_rerun_quaternion(&t);
            self.trace_imu.push(true_q);
            let drawn = rotvec::exp(&err);
            let computed = drawn * t;
            let moved = self.trace_last.is_none_or(|(last_t, last_drawn)| {
                last_t != true_q || last_drawn.angle_to(&drawn) > TRACE_DEAD_BAND_RAD
            });
            if moved {
                self.trace_computed_t.push(t_s);
                self.trace_computed.push(super::to_rerun_quaternion(&computed));
                self.trace_last = Some((true_q, drawn));
                self.trace_computed_pending = None;
            } else {
                self.trace_computed_pending = Some((t_s, computed));
            }
        }
        // The needles turn clockwise by the size of each algorithm's attitude error (whichever
        // axis it is on: heading for a cone about z, pitch for Li et al. 2014's wobble), ×N.
        if self.dial_on && t_s >= self.dial_next_t {
            self.dial_t.push(t_s);
            self.dial_next_t = t_s + 1.0 / DIAL_HZ - 1e-9;
            for (k, name) in self.algorithms.iter().enumerate() {
                let size = ins
                    .and_then(|v| v.errors.get(k))
                    .filter(|_| !self.hidden.contains(name))
                    .map_or(0.0, |e| e.as_array().iter().map(|x| x * x).sum::<f64>().sqrt());
                self.dial.push(needle(-size * self.exaggeration));
            }
        }
    }

    /// Sends the trace's buffered frames at `times` (`newest`: and the computed axes' newest frame
    /// if it moved less than the dead band since the last sent: a live viewer's periodic flush
    /// leaves it out, a chunk it could not show); returns the chunks sent.
    pub(crate) fn flush_scene(&mut self, stream: &Stream, times: &[f64], newest: bool) -> RecordingStreamResult<usize> {
        let imu = std::mem::take(&mut self.trace_imu);
        if imu.is_empty() {
            return Ok(0);
        }
        debug_assert_eq!(imu.len(), times.len());
        let mut sent = 0;
        if !imu.iter().all(|q| Some(*q) == self.trace_imu_last) {
            self.trace_imu_last = imu.last().copied();
            stream.rec().send_columns(
                TRACE_IMU_PATH,
                stream.time_columns(times),
                rerun::Transform3D::update_fields().with_many_quaternion(imu).columns_of_unit_batches()?,
            )?;
            sent += 1;
        }
        // The computed axes at the newest frame, if their error moved less than the dead band since.
        if let Some((t, q)) = self.trace_computed_pending.take_if(|_| newest) {
            self.trace_computed_t.push(t);
            self.trace_computed.push(super::to_rerun_quaternion(&q));
        }
        let computed_t = std::mem::take(&mut self.trace_computed_t);
        if !computed_t.is_empty() {
            stream.rec().send_columns(
                TRACE_COMPUTED_PATH,
                stream.time_columns(&computed_t),
                rerun::Transform3D::update_fields()
                    .with_many_quaternion(std::mem::take(&mut self.trace_computed))
                    .columns_of_unit_batches()?,
            )?;
            sent += 1;
        }
        Ok(sent)
    }

    /// The drift dial's frames buffered.
    pub(crate) fn dial_buffered(&self) -> usize {
        self.dial_t.len()
    }

    /// Sends the drift dial's buffered frames (with the plots: the needles turn with the errors);
    /// returns the chunks sent.
    pub(crate) fn flush_dial(&mut self, stream: &Stream) -> RecordingStreamResult<usize> {
        let dial_t = std::mem::take(&mut self.dial_t);
        let needles = std::mem::take(&mut self.dial);
        if dial_t.is_empty() {
            return Ok(0);
        }
        let k = self.algorithms.len();
        stream.rec().send_columns(
            DIAL_NEEDLES_PATH,
            stream.time_columns(&dial_t),
            rerun::Arrows3D::update_fields().with_vectors(needles).columns(std::iter::repeat_n(k, dial_t.len()))?,
        )?;
        Ok(1)
    }

    /// Live mode: the algorithms shown (`[recording.show]`).
    pub(crate) fn set_hidden(&mut self, hidden: &[String]) {
        self.hidden = hidden.to_vec();
    }
}

/// Frames per second of the drift dial, at most.
pub(crate) const DIAL_HZ: f64 = 4.0;

/// The needles of the drift dial (one arrow per algorithm, in the dial's frame).
pub(crate) const DIAL_NEEDLES_PATH: &str = "world/drift_dial/needles";

/// Length of a dial needle.
const NEEDLE_LENGTH: f64 = 0.42;

/// A dial needle turned by `angle_rad` about the dial's axis (counter-clockwise when positive).
pub(crate) fn needle(angle_rad: f64) -> [f32; 3] {
    let (s, c) = angle_rad.sin_cos();
    [(-NEEDLE_LENGTH * s) as f32, (NEEDLE_LENGTH * c) as f32, 0.0]
}

/// The INS trace's true axes: the true IMU attitude (its arrows).
pub(crate) const TRACE_IMU_PATH: &str = "world/ins_trace/imu";
/// The computed axes: the INS's attitude error ×N (a rotation in the navigation frame) turning the
/// true IMU attitude.
pub(crate) const TRACE_COMPUTED_PATH: &str = "world/ins_trace/computed";
/// The drawn computed axes are sent again when they moved by more than this, rad (0.2°: under
/// what the eye tells apart on an axis 0.6 long; the newest frame goes out at every flush).
const TRACE_DEAD_BAND_RAD: f64 = 0.2 * crate::math::units::RAD_PER_DEG;

/// Length of a trace arrow.
pub(crate) const TRACE_AXIS_LENGTH: f64 = 0.6;

/// Where the drift dial (one needle per algorithm, turned by the size of its attitude error ×N) stands.
pub(crate) const DIAL_OFFSET: [f32; 3] = [2.3, 0.2, -0.5];

/// The raw gyro signal of the first moments.
pub(crate) const GYRO_RAW_PATH: &str = "ins/gyro_raw_deg_per_s";
/// The gyro signal after the FIR (with a FIR only).
pub(crate) const GYRO_FILTERED_PATH: &str = "ins/gyro_filtered_deg_per_s";

/// The gyro signals' lines.
const GYRO_NAMES: [&str; 3] = ["gyro x", "gyro y", "gyro z"];

/// Where the INS trace (true and computed IMU axes) is drawn, beside the table.
pub(crate) const TRACE_OFFSET: [f32; 3] = [1.3, 1.3, -0.5];

impl InsScene {
    /// Buffers one raw and filtered gyro sample (the signal window at the IMU rate).
    pub(crate) fn push_signal(&mut self, s: &SampleOut, stream: &Stream) -> RecordingStreamResult<()> {
        let layout = self;
        layout.signal_t.push(s.t_s);
        layout.raw.extend(s.raw_rate_s.iter().map(|x| x * DEG_PER_RAD));
        layout.filtered.extend(s.filtered_rate_s.iter().map(|x| x * DEG_PER_RAD));
        layout.signal_peak_deg_per_s[0] = layout.signal_peak_deg_per_s[0].max(s.raw_rate_s.amax() * DEG_PER_RAD);
        layout.signal_peak_deg_per_s[1] = layout.signal_peak_deg_per_s[1].max(s.filtered_rate_s.amax() * DEG_PER_RAD);
        if layout.signal_t.len() >= SERIES_CHUNK_ROWS {
            layout.flush_signal(stream)?;
        }
        Ok(())
    }

    /// Sends the buffered gyro samples.
    pub(crate) fn flush_signal(&mut self, stream: &Stream) -> RecordingStreamResult<()> {
        let layout = self;
        if layout.signal_t.is_empty() {
            return Ok(());
        }
        let times = std::mem::take(&mut layout.signal_t);
        let names = GYRO_NAMES.map(String::from);
        let (raw, filtered) = (std::mem::take(&mut layout.raw), std::mem::take(&mut layout.filtered));
        stream.send_series(GYRO_RAW_PATH, &names, &times, raw, 3)?;
        // Without a FIR the filtered signal is the raw one.
        if layout.fir_taps.len() > 1 {
            stream.send_series(GYRO_FILTERED_PATH, &names, &times, filtered, 3)?;
        }
        Ok(())
    }

    /// Its static parts: the gyro plots' styles, the FIR's amplitude response, the dial, the trace's axes.
    pub(crate) fn log_static(&self, stream: &Stream) -> RecordingStreamResult<()> {
        let layout = self;
        let rec = stream.rec();
        for path in [GYRO_RAW_PATH, GYRO_FILTERED_PATH].into_iter().take(if layout.fir_taps.len() > 1 { 2 } else { 1 })
        {
            rec.log_static(
                path,
                &rerun::SeriesLines::new().with_colors(colors::SENSOR.map(rgb)).with_names(GYRO_NAMES),
            )?;
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
            rec.log_static(
                "ins/fir_response/curve",
                &rerun::LineStrips2D::new([curve]).with_colors([rgb([90, 200, 250])]).with_radii([1.5]),
            )?;
            let mut grid = Vec::new();
            for db in [0.0f32, -50.0, -100.0, -150.0] {
                grid.push(vec![[0.0, -5.0 * db], [nyquist as f32, -5.0 * db]]);
            }
            rec.log_static(
                "ins/fir_response/grid",
                &rerun::LineStrips2D::new(grid)
                    .with_colors([rgba([120, 120, 120], 120)])
                    .with_radii([0.8])
                    .with_labels(["0 dB", "-50 dB", "-100 dB", "-150 dB"]),
            )?;
            let tones: Vec<[f32; 2]> = [335.4f64, 375.5, 425.7]
                .iter()
                .filter(|f| **f < nyquist)
                .map(|f| [*f as f32, (-5.0 * (20.0 * fir.amplitude(*f, layout.rate_hz).log10()).max(-160.0)) as f32])
                .collect();
            let labels: Vec<String> =
                [335.4f64, 375.5, 425.7].iter().filter(|f| **f < nyquist).map(|f| format!("{f} Hz dither")).collect();
            rec.log_static(
                "ins/fir_response/dither",
                &rerun::Points2D::new(tones).with_labels(labels).with_radii([6.0]).with_colors([rgb([240, 90, 90])]),
            )?;
        }
        // The drift dial: a student sees the heading error of each algorithm accumulate, ×N, and
        // why a higher-order algorithm helps (the needles of the good ones barely move).
        if layout.dial_on {
            let circle: Vec<[f32; 3]> = (0..=72)
                .map(|i| {
                    let a = f64::from(i) * std::f64::consts::TAU / 72.0;
                    [(0.45 * a.cos()) as f32, (0.45 * a.sin()) as f32, 0.0]
                })
                .collect();
            rec.log_static("world/drift_dial", &rerun::Transform3D::from_translation(DIAL_OFFSET))?;
            rec.log_static(
                "world/drift_dial/rim",
                &rerun::LineStrips3D::new([circle]).with_colors([rgba([200, 200, 200], 160)]).with_radii([0.004]),
            )?;
            let title = format!(
                "attitude error per algorithm, clockwise ×{} (a turn: {:.0}″)",
                layout.exaggeration,
                360.0 * 3600.0 / layout.exaggeration
            );
            // The title above the dial (below it, it met the compass's E), the names in a column
            // to its right, spaced for their boxes, on points too small to cover a neighbour.
            let mut items: Vec<([f32; 3], String)> = vec![([0.0, 0.8, 0.0], title)];
            for (k, name) in layout.algorithms.iter().enumerate() {
                items.push(([0.7, 0.0, 0.5 - 0.14 * k as f32], name.clone()));
            }
            // The needles' colours and widths; their directions go on the timeline.
            rec.log_static(
                DIAL_NEEDLES_PATH,
                &rerun::Arrows3D::update_fields()
                    .with_colors(layout.algorithms.iter().map(|n| rgb(colors::algorithm(n))))
                    .with_radii([0.01]),
            )?;
            let colors: Vec<rerun::Color> = std::iter::once(super::palette::label([230, 230, 230]))
                .chain(layout.algorithms.iter().map(|n| super::palette::label(colors::algorithm(n))))
                .collect();
            rec.log_static(
                "world/drift_dial/labels",
                &rerun::Points3D::new(items.iter().map(|(p, _)| *p))
                    .with_labels(items.iter().map(|(_, t)| t.as_str()))
                    .with_colors(colors)
                    .with_radii([0.002]),
            )?;
        }
        if !layout.trace {
            return Ok(());
        }
        // The INS trace: true IMU axes (grey) and computed (coloured, error ×N), beside the table:
        // fixed arrows in the moving frames (true attitude; error in it, `push_scene`).
        rec.log_static("world/ins_trace", &rerun::Transform3D::from_translation(TRACE_OFFSET))?;
        let unit = |a: Vector3<f64>| {
            let v = a * TRACE_AXIS_LENGTH;
            [v.x as f32, v.y as f32, v.z as f32]
        };
        let axes = [Vector3::x(), Vector3::y(), Vector3::z()].map(unit);
        rec.log_static(
            format!("{TRACE_IMU_PATH}/axes"),
            &rerun::Arrows3D::from_vectors(axes).with_colors([rgb([170, 170, 170])]).with_radii([0.012]),
        )?;
        rec.log_static(
            format!("{TRACE_COMPUTED_PATH}/axes"),
            &rerun::Arrows3D::from_vectors(axes).with_colors(colors::SENSOR.map(rgb)).with_radii([0.012]),
        )?;
        let ins_label = format!("INS IMU axes (error ×{})", layout.exaggeration);
        // In a frame that does not turn with the axes (turning, the two labels met).
        let labels = [
            ([0.0f32, 0.0, -0.3], "true IMU axes".to_owned(), [170, 170, 170]),
            ([0.0f32, 0.0, 0.8], ins_label, colors::SENSOR[0]),
        ];
        rec.log_static(
            "world/ins_trace/labels",
            &rerun::Points3D::new(labels.iter().map(|(p, _, _)| *p))
                .with_labels(labels.iter().map(|(_, l, _)| l.as_str()))
                .with_radii([0.002])
                .with_colors(labels.iter().map(|(_, _, c)| super::palette::label(*c))),
        )?;
        Ok(())
    }
}
