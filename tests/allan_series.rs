//! `rinscope allan --series`: any series, as the field's files hold it, against published values.
//!
//! Golden numbers: NIST SP 1065 (Riley 2008) p. 107-108 — the NBS14 9-point frequency set with its
//! deviations at τ = 1 and 2 (Table 31), and the 1000-point set (generated as the handbook says)
//! with its deviations at τ = 1, 10, 100 — printed to 7 digits, so agreement to 2e-6 is what the
//! print allows. The files are written here in the formats' documented layouts (CSV, NumPy .npy
//! by hand, Parquet by the parquet crate's own writer), not by rinscope.

// The io tests' own writers (hand-written .npy, the parquet crate's ArrowWriter); test helpers unwrap.
#[allow(dead_code, clippy::unwrap_used)]
#[path = "io/common.rs"]
mod writers;

mod common;
use common::{rinscope, scratch};
use std::path::Path;
use std::process::Output;

use serde_json::Value;

use writers::nbs14_1000;

fn text(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// Runs `allan` with `args` and `--json`, no recording; the JSON.
fn analyse(dir: &Path, args: &[&str]) -> (Value, String) {
    let json = dir.join("out.json");
    let o = rinscope().arg("allan").args(args).arg("--no-recording").arg("--json").arg(&json).output().expect("run");
    assert!(o.status.success(), "{}", text(&o));
    (serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("valid json"), text(&o))
}

/// NBS14's 9 frequency values (NIST SP 1065 §12.2).
const NBS14_9: [f64; 9] = [892.0, 809.0, 823.0, 798.0, 671.0, 644.0, 883.0, 903.0, 677.0];

/// SP 1065 p. 108: the 1000-point set's deviations at τ = 1, 10, 100 s (TDEV in s, the phase's unit).
const NBS14_1000_DEVS: [(&str, [f64; 3]); 7] = [
    ("adev", [2.922319e-01, 9.965736e-02, 3.897804e-02]),
    ("oadev", [2.922319e-01, 9.159953e-02, 3.241343e-02]),
    ("mdev", [2.922319e-01, 6.172376e-02, 2.170921e-02]),
    ("tdev", [1.687202e-01, 3.563623e-01, 1.253382e+00]),
    ("hdev", [2.943883e-01, 1.052754e-01, 3.910860e-02]),
    ("ohdev", [2.943883e-01, 9.581083e-02, 3.237638e-02]),
    ("totdev", [2.922319e-01, 9.134743e-02, 3.406530e-02]),
];

/// The curve of `estimator` on the first channel of `sensor`.
fn curve<'a>(j: &'a Value, sensor: &str, estimator: &str) -> &'a Value {
    j[sensor][0]["curves"]
        .as_array()
        .expect("curves")
        .iter()
        .find(|c| c["estimator"] == estimator)
        .unwrap_or_else(|| panic!("no {estimator} curve"))
}

/// The deviation at τ (the first key starting with `dev_`), in that key's unit.
fn dev_at(c: &Value, tau_s: f64) -> f64 {
    let taus = c["tau_s"].as_array().expect("taus");
    let j = taus
        .iter()
        .position(|t| (t.as_f64().expect("tau") - tau_s).abs() < 1e-9)
        .unwrap_or_else(|| panic!("no τ = {tau_s}"));
    let key = c.as_object().expect("object").keys().find(|k| k.starts_with("dev_")).expect("a dev_ key");
    c[key][j].as_f64().expect("value")
}

fn check_nbs14_1000(j: &Value, phase_scale: f64) {
    for (est, devs) in NBS14_1000_DEVS {
        let c = curve(j, "clock", est);
        for (tau, want) in [1.0, 10.0, 100.0].into_iter().zip(devs) {
            let want = if est == "tdev" { want * phase_scale } else { want };
            let got = dev_at(c, tau);
            assert!((got / want - 1.0).abs() < 2e-6, "{est} τ = {tau}: {got:e} vs the published {want:e}");
        }
    }
}

