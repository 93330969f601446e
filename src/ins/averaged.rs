//! The averaged error model of a rotation scheme: what of each IMU error the turning leaves, as a
//! constant error in the navigation frame, and the position error that leaves.
//!
//! A gyro error `δω^s = b + K ω_is^s` (bias `b`; scale factors on the diagonal of `K`,
//! misalignments off it; `ω_is^s` the IMU's rate, the table's turning plus the Earth's) reaches
//! the navigation frame as `C_n^s(t) δω^s(t)`. Averaged over one period of the scheme,
//!
//! ```text
//!   d̄ = ⟨C⟩ b + Σ_ij K_ij ⟨C e_i ω_j⟩,
//! ```
//!
//! is the drift the scheme leaves; what is left over oscillates with the period (minutes) and, well
//! inside the Schuler loop's 84 min, stays bounded. The accelerometers alike, with the specific
//! force `f^s = C_s^n f^n` for `ω`. A constant navigation-frame error drives the position error
//! linearly: `p(t) = R_g(t) d̄ + R_a(t) ā`, with `R` read off the exact INS (a static table, one
//! unit error along each navigation axis: [`Responses::from_runs`]). Each term of `K` and `b` is a
//! zero-mean draw of a stated σ (or a fixed value), so the mean square over the run is the sum
//! `Σ σ² vᵀ Q v` with `Q = ⟨Rᵀ R⟩`. It is a model to rank candidates: the search confirms its best
//! with the exact simulation (`app::design`).

use nalgebra::{Matrix3, Vector3};

use super::budget::{ImuTerm, Source, Triad};
use super::sensor::{ImuErrorSpec, Spec};
use crate::model::earth::Earth;
use crate::model::gimbal::{Chain, TableErrors};
use crate::model::scheme::Scheme;

/// One scheme's averages over its window (navigation frame, ENU).
#[derive(Debug, Clone, PartialEq)]
pub struct Averages {
    /// `⟨C_n^s⟩`: a constant error along IMU axis `i` becomes `c.column(i)` on average.
    pub c: Matrix3<f64>,
    /// `gyro[i][j] = ⟨C e_i ω_j⟩`, rad/s: the drift a unit `K_ij` leaves.
    pub gyro: [[Vector3<f64>; 3]; 3],
    /// `accel[i][j] = ⟨C e_i f_j⟩`, m/s²: the acceleration error a unit `K_ij` leaves.
    pub accel: [[Vector3<f64>; 3]; 3],
    /// The window averaged over, s (start, length).
    pub window_s: (f64, f64),
}

/// The averages of `scheme` on `chain` (its nominal geometry: the table's own errors are the
/// compensation's business), the base at rest at `n_from_b` (body to navigation), over one period
/// of a repeated sequence — or over `[0, fallback_s]` for a continuous or one-off scheme — by the
/// midpoint rule at `step_s`.
#[must_use]
pub fn averages(
    chain: &Chain,
    scheme: &Scheme,
    n_from_b: &Matrix3<f64>,
    earth: &Earth,
    fallback_s: f64,
    step_s: f64,
) -> Averages {
    let window_s = scheme.period_window().unwrap_or((0.0, fallback_s));
    let nominal = chain.error_rotations(&TableErrors::zero(chain.axes().len()));
    let steps = ((window_s.1 / step_s).ceil() as usize).max(1);
    let h = window_s.1 / steps as f64;
    let f_n = -earth.gravity_n;
    let mut out = Averages { c: Matrix3::zeros(), gyro: Default::default(), accel: Default::default(), window_s };
    for k in 0..steps {
        let t = window_s.0 + (k as f64 + 0.5) * h;
        let (angles, rates) = scheme.state(t);
        let (b_from_s, omega_bs_s) = chain.b_from_s_and_rate(&nominal, &chain.shaft_rotations(&angles), &rates);
        // FRAME: n ← b ← s; the IMU's rate is the table's plus the Earth's seen in s.
        let c = n_from_b * b_from_s.matrix();
        let omega = omega_bs_s.v + c.transpose() * earth.omega_ie_n;
        let f = c.transpose() * f_n;
        out.c += c;
        for i in 0..3 {
            let col = c.column(i).into_owned();
            for j in 0..3 {
                out.gyro[i][j] += col * omega[j];
                out.accel[i][j] += col * f[j];
            }
        }
    }
    let w = 1.0 / steps as f64;
    out.c *= w;
    for i in 0..3 {
        for j in 0..3 {
            out.gyro[i][j] *= w;
            out.accel[i][j] *= w;
        }
    }
    out
}

