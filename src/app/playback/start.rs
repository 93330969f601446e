//! How a replay starts when the log gives no attitude: the window at rest is read (found by the
//! rest scan, or declared), the IMU is aligned on it (`ins::align`), and what came out is reported
//! with its 1σ, the window, the disturbance and the latitude the data imply — with a warning where the
//! data contradict rest or the site.

use crate::ins::imu_errors::ImuErrors;
use std::collections::VecDeque;

use nalgebra::Vector3;
use serde::Serialize;

use super::{Playback, PlaybackError, Sample, data_err};
use crate::ins::align::{self, AlignConfig, Increment, RestScanner};
use crate::ins::sensor::Spec;
use crate::math::attitude::Attitude;
use crate::math::frames::{N, Rot, S};
use crate::math::units::{
    MPS_PER_SQRT_S_PER_UG_PER_SQRT_HZ, MPS2_PER_UG, RAD_PER_S_PER_DEG_PER_H, RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H,
    heading_deg_0_360,
};
use crate::model::gimbal::TableErrors;
use crate::scenario::logset::{DEFAULT_ALIGNMENT_S, LogSet};

/// The alignment as reported (terminal, summary JSON, recording).
#[derive(Debug, Clone, Serialize)]
pub struct AlignmentReport {
    /// What was done.
    pub method: String,
    /// The window, on the IMU file's clock, s.
    pub window_from_s: f64,
    /// Its end, s.
    pub window_to_s: f64,
    /// "detected rest" or "declared (initial.alignment_s)".
    pub window_source: String,
    /// The rest scan's threshold between one-second means of the specific force, m/s².
    pub rest_threshold_mps2: f64,
    /// Disturbance: the largest change between one-second means within the window, m/s².
    pub disturbance_change_mps2: f64,
    /// Disturbance: RMS of the zero-velocity innovations (what the vehicle's rocking moved), m/s.
    pub velocity_residual_rms_mps: f64,
    /// Pitch of the IMU's axes, deg.
    pub imu_pitch_deg: f64,
    /// Roll, deg.
    pub imu_roll_deg: f64,
    /// Heading (clockwise from North), deg.
    pub imu_heading_deg: f64,
    /// 1σ of pitch, roll, heading, deg.
    pub sigma_deg: [f64; 3],
    /// The body's attitude through the compensated table at the window's end [pitch, roll,
    /// heading], deg (a table's log; the same as the IMU's for a strapdown one).
    pub body_attitude_deg: [f64; 3],
    /// The heading of the coarse step alone, deg (to see what the fine step did).
    pub coarse_heading_deg: f64,
    /// Estimated gyro bias, sensor axes, °/h.
    pub gyro_bias_deg_per_h: [f64; 3],
    /// Its 1σ, °/h.
    pub gyro_bias_sigma_deg_per_h: [f64; 3],
    /// Estimated accelerometer bias, µg.
    pub accel_bias_ug: [f64; 3],
    /// Its 1σ, µg.
    pub accel_bias_sigma_ug: [f64; 3],
    /// The gyro bias 1σ the filter started from, °/h, and whether it was given.
    pub gyro_bias_prior_deg_per_h: (f64, bool),
    /// The accelerometer bias 1σ it started from, µg, and whether it was given.
    pub accel_bias_prior_ug: (f64, bool),
    /// The gyro angle random walk used, °/√h, and whether it was given (else measured).
    pub gyro_random_walk_deg_per_sqrt_h: (f64, bool),
    /// The accelerometer white noise used, µg/√Hz, and whether it was given.
    pub accel_white_noise_ug_per_sqrt_hz: (f64, bool),
    /// The site's latitude, deg.
    pub latitude_site_deg: f64,
    /// The latitude the data imply, deg, and its 1σ (None: too short a window).
    pub latitude_implied_deg: Option<(f64, f64)>,
    /// The attitude the IMU file's header states [pitch, roll, heading], deg, and where from (a PSINS
    /// .imu; "maybe inaccurate", its writer says): shown beside the alignment's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub header_attitude_deg: Option<([f64; 3], String)>,
    /// Where the data contradict rest or the site, or leave something undetermined.
    pub warnings: Vec<String>,
}

