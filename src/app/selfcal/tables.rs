//! What `selfcal` prints and records as text: the result table, the estimates with their 1σ and
//! what the sequence can see, the notes.

use super::*;
use crate::calib::selfcal::ParamKind;
use crate::calib::selfcal_table::TableKind;

/// The accuracy issue 23 asks of a navigation-grade IMU, and issue 32 of its table (1σ, in each
/// kind's display unit: a table's folded rotation as an IMU misalignment, its encoder scale as a
/// gyro's, a latch delay to a tenth of a millisecond — 3.6″ at 10°/s).
#[must_use]
pub fn target(kind: ParamKind) -> f64 {
    match kind {
        ParamKind::Imu(Kind::GyroBias) => 0.002,
        ParamKind::Imu(Kind::GyroScale) => 2.0,
        ParamKind::Imu(Kind::GyroMisalignment | Kind::AccelMisalignment) => 2.0,
        ParamKind::Imu(Kind::AccelBias) => 5.0,
        ParamKind::Imu(Kind::AccelScale) => 10.0,
        ParamKind::Table(TableKind::Swing | TableKind::EncoderScale) => 2.0,
        ParamKind::Table(TableKind::EncoderDelay) => 0.1,
    }
}

/// The first line of one calibration's result.
pub(super) fn head(s: &Setup, o: &Outcome) -> String {
    format!(
        "self-calibration: {} — {} positions, {:.2} h at {:.0} Hz; estimated in {:.2} s",
        s.sequence,
        s.move_starts_s.len() + 1,
        s.samples as f64 * s.config.h / 3600.0,
        1.0 / s.config.h,
        o.estimation_s
    )
}

/// The terminal table of one calibration (and the Monte Carlo's columns when there is one).
#[must_use]
pub fn table(s: &Setup, o: &Outcome, plan: &selfcal::Observability, mc: Option<&MonteCarlo>) -> String {
    estimates_table(
        format!("{}\n\n", head(s, o)),
        &o.estimate,
        Some(&o.all_truth(s)),
        plan,
        &s.move_starts_s,
        mc,
        s.table_note.as_deref(),
    )
}

/// When a parameter became observable (its 1σ under a tenth of its prior).
enum Seen {
    /// Before the first move.
    AtRest,
    /// After this many moves.
    AfterMove(usize),
    /// From this time, s (a log: no moves known).
    From(f64),
    /// Never.
    Never,
}

/// One parameter's line of a result table: its values in display units, its texts.
struct Cells {
    name: String,
    unit: &'static str,
    /// The truth, or "—".
    truth: String,
    estimate: f64,
    sigma: f64,
    /// (estimate − truth)/σ, or "—".
    z: String,
    /// σ/σ0.
    ratio: f64,
    /// "ok 2" or "MISS 2": the 1σ against its target.
    target: String,
    seen: Seen,
    /// The Monte Carlo's spread and 1σ/spread.
    monte_carlo: Option<(f64, f64)>,
}

/// The lines of a result table, one per parameter.
fn cells(
    e: &Estimate,
    truth: Option<&[f64]>,
    plan: &selfcal::Observability,
    move_starts_s: &[f64],
    mc: Option<&MonteCarlo>,
) -> Vec<Cells> {
    let (names, params, sigma) = (e.names(), e.all_params(), e.all_sigma());
    (0..names.len())
        .map(|k| {
            let (kind, name) = (ParamKind::of(k), names[k].clone());
            let (unit, per_si) = kind.unit();
            let seen = match plan.observable_from_s[k] {
                Some(t) if move_starts_s.is_empty() => Seen::From(t),
                Some(t) => match move_starts_s.iter().filter(|m| **m < t).count() {
                    0 => Seen::AtRest,
                    after => Seen::AfterMove(after),
                },
                None => Seen::Never,
            };
            let (truth, z) = match truth {
                Some(t) => (format!("{:.4}", t[k] * per_si), format!("{:.2}", (params[k] - t[k]) / sigma[k])),
                None => ("—".to_owned(), "—".to_owned()),
            };
            Cells {
                name,
                unit,
                truth,
                estimate: params[k] * per_si,
                sigma: sigma[k] * per_si,
                z,
                ratio: plan.ratio[k],
                target: format!("{}{}", if sigma[k] * per_si <= target(kind) { "ok " } else { "MISS " }, target(kind)),
                seen,
                monte_carlo: mc.map(|m| (m.spread[k] * per_si, m.reported_sigma[k] / m.spread[k])),
            }
        })
        .collect()
}

