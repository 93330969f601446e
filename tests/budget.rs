//! The error budget (`rinscope budget`, docs/budget.md): its parts add up to the full run within a
//! remainder that is second order (halving every source quarters it), and a bias the scheme turns
//! stays bounded while one along the never-turned axis grows, at the analytic rates.

use std::sync::atomic::AtomicBool;

use rinscope::app::budget::{compute, setup};
use rinscope::ins::budget::{Budget, CHANNELS, INS_HEADING, ImuTerm, ROUNDING, Source, Triad};
use rinscope::scenario::presets;

fn budget(s: &rinscope::ins::budget::Setup) -> Budget {
    compute(s, 0, &AtomicBool::new(false), &|_| {}).expect("budget").0
}

/// Every preset with an error source, over its first minutes: the parts plus the baseline equal the
/// full run but for a remainder that is the non-linear interplay of the sources — with every source
/// halved, the largest part halves (linear: 0.5 ± 0.05) and the remainder falls to a quarter
/// (second order: ¼ ± 0.05, room for the next order's terms, whose share is the remainder's own
/// relative size, under a fifth here) or, where a symmetry cancels the second order (a dual-axis
/// table's pitch), to an eighth (third order: ⅛ ± 0.025). A missing source, a part drawn with other
/// random numbers than the full run's or a baseline counted twice would leave a remainder of first
/// order, halving with the sources. Channels whose remainder is rounding (under 1e-4 of the unit or
/// 1e-6 of the full run: numbers the quaternion's rounding reaches) are not asked to scale.
#[test]
fn every_presets_parts_sum_to_the_full_run_within_a_second_order_remainder() {
    let mut checked = Vec::new();
    for (name, _) in presets::PRESETS {
        let mut p = presets::load(name).expect(name);
        let span = if p.ins.is_some() { 300.0 } else { 1800.0 };
        p.set_duration(p.duration_s.min(span));
        let full = setup(&p, (p.duration_s / 600.0).max(1.0 / p.step_hz));
        let b1 = budget(&full);
        if b1.parts.is_empty() {
            continue;
        }
        let b2 = budget(&full.scaled(0.5));
        for c in 0..CHANNELS.len() {
            let f = b1.full.metrics(c).peak;
            if f.is_nan() || f <= 1e3 * ROUNDING {
                continue;
            }
            let what = format!("{name}: {} {}", CHANNELS[c].group, CHANNELS[c].component);
            let (k, big) = b1
                .parts
                .iter()
                .enumerate()
                .max_by(|x, y| x.1.1.metrics(c).peak.total_cmp(&y.1.1.metrics(c).peak))
                .expect("a part");
            let half = b2.parts[k].1.metrics(c).peak / big.1.metrics(c).peak;
            assert!((half - 0.5).abs() < 0.05, "{what}: the largest part scaled by {half} with its source halved");
            let (r1, r2) = (b1.remainder.metrics(c).peak, b2.remainder.metrics(c).peak);
            if r1 > 1e-4 && r1 > 1e-6 * f {
                let q = r2 / r1;
                let order = if (q - 0.25).abs() < 0.05 {
                    2
                } else if (q - 0.125).abs() < 0.025 {
                    3
                } else {
                    panic!("{what}: remainder {r1} of {f} scaled by {q} with every source halved")
                };
                eprintln!("{what}: remainder {r1:.3e} of {f:.3e}, order {order} (×{q:.4} with the sources halved)");
                checked.push(what);
            }
        }
    }
    assert!(checked.len() >= 20, "only {} channels had a remainder clear of rounding: {checked:?}", checked.len());
}

