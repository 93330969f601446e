//! The instrument sections of a scenario: `[imu]` (with its presets) and `[navigation]` become
//! [`InsParams`], `[calibration]` becomes [`CalibConfig`].

use nalgebra::Vector3;

use super::ConfigError;
use super::raw::{RawCalibration, RawFir, RawImu, RawNavigation, RawSpec};
use super::validate::{Checker, ERROR_HINT, MAX_ERROR_ANGLE_ARCSEC};
use crate::calib::{CalibConfig, InsErrorModel, MonteCarloConfig, Nuisance};
use crate::ins::coning::Algorithm;
use crate::ins::nav::{NavOptions, Vertical};
use crate::ins::noise::IeeeTerms;
use crate::ins::sensor::{AccelSpec, DitherSpec, GyroSpec, Spec};
use crate::ins::{InsParams, fir};
use crate::math::units::{
    MPS2_PER_UG, RAD_PER_ARCMIN, RAD_PER_ARCSEC, RAD_PER_DEG, RAD_PER_S_PER_DEG_PER_H,
    RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H, STANDARD_GRAVITY_MPS2,
};
use crate::model::gimbal::TableErrors;

/// Starting values of the `[imu]` section; keys in the file override them.
#[must_use]
pub fn imu_preset(name: &str) -> Option<InsParams> {
    const DEG_PER_H: f64 = RAD_PER_S_PER_DEG_PER_H;
    const ARW: f64 = RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H;
    const UG: f64 = MPS2_PER_UG;
    let mut cfg = InsParams::ideal(200.0, Algorithm::TwoSampleP1);
    match name {
        "none" => {}
        // Jiang et al. 2017 Table 1 (the dual-axis RINS of Jiang et al.): biases 1σ, "<" limits taken as 1σ,
        // "50 µg/h^½" read as a velocity random walk of 50 µg/√Hz (docs/ins.md).
        "jiang2017-table1" => {
            cfg.errors.gyro = GyroSpec {
                bias_rad_per_s: Spec::Sigma(0.005 * DEG_PER_H),
                scale: Spec::Sigma(20e-6),
                misalignment_rad: 5.0 * RAD_PER_ARCSEC,
                noise: IeeeTerms { random_walk_si: 0.0005 * ARW, ..IeeeTerms::default() },
                ..GyroSpec::default()
            };
            cfg.errors.accel = AccelSpec {
                bias_mps2: Spec::Sigma(100.0 * UG),
                scale: Spec::Sigma(20e-6),
                misalignment_rad: 5.0 * RAD_PER_ARCSEC,
                noise: IeeeTerms { random_walk_si: 50.0 * UG, ..IeeeTerms::default() },
                ..AccelSpec::default()
            };
            cfg.errors.g_sensitivity = 0.0001 * DEG_PER_H / STANDARD_GRAVITY_MPS2;
        }
        // Zheng et al. 2016 §4.3 simulation: gyro random walk 3e-3 °/√h, accelerometer noise 20 µg/√Hz.
        "zheng2016" => {
            cfg.errors.gyro.noise.random_walk_si = 3e-3 * ARW;
            cfg.errors.accel.noise.random_walk_si = 20.0 * UG;
        }
        // Li et al. 2014 Table 4 (the DAMS laser INS), 2 kHz sampling, three dithered RLGs and the FIR. Its
        // "bias instability" is modelled as a first-order Gauss-Markov bias of that σ and a 1 h
        // correlation time (the model this preset always had; its Allan curve peaks at 0.62σ near
        // τ = 1.9 h, docs/allan.md).
        "li2014-table4" => {
            cfg.errors.gyro = GyroSpec {
                bias_rad_per_s: Spec::Sigma(0.01 * DEG_PER_H),
                scale: Spec::Sigma(2e-6),
                misalignment_rad: RAD_PER_ARCSEC,
                noise: IeeeTerms { random_walk_si: 0.0008 * ARW, ..IeeeTerms::default() },
                markov_sigma_rad_per_s: 0.005 * DEG_PER_H,
                correlation_s: 3600.0,
            };
            cfg.errors.accel = AccelSpec {
                bias_mps2: Spec::Sigma(2.0 * UG),
                scale: Spec::Sigma(5e-6),
                misalignment_rad: RAD_PER_ARCSEC,
                noise: IeeeTerms::default(),
                markov_sigma_mps2: 20.0 * UG,
                correlation_s: 3600.0,
            };
            cfg.errors.dither = DitherSpec {
                frequencies_hz: [335.4, 375.5, 425.7],
                amplitudes_rad: [500.0 * RAD_PER_ARCSEC; 3],
                coupling: 0.3,
            };
            cfg.fir_taps = fir::SEED001_TAPS.to_vec();
            cfg.zero_order_hold = true;
        }
        _ => return None,
    }
    Some(cfg)
}

