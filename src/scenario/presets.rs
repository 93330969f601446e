//! The scenario presets shipped in `assets/scenarios/`, embedded in the binary so that it runs
//! anywhere; `--config FILE` reads any other file in the same format.

use super::{ConfigError, Params};

/// The scenario `rinscope` runs with no arguments.
pub const DEFAULT_SCENARIO: &str = "jiang2017-dual-axis";

/// (name, TOML text) of every preset, in display order.
pub const PRESETS: &[(&str, &str)] = &[
    ("jiang2017-dual-axis", include_str!("../../assets/scenarios/jiang2017-dual-axis.toml")),
    ("jiang2017-calibration", include_str!("../../assets/scenarios/jiang2017-calibration.toml")),
    ("rotary-table-2016-installation", include_str!("../../assets/scenarios/rotary-table-2016-installation.toml")),
    ("rotary-table-2016-wobble", include_str!("../../assets/scenarios/rotary-table-2016-wobble.toml")),
    ("rotary-table-2016-angular", include_str!("../../assets/scenarios/rotary-table-2016-angular.toml")),
    ("dual-axis-8-position", include_str!("../../assets/scenarios/dual-axis-8-position.toml")),
    ("dual-axis-16-position", include_str!("../../assets/scenarios/dual-axis-16-position.toml")),
    ("budget-dual-axis-16", include_str!("../../assets/scenarios/budget-dual-axis-16.toml")),
    ("li2014-phase-lag", include_str!("../../assets/scenarios/li2014-phase-lag.toml")),
    ("li2014-coning", include_str!("../../assets/scenarios/li2014-coning.toml")),
    ("li2014-wobble-1", include_str!("../../assets/scenarios/li2014-wobble-1.toml")),
    ("li2014-wobble-2", include_str!("../../assets/scenarios/li2014-wobble-2.toml")),
    ("pure-coning", include_str!("../../assets/scenarios/pure-coning.toml")),
    ("zheng2016-tpr", include_str!("../../assets/scenarios/zheng2016-tpr.toml")),
    ("static-imu-10h", include_str!("../../assets/scenarios/static-imu-10h.toml")),
    ("rotation-modulation-none", include_str!("../../assets/scenarios/rotation-modulation-none.toml")),
    ("rotation-modulation-continuous", include_str!("../../assets/scenarios/rotation-modulation-continuous.toml")),
    ("rotation-modulation-16-position", include_str!("../../assets/scenarios/rotation-modulation-16-position.toml")),
    ("selfcal-nav-grade", include_str!("../../assets/scenarios/selfcal-nav-grade.toml")),
    ("sensors2014-rate", include_str!("../../assets/scenarios/sensors2014-rate.toml")),
];

/// The TOML text of a preset.
#[must_use]
pub fn text(name: &str) -> Option<&'static str> {
    PRESETS.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

/// Parses a preset by name.
pub fn load(name: &str) -> Result<Params, ConfigError> {
    let Some(t) = text(name) else {
        let names: Vec<&str> = PRESETS.iter().map(|(n, _)| *n).collect();
        return Err(ConfigError::Invalid {
            origin: "--scenario".into(),
            key: name.into(),
            message: format!("no such scenario; the presets are {} (see `rinscope scenarios`)", names.join(", ")),
        });
    };
    super::parse(t, &format!("assets/scenarios/{name}.toml"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_parses_and_is_named_after_its_file() {
        for (name, _) in PRESETS {
            let p = load(name).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(&p.meta.name, name);
            assert!(!p.meta.description.trim().is_empty(), "{name} explains itself");
        }
    }
}
