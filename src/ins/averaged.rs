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
//! is the drift the scheme leaves. What is left over, `g(t) − d̄`, oscillates with the period
//! (minutes, well inside the Schuler loop's 84 min), but its integral — the attitude error the
//! moves hold between a move and its return — need not average to zero: its mean over the period,
//!
//! ```text
//!   θ̄ = ⟨∫(g − d̄)⟩ = ⟨g(s) (T/2 − s)⟩,   s the time into the period,
//! ```
//!
//! tilts the computed specific force by `θ̄ × f^n` for as long as the scheme runs: a constant
//! accelerometer error. A misalignment of 5″ turned through 180° holds 16″ until it is turned back;
//! the order of the moves sets how long. The accelerometers alike, with the specific force
//! `f^s = C_s^n f^n` for `ω`: their average `ā` is a constant acceleration error, the mean of their
//! held integral `v̄` a velocity offset. These constants drive the position error linearly,
//! `p(t) = R_g(t) d̄ + R_a(t) ā + R_v(t) v̄`, with `R` read off the exact INS (a static table, one unit
//! error along each navigation axis: [`Responses::from_runs`]). Each term of `K` and `b` is a
//! zero-mean draw of a stated σ (or a fixed value), so the mean square over the run is the sum
//! `Σ σ² xᵀ Q x` with `Q = ⟨Rᵀ R⟩`, `x = (d̄, ā, v̄)`. It is a model to rank candidates: the search
//! confirms its best with the exact simulation (`app::design`).

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

use super::InsParams;
use super::budget::{ImuTerm, Source, Triad};
use super::sensor::{ImuErrorSpec, Spec};
use crate::model::earth::Earth;
use crate::model::gimbal::{Chain, TableErrors};
use crate::model::scheme::Scheme;

/// One unit error's averages over the window: its mean `⟨g⟩` and the mean of its integral less the
/// mean's, `⟨g(s) (T/2 − s)⟩` (what the moves hold).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Unit {
    /// `⟨g⟩`, navigation frame.
    pub mean: Vector3<f64>,
    /// `⟨∫(g − ⟨g⟩)⟩`, navigation frame.
    pub held: Vector3<f64>,
}

impl Unit {
    fn add(&mut self, g: Vector3<f64>, lever: f64) {
        self.mean += g;
        self.held += g * lever;
    }

    fn scale(&mut self, w: f64) {
        self.mean *= w;
        self.held *= w;
    }
}

/// One scheme's averages over its window (navigation frame, ENU).
#[derive(Debug, Clone, PartialEq)]
pub struct Averages {
    /// `c[i]`: a constant unit error along IMU axis `i` (`C e_i`), rad/s or m/s² per unit.
    pub c: [Unit; 3],
    /// `gyro[i][j]`: `C e_i ω_j`, what a unit `K_ij` of the gyros does, rad/s.
    pub gyro: [[Unit; 3]; 3],
    /// `accel[i][j]`: `C e_i f_j`, what a unit `K_ij` of the accelerometers does, m/s².
    pub accel: [[Unit; 3]; 3],
    /// The specific force at rest in the navigation frame, m/s².
    pub f_n: Vector3<f64>,
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
    let mut out =
        Averages { c: Default::default(), gyro: Default::default(), accel: Default::default(), f_n, window_s };
    for k in 0..steps {
        let tau = (k as f64 + 0.5) * h;
        let lever = 0.5 * window_s.1 - tau;
        let (angles, rates) = scheme.state(window_s.0 + tau);
        let (b_from_s, omega_bs_s) = chain.b_from_s_and_rate(&nominal, &chain.shaft_rotations(&angles), &rates);
        // FRAME: n ← b ← s; the IMU's rate is the table's plus the Earth's seen in s.
        let c = n_from_b * b_from_s.matrix();
        let omega = omega_bs_s.v + c.transpose() * earth.omega_ie_n;
        let f = c.transpose() * f_n;
        for i in 0..3 {
            let col = c.column(i).into_owned();
            out.c[i].add(col, lever);
            for j in 0..3 {
                out.gyro[i][j].add(col * omega[j], lever);
                out.accel[i][j].add(col * f[j], lever);
            }
        }
    }
    let w = 1.0 / steps as f64;
    for i in 0..3 {
        out.c[i].scale(w);
        for j in 0..3 {
            out.gyro[i][j].scale(w);
            out.accel[i][j].scale(w);
        }
    }
    out
}