fn spec(c: &Checker<'_>, key: &str, v: RawSpec, unit: &'static str, max: f64, to_si: f64) -> Result<Spec, ConfigError> {
    Ok(match v {
        RawSpec::Sigma(s) => {
            Spec::Sigma(c.range(key, s, unit, 0.0, max, "a number is the 1σ of a per-axis draw")? * to_si)
        }
        RawSpec::Fixed(a) => {
            let mut out = [0.0; 3];
            for (i, x) in a.iter().enumerate() {
                out[i] = c.range(&format!("{key}[{i}]"), *x, unit, -max, max, "")? * to_si;
            }
            Spec::Fixed(out)
        }
    })
}

/// `[imu]` with `[navigation]` at the IMU rate `step_hz` (None without `[imu]`; `[navigation]`
/// alone is refused).
pub(super) fn validate_ins(
    c: &Checker<'_>,
    imu: Option<&RawImu>,
    nav: Option<&RawNavigation>,
    step_hz: f64,
) -> Result<Option<InsParams>, ConfigError> {
    match imu {
        None if nav.is_some() => {
            Err(c.invalid("navigation", "needs an [imu] section (navigation runs on the IMU's increments)"))
        }
        None => Ok(None),
        Some(imu) => validate_imu(c, imu, nav, step_hz).map(Some),
    }
}

