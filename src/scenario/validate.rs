//! Validation of the scenario file: every number checked with its key, value and unit, and the
//! conversion into the layers' parameter structs (SI, radians).

use std::collections::BTreeMap;

use nalgebra::Vector3;

use super::raw::{RawAxisCompensation, RawCompensation, RawConfig, RawRecording, RawScheme, RawSite, RawTurntable};
use super::{ConfigError, Params, RecordingParams, ScenarioMeta, instruments};
use crate::math::attitude::Attitude;
use crate::math::units::{RAD_PER_ARCSEC, RAD_PER_DEG};
use crate::model::earth::Site;
use crate::model::gimbal::{AxisErrors, AxisGeometry, Chain, TableErrors};
use crate::model::motion::{AngleKind, Ramp, VehicleMotion, Wobble};
use crate::model::scheme::{IndexedStep, Scheme};
use crate::sim::TableParams;

/// A helper that knows the file name and checks numbers with their keys and units.
pub(super) struct Checker<'a> {
    pub(super) origin: &'a str,
}

impl Checker<'_> {
    pub(super) fn finite(&self, key: &str, value: f64, unit: &'static str) -> Result<f64, ConfigError> {
        if value.is_finite() {
            Ok(value)
        } else {
            Err(ConfigError::NotFinite { origin: self.origin.to_owned(), key: key.to_owned(), value, unit })
        }
    }

    /// Checks `lo <= value <= hi` (and finiteness).
    pub(super) fn range(
        &self,
        key: &str,
        value: f64,
        unit: &'static str,
        lo: f64,
        hi: f64,
        hint: &str,
    ) -> Result<f64, ConfigError> {
        self.finite(key, value, unit)?;
        if value < lo || value > hi {
            let mut range =
                format!("allowed {} ..= {} {unit}", crate::io::short_number(lo), crate::io::short_number(hi));
            if !hint.is_empty() {
                range.push_str(" (");
                range.push_str(hint);
                range.push(')');
            }
            return Err(ConfigError::OutOfRange {
                origin: self.origin.to_owned(),
                key: key.to_owned(),
                value,
                unit,
                range,
            });
        }
        Ok(value)
    }

    /// Checks `lo < value <= hi`.
    pub(super) fn positive(&self, key: &str, value: f64, unit: &'static str, hi: f64) -> Result<f64, ConfigError> {
        self.finite(key, value, unit)?;
        if value <= 0.0 || value > hi {
            return Err(ConfigError::OutOfRange {
                origin: self.origin.to_owned(),
                key: key.to_owned(),
                value,
                unit,
                range: format!("must be > 0 and <= {} {unit}", crate::io::short_number(hi)),
            });
        }
        Ok(value)
    }

    pub(super) fn invalid(&self, key: &str, message: impl Into<String>) -> ConfigError {
        ConfigError::Invalid { origin: self.origin.to_owned(), key: key.to_owned(), message: message.into() }
    }
}

/// Largest error angle accepted anywhere, arcsec: 10 deg. Turntable errors are arcseconds to
/// arcminutes; a value this large is a typo (degrees typed into an arcsec key, say).
pub const MAX_ERROR_ANGLE_ARCSEC: f64 = 36_000.0;
pub(super) const ERROR_HINT: &str = "turntable errors are arcsec to arcmin; over 10 deg is a typo";

fn angle_kind(c: &Checker<'_>, key: &str, s: &str) -> Result<AngleKind, ConfigError> {
    match s {
        "pitch" => Ok(AngleKind::Pitch),
        "roll" => Ok(AngleKind::Roll),
        "heading" => Ok(AngleKind::Heading),
        other => {
            Err(c.invalid(key, format!("\"{other}\" is not an Euler angle; use \"pitch\", \"roll\" or \"heading\"")))
        }
    }
}

