//! How large the table's errors are drawn: each class's exaggeration, raised where the scenario's
//! would draw it too small to see, and the floor an error plot is framed on.

use crate::model::gimbal::{ClassFactors, TableErrors};

/// The classes drawn with a factor of their own (not the scenario's `x`), as "η ×500".
pub(super) fn own_factors(f: &ClassFactors, x: f64) -> Vec<String> {
    [("swing", f.swing), ("η", f.non_orthogonality), ("installation", f.installation), ("IMU mounting", f.imu_mount)]
        .iter()
        .filter(|(_, v)| *v != x)
        .map(|(n, v)| format!("{n} ×{v}"))
        .collect()
}

/// The peak an error plot of axis `a` is framed on: its own, but not below a hundredth of the
/// largest axis of its group (1e-5″ of rounding beside a 500″ error would fill its plot and look
/// like a drift).
pub(super) fn floored_peak(peaks: [f64; 3], a: usize) -> f64 {
    peaks[a].max(peaks.iter().fold(0.0_f64, |m, x| m.max(*x)) / 100.0)
}

/// The smallest angle an error class is drawn at, rad (2°): under it a cone or wedge cannot be seen
/// at the default camera (Jiang et al. 2017's 20″ non-orthogonality is 0.56° at ×100).
const MIN_DRAWN_RAD: f64 = 2.0 * crate::math::units::RAD_PER_DEG;

/// The drawing factor of each error class: the scenario's exaggeration `x`, or, for a class whose
/// largest angle `x` would draw under [`MIN_DRAWN_RAD`], the smallest of 1, 2, 5 × 10^k that draws
/// it there (at most 10^5). The labels say each class's factor.
#[must_use]
pub fn drawing_factors(truth: &TableErrors, x: f64) -> ClassFactors {
    let raise = |a: f64| {
        if a <= 0.0 || a * x >= MIN_DRAWN_RAD {
            return x;
        }
        crate::math::units::nice_at_least(MIN_DRAWN_RAD / a * (1.0 - 1e-12)).min(1e5).max(x)
    };
    let s = truth.class_sizes();
    ClassFactors {
        swing: raise(s.swing),
        non_orthogonality: raise(s.non_orthogonality),
        installation: raise(s.installation),
        imu_mount: raise(s.imu_mount),
    }
}