/// What the plan warns of, one line each: parameters not or weakly observable, aliased pairs.
fn warnings(plan: &selfcal::Observability) -> Vec<String> {
    let mut out = Vec::new();
    if !plan.unobservable.is_empty() {
        out.push(format!(
            "NOT OBSERVABLE from this sequence (1σ fell by less than half): {}",
            plan.unobservable.join(", ")
        ));
    }
    if !plan.weak.is_empty() {
        out.push(format!("WEAKLY OBSERVABLE (1σ still above a tenth of its prior): {}", plan.weak.join(", ")));
    }
    out.extend(plan.aliased.iter().map(|a| format!("ALIASED: {a}")));
    out
}

/// What the calibration cannot see, under every result.
const FRAME_NOTE: &str = "The IMU frame is the accelerometer triad's (K_a upper triangular): a rotation of both triads together is the IMU's\n\
     attitude, not an error (docs/selfcal.md).\n";

/// What the encoders let the table's states hold, or why there are none.
fn table_note(e: &Estimate, why_not: Option<&str>) -> String {
    match (&e.table, why_not) {
        (Some(_), _) => "The table's states are what its encoders can separate (docs/selfcal.md): <axis>.swing_* is the constant rotation\n\
             after that shaft, across it — its swing cone with the next axis's non-orthogonality, the next encoder's offset and\n\
             (last axis) the IMU's mounting folded in; the installation and the first encoder's offset are the base's attitude,\n\
             which nothing on the table sees.\n"
            .to_owned(),
        (None, Some(why)) => format!("The table's errors are not estimated: {why}.\n"),
        (None, None) => "The table's errors are not estimated: the log has no encoder file.\n".to_owned(),
    }
}

/// The Monte Carlo's line under a result.
fn monte_carlo_note(m: &MonteCarlo) -> String {
    format!(
        "Monte Carlo: {} IMUs in {:.1} s; 1σ/spread is the reported 1σ over the spread of the errors (1 = honest).\n",
        m.runs, m.wall_s
    )
}

/// A merged Monte Carlo's table: per parameter the spread of the errors, the mean reported 1σ and
/// their ratio, in display units.
#[must_use]
pub fn monte_carlo_table(names: &[String], m: &MonteCarlo) -> String {
    let mut out = format!(
        "Monte Carlo: {} IMUs merged from shards; 1σ/spread is the reported 1σ over the spread of the errors (1 = honest).\n\n  {:<22} {:>5} {:>12} {:>12} {:>10}\n",
        m.runs, "param", "unit", "MC spread", "mean 1σ", "1σ/spread"
    );
    for (k, name) in names.iter().enumerate() {
        let (unit, per_si) = ParamKind::of(k).unit();
        out.push_str(&format!(
            "  {name:<22} {unit:>5} {:>12.4} {:>12.4} {:>10.2}\n",
            m.spread[k] * per_si,
            m.reported_sigma[k] * per_si,
            m.reported_sigma[k] / m.spread[k]
        ));
    }
    out
}

