//! Layer 6, the scenario: the only code that knows the TOML. The file is parsed strictly
//! ([`raw`]), validated once and converted once into SI [`Params`] made of the lower layers' own
//! parameter structs ([`validate`], [`instruments`]); [`presets`] embeds the shipped scenarios.
//!
//! Every error names the key, the value and the unit (and the allowed range where there is one).

/// The longest simulation a scenario (or `--duration-s`) may ask for: 30 days, s.
pub const MAX_DURATION_S: f64 = 30.0 * 86_400.0;

/// A simulated duration, s: > 0 and at most 30 days — the rule of `simulation.duration_s` and of
/// every run length given beside a file (`--duration-s`, Python's `duration_s`), written once.
pub const DURATION: crate::io::validity::Range = crate::io::validity::Range::positive(
    MAX_DURATION_S,
    "s",
    "a simulated duration (30 days at most, as simulation.duration_s)",
);

/// Checks a run length a user gives beside the file against [`DURATION`]; the message says the
/// value and the range, the caller names the flag.
///
/// # Errors
/// Not finite, not positive, or over [`MAX_DURATION_S`].
pub fn check_duration(duration_s: f64) -> Result<f64, String> {
    crate::io::validity::check_number(duration_s, &DURATION)
}

pub mod compensation;
pub mod instruments;
pub mod logset;
pub mod presets;
pub mod raw;
mod stochastic;
pub mod validate;

use std::collections::BTreeMap;
use std::path::Path;

use crate::calib::CalibConfig;
use crate::ins::InsParams;
use crate::ins::pipeline::InsRun;
use crate::math::timeline::Timeline;
use crate::model::earth::Site;
use crate::sim::{Model, TableParams};
pub use raw::RawConfig;

/// A configuration problem a user can fix. Displayed as one line naming key, value and unit.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The file could not be read.
    #[error("cannot read config file {path}: {source}")]
    Read {
        /// The path as given.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// TOML syntax, an unknown key or a wrong type (the toml crate's message shows the line).
    #[error("{origin}: {message}")]
    Parse {
        /// The file or scenario name.
        origin: String,
        /// toml's message, with the offending line and key.
        message: String,
    },
    /// A number that is not finite (nan, inf).
    #[error("{origin}: `{key}` = {} {unit} is not a finite number", crate::io::short_number(*.value))]
    NotFinite {
        /// The file or scenario name.
        origin: String,
        /// Dotted key path.
        key: String,
        /// The value as read.
        value: f64,
        /// The unit of the key.
        unit: &'static str,
    },
    /// A number outside its allowed range.
    #[error("{origin}: `{key}` = {} {unit} is out of range: {range}", crate::io::short_number(*.value))]
    OutOfRange {
        /// The file or scenario name.
        origin: String,
        /// Dotted key path.
        key: String,
        /// The value as read.
        value: f64,
        /// The unit of the key.
        unit: &'static str,
        /// The allowed range and a hint.
        range: String,
    },
    /// Any other inconsistency (duplicate axis names, an unknown axis referenced, ...).
    #[error("{origin}: `{key}`: {message}")]
    Invalid {
        /// The file or scenario name.
        origin: String,
        /// Dotted key path.
        key: String,
        /// What is wrong and how to fix it.
        message: String,
    },
}

/// What the scenario is, for people.
#[derive(Debug, Clone)]
pub struct ScenarioMeta {
    /// Identifier.
    pub name: String,
    /// One line.
    pub title: String,
    /// Markdown.
    pub description: String,
    /// Seed of every random draw.
    pub seed: u64,
}