impl AlignmentReport {
    /// The lines printed at the end of a replay.
    #[must_use]
    pub fn text(&self) -> String {
        let mut s = format!(
            "alignment ({}): window {:.3} → {:.3} s on the file's clock ({}), {}\n",
            self.method,
            self.window_from_s,
            self.window_to_s,
            self.window_source,
            self.disturbance_text()
        );
        s.push_str(&format!(
            "  IMU attitude: pitch {:.4}° ± {}, roll {:.4}° ± {}, heading {:.4}° ± {} (1σ; coarse step alone {:.4}°)\n",
            self.imu_pitch_deg,
            sigma_text(self.sigma_deg[0]),
            self.imu_roll_deg,
            sigma_text(self.sigma_deg[1]),
            self.imu_heading_deg,
            sigma_text(self.sigma_deg[2]),
            self.coarse_heading_deg
        ));
        s.push_str(&format!(
            "  gyro bias [{}] °/h ± [{}] (prior 1σ {:.4} °/h, {}); accelerometer bias [{}] µg ± [{}] (prior {:.0} µg, {})\n",
            triple(&self.gyro_bias_deg_per_h, 4),
            triple(&self.gyro_bias_sigma_deg_per_h, 4),
            self.gyro_bias_prior_deg_per_h.0,
            given(self.gyro_bias_prior_deg_per_h.1),
            triple(&self.accel_bias_ug, 1),
            triple(&self.accel_bias_sigma_ug, 1),
            self.accel_bias_prior_ug.0,
            given(self.accel_bias_prior_ug.1)
        ));
        if let Some(([p, r, h], from)) = &self.header_attitude_deg {
            let dh = (self.body_attitude_deg[2] - h + 540.0).rem_euclid(360.0) - 180.0;
            s.push_str(&format!("  {from} says pitch {p:.4}°, roll {r:.4}°, heading {h:.4}°: the alignment's body heading differs by {dh:+.4}°\n"));
        }
        if let Some((lat, sigma)) = self.latitude_implied_deg {
            s.push_str(&format!(
                "  latitude: site {:.4}°, the data imply {lat:.3}° ± {sigma:.3}°\n",
                self.latitude_site_deg
            ));
        }
        for w in &self.warnings {
            s.push_str(&format!("  WARNING: {w}\n"));
        }
        s
    }

    fn disturbance_text(&self) -> String {
        format!(
            "disturbance: 1-s specific force means within {:.4} m/s² (threshold {:.3}), velocity residual {:.4} m/s RMS",
            self.disturbance_change_mps2, self.rest_threshold_mps2, self.velocity_residual_rms_mps
        )
    }
}

fn sigma_text(deg: f64) -> String {
    if deg < 1.0 / 60.0 {
        format!("{:.1}″", deg * 3600.0)
    } else if deg < 1.0 {
        format!("{:.2}′", deg * 60.0)
    } else {
        format!("{deg:.1}°")
    }
}

fn triple(v: &[f64; 3], decimals: usize) -> String {
    v.iter().map(|x| format!("{x:.decimals$}")).collect::<Vec<_>>().join(", ")
}

fn given(g: bool) -> &'static str {
    if g { "given" } else { "assumed from the measured noise: give initial.gyro_bias_deg_per_h / accel_bias_ug" }
}

/// The 1σ a spec implies: a σ, or the largest fixed value; None if zero.
fn spec_sigma(s: Spec) -> Option<f64> {
    let v = match s {
        Spec::Sigma(x) => x.abs(),
        Spec::Fixed(v) => v.iter().fold(0.0_f64, |m, x| m.max(x.abs())),
    };
    (v > 0.0).then_some(v)
}

/// The samples kept to give back to the INS when the start moves: 10 s at up to 10 kHz.
const HEAD_SAMPLES: usize = 100_000;