pub(super) fn validate(raw: RawConfig, origin: &str) -> Result<Params, ConfigError> {
    let c = Checker { origin };

    // [scenario]
    if raw.scenario.name.trim().is_empty()
        || !raw.scenario.name.chars().all(|ch| ch.is_ascii_alphanumeric() || ch == '-' || ch == '_')
    {
        return Err(c.invalid(
            "scenario.name",
            format!(
                "\"{}\" must be non-empty and use only letters, digits, '-' and '_' (it names the recording file)",
                raw.scenario.name
            ),
        ));
    }

    // [simulation]
    let step_hz = c.range("simulation.step_hz", raw.simulation.step_hz, "Hz", 1.0, 100_000.0, "")?;
    let duration_s = c.positive("simulation.duration_s", raw.simulation.duration_s, "s", super::MAX_DURATION_S)?;
    if duration_s * step_hz > 2.0e9 {
        return Err(c.invalid(
            "simulation.duration_s",
            format!("{duration_s} s at {step_hz} Hz is {:.3e} steps; at most 2e9 are supported", duration_s * step_hz),
        ));
    }

    let site = site(&c, &raw.site)?;

    // [vehicle]
    let pitch_hint = "Euler angles are singular at +-90 deg pitch";
    let base = Attitude {
        pitch_rad: c.range("vehicle.pitch_deg", raw.vehicle.pitch_deg, "deg", -85.0, 85.0, pitch_hint)? * RAD_PER_DEG,
        roll_rad: c.range("vehicle.roll_deg", raw.vehicle.roll_deg, "deg", -180.0, 180.0, "")? * RAD_PER_DEG,
        heading_rad: c.range("vehicle.heading_deg", raw.vehicle.heading_deg, "deg", -360.0, 360.0, "")? * RAD_PER_DEG,
    };
    let mut ramps = Vec::new();
    for (i, r) in raw.vehicle.ramp.iter().enumerate() {
        let k = |f: &str| format!("vehicle.ramp[{i}].{f}");
        let kind = angle_kind(&c, &k("angle"), &r.angle)?;
        let (lo, hi, hint) = match kind {
            AngleKind::Pitch => (-85.0, 85.0, pitch_hint),
            AngleKind::Roll => (-180.0, 180.0, ""),
            AngleKind::Heading => (-3600.0, 3600.0, ""),
        };
        ramps.push(Ramp {
            angle: kind,
            start_s: c.range(&k("start_s"), r.start_s, "s", 0.0, duration_s, "within the run")?,
            target_rad: c.range(&k("target_deg"), r.target_deg, "deg", lo, hi, hint)? * RAD_PER_DEG,
            rate_rad_per_s: c.positive(&k("rate_deg_per_s"), r.rate_deg_per_s, "deg/s", 1000.0)? * RAD_PER_DEG,
        });
    }
    let mut wobbles = Vec::new();
    for (i, w) in raw.vehicle.wobble.iter().enumerate() {
        let k = |f: &str| format!("vehicle.wobble[{i}].{f}");
        wobbles.push(Wobble {
            angle: angle_kind(&c, &k("angle"), &w.angle)?,
            amplitude_rad: c.range(&k("amplitude_deg"), w.amplitude_deg, "deg", 0.0, 45.0, "")? * RAD_PER_DEG,
            omega_rad_per_s: c.range(
                &k("frequency_hz"),
                w.frequency_hz,
                "Hz",
                0.0,
                0.25 * step_hz,
                "at most a quarter of simulation.step_hz",
            )? * std::f64::consts::TAU,
            phase_rad: c.finite(&k("phase_deg"), w.phase_deg, "deg")? * RAD_PER_DEG,
        });
    }
    let coning = crate::model::motion::Coning {
        half_angle_rad: c.range(
            "vehicle.coning_half_angle_deg",
            raw.vehicle.coning_half_angle_deg,
            "deg",
            0.0,
            45.0,
            "",
        )? * RAD_PER_DEG,
        omega_rad_per_s: c.range(
            "vehicle.coning_frequency_hz",
            raw.vehicle.coning_frequency_hz,
            "Hz",
            0.0,
            0.25 * step_hz,
            "at most a quarter of simulation.step_hz",
        )? * std::f64::consts::TAU,
    };
    let vehicle =
        VehicleMotion::new(base, ramps, wobbles).map_err(|m| c.invalid("vehicle.ramp", m))?.with_coning(coning);
    // Pitch must stay clear of the Euler singularity over the whole profile (ramps + wobble).
    let max_pitch = vehicle.max_abs_pitch_rad(duration_s);
    if max_pitch > 85.0 * RAD_PER_DEG {
        return Err(c.invalid(
            "vehicle",
            format!(
                "the pitch profile reaches {:.2} deg; keep |pitch| <= 85 deg ({pitch_hint})",
                max_pitch / RAD_PER_DEG
            ),
        ));
    }

    let (chain, truth) = turntable(&c, &raw.turntable)?;

    // [scheme]
    let scheme = validate_scheme(&c, &raw.scheme, &chain)?;

    let motion_hz =
        raw.vehicle.wobble.iter().map(|w| w.frequency_hz).fold(
            raw.vehicle.coning_frequency_hz * f64::from(u8::from(raw.vehicle.coning_half_angle_deg > 0.0)),
            f64::max,
        );
    let bandwidth = Bandwidth { shaft_deg_per_s: scheme.max_rate().to_degrees(), motion_hz, duration_s };
    // [compensation]
    let (compensation, resolved_comp) = validate_compensation(&c, &raw.compensation, &raw.turntable, &chain, &truth)?;

    // The plots' unit follows the size of the table's errors: a preview of the uncompensated error
    // on at most 2000 instants (a millisecond; the model is pure).
    let preview = {
        let table = TableParams {
            chain: chain.clone(),
            vehicle: vehicle.clone(),
            scheme: scheme.clone(),
            truth: truth.clone(),
            compensation: compensation.clone(),
        };
        let model = crate::sim::Model::new(&table, raw.scenario.seed);
        let hz = (2000.0 / duration_s).min(step_hz);
        crate::sim::run_stats(&model, &crate::math::timeline::Timeline::new(duration_s, hz)).peak_over_axes(0)
    };
    let recording = recording(&c, &raw.recording, step_hz, bandwidth, preview)?;

    let meta = ScenarioMeta {
        name: raw.scenario.name.clone(),
        title: raw.scenario.title.clone(),
        description: raw.scenario.description.clone(),
        seed: raw.scenario.seed,
    };
    let live_speed = c.range("live.speed", raw.live.speed, "x real time", 0.01, 10_000.0, "")?;
    let ins = instruments::validate_ins(&c, raw.imu.as_ref(), raw.navigation.as_ref(), step_hz)?;
    let calibration =
        instruments::validate_calibration(&c, &raw.calibration.clone().unwrap_or_default(), &truth, ins.as_ref())?;
    let mut position_fix_s = Vec::new();
    if let Some(fix) = &raw.position_fix {
        if raw.navigation.is_none() {
            return Err(
                c.invalid("position_fix", "needs a [navigation] section (a position fix resets the navigation)")
            );
        }
        for (i, h) in fix.at_h.iter().enumerate() {
            let key = format!("position_fix.at_h[{i}]");
            let t = c.positive(&key, *h, "h", duration_s / 3600.0)? * 3600.0;
            if position_fix_s.last().is_some_and(|prev| t <= *prev) {
                return Err(
                    c.invalid(&key, format!("{h} h is not after the previous fix; list the fixes in increasing time"))
                );
            }
            position_fix_s.push(t);
        }
    }
    let written = raw.clone();
    let mut resolved = raw;
    resolved.compensation = resolved_comp;
    resolved.recording.series_hz = Some(recording.series_hz);
    resolved.recording.scene_hz = Some(recording.scene_hz);
    let resolved_toml = toml::to_string_pretty(&resolved).unwrap_or_else(|e| format!("# could not serialise: {e}"));

    let mut params = Params {
        meta,
        duration_s,
        step_hz,
        recording,
        site,
        calibration_known: TableErrors::zero(chain.axes().len()),
        table: TableParams { chain, vehicle, scheme, truth, compensation },
        resolved_toml,
        resolved,
        written,
        live_speed,
        ins,
        calibration,
        position_fix_s,
    };
    params.calibration_known = params.calibration_knowledge()?;
    Ok(params)
}

