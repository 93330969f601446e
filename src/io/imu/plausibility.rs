//! Static-segment plausibility: do the first seconds of a log look like an IMU at rest, in the declared units?
//!
//! At rest an accelerometer measures gravity, |f| ≈ 9.8 m/s² (or 9.8·dt m/s per sample as
//! increments), and a gyro measures at most the Earth rate, 7.292115e-5 rad/s, plus its bias. A
//! file whose numbers are off by the factors that wrong declarations produce gets a message saying
//! what the numbers look like: rates declared as increments (off by 1/dt), increments declared as
//! rates (off by dt), g declared as m/s² and the reverse (off by 9.80665), and degrees declared
//! as radians (off by 180/π). (Radians declared as degrees is not flagged: a simulated gyro
//! without Earth rate reads as little at rest.)

use crate::io::error::Result;
use crate::io::imu::units::STANDARD_GRAVITY_MPS2 as G0;
use crate::io::imu::{ImuEvent, ImuOptions, ImuReader, Layout, SampleKind, StaticCheck};
use nalgebra::Vector3;
use std::path::Path;

pub use crate::math::units::EARTH_RATE_RAD_PER_S;

/// What the static segment showed.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticReport {
    /// Samples examined.
    pub samples: usize,
    /// Their time span, s.
    pub duration_s: f64,
    /// Median sampling interval, s.
    pub dt_s: f64,
    /// Mean specific force as a rate (m/s²), RFU; increments are divided by dt.
    pub accel_mean_mps2: Vector3<f64>,
    /// Mean angular rate (rad/s), RFU; increments are divided by dt.
    pub gyro_mean_rad_per_s: Vector3<f64>,
    /// Everything implausible, one message each, naming the columns; empty when all is well.
    pub problems: Vec<String>,
}

fn near(value: f64, target: f64, tolerance: f64) -> bool {
    (value - target).abs() <= tolerance * target
}

fn kind_fix(layout: &Layout, want: SampleKind) -> String {
    match (layout, want) {
        (Layout::Rinscope, SampleKind::Increments) => {
            "set kind = increments: name the columns dtheta_{x,y,z}_rad and dv_{x,y,z}_mps".into()
        }
        (Layout::Rinscope, SampleKind::Rates) => {
            "set kind = rates: name the columns gyro_{x,y,z}_rad_per_s and accel_{x,y,z}_mps2".into()
        }
        (other, want) => format!(
            "the {other:?} layout is fixed to {}; this file holds {}: convert it, or write it in the rinscope layout with {} columns",
            if want == SampleKind::Rates { "increments" } else { "rates" },
            if want == SampleKind::Rates { "rates" } else { "increments" },
            if want == SampleKind::Rates { "gyro_*/accel_*" } else { "dtheta_*/dv_*" },
        ),
    }
}

