//! The stochastic keys of `[imu.gyro]` and `[imu.accel]` by the names and units of IEEE Std 952 and
//! 1293 (Q, N, B, K, R, saturation), checked and converted to the SI [`IeeeTerms`] once.

use super::ConfigError;
use super::raw::{RawAccel, RawGyro};
use super::validate::Checker;
use crate::ins::noise::IeeeTerms;
use crate::math::units::{
    MPS_PER_SQRT_S_PER_UG_PER_SQRT_HZ, MPS2_PER_SQRT_S_PER_UG_PER_SQRT_H, MPS2_PER_UG, MPS3_PER_UG_PER_H,
    RAD_PER_ARCSEC, RAD_PER_DEG, RAD_PER_S_PER_DEG_PER_H, RAD_PER_S_PER_SQRT_S_PER_DEG_PER_H_PER_SQRT_H,
    RAD_PER_S2_PER_DEG_PER_H2, RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H, STANDARD_GRAVITY_MPS2,
};

/// One key: its name in the section, unit, SI per unit, and the largest value accepted.
struct Key {
    name: &'static str,
    unit: &'static str,
    to_si: f64,
    max: f64,
}

/// The keys of one section.
struct Section {
    path: &'static str,
    quantization: Key,
    pulse_weight: Key,
    random_walk: Key,
    bias_instability: Key,
    rate_random_walk: Key,
    rate_ramp: Key,
    saturation: Key,
    markov: &'static str,
}

/// The values a file gives (None: keep the preset's).
struct Given {
    quantization: Option<f64>,
    pulse_weight: Option<f64>,
    random_walk: Option<f64>,
    bias_instability: Option<f64>,
    range_s: Option<[f64; 2]>,
    rate_random_walk: Option<f64>,
    rate_ramp: Option<f64>,
    saturation: Option<f64>,
    correlation_given: bool,
}

/// The widest flat-floor range accepted (eight decades: at most 11 Gauss-Markov processes per axis).
const MAX_FLICKER_DECADES: f64 = 8.0;

fn terms(c: &Checker<'_>, s: &Section, g: &Given, out: &mut IeeeTerms, step_hz: f64) -> Result<(), ConfigError> {
    let key = |k: &Key| format!("{}.{}", s.path, k.name);
    let value =
        |k: &Key, v: f64| -> Result<f64, ConfigError> { Ok(c.range(&key(k), v, k.unit, 0.0, k.max, "")? * k.to_si) };
    match (g.quantization, g.pulse_weight) {
        (Some(_), Some(_)) => {
            return Err(c.invalid(
                &key(&s.pulse_weight),
                format!(
                    "give one of `{}` (Q) and `{}` (the pulse weight, √12·Q), not both",
                    s.quantization.name, s.pulse_weight.name
                ),
            ));
        }
        (Some(q), None) => out.quantization_si = value(&s.quantization, q)?,
        (None, Some(w)) => out.quantization_si = value(&s.pulse_weight, w)? / 12f64.sqrt(),
        (None, None) => {}
    }
    if let Some(v) = g.random_walk {
        out.random_walk_si = value(&s.random_walk, v)?;
    }
    if let Some(v) = g.bias_instability {
        if g.correlation_given {
            return Err(c.invalid(
                &key(&s.bias_instability),
                format!(
                    "is IEEE's bias instability B, flicker noise with a flat Allan floor of 0.664·B, and takes no correlation time; a first-order Gauss-Markov bias is `{}` with `correlation_time_s` (docs/allan.md)",
                    s.markov
                ),
            ));
        }
        out.bias_instability_si = value(&s.bias_instability, v)?;
    }
    if let Some([lo, hi]) = g.range_s {
        let k = format!("{}.bias_instability_range_s", s.path);
        let lo = c.positive(&format!("{k}[0]"), lo, "s", 1e7)?;
        let hi = c.positive(&format!("{k}[1]"), hi, "s", 1e7)?;
        if hi <= lo || (hi / lo).log10() > MAX_FLICKER_DECADES {
            return Err(c.invalid(&k, format!("[{lo}, {hi}] s: the upper end must be above the lower one, by at most {MAX_FLICKER_DECADES} decades (one Gauss-Markov process per decade)")));
        }
        if lo < 0.5 / step_hz {
            return Err(c.invalid(
                &k,
                format!(
                    "[{lo}, {hi}] s: the floor cannot start below half the IMU's sample interval ({} s)",
                    0.5 / step_hz
                ),
            ));
        }
        out.flicker_range_s = [lo, hi];
    }
    if let Some(v) = g.rate_random_walk {
        out.rate_random_walk_si = value(&s.rate_random_walk, v)?;
    }
    if let Some(v) = g.rate_ramp {
        let k = &s.rate_ramp;
        out.rate_ramp_si = c.range(&key(k), v, k.unit, -k.max, k.max, "signed")? * k.to_si;
    }
    if let Some(v) = g.saturation {
        let k = &s.saturation;
        out.saturation_si = Some(c.positive(&key(k), v, k.unit, k.max)? * k.to_si);
    }
    Ok(())
}

