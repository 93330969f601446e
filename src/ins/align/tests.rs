//! The alignment on synthetic IMUs whose increments are exact (an IMU fixed on the Earth, or turning
//! about its z axis at a constant rate): every expected number is an analytic one.

use super::*;
use crate::math::units::{RAD_PER_DEG, RAD_PER_S_PER_DEG_PER_H};

const LAT: f64 = 34.0 * RAD_PER_DEG;
const H: f64 = 0.01;

fn cfg() -> AlignConfig {
    AlignConfig {
        latitude_rad: LAT,
        height_m: 0.0,
        interval_s: H,
        gyro_bias_sigma_rad_per_s: Some(0.01 * RAD_PER_S_PER_DEG_PER_H),
        accel_bias_sigma_mps2: Some(1e-4),
        gyro_random_walk: Some(1e-7),
        accel_random_walk: Some(1e-6),
    }
}

/// An IMU at rest at `LAT` with C_s^n = `n_from_s0`, turning about its own z axis at `spin` rad/s
/// (an azimuth table), with constant sensor biases: exact increments (the rotation of s is
/// composed exactly per sample, the specific force integrated by the midpoint rule at 100 Hz,
/// whose error is ~1e-9 of g over a sample at 10°/s).
fn imu(
    n_from_s0: UnitQuaternion<f64>,
    spin: f64,
    seconds: f64,
    gyro_bias: Vector3<f64>,
    accel_bias: Vector3<f64>,
) -> (Vec<Increment>, UnitQuaternion<f64>) {
    let w_ie = omega_ie_n(LAT);
    let f_n = Vector3::new(0.0, 0.0, normal_gravity(LAT, 0.0));
    let n = (seconds / H).round() as usize;
    let mut q = n_from_s0;
    let mut out = Vec::with_capacity(n);
    let spin_step = rotvec::exp(&Vector3::new(0.0, 0.0, spin * H));
    for _ in 0..n {
        // s turns relative to n by `spin` about z_s; n turns with the Earth: ω_is^s = C_n^s ω_ie + spin z.
        let q_mid = q * rotvec::exp(&Vector3::new(0.0, 0.0, 0.5 * spin * H));
        let dtheta = q_mid.inverse() * w_ie * H + Vector3::new(0.0, 0.0, spin * H) + gyro_bias * H;
        let dv = q_mid.inverse() * f_n * H + accel_bias * H;
        out.push((dtheta, dv));
        q *= spin_step;
    }
    (out, q)
}

fn heading_tilt_error(est: &Rot<N, S>, truth: &UnitQuaternion<f64>) -> Vector3<f64> {
    // φ with C_est = (I − [φ×]) C_true: C_true C_estᵀ = exp(φ).
    rotvec::log(&(truth * est.quaternion().inverse()))
}

fn level_at(heading_deg: f64) -> UnitQuaternion<f64> {
    *Attitude { pitch_rad: 2.0 * RAD_PER_DEG, roll_rad: -RAD_PER_DEG, heading_rad: heading_deg * RAD_PER_DEG }
        .n_from_b()
        .quaternion()
}

#[test]
fn an_exact_resting_imu_aligns_to_its_attitude() {
    let truth0 = level_at(123.0);
    let (samples, truth_end) = imu(truth0, 0.0, 120.0, Vector3::zeros(), Vector3::zeros());
    let c = coarse(&samples, &cfg()).expect("coarse");
    // Coarse: within 0.01° (the triad on two exact velocity vectors; the residual is the sampling).
    let e0 = heading_tilt_error(&c, &truth0);
    assert!(e0.norm() < 0.01 * RAD_PER_DEG, "coarse error {e0:?} rad");
    let a = fine(&samples, &cfg()).expect("fine");
    let e = heading_tilt_error(&a.n_from_s, &truth_end);
    assert!(e.norm() < 2e-5, "fine error {e:?} rad");
    let (att, sigma) = a.attitude_with_sigma();
    assert!((att.heading_rad.to_degrees() - 123.0).abs() < 1e-3, "heading {}", att.heading_rad.to_degrees());
    // The heading 1σ of a fixed IMU after 120 s is bounded below by the east gyro bias prior over the
    // horizontal Earth rate (0.01 °/h / (15.04 °/h · cos 34°) = 8.0e-4 rad) and the filter cannot
    // beat it; it starts at 30× that at most.
    let floor = 0.01 * RAD_PER_S_PER_DEG_PER_H / (EARTH_RATE * LAT.cos());
    assert!(sigma[2] > 0.9 * floor && sigma[2] < 3.0 * floor, "heading 1σ {} vs floor {floor}", sigma[2]);
}

