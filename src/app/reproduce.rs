//! `rinscope reproduce`: every scenario that reproduces a paper's number, paper beside rinscope.
//!
//! Each row states the quantity, the paper's value as printed, rinscope's value and the tolerance
//! band it must fall in. Later issues add rows; docs/reproduce.md keeps the latest table.

mod modulation;

use std::sync::atomic::{AtomicBool, Ordering};

use crate::app::failure::Failure;
use crate::app::outputs::check_output;
use crate::io::files::write_atomically;
use crate::math::stats::RunningStat;
use crate::math::units::{ARCSEC_PER_RAD, DEG_PER_RAD};
use crate::scenario::Params;
use crate::scenario::presets;
use crate::sim::run_stats;

/// Runs the INS of a scenario and returns, per algorithm and axis, the statistics of the body
/// attitude error at every attitude update after `settle_s` (the FIR and the alignment settle).
fn ins_stats(p: &Params, settle_s: f64) -> Vec<[RunningStat; 3]> {
    let Some(mut ins) = p.ins_run() else { return Vec::new() };
    let steps = p.timeline().intervals();
    let mut stats = vec![[RunningStat::default(); 3]; ins.algorithms().len()];
    for _ in 0..steps {
        let s = ins.step();
        if s.updated && s.t_s >= settle_s {
            let v = ins.view(s.t_s);
            for (k, e) in v.errors.iter().enumerate() {
                for (a, x) in e.as_array().into_iter().enumerate() {
                    stats[k][a].add(x);
                }
            }
        }
    }
    stats
}

/// Standard deviation-like 1σ of a zero-mean error: its RMS.
fn sigma(s: &RunningStat) -> f64 {
    s.rms()
}

/// One comparison.
#[derive(Debug, Clone)]
pub struct Row {
    /// Paper and place (seed, section, figure or table).
    pub source: String,
    /// Scenario that reproduces it.
    pub scenario: String,
    /// What is compared, with its unit.
    pub quantity: String,
    /// The paper's value, as printed.
    pub paper: String,
    /// rinscope's value.
    pub value: f64,
    /// Accepted band, inclusive: two-sided, around an analytic value or the paper's value at its
    /// printed precision.
    pub band: (f64, f64),
    /// What the band is and where it comes from.
    pub tolerance: String,
    /// Where the paper's number differs from rinscope's by more than its printed precision: why.
    pub paper_note: String,
    /// Set when the paper's number cannot be reproduced here (an input it does not give, error
    /// sources the scenario does not have): why. The row is then not a pass.
    pub not_reproduced: Option<String>,
}

/// A band bound with at most 4 significant digits.
fn num(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    let digits = (4 - x.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.digits$}");
    if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_owned() } else { s }
}

impl Row {
    /// A row checked against `band`.
    fn new(
        source: &str,
        scenario: &str,
        quantity: String,
        paper: String,
        value: f64,
        band: (f64, f64),
        tolerance: String,
    ) -> Self {
        Self {
            source: source.into(),
            scenario: scenario.into(),
            quantity,
            paper,
            value,
            band,
            tolerance,
            paper_note: String::new(),
            not_reproduced: None,
        }
    }

    /// The same row with an explanation of its difference from the paper.
    fn note(mut self, note: impl Into<String>) -> Self {
        self.paper_note = note.into();
        self
    }

    /// The same row marked as not reproduced, and why.
    fn not_reproduced(mut self, why: impl Into<String>) -> Self {
        self.not_reproduced = Some(why.into());
        self
    }

    /// Whether rinscope's value falls in the band (a row that is not a reproduction is never checked).
    #[must_use]
    pub fn agrees(&self) -> bool {
        self.value >= self.band.0 && self.value <= self.band.1
    }

