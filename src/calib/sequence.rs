//! The built-in self-calibration sequences of a dual-axis table (docs/selfcal.md, "Sequences").

use crate::math::units::RAD_PER_DEG;
use crate::model::scheme::IndexedStep;

/// A built-in calibration sequence of a dual-axis table (outer axis first in the chain, the inner
/// one carrying the IMU about its z): table moves and dwells.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sequence {
    /// 19 positions joined by 18 rotations of 90° and 180° about each IMU axis (z while
    /// horizontal), in both senses, 240 s at each, after PSINS's systematic calibration
    /// (`sysclbt`); 1.4 h.
    Positions19,
    /// 29 positions: about the IMU's z (held horizontal), y and x in turn, four quarter turns
    /// forward and four back, 160 s at each (the kind of sequence Cai et al. 2016 and Ren et al.
    /// 2019 use); 1.4 h.
    DualAxis29,
    /// Only the inner (azimuth) axis turns: what it cannot see is the point (a degenerate case).
    AzimuthOnly,
}

impl Sequence {
    /// Every built-in, with its command-line name.
    pub const ALL: [(Self, &'static str); 3] =
        [(Self::Positions19, "positions-19"), (Self::DualAxis29, "dual-axis-29"), (Self::AzimuthOnly, "azimuth-only")];

    /// By its command-line name.
    #[must_use]
    pub fn named(name: &str) -> Option<Self> {
        Self::ALL.iter().find(|(_, n)| *n == name).map(|(s, _)| *s)
    }

    /// Its command-line name.
    #[must_use]
    pub fn name(self) -> &'static str {
        Self::ALL.iter().find(|(s, _)| *s == self).map_or("", |(_, n)| n)
    }

    /// The table moves (outer axis 0, inner axis 1) and the dwell before the first move, s.
    #[must_use]
    pub fn steps(self) -> (f64, Vec<IndexedStep>) {
        // (axis, degrees): the inner axis is the IMU's z; the outer turns the IMU about its y
        // with the inner at 0° or 180°, about its x with the inner at ±90°.
        let (z, o) = (1usize, 0usize);
        let (moves, dwell): (Vec<(usize, f64)>, f64) = match self {
            Self::Positions19 => (
                vec![
                    (o, 90.0), // z horizontal
                    (z, 90.0),
                    (z, 90.0),
                    (z, 90.0),
                    (z, 90.0), // about z, gravity sweeping the x-y plane
                    (o, 90.0),
                    (o, 90.0),
                    (o, 90.0), // about y: z down, horizontal, up
                    (z, 90.0), // x onto the outer axis
                    (o, 90.0),
                    (o, 90.0),
                    (o, 90.0),
                    (o, 90.0), // about x
                    (o, -180.0),
                    (o, 180.0), // about x, back and forth
                    (z, -90.0), // y onto the outer axis
                    (o, -180.0),
                    (o, 180.0), // about y, back and forth
                ],
                240.0,
            ),
            Self::DualAxis29 => {
                let mut m = vec![(o, 90.0)];
                // About z with z horizontal (a z scale error then tilts the IMU, which the
                // accelerometers see; about a vertical z it would only turn the heading).
                m.extend(std::iter::repeat_n((z, 90.0), 4));
                m.extend(std::iter::repeat_n((z, -90.0), 4));
                m.push((o, -90.0));
                // About y (inner at 0°), then about x (inner at 90°).
                m.extend(std::iter::repeat_n((o, 90.0), 4));
                m.extend(std::iter::repeat_n((o, -90.0), 4));
                m.push((z, 90.0));
                m.extend(std::iter::repeat_n((o, 90.0), 4));
                m.extend(std::iter::repeat_n((o, -90.0), 4));
                m.push((z, -90.0));
                (m, 160.0)
            }
            Self::AzimuthOnly => (
                std::iter::repeat_n((z, 90.0), 4)
                    .chain(std::iter::repeat_n((z, -90.0), 4))
                    .chain(std::iter::repeat_n((z, 90.0), 4))
                    .collect(),
                300.0,
            ),
        };
        let rate = 10.0 * RAD_PER_DEG;
        let steps = moves
            .into_iter()
            .map(|(axis, deg)| IndexedStep {
                axis,
                angle_rad: deg * RAD_PER_DEG,
                rate_rad_per_s: rate,
                dwell_s: dwell,
                accel_rad_per_s2: rate,
            })
            .collect();
        (INITIAL_DWELL_S, steps)
    }
}

impl Sequence {
    /// The table's motion through the sequence (outer and inner axis from 0°, not repeated).
    #[must_use]
    pub fn scheme(self) -> crate::model::scheme::Scheme {
        let (dwell, steps) = self.steps();
        crate::model::scheme::Scheme::indexed(vec![0.0; 2], dwell, steps, false)
    }

    /// Its length, s: the first dwell and every move with its dwell.
    #[must_use]
    pub fn duration_s(self) -> f64 {
        let scheme = self.scheme();
        self.steps().0 + scheme.period_s()
    }
}

/// The dwell before the first move: the coarse alignment's data, s.
pub const INITIAL_DWELL_S: f64 = 300.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sequences_stay_within_two_hours_and_end_where_they_started() {
        for (s, _) in Sequence::ALL {
            let steps = s.steps().1;
            let total = s.duration_s();
            assert!(total <= 2.0 * 3600.0, "{}: {total} s", s.name());
            for axis in 0..2 {
                let turned: f64 = steps.iter().filter(|m| m.axis == axis).map(|m| m.angle_rad).sum();
                assert!(
                    (turned / std::f64::consts::TAU).fract().abs() < 1e-9,
                    "{}: axis {axis} ends at {turned} rad",
                    s.name()
                );
            }
        }
    }
}
