//! The Earth and a site on it: WGS84 rate, radii of curvature and normal gravity, the Earth rate
//! in the local-level (East-North-Up) frame.

use nalgebra::Vector3;

/// Site on Earth.
#[derive(Debug, Clone, Copy)]
pub struct Site {
    /// Geodetic latitude, rad.
    pub latitude_rad: f64,
    /// Longitude, rad.
    pub longitude_rad: f64,
    /// Height, m.
    pub height_m: f64,
}

/// Earth's rotation rate, rad/s (WGS84; defined in `math::units`).
pub const EARTH_RATE: f64 = crate::math::units::EARTH_RATE_RAD_PER_S;
/// WGS84 semi-major axis, m.
pub const EARTH_A: f64 = 6_378_137.0;
/// WGS84 first eccentricity squared.
pub const EARTH_E2: f64 = 0.006_694_379_990_14;

/// Normal gravity (WGS84 Somigliana, with the free-air gradient), m/s², at latitude and height.
#[must_use]
pub fn normal_gravity(latitude_rad: f64, height_m: f64) -> f64 {
    let s2 = latitude_rad.sin().powi(2);
    let g0 = 9.780_325_335_9 * (1.0 + 0.001_931_852_652_41 * s2) / (1.0 - EARTH_E2 * s2).sqrt();
    g0 - 3.086e-6 * height_m
}

/// The Earth seen from a site: rate and gravity in the navigation frame (ENU).
#[derive(Debug, Clone, Copy)]
pub struct Earth {
    /// ω_ie^n = Ω (0, cos L, sin L).
    pub omega_ie_n: Vector3<f64>,
    /// Gravity (with centrifugal) in n: (0, 0, −g).
    pub gravity_n: Vector3<f64>,
    /// Site.
    pub site: Site,
}

impl Earth {
    /// At `site`.
    #[must_use]
    pub fn at(site: Site) -> Self {
        Self {
            omega_ie_n: omega_ie_n(site.latitude_rad),
            gravity_n: Vector3::new(0.0, 0.0, -normal_gravity(site.latitude_rad, site.height_m)),
            site,
        }
    }

    /// Meridian and transverse radii of curvature, m.
    #[must_use]
    pub fn radii(latitude_rad: f64) -> (f64, f64) {
        let w = (1.0 - EARTH_E2 * latitude_rad.sin().powi(2)).sqrt();
        (EARTH_A * (1.0 - EARTH_E2) / (w * w * w), EARTH_A / w)
    }
}

/// The Earth's rate in the local-level frame at geodetic latitude `latitude_rad`:
/// ω_ie^n = Ω (0, cos L, sin L) (East, North, Up), rad/s.
#[must_use]
pub fn omega_ie_n(latitude_rad: f64) -> Vector3<f64> {
    let (sl, cl) = latitude_rad.sin_cos();
    Vector3::new(0.0, EARTH_RATE * cl, EARTH_RATE * sl)
}

/// Schuler frequency, rad/s: √(g/R) ≈ 1.24e-3.
#[must_use]
pub fn schuler_rate() -> f64 {
    (normal_gravity(0.0, 0.0) / EARTH_A).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_gravity_at_the_equator_and_pole() {
        // WGS84 normal gravity: 9.7803253359 (equator), 9.8321849378 (pole).
        assert!((normal_gravity(0.0, 0.0) - 9.780_325_335_9).abs() < 1e-9);
        assert!((normal_gravity(std::f64::consts::FRAC_PI_2, 0.0) - 9.832_184_937_8).abs() < 1e-7);
    }

    #[test]
    fn schuler_period_is_84_minutes() {
        // T = 2π √(a/g₀) with a = 6 378 137 m, g₀ = 9.780 325 m/s²: 2π·807.55 s = 84.57 min.
        let t_min = std::f64::consts::TAU / schuler_rate() / 60.0;
        assert!((t_min - 84.57).abs() < 0.01, "{t_min}");
    }
}
