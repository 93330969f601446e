//! The rotation-scheme designer (`rinscope design`, docs/schemes.md) on an error set whose best
//! scheme is known analytically.
//!
//! A single azimuth axis, horizontal gyro biases only, moves of 180° with the cable held to ±180°:
//! every sequence of two or four such moves that returns is one of six — (+−), (−+), (+−+−),
//! (−+−+), (+−−+), (−++−). The dwells at 0° and 180° cancel a horizontal bias in all six; the moves
//! do not: a move sweeps a half plane, ∫(cos θ, sin θ) dθ/ω = (0, ±2/ω), and (+−) sweeps the upper
//! one twice (the averaged bias 4ε/(ωT), `ins::averaged`'s test), as does (+−+−); only (+−−+) and
//! its mirror sweep both halves and leave no drift. The designer must find exactly those two, and
//! the exact simulation must confirm them far ahead of the two-move sequence that is the textbook
//! "two-position" scheme.

use std::sync::atomic::AtomicBool;

use rinscope::app::design::{DesignRequest, DesignSpace, execute};
use rinscope::app::outputs::RecordingRequest;
use rinscope::scenario;

const TABLE: &str = r#"
[scenario]
name = "design-test"
title = "one azimuth axis, horizontal gyro biases"
seed = 5
[simulation]
duration_s = 43200.0
step_hz = 20.0
[site]
latitude_deg = 40.0
longitude_deg = 116.0
[turntable]
[[turntable.axis]]
name = "inner"
axis = "z"
[scheme]
kind = "indexed"
[[scheme.step]]
axis = "inner"
angle_deg = 180.0
rate_deg_per_s = 10.0
dwell_s = 60.0
[[scheme.step]]
axis = "inner"
angle_deg = -180.0
rate_deg_per_s = 10.0
dwell_s = 60.0
[imu]
algorithm = "two-sample"
[imu.gyro]
bias_deg_per_h = [0.05, 0.05, 0.0]
[navigation]
vertical = "held"
"#;

fn request(space: DesignSpace) -> DesignRequest {
    DesignRequest {
        params: scenario::parse(TABLE, "the test's table").expect("the test's scenario"),
        space,
        candidates: 200,
        refine: 50,
        confirm: 6,
        seeds: 1,
        threads: None,
        json: None,
        save_scheme: None,
        recording: RecordingRequest::default(),
    }
}

/// The signs of a `[scheme]`'s moves.
fn signs(toml_text: &str) -> String {
    let v: toml::Table = toml::from_str(toml_text).expect("the printed scheme is TOML");
    v["scheme"]["step"]
        .as_array()
        .expect("steps")
        .iter()
        .map(|s| if s["angle_deg"].as_float().expect("an angle") > 0.0 { '+' } else { '-' })
        .collect()
}

#[test]
fn the_designer_finds_the_sequence_that_sweeps_both_half_planes() {
    let space = DesignSpace { steps: vec![2, 4], max_wrap_deg: 180.0, ..DesignSpace::default() };
    let report = execute(&request(space), &AtomicBool::new(false)).expect("design");
    // Every distinct sequence there is (six), however many were drawn.
    assert_eq!(report.distinct, 6, "{}", report.text());
    let found: Vec<_> = report.ranked.iter().filter(|r| !r.built_in).collect();
    let order: Vec<String> = found.iter().map(|r| signs(&r.scheme)).collect();
    let mut first_two = order[..2].to_vec();
    first_two.sort();
    assert_eq!(first_two, ["+--+", "-++-"], "the model's ranking: {order:?}\n{}", report.text());
    // The model: the two leave no drift of the biases, only the tilt the dwells hold between the
    // moves (bounded: about R·ε·D/4 ≈ 20 m for the 60 s dwells D); the rest a drift of 4ε/(ωT) =
    // 0.15 ε or, for (+−+−), the same over a period twice as long, whose position error grows as
    // R·0.15·ε·t, a few km in 12 h: two orders of magnitude apart.
    let two = found.iter().find(|r| signs(&r.scheme) == "+-").expect("(+−) drawn");
    assert!(found[0].model_m < 0.05 * two.model_m, "{} vs {}", found[0].model_m, two.model_m);
    // The exact simulation agrees: the best confirmed is one of the two, and its position error is a
    // small fraction of the two-position sequence's (which drifts by 0.15 of the bias).
    let end = |label: &str| {
        report
            .ranked
            .iter()
            .find(|r| r.label == label)
            .and_then(|r| r.exact.as_ref())
            .expect("confirmed")
            .position_end_m
            .median
    };
    let best = report.ranked.iter().find(|r| r.label == report.best).expect("the best");
    assert!(["+--+", "-++-"].contains(&signs(&best.scheme).as_str()), "{}", report.text());
    assert!(end(&found[0].label) < 0.1 * end(&two.label), "{}", report.text());
}

#[test]
fn constraints_no_sequence_fits_are_named() {
    for (space, says) in [
        (DesignSpace { axes: vec!["outer".into()], ..DesignSpace::default() }, "the table's axes are inner"),
        (DesignSpace { max_wrap_deg: 90.0, ..DesignSpace::default() }, "90.0°"),
        (DesignSpace { steps: vec![3], ..DesignSpace::default() }, "even"),
    ] {
        let e = execute(&request(space), &AtomicBool::new(false)).expect_err("refused");
        assert!(e.message.contains(says), "{}", e.message);
    }
}