fn validate_imu(
    c: &Checker<'_>,
    raw: &RawImu,
    nav: Option<&RawNavigation>,
    step_hz: f64,
) -> Result<InsParams, ConfigError> {
    const DEG_PER_H: f64 = RAD_PER_S_PER_DEG_PER_H;
    const UG: f64 = MPS2_PER_UG;
    let preset_name = raw.preset.as_deref().unwrap_or("none");
    let mut cfg = imu_preset(preset_name).ok_or_else(|| {
        c.invalid("imu.preset", format!("\"{preset_name}\" is not a preset; use \"none\", \"jiang2017-table1\", \"zheng2016\" or \"li2014-table4\""))
    })?;
    cfg.rate_hz = step_hz;
    if let Some(a) = &raw.algorithm {
        cfg.algorithm = Algorithm::from_name(a).ok_or_else(|| {
            let names: Vec<&str> = Algorithm::ALL.iter().map(|a| a.name()).collect();
            c.invalid("imu.algorithm", format!("\"{a}\" is not an algorithm; use one of {names:?}"))
        })?;
    }
    if let Some(x) = raw.compare {
        cfg.compare = x;
    }
    if let Some(d) = raw.decimation {
        cfg.decimation = c.range("imu.decimation", f64::from(d), "samples", 1.0, 1000.0, "")? as usize;
    }
    match &raw.fir {
        None => {}
        Some(RawFir::Named(n)) if n == "seed001" => cfg.fir_taps = fir::SEED001_TAPS.to_vec(),
        Some(RawFir::Named(n)) if n == "none" => cfg.fir_taps = vec![1.0],
        Some(RawFir::Named(n)) => {
            return Err(
                c.invalid("imu.fir", format!("\"{n}\" is not a filter; use \"seed001\", \"none\" or a list of taps"))
            );
        }
        Some(RawFir::Taps(t)) => {
            if t.is_empty() || t.len() > 1001 {
                return Err(c.invalid("imu.fir", format!("{} taps given; 1 to 1001 are supported", t.len())));
            }
            for (i, x) in t.iter().enumerate() {
                c.finite(&format!("imu.fir[{i}]"), *x, "")?;
            }
            if t.iter().sum::<f64>().abs() < 1e-6 {
                return Err(c.invalid("imu.fir", "the taps sum to zero: the filter would remove the signal itself"));
            }
            cfg.fir_taps = t.clone();
        }
    }
    if let Some(z) = raw.zero_order_hold {
        cfg.zero_order_hold = z;
    }
    if let Some(ms) = raw.output_compensation_ms {
        cfg.output_compensation_s = c.range("imu.output_compensation_ms", ms, "ms", -1000.0, 1000.0, "")? * 1e-3;
    }
    if let Some(w) = raw.signal_window_s {
        cfg.signal_window_s = c.range("imu.signal_window_s", w, "s", 0.0, 60.0, "")?;
    }
    let g = &raw.gyro;
    let e = &mut cfg.errors;
    if let Some(v) = g.bias_deg_per_h {
        e.gyro.bias_rad_per_s = spec(c, "imu.gyro.bias_deg_per_h", v, "deg/h", 3600.0, DEG_PER_H)?;
    }
    if let Some(v) = g.scale_ppm {
        e.gyro.scale = spec(c, "imu.gyro.scale_ppm", v, "ppm", 1e5, 1e-6)?;
    }
    if let Some(v) = g.misalignment_arcsec {
        e.gyro.misalignment_rad =
            c.range("imu.gyro.misalignment_arcsec", v, "arcsec", 0.0, MAX_ERROR_ANGLE_ARCSEC, ERROR_HINT)?
                * RAD_PER_ARCSEC;
    }
    super::stochastic::gyro_terms(c, g, &mut e.gyro.noise, step_hz)?;
    if let Some(v) = g.markov_sigma_deg_per_h {
        e.gyro.markov_sigma_rad_per_s =
            c.range("imu.gyro.markov_sigma_deg_per_h", v, "deg/h", 0.0, 3600.0, "")? * DEG_PER_H;
    }
    if let Some(v) = g.correlation_time_s {
        e.gyro.correlation_s = c.positive("imu.gyro.correlation_time_s", v, "s", 1e9)?;
    }
    if let Some(v) = g.g_sensitivity_deg_per_h_per_g {
        e.g_sensitivity = c.range("imu.gyro.g_sensitivity_deg_per_h_per_g", v, "deg/h/g", -3600.0, 3600.0, "")?
            * DEG_PER_H
            / STANDARD_GRAVITY_MPS2;
    }
    let a = &raw.accel;
    if let Some(v) = a.bias_ug {
        e.accel.bias_mps2 = spec(c, "imu.accel.bias_ug", v, "µg", 1e5, UG)?;
    }
    if let Some(v) = a.scale_ppm {
        e.accel.scale = spec(c, "imu.accel.scale_ppm", v, "ppm", 1e5, 1e-6)?;
    }
    if let Some(v) = a.misalignment_arcsec {
        e.accel.misalignment_rad =
            c.range("imu.accel.misalignment_arcsec", v, "arcsec", 0.0, MAX_ERROR_ANGLE_ARCSEC, ERROR_HINT)?
                * RAD_PER_ARCSEC;
    }
    super::stochastic::accel_terms(c, a, &mut e.accel.noise, step_hz)?;
    if let Some(v) = a.markov_sigma_ug {
        e.accel.markov_sigma_mps2 = c.range("imu.accel.markov_sigma_ug", v, "µg", 0.0, 1e5, "")? * UG;
    }
    if let Some(v) = a.correlation_time_s {
        e.accel.correlation_s = c.positive("imu.accel.correlation_time_s", v, "s", 1e9)?;
    }
    let d = &raw.dither;
    if let Some(f) = d.frequencies_hz {
        for (i, x) in f.iter().enumerate() {
            e.dither.frequencies_hz[i] = c.range(
                &format!("imu.dither.frequencies_hz[{i}]"),
                *x,
                "Hz",
                0.0,
                0.5 * step_hz,
                "below half the IMU rate (simulation.step_hz)",
            )?;
        }
    }
    if let Some(amp) = d.amplitudes_arcsec {
        for (i, x) in amp.iter().enumerate() {
            e.dither.amplitudes_rad[i] =
                c.range(&format!("imu.dither.amplitudes_arcsec[{i}]"), *x, "arcsec", 0.0, MAX_ERROR_ANGLE_ARCSEC, "")?
                    * RAD_PER_ARCSEC;
        }
    }
    if let Some(k) = d.coupling {
        e.dither.coupling = c.range("imu.dither.coupling", k, "", 0.0, 1.0, "")?;
    }
    if let Some(n) = nav {
        let vertical = match n.vertical.as_str() {
            "held" => Vertical::Held,
            "free" => Vertical::Free,
            other => {
                return Err(
                    c.invalid("navigation.vertical", format!("\"{other}\" is not a mode; use \"held\" or \"free\""))
                );
            }
        };
        let mut err = [0.0; 3];
        for (i, x) in n.initial_attitude_error_arcmin.iter().enumerate() {
            err[i] =
                c.range(&format!("navigation.initial_attitude_error_arcmin[{i}]"), *x, "arcmin", -600.0, 600.0, "")?
                    * RAD_PER_ARCMIN;
        }
        cfg.navigation = Some(NavOptions {
            vertical,
            damping_per_s: if n.velocity_damping { crate::model::earth::schuler_rate() } else { 0.0 },
        });
        cfg.initial_error_rad = Vector3::from(err);
    }
    Ok(cfg)
}