fn axis_index(c: &Checker<'_>, key: &str, chain: &Chain, name: &str) -> Result<usize, ConfigError> {
    chain.index_of(name).ok_or_else(|| {
        let names: Vec<&str> = chain.axes().iter().map(|a| a.name.as_str()).collect();
        c.invalid(key, format!("no turntable axis is named \"{name}\"; the axes are {names:?}"))
    })
}

fn validate_scheme(c: &Checker<'_>, s: &RawScheme, chain: &Chain) -> Result<Scheme, ConfigError> {
    let n = chain.axes().len();
    let only_for = |key: &str, kind: &str| {
        c.invalid(key, format!("is only read when scheme.kind = \"{kind}\"; remove it or change the kind"))
    };
    match s.kind.as_str() {
        "static" | "continuous" => {
            if s.initial_dwell_s.is_some() {
                return Err(only_for("scheme.initial_dwell_s", "indexed"));
            }
            if s.repeat.is_some() {
                return Err(only_for("scheme.repeat", "indexed"));
            }
            if !s.step.is_empty() {
                return Err(only_for("scheme.step", "indexed"));
            }
        }
        "indexed" => {
            if !s.rate.is_empty() {
                return Err(only_for("scheme.rate", "continuous"));
            }
        }
        other => {
            return Err(c.invalid(
                "scheme.kind",
                format!("\"{other}\" is not a scheme; use \"static\", \"continuous\" or \"indexed\""),
            ));
        }
    }
    let initial: Vec<f64> = chain.axes().iter().map(|a| a.initial_angle_rad).collect();
    match s.kind.as_str() {
        "static" => {
            if !s.rate.is_empty() {
                return Err(only_for("scheme.rate", "continuous"));
            }
            Ok(Scheme::continuous(initial, vec![0.0; n]))
        }
        "continuous" => {
            if s.rate.is_empty() {
                return Err(c.invalid("scheme.rate", "a continuous scheme needs at least one [[scheme.rate]] entry"));
            }
            let mut rates = vec![0.0; n];
            for (i, r) in s.rate.iter().enumerate() {
                let idx = axis_index(c, &format!("scheme.rate[{i}].axis"), chain, &r.axis)?;
                rates[idx] = c.range(
                    &format!("scheme.rate[{i}].rate_deg_per_s"),
                    r.rate_deg_per_s,
                    "deg/s",
                    -1000.0,
                    1000.0,
                    "",
                )? * RAD_PER_DEG;
            }
            Ok(Scheme::continuous(initial, rates))
        }
        _ => {
            if s.step.is_empty() {
                return Err(c.invalid("scheme.step", "an indexed scheme needs at least one [[scheme.step]]"));
            }
            let dwell0 = c.range("scheme.initial_dwell_s", s.initial_dwell_s.unwrap_or(0.0), "s", 0.0, 1e7, "")?;
            let mut steps = Vec::new();
            for (i, st) in s.step.iter().enumerate() {
                let k = |f: &str| format!("scheme.step[{i}].{f}");
                steps.push(IndexedStep {
                    axis: axis_index(c, &k("axis"), chain, &st.axis)?,
                    angle_rad: c.range(&k("angle_deg"), st.angle_deg, "deg", -3600.0, 3600.0, "")? * RAD_PER_DEG,
                    rate_rad_per_s: c.positive(&k("rate_deg_per_s"), st.rate_deg_per_s, "deg/s", 1000.0)? * RAD_PER_DEG,
                    dwell_s: c.range(&k("dwell_s"), st.dwell_s, "s", 0.0, 1e7, "")?,
                    accel_rad_per_s2: c.range(
                        &k("accel_deg_per_s2"),
                        st.accel_deg_per_s2,
                        "deg/s^2",
                        0.0,
                        1e5,
                        "0 means the rate steps instantly",
                    )? * RAD_PER_DEG,
                });
            }
            let scheme = Scheme::indexed(initial, dwell0, steps, s.repeat.unwrap_or(true));
            if scheme.period_s() <= 0.0 {
                return Err(c.invalid("scheme.step", "the sequence takes no time (all moves and dwells are zero)"));
            }
            Ok(scheme)
        }
    }
}

