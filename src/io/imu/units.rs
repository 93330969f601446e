//! Units carried in column names (`gyro_x_deg_per_h`, `dv_z_mps`, `t_ns`): parsing and conversion to SI.
//!
//! A column name is `<base>_<unit>`. The unit is the longest suffix from the table below that
//! follows an underscore, so `gyro_x_rad_per_s` is an angular rate in rad/s and `t_s` a time in s.
//!
//! | suffix | quantity | factor to SI |
//! |---|---|---|
//! | `rad`, `mrad`, `urad`, `deg`, `arcsec` | angle (rad) | 1, 1e-3, 1e-6, π/180, π/648000 |
//! | `rad_per_s`, `deg_per_s`, `deg_per_h` | angular rate (rad/s) | 1, π/180, π/648000 |
//! | `mps`, `m_per_s` | velocity (m/s) | 1 |
//! | `mps2`, `m_per_s2`, `g`, `mg`, `ug` | acceleration (m/s²) | 1, 1, g₀, 1e-3 g₀, 1e-6 g₀ (g₀ = 9.80665, standard gravity) |
//! | `s`, `ms`, `us`, `ns`, `ps` | time (s) | 1, 1e-3, 1e-6, 1e-9, 1e-12 |
//! | `m` | length (m) | 1 |
//! | `ppm`, `ppb`, `ppt`, `1`, `count` | dimensionless | 1e-6, 1e-9, 1e-12, 1, 1 |

use std::f64::consts::PI;

/// Standard gravity g₀ (m/s²), the conversion factor of the `_g` unit.
pub use crate::math::units::STANDARD_GRAVITY_MPS2;

/// The physical quantity of a unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Angle or angle increment (SI: rad).
    Angle,
    /// Angular rate (SI: rad/s).
    AngularRate,
    /// Velocity or velocity increment (SI: m/s).
    Velocity,
    /// Acceleration / specific force (SI: m/s²).
    Acceleration,
    /// Time (SI: s).
    Time,
    /// Length (SI: m).
    Length,
    /// A pure number.
    Dimensionless,
}

impl Quantity {}

/// A unit recognised in a column name.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unit {
    /// The suffix as written in the name, e.g. `deg_per_h`.
    pub suffix: &'static str,
    /// What it measures.
    pub quantity: Quantity,
    /// Multiply a value in this unit by this to get SI.
    pub to_si: f64,
}

const ARCSEC: f64 = crate::math::units::RAD_PER_ARCSEC;

const UNITS: &[Unit] = &[
    Unit { suffix: "rad", quantity: Quantity::Angle, to_si: 1.0 },
    Unit { suffix: "mrad", quantity: Quantity::Angle, to_si: 1e-3 },
    Unit { suffix: "urad", quantity: Quantity::Angle, to_si: 1e-6 },
    Unit { suffix: "deg", quantity: Quantity::Angle, to_si: PI / 180.0 },
    Unit { suffix: "arcsec", quantity: Quantity::Angle, to_si: ARCSEC },
    Unit { suffix: "arcmin", quantity: Quantity::Angle, to_si: ARCSEC * 60.0 },
    Unit { suffix: "rad_per_s", quantity: Quantity::AngularRate, to_si: 1.0 },
    Unit { suffix: "deg_per_s", quantity: Quantity::AngularRate, to_si: PI / 180.0 },
    Unit { suffix: "deg_per_h", quantity: Quantity::AngularRate, to_si: ARCSEC },
    Unit { suffix: "mps", quantity: Quantity::Velocity, to_si: 1.0 },
    Unit { suffix: "m_per_s", quantity: Quantity::Velocity, to_si: 1.0 },
    Unit { suffix: "mps2", quantity: Quantity::Acceleration, to_si: 1.0 },
    Unit { suffix: "m_per_s2", quantity: Quantity::Acceleration, to_si: 1.0 },
    Unit { suffix: "g", quantity: Quantity::Acceleration, to_si: STANDARD_GRAVITY_MPS2 },
    Unit { suffix: "mg", quantity: Quantity::Acceleration, to_si: 1e-3 * STANDARD_GRAVITY_MPS2 },
    Unit { suffix: "ug", quantity: Quantity::Acceleration, to_si: 1e-6 * STANDARD_GRAVITY_MPS2 },
    Unit { suffix: "s", quantity: Quantity::Time, to_si: 1.0 },
    Unit { suffix: "ms", quantity: Quantity::Time, to_si: 1e-3 },
    Unit { suffix: "us", quantity: Quantity::Time, to_si: 1e-6 },
    Unit { suffix: "ns", quantity: Quantity::Time, to_si: 1e-9 },
    Unit { suffix: "ps", quantity: Quantity::Time, to_si: 1e-12 },
    Unit { suffix: "m", quantity: Quantity::Length, to_si: 1.0 },
    Unit { suffix: "ppm", quantity: Quantity::Dimensionless, to_si: 1e-6 },
    Unit { suffix: "ppb", quantity: Quantity::Dimensionless, to_si: 1e-9 },
    Unit { suffix: "ppt", quantity: Quantity::Dimensionless, to_si: 1e-12 },
    Unit { suffix: "1", quantity: Quantity::Dimensionless, to_si: 1.0 },
    Unit { suffix: "count", quantity: Quantity::Dimensionless, to_si: 1.0 },
];