/// The INS error a calibration allows for: the stated keys, else what `ins` simulates (its angle
/// random walk; its bias's 1σ — the RMS per axis of a fixed bias, which the calibration does not
/// know either — with a Gauss–Markov bias, nearly constant over a test, added in quadrature).
fn calibration_ins_error(
    c: &Checker<'_>,
    cal: &RawCalibration,
    ins: Option<&InsParams>,
) -> Result<InsErrorModel, ConfigError> {
    let gyro = ins.map(|i| i.errors.gyro);
    let walk = match cal.ins_random_walk_deg_per_sqrt_h {
        Some(v) => {
            c.range("calibration.ins_random_walk_deg_per_sqrt_h", v, "deg/sqrt(h)", 0.0, 100.0, "")?
                * RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H
        }
        None => gyro.map_or(0.0, |g| g.noise.random_walk_si),
    };
    let bias = match cal.ins_bias_deg_per_h {
        Some(v) => c.range("calibration.ins_bias_deg_per_h", v, "deg/h", 0.0, 3600.0, "")? * RAD_PER_S_PER_DEG_PER_H,
        None => gyro.map_or(0.0, |g| {
            let constant = match g.bias_rad_per_s {
                Spec::Sigma(s) => s,
                Spec::Fixed(v) => (v.iter().map(|x| x * x).sum::<f64>() / 3.0).sqrt(),
            };
            constant.hypot(g.markov_sigma_rad_per_s)
        }),
    };
    Ok(InsErrorModel { random_walk_rad_per_sqrt_s: walk, bias_sigma_rad_per_s: bias })
}