/// Output rates and drawing.
#[derive(Debug, Clone, Copy)]
pub struct RecordingParams {
    /// Time-series output rate, Hz.
    pub series_hz: f64,
    /// Scene output rate, Hz.
    pub scene_hz: f64,
    /// Drawing factor for error angles.
    pub exaggeration: f64,
    /// Unit of the attitude-error plots.
    pub error_unit: crate::math::units::AngleUnit,
    /// The recording opens at the end of the run (the time cursor follows the newest data).
    pub open_at_end: bool,
    /// Per attitude algorithm (in `Algorithm::ALL`'s order), whether its lines and needle are
    /// hidden (`[recording.show]`).
    pub hidden_algorithms: [bool; 5],
    /// What the rates not given in the file were chosen from (series, scene: `true` if chosen).
    pub chosen: (bool, bool),
    /// The motion's bandwidth the chosen rates follow.
    pub bandwidth: validate::Bandwidth,
}

impl RecordingParams {
    /// Whether the attitude algorithm named `name` is shown.
    #[must_use]
    pub fn shows(&self, name: &str) -> bool {
        crate::ins::coning::Algorithm::ALL
            .iter()
            .position(|a| a.name() == name)
            .is_none_or(|i| !self.hidden_algorithms[i])
    }
}

/// A validated scenario in SI units.
#[derive(Debug, Clone)]
pub struct Params {
    /// Name, title, description, seed.
    pub meta: ScenarioMeta,
    /// Simulated time, s.
    pub duration_s: f64,
    /// Simulation rate, Hz.
    pub step_hz: f64,
    /// Output rates and drawing.
    pub recording: RecordingParams,
    /// Site.
    pub site: Site,
    /// The turntable: chain, vehicle motion, scheme, true and assumed errors.
    pub table: TableParams,
    /// The configuration as resolved (defaults and compensation filled in), as TOML.
    pub resolved_toml: String,
    /// The same, as data.
    pub resolved: RawConfig,
    /// The configuration as written (defaults of optional keys not filled in): live mode describes
    /// reloads as its differences.
    pub written: RawConfig,
    /// What a calibration assumes about the errors it does not estimate (see
    /// [`Params::calibration_knowledge`]).
    pub calibration_known: crate::model::gimbal::TableErrors,
    /// `[live] speed`: simulated seconds per wall-clock second.
    pub live_speed: f64,
    /// The INS in the loop, if any.
    pub ins: Option<InsParams>,
    /// `[calibration]` (its defaults when the section is absent).
    pub calibration: CalibConfig,
    /// Times of the position fixes, s (`[position_fix]`).
    pub position_fix_s: Vec<f64>,
}

impl Params {
    /// What a calibration may assume about the errors it does not estimate: the `[compensation]`
    /// values the file gives, and nominal (zero) for every error it does not — a user calibrating a
    /// table does not know its true errors (the run's own `[compensation]` defaults to the truth,
    /// which is right for demodulating, not for calibrating).
    ///
    /// # Errors
    /// None in practice (the file was validated); a `ConfigError` if re-validation fails.
    pub fn calibration_knowledge(&self) -> Result<crate::model::gimbal::TableErrors, ConfigError> {
        let mut nominal = self.written.turntable.clone();
        nominal.installation_x_arcsec = 0.0;
        nominal.installation_y_arcsec = 0.0;
        nominal.installation_z_arcsec = 0.0;
        nominal.imu_mount_x_arcsec = 0.0;
        nominal.imu_mount_y_arcsec = 0.0;
        nominal.imu_mount_z_arcsec = 0.0;
        for a in &mut nominal.axis {
            a.swing_half_angle_arcsec = 0.0;
            a.swing_phase_deg = 0.0;
            a.non_orthogonality_arcsec = 0.0;
            a.encoder_offset_arcsec = 0.0;
            a.encoder_scale_ppm = 0.0;
            a.encoder_delay_ms = 0.0;
        }
        let origin = format!("{} (what the calibration knows)", self.meta.name);
        let c = validate::Checker { origin: &origin };
        let zero = crate::model::gimbal::TableErrors::zero(self.table.chain.axes().len());
        Ok(validate::validate_compensation(&c, &self.written.compensation, &nominal, &self.table.chain, &zero)?.0)
    }

