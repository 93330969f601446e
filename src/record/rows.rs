//! The plotted series of a recording: which entities exist — decided once, from the scenario and
//! what is recorded (a simulation, a replay through a table, a strapdown replay) — and what each
//! row adds to each of them. What does not exist is neither logged, exported nor laid out.

use nalgebra::Vector3;

use super::ins_view::{self, InsLayout};
use super::{CLOSED_FORM_PATH, Recorder, ReplayKind, error_path};
use crate::ins::core::NavError;
use crate::ins::nav::{NavState, Vertical};
use crate::ins::pipeline::InsView;
use crate::math::attitude::Attitude;
use crate::math::units::{ARCSEC_PER_RAD, AngleUnit, DEG_PER_RAD};
use crate::model::gimbal::Chain;
use crate::scenario::Params;
use crate::sim::{DEMODULATIONS, ERROR_AXES, StepOutput};

/// The INS's own solution at a recorded row of a replay (a simulation records the truth and the
/// INS's errors instead).
#[derive(Debug, Clone, Copy)]
pub struct Solution {
    /// The primary algorithm's body attitude: its IMU's through the compensated table, or a
    /// strapdown IMU's own axes.
    pub body: Attitude,
    /// Its navigation state, when navigating.
    pub nav: Option<NavState>,
}

/// What an entity shows, row by row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Quantity {
    /// The table's attitude error about `ERROR_AXES[a]`, one line per demodulation shown.
    TableError(usize),
    /// The closed form − the exact chain (pitch, roll, heading).
    ClosedForm,
    /// The gimbal angles.
    GimbalAngles,
    /// The vehicle's true attitude (a simulation's).
    VehicleAttitude,
    /// Axis `k`'s swing rotation vector (its two components).
    Swing(usize),
    /// Each algorithm's attitude error about `ERROR_AXES[a]`.
    InsError(usize),
    /// Pure coning: log10 |heading error| and the analytic drift, per algorithm.
    ConingLog,
    /// A simulation's navigation errors: position (east, north, radial) and velocity.
    PositionError,
    /// The velocity error (a vehicle at rest: the velocity).
    VelocityError,
    /// A replay's INS solution: the body attitude (pitch, roll, heading).
    BodyAttitude,
    /// Its velocity (east, north and, with a free vertical channel, up).
    Velocity,
    /// Its position from the start (east, north).
    PositionFromStart,
    /// Its latitude and longitude.
    LatitudeLongitude,
    /// Its height (a free vertical channel only: held, it is the start's).
    Height,
}

/// One entity of `width` plotted series, buffered row-major.
pub(crate) struct Series {
    pub(crate) path: String,
    /// The names of its lines (the legend, and the export's columns).
    pub(crate) names: Vec<String>,
    pub(crate) values: Vec<f64>,
    pub(crate) what: Quantity,
    /// The last row sent and when (a live viewer's stream holds rows that repeat it).
    pub(crate) last_sent: Option<(Vec<f64>, std::time::Instant)>,
    /// The time of the newest row held back since (equal to the last row sent), s.
    pub(crate) held_until_s: Option<f64>,
}

/// Whether two rows hold the same values to a part in 10⁹ (a NaN row repeats a NaN row): a zero
/// error whose rounding flickers at 1e-13″ is a repeated row to a plot.
pub(crate) fn same_row(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| x.to_bits() == y.to_bits() || (x - y).abs() <= 1e-9 * x.abs().max(y.abs()).max(1.0))
}

impl Series {
    fn new(path: impl Into<String>, names: Vec<String>, what: Quantity) -> Self {
        Self { path: path.into(), names, values: Vec::new(), what, last_sent: None, held_until_s: None }
    }

    pub(crate) fn width(&self) -> usize {
        self.names.len()
    }
}

fn names(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| (*s).to_owned()).collect()
}

/// The body attitude's entity in a replay (the primary algorithm's).
pub const BODY_ATTITUDE_PATH: &str = "ins/body_attitude_deg";
/// The INS velocity's entity in a replay.
pub const VELOCITY_PATH: &str = "ins/velocity_enu_mps";
/// The INS position from the start, in a replay.
pub const POSITION_PATH: &str = "ins/position_from_start_m";
/// The INS latitude and longitude, in a replay.
pub const LAT_LON_PATH: &str = "ins/latitude_longitude_deg";
/// The INS height, in a replay with a free vertical channel.
pub const HEIGHT_PATH: &str = "ins/height_m";