#[test]
fn a_fixed_imu_cannot_tell_an_east_gyro_bias_from_heading_but_a_turning_one_can() {
    // A bias of 0.01 °/h on every axis. Fixed IMU: the heading error is the east component over the
    // horizontal Earth rate (gyrocompassing's classic limit); turning at 6 °/s about z, the horizontal
    // biases average out of the east axis and are estimated: the error falls below a tenth of it.
    let bias = Vector3::new(1.0, 1.0, 1.0) * 0.01 * RAD_PER_S_PER_DEG_PER_H;
    let truth0 = level_at(0.0);
    let (fixed, t_fixed) = imu(truth0, 0.0, 300.0, bias, Vector3::zeros());
    let a = fine(&fixed, &cfg()).expect("fine");
    let err_fixed = heading_tilt_error(&a.n_from_s, &t_fixed).z;
    let east_bias = (truth0 * bias).x;
    let classic = east_bias / (EARTH_RATE * LAT.cos());
    assert!(
        (err_fixed.abs() - classic.abs()).abs() < 0.25 * classic.abs(),
        "fixed: heading error {err_fixed} rad, classic limit {classic} rad"
    );
    let (turning, t_turning) = imu(truth0, 6.0 * RAD_PER_DEG, 300.0, bias, Vector3::zeros());
    let b = fine(&turning, &cfg()).expect("fine");
    let err_turning = heading_tilt_error(&b.n_from_s, &t_turning).z;
    assert!(err_turning.abs() < 0.1 * classic.abs(), "turning: heading error {err_turning} rad vs fixed {err_fixed}");
    let (_, sigma_fixed) = a.attitude_with_sigma();
    let (_, sigma_turning) = b.attitude_with_sigma();
    assert!(
        sigma_turning[2] < 0.3 * sigma_fixed[2],
        "heading 1σ turning {} vs fixed {}",
        sigma_turning[2],
        sigma_fixed[2]
    );
}

#[test]
fn the_rest_scan_ends_where_the_vehicle_starts_to_accelerate() {
    let (mut samples, _) = imu(level_at(40.0), 0.0, 90.0, Vector3::zeros(), Vector3::zeros());
    // From 60 s on, 0.5 m/s² along the sensor's y axis (a car pulling away).
    for s in samples.iter_mut().skip(6000) {
        s.1.y += 0.5 * H;
    }
    let scan = scan_rest(&samples, H, REST_THRESHOLD_MPS2);
    assert!((scan.rest_s - 60.0).abs() <= 1.0, "rest {} s", scan.rest_s);
    assert!(scan.ending_change_mps2.is_some_and(|c| (c - 0.5).abs() < 0.05));
    let whole = scan_rest(&samples[..5000], H, REST_THRESHOLD_MPS2);
    assert!((whole.rest_s - 50.0).abs() < 1e-9 && whole.ending_change_mps2.is_none());
}

#[test]
fn the_implied_latitude_is_the_site_s_on_exact_data_and_another_site_s_is_found_out() {
    let (samples, _) = imu(level_at(10.0), 0.0, 600.0, Vector3::zeros(), Vector3::zeros());
    let l = implied_latitude(&samples, H, LAT, 0.0).expect("latitude");
    assert!((l.latitude_rad - LAT).abs() < 0.05 * RAD_PER_DEG, "implied {}° vs 34°", l.latitude_rad.to_degrees());
    // The same data claimed to be 8° further north: 42° lies many σ away.
    assert!((42.0 * RAD_PER_DEG - l.latitude_rad).abs() > 3.0 * l.sigma_rad, "σ {}°", l.sigma_rad.to_degrees());
}

#[test]
fn a_moving_log_and_a_unit_slip_are_refused_by_name() {
    let (samples, _) = imu(level_at(0.0), 0.0, 5.0, Vector3::zeros(), Vector3::zeros());
    assert!(matches!(fine(&samples, &cfg()), Err(AlignError::TooShort(_))));
    let (mut g, _) = imu(level_at(0.0), 0.0, 30.0, Vector3::zeros(), Vector3::zeros());
    for s in &mut g {
        s.1 /= 9.80665; // accelerometers in g declared as m/s²
    }
    assert!(matches!(fine(&g, &cfg()), Err(AlignError::NotGravity { .. })));
}

#[test]
fn the_noise_is_measured_under_rocking_that_swamps_first_differences() {
    // White gyro noise of 2.9e-8 rad per 0.01 s sample (0.001 °/√h) under a 0.08° roll at 1.3 Hz
    // (first differences 9e-6 rad): the estimate is the noise's within 10 %, not the rocking's.
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let arw = 0.001 * crate::math::units::RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H;
    let (w, a) = (2.0 * std::f64::consts::PI * 1.3, 0.08 * RAD_PER_DEG);
    let samples: Vec<Increment> = (0..30_000)
        .map(|k| {
            let t = k as f64 * H;
            let rock = a * ((w * (t + H)).sin() - (w * t).sin());
            let mut n = || -> f64 { StandardNormal.sample(&mut rng) };
            (
                Vector3::new(rock + arw * H.sqrt() * n(), arw * H.sqrt() * n(), arw * H.sqrt() * n()),
                Vector3::new(0.0, 0.0, 9.8 * H),
            )
        })
        .collect();
    let measured = random_walk(&samples, H, true);
    assert!((measured / arw - 1.0).abs() < 0.1, "measured {measured:e} vs {arw:e} rad/√s");
}
