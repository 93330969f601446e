//! Unit conversions: SI and radians inside, units in the name at every edge.

/// Radians per degree.
pub const RAD_PER_DEG: f64 = std::f64::consts::PI / 180.0;
/// Radians per arcminute.
pub const RAD_PER_ARCMIN: f64 = RAD_PER_DEG / 60.0;
/// Radians per arcsecond.
pub const RAD_PER_ARCSEC: f64 = RAD_PER_DEG / 3600.0;
/// Arcseconds per radian.
pub const ARCSEC_PER_RAD: f64 = 1.0 / RAD_PER_ARCSEC;
/// Degrees per radian.
pub const DEG_PER_RAD: f64 = 1.0 / RAD_PER_DEG;
/// rad/s per deg/h (a gyro bias or a rate).
pub const RAD_PER_S_PER_DEG_PER_H: f64 = RAD_PER_DEG / 3600.0;
/// rad/√s per deg/√h (an angle random walk).
pub const RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H: f64 = RAD_PER_DEG / 60.0;
/// rad/s/√s per deg/h/√h (a gyro's rate random walk K; √h = 60 √s).
pub const RAD_PER_S_PER_SQRT_S_PER_DEG_PER_H_PER_SQRT_H: f64 = RAD_PER_S_PER_DEG_PER_H / 60.0;
/// rad/s² per deg/h² (a gyro's rate ramp R).
pub const RAD_PER_S2_PER_DEG_PER_H2: f64 = RAD_PER_DEG / (3600.0 * 3600.0);
/// Standard gravity g₀, m/s² (the unit of "µg" and "per g"; CGPM 1901).
pub const STANDARD_GRAVITY_MPS2: f64 = 9.806_65;
/// m/s² per µg: g₀ × 10⁻⁶, written out (the product `STANDARD_GRAVITY_MPS2 * 1e-6` rounds to
/// the next double; every number this program has printed used this one).
pub const MPS2_PER_UG: f64 = 9.806_65e-6;
/// The Earth's rotation rate, WGS 84, rad/s.
pub const EARTH_RATE_RAD_PER_S: f64 = 7.292_115e-5;
/// m/s/√s per µg/√Hz (an accelerometer's velocity random walk N: m/s²/√Hz is m/s/√s).
pub const MPS_PER_SQRT_S_PER_UG_PER_SQRT_HZ: f64 = MPS2_PER_UG;
/// m/s²/√s per µg/√h (an accelerometer's acceleration random walk K).
pub const MPS2_PER_SQRT_S_PER_UG_PER_SQRT_H: f64 = MPS2_PER_UG / 60.0;
/// m/s³ per µg/h (an accelerometer's acceleration ramp R).
pub const MPS3_PER_UG_PER_H: f64 = MPS2_PER_UG / 3600.0;

/// A heading in degrees as people write it: [0, 360), with −0.00001° shown as 0, not 359.99999.
#[must_use]
pub fn heading_deg_0_360(heading_rad: f64) -> f64 {
    let h = heading_rad.to_degrees().rem_euclid(360.0);
    if h >= 360.0 - 5e-7 { 0.0 } else { h }
}

/// Wraps an angle difference into (-pi, pi].
#[must_use]
pub fn wrap_pi(angle_rad: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    // Differences of wrapped angles are within (-2pi, 2pi): one conditional turn suffices up to 3pi,
    // and the hot path needs no division.
    let a = if angle_rad.abs() <= 3.0 * PI { angle_rad } else { angle_rad - TAU * (angle_rad / TAU).round() };
    if a > PI {
        a - TAU
    } else if a <= -PI {
        a + TAU
    } else {
        a
    }
}

/// Formats an angle given in radians the way an inertial engineer reads it:
/// arcseconds below 1', arcminutes below 1 deg, degrees above.
#[must_use]
pub fn fmt_angle(angle_rad: f64) -> String {
    let arcsec = angle_rad * ARCSEC_PER_RAD;
    if arcsec.abs() < 60.0 {
        format!("{arcsec:.2}″")
    } else if arcsec.abs() < 3600.0 {
        format!("{:.3}′", arcsec / 60.0)
    } else {
        format!("{:.4}°", arcsec / 3600.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_pi_keeps_small_angles_and_folds_large_ones() {
        assert!((wrap_pi(0.1) - 0.1).abs() < 1e-15);
        assert!((wrap_pi(-0.1) + 0.1).abs() < 1e-15);
        // 350 deg - 0 deg is a -10 deg difference.
        assert!((wrap_pi(350.0 * RAD_PER_DEG) + 10.0 * RAD_PER_DEG).abs() < 1e-12);
        assert!((wrap_pi(-190.0 * RAD_PER_DEG) - 170.0 * RAD_PER_DEG).abs() < 1e-12);
        // Every result is in (-pi, pi] and differs from the input by whole turns.
        for i in -2000..=2000 {
            let a = f64::from(i) * 0.0137;
            let w = wrap_pi(a);
            assert!(w > -std::f64::consts::PI && w <= std::f64::consts::PI, "{a} -> {w}");
            let turns = (a - w) / std::f64::consts::TAU;
            assert!((turns - turns.round()).abs() < 1e-9, "{a} -> {w}");
        }
    }

    #[test]
    fn arcsec_conversions_round_trip() {
        // 1 deg = 3600 arcsec by definition.
        assert!((3600.0 * RAD_PER_ARCSEC - RAD_PER_DEG).abs() < 1e-18);
        assert!((RAD_PER_ARCMIN * 60.0 - RAD_PER_DEG).abs() < 1e-18);
    }
}

/// The unit an angle plot reads in: chosen per scenario so its numbers read naturally.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AngleUnit {
    /// Arcseconds.
    #[default]
    Arcsec,
    /// Arcminutes.
    Arcmin,
    /// Degrees.
    Deg,
}

impl AngleUnit {
    /// Every choice, smallest first.
    pub const ALL: [Self; 3] = [Self::Arcsec, Self::Arcmin, Self::Deg];

    /// Its name as entity paths and columns spell it (`arcsec`, `arcmin`, `deg`).
    #[must_use]
    pub fn suffix(self) -> &'static str {
        match self {
            Self::Arcsec => "arcsec",
            Self::Arcmin => "arcmin",
            Self::Deg => "deg",
        }
    }

    /// Units of this per radian.
    #[must_use]
    pub fn per_rad(self) -> f64 {
        match self {
            Self::Arcsec => ARCSEC_PER_RAD,
            Self::Arcmin => ARCSEC_PER_RAD / 60.0,
            Self::Deg => DEG_PER_RAD,
        }
    }

    /// Parses a suffix.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|u| u.suffix() == s)
    }

    /// The unit a signal of `peak_rad` reads naturally in: the largest in which its peak is at
    /// least one (1.07° in degrees, 10′ in arcminutes, 45″ in arcseconds); arcsec for (almost)
    /// nothing. The plot's range then follows [`nice_half_range`].
    #[must_use]
    pub fn for_peak(peak_rad: f64) -> Self {
        if !(peak_rad.is_finite() && peak_rad > 0.0) {
            return Self::Arcsec;
        }
        [Self::Deg, Self::Arcmin].into_iter().find(|u| peak_rad * u.per_rad() >= 1.0).unwrap_or(Self::Arcsec)
    }
}