    /// The verdict column.
    #[must_use]
    pub fn verdict(&self) -> String {
        match (&self.not_reproduced, self.agrees()) {
            (Some(why), true) => format!("not reproduced: {why}"),
            (Some(why), false) => format!("NO (and not reproduced: {why})"),
            (None, true) => "yes".into(),
            (None, false) => "NO".into(),
        }
    }
}

/// All rows.
#[derive(Debug, Clone, Default)]
pub struct Table {
    /// In display order.
    pub rows: Vec<Row>,
}

impl Table {
    /// True when every row agrees.
    #[must_use]
    pub fn all_agree(&self) -> bool {
        self.rows.iter().filter(|r| r.not_reproduced.is_none()).all(Row::agrees)
    }

    /// Plain-text table for the terminal.
    #[must_use]
    pub fn text(&self) -> String {
        let mut s = format!(
            "{:<34} {:<64} {:>14} {:>12}  {:<24} {}\n",
            "scenario", "quantity", "paper", "rinscope", "accepted band", "agrees"
        );
        for r in &self.rows {
            s.push_str(&format!(
                "{:<34} {:<64} {:>14} {:>12.5}  {:<24} {}\n",
                r.scenario,
                r.quantity,
                r.paper,
                r.value,
                format!("[{}, {}]", num(r.band.0), num(r.band.1)),
                r.verdict()
            ));
            s.push_str(&format!("{:<34}   band: {}\n", "", r.tolerance));
            if !r.paper_note.is_empty() {
                s.push_str(&format!("{:<34}   vs the paper: {}\n", "", r.paper_note));
            }
        }
        s
    }

    /// Markdown table for docs/reproduce.md.
    #[must_use]
    pub fn markdown(&self) -> String {
        let mut s = String::from(
            "# Paper vs rinscope\n\nGenerated by `cargo run --release -- reproduce --markdown docs/reproduce.md`; \
             exit code 1 if a row falls outside its band.\n\n\
             Every band is two-sided and derived: around an analytic value (with the size of what the \
             analysis neglects), or around the paper's number at its printed precision. A row whose paper \
             number cannot be reproduced here says why, and is not counted as a pass.\n\n\
             | source | scenario | quantity | paper | rinscope | accepted band | agrees | vs the paper |\n|---|---|---|---|---|---|---|---|\n",
        );
        for r in &self.rows {
            s.push_str(&format!(
                "| {} | `{}` | {} | {} | {:.5} | [{}, {}] ({}) | {} | {} |\n",
                r.source,
                r.scenario,
                r.quantity,
                r.paper,
                r.value,
                num(r.band.0),
                num(r.band.1),
                r.tolerance,
                if r.agrees() { r.verdict() } else { format!("**{}**", r.verdict()) },
                r.paper_note
            ));
        }
        s
    }
}

/// The largest first-order error angle of a table's truth, rad (what the closed form neglects is
/// of second order in it).
fn largest_error_angle(p: &Params) -> f64 {
    let t = &p.table.truth;
    let mut m = t.installation_rad.iter().chain(t.imu_mount_rad.iter()).fold(0.0_f64, |m, x| m.max(x.abs()));
    for a in &t.axes {
        m = m.max(a.swing_half_angle_rad).max(a.non_orthogonality_rad.abs()).max(a.encoder_offset_rad.abs());
    }
    m
}

/// The closed form's residual against the exact chain: second order in the error angle θ, so
/// |residual| / |error| ≈ c·θ with c of order one; accepted c ∈ [1/20, 2].
fn closed_form_row(source: &str, name: &str, p: &Params, stats: &crate::sim::ErrorStats) -> Row {
    let theta = largest_error_angle(p);
    let dev = stats.closed_form_deviation.iter().map(RunningStat::peak).fold(0.0, f64::max);
    let relative = 100.0 * dev / stats.peak_over_axes(0).max(1e-300);
    Row::new(
        source,
        name,
        "closed form − exact, peak, % of peak error".into(),
        "agree well".into(),
        relative,
        (100.0 * theta / 20.0, 100.0 * 2.0 * theta),
        format!("second order: residual/error ≈ c·θ, θ = {:.3e} rad the largest error angle, c ∈ [1/20, 2]", theta),
    )
}