/// Reads the first [`StaticCheck::duration_s`] seconds of `path` and judges them.
///
/// `options.static_check` and `options.gap_policy` are ignored (gaps are skipped over).
///
/// # Errors
/// Only what reading the file reports; implausible data are [`StaticReport::problems`].
pub fn check_static(path: impl AsRef<Path>, options: &ImuOptions, check: &StaticCheck) -> Result<StaticReport> {
    let path = path.as_ref();
    let mut opts = options.clone();
    opts.static_check = None;
    opts.gap_policy = crate::io::imu::GapPolicy::Split;
    let mut reader = ImuReader::open(path, &opts)?;
    let kind = reader.kind();
    let columns = reader.columns().to_vec();
    let (mut sum_g, mut sum_a) = (Vector3::zeros(), Vector3::zeros());
    // The size of the specific force sample by sample: a table turning the IMU turns its direction,
    // not its size (the mean vector of a turning IMU is not gravity's size).
    let mut sum_a_norm = 0.0;
    let mut times = Vec::new();
    for event in reader.by_ref() {
        let ImuEvent::Sample(s) = event? else {
            continue;
        };
        if s.t_s > check.duration_s {
            break;
        }
        sum_g += s.gyro;
        sum_a += s.accel;
        sum_a_norm += s.accel.norm();
        times.push(s.t_s);
        if times.len() >= 1_000_000 {
            break;
        }
    }
    let n = times.len();
    let mut dts: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    dts.sort_by(f64::total_cmp);
    let dt = dts.get(dts.len() / 2).copied().unwrap_or(f64::NAN);
    let mean_g = if n > 0 { sum_g / n as f64 } else { Vector3::zeros() };
    let mean_a = if n > 0 { sum_a / n as f64 } else { Vector3::zeros() };
    let (rate_g, rate_a) = match kind {
        SampleKind::Rates => (mean_g, mean_a),
        SampleKind::Increments => (mean_g / dt, mean_a / dt),
    };
    let mut report = StaticReport {
        samples: n,
        duration_s: times.last().copied().unwrap_or(0.0),
        dt_s: dt,
        accel_mean_mps2: rate_a,
        gyro_mean_rad_per_s: rate_g,
        problems: Vec::new(),
    };
    if n < 10 || dt.is_nan() || dt <= 0.0 {
        report
            .problems
            .push(format!("only {n} samples in the first {} s: too few to check the static segment", check.duration_s));
        return Ok(report);
    }
    let accel_cols = columns.get(4..7).map_or_else(String::new, |c| c.join(", "));
    let gyro_cols = columns.get(1..4).map_or_else(String::new, |c| c.join(", "));
    let hz = 1.0 / dt;
    let tol = check.gravity_tolerance;
    let a = if n > 0 { sum_a_norm / n as f64 } else { 0.0 };
    let per = |x: f64| {
        if kind == SampleKind::Rates { format!("{x:.4} m/s²") } else { format!("{x:.4} m/s per sample") }
    };
    let lead = format!(
        "accelerometer columns {accel_cols}: the mean magnitude over the first {:.1} s is {}",
        report.duration_s,
        per(a)
    );
    // `diagnosed`: the numbers match a known wrong declaration, which also scales the gyro.
    let (accel_problem, diagnosed) = match kind {
        SampleKind::Rates if near(a, G0, tol) => (None, false),
        SampleKind::Increments if near(a / dt, G0, tol) => (None, false),
        SampleKind::Rates if near(a / dt, G0, tol) => (
            Some(format!(
                "{lead}; read as m/s per sample that is {:.2} m/s² at {hz:.0} Hz: these look like increments, not rates; {}",
                a / dt,
                kind_fix(&options.layout, SampleKind::Increments)
            )),
            true,
        ),
        SampleKind::Increments if near(a, G0, tol) => (
            Some(format!(
                "{lead} = {:.1} m/s² at {hz:.0} Hz; read as m/s² it would be {a:.2} m/s²: these look like rates, not increments; {}",
                a / dt,
                kind_fix(&options.layout, SampleKind::Rates)
            )),
            true,
        ),
        SampleKind::Rates if near(a * G0, G0, tol) => (
            Some(format!(
                "{lead}: that is 1 g; the values look like units of g declared as m/s² (name the columns accel_*_g)"
            )),
            false,
        ),
        SampleKind::Rates if near(a / G0, G0, tol) => (
            Some(format!(
                "{lead} = {:.1} g: the values look like m/s² declared as g (name the columns accel_*_mps2)",
                a / G0
            )),
            false,
        ),
        _ => (
            Some(format!(
                "{lead}, {} as specific force, not the ~{G0} m/s² of gravity: the segment is not static, or the units or kind are wrong",
                if kind == SampleKind::Rates { format!("{a:.4} m/s²") } else { format!("{:.4} m/s²", a / dt) }
            )),
            false,
        ),
    };
    report.problems.extend(accel_problem);
    let w = rate_g.norm();
    let max = check.max_gyro_rad_per_s;
    let gyro_lead = format!(
        "gyro columns {gyro_cols}: the mean angular rate over the first {:.1} s is {w:.3e} rad/s = {:.1} × Earth rate",
        report.duration_s,
        w / EARTH_RATE_RAD_PER_S
    );
    let deg = std::f64::consts::PI / 180.0;
    if w > max && !diagnosed {
        if w * deg <= max {
            report.problems.push(format!(
                "{gyro_lead}: as degrees it would be {:.3e} rad/s = {:.1} × Earth rate; these look like degrees declared as radians (use a _deg or _deg_per_s unit)",
                w * deg,
                w * deg / EARTH_RATE_RAD_PER_S
            ));
        } else {
            report.problems.push(format!(
                "{gyro_lead}, above the {max:.3e} rad/s accepted: the segment is not static, the gyro bias is large (raise StaticCheck::max_gyro_rad_per_s), or the units are wrong"
            ));
        }
    }
    Ok(report)
}
