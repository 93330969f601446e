//! What a run with the INS in the loop adds to a recording: the INS error plots' styles, the raw and
//! filtered gyro signals of the first moments, the FIR's amplitude response and the trace of the
//! true and computed IMU axes beside the table.

use rerun::RecordingStreamResult;

use super::palette::{colors, rgb, rgba};
use super::{Recorder, SERIES_CHUNK_ROWS, rows};
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
    /// Per buffered scene frame, the true IMU axes then the computed ones (six arrows).
    pub(crate) trace_axes: Vec<[f32; 3]>,
    pub(crate) exaggeration: f64,
    pub(crate) fir_taps: Vec<f64>,
    pub(crate) rate_hz: f64,
    pub(crate) signal_window_s: f64,
    /// Largest |rate| in the raw and the filtered gyro window, deg/s (their plots' framing).
    pub(crate) signal_peak_deg_per_s: [f64; 2],
    /// Pure coning: each algorithm's analytic drift about the cone axis, drawn beside its
    /// measured error on the log10 drift plot.
    pub(crate) coning_log: Option<ConingLines>,
    /// With two algorithms or more: the drift dial, a needle per algorithm.
    pub(crate) dial_on: bool,
    /// The algorithms not shown (`[recording.show]`), by name.
    pub(crate) hidden: Vec<String>,
    /// Per buffered dial frame (at most [`DIAL_HZ`]: the errors grow slowly; at the scene's rate
    /// the dial would add 13 MB/h), each algorithm's needle.
    pub(crate) dial: Vec<[f32; 3]>,
    /// The dial's frame times, s, and the time of the next.
    pub(crate) dial_t: Vec<f64>,
    pub(crate) dial_next_t: f64,
}

/// Pure coning's analytic drift lines: each algorithm's |heading error| grows at its rate
/// (`ins::coning::coning_drift_rate`, arcsec/s); in a live session whose cone or sample rate
/// changed, from what it had reached at the change (`base` at `since_s`) at the new rate.
#[derive(Debug, Clone)]
pub(crate) struct ConingLines {
    /// Each algorithm's analytic drift rate now, arcsec/s.
    pub(crate) rates: Vec<f64>,
    /// Since when, s.
    pub(crate) since_s: f64,
    /// Each line's value then, arcsec.
    pub(crate) base: Vec<f64>,
}

impl ConingLines {
    /// Lines from t = 0 at `rates`.
    pub(crate) fn new(rates: Vec<f64>) -> Self {
        let base = vec![0.0; rates.len()];
        Self { rates, since_s: 0.0, base }
    }

    /// Algorithm `j`'s analytic |heading error| at `t_s`, arcsec.
    pub(crate) fn at(&self, j: usize, t_s: f64) -> f64 {
        self.base[j] + self.rates[j] * (t_s - self.since_s)
    }

    /// From `t_s` on, the lines grow at `rates` from where they are.
    pub(crate) fn change(&mut self, t_s: f64, rates: Vec<f64>) {
        self.base = (0..self.rates.len()).map(|j| self.at(j, t_s)).collect();
        self.since_s = t_s;
        self.rates = rates;
    }
}

/// Each algorithm's analytic drift rate about the cone axis for the pure cone of `params` at its
/// step rate, arcsec/s (None without one).
pub(crate) fn coning_rates(
    params: &crate::scenario::Params,
    algorithms: &[crate::ins::coning::Algorithm],
) -> Option<Vec<f64>> {
    let cone = params.table.vehicle.pure_coning()?;
    let freq_hz = cone.omega_rad_per_s / std::f64::consts::TAU;
    Some(
        algorithms
            .iter()
            .map(|a| {
                crate::ins::coning::coning_drift_rate(*a, cone.half_angle_rad, freq_hz, 1.0 / params.step_hz).abs()
                    * crate::math::units::ARCSEC_PER_RAD
            })
            .collect(),
    )
}

/// Frames per second of the drift dial, at most.
pub(crate) const DIAL_HZ: f64 = 4.0;

impl InsLayout {
    /// Whether the drift dial is drawn.
    pub(crate) fn dial_shown(&self) -> bool {
        self.dial_on
    }
}

/// The needles of the drift dial (one arrow per algorithm, in the dial's frame).
pub(crate) const DIAL_NEEDLES_PATH: &str = "world/drift_dial/needles";

/// Length of a dial needle.
const NEEDLE_LENGTH: f64 = 0.42;

