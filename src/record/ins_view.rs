//! What a run with the INS in the loop adds to a recording: the INS error plots' styles, the raw and
//! filtered gyro signals of the first moments, the FIR's amplitude response and the trace of the
//! true and computed IMU axes beside the table.

use rerun::RecordingStreamResult;

use super::palette::{colors, rgb, rgba};
use super::{rows, Recorder, SERIES_CHUNK_ROWS};
use crate::ins::core::SampleOut;
use crate::math::units::DEG_PER_RAD;
use crate::sim::ERROR_AXES;

/// What a run with an IMU in the loop adds to the recording.
pub(crate) struct InsLayout {
    pub(crate) algorithms: Vec<String>,
    /// The attitude errors per algorithm are recorded (a simulation, a replay with a reference).
    pub(crate) errors: bool,
    /// The trace of the true and computed IMU axes beside the table (not for a strapdown IMU).
    pub(crate) trace: bool,
    pub(crate) signal_t: Vec<f64>,
    pub(crate) raw: Vec<f64>,
    pub(crate) filtered: Vec<f64>,
    pub(crate) trace_true: Vec<rerun::Quaternion>,
    pub(crate) trace_ins: Vec<rerun::Quaternion>,
    pub(crate) exaggeration: f64,
    pub(crate) fir_taps: Vec<f64>,
    pub(crate) rate_hz: f64,
    pub(crate) signal_window_s: f64,
    /// Largest |rate| in the raw and the filtered gyro window, deg/s (their plots' framing).
    pub(crate) signal_peak_deg_per_s: [f64; 2],
    /// Pure coning: the series index of the log10 drift plot and each algorithm's analytic drift
    /// rate about the cone axis, arcsec/s (`ins::coning::coning_drift_rate`).
    pub(crate) coning_log: Option<(usize, Vec<f64>)>,
    /// With two algorithms or more: per algorithm, the drift dial needle's rotation, at most
    /// [`DIAL_HZ`] (the errors grow slowly; at the scene's rate the dial would add 13 MB/h).
    pub(crate) dial: Vec<Vec<rerun::Quaternion>>,
    /// The dial's frame times, s, and the time of the next.
    pub(crate) dial_t: Vec<f64>,
    pub(crate) dial_next_t: f64,
}

/// Frames per second of the drift dial, at most.
pub(crate) const DIAL_HZ: f64 = 4.0;

/// Where the drift dial (one needle per algorithm, turned by the size of its attitude error ×N) stands.
pub(crate) const DIAL_OFFSET: [f32; 3] = [2.3, 0.2, -0.5];

/// The needle of algorithm `k` on the drift dial.
pub(crate) fn dial_path(name: &str) -> String {
    format!("world/drift_dial/{name}")
}

/// The log10 plot of the coning drift: each algorithm's |heading error| beside its analytic rate × t.
pub(crate) const CONING_LOG_PATH: &str = "ins/coning_drift_log10_arcsec";

/// The raw gyro signal of the first moments.
pub(crate) const GYRO_RAW_PATH: &str = "ins/gyro_raw_deg_per_s";
/// The gyro signal after the FIR (with a FIR only).
pub(crate) const GYRO_FILTERED_PATH: &str = "ins/gyro_filtered_deg_per_s";

/// The gyro signals' lines.
const GYRO_NAMES: [&str; 3] = ["gyro x", "gyro y", "gyro z"];

/// Where the INS trace (true and computed IMU axes) is drawn, beside the table.
pub(crate) const TRACE_OFFSET: [f32; 3] = [1.3, 1.3, -0.5];

impl Recorder {
    /// Buffers one raw and filtered gyro sample (the signal window at the IMU rate).
    pub fn push_signal(&mut self, s: &SampleOut) -> RecordingStreamResult<()> {
        let Some(layout) = self.ins.as_mut() else { return Ok(()) };
        layout.signal_t.push(s.t_s);
        layout.raw.extend(s.raw_rate_s.iter().map(|x| x * DEG_PER_RAD));
        layout.filtered.extend(s.filtered_rate_s.iter().map(|x| x * DEG_PER_RAD));
        layout.signal_peak_deg_per_s[0] = layout.signal_peak_deg_per_s[0].max(s.raw_rate_s.amax() * DEG_PER_RAD);
        layout.signal_peak_deg_per_s[1] = layout.signal_peak_deg_per_s[1].max(s.filtered_rate_s.amax() * DEG_PER_RAD);
        if layout.signal_t.len() >= SERIES_CHUNK_ROWS {
            self.flush_signal()?;
        }
        Ok(())
    }

    pub(crate) fn flush_signal(&mut self) -> RecordingStreamResult<()> {
        let Some(layout) = self.ins.as_mut() else { return Ok(()) };
        if layout.signal_t.is_empty() {
            return Ok(());
        }
        let times = std::mem::take(&mut layout.signal_t);
        let names = GYRO_NAMES.map(String::from);
        let (raw, filtered) = (std::mem::take(&mut layout.raw), std::mem::take(&mut layout.filtered));
        self.stream.send_series(GYRO_RAW_PATH, &names, &times, raw, 3)?;
        // Without a FIR the filtered signal is the raw one.
        if layout.fir_taps.len() > 1 {
            self.stream.send_series(GYRO_FILTERED_PATH, &names, &times, filtered, 3)?;
        }
        Ok(())
    }