/// How the INS's horizontal position error answers constant navigation-frame errors
/// `x = (d̄, ā, v̄)` (a gyro drift, rad/s; an acceleration error, m/s²; a velocity offset, m/s):
/// `Q = ⟨R(t)ᵀ R(t)⟩` over the run, m² per unit², with `R(t)` the 2 × 9 response.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Responses {
    /// `⟨Rᵀ R⟩`.
    pub q: SMatrix<f64, 9, 9>,
}

impl Responses {
    /// From six runs' (east, north) position errors at instants `dt_s` apart: a constant drift of `unit_gyro` rad/s along east, north and up, then an
    /// acceleration error of `unit_accel` m/s² along each. A velocity offset's response is the
    /// acceleration step's derivative (an offset is an impulse of acceleration; the INS at rest is
    /// time-invariant).
    #[must_use]
    pub fn from_runs(
        gyro: [&[[f64; 2]]; 3],
        unit_gyro: f64,
        accel: [&[[f64; 2]]; 3],
        unit_accel: f64,
        dt_s: f64,
    ) -> Self {
        let n = gyro.iter().chain(&accel).map(|r| r.len()).min().unwrap_or(0);
        let mut q = SMatrix::<f64, 9, 9>::zeros();
        for i in 0..n {
            let mut r = SMatrix::<f64, 2, 9>::zeros();
            for k in 0..3 {
                for e in 0..2 {
                    r[(e, k)] = gyro[k][i][e] / unit_gyro;
                    r[(e, 3 + k)] = accel[k][i][e] / unit_accel;
                    // The derivative: central differences, one-sided at the ends.
                    let (lo, hi) = (i.saturating_sub(1), (i + 1).min(n - 1));
                    r[(e, 6 + k)] = (accel[k][hi][e] - accel[k][lo][e]) / (unit_accel * dt_s * (hi - lo).max(1) as f64);
                }
            }
            q += r.transpose() * r;
        }
        Self { q: q / n.max(1) as f64 }
    }
}

/// A source's navigation-frame errors per unit of it, `x = (d̄, ā, v̄)`.
type Direction = SVector<f64, 9>;

/// `x` of a gyro error (`Unit` of its `g = C δω`): its mean drifts, its held integral tilts `f`.
fn gyro_direction(u: &Unit, f_n: &Vector3<f64>) -> Direction {
    let mut x = Direction::zeros();
    x.fixed_rows_mut::<3>(0).copy_from(&u.mean);
    x.fixed_rows_mut::<3>(3).copy_from(&u.held.cross(f_n));
    x
}

/// `x` of an accelerometer error: its mean accelerates, its held integral is a velocity offset.
fn accel_direction(u: &Unit) -> Direction {
    let mut x = Direction::zeros();
    x.fixed_rows_mut::<3>(3).copy_from(&u.mean);
    x.fixed_rows_mut::<3>(6).copy_from(&u.held);
    x
}

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
    let quad = |x: &Direction| x.dot(&(r.q * x)).max(0.0);
    let mut fixed = Direction::zeros();
    let mut random = 0.0;
    let mut terms = Vec::new();
    for triad in [Triad::Gyro, Triad::Accel] {
        let (bias, scale, mis, k) = match triad {
            Triad::Gyro => (errors.gyro.bias_rad_per_s, errors.gyro.scale, errors.gyro.misalignment_rad, &avg.gyro),
            Triad::Accel => (errors.accel.bias_mps2, errors.accel.scale, errors.accel.misalignment_rad, &avg.accel),
        };
        let along = |u: &Unit| match triad {
            Triad::Gyro => gyro_direction(u, &avg.f_n),
            Triad::Accel => accel_direction(u),
        };
        for i in 0..3 {
            for (spec, unit, term) in
                [(bias, &avg.c[i], ImuTerm::Bias(triad, i)), (scale, &k[i][i], ImuTerm::Scale(triad, i))]
            {
                let x = along(unit);
                let ms = match spec {
                    Spec::Sigma(s) => {
                        random += s * s * quad(&x);
                        s * s * quad(&x)
                    }
                    Spec::Fixed(v) => {
                        fixed += x * v[i];
                        v[i] * v[i] * quad(&x)
                    }
                };
                terms.push((Source::Imu(term), ms.sqrt()));
            }
        }
        let ms: f64 = (0..3)
            .flat_map(|i| (0..3).filter(move |j| *j != i).map(move |j| (i, j)))
            .map(|(i, j)| mis * mis * quad(&along(&k[i][j])))
            .sum();
        random += ms;
        terms.push((Source::Imu(ImuTerm::Misalignment(triad)), ms.sqrt()));
    }
    terms.retain(|(_, m)| *m > 0.0);
    Score { rms_m: (random + quad(&fixed)).sqrt(), terms }
}