    /// Sets the run's length (`--duration-s`), with the recording rates the file did not give chosen
    /// again for it.
    pub fn set_duration(&mut self, duration_s: f64) {
        self.duration_s = duration_s;
        let r = &mut self.recording;
        r.bandwidth.duration_s = duration_s;
        if r.chosen.0 {
            r.series_hz = r.bandwidth.series_hz().min(self.step_hz);
        }
        if r.chosen.1 {
            r.scene_hz = r.bandwidth.scene_hz().min(self.step_hz);
        }
    }

    /// Steps between two samples of a run's RMS and peak statistics: the step rate over
    /// [`validate::Bandwidth::statistics_hz`], rounded down (so at least that rate), at least 1.
    #[must_use]
    pub fn statistics_every(&self) -> u64 {
        let ratio = self.step_hz / self.recording.bandwidth.statistics_hz();
        if ratio.is_finite() && ratio >= 1.0 { ratio.floor() as u64 } else { 1 }
    }

    /// The run's instants at the simulation rate (the one sampling rule, `math::timeline`).
    #[must_use]
    pub fn timeline(&self) -> Timeline {
        Timeline::new(self.duration_s, self.step_hz)
    }

    /// The turntable step's model (encoder noise seeded with the scenario's seed).
    #[must_use]
    pub fn table_model(&self) -> Model {
        Model::new(&self.table, self.meta.seed)
    }

    /// The INS in the loop on this scenario's table, if it has an `[imu]` section.
    #[must_use]
    pub fn ins_run(&self) -> Option<InsRun> {
        let ins = self.ins.as_ref()?;
        Some(InsRun::new(ins, self.site, self.meta.seed, self.table_model()))
    }
}

/// Largest configuration file read, bytes: a scenario is a few kB; anything this big is not one.
const MAX_CONFIG_BYTES: u64 = 16 << 20;

/// Reads a configuration file (a scenario, a log set's manifest or table description): a regular
/// file ([`crate::io::files::open_input`], the rule for every input) of at most
/// [`MAX_CONFIG_BYTES`].
pub fn read_text(path: &Path) -> Result<String, ConfigError> {
    use std::io::Read as _;
    let err = |source: std::io::Error| ConfigError::Read { path: path.display().to_string(), source };
    let file = crate::io::files::open_input(path).map_err(err)?;
    let meta = file.metadata().map_err(err)?;
    if meta.len() > MAX_CONFIG_BYTES {
        return Err(err(std::io::Error::other(format!(
            "{} bytes: larger than any configuration ({} MB at most)",
            meta.len(),
            MAX_CONFIG_BYTES >> 20
        ))));
    }
    let mut text = String::new();
    file.take(MAX_CONFIG_BYTES + 1).read_to_string(&mut text).map_err(err)?;
    Ok(text)
}

/// Reads and validates a scenario file.
pub fn load_file(path: &Path) -> Result<Params, ConfigError> {
    parse(&read_text(path)?, &path.display().to_string())
}

/// Parses and validates scenario text; `origin` names the file or the embedded scenario in errors.
pub fn parse(text: &str, origin: &str) -> Result<Params, ConfigError> {
    let raw: RawConfig = toml::from_str(text)
        .map_err(|e| ConfigError::Parse { origin: origin.to_owned(), message: parse_message(&e) })?;
    validate::validate(raw, origin)
}

/// Validates an already parsed configuration (a resolved one a live session holds, say).
pub fn from_raw(raw: RawConfig, origin: &str) -> Result<Params, ConfigError> {
    validate::validate(raw, origin)
}