/// The table's series: a simulation's three demodulations, gimbals, vehicle attitude, swings and
/// closed form; a replay's nominal and compensated table (one line, nominal − compensated, without
/// a reference), gimbals and swings; nothing for a strapdown IMU.
pub(crate) fn table_series(chain: &Chain, replay: Option<ReplayKind>, unit: AngleUnit) -> Vec<Series> {
    let demodulations: Vec<String> = match replay {
        None => DEMODULATIONS.iter().map(|v| v.replace('_', " ")).collect(),
        Some(ReplayKind { table: false, .. }) => return Vec::new(),
        Some(ReplayKind { reference: true, .. }) => names(&["nominal table", "compensated table"]),
        // The compensated demodulation is the reference: its own error would be zero.
        Some(ReplayKind { reference: false, .. }) => names(&["nominal − compensated table"]),
    };
    let mut series: Vec<Series> = ERROR_AXES
        .iter()
        .enumerate()
        .map(|(a, axis)| Series::new(error_path(unit, axis), demodulations.clone(), Quantity::TableError(a)))
        .collect();
    let axis_names: Vec<String> = chain.axes().iter().map(|a| a.name.clone()).collect();
    series.push(Series::new("gimbal_angle_deg", axis_names.clone(), Quantity::GimbalAngles));
    // A replay's "truth" is the reference (or the INS itself): the INS's attitude is its own series.
    if replay.is_none() {
        series.push(Series::new("vehicle_attitude_deg", names(&ERROR_AXES), Quantity::VehicleAttitude));
    }
    for (k, (name, g)) in axis_names.iter().zip(chain.axes()).enumerate() {
        let about = |v: &Vector3<f64>| format!("{name} swing about {}", super::scene::axis_letter(v));
        series.push(Series::new(format!("swing_arcsec/{name}"), vec![about(&g.e1), about(&g.e2)], Quantity::Swing(k)));
    }
    // The closed form's residual against the exact chain, where the two lines lie on each other.
    if replay.is_none() {
        series.push(Series::new(CLOSED_FORM_PATH, names(&ERROR_AXES), Quantity::ClosedForm));
    }
    series
}

/// The INS's series (appended to `series`) and what its recording adds, when `params` has an IMU.
pub(crate) fn ins_layout(params: &Params, replay: Option<ReplayKind>, series: &mut Vec<Series>) -> Option<InsLayout> {
    let cfg = params.ins.as_ref()?;
    let algorithms: Vec<String> = cfg.algorithms().iter().map(|a| a.name().to_owned()).collect();
    let n_algorithms = algorithms.len();
    // A replay without a reference has no errors to plot (they would be zero).
    let errors = replay.is_none_or(|k| k.reference);
    if errors {
        for (a, axis) in ERROR_AXES.iter().enumerate() {
            let lines = algorithms.iter().map(|alg| format!("{alg} {axis} error")).collect();
            series.push(Series::new(format!("ins/attitude_error_arcsec/{axis}"), lines, Quantity::InsError(a)));
        }
    }
    match (replay, cfg.navigation) {
        (_, None) => {}
        (None, Some(_)) => {
            series.push(Series::new(
                "ins/position_error_m",
                names(&["east", "north", "radial"]),
                Quantity::PositionError,
            ));
            series.push(Series::new(
                "ins/velocity_error_mps",
                names(&["east", "north", "up"]),
                Quantity::VelocityError,
            ));
        }
        (Some(_), Some(nav)) => {
            let free = nav.vertical == Vertical::Free;
            series.push(Series::new(
                VELOCITY_PATH,
                names(if free { &["east", "north", "up"] } else { &["east", "north"] }),
                Quantity::Velocity,
            ));
            series.push(Series::new(POSITION_PATH, names(&["east", "north"]), Quantity::PositionFromStart));
            series.push(Series::new(LAT_LON_PATH, names(&["latitude", "longitude"]), Quantity::LatitudeLongitude));
            if free {
                series.push(Series::new(HEIGHT_PATH, names(&["height"]), Quantity::Height));
            }
        }
    }
    if replay.is_some() {
        series.push(Series::new(BODY_ATTITUDE_PATH, names(&ERROR_AXES), Quantity::BodyAttitude));
    }
    // Pure coning on a table at rest: the drifts span decades, a log10 plot with the
    // analytic rates shows each algorithm on its line.
    let coning_log =
        params.table.vehicle.pure_coning().filter(|_| errors && params.table.scheme.max_rate() == 0.0).and_then(|_| {
            let lines = algorithms
                .iter()
                .flat_map(|a| [format!("{a}: log10 |heading error|"), format!("{a}: analytic coning drift")])
                .collect();
            series.push(Series::new(ins_view::CONING_LOG_PATH, lines, Quantity::ConingLog));
            ins_view::coning_rates(params, &cfg.algorithms()).map(ins_view::ConingLines::new)
        });
    // The INS trace and the drift dial draw the INS's error ×N: where the largest error of
    // the run is known in advance (pure coning: the analytic drifts), N is lowered to the
    // largest 1-2-5 factor that keeps it under 150°, so the picture never wraps round.
    let exaggeration = coning_log.as_ref().map_or(params.recording.exaggeration, |lines| {
        let worst_rad = lines.rates.iter().fold(0.0_f64, |m, r| m.max(*r)) * params.duration_s / ARCSEC_PER_RAD;
        let limit = 150.0 * crate::math::units::RAD_PER_DEG;
        if worst_rad * params.recording.exaggeration <= limit {
            return params.recording.exaggeration;
        }
        crate::math::units::nice_at_most(limit / worst_rad).max(1e-3)
    });
    Some(InsLayout {
        hidden: algorithms.iter().filter(|a| !params.recording.shows(a)).cloned().collect(),
        algorithms,
        errors,
        // A strapdown IMU's axes are drawn as the body (`body_view`), not as a trace beside a table.
        trace: replay.is_none_or(|k| k.table),
        signal_t: Vec::new(),
        raw: Vec::new(),
        filtered: Vec::new(),
        trace_axes: Vec::new(),
        // The dial turns by the errors: none without them.
        dial_on: n_algorithms >= 2 && errors,
        dial: Vec::new(),
        dial_t: Vec::new(),
        dial_next_t: f64::NEG_INFINITY,
        exaggeration,
        fir_taps: cfg.fir_taps.clone(),
        rate_hz: params.step_hz,
        signal_window_s: cfg.signal_window_s.max(0.01),
        coning_log,
        signal_peak_deg_per_s: [0.0; 2],
    })
}