#[test]
fn the_nbs14_1000_point_set_from_a_csv_matches_the_published_deviations_of_every_estimator() {
    let dir = scratch("nbs1000");
    let csv = dir.join("nbs14.csv");
    let body: String = nbs14_1000().iter().map(|y| format!("{y:.17e}\n")).collect();
    std::fs::write(&csv, format!("y\n{body}")).expect("write");
    let (j, out) = analyse(
        &dir,
        &[
            "--series",
            csv.to_str().expect("utf-8"),
            "--column",
            "y:frequency",
            "--rate-hz",
            "1",
            "--estimator",
            "all",
            "--taus",
            "decade",
        ],
    );
    // TDEV is printed in ns for a clock: the published seconds × 1e9.
    check_nbs14_1000(&j, 1e9);
    assert!(out.contains("clock y") && out.contains("TOTDEV"), "{out}");
    // Each curve carries its EDF, which grows with the number of terms: positive, finite, falling with τ.
    for est in ["oadev", "mdev", "totdev", "hdev"] {
        let edf: Vec<f64> = curve(&j, "clock", est)["edf"]
            .as_array()
            .expect("edf")
            .iter()
            .map(|v| v.as_f64().expect("edf value"))
            .collect();
        assert!(
            edf.iter().all(|e| e.is_finite() && *e >= 1.0) && edf.windows(2).all(|w| w[1] < w[0]),
            "{est}: {edf:?}"
        );
    }
}

#[test]
fn the_same_set_as_a_phase_record_in_npy_with_a_time_column_gives_the_same_curves() {
    // The phase x_k = Σ_{i<k} y_i·τ0 in ns (1001 points), with a clock column in ms: the kind,
    // the unit and the sampling all change, the deviations must not.
    let dir = scratch("phase");
    let npy = dir.join("phase.npy");
    let mut x = 0.0;
    let mut rows = vec![vec![0.0, 0.0]];
    for (k, y) in nbs14_1000().iter().enumerate() {
        x += y * 1e9;
        rows.push(vec![x, (k + 1) as f64 * 1000.0]);
    }
    writers::write_npy(&npy, &rows, "<f8");
    let (j, _) = analyse(
        &dir,
        &[
            "--series",
            npy.to_str().expect("utf-8"),
            "--column",
            "0:phase:ns",
            "--time-column",
            "1:ms",
            "--estimator",
            "all",
            "--taus",
            "decade",
        ],
    );
    assert_eq!(j["samples"].as_u64(), Some(1000), "1001 phase points are 1000 intervals");
    // Summing in ns then scaling back costs a few ulps of the phase: 1e-9 would still be exact
    // to the published digits; the 2e-6 of the print is what is checked.
    check_nbs14_1000(&j, 1e9);
}

#[test]
fn the_9_point_set_is_analysed_as_far_as_each_estimator_is_defined() {
    // Nine samples: no 16-sample minimum. The published τ = 1 and 2 values (SP 1065 Table 31).
    let dir = scratch("nbs9");
    let pq = dir.join("nbs9.parquet");
    writers::write_parquet(&pq, &["f"], &NBS14_9.iter().map(|v| vec![*v]).collect::<Vec<_>>(), None, 4);
    let (j, out) = analyse(
        &dir,
        &[
            "--series",
            pq.to_str().expect("utf-8"),
            "--column",
            "f:frequency",
            "--rate-hz",
            "1",
            "--estimator",
            "all",
            "--taus",
            "all",
        ],
    );
    let published = [
        ("adev", 91.22945, 115.8082),
        ("oadev", 91.22945, 85.95287),
        ("mdev", 91.22945, 74.78849),
        ("tdev", 52.67135, 86.35831),
        ("hdev", 70.80608, 116.7980),
        ("ohdev", 70.80607, 85.61487),
        ("totdev", 91.22945, 93.90379),
    ];
    for (est, d1, d2) in published {
        let c = curve(&j, "clock", est);
        let scale = if est == "tdev" { 1e9 } else { 1.0 };
        for (tau, want) in [(1.0, d1), (2.0, d2)] {
            let got = dev_at(c, tau);
            assert!((got / (want * scale) - 1.0).abs() < 1.5e-6, "{est} τ = {tau}: {got} vs {}", want * scale);
        }
    }
    // As far as defined, and said: with 10 phase points, OADEV to m = 4 (2m < 10), OHDEV to m = 3 (3m < 10).
    let last_tau =
        |est: &str| curve(&j, "clock", est)["tau_s"].as_array().expect("taus").last().and_then(Value::as_f64);
    assert_eq!(last_tau("oadev"), Some(4.0));
    assert_eq!(last_tau("ohdev"), Some(3.0));
    assert!(out.contains("9 samples") && out.contains("defined up to"), "{out}");
}

