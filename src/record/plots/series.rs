//! Which series a recording plots — decided once, from the scenario and what is recorded (a
//! simulation, a replay through a table, a strapdown replay). What does not exist is neither
//! logged, exported nor laid out.

use nalgebra::Vector3;

use super::coning::{self, ConingLines};
use super::envelope::Rows;
use crate::ins::nav::{NavState, Vertical};
use crate::math::attitude::Attitude;
use crate::math::units::AngleUnit;
use crate::model::gimbal::Chain;
use crate::record::{CLOSED_FORM_PATH, ReplayKind, error_path};
use crate::scenario::Params;
use crate::sim::{DEMODULATIONS, ERROR_AXES};

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
    /// Every sample's row since the last flush (exported at full rate, then dropped).
    pub(crate) values: Vec<f64>,
    /// What the plot draws of them: the per-bucket envelope's rows, from its `lines` of the plots'
    /// shared [`super::envelope::Bucket`] (where `Plots::set_series_hz` places them).
    pub(crate) rows: Rows,
    pub(crate) lines: std::ops::Range<usize>,
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
    pub(crate) fn new(path: impl Into<String>, names: Vec<String>, what: Quantity) -> Self {
        Self {
            path: path.into(),
            names,
            values: Vec::new(),
            rows: Rows::default(),
            lines: 0..0,
            what,
            last_sent: None,
            held_until_s: None,
        }
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
        let about = |v: &Vector3<f64>| format!("{name} swing about {}", crate::record::scene::axis_letter(v));
        series.push(Series::new(format!("swing_arcsec/{name}"), vec![about(&g.e1), about(&g.e2)], Quantity::Swing(k)));
    }
    // The closed form's residual against the exact chain, where the two lines lie on each other.
    if replay.is_none() {
        series.push(Series::new(CLOSED_FORM_PATH, names(&ERROR_AXES), Quantity::ClosedForm));
    }
    series
}

/// The INS's plots: which algorithms, which of them are hidden, whether their errors are plotted,
/// pure coning's analytic lines.
pub(crate) struct InsSeries {
    pub(crate) algorithms: Vec<String>,
    /// The algorithms not shown (`[recording.show]`), by name.
    pub(crate) hidden: Vec<String>,
    /// The attitude errors per algorithm are recorded (a simulation, a replay with a reference).
    pub(crate) errors: bool,
    /// Pure coning: each algorithm's analytic drift about the cone axis, drawn beside its
    /// measured error on the log10 drift plot.
    pub(crate) coning: Option<ConingLines>,
}

/// The INS's series (appended to `series`), when `params` has an IMU.
pub(crate) fn ins_series(params: &Params, replay: Option<ReplayKind>, series: &mut Vec<Series>) -> Option<InsSeries> {
    let cfg = params.ins.as_ref()?;
    let algorithms: Vec<String> = cfg.algorithms().iter().map(|a| a.name().to_owned()).collect();
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
            series.push(Series::new(coning::CONING_LOG_PATH, lines, Quantity::ConingLog));
            coning::coning_rates(params, &cfg.algorithms()).map(ConingLines::new)
        });
    Some(InsSeries {
        hidden: algorithms.iter().filter(|a| !params.recording.shows(a)).cloned().collect(),
        algorithms,
        errors,
        coning: coning_log,
    })
}