/// `rinscope reproduce`'s owner: every reproducing scenario run, the table written as markdown
/// to `markdown` (checked before anything runs). A table with a row outside its band is a
/// report, not a failure: the caller says so.
///
/// # Errors
/// An output that cannot be written, a preset that does not load, a signal (between scenarios:
/// within the longest one's time, a few seconds).
pub fn execute(markdown: Option<&std::path::Path>, stop: &AtomicBool) -> Result<Table, Failure> {
    check_output("--markdown", markdown)?;
    let table = match run_all(stop) {
        Ok(t) => t,
        Err(_) if stop.load(Ordering::SeqCst) => {
            return Err(Failure::interrupted("the reproductions did not finish; nothing written"));
        }
        Err(e) => return Err(Failure::from(e)),
    };
    if let Some(path) = markdown {
        write_atomically(path, table.markdown().as_bytes()).map_err(|e| Failure::output("--markdown", &e))?;
    }
    Ok(table)
}

/// An error once `stop` is set (checked between the scenarios).
fn go_on(stop: &AtomicBool) -> anyhow::Result<()> {
    if stop.load(Ordering::SeqCst) { Err(anyhow::anyhow!("interrupted")) } else { Ok(()) }
}

/// Runs every reproducing scenario (no recording) and builds the table.
pub fn run_all(stop: &AtomicBool) -> anyhow::Result<Table> {
    let mut rows = Vec::new();
    let rad_per_arcmin = crate::math::units::RAD_PER_ARCMIN;

    // The rotary-table paper §5, installation error 5′/5′: the paper's "reach 0.1 degrees", printed to one
    // significant digit ([0.05, 0.15]).
    go_on(stop)?;
    let p = presets::load("rotary-table-2016-installation")?;
    let stats = run_stats(&p.table_model(), &p.timeline());
    rows.push(Row::new(
        "the rotary-table paper §5, Fig. 5",
        "rotary-table-2016-installation",
        "peak error, largest of pitch, roll, heading, deg".into(),
        "reaches 0.1°".into(),
        stats.peak_over_axes(0) * DEG_PER_RAD,
        (0.05, 0.15),
        "the paper's 0.1, printed to one significant digit".into(),
    ));
    rows.push(closed_form_row("the rotary-table paper §5, Tables 1-3", "rotary-table-2016-installation", &p, &stats));

    // The rotary-table paper §5, wobble θ = 0.01 rad at azimuth 30°: in the 180° dwell of a level vehicle the board
    // is tilted by 2θ toward azimuth 30°, so the largest Euler error is 2θ·cos 30° (first order; the
    // neglected terms are θ² relative).
    go_on(stop)?;
    let p = presets::load("rotary-table-2016-wobble")?;
    let stats = run_stats(&p.table_model(), &p.timeline());
    let mut level = p.clone();
    level.table.vehicle =
        crate::model::motion::VehicleMotion::new(crate::math::attitude::Attitude::default(), Vec::new(), Vec::new())
            .map_err(anyhow::Error::msg)?;
    let model = level.table_model();
    // The 180° dwell of the 4-position scheme: 0° 290 s, move 9 s, 90° 290 s, move 9 s, 180° from 598 s.
    let t_dwell = 598.0 + 145.0;
    let (angles, rates) = model.scheme.state(t_dwell - model.scheme_t0_s);
    anyhow::ensure!(
        (angles[0] - std::f64::consts::PI).abs() < 1e-9 && rates[0] == 0.0,
        "the wobble preset's 180° dwell moved (t = {t_dwell} s)"
    );
    let out = crate::sim::step(&model, &mut crate::sim::DemodState::default(), t_dwell);
    let dwell_deg = out.errors[0].as_array().iter().fold(0.0_f64, |m, x| m.max(x.abs())) * DEG_PER_RAD;
    let theta = 0.01;
    let analytic = 2.0 * theta * (30.0_f64).to_radians().cos() * DEG_PER_RAD;
    rows.push(
        Row::new(
            "the rotary-table paper §4.2, Figs. 6-7",
            "rotary-table-2016-wobble",
            "180° dwell, vehicle level: largest Euler error, deg".into(),
            "almost 1°".into(),
            dwell_deg,
            (analytic * (1.0 - theta), analytic * (1.0 + theta)),
            format!("analytic 2θ·cos 30° = {analytic:.4}°, ± θ = 1 % (second order)"),
        )
        .note(format!("the run's peak, {:.3}°, comes in a 9-s move with the vehicle tilted; the paper's \"almost 1°\" is the dwell value", stats.peak_over_axes(0) * DEG_PER_RAD)),
    );
    rows.push(closed_form_row("the rotary-table paper §5, Tables 4-6", "rotary-table-2016-wobble", &p, &stats));

    // The rotary-table paper §5, encoder (angular) error 1′: a heading error of 1′ while level, shared with roll
    // and pitch when tilted; its peak over the run is 1′ to second order (1′² relative).
    go_on(stop)?;
    let p = presets::load("rotary-table-2016-angular")?;
    let stats = run_stats(&p.table_model(), &p.timeline());
    let one_arcmin_deg = rad_per_arcmin * DEG_PER_RAD;
    let th = rad_per_arcmin;
    rows.push(
        Row::new(
            "the rotary-table paper §5, Fig. 8",
            "rotary-table-2016-angular",
            "peak error, largest of pitch, roll, heading, deg".into(),
            "< 0.02°".into(),
            stats.peak_over_axes(0) * DEG_PER_RAD,
            (one_arcmin_deg * (1.0 - 10.0 * th), one_arcmin_deg * (1.0 + 10.0 * th)),
            format!(
                "analytic: the encoder error itself, 1′ = {one_arcmin_deg:.5}°, ± 10·θ relative (second order, θ = 1′)"
            ),
        )
        .note("consistent: the paper gives only the bound \"less than 0.02 degrees\""),
    );
    rows.push(closed_form_row("the rotary-table paper §5, Tables 7-9", "rotary-table-2016-angular", &p, &stats));

    // Jiang et al. 2017: the closed form of eq. 28 (re-derived) against the exact model at Table 2's values;
    // absolute residual of order α², α the largest error angle.
    go_on(stop)?;
    let p = presets::load("jiang2017-dual-axis")?;
    let stats = run_stats(&p.table_model(), &p.timeline());
    let dev = stats.closed_form_deviation.iter().map(|s| s.peak()).fold(0.0, f64::max) * ARCSEC_PER_RAD;
    let alpha = largest_error_angle(&p);
    let a2 = alpha * alpha * ARCSEC_PER_RAD;
    rows.push(Row::new(
        "Jiang et al. 2017 eq. 28, Table 2",
        "jiang2017-dual-axis",
        "closed form − exact, peak, arcsec".into(),
        "small-angle model".into(),
        dev,
        (a2 / 20.0, 2.0 * a2),
        format!(
            "second order: c·α², α = {:.1}′ the largest error angle (α² = {a2:.3}″), c ∈ [1/20, 2]",
            alpha / rad_per_arcmin
        ),
    ));

    // Li et al. 2014 §3 eq. 16/19 and Figure 10: 7°, 0.5 Hz azimuth wobble, 6.25 ms lag. Theorem: the
    // error is A·ω·τ·cos; neglected: (ωτ)²/2 = 2e-4 and the 100-Hz sampling of the peak,
    // (π f/fs)²/2 = 1.2e-4 relative.
    go_on(stop)?;
    let base = presets::load("li2014-phase-lag")?;
    let stats = ins_stats(&base, 2.0);
    let (amp, omega, tau) = (7.0, std::f64::consts::TAU * 0.5, 6.25e-3);
    let theorem = amp * omega * tau;
    let neglected = (omega * tau).powi(2) / 2.0 + (std::f64::consts::PI * 0.5 / 100.0).powi(2) / 2.0;
    rows.push(
        Row::new(
            "Li et al. 2014 eq. 19, Fig. 10",
            "li2014-phase-lag",
            "heading error amplitude, Δt = 0, deg".into(),
            "0.1374 (0.1368 measured)".into(),
            stats[0][2].peak() * DEG_PER_RAD,
            (theorem * (1.0 - 1.5 * neglected), theorem * (1.0 + 1.5 * neglected)),
            format!("theorem A·ω·τ = {theorem:.5}°, ± 1.5 × the neglected {neglected:.1e} relative"),
        )
        .note("the paper's 0.1368 is its measured value (noise and its wobbler); its theorem gives 0.1374"),
    );
    // Li et al. 2014 Table 3: the synchronisation sweep. Theorem: 1σ = A·ω·τ_res/√2, τ_res = 6.25 ms − Δt.
    for (dt_ms, paper_lag, paper_sigma) in
        [(0.0, "6.22", 0.097), (3.0, "3.21", 0.053), (5.0, "1.20", 0.021), (6.1, "0.27", 0.011), (6.25, "×", 0.003)]
    {
        let mut p = base.clone();
        if let Some(ins) = p.ins.as_mut() {
            ins.output_compensation_s = dt_ms * 1e-3;
        }
        let stats = ins_stats(&p, 2.0);
        let sig = sigma(&stats[0][2]) * DEG_PER_RAD;
        let tau_res = 6.25e-3 - dt_ms * 1e-3;
        let expected = amp * omega * tau_res / std::f64::consts::SQRT_2;
        // Neglected: the cross term of second order, ωτ relative to the residual error; at τ_res = 0
        // only the second-order term A·(ωτ)²/2 is left.
        let second = amp * (omega * tau).powi(2) / 2.0;
        let (band, why) = if tau_res > 0.0 {
            (
                (expected * (1.0 - 2.0 * omega * tau), expected * (1.0 + 2.0 * omega * tau)),
                format!("theorem A·ω·τ_res/√2 = {expected:.5}°, ± 2ωτ = {:.1} % (second order)", 200.0 * omega * tau),
            )
        } else {
            ((0.0, second), format!("theorem: 0; what the theorem neglects, A·(ωτ)²/2 = {second:.1e}°"))
        };
        let mut row = Row::new(
            "Li et al. 2014 Table 3",
            "li2014-phase-lag",
            format!(
                "Δt = {dt_ms} ms: 1σ heading error, deg (residual lag {:.2} ms; paper {})",
                tau_res * 1e3,
                if paper_lag == "×" { "gives no lag".to_owned() } else { format!("{paper_lag} ms") }
            ),
            format!("{paper_sigma}"),
            sig,
            band,
            why,
        );
        let precision = 0.0005;
        if (paper_sigma - sig).abs() > precision {
            row = if dt_ms < 6.0 {
                row.note(format!("the paper measured with its instrument noise and a residual lag of {paper_lag} ms (its σ follows from it); rinscope's lag model has no noise"))
            } else {
                row.note("at this residual lag the paper's σ is its instrument-noise floor, which this scenario does not model")
            };
        }
        rows.push(row);
    }
    // Li et al. 2014 Table 1: the single-sample (the paper's "quaternion") algorithm's coning drift.
    go_on(stop)?;
    let p = presets::load("li2014-coning")?;
    let stats = ins_stats(&p, 0.0);
    let single = crate::ins::coning::Algorithm::SingleSample;
    let k = p.ins_run().map(|i| i.algorithms()).unwrap_or_default().iter().position(|a| *a == single).unwrap_or(0);
    let drift = stats[k][0].peak() * DEG_PER_RAD;
    let implied = (0.1381 / drift).clamp(-1.0, 1.0).asin().to_degrees();
    rows.push(
        Row::new(
            "Li et al. 2014 Table 1",
            "li2014-coning",
            "single-sample (the paper's quaternion) algorithm: pitch drift in 10 min, deg".into(),
            "0.1381".into(),
            drift,
            (0.0, drift),
            "drift = D·sin(φ) over the unknown yaw-roll wobble phase φ ∈ [0°, 90°]; rinscope runs φ = 90°, D".into(),
        )
        .note(format!("the paper's 0.1381° is D·sin φ for φ = {implied:.1}°"))
        .not_reproduced("the paper does not give the phase between its yaw and roll wobbles"),
    );
    // Li et al. 2014 §4.2 / Table 6: the DAMS reaches 20″ (1σ) under three-axis wobbling.
    for name in ["li2014-wobble-1", "li2014-wobble-2"] {
        go_on(stop)?;
        let p = presets::load(name)?;
        let stats = ins_stats(&p, 0.0);
        let worst = stats[0].iter().map(sigma).fold(0.0, f64::max) * ARCSEC_PER_RAD;
        rows.push(
            Row::new(
                "Li et al. 2014 §4.2, Table 6",
                name,
                "largest 1σ attitude error over the 3 axes, arcsec".into(),
                "≤ 20 (7.3-20.7)".into(),
                worst,
                (0.0, 20.7),
                "the paper's range".into(),
            )
            .not_reproduced("the paper's 7.3-20.7″ include its turntable's and alignment errors, which this scenario does not have; rinscope's value is the algorithms' and the sensors' part"),
        );
    }
    calibration_rows(&mut rows, stop)?;
    modulation::rate_rows(&mut rows, stop)?;
    modulation::positions_rows(&mut rows, stop)?;
    Ok(Table { rows })
}