pub(super) fn validate_compensation(
    c: &Checker<'_>,
    comp: &RawCompensation,
    table: &RawTurntable,
    chain: &Chain,
    truth: &TableErrors,
) -> Result<(TableErrors, RawCompensation), ConfigError> {
    for name in comp.axis.keys() {
        axis_index(c, &format!("compensation.axis.{name}"), chain, name)?;
    }
    let pick = |v: Option<f64>, default: f64| v.unwrap_or(default);
    let enabled = comp.enabled.unwrap_or(true);
    let mut resolved = RawCompensation {
        enabled: Some(enabled),
        installation_x_arcsec: Some(pick(comp.installation_x_arcsec, table.installation_x_arcsec)),
        installation_y_arcsec: Some(pick(comp.installation_y_arcsec, table.installation_y_arcsec)),
        installation_z_arcsec: Some(pick(comp.installation_z_arcsec, table.installation_z_arcsec)),
        imu_mount_x_arcsec: Some(pick(comp.imu_mount_x_arcsec, table.imu_mount_x_arcsec)),
        imu_mount_y_arcsec: Some(pick(comp.imu_mount_y_arcsec, table.imu_mount_y_arcsec)),
        imu_mount_z_arcsec: Some(pick(comp.imu_mount_z_arcsec, table.imu_mount_z_arcsec)),
        axis: BTreeMap::new(),
    };
    let mut axes = Vec::new();
    for (i, a) in table.axis.iter().enumerate() {
        let given = comp.axis.get(&a.name).cloned().unwrap_or_default();
        let k = |f: &str| format!("compensation.axis.{}.{f}", a.name);
        let r = RawAxisCompensation {
            swing_half_angle_arcsec: Some(pick(given.swing_half_angle_arcsec, a.swing_half_angle_arcsec)),
            swing_phase_deg: Some(pick(given.swing_phase_deg, a.swing_phase_deg)),
            non_orthogonality_arcsec: Some(pick(given.non_orthogonality_arcsec, a.non_orthogonality_arcsec)),
            encoder_offset_arcsec: Some(pick(given.encoder_offset_arcsec, a.encoder_offset_arcsec)),
            encoder_scale_ppm: Some(pick(given.encoder_scale_ppm, a.encoder_scale_ppm)),
            encoder_delay_ms: Some(pick(given.encoder_delay_ms, a.encoder_delay_ms)),
        };
        if i == 0 && r.non_orthogonality_arcsec != Some(0.0) {
            return Err(c.invalid(
                &k("non_orthogonality_arcsec"),
                "the first axis has no non-orthogonality; compensate installation_*_arcsec instead",
            ));
        }
        let values = AxisErrorKeys {
            swing_half_angle_arcsec: r.swing_half_angle_arcsec.unwrap_or_default(),
            swing_phase_deg: r.swing_phase_deg.unwrap_or_default(),
            non_orthogonality_arcsec: r.non_orthogonality_arcsec.unwrap_or_default(),
            encoder_offset_arcsec: r.encoder_offset_arcsec.unwrap_or_default(),
            encoder_scale_ppm: r.encoder_scale_ppm.unwrap_or_default(),
            encoder_delay_ms: r.encoder_delay_ms.unwrap_or_default(),
        };
        // Noise is not a parameter a compensation can remove: it stays 0.
        axes.push(axis_errors_of(c, &k, &values)?);
        resolved.axis.insert(a.name.clone(), r);
    }
    if !enabled {
        return Ok((TableErrors::zero(chain.axes().len()), resolved));
    }
    let errors = TableErrors {
        installation_rad: rotation_arcsec(
            c,
            "compensation.installation",
            [resolved.installation_x_arcsec, resolved.installation_y_arcsec, resolved.installation_z_arcsec]
                .map(Option::unwrap_or_default),
        )?,
        imu_mount_rad: rotation_arcsec(
            c,
            "compensation.imu_mount",
            [resolved.imu_mount_x_arcsec, resolved.imu_mount_y_arcsec, resolved.imu_mount_z_arcsec]
                .map(Option::unwrap_or_default),
        )?,
        axes,
    };
    debug_assert_eq!(errors.axes.len(), truth.axes.len());
    Ok((errors, resolved))
}