    /// Static parts of an INS run: series styles, the FIR's amplitude response, the trace's axes.
    pub(crate) fn log_ins_once(&self) -> RecordingStreamResult<()> {
        let Some(layout) = &self.ins else { return Ok(()) };
        let rec = &self.rec;
        // Each algorithm keeps its colour in every recording (by identity, not by position).
        let algo_colors: Vec<rerun::Color> = layout.algorithms.iter().map(|name| rgb(colors::algorithm(name))).collect();
        for axis in ERROR_AXES.iter().filter(|_| layout.errors) {
            let path = format!("ins/attitude_error_arcsec/{axis}");
            rec.log_static(path.as_str(), &rerun::SeriesLines::new().with_colors(algo_colors.clone()).with_names(self.series_names(&path)))?;
        }
        if layout.coning_log.is_some() {
            // Measured: the algorithm's colour, wide; analytic: the same colour, thin.
            let colors: Vec<rerun::Color> = layout.algorithms.iter().flat_map(|name| [rgb(colors::algorithm(name)); 2]).collect();
            let widths: Vec<f32> = layout.algorithms.iter().flat_map(|_| [2.5, 1.0]).collect();
            rec.log_static(CONING_LOG_PATH, &rerun::SeriesLines::new().with_colors(colors).with_widths(widths).with_names(self.series_names(CONING_LOG_PATH)))?;
        }
        // Pitch/roll/heading and east/north/up: red, green, blue.
        let three = ["ins/position_error_m", "ins/velocity_error_mps", rows::BODY_ATTITUDE_PATH, rows::VELOCITY_PATH, rows::POSITION_PATH, rows::LAT_LON_PATH, rows::HEIGHT_PATH];
        for path in three.into_iter().filter(|p| self.has_series(p)) {
            let names = self.series_names(path);
            rec.log_static(path, &rerun::SeriesLines::new().with_colors(colors::EULER[..names.len()].iter().map(|c| rgb(*c))).with_names(names))?;
        }
        for path in [GYRO_RAW_PATH, GYRO_FILTERED_PATH].into_iter().take(if layout.fir_taps.len() > 1 { 2 } else { 1 }) {
            rec.log_static(path, &rerun::SeriesLines::new().with_colors(colors::SENSOR.map(rgb)).with_names(GYRO_NAMES))?;
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
        // The drift dial: a student sees the heading error of each algorithm accumulate, ×N, and
        // why a higher-order algorithm helps (the needles of the good ones barely move).
        if !layout.dial.is_empty() {
            let circle: Vec<[f32; 3]> = (0..=72).map(|i| {
                let a = f64::from(i) * std::f64::consts::TAU / 72.0;
                [(0.45 * a.cos()) as f32, (0.45 * a.sin()) as f32, 0.0]
            }).collect();
            rec.log_static("world/drift_dial", &rerun::Transform3D::from_translation(DIAL_OFFSET))?;
            rec.log_static("world/drift_dial/rim", &rerun::LineStrips3D::new([circle]).with_colors([rgba([200, 200, 200], 160)]).with_radii([0.004]))?;
            let title = format!("attitude error per algorithm, clockwise ×{} (a turn: {:.0}″)", layout.exaggeration, 360.0 * 3600.0 / layout.exaggeration);
            // The title above the dial (below it, it met the compass's E), the names in a column
            // to its right, spaced for their boxes, on points too small to cover a neighbour.
            let mut items: Vec<([f32; 3], String)> = vec![([0.0, 0.8, 0.0], title)];
            for (k, name) in layout.algorithms.iter().enumerate() {
                let path = dial_path(name);
                rec.log_static(path.as_str(), &rerun::Transform3D::IDENTITY)?;
                rec.log_static(format!("{path}/needle"), &rerun::Arrows3D::from_vectors([[0.0, 0.42, 0.0]]).with_colors([rgb(colors::algorithm(name))]).with_radii([0.01]))?;
                items.push(([0.7, 0.0, 0.5 - 0.14 * k as f32], name.clone()));
            }
            let colors: Vec<rerun::Color> = std::iter::once(super::palette::label([230, 230, 230])).chain(layout.algorithms.iter().map(|n| super::palette::label(colors::algorithm(n)))).collect();
            rec.log_static(
                "world/drift_dial/labels",
                &rerun::Points3D::new(items.iter().map(|(p, _)| *p)).with_labels(items.iter().map(|(_, t)| t.as_str())).with_colors(colors).with_radii([0.002]),
            )?;
        }
        if !layout.trace {
            return Ok(());
        }
        // The INS trace: true IMU axes (grey) and computed (coloured, error ×N), beside the table.
        let ins_label = format!("INS IMU axes (error ×{})", layout.exaggeration);
        for (path, colors, label) in [("world/ins_trace/true", [[170, 170, 170]; 3], "true IMU axes"), ("world/ins_trace/ins", colors::SENSOR, ins_label.as_str())] {
            rec.log_static(path, &rerun::Transform3D::from_translation(TRACE_OFFSET))?;
            rec.log_static(
                format!("{path}/axes"),
                &rerun::Arrows3D::from_vectors([[0.6, 0.0, 0.0], [0.0, 0.6, 0.0], [0.0, 0.0, 0.6]]).with_colors(colors.map(rgb)).with_radii([0.012]),
            )?;
            // In a frame that does not turn with the axes (turning, the two labels met).
            let at = if path.ends_with("true") { [0.0f32, 0.0, -0.3] } else { [0.0f32, 0.0, 0.8] };
            let labels = format!("world/ins_trace_labels/{}", if path.ends_with("true") { "true" } else { "ins" });
            rec.log_static(labels.as_str(), &rerun::Transform3D::from_translation(TRACE_OFFSET))?;
            rec.log_static(format!("{labels}/label"), &rerun::Points3D::new([at]).with_labels([label]).with_radii([0.002]).with_colors([super::palette::label(colors[0])]))?;
        }
        Ok(())
    }
}