#[test]
fn a_gyro_rate_column_with_a_time_column_gives_its_angle_random_walk() {
    // White rate noise of σ = 0.05 °/s at 100 Hz: N = σ·√τ0 = 0.005 °/√s = 0.3 °/√h (analytic),
    // ADEV(τ) = N/√τ. 200 000 samples (2000 s), a t column in s beside a counter column.
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let dir = scratch("gyro");
    let csv = dir.join("rate_table.csv");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(952);
    let mut body = String::from("t,counter,gz\n");
    for k in 0..200_000 {
        let w: f64 = StandardNormal.sample(&mut rng);
        body += &format!("{:.2},{k},{:.9}\n", k as f64 * 0.01, 0.05 * w);
    }
    std::fs::write(&csv, body).expect("write");
    let (j, out) = analyse(
        &dir,
        &[
            "--series",
            csv.to_str().expect("utf-8"),
            "--column",
            "gz:rate:deg/s",
            "--time-column",
            "t",
            "--estimator",
            "oadev,totdev,mdev",
        ],
    );
    let g = &j["gyro"][0];
    let (n, sigma) = (
        g["fitted"]["n_deg_per_sqrt_h"]["value"].as_f64().expect("N"),
        g["fitted"]["n_deg_per_sqrt_h"]["sigma"].as_f64().expect("σ"),
    );
    assert!((n - 0.3).abs() < 4.0 * sigma && sigma / n < 0.02, "N {n} ± {sigma} °/√h vs 0.3");
    assert!(!g["fitted"]["b_deg_per_h"]["significant"].as_bool().expect("flag"), "no bias instability in white noise");
    // TOTDEV follows the analytic white-FM curve within its ±1σ bounds at most τ (68 % expected;
    // 50 % asked), and its noise type is named white FM wherever it is identified.
    let t = curve(&j, "gyro", "totdev");
    let taus: Vec<f64> = t["tau_s"].as_array().expect("taus").iter().map(|v| v.as_f64().expect("tau")).collect();
    let inside = taus
        .iter()
        .enumerate()
        .filter(|(i, tau)| {
            let analytic = 0.3 * 60.0 / tau.sqrt(); // °/h: N/√τ, N = 0.3 °/√h = 18 °/h·√s
            let (lo, hi) =
                (t["lower_deg_per_h"][*i].as_f64().expect("lo"), t["upper_deg_per_h"][*i].as_f64().expect("hi"));
            (lo..=hi).contains(&analytic)
        })
        .count();
    assert!(2 * inside >= taus.len(), "TOTDEV covers the analytic curve at {inside} of {} τ", taus.len());
    let alphas: Vec<(i64, bool)> = t["alpha"]
        .as_array()
        .expect("alpha")
        .iter()
        .zip(t["alpha_identified"].as_array().expect("flags"))
        .map(|(a, f)| (a.as_i64().expect("α"), f.as_bool().expect("flag")))
        .collect();
    assert!(
        alphas.iter().filter(|(_, f)| *f).all(|(a, _)| *a == 0),
        "white FM everywhere it is identified: {alphas:?}"
    );
    assert!(out.contains("gyro gz") && out.contains("MDEV (°/h)"), "{out}");
}

#[test]
fn bad_series_input_is_refused_by_name() {
    let dir = scratch("bad");
    let csv = dir.join("s.csv");
    std::fs::write(&csv, "t,y\n0,1\n1,2\n2,3\n4,5\n5,6\n").expect("write");
    let f = csv.to_str().expect("utf-8");
    let cases: [(&[&str], &str); 6] = [
        (&["--column", "nope:frequency", "--rate-hz", "1"], "the file has"),
        (&["--column", "y:rate:furlong", "--rate-hz", "1"], "unknown unit \"furlong\""),
        (&["--column", "y:rate:ns", "--rate-hz", "1"], "not a unit of a rate"),
        (&["--column", "y:frequency"], "--rate-hz HZ or --time-column"),
        (&["--column", "y:frequency", "--time-column", "t"], "evenly spaced"),
        (&["--column", "y:frequency", "--rate-hz", "1", "--estimator", "adevv"], "\"adevv\" is not an estimator"),
    ];
    for (args, says) in cases {
        let o = rinscope().args(["allan", "--series", f, "--no-recording"]).args(args).output().expect("run");
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o));
        assert!(text(&o).contains(says), "{args:?} should say {says:?}: {}", text(&o));
    }
}