/// An error angle in arcsec (±10°), in rad.
fn error_angle(c: &Checker<'_>, key: &str, v: f64) -> Result<f64, ConfigError> {
    Ok(c.range(key, v, "arcsec", -MAX_ERROR_ANGLE_ARCSEC, MAX_ERROR_ANGLE_ARCSEC, ERROR_HINT)? * RAD_PER_ARCSEC)
}

/// A rotation vector given as `{prefix}_x/y/z_arcsec`, in rad.
fn rotation_arcsec(c: &Checker<'_>, prefix: &str, xyz: [f64; 3]) -> Result<Vector3<f64>, ConfigError> {
    Ok(Vector3::new(
        error_angle(c, &format!("{prefix}_x_arcsec"), xyz[0])?,
        error_angle(c, &format!("{prefix}_y_arcsec"), xyz[1])?,
        error_angle(c, &format!("{prefix}_z_arcsec"), xyz[2])?,
    ))
}

/// The error keys an axis shares with its compensation, in the file's units.
struct AxisErrorKeys {
    swing_half_angle_arcsec: f64,
    swing_phase_deg: f64,
    non_orthogonality_arcsec: f64,
    encoder_offset_arcsec: f64,
    encoder_scale_ppm: f64,
    encoder_delay_ms: f64,
}