/// What a row without a navigation view shows.
const NO_NAV: NavError = NavError {
    east_m: f64::NAN,
    north_m: f64::NAN,
    radial_m: f64::NAN,
    velocity_enu_mps: Vector3::new(f64::NAN, f64::NAN, f64::NAN),
};

impl Recorder {
    /// Buffers one row of every series from the table's step `out`, the INS's view `ins` (errors,
    /// navigation) and, in a replay, its own `solution`.
    pub(crate) fn push_values(&mut self, out: &StepOutput, ins: Option<&InsView>, solution: Option<&Solution>) {
        let Self { series, chain, truth, error_unit, ins: layout, .. } = self;
        let per_rad = error_unit.per_rad();
        let lines = layout.as_ref().and_then(|l| l.coning_log.as_ref());
        let nav = ins.and_then(|v| v.nav).unwrap_or(NO_NAV);
        let state = solution.and_then(|s| s.nav);
        for s in series.iter_mut() {
            let width = s.width();
            let v = &mut s.values;
            match s.what {
                Quantity::TableError(a) => v.extend(out.errors[..width].iter().map(|e| e.as_array()[a] * per_rad)),
                Quantity::ClosedForm => {
                    let (exact, closed) = (out.errors[0].as_array(), out.errors[2].as_array());
                    v.extend((0..3).map(|a| (closed[a] - exact[a]) * ARCSEC_PER_RAD));
                }
                Quantity::GimbalAngles => v.extend(out.gimbal_rad[..width].iter().map(|x| x * DEG_PER_RAD)),
                Quantity::VehicleAttitude => v.extend(
                    [out.attitude.pitch_rad, out.attitude.roll_rad, out.attitude.heading_rad].map(|x| x * DEG_PER_RAD),
                ),
                Quantity::Swing(k) => {
                    let g = &chain.axes()[k];
                    let sw = chain.swing_vector(k, &truth.axes[k], out.gimbal_rad[k]);
                    v.extend([sw.dot(&g.e1) * ARCSEC_PER_RAD, sw.dot(&g.e2) * ARCSEC_PER_RAD]);
                }
                Quantity::InsError(a) => match ins {
                    Some(view) => v.extend(view.errors.iter().map(|e| e.as_array()[a] * ARCSEC_PER_RAD)),
                    None => v.extend(std::iter::repeat_n(f64::NAN, width)),
                },
                Quantity::ConingLog => {
                    let log10 = |x: f64| if x > 0.0 && x.is_finite() { x.log10() } else { f64::NAN };
                    for j in 0..lines.map_or(0, |l| l.rates.len()) {
                        let measured =
                            ins.map_or(f64::NAN, |view| log10(view.errors[j].heading_rad.abs() * ARCSEC_PER_RAD));
                        v.extend([measured, log10(lines.map_or(f64::NAN, |l| l.at(j, out.t_s)))]);
                    }
                }
                Quantity::PositionError => v.extend([nav.east_m, nav.north_m, nav.radial_m]),
                Quantity::VelocityError => v.extend(nav.velocity_enu_mps.iter()),
                Quantity::BodyAttitude => match solution {
                    // Heading in (−180°, 180°]: a vehicle pointing North (most tests) does not jump by 360°.
                    Some(s) => {
                        v.extend([s.body.pitch_rad, s.body.roll_rad, s.body.heading_rad].map(|x| x * DEG_PER_RAD))
                    }
                    None => v.extend([f64::NAN; 3]),
                },
                Quantity::Velocity => {
                    v.extend(state.map_or([f64::NAN; 3], |n| [n.v_n.x, n.v_n.y, n.v_n.z])[..width].iter())
                }
                Quantity::PositionFromStart => v.extend([nav.east_m, nav.north_m]),
                Quantity::LatitudeLongitude => v.extend(
                    state.map_or([f64::NAN; 2], |n| [n.latitude_rad * DEG_PER_RAD, n.longitude_rad * DEG_PER_RAD]),
                ),
                Quantity::Height => v.push(state.map_or(f64::NAN, |n| n.height_m)),
            }
        }
    }

    /// True if the recording has the entity `path`.
    pub(crate) fn has_series(&self, path: &str) -> bool {
        self.series.iter().any(|s| s.path == path)
    }
}