/// The toml crate's message, which quotes the offending line: each quoted line cut to 160
/// characters and the whole to 40 lines (a 200 kB line of nested brackets is not echoed back).
///
/// A misspelt key (serde's "unknown field `x`, expected one of `a`, `b`, ...") or value ("unknown
/// variant") is said with the closest valid one(s) and the whole list of the section's keys,
/// never cut ([`did_you_mean`]).
pub fn parse_message(e: &toml::de::Error) -> String {
    const LINE: usize = 160;
    let text = e.to_string();
    let mut out: Vec<String> = Vec::new();
    for line in text.trim_end().lines().take(40) {
        if let Some(said) = did_you_mean(line) {
            out.push(said);
        } else if line.chars().count() > LINE {
            let cut: String = line.chars().take(LINE).collect();
            out.push(format!("{cut}… ({} characters)", line.chars().count()));
        } else {
            out.push(line.to_owned());
        }
    }
    out.join("\n")
}

/// serde's message for an unknown key or value (`unknown field `swing_half_angle_arcsex`,
/// expected one of `name`, `swing_half_angle_arcsec`, ...`) said for a person: the closest valid
/// name(s) by edit distance, and every valid name of the section (None for any other line).
#[must_use]
pub fn did_you_mean(line: &str) -> Option<String> {
    let (what, rest) = [("field", "key"), ("variant", "value")]
        .iter()
        .find_map(|(serde_word, ours)| line.strip_prefix(&format!("unknown {serde_word} `")).map(|r| (*ours, r)))?;
    let (given, rest) = rest.split_once('`')?;
    let rest = rest.strip_prefix(", ")?;
    let valid: Vec<&str> = if rest.starts_with("there are no") {
        Vec::new()
    } else {
        let list = rest.strip_prefix("expected one of ").or_else(|| rest.strip_prefix("expected "))?;
        list.split('`').skip(1).step_by(2).collect()
    };
    if valid.is_empty() {
        return Some(format!("unknown {what} `{given}`: this section takes none"));
    }
    // The closest by edit distance, if close enough to be a slip (a third of the name, at least 2).
    let distance = |v: &str| strsim::damerau_levenshtein(&given.to_lowercase(), &v.to_lowercase());
    let best = valid.iter().map(|v| distance(v)).min().unwrap_or(usize::MAX);
    let near: Vec<String> = valid
        .iter()
        .filter(|v| distance(v) == best && best <= (given.chars().count() / 3).max(2))
        .map(|v| format!("`{v}`"))
        .collect();
    let hint = if near.is_empty() { String::new() } else { format!("; did you mean {}?", near.join(" or ")) };
    Some(format!("unknown {what} `{given}`{hint}\nvalid {what}s here ({}): {}", valid.len(), valid.join(", ")))
}

/// Every leaf of a resolved config as `dotted.key -> value text` (arrays of tables indexed `[i]`),
/// for describing what changed between two versions.
#[must_use]
pub fn flatten(raw: &RawConfig) -> BTreeMap<String, String> {
    fn walk(prefix: &str, v: &toml::Value, out: &mut BTreeMap<String, String>) {
        match v {
            toml::Value::Table(t) => {
                for (k, x) in t {
                    let key = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
                    walk(&key, x, out);
                }
            }
            toml::Value::Array(a) if a.iter().all(toml::Value::is_table) && !a.is_empty() => {
                for (i, x) in a.iter().enumerate() {
                    walk(&format!("{prefix}[{i}]"), x, out);
                }
            }
            other => {
                out.insert(prefix.to_owned(), other.to_string());
            }
        }
    }
    let mut out = BTreeMap::new();
    if let Ok(v) = toml::Value::try_from(raw) {
        walk("", &v, &mut out);
    }
    out
}