/// A continuously turning azimuth axis (rotation-modulation-continuous, 10°/s about z, constant gyro
/// biases 0.01°/h): the x gyro's bias is turned at Ω, its part of the tilt bounded by the direct
/// integral 2ε/Ω plus the Schuler loop's answer to its mean ε/Ω, and not growing; the z gyro's (along
/// the never-turned axis) drives the heading error at its own rate, ε·sin(ω_ie t)/ω_ie in a static
/// INS (0.989 εt at 1 h), from which the tilt coupling moves it by under 1 %.
#[test]
fn a_turned_bias_stays_bounded_and_one_along_the_never_turned_axis_grows_at_its_rate() {
    let mut p = presets::load("rotation-modulation-continuous").expect("preset");
    let hours = 1.0;
    p.set_duration(hours * 3600.0);
    let b = budget(&setup(&p, 10.0));
    let part = |t: ImuTerm| &b.parts.iter().find(|(s, _)| *s == Source::Imu(t)).expect("the source").1;
    let eps = 0.01f64.to_radians() / 3600.0; // rad/s
    let omega = 10f64.to_radians();
    let arcsec = |rad: f64| rad.to_degrees() * 3600.0;
    let n = b.t_s.len();
    // Turned: the tilt part's size bounded and the same in each half.
    let x = part(ImuTerm::Bias(Triad::Gyro, 0));
    let tilt = |i: usize| x.values[i][0].hypot(x.values[i][1]);
    let peak = |r: std::ops::Range<usize>| r.map(tilt).fold(0.0, f64::max);
    let (first, second) = (peak(0..n / 2), peak(n / 2..n));
    assert!(second <= 3.0 * arcsec(eps / omega), "turned x bias: tilt {second}″ over 3ε/Ω");
    assert!((0.5..=2.0).contains(&(second / first)), "turned x bias grows: {first}″ then {second}″");
    // Never turned: the heading part at the rate.
    let z = part(ImuTerm::Bias(Triad::Gyro, 2));
    let heading = |i: usize| z.values[i][INS_HEADING].abs();
    let t = b.t_s[n - 1];
    let expected = arcsec(
        eps * (rinscope::math::units::EARTH_RATE_RAD_PER_S * t).sin() / rinscope::math::units::EARTH_RATE_RAD_PER_S,
    );
    let ratio = heading(n - 1) / expected;
    assert!((0.99..=1.01).contains(&ratio), "z bias heading {}″ at {t} s, analytic {expected}″", heading(n - 1));
    assert!(heading(n - 1) > 20.0 * second, "the never-turned bias should dominate the turned one");
}

/// Schemes side by side (`app::schemes`) on an IMU whose only error is a vertical gyro bias ε = 0.01°/h:
/// a scheme that never turns the z axis over (none, single-axis-4, continuous) leaves the static
/// INS's heading drift ε·sin(ω_ie t)/ω_ie (within 2 % at 2 h, the coupling with the tilts), the
/// dual-axis sequences turn it over and keep the heading within a tenth of it.
#[test]
fn schemes_side_by_side_leave_a_vertical_gyro_bias_to_the_azimuth_only_ones() {
    use rinscope::app::outputs::RecordingRequest;
    use rinscope::app::schemes::{SchemesRequest, built_in, execute};
    let text = r#"
[scenario]
name = "vertical-gyro-bias"
title = "A vertical gyro bias alone"
[simulation]
duration_s = 7200.0
step_hz = 100.0
[site]
latitude_deg = 40.0
[turntable]
[[turntable.axis]]
name = "outer"
axis = "y"
[[turntable.axis]]
name = "inner"
axis = "z"
[scheme]
kind = "static"
[imu]
algorithm = "two-sample"
[imu.gyro]
bias_deg_per_h = [0.0, 0.0, 0.01]
[navigation]
vertical = "held"
"#;
    let params = rinscope::scenario::parse(text, "the test scenario").expect("scenario");
    let names = ["none", "single-axis-4", "continuous", "dual-axis-8", "dual-axis-16", "dual-axis-32", "dual-axis-64"];
    let request = SchemesRequest {
        params,
        schemes: names.iter().map(|n| ((*n).to_owned(), built_in(n).expect("built-in").to_owned())).collect(),
        seeds: 1,
        threads: None,
        json: None,
        budget: false,
        modulable_only: false,
        preface: None,
        recording: RecordingRequest { sinks: Default::default(), save_by_default: false },
    };
    let report = execute(&request, &AtomicBool::new(false)).expect("schemes");
    let heading = |name: &str| report.rows.iter().find(|r| r.scheme == name).expect(name).heading_peak_arcsec.median;
    let w = rinscope::math::units::EARTH_RATE_RAD_PER_S;
    let t = report.duration_s;
    let drift = (0.01f64.to_radians() / 3600.0 * (w * t).sin() / w).to_degrees() * 3600.0;
    for name in ["none", "single-axis-4", "continuous"] {
        let r = heading(name) / drift;
        assert!((0.98..=1.02).contains(&r), "{name}: peak heading {}″, the drift ε·sin(ω t)/ω {drift}″", heading(name));
    }
    for name in ["dual-axis-8", "dual-axis-16", "dual-axis-32", "dual-axis-64"] {
        assert!(heading(name) < 0.1 * drift, "{name}: peak heading {}″ of the unmodulated {drift}″", heading(name));
    }
    // Geometry: the 16-position sequence turns each axis 180° per move and comes back (wrap 360°).
    let row = report.rows.iter().find(|r| r.scheme == "dual-axis-16").expect("row");
    assert!(row.wrap_deg.iter().all(|(_, w)| (w - 360.0).abs() < 1e-6), "{:?}", row.wrap_deg);
    assert!((row.period_s.expect("periodic") - 16.0 * 79.0).abs() < 1e-6);
}