/// The table of `e` (with the truth when it is known), under `head`.
#[must_use]
pub fn estimates_table(
    head: String,
    e: &Estimate,
    truth: Option<&[f64]>,
    plan: &selfcal::Observability,
    move_starts_s: &[f64],
    mc: Option<&MonteCarlo>,
    why_not: Option<&str>,
) -> String {
    let mut out = head;
    out.push_str(&format!(
        "  {:<8} {:>5} {:>11} {:>11} {:>9} {:>7} {:>8} {:>10}  {:<14}{}\n",
        "param",
        "unit",
        "true",
        "estimate",
        "1σ",
        "err/σ",
        "σ/σ0",
        "target",
        "observable",
        if mc.is_some() { "    MC spread  1σ/spread" } else { "" }
    ));
    for c in cells(e, truth, plan, move_starts_s, mc) {
        let seen = match c.seen {
            Seen::AtRest => "at rest".to_owned(),
            Seen::AfterMove(n) => format!("after move {n}"),
            Seen::From(t) => format!("from {t:.0} s"),
            Seen::Never => "NO".to_owned(),
        };
        // What the data cannot see gets no number (it would be the prior's, or noise).
        let (estimate, sigma) = match c.seen {
            Seen::Never => ("—".to_owned(), "—".to_owned()),
            _ => (format!("{:.4}", c.estimate), format!("{:.4}", c.sigma)),
        };
        out.push_str(&format!(
            "  {:<8} {:>5} {:>11} {:>11} {:>9} {:>7} {:>8.1e} {:>10}  {:<14}",
            c.name, c.unit, c.truth, estimate, sigma, c.z, c.ratio, c.target, seen
        ));
        if let Some((spread, ratio)) = c.monte_carlo {
            out.push_str(&format!(" {spread:>12.4} {ratio:>10.2}"));
        }
        out.push('\n');
    }
    let warnings = warnings(plan);
    if !warnings.is_empty() {
        out.push('\n');
    }
    for w in warnings {
        out.push_str(&w);
        out.push('\n');
    }
    out.push('\n');
    out.push_str(FRAME_NOTE);
    out.push_str(&table_note(e, why_not));
    if let Some(m) = mc {
        out.push_str(&monte_carlo_note(m));
    }
    out
}

/// The result of `e` as the recording's document shows it (markdown): `head` as prose, the table
/// narrow enough for the viewer's text panel at 1600×1000 (about 80 monospace characters: no
/// σ/σ0, which the plots show; the Monte Carlo's columns in a table of their own), the remarks as
/// prose.
#[must_use]
pub fn estimates_document(
    head: &str,
    e: &Estimate,
    truth: Option<&[f64]>,
    plan: &selfcal::Observability,
    move_starts_s: &[f64],
    mc: Option<&MonteCarlo>,
    why_not: Option<&str>,
) -> String {
    let cells = cells(e, truth, plan, move_starts_s, mc);
    let mut out = format!(
        "{head}\n\n```\n{:<6} {:>4} {:>9} {:>9} {:>9} {:>6}  {:<10}  {}\n",
        "param", "unit", "true", "estimate", "1σ", "err/σ", "target", "seen from"
    );
    for c in &cells {
        let seen = match c.seen {
            Seen::AtRest => "the start".to_owned(),
            Seen::AfterMove(n) => format!("move {n}"),
            Seen::From(t) => format!("{t:.0} s"),
            Seen::Never => "NEVER".to_owned(),
        };
        out.push_str(&format!(
            "{:<6} {:>4} {:>9} {:>9.4} {:>9.4} {:>6}  {:<10}  {seen}\n",
            c.name, c.unit, c.truth, c.estimate, c.sigma, c.z, c.target
        ));
    }
    out.push_str("```\n");
    for w in warnings(plan) {
        out.push_str(&format!("\n{w}\n"));
    }
    out.push_str(&format!("\n{FRAME_NOTE}{}", table_note(e, why_not)));
    if let Some(m) = mc {
        out.push_str(&format!(
            "\n{}\n```\n{:<6} {:>4} {:>10} {:>10}\n",
            monte_carlo_note(m),
            "param",
            "unit",
            "MC spread",
            "1σ/spread"
        ));
        for c in &cells {
            if let Some((spread, ratio)) = c.monte_carlo {
                out.push_str(&format!("{:<6} {:>4} {spread:>10.4} {ratio:>10.2}\n", c.name, c.unit));
            }
        }
        out.push_str("```\n");
    }
    out
}