/// One axis's errors (no encoder noise), each key checked; `key` makes the dotted key of a field.
fn axis_errors_of(c: &Checker<'_>, key: &dyn Fn(&str) -> String, v: &AxisErrorKeys) -> Result<AxisErrors, ConfigError> {
    Ok(AxisErrors {
        swing_half_angle_rad: c.range(
            &key("swing_half_angle_arcsec"),
            v.swing_half_angle_arcsec,
            "arcsec",
            0.0,
            MAX_ERROR_ANGLE_ARCSEC,
            ERROR_HINT,
        )? * RAD_PER_ARCSEC,
        swing_phase_rad: c.range(&key("swing_phase_deg"), v.swing_phase_deg, "deg", -360.0, 360.0, "")? * RAD_PER_DEG,
        non_orthogonality_rad: error_angle(c, &key("non_orthogonality_arcsec"), v.non_orthogonality_arcsec)?,
        encoder_offset_rad: error_angle(c, &key("encoder_offset_arcsec"), v.encoder_offset_arcsec)?,
        encoder_scale: c.range(
            &key("encoder_scale_ppm"),
            v.encoder_scale_ppm,
            "ppm",
            -10_000.0,
            10_000.0,
            "1% at most",
        )? * 1e-6,
        encoder_delay_s: c.range(&key("encoder_delay_ms"), v.encoder_delay_ms, "ms", -1000.0, 1000.0, "")? * 1e-3,
        encoder_noise_rad: 0.0,
    })
}

/// What the default recording rates follow: the fastest gimbal rate, the fastest periodic motion
/// of the vehicle, the run's length.
#[derive(Debug, Clone, Copy)]
pub struct Bandwidth {
    /// Fastest gimbal rate, deg/s.
    pub shaft_deg_per_s: f64,
    /// Fastest vehicle wobble or coning frequency, Hz.
    pub motion_hz: f64,
    /// The run's length, s.
    pub duration_s: f64,
}

impl Bandwidth {
    /// The default series rate, Hz: buckets per second of the plots' envelopes (each bucket keeps
    /// every line's first, smallest, largest and last sample, `record/plots/envelope.rs`). 3000
    /// buckets over the run — one per pixel of the widest plot, two or more per pixel of a laptop's,
    /// so a plot zoomed in twice still draws each pixel column from every sample in it —, at most
    /// 50 Hz (a short run: nearly every sample). The motion does not enter: a bucket spanning
    /// several periods draws their band, its extremes exact. Four rows per bucket at most: about
    /// 12 000 rows per plot over any run, a few MB per hour of the noisiest (docs/benchmarks.md).
    #[must_use]
    pub fn series_hz(&self) -> f64 {
        (3000.0 / self.duration_s).clamp(1e-3, 50.0)
    }