/// Jiang et al. 2017 §6: what compensation with the calibrated parameters leaves, and the Monte Carlo.
fn calibration_rows(rows: &mut Vec<Row>, stop: &AtomicBool) -> anyhow::Result<()> {
    go_on(stop)?;
    let p = presets::load("jiang2017-calibration")?;
    let outcome = crate::app::calibrate::calibrate_scenario(&p, false, stop)?;
    go_on(stop)?;
    // The least-squares compensation against compensating with the true values, on the independent
    // run: RMS² adds, so the ratio is √(1 + (3σ/floor)²) at most, σ the largest estimate 1σ; fitting
    // the noise could lower it by no more than p/n.
    // The table states the data determine (a prior-dominated direction does not change the
    // demodulation; the reference's nuisance states are not part of the compensation).
    let sig = outcome
        .report
        .state
        .iter()
        .take(outcome.cal.set.n_table)
        .filter(|r| r.flag.is_empty() && r.unit == "arcsec")
        .map(|r| r.nls.sigma)
        .fold(0.0, f64::max)
        * crate::math::units::RAD_PER_ARCSEC;
    let n = outcome.cal.samples.max(1) as f64;
    let p_over_n = outcome.cal.set.len() as f64 / n;
    if let Some(c) = outcome.report.compensation {
        for (axis, name) in ["pitch", "roll", "heading"].iter().enumerate() {
            let (before, after) = crate::calib::report::PAPER_LAB[axis];
            let floor = c.with_truth.rms_rad[axis];
            let ratio = c.after_nls.rms_rad[axis] / floor.max(1e-300);
            let hi = (1.0 + (3.0 * sig / floor.max(1e-300)).powi(2)).sqrt();
            rows.push(
                Row::new(
                    "Jiang et al. 2017 §6.2.2",
                    "jiang2017-calibration",
                    format!("{name}: RMS error after LSQ compensation / with the true values (independent run)"),
                    format!("{:.2}× ({before}″ → {after}″)", before / after),
                    ratio,
                    (1.0 - p_over_n, hi),
                    format!("√(1 + (3σ/floor)²) with σ = {:.3}″ the largest determined table state's 1σ, floor {:.2}″; − p/n below", sig * ARCSEC_PER_RAD, floor * ARCSEC_PER_RAD),
                )
                .note(format!(
                    "the paper's factor {:.2}× before/after is set by its lab's residual ({after}″: turntable and INS errors beyond the model); rinscope's before/after peak factor is {:.1}×, set by the 12″ encoder noise",
                    before / after,
                    c.before.peak_rad[axis] / c.after_nls.peak_rad[axis]
                )),
            );
        }
    }
    // The floor itself, on the same table without the INS (only encoder noise left): its RMS per
    // axis against the linear propagation of the encoders' white noise through the chain
    // (app::calibrate::encoder_noise_floor), 3σ of an RMS over n samples: 3/√(2n) relative.
    let mut ideal = p.clone();
    ideal.ins = None;
    let outcome = crate::app::calibrate::calibrate_scenario(&ideal, false, stop)?;
    let analytic = crate::app::calibrate::encoder_noise_floor(&ideal, stop)?;
    if let Some(c) = outcome.report.compensation {
        let n = outcome.cal.samples.max(1) as f64;
        for (axis, name) in ["pitch", "roll", "heading"].iter().enumerate() {
            let expected = analytic[axis];
            let rel = 3.0 / (2.0 * n).sqrt();
            rows.push(Row::new(
                "Jiang et al. 2017 §6.2",
                "jiang2017-calibration (no INS)",
                format!("{name}: RMS error with the true values (encoder noise only), arcsec"),
                "—".into(),
                c.with_truth.rms_rad[axis] * ARCSEC_PER_RAD,
                (expected * (1.0 - rel) * ARCSEC_PER_RAD, expected * (1.0 + rel) * ARCSEC_PER_RAD),
                format!(
                    "the encoders' 12″ white noise propagated through the chain: {:.3}″, ± 3/√(2n)",
                    expected * ARCSEC_PER_RAD
                ),
            ));
        }
    }
    // Jiang et al. 2017 Table 3: mean calibration errors over many runs; rinscope's mean |error| of each
    // identifiable quantity, against the spread the filter reports for it: E|x| = σ·√(2/π).
    let mc = crate::app::calibrate::monte_carlo(&p, 200, &|| {}, stop)?;
    let worst = mc
        .rows
        .iter()
        .filter(|r| r.identifiable && !r.label.contains("of phase"))
        .map(|r| r.nls.mean_abs)
        .fold(0.0, f64::max);
    rows.push(
        Row::new(
            "Jiang et al. 2017 §6.1, Table 3",
            "jiang2017-calibration",
            "Monte Carlo (200 runs): largest mean |error| of the identifiable parameters, arcsec".into(),
            "0.65-1.14".into(),
            worst,
            (0.0, 0.65),
            "the paper's range".into(),
        )
        .not_reproduced("the paper's runs include its filter's model errors and its INS's; rinscope's encoder-noise-limited errors are an order smaller (docs/calibration.md compares the reported 1σ with the spread)"),
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_paper_number_is_reproduced_within_its_band() {
        // The bands and the papers' values are in `run_all`; this fails if a model change moves a
        // reproduction out of agreement (the same check `rinscope reproduce` makes with exit code 1).
        let table = run_all(&AtomicBool::new(false)).expect("scenarios load");
        assert!(table.rows.len() >= 7);
        for r in table.rows.iter().filter(|r| r.not_reproduced.is_none()) {
            assert!(r.agrees(), "{} / {}: {} not in {:?}", r.scenario, r.quantity, r.value, r.band);
            assert!(r.band.0 > 0.0 || r.band.1 < f64::INFINITY, "{}: a band must bound the value", r.quantity);
            assert!(r.band.1.is_finite(), "{}: two-sided", r.quantity);
        }
    }
}
