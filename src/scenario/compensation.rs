//! A compensation document, one model for the whole RINS: the table's errors
//! (`estimated_compensation`, what `calibrate --json` writes, as `[compensation]` keys) and the IMU's
//! (`estimated_imu_compensation`, what `selfcal --json` writes), each with its 1σ, each in a stated
//! frame; `replay --compensation FILE` reads either or both (docs/selfcal.md, docs/calibration.md).
//!
//! measured = (I + K)·true + b, per triad; the compensation applied to every sample is
//! (I + K)⁻¹(measured − b·h). The frame is the accelerometer triad's (K_a upper triangular: a
//! rotation of both triads together is the IMU's attitude, which a replay's alignment finds in the
//! compensated frame).

use serde::{Deserialize, Serialize};

use super::logset::RawTable;
use super::raw::{RawCompensation, RawTurntable};
use super::validate::{self, Checker};
use crate::model::gimbal::TableErrors;

use crate::ins::imu_errors::ImuErrors;
use crate::io::validity::{Range, check_number};
use crate::math::units::{MPS2_PER_UG, RAD_PER_S_PER_DEG_PER_H};
use crate::scenario::ConfigError;

/// The frame every estimate of the IMU is stated in.
pub const FRAME: &str = "accelerometer triad (K_a upper triangular; docs/selfcal.md)";

/// `estimated_imu_compensation`: biases in °/h and µg, gains in ppm (row i, column j: K_ij), with
/// their 1σ where the calibration gives them; the parameters it could not see are zero and named.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawImuCompensation {
    /// The frame the compensated increments are in ([`FRAME`]).
    pub frame: String,
    /// Gyro bias, °/h.
    pub gyro_bias_deg_per_h: [f64; 3],
    /// Gyro gain error (scale factors on the diagonal, misalignments off it), ppm.
    pub gyro_gain_ppm: [[f64; 3]; 3],
    /// Accelerometer bias, µg.
    pub accel_bias_ug: [f64; 3],
    /// Accelerometer gain error, ppm.
    pub accel_gain_ppm: [[f64; 3]; 3],
    /// The 1σ of each, in the same units and layout (absent: not stated).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma: Option<Box<RawImuCompensation>>,
    /// Parameters the calibration could not see: left at zero (not compensated).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub not_compensated: Vec<String>,
}

/// A gyro bias a compensation may state: up to 1 °/s (3600 °/h).
const GYRO_BIAS: Range = Range::symmetric(3600.0, "°/h", "a gyro bias");
/// An accelerometer bias: up to 0.1 g.
const ACCEL_BIAS: Range = Range::symmetric(1e5, "µg", "an accelerometer bias");
/// A gain error: up to 10 %.
const GAIN: Range = Range::symmetric(1e5, "ppm", "a gain error (scale factor or misalignment)");

impl RawImuCompensation {
    /// `e` (and its 1σ `sigma`) as the document states them; `hidden` names what is not compensated.
    #[must_use]
    pub fn from_errors(e: &ImuErrors, sigma: Option<&ImuErrors>, hidden: Vec<String>) -> Self {
        let m = |k: &nalgebra::Matrix3<f64>| std::array::from_fn(|i| std::array::from_fn(|j| k[(i, j)] * 1e6));
        let v = |x: &nalgebra::Vector3<f64>, unit: f64| [x.x / unit, x.y / unit, x.z / unit];
        Self {
            frame: FRAME.to_owned(),
            gyro_bias_deg_per_h: v(&e.bg, RAD_PER_S_PER_DEG_PER_H),
            gyro_gain_ppm: m(&e.kg),
            accel_bias_ug: v(&e.ba, MPS2_PER_UG),
            accel_gain_ppm: m(&e.ka),
            sigma: sigma.map(|s| Box::new(Self::from_errors(s, None, Vec::new()))),
            not_compensated: hidden,
        }
    }

    /// The errors to remove, every number held to its range (`origin` names the document).
    ///
    /// # Errors
    /// A number that is not finite or out of its range, named by its key and index.
    pub fn validate(&self, origin: &str) -> Result<ImuErrors, ConfigError> {
        let bad = |key: String, e: String| ConfigError::Invalid {
            origin: origin.to_owned(),
            key: format!("estimated_imu_compensation.{key}"),
            message: e,
        };
        let vector = |key: &str, v: &[f64; 3], range: &Range, unit: f64| {
            let mut out = nalgebra::Vector3::zeros();
            for i in 0..3 {
                out[i] = check_number(v[i], range).map_err(|e| bad(format!("{key}[{i}]"), e))? * unit;
            }
            Ok::<_, ConfigError>(out)
        };
        let matrix = |key: &str, k: &[[f64; 3]; 3]| {
            let mut out = nalgebra::Matrix3::zeros();
            for i in 0..3 {
                for j in 0..3 {
                    out[(i, j)] = check_number(k[i][j], &GAIN).map_err(|e| bad(format!("{key}[{i}][{j}]"), e))? * 1e-6;
                }
            }
            Ok::<_, ConfigError>(out)
        };
        Ok(ImuErrors {
            bg: vector("gyro_bias_deg_per_h", &self.gyro_bias_deg_per_h, &GYRO_BIAS, RAD_PER_S_PER_DEG_PER_H)?,
            kg: matrix("gyro_gain_ppm", &self.gyro_gain_ppm)?,
            ba: vector("accel_bias_ug", &self.accel_bias_ug, &ACCEL_BIAS, MPS2_PER_UG)?,
            ka: matrix("accel_gain_ppm", &self.accel_gain_ppm)?,
        })
    }
}