    /// The default scene rate, Hz: what the eye needs when the run plays in a minute (1500 frames,
    /// 25 per second), at least a frame per degree of the fastest shaft and 10 per period of the
    /// vehicle's motion; at most 25 Hz.
    #[must_use]
    pub fn scene_hz(&self) -> f64 {
        self.shaft_deg_per_s.max(10.0 * self.motion_hz).max(1500.0 / self.duration_s).clamp(1e-3, 25.0)
    }

    /// The rate the run's RMS and peak statistics sample the errors at, Hz (at most the step rate):
    /// 250 points per period of the fastest vehicle motion, 4 per degree of the fastest shaft, at
    /// least 200 Hz. A sinusoid's peak sampled at N points per period reads at least cos(π/N) of
    /// it: 1 − 7.9e-5 at N = 250, so a peak is read to 1e-4 of itself; the shaft-driven errors,
    /// periodic in the shaft angle, get 1440 points per turn (1e-4 up to the 5th harmonic). The
    /// white part of a noisy error has the same RMS at any rate; its largest sample grows with the
    /// number of samples, so a noise peak is a statement about the rate (given in the summary).
    #[must_use]
    pub fn statistics_hz(&self) -> f64 {
        (250.0 * self.motion_hz).max(4.0 * self.shaft_deg_per_s).max(200.0)
    }
}

/// `[recording]`: output rates (at most the simulation rate `step_hz`; absent, from `bandwidth`)
/// and the drawing factor.
pub(super) fn recording(
    c: &Checker<'_>,
    raw: &RawRecording,
    step_hz: f64,
    bandwidth: Bandwidth,
    error_peak_rad: f64,
) -> Result<RecordingParams, ConfigError> {
    let hint = "at most the step rate; at least one point every 1000 s";
    let error_unit = match &raw.error_unit {
        None => crate::math::units::AngleUnit::for_peak(error_peak_rad),
        Some(s) => crate::math::units::AngleUnit::parse(s).ok_or_else(|| {
            c.invalid("recording.error_unit", format!("\"{s}\" is not a unit; use \"arcsec\", \"arcmin\" or \"deg\""))
        })?,
    };
    Ok(RecordingParams {
        series_hz: match raw.series_hz {
            Some(v) => c.range("recording.series_hz", v, "Hz", 1e-3, step_hz, hint)?,
            None => bandwidth.series_hz().min(step_hz),
        },
        scene_hz: match raw.scene_hz {
            Some(v) => c.range("recording.scene_hz", v, "Hz", 1e-3, step_hz, hint)?,
            None => bandwidth.scene_hz().min(step_hz),
        },
        exaggeration: c.range("recording.exaggeration", raw.exaggeration, "x", 1.0, 100_000.0, "")?,
        error_unit,
        open_at_end: match raw.open_at.as_deref() {
            None | Some("start") => false,
            Some("end") => true,
            Some(s) => {
                return Err(c.invalid(
                    "recording.open_at",
                    format!("\"{s}\" is not a place in the run; use \"start\" or \"end\""),
                ));
            }
        },
        chosen: (raw.series_hz.is_none(), raw.scene_hz.is_none()),
        bandwidth,
        hidden_algorithms: {
            use crate::ins::coning::Algorithm;
            let mut hidden = [false; 5];
            for (name, shown) in &raw.show {
                let Some(i) = Algorithm::ALL.iter().position(|a| a.name() == name) else {
                    let names: Vec<&str> = Algorithm::ALL.iter().map(|a| a.name()).collect();
                    return Err(c.invalid(
                        &format!("recording.show.{name}"),
                        format!("\"{name}\" is not an attitude algorithm; the names are {}", names.join(", ")),
                    ));
                };
                hidden[i] = !shown;
            }
            hidden
        },
    })
}