/// A dial needle turned by `angle_rad` about the dial's axis (counter-clockwise when positive).
pub(crate) fn needle(angle_rad: f64) -> [f32; 3] {
    let (s, c) = angle_rad.sin_cos();
    [(-NEEDLE_LENGTH * s) as f32, (NEEDLE_LENGTH * c) as f32, 0.0]
}

/// The INS trace's arrows: the true IMU axes, then the computed ones (error ×N).
pub(crate) const TRACE_AXES_PATH: &str = "world/ins_trace/axes";

/// Length of a trace arrow.
pub(crate) const TRACE_AXIS_LENGTH: f64 = 0.6;

/// Where the drift dial (one needle per algorithm, turned by the size of its attitude error ×N) stands.
pub(crate) const DIAL_OFFSET: [f32; 3] = [2.3, 0.2, -0.5];

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

    /// Which algorithms' lines are shown (`[recording.show]`): the whole line of a hidden one, on
    /// every INS error plot and the coning plot (its needle on the dial stands at zero).
    pub(crate) fn log_shown_algorithms(&self) -> RecordingStreamResult<()> {
        let Some(layout) = &self.ins else { return Ok(()) };
        let shown: Vec<bool> = layout.algorithms.iter().map(|a| !layout.hidden.contains(a)).collect();
        for axis in ERROR_AXES.iter().filter(|_| layout.errors && layout.algorithms.len() > 1) {
            self.rec.log_static(
                format!("ins/attitude_error_arcsec/{axis}"),
                &rerun::SeriesLines::update_fields().with_visible_series(shown.iter().copied()),
            )?;
        }
        if layout.coning_log.is_some() {
            self.rec.log_static(
                CONING_LOG_PATH,
                &rerun::SeriesLines::update_fields().with_visible_series(shown.iter().flat_map(|v| [*v; 2])),
            )?;
        }
        Ok(())
    }

    /// Static parts of an INS run: series styles, the FIR's amplitude response, the trace's axes.
    pub(crate) fn log_ins_once(&self) -> RecordingStreamResult<()> {
        let Some(layout) = &self.ins else { return Ok(()) };
        let rec = &self.rec;
        // Each algorithm keeps its colour in every recording (by identity, not by position).
        let algo_colors: Vec<rerun::Color> =
            layout.algorithms.iter().map(|name| rgb(colors::algorithm(name))).collect();
        for axis in ERROR_AXES.iter().filter(|_| layout.errors) {
            let path = format!("ins/attitude_error_arcsec/{axis}");
            rec.log_static(
                path.as_str(),
                &rerun::SeriesLines::new().with_colors(algo_colors.clone()).with_names(self.series_names(&path)),
            )?;
        }
        if layout.coning_log.is_some() {
            // Measured: the algorithm's colour, wide; analytic: the same colour, thin.
            let colors: Vec<rerun::Color> =
                layout.algorithms.iter().flat_map(|name| [rgb(colors::algorithm(name)); 2]).collect();
            let widths: Vec<f32> = layout.algorithms.iter().flat_map(|_| [2.5, 1.0]).collect();
            rec.log_static(
                CONING_LOG_PATH,
                &rerun::SeriesLines::new()
                    .with_colors(colors)
                    .with_widths(widths)
                    .with_names(self.series_names(CONING_LOG_PATH)),
            )?;
        }
        self.log_shown_algorithms()?;
        // Pitch/roll/heading and east/north/up: red, green, blue.
        let three = [
            "ins/position_error_m",
            "ins/velocity_error_mps",
            rows::BODY_ATTITUDE_PATH,
            rows::VELOCITY_PATH,
            rows::POSITION_PATH,
            rows::LAT_LON_PATH,
            rows::HEIGHT_PATH,
        ];
        for path in three.into_iter().filter(|p| self.has_series(p)) {
            let names = self.series_names(path);
            rec.log_static(
                path,
                &rerun::SeriesLines::new()
                    .with_colors(colors::EULER[..names.len()].iter().map(|c| rgb(*c)))
                    .with_names(names),
            )?;
        }
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
        // The INS trace: true IMU axes (grey) and computed (coloured, error ×N), beside the table,
        // as six arrows of one entity (their directions on the timeline).
        rec.log_static("world/ins_trace", &rerun::Transform3D::from_translation(TRACE_OFFSET))?;
        let trace_colors = [[170, 170, 170]; 3].into_iter().chain(colors::SENSOR).map(rgb);
        rec.log_static(
            TRACE_AXES_PATH,
            &rerun::Arrows3D::update_fields().with_colors(trace_colors).with_radii([0.012]),
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