/// A compensation document's two parts, as `calibrate --json` (the table's) and `selfcal --json`
/// (both) write them; anything else in the file is not read.
#[derive(Deserialize)]
struct Document {
    estimated_compensation: Option<RawCompensation>,
    estimated_imu_compensation: Option<RawImuCompensation>,
}

fn parse_document(json_text: &str, origin: &str) -> Result<Document, ConfigError> {
    serde_json::from_str(json_text).map_err(|e| ConfigError::Parse {
        origin: origin.to_owned(),
        message: format!("not a compensation document of `rinscope calibrate --json` or `selfcal --json` ({e})"),
    })
}

/// The IMU compensation of a compensation document (`selfcal --json`), if it has one.
///
/// # Errors
/// Not JSON, or an `estimated_imu_compensation` with a bad number.
pub fn from_document(json_text: &str, origin: &str) -> Result<Option<ImuErrors>, ConfigError> {
    parse_document(json_text, origin)?.estimated_imu_compensation.map(|c| c.validate(origin)).transpose()
}

/// The document's table part (`estimated_compensation`), if it has one.
fn table_part(json_text: &str, origin: &str) -> Result<Option<RawCompensation>, ConfigError> {
    Ok(parse_document(json_text, origin)?.estimated_compensation)
}

/// The document's table part as the scenario keys it sets (`compensation.axis.inner.swing_half_angle_arcsec`
/// = 512.3, ...), in a stable order: what `live --compensation` writes into the session's config.
/// Empty when the document has no table part.
///
/// # Errors
/// Not a compensation document.
pub fn table_keys(json_text: &str, origin: &str) -> Result<Vec<(String, toml::Value)>, ConfigError> {
    fn walk(prefix: &str, v: &toml::Value, out: &mut Vec<(String, toml::Value)>) {
        match v {
            toml::Value::Table(t) => t.iter().for_each(|(k, x)| walk(&format!("{prefix}.{k}"), x, out)),
            leaf => out.push((prefix.to_owned(), leaf.clone())),
        }
    }
    let mut out = Vec::new();
    if let Some(part) = table_part(json_text, origin)? {
        let value = toml::Value::try_from(&part).map_err(|e| ConfigError::Parse {
            origin: origin.to_owned(),
            message: format!("its estimated_compensation cannot be written as scenario keys ({e})"),
        })?;
        walk("compensation", &value, &mut out);
    }
    Ok(out)
}

/// The `estimated_compensation` of a calibration JSON (`rinscope calibrate --json`) as the table errors of
/// `table`: its keys are `[compensation]`'s, and the table's own values fill what it leaves out.
///
/// `has_imu`: the document also holds an IMU compensation (`selfcal --json`), and may then have no
/// table part (the table's own compensation stands).
pub fn compensation_from_calibration(
    table: &RawTable,
    json_text: &str,
    origin: &str,
    has_imu: bool,
) -> Result<TableErrors, ConfigError> {
    let c = Checker { origin };
    let turntable = table.turntable.clone().unwrap_or_else(RawTurntable::strapdown);
    let (chain, stated) = validate::turntable(&c, &turntable)?;
    let mut merged = table.compensation.clone();
    let given = match table_part(json_text, origin)? {
        Some(g) => g,
        None if has_imu => RawCompensation::default(),
        None => {
            return Err(ConfigError::Parse {
                origin: origin.to_owned(),
                message: "holds neither `estimated_compensation` (the table's, from `rinscope calibrate --json`) nor `estimated_imu_compensation` (the IMU's, from `rinscope selfcal --json`)".to_owned(),
            });
        }
    };
    merged.enabled = given.enabled.or(merged.enabled);
    for (k, v) in given.axis {
        merged.axis.insert(k, v);
    }
    macro_rules! take {
        ($($f:ident),*) => { $( if given.$f.is_some() { merged.$f = given.$f; } )* };
    }
    take!(
        installation_x_arcsec,
        installation_y_arcsec,
        installation_z_arcsec,
        imu_mount_x_arcsec,
        imu_mount_y_arcsec,
        imu_mount_z_arcsec
    );
    Ok(validate::validate_compensation(&c, &merged, &turntable, &chain, &stated)?.0)
}

/// A compensation document (`calibrate --json`, `selfcal --json`, or one written by hand) applied
/// to a simulated scenario, as `replay --compensation` applies it to a log: its table part
/// replaces the scenario's `[compensation]` keys it names, its IMU part is removed from every
/// sample the computer reads (`run --compensation`). Returns what was applied, as notes.
///
/// # Errors
/// Not a compensation document, a bad number (named by key), an IMU part for a scenario without
/// `[imu]`.
pub fn apply_to_scenario(
    params: &mut super::Params,
    json_text: &str,
    origin: &str,
) -> Result<Vec<String>, ConfigError> {
    let imu = from_document(json_text, origin)?;
    let raw = RawTable {
        recording: Default::default(),
        site: Default::default(),
        turntable: Some(params.resolved.turntable.clone()),
        compensation: params.resolved.compensation.clone(),
        imu: None,
        navigation: None,
        calibration: None,
    };
    params.table.compensation = compensation_from_calibration(&raw, json_text, origin, imu.is_some())?;
    let mut notes =
        vec![format!("the table is compensated with {origin}'s estimates (the scenario's own where it names none)")];
    if let Some(errors) = imu {
        let ins = params.ins.as_mut().ok_or_else(|| ConfigError::Invalid {
            origin: origin.to_owned(),
            key: "estimated_imu_compensation".to_owned(),
            message: format!("{} has no [imu] section: there is no IMU to compensate", params.meta.name),
        })?;
        ins.imu_compensation = Some(errors);
        notes.push(format!("the IMU is compensated with {origin}'s estimates, in the accelerometer triad's frame"));
    }
    Ok(notes)
}