/// The `[compensation]` keys that state `errors` on `chain` (every key given): what a calibration
/// writes for `replay --compensation` and a scenario's `[compensation]`.
#[must_use]
pub fn compensation_keys(
    chain: &crate::model::gimbal::Chain,
    errors: &crate::model::gimbal::TableErrors,
) -> raw::RawCompensation {
    use crate::math::units::{ARCSEC_PER_RAD, DEG_PER_RAD};
    let arcsec = |x: f64| Some(x * ARCSEC_PER_RAD);
    let mut axis = BTreeMap::new();
    for (g, e) in chain.axes().iter().zip(&errors.axes) {
        axis.insert(
            g.name.clone(),
            raw::RawAxisCompensation {
                swing_half_angle_arcsec: arcsec(e.swing_half_angle_rad),
                swing_phase_deg: Some(e.swing_phase_rad * DEG_PER_RAD),
                non_orthogonality_arcsec: arcsec(e.non_orthogonality_rad),
                encoder_offset_arcsec: arcsec(e.encoder_offset_rad),
                encoder_scale_ppm: Some(e.encoder_scale * 1e6),
                encoder_delay_ms: Some(e.encoder_delay_s * 1e3),
            },
        );
    }
    raw::RawCompensation {
        enabled: Some(true),
        installation_x_arcsec: arcsec(errors.installation_rad.x),
        installation_y_arcsec: arcsec(errors.installation_rad.y),
        installation_z_arcsec: arcsec(errors.installation_rad.z),
        imu_mount_x_arcsec: arcsec(errors.imu_mount_rad.x),
        imu_mount_y_arcsec: arcsec(errors.imu_mount_rad.y),
        imu_mount_z_arcsec: arcsec(errors.imu_mount_rad.z),
        axis,
    }
}

/// An indexed sequence as a `[scheme]` table of TOML (what `rinscope design` prints and `schemes`
/// reads): `steps` on the chain's `axes`, repeated, after `initial_dwell_s`.
#[must_use]
pub fn indexed_scheme_toml(
    axes: &[String],
    initial_dwell_s: f64,
    steps: &[crate::model::scheme::IndexedStep],
) -> String {
    #[derive(serde::Serialize)]
    struct File {
        scheme: raw::RawScheme,
    }
    // Degrees back from radians to the digits they were given in.
    let deg = |rad: f64| (rad.to_degrees() * 1e9).round() / 1e9;
    let scheme = raw::RawScheme {
        kind: "indexed".into(),
        rate: Vec::new(),
        initial_dwell_s: Some(initial_dwell_s),
        repeat: Some(true),
        step: steps
            .iter()
            .map(|s| raw::RawStep {
                axis: axes.get(s.axis).cloned().unwrap_or_default(),
                angle_deg: deg(s.angle_rad),
                rate_deg_per_s: deg(s.rate_rad_per_s),
                dwell_s: s.dwell_s,
                accel_deg_per_s2: deg(s.accel_rad_per_s2),
            })
            .collect(),
    };
    toml::to_string(&File { scheme }).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_misspelt_key_gets_the_closest_and_the_whole_list() {
        // Issue 31: the list of valid keys was cut, with no "did you mean".
        let keys: Vec<String> = (0..40).map(|i| format!("`key_number_{i:02}_with_a_long_name`")).collect();
        let line = format!("unknown field `key_number_07_with_a_lng_name`, expected one of {}", keys.join(", "));
        let said = super::did_you_mean(&line).expect("recognised");
        assert!(said.contains("did you mean `key_number_07_with_a_long_name`?"), "{said}");
        assert!(said.contains("key_number_39_with_a_long_name") && said.contains("(40)"), "the whole list: {said}");
        let said = super::did_you_mean("unknown field `duraton_s`, expected `duration_s` or `step_hz`").expect("two");
        assert!(said.contains("did you mean `duration_s`?") && said.contains("duration_s, step_hz"), "{said}");
        let said = super::did_you_mean("unknown field `zzzzzzzz`, expected `duration_s`").expect("one");
        assert!(!said.contains("did you mean") && said.contains("duration_s"), "{said}");
        assert!(
            super::did_you_mean("unknown variant `sin`, expected one of `sine`, `square`")
                .expect("variant")
                .contains("did you mean `sine`?")
        );
        assert!(super::did_you_mean("invalid type: string, expected f64").is_none());
        // Through the parser, as a user meets it: the whole list, never cut.
        let e = super::parse("[simulation]\nduraton_s = 3\n", "t.toml").expect_err("typo").to_string();
        assert!(e.contains("did you mean `duration_s`?"), "{e}");
    }
}