pub(super) fn validate_calibration(
    c: &Checker<'_>,
    cal: &RawCalibration,
    truth: &TableErrors,
    ins: Option<&InsParams>,
) -> Result<CalibConfig, ConfigError> {
    // The isotropic part: the INS and the reference, 1″ unless stated; the encoders' part comes
    // from their stated noise, per axis, in the direction each one acts.
    let measurement_sigma_rad = match cal.measurement_sigma_arcsec {
        Some(v) => {
            c.positive("calibration.measurement_sigma_arcsec", v, "arcsec", MAX_ERROR_ANGLE_ARCSEC)? * RAD_PER_ARCSEC
        }
        None => RAD_PER_ARCSEC,
    };
    let encoder_noise_rad: Vec<f64> = truth.axes.iter().map(|a| a.encoder_noise_rad).collect();
    let nuisance = match cal.nuisance.as_str() {
        "none" => Nuisance::None,
        "offset" => Nuisance::Offset,
        "offset+drift" => Nuisance::OffsetDrift,
        other => {
            return Err(c.invalid(
                "calibration.nuisance",
                format!("\"{other}\" is not a choice; use \"none\", \"offset\" or \"offset+drift\""),
            ));
        }
    };
    let mc = &cal.montecarlo;
    let pair = |key: &str, v: [f64; 2], unit: &'static str, lo: f64, hi: f64| -> Result<[f64; 2], ConfigError> {
        let a = c.range(&format!("calibration.montecarlo.{key}[0]"), v[0], unit, lo, hi, "")?;
        let b = c.range(&format!("calibration.montecarlo.{key}[1]"), v[1], unit, lo, hi, "")?;
        if b < a {
            return Err(c.invalid(
                &format!("calibration.montecarlo.{key}"),
                format!("[{a}, {b}]: the upper bound is below the lower one"),
            ));
        }
        Ok([a, b])
    };
    let montecarlo = MonteCarloConfig {
        runs: mc.runs,
        swing_half_angle_rad: pair(
            "swing_half_angle_arcsec",
            mc.swing_half_angle_arcsec,
            "arcsec",
            0.0,
            MAX_ERROR_ANGLE_ARCSEC,
        )?
        .map(|x| x * RAD_PER_ARCSEC),
        swing_phase_rad: pair("swing_phase_deg", mc.swing_phase_deg, "deg", -360.0, 360.0)?.map(|x| x * RAD_PER_DEG),
        non_orthogonality_rad: pair(
            "non_orthogonality_arcsec",
            mc.non_orthogonality_arcsec,
            "arcsec",
            -MAX_ERROR_ANGLE_ARCSEC,
            MAX_ERROR_ANGLE_ARCSEC,
        )?
        .map(|x| x * RAD_PER_ARCSEC),
        eta_measured_sigma_rad: mc
            .non_orthogonality_measured_sigma_arcsec
            .map(|v| {
                c.positive(
                    "calibration.montecarlo.non_orthogonality_measured_sigma_arcsec",
                    v,
                    "arcsec",
                    MAX_ERROR_ANGLE_ARCSEC,
                )
            })
            .transpose()?
            .map(|v| v * RAD_PER_ARCSEC),
    };
    Ok(CalibConfig {
        measurement_sigma_rad,
        encoder_noise_rad,
        measurement_sigma_stated: cal.measurement_sigma_arcsec.is_some(),
        ins_error: calibration_ins_error(c, cal, ins)?,
        prior_swing_sigma_rad: c.positive(
            "calibration.prior_swing_sigma_arcsec",
            cal.prior_swing_sigma_arcsec,
            "arcsec",
            MAX_ERROR_ANGLE_ARCSEC,
        )? * RAD_PER_ARCSEC,
        prior_eta_rad: c.range(
            "calibration.prior_non_orthogonality_arcsec",
            cal.prior_non_orthogonality_arcsec,
            "arcsec",
            -MAX_ERROR_ANGLE_ARCSEC,
            MAX_ERROR_ANGLE_ARCSEC,
            ERROR_HINT,
        )? * RAD_PER_ARCSEC,
        prior_eta_sigma_rad: c.positive(
            "calibration.prior_non_orthogonality_sigma_arcsec",
            cal.prior_non_orthogonality_sigma_arcsec,
            "arcsec",
            MAX_ERROR_ANGLE_ARCSEC,
        )? * RAD_PER_ARCSEC,
        nuisance,
        record_hz: c.positive("calibration.record_hz", cal.record_hz, "Hz", 1000.0)?,
        montecarlo,
    })
}