/// How the INS's horizontal position error answers a constant navigation-frame error: the mean over
/// the run of `R_xᵀ R_y` for the gyro (x, y = g) and accelerometer (a) responses, m² per unit².
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Responses {
    /// `⟨R_gᵀ R_g⟩`, m² per (rad/s)².
    pub gg: Matrix3<f64>,
    /// `⟨R_gᵀ R_a⟩`.
    pub ga: Matrix3<f64>,
    /// `⟨R_aᵀ R_a⟩`, m² per (m/s²)².
    pub aa: Matrix3<f64>,
}

impl Responses {
    /// From six runs' (east, north) position errors on the same instants: a constant drift of
    /// `unit_gyro` rad/s along east, north and up, then an accelerometer error of `unit_accel` m/s²
    /// along each.
    #[must_use]
    pub fn from_runs(gyro: [&[[f64; 2]]; 3], unit_gyro: f64, accel: [&[[f64; 2]]; 3], unit_accel: f64) -> Self {
        let n = gyro.iter().chain(&accel).map(|r| r.len()).min().unwrap_or(0).max(1);
        let q = |x: [&[[f64; 2]]; 3], ux: f64, y: [&[[f64; 2]]; 3], uy: f64| {
            Matrix3::from_fn(|k, l| {
                let s: f64 = (0..n.min(x[k].len())).map(|i| x[k][i][0] * y[l][i][0] + x[k][i][1] * y[l][i][1]).sum();
                s / (n as f64 * ux * uy)
            })
        };
        Self { gg: q(gyro, unit_gyro, gyro, unit_gyro), ga: q(gyro, unit_gyro, accel, unit_accel), aa: q(accel, unit_accel, accel, unit_accel) }
    }
}

/// A source's navigation-frame errors per unit of it: (gyro drift, accelerometer error).
type Direction = (Vector3<f64>, Vector3<f64>);

/// The model's position error of one scheme.
#[derive(Debug, Clone, PartialEq)]
pub struct Score {
    /// RMS horizontal position error over the run, m: the expected value over the error draws.
    pub rms_m: f64,
    /// Each source's own RMS, m (the biases and scale factors per axis, the misalignments per triad).
    pub terms: Vec<(Source, f64)>,
}