/// `[site]`.
pub(super) fn site(c: &Checker<'_>, raw: &RawSite) -> Result<Site, ConfigError> {
    Ok(Site {
        latitude_rad: c.range("site.latitude_deg", raw.latitude_deg, "deg", -90.0, 90.0, "")? * RAD_PER_DEG,
        longitude_rad: c.range("site.longitude_deg", raw.longitude_deg, "deg", -180.0, 360.0, "")? * RAD_PER_DEG,
        height_m: c.range("site.height_m", raw.height_m, "m", -1000.0, 100_000.0, "")?,
    })
}

/// `[turntable]`: the nominal chain and the table's errors as written.
pub(super) fn turntable(c: &Checker<'_>, raw: &RawTurntable) -> Result<(Chain, TableErrors), ConfigError> {
    let t = raw;
    if t.axis.is_empty() || t.axis.len() > 3 {
        return Err(c.invalid("turntable.axis", format!("{} axes given; a table has 1, 2 or 3", t.axis.len())));
    }
    let mut geometry = Vec::new();
    let mut axis_errors = Vec::new();
    for (i, a) in t.axis.iter().enumerate() {
        let k = |f: &str| format!("turntable.axis[{i}] (\"{}\").{f}", a.name);
        if a.name.trim().is_empty() || geometry.iter().any(|g: &AxisGeometry| g.name == a.name) {
            return Err(c.invalid(&k("name"), format!("\"{}\" must be non-empty and unique", a.name)));
        }
        let dir = match a.axis.as_str() {
            "x" => Vector3::x(),
            "y" => Vector3::y(),
            "z" => Vector3::z(),
            other => {
                return Err(c.invalid(&k("axis"), format!("\"{other}\" is not an axis; use \"x\", \"y\" or \"z\"")));
            }
        };
        if let Some(prev) = geometry.last() {
            let prev: &AxisGeometry = prev;
            if prev.axis.dot(&dir).abs() > 0.5 {
                return Err(c.invalid(
                    &k("axis"),
                    format!(
                        "\"{}\" is parallel to the previous axis \"{}\"; consecutive gimbal axes must be perpendicular",
                        a.axis, prev.name
                    ),
                ));
            }
        }
        if i == 0 && a.non_orthogonality_arcsec != 0.0 {
            return Err(c.invalid(
                &k("non_orthogonality_arcsec"),
                format!(
                    "{} arcsec given on the first axis; its tilt against the body is the installation error (turntable.installation_*_arcsec)",
                    a.non_orthogonality_arcsec
                ),
            ));
        }
        geometry.push(AxisGeometry::new(
            a.name.clone(),
            dir,
            c.finite(&k("initial_angle_deg"), a.initial_angle_deg, "deg")? * RAD_PER_DEG,
        ));
        let values = AxisErrorKeys {
            swing_half_angle_arcsec: a.swing_half_angle_arcsec,
            swing_phase_deg: a.swing_phase_deg,
            non_orthogonality_arcsec: a.non_orthogonality_arcsec,
            encoder_offset_arcsec: a.encoder_offset_arcsec,
            encoder_scale_ppm: a.encoder_scale_ppm,
            encoder_delay_ms: a.encoder_delay_ms,
        };
        let mut errors = axis_errors_of(c, &k, &values)?;
        errors.encoder_noise_rad = c.range(
            &k("encoder_noise_arcsec"),
            a.encoder_noise_arcsec,
            "arcsec",
            0.0,
            3600.0,
            "1σ per reading, 1° at most",
        )? * RAD_PER_ARCSEC;
        axis_errors.push(errors);
    }
    let chain = Chain::new(geometry);
    let truth = TableErrors {
        installation_rad: rotation_arcsec(
            c,
            "turntable.installation",
            [t.installation_x_arcsec, t.installation_y_arcsec, t.installation_z_arcsec],
        )?,
        imu_mount_rad: rotation_arcsec(
            c,
            "turntable.imu_mount",
            [t.imu_mount_x_arcsec, t.imu_mount_y_arcsec, t.imu_mount_z_arcsec],
        )?,
        axes: axis_errors,
    };
    Ok((chain, truth))
}
