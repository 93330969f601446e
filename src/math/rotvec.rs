//! Rotation vectors and unit quaternions: the exponential map (a rotation vector to its
//! quaternion) and the logarithm (a quaternion to its rotation vector), for every module.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// The rotation whose rotation vector is `phi` (the exponential map, any size): a series for the
/// small angles of one update or one error (exact to double precision for |φ| < 0.01 rad),
/// trigonometry above.
#[must_use]
#[inline]
pub fn exp(phi: &Vector3<f64>) -> UnitQuaternion<f64> {
    let x2 = phi.norm_squared();
    let (c, s_over) = if x2 < 1e-4 {
        // cos(x/2) and sin(x/2)/x to x^6: error < 1e-20 at x = 0.01.
        // Horner form with the reciprocals as constants (a division by 48 is not a multiplication
        // to the compiler, and these divisions were a tenth of the attitude update's time).
        const C: [f64; 3] = [1.0 / 8.0, 1.0 / 384.0, 1.0 / 46_080.0];
        const S: [f64; 3] = [1.0 / 48.0, 1.0 / 3840.0, 1.0 / 645_120.0];
        (1.0 - x2 * (C[0] - x2 * (C[1] - x2 * C[2])), 0.5 - x2 * (S[0] - x2 * (S[1] - x2 * S[2])))
    } else {
        let x = x2.sqrt();
        ((0.5 * x).cos(), (0.5 * x).sin() / x)
    };
    UnitQuaternion::new_unchecked(Quaternion::new(c, phi.x * s_over, phi.y * s_over, phi.z * s_over))
}

/// The rotation vector of a unit quaternion (its logarithm ×2). Small rotations (the hot path: every
/// residual is below a degree) use the series 2·asin(s)/s = 2(1 + s²/6 + 3s⁴/40 + 5s⁶/112 + …) of
/// the vector part's norm s; the first omitted term, 35s⁸/1152, is below 1e-17 for s < 0.01
/// (rotations under 1.1°); larger ones the library's atan2 form.
#[must_use]
pub fn log(q: &UnitQuaternion<f64>) -> Vector3<f64> {
    let v = if q.w < 0.0 { -q.imag() } else { q.imag() };
    let s2 = v.norm_squared();
    if s2 < 1e-4 {
        v * (2.0 * (1.0 + s2 * (1.0 / 6.0 + s2 * (3.0 / 40.0 + s2 * (5.0 / 112.0)))))
    } else {
        q.scaled_axis()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_maps_match_the_library_for_small_and_large_angles() {
        // Independent computation: nalgebra's scaled-axis maps, on both sides of each series' switch
        // (|φ| = 0.01 for exp, s = 0.01 ↔ 0.02 rad for log).
        for angle in [0.0, 1e-9, 1e-5, 1e-3, 0.0099, 0.0101, 0.019, 0.021, 0.5, 3.0] {
            let v = Vector3::new(0.3, -0.5, 0.81).normalize() * angle;
            let q = UnitQuaternion::from_scaled_axis(v);
            assert!(exp(&v).angle_to(&q) < 1e-15, "exp, angle {angle}");
            assert!((log(&q) - v).norm() <= 1e-15 * angle.max(1e-3), "log, angle {angle}");
            // The same rotation with the quaternion's other sign.
            let neg = UnitQuaternion::new_unchecked(-q.into_inner());
            assert!((log(&neg) - v).norm() <= 1e-15 * angle.max(1e-3), "log, angle {angle} (−q)");
        }
    }
}