/// Splits a column name into its base and unit: `"gyro_x_deg_per_h"` → `("gyro_x", deg_per_h)`.
/// `None` when the name ends in no known unit (or is only a unit).
#[must_use]
pub fn split_unit(name: &str) -> Option<(&str, Unit)> {
    let mut best: Option<(&str, Unit)> = None;
    for unit in UNITS {
        let Some(base) = name.strip_suffix(unit.suffix) else {
            continue;
        };
        let Some(base) = base.strip_suffix('_') else {
            continue;
        };
        if base.is_empty() {
            continue;
        }
        if best.is_none_or(|(_, b)| unit.suffix.len() > b.suffix.len()) {
            best = Some((base, *unit));
        }
    }
    best
}

/// A unit written on its own, as a user types it on a command line: the suffixes above, or the
/// same with `/` for `_per_`, `µ` for `u`, `^2` or `²` for `2` and `m/s2` for `mps2`
/// (`deg/h`, `m/s^2`, `µg`, `ns`).
#[must_use]
pub fn unit_named(text: &str) -> Option<Unit> {
    let t = text.trim().replace('µ', "u").replace("^2", "2").replace('²', "2").replace('/', "_per_");
    let t = match t.as_str() {
        "m_per_s2" | "m_per_s_per_s" => "mps2".to_owned(),
        "m_per_s" => "mps".to_owned(),
        "" => "1".to_owned(),
        _ => t,
    };
    UNITS.iter().find(|u| u.suffix == t).copied()
}

/// Every unit of `quantity` as a user writes it (`deg/h`), for error messages.
#[must_use]
pub fn units_for(quantity: Quantity) -> String {
    UNITS
        .iter()
        .filter(|u| u.quantity == quantity)
        .map(|u| u.suffix.replace("_per_", "/"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The list of accepted suffixes for a quantity, for error messages.
#[must_use]
pub fn suffixes_for(quantity: Quantity) -> String {
    UNITS.iter().filter(|u| u.quantity == quantity).map(|u| format!("_{}", u.suffix)).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn longest_suffix_wins() {
        let (base, unit) = split_unit("gyro_x_rad_per_s").unwrap();
        assert_eq!((base, unit.suffix, unit.quantity), ("gyro_x", "rad_per_s", Quantity::AngularRate));
        let (base, unit) = split_unit("accel_z_mps2").unwrap();
        assert_eq!((base, unit.suffix), ("accel_z", "mps2"));
        let (base, unit) = split_unit("t_ns").unwrap();
        assert_eq!((base, unit.suffix), ("t", "ns"));
        let (base, unit) = split_unit("gps_sow_s").unwrap();
        assert_eq!((base, unit.suffix), ("gps_sow", "s"));
        assert!(split_unit("gyro_x").is_none());
        assert!(split_unit("s").is_none());
        assert!(split_unit("gyro_x_furlong").is_none());
    }

    #[test]
    fn factors() {
        // 1 deg/h = π/180/3600 rad/s = 4.84813681109536e-6 rad/s (definition).
        let (_, u) = split_unit("w_deg_per_h").unwrap();
        assert!((u.to_si - 4.848_136_811_095_36e-6).abs() < 1e-18);
        let (_, u) = split_unit("a_g").unwrap();
        assert_eq!(u.to_si, 9.80665);
    }
}