/// Samples of the alignment input at most this rate, Hz (summed in groups above it: the alignment
/// needs no more, and its memory stays a few MB for any IMU).
const ALIGN_MAX_HZ: f64 = 400.0;

/// Reads the window at rest, aligns, reports: (C_s^n at the window's end, the pre-roll, the report).
/// None: the vehicle moves at the start and the log's header gives a start (the samples read are put
/// back for the INS).
/// What [`aligned`] finds: C_s^n at the window's end, the pre-roll, the report.
/// An alignment's start: C_s^n at the window's end, the pre-roll, the report, and the biases it
/// estimated (the navigation removes them: the attitude and these biases are one solution of the
/// zero-velocity data, and the attitude alone leaves the bias estimate as a force error).
pub(super) type Aligned = (Rot<N, S>, Vec<Increment>, AlignmentReport, ImuErrors);

pub(super) fn aligned(
    pb: &mut Playback,
    log: &LogSet,
    compensation: &TableErrors,
    declared_s: Option<f64>,
    pre: usize,
) -> Result<Option<Aligned>, PlaybackError> {
    let f = &log.imu;
    let h = 1.0 / f.rate_hz;
    let per_block = align::block_samples(h);
    let max_s = declared_s.unwrap_or(DEFAULT_ALIGNMENT_S);
    let group = ((f.rate_hz / ALIGN_MAX_HZ).floor() as usize).max(1);
    let mut scanner = RestScanner::new(log.align.rest_threshold_mps2);
    let mut window: Vec<Increment> = Vec::new();
    let mut acc = (Vector3::zeros(), Vector3::zeros(), 0usize);
    let mut block: Vec<Sample> = Vec::with_capacity(per_block);
    let mut ring: VecDeque<Sample> = VecDeque::with_capacity(pre + 1);
    let mut first_t = None;
    let mut last_t = 0.0;
    let mut motion: Option<(f64, f64)> = None;
    let mut ended_by_motion = false;
    // The first seconds as read, to give them back to the INS if the start moves.
    let mut head: Vec<Sample> = Vec::new();
    loop {
        let s = pb.read()?;
        let done = match s {
            Some(s) => {
                first_t.get_or_insert(s.t_s);
                block.push(s);
                block.len() == per_block
            }
            None => true,
        };
        if !done {
            continue;
        }
        if block.is_empty() {
            break;
        }
        let increments: Vec<Increment> = block.iter().map(|s| (s.dtheta, s.dv)).collect();
        if block.len() == per_block
            && let Some(change) = scanner.push_block(&increments, h)
        {
            let at = block[0].t_s;
            if declared_s.is_none() {
                // The window ends before this block; its samples go to the INS.
                pb.pending.extend(block.drain(..));
                motion = Some((at, change));
                ended_by_motion = true;
                break;
            }
            motion.get_or_insert((at, change));
        }
        for s in block.drain(..) {
            if head.len() < HEAD_SAMPLES {
                head.push(s);
            }
            acc.0 += s.dtheta;
            acc.1 += s.dv;
            acc.2 += 1;
            if acc.2 == group {
                window.push((acc.0, acc.1));
                acc = (Vector3::zeros(), Vector3::zeros(), 0);
            }
            last_t = s.t_s;
            ring.push_back(s);
            if ring.len() > pre.max(1) {
                ring.pop_front();
            }
        }
        if s.is_none() || last_t - first_t.unwrap_or(0.0) >= max_s - 0.5 * h {
            break;
        }
    }
    let t0 = first_t.ok_or_else(|| data_err(format!("{}: no IMU samples to align on", f.path.display())))?;
    let span = last_t - t0 + h;
    let file_start_s = pb.file_start_s;
    let clock = |t: f64| file_start_s + t;
    if ended_by_motion && span < 10.0 && log.header_start.is_some() && head.len() < HEAD_SAMPLES {
        let moving: Vec<Sample> = pb.pending.drain(..).collect();
        pb.pending.extend(head.into_iter().chain(moving));
        return Ok(None);
    }
    if ended_by_motion && span < 10.0 {
        let (at, change) = motion.unwrap_or((t0, 0.0));
        return Err(data_err(format!(
            "{}: the vehicle is not at rest at the start (the 1-s mean specific force changes by {change:.3} m/s² at {:.3} s on the file's clock, after {span:.1} s; the threshold is {:.3} m/s², initial.rest_threshold_mps2): a moving start cannot be aligned — give the initial attitude ([initial] body_attitude_deg or --attitude-deg), velocity (velocity_enu_mps or --velocity-enu-mps) and position (position or --position), or a window at rest (initial.alignment_s)",
            f.path.display(),
            clock(at),
            log.align.rest_threshold_mps2
        )));
    }
    if ring.len() < pre {
        return Err(data_err(format!("{}: the log ends before the pre-roll ({pre} samples)", f.path.display())));
    }
    super::check_units_at_rest(log, span)?;
    let imu_spec = &log.table.ins.errors;
    let cfg = AlignConfig {
        latitude_rad: log.table.site.latitude_rad,
        height_m: log.table.site.height_m,
        interval_s: h * group as f64,
        gyro_bias_sigma_rad_per_s: log.align.gyro_bias_rad_per_s.or_else(|| spec_sigma(imu_spec.gyro.bias_rad_per_s)),
        accel_bias_sigma_mps2: log.align.accel_bias_mps2.or_else(|| spec_sigma(imu_spec.accel.bias_mps2)),
        gyro_random_walk: (imu_spec.gyro.noise.random_walk_si > 0.0).then_some(imu_spec.gyro.noise.random_walk_si),
        accel_random_walk: (imu_spec.accel.noise.random_walk_si > 0.0).then_some(imu_spec.accel.noise.random_walk_si),
    };
    let a = align::fine(&window, &cfg).map_err(|e| {
        data_err(format!("{}: alignment over {:.3} → {:.3} s: {e}", f.path.display(), clock(t0), clock(last_t)))
    })?;
    pb.origin_s = last_t;
    let pre_roll: Vec<Increment> = ring.iter().map(|s| (s.dtheta, s.dv)).collect();
    let (att, sigma) = a.attitude_with_sigma();
    // The body through the table at the window's end (t = 0 of the replay, before the FIR's delay).
    let b_from_s = pb.table_b_from_s(log, compensation, 0.0)?;
    let body = Attitude::from_n_from_b(&(a.n_from_s * b_from_s.inverse()));
    let coarse = Attitude::from_n_from_b(&Rot::from_quaternion(*a.coarse_n_from_s.quaternion()));
    let lat = align::implied_latitude(&window, cfg.interval_s, cfg.latitude_rad, a.bias_prior.0.value);
    let deg = f64::to_degrees;
    let mut warnings = Vec::new();
    let heading_sigma_deg = deg(sigma[2]);
    if heading_sigma_deg > 5.0 {
        warnings.push(format!(
            "the heading is not determined by these data (1σ {heading_sigma_deg:.1}°: a gyro bias of {:.3} °/h against the Earth's horizontal rate of {:.2} °/h here); give it: [initial] body_attitude_deg or --attitude-deg",
            a.bias_prior.0.value / RAD_PER_S_PER_DEG_PER_H,
            crate::model::earth::EARTH_RATE * cfg.latitude_rad.cos() / RAD_PER_S_PER_DEG_PER_H
        ));
    }
    if let Some((at, change)) = motion.filter(|_| !ended_by_motion) {
        warnings.push(format!("the data contradict rest inside the declared window: the 1-s mean specific force changes by {change:.3} m/s² at {:.3} s (threshold {:.3} m/s²)", clock(at), log.align.rest_threshold_mps2));
    }
    if a.velocity_residual_peak_mps > 0.5 {
        warnings.push(format!("the data contradict rest: the velocity reached {:.2} m/s between zero-velocity updates (RMS {:.3} m/s); the alignment is not trustworthy", a.velocity_residual_peak_mps, a.velocity_residual_rms_mps));
    }
    if let Some(l) = lat {
        let off = (l.latitude_rad - cfg.latitude_rad).abs();
        if off > 3.0 * l.sigma_rad && off > 0.5_f64.to_radians() {
            warnings.push(format!(
                "the data imply a latitude of {:.3}° ± {:.3}° (the rate at which gravity turns with the Earth), the site says {:.4}°: check the site ([initial] position, [site], the .imu header) or the gyros' scale",
                deg(l.latitude_rad),
                deg(l.sigma_rad),
                deg(cfg.latitude_rad)
            ));
        }
    }
    let per_h = |v: Vector3<f64>| (v / RAD_PER_S_PER_DEG_PER_H).into();
    let ug = |v: Vector3<f64>| (v / MPS2_PER_UG).into();
    let report = AlignmentReport {
        method: "inertial-frame coarse + 12-state Kalman filter on zero velocity".into(),
        // The start of the window's first sample's interval (the exact zero of a clock shows as 0).
        window_from_s: if (clock(t0) - h).abs() < 1e-9 { 0.0 } else { clock(t0) - h },
        window_to_s: clock(last_t),
        window_source: if declared_s.is_some() {
            "declared: initial.alignment_s".into()
        } else {
            format!(
                "detected rest{}",
                if ended_by_motion {
                    ", ended by motion"
                } else if span >= max_s - h {
                    ", 300 s at most"
                } else {
                    ", the whole log"
                }
            )
        },
        rest_threshold_mps2: log.align.rest_threshold_mps2,
        disturbance_change_mps2: scanner.largest_change_mps2,
        velocity_residual_rms_mps: a.velocity_residual_rms_mps,
        imu_pitch_deg: deg(att.pitch_rad),
        imu_roll_deg: deg(att.roll_rad),
        imu_heading_deg: heading_deg_0_360(att.heading_rad),
        sigma_deg: sigma.map(deg),
        body_attitude_deg: [deg(body.pitch_rad), deg(body.roll_rad), heading_deg_0_360(body.heading_rad)],
        coarse_heading_deg: heading_deg_0_360(coarse.heading_rad),
        gyro_bias_deg_per_h: per_h(a.gyro_bias_rad_per_s.0),
        gyro_bias_sigma_deg_per_h: per_h(a.gyro_bias_rad_per_s.1),
        accel_bias_ug: ug(a.accel_bias_mps2.0),
        accel_bias_sigma_ug: ug(a.accel_bias_mps2.1),
        gyro_bias_prior_deg_per_h: (a.bias_prior.0.value / RAD_PER_S_PER_DEG_PER_H, a.bias_prior.0.given),
        accel_bias_prior_ug: (a.bias_prior.1.value / MPS2_PER_UG, a.bias_prior.1.given),
        gyro_random_walk_deg_per_sqrt_h: (
            a.random_walk.0.value / RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H,
            a.random_walk.0.given,
        ),
        accel_white_noise_ug_per_sqrt_hz: (
            a.random_walk.1.value / MPS_PER_SQRT_S_PER_UG_PER_SQRT_HZ,
            a.random_walk.1.given,
        ),
        latitude_site_deg: deg(cfg.latitude_rad),
        latitude_implied_deg: lat.map(|l| (deg(l.latitude_rad), deg(l.sigma_rad))),
        header_attitude_deg: log.header_start.as_ref().map(|h| {
            (
                [deg(h.attitude.pitch_rad), deg(h.attitude.roll_rad), heading_deg_0_360(h.attitude.heading_rad)],
                h.source.clone(),
            )
        }),
        warnings,
    };
    let biases = ImuErrors::biases(a.gyro_bias_rad_per_s.0, a.accel_bias_mps2.0);
    Ok(Some((a.n_from_s, pre_roll, report, biases)))
}