/// The half-range of a symmetric plot for a signal of `peak` (in the plot's unit): the smallest of
/// 1, 2, 3 × 10^k at or above 1.05 × peak. Drawn at ±1.25 × that (`record::blueprint::symmetric_range`),
/// a plot's power-of-ten grid labels 3, 5 or 7 ticks (a span of 1.2 × 10^k would show one, 5 × 10^k
/// none but 0 in a plot 170 px high).
#[must_use]
pub fn nice_half_range(peak: f64) -> f64 {
    let p = (peak.abs() * 1.05).max(1e-12);
    let k = p.log10().floor();
    let base = 10f64.powf(k);
    [1.0, 2.0, 3.0, 10.0].into_iter().map(|m| m * base).find(|h| *h >= p).unwrap_or(10.0 * base)
}

/// The 1, 2, 5 × 10^k "round" values of a logarithmic scale (drawing factors, slider steps):
/// the smallest at or above `v` (> 0).
#[must_use]
pub fn nice_at_least(v: f64) -> f64 {
    let decade = 10f64.powf(v.log10().floor());
    // The decade's ×10 rung catches log10's rounding (log10(1000) = 2.9999999999999996).
    [1.0, 2.0, 5.0, 10.0].into_iter().map(|m| m * decade).find(|r| *r >= v).unwrap_or(10.0 * decade)
}

/// The largest 1, 2, 5 × 10^k value at or below `v` (> 0).
#[must_use]
pub fn nice_at_most(v: f64) -> f64 {
    let decade = 10f64.powf(v.log10().floor());
    [10.0, 5.0, 2.0, 1.0].into_iter().map(|m| m * decade).find(|r| *r <= v).unwrap_or(decade)
}

#[cfg(test)]
mod angle_unit_tests {
    use super::*;

    #[test]
    fn the_1_2_5_scale_rounds_up_and_down_onto_its_rungs() {
        assert_eq!(nice_at_least(360.0), 500.0);
        assert_eq!(nice_at_least(500.0), 500.0);
        assert_eq!(nice_at_least(1000.0), 1000.0);
        assert_eq!(nice_at_least(0.03), 0.05);
        assert_eq!(nice_at_most(278.0), 200.0);
        assert_eq!(nice_at_most(1000.0), 1000.0);
        assert_eq!(nice_at_most(0.09), 0.05);
    }

    #[test]
    fn plot_ranges_have_labelled_ticks_and_units_read_naturally() {
        // Spans of 2, 4 or 6 × 10^k, at or above 1.05 × the peak.
        assert_eq!(nice_half_range(603.8), 1000.0);
        assert_eq!(nice_half_range(300.06), 1000.0);
        assert_eq!(nice_half_range(280.0), 300.0);
        assert_eq!(nice_half_range(0.1075), 0.2);
        assert_eq!(nice_half_range(1.0695), 2.0);
        // The rotary-table paper's "about 1 degree" reads in degrees; Jiang et al. 2017's 10′ errors in arcminutes, as the
        // paper gives them; encoder-noise arcseconds stay arcseconds.
        assert_eq!(AngleUnit::for_peak(1.0695 * RAD_PER_DEG), AngleUnit::Deg);
        assert_eq!(AngleUnit::for_peak(603.8 * RAD_PER_ARCSEC), AngleUnit::Arcmin);
        assert_eq!(AngleUnit::for_peak(0.1075 * RAD_PER_DEG), AngleUnit::Arcmin);
        assert_eq!(AngleUnit::for_peak(45.0 * RAD_PER_ARCSEC), AngleUnit::Arcsec);
        assert_eq!(AngleUnit::for_peak(0.0), AngleUnit::Arcsec);
    }
}