/// `ins` with only the sources a rotation scheme can modulate acting — the constant errors (biases,
/// scale factors, misalignments, g-sensitivity) — on the same draws: the noise (a random walk turned
/// is still one), the readout, the dither and the alignment off. The table's errors are the
/// compensation's, not the scheme's, and stay.
#[must_use]
pub fn modulable_only(ins: &InsParams) -> InsParams {
    let mut i = ins.clone();
    for t in [&mut i.sources.gyro, &mut i.sources.accel] {
        t.white = false;
        t.markov = false;
        t.instability = false;
        t.random_walk = false;
        t.ramp = false;
        t.readout = false;
    }
    i.sources.dither = false;
    i.initial_error_rad = Vector3::zeros();
    i
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
            .map(|s| IndexedStep {
                axis: 0,
                angle_rad: s * std::f64::consts::PI,
                rate_rad_per_s: rate,
                dwell_s: dwell,
                accel_rad_per_s2: 0.0,
            })
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
        let two = averages(
            &azimuth_table(),
            &back_and_forth(&[1.0, -1.0], rate, dwell),
            &Matrix3::identity(),
            &earth(),
            0.0,
            0.01,
        );
        assert!((two.window_s.1 - t).abs() < 1e-9);
        let want = 4.0 / rate / t;
        assert!((two.c[0].mean.y - want).abs() < 1e-5 * want, "{} vs {want}", two.c[0].mean.y);
        assert!(two.c[0].mean.x.abs() < 1e-6 && (two.c[2].mean.z - 1.0).abs() < 1e-12);
        let four = averages(
            &azimuth_table(),
            &back_and_forth(&[1.0, -1.0, -1.0, 1.0], rate, dwell),
            &Matrix3::identity(),
            &earth(),
            0.0,
            0.01,
        );
        assert!(four.c[0].mean.xy().norm() < 1e-6 && four.c[1].mean.xy().norm() < 1e-6, "{:?}", four.c);
        // A misalignment K_xz (x gyro sensing the table's z rate) averages out on the return path in
        // both: ⟨C e_x θ̇⟩ = ∫ C e_x dθ over the path and back = 0; what is left is the Earth's
        // vertical rate on the bias's average, Ω_up ⟨C e_x⟩.
        let up = earth().omega_ie_n.z;
        for a in [&two, &four] {
            let rest = a.gyro[0][2].mean - a.c[0].mean * up;
            assert!(rest.xy().norm() < 1e-9 * rate, "{rest}");
        }
    }

    #[test]
    fn the_score_adds_each_sources_mean_square() {
        // With Q = identity, the score is the RMS of the averaged errors: a σ on the x gyro bias of a
        // never-turned table counts σ², a fixed z bias its square, the two add in quadrature.
        let mut q = SMatrix::<f64, 9, 9>::zeros();
        q.fixed_view_mut::<3, 3>(0, 0).fill_with_identity();
        let r = Responses { q };
        let avg = averages(
            &azimuth_table(),
            &Scheme::continuous(vec![0.0], vec![0.0]),
            &Matrix3::identity(),
            &earth(),
            10.0,
            1.0,
        );
        let mut e = ImuErrorSpec::default();
        e.gyro.bias_rad_per_s = Spec::Sigma(3.0);
        let s = score(&avg, &e, &r);
        assert!((s.rms_m - 3.0 * 3f64.sqrt()).abs() < 1e-12, "{}", s.rms_m);
        e.gyro.bias_rad_per_s = Spec::Fixed([0.0, 0.0, 4.0]);
        let s = score(&avg, &e, &r);
        assert!((s.rms_m - 4.0).abs() < 1e-12 && s.terms.len() == 1, "{s:?}");
    }
}