/// The model's score of `avg` for the IMU errors `errors` (biases, scale factors, misalignments; the
/// noise and the alignment do not depend on the scheme and are left out).
#[must_use]
pub fn score(avg: &Averages, errors: &ImuErrorSpec, r: &Responses) -> Score {
    let quad = |(g, a): &Direction| (g.dot(&(r.gg * g)) + 2.0 * g.dot(&(r.ga * a)) + a.dot(&(r.aa * a))).max(0.0);
    let mut fixed: Direction = (Vector3::zeros(), Vector3::zeros());
    let mut random = 0.0;
    let mut terms = Vec::new();
    for triad in [Triad::Gyro, Triad::Accel] {
        let (bias, scale, mis, k) = match triad {
            Triad::Gyro => (errors.gyro.bias_rad_per_s, errors.gyro.scale, errors.gyro.misalignment_rad, &avg.gyro),
            Triad::Accel => (errors.accel.bias_mps2, errors.accel.scale, errors.accel.misalignment_rad, &avg.accel),
        };
        let along = |v: Vector3<f64>| -> Direction {
            match triad {
                Triad::Gyro => (v, Vector3::zeros()),
                Triad::Accel => (Vector3::zeros(), v),
            }
        };
        for i in 0..3 {
            for (spec, unit, term) in [
                (bias, avg.c.column(i).into_owned(), ImuTerm::Bias(triad, i)),
                (scale, k[i][i], ImuTerm::Scale(triad, i)),
            ] {
                let d = along(unit);
                let ms = match spec {
                    Spec::Sigma(s) => {
                        random += s * s * quad(&d);
                        s * s * quad(&d)
                    }
                    Spec::Fixed(v) => {
                        fixed.0 += d.0 * v[i];
                        fixed.1 += d.1 * v[i];
                        v[i] * v[i] * quad(&d)
                    }
                };
                terms.push((Source::Imu(term), ms.sqrt()));
            }
        }
        let ms: f64 = (0..3)
            .flat_map(|i| (0..3).filter(move |j| *j != i).map(move |j| (i, j)))
            .map(|(i, j)| mis * mis * quad(&along(k[i][j])))
            .sum();
        random += ms;
        terms.push((Source::Imu(ImuTerm::Misalignment(triad)), ms.sqrt()));
    }
    terms.retain(|(_, m)| *m > 0.0);
    Score { rms_m: (random + quad(&fixed)).sqrt(), terms }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::earth::Site;
    use crate::model::gimbal::AxisGeometry;
    use crate::model::scheme::IndexedStep;

    fn azimuth_table() -> Chain {
        Chain::new(vec![AxisGeometry::new("azimuth".into(), Vector3::z(), 0.0)])
    }

    fn earth() -> Earth {
        Earth::at(Site { latitude_rad: 40f64.to_radians(), longitude_rad: 0.0, height_m: 0.0 })
    }

    fn back_and_forth(signs: &[f64], rate: f64, dwell: f64) -> Scheme {
        let steps = signs
            .iter()
            .map(|s| IndexedStep { axis: 0, angle_rad: s * std::f64::consts::PI, rate_rad_per_s: rate, dwell_s: dwell, accel_rad_per_s2: 0.0 })
            .collect();
        Scheme::indexed(vec![0.0], 0.0, steps, true)
    }

    #[test]
    fn the_moves_of_a_two_position_sequence_leave_four_over_omega_t_of_a_horizontal_bias() {
        // Analytic: turning 0 → π and back at ω, dwelling D at each end, a bias ε along x averages to
        // ⟨C e_x⟩ = (0, 4/ω, 0)/T (each move sweeps the upper half plane: ∫ (cos θ, sin θ) dθ/ω =
        // (0, 2/ω)), T = 2(π/ω + D); the four-move (+, −, −, +) sweeps both halves: 0. The z axis
        // never turns: ⟨C e_z⟩ = e_z.
        let (rate, dwell) = (10f64.to_radians(), 60.0);
        let t = 2.0 * (std::f64::consts::PI / rate + dwell);
        let two = averages(&azimuth_table(), &back_and_forth(&[1.0, -1.0], rate, dwell), &Matrix3::identity(), &earth(), 0.0, 0.01);
        assert!((two.window_s.1 - t).abs() < 1e-9);
        let want = 4.0 / rate / t;
        assert!((two.c[(1, 0)] - want).abs() < 1e-5 * want, "{} vs {want}", two.c[(1, 0)]);
        assert!(two.c[(0, 0)].abs() < 1e-6 && (two.c[(2, 2)] - 1.0).abs() < 1e-12);
        let four = averages(&azimuth_table(), &back_and_forth(&[1.0, -1.0, -1.0, 1.0], rate, dwell), &Matrix3::identity(), &earth(), 0.0, 0.01);
        assert!(four.c.fixed_view::<2, 2>(0, 0).abs().max() < 1e-6, "{}", four.c);
        // A misalignment K_xz (x gyro sensing the table's z rate) averages out on the return path in
        // both: ⟨C e_x θ̇⟩ = ∫ C e_x dθ over the path and back = 0; what is left is the Earth's
        // vertical rate on the bias's average, Ω_up ⟨C e_x⟩.
        let up = earth().omega_ie_n.z;
        for a in [&two, &four] {
            let rest = a.gyro[0][2] - a.c.column(0) * up;
            assert!(rest.xy().norm() < 1e-9 * rate, "{rest}");
        }
    }

    #[test]
    fn the_score_adds_each_sources_mean_square() {
        // With Q = identity, the score is the RMS of the averaged errors: a σ on the x gyro bias of a
        // never-turned table counts σ², a fixed z bias its square, the two add in quadrature.
        let r = Responses { gg: Matrix3::identity(), ga: Matrix3::zeros(), aa: Matrix3::zeros() };
        let avg = averages(&azimuth_table(), &Scheme::continuous(vec![0.0], vec![0.0]), &Matrix3::identity(), &earth(), 10.0, 1.0);
        let mut e = ImuErrorSpec::default();
        e.gyro.bias_rad_per_s = Spec::Sigma(3.0);
        let s = score(&avg, &e, &r);
        assert!((s.rms_m - 3.0 * 3f64.sqrt()).abs() < 1e-12, "{}", s.rms_m);
        e.gyro.bias_rad_per_s = Spec::Fixed([0.0, 0.0, 4.0]);
        let s = score(&avg, &e, &r);
        assert!((s.rms_m - 4.0).abs() < 1e-12 && s.terms.len() == 1, "{s:?}");
    }
}