/// `[imu.gyro]`'s Q, N, B, K, R and saturation onto `out` (the preset's values where a key is absent).
pub(super) fn gyro_terms(c: &Checker<'_>, g: &RawGyro, out: &mut IeeeTerms, step_hz: f64) -> Result<(), ConfigError> {
    let section = Section {
        path: "imu.gyro",
        quantization: Key { name: "quantization_arcsec", unit: "arcsec", to_si: RAD_PER_ARCSEC, max: 1000.0 },
        pulse_weight: Key { name: "pulse_weight_arcsec", unit: "arcsec", to_si: RAD_PER_ARCSEC, max: 3600.0 },
        random_walk: Key {
            name: "arw_deg_per_sqrt_h",
            unit: "deg/√h",
            to_si: RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H,
            max: 100.0,
        },
        bias_instability: Key {
            name: "bias_instability_deg_per_h",
            unit: "deg/h",
            to_si: RAD_PER_S_PER_DEG_PER_H,
            max: 3600.0,
        },
        rate_random_walk: Key {
            name: "rate_random_walk_deg_per_h_per_sqrt_h",
            unit: "deg/h/√h",
            to_si: RAD_PER_S_PER_SQRT_S_PER_DEG_PER_H_PER_SQRT_H,
            max: 1e5,
        },
        rate_ramp: Key { name: "rate_ramp_deg_per_h2", unit: "deg/h²", to_si: RAD_PER_S2_PER_DEG_PER_H2, max: 1e6 },
        saturation: Key { name: "saturation_deg_per_s", unit: "deg/s", to_si: RAD_PER_DEG, max: 1e5 },
        markov: "markov_sigma_deg_per_h",
    };
    let given = Given {
        quantization: g.quantization_arcsec,
        pulse_weight: g.pulse_weight_arcsec,
        random_walk: g.arw_deg_per_sqrt_h,
        bias_instability: g.bias_instability_deg_per_h,
        range_s: g.bias_instability_range_s,
        rate_random_walk: g.rate_random_walk_deg_per_h_per_sqrt_h,
        rate_ramp: g.rate_ramp_deg_per_h2,
        saturation: g.saturation_deg_per_s,
        correlation_given: g.correlation_time_s.is_some(),
    };
    terms(c, &section, &given, out, step_hz)
}

/// `[imu.accel]`'s Q, N, B, K, R and saturation onto `out` (the preset's values where a key is absent).
pub(super) fn accel_terms(c: &Checker<'_>, a: &RawAccel, out: &mut IeeeTerms, step_hz: f64) -> Result<(), ConfigError> {
    let section = Section {
        path: "imu.accel",
        quantization: Key { name: "quantization_mps", unit: "m/s", to_si: 1.0, max: 1.0 },
        pulse_weight: Key { name: "pulse_weight_mps", unit: "m/s", to_si: 1.0, max: 3.0 },
        random_walk: Key {
            name: "vrw_ug_per_sqrt_hz",
            unit: "µg/√Hz",
            to_si: MPS_PER_SQRT_S_PER_UG_PER_SQRT_HZ,
            max: 1e5,
        },
        bias_instability: Key { name: "bias_instability_ug", unit: "µg", to_si: MPS2_PER_UG, max: 1e5 },
        rate_random_walk: Key {
            name: "acceleration_random_walk_ug_per_sqrt_h",
            unit: "µg/√h",
            to_si: MPS2_PER_SQRT_S_PER_UG_PER_SQRT_H,
            max: 1e7,
        },
        rate_ramp: Key { name: "acceleration_ramp_ug_per_h", unit: "µg/h", to_si: MPS3_PER_UG_PER_H, max: 1e7 },
        saturation: Key { name: "saturation_g", unit: "g", to_si: STANDARD_GRAVITY_MPS2, max: 1e4 },
        markov: "markov_sigma_ug",
    };
    let given = Given {
        quantization: a.quantization_mps,
        pulse_weight: a.pulse_weight_mps,
        random_walk: a.vrw_ug_per_sqrt_hz,
        bias_instability: a.bias_instability_ug,
        range_s: a.bias_instability_range_s,
        rate_random_walk: a.acceleration_random_walk_ug_per_sqrt_h,
        rate_ramp: a.acceleration_ramp_ug_per_h,
        saturation: a.saturation_g,
        correlation_given: a.correlation_time_s.is_some(),
    };
    terms(c, &section, &given, out, step_hz)
}
