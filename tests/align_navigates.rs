//! Issue 32: an alignment whose navigation uses what it estimates. At rest only the sum of the
//! tilt (× g) and the horizontal accelerometer bias is seen; the fine alignment splits it between
//! the two by their priors. Navigating with its tilt and without its bias leaves the bias estimate
//! as a horizontal force error: the Schuler swing of the *estimate* (PSINS's `lasergyro.imu`: 61 km
//! in 26 minutes from a 7 mg estimate). Navigating with both, only the residual of the data is
//! left. A parked navigation-grade IMU with a large horizontal accelerometer bias (2 mg, −1.5 mg),
//! aligned with a wide accelerometer prior (50 mg: what a running engine's vibration made of the
//! measured noise before the prior was capped), navigated 30 minutes both ways.

use rinscope::ins::align::{self, AlignConfig, Increment};
use rinscope::ins::core::InsCore;
use rinscope::ins::imu_errors::ImuErrors;
use rinscope::math::units::{
    MPS_PER_SQRT_S_PER_UG_PER_SQRT_HZ, MPS2_PER_UG, RAD_PER_S_PER_DEG_PER_H, RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H,
    STANDARD_GRAVITY_MPS2,
};

const SCENARIO: &str = "[scenario]\nname = \"parked\"\ntitle = \"t\"\nseed = 11\n\
[simulation]\nduration_s = 2200.0\nstep_hz = 100.0\n[site]\nlatitude_deg = 34.0\n\
[vehicle]\nheading_deg = 30.0\npitch_deg = 1.0\nroll_deg = -1.5\n\
[turntable]\n[[turntable.axis]]\nname = \"azimuth\"\naxis = \"z\"\n[scheme]\nkind = \"static\"\n\
[imu]\nalgorithm = \"two-sample\"\n[imu.gyro]\nbias_deg_per_h = [0.0, 0.0, 0.0]\narw_deg_per_sqrt_h = 0.001\n\
[imu.accel]\nbias_ug = [2000.0, -1500.0, 100.0]\nvrw_ug_per_sqrt_hz = 10.0\n[navigation]\nvertical = \"held\"\n";

const ALIGN_S: f64 = 300.0;
const NAVIGATE_S: f64 = 1800.0;
const RATE_HZ: f64 = 100.0;

/// The horizontal distance from the start after navigating `samples` from the alignment `a`,
/// with or without the biases it estimated removed, m.
fn drift(
    params: &rinscope::scenario::Params,
    a: &align::Alignment,
    pre_roll: &[Increment],
    samples: &[Increment],
    with_biases: bool,
) -> f64 {
    let cfg = params.ins.as_ref().expect("[imu]");
    let biases = ImuErrors::biases(a.gyro_bias_rad_per_s.0, a.accel_bias_mps2.0);
    let h = 1.0 / RATE_HZ;
    let mut core = InsCore::compensated(cfg, params.site, a.n_from_s, pre_roll, with_biases.then_some(biases));
    for (k, (g, f)) in samples.iter().enumerate() {
        core.push((k + 1) as f64 * h, *g, *f);
    }
    let s = core.nav_state().expect("navigating");
    let r = 6_371_000.0;
    let north = (s.latitude_rad - params.site.latitude_rad) * r;
    let east = (s.longitude_rad - params.site.longitude_rad) * r * params.site.latitude_rad.cos();
    east.hypot(north)
}

#[test]
fn the_navigation_uses_the_biases_the_alignment_estimated() {
    let params = rinscope::scenario::parse(SCENARIO, "parked").expect("scenario");
    let mut ins = params.ins_run().expect("an [imu]");
    let n_align = (ALIGN_S * RATE_HZ) as usize;
    let n_nav = (NAVIGATE_S * RATE_HZ) as usize;
    let mut window: Vec<Increment> = Vec::with_capacity(n_align);
    let mut samples: Vec<Increment> = Vec::with_capacity(n_nav);
    for k in 0..n_align + n_nav {
        let (_, g, f) = ins.next_measurement();
        if k < n_align { window.push((g, f)) } else { samples.push((g, f)) }
    }
    let cfg = AlignConfig {
        latitude_rad: params.site.latitude_rad,
        height_m: 0.0,
        interval_s: 1.0 / RATE_HZ,
        gyro_bias_sigma_rad_per_s: Some(0.01 * RAD_PER_S_PER_DEG_PER_H),
        accel_bias_sigma_mps2: Some(50_000.0 * MPS2_PER_UG),
        gyro_random_walk: Some(0.001 * RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H),
        accel_random_walk: Some(10.0 * MPS_PER_SQRT_S_PER_UG_PER_SQRT_HZ),
    };
    let a = align::fine(&window, &cfg).expect("alignment");
    let pre = InsCore::pre_roll_samples(params.ins.as_ref().expect("[imu]"));
    let pre_roll = &window[window.len() - pre..];
    let without = drift(&params, &a, pre_roll, &samples, false);
    let with = drift(&params, &a, pre_roll, &samples, true);
    // The Schuler model of a constant horizontal force error δf: R (δf/g)(1 − cos ω_s t),
    // ω_s = √(g/R). Of the estimate: what navigating without it gives.
    let (r, g) = (6_371_000.0, STANDARD_GRAVITY_MPS2);
    let schuler = |df: f64| r * (df / g) * (1.0 - ((g / r).sqrt() * NAVIGATE_S).cos());
    let estimate_h = a.accel_bias_mps2.0.xy().norm();
    let of_estimate = schuler(estimate_h);
    // Of the residual: what the data leave of the sum tilt·g + bias after 300 s (the accelerometer
    // white noise averaged over the window, 10 µg/√Hz / √300 s), the error of the horizontal gyro
    // bias estimate (its reported 1σ: a constant rate error ε tilts the platform and gives
    // R ε (t − sin ω_s t / ω_s)), and the gyros' angle random walk turned into a tilt over the 30
    // minutes (0.001 °/√h · √0.5 h); each at 3σ.
    let w = (g / r).sqrt();
    let df_noise = 3.0 * 10.0 * MPS2_PER_UG / ALIGN_S.sqrt();
    let gyro_sigma = a.gyro_bias_rad_per_s.1.xy().norm();
    let gyro_term = 3.0 * r * gyro_sigma * (NAVIGATE_S - (w * NAVIGATE_S).sin() / w);
    let tilt_walk = 3.0 * 0.001 * RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H * NAVIGATE_S.sqrt();
    let of_residual = schuler(df_noise) + gyro_term + r * tilt_walk;
    eprintln!(
        "accelerometer bias estimate {:.0} µg horizontal; drift in 30 min: without it {without:.0} m (Schuler of the estimate {of_estimate:.0} m), with it {with:.0} m (residual model ≤ {of_residual:.0} m)",
        estimate_h / MPS2_PER_UG
    );
    // The wide prior puts most of the 2.5 mg misfit into the bias.
    assert!(estimate_h > 1000.0 * MPS2_PER_UG, "estimate {} µg", estimate_h / MPS2_PER_UG);
    // Without it: the swing of the estimate (within the Earth-rate coupling's few per cent, and the
    // part of the misfit the tilt took).
    assert!((0.7 * of_estimate..1.3 * of_estimate).contains(&without), "{without} m vs {of_estimate} m");
    // With it: within the residual's, and a small fraction of the old drift.
    assert!(with < of_residual, "{with} m, more than the residual model's {of_residual} m");
    assert!(with < 0.1 * without, "{with} m against {without} m");
}
