//! The one number rule at clap's parser (issue 31): every numeric option of every command is
//! parsed here, held to its physical range by [`validity::check_number`] (the rule a log's samples
//! pass), and said short.

use crate::io::validity::{Range, check_number};
use crate::scenario;

// The one number rule at the parser (issue 31): every numeric option is parsed by [`number`] or
// [`count`], which hold it to its physical range with the samples' rule
// ([`validity::check_number`]) and accept a negative number as a value (`--duration-s -10` is
// answered "-10 s is out of range ...", not "unexpected argument '-1'"). clap exits 2 with
// `invalid value '-10' for '--duration-s <DURATION_S>': ...`, naming the option. The ranges, and
// why:

/// A simulated duration, s: the rule of `simulation.duration_s` ([`scenario::DURATION`]).
pub(super) const DURATION_S: Range = scenario::DURATION;
/// The ranges the commands' owners hold their requests to (the parser answers first, with the
/// same words; Python's calls meet the owners' checks).
pub(super) use crate::app::allan::CI_SIGMA;
pub(super) use crate::app::live::SPEED;
pub(super) use crate::app::modulation::HOURS;
pub(super) use crate::app::selfcal::NAVIGATE_HOURS;
/// `replay --align-s`: > 0 and at most a day (a manifest's `initial.alignment_s`).
pub(super) const ALIGN_S: Range = Range::positive(86_400.0, "s", "an alignment time");
/// `budget --sample-s`: > 0, at most a day.
pub(super) const SAMPLE_S: Range = Range::positive(86_400.0, "s", "a sampling interval");
/// `design --angles-deg`: a move of at most two turns.
pub(super) const MOVE_DEG: Range = Range::positive(720.0, "deg", "a move");
/// `design --rates-deg-per-s`: a table's rate, at most 1000°/s.
pub(super) const RATE_DEG_PER_S: Range = Range::positive(1000.0, "deg/s", "a rate");
/// `design --dwells-s`: 0 (no dwell) to a day.
pub(super) const DWELL_S: Range = Range::closed(0.0, 86_400.0, "s", "a dwell");
/// `design --max-wrap-deg`: up to ten turns.
pub(super) const WRAP_DEG: Range = Range::positive(3600.0, "deg", "a cable wrap");
/// One of `--attitude-deg` / `--reference-attitude-deg`: within ±360° (each angle's own bound,
/// pitch ±90°, roll ±180°, is the manifest's check, which these options feed).
pub(super) const ANGLE_DEG: Range = Range::symmetric(360.0, "deg", "an attitude angle");
/// One of `--position LAT LON HEIGHT`: within ±100 000 (the widest of the three, the height in m;
/// each one's own bound is the manifest's check, which this option feeds).
pub(super) const POSITION_PART: Range =
    Range::symmetric(100_000.0, "", "a latitude (deg), longitude (deg) or height (m)");
/// `--eta-measured-sigma-arcsec`: > 0 and at most 3600″ (`calib`'s bound: a 1° measurement tells
/// the filter nothing).
pub(super) const ETA_SIGMA_ARCSEC: Range = Range::positive(3600.0, "arcsec", "a measurement's 1σ");

/// Parses `text` as a number in `range` (the one number rule).
pub(super) fn number(text: &str, range: &Range) -> Result<f64, String> {
    let v: f64 = text.trim().parse().map_err(|_| format!("{} is not a number", cut(text)))?;
    check_number(v, range)
}

/// `--duration-s`.
pub(super) fn duration_s(text: &str) -> Result<f64, String> {
    number(text, &DURATION_S)
}

/// Parses `text` as a whole number in `min..=max` (`unit` names what it counts).
pub(super) fn count(text: &str, min: u64, max: u64, unit: &str) -> Result<u64, String> {
    let t = text.trim();
    let refuse = || format!("{}: must be a whole number of {unit}, {min} ..= {max}", cut(t));
    match t.parse::<i128>() {
        Ok(n) if n >= i128::from(min) && n <= i128::from(max) => u64::try_from(n).map_err(|_| refuse()),
        _ => Err(refuse()),
    }
}

/// A TCP port, 1 ..= 65535.
pub(super) fn port(text: &str) -> Result<u16, String> {
    count(text, 1, 65_535, "port").map(|n| n as u16)
}

/// A user's text cut for a message (40 characters).
pub(super) fn cut(text: &str) -> String {
    let mut out: String = text.chars().take(40).collect();
    if text.chars().count() > 40 {
        out.push('…');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::Cli;
    use crate::io::validity;
    use clap::{CommandFactory as _, Parser as _};

    /// Every option of every (sub)command, with its command line's words.
    fn walk(cmd: &clap::Command, path: &mut Vec<String>, out: &mut Vec<(Vec<String>, clap::Arg)>) {
        for a in cmd.get_arguments() {
            out.push((path.clone(), a.clone()));
        }
        for sub in cmd.get_subcommands() {
            path.push(sub.get_name().to_owned());
            walk(sub, path, out);
            path.pop();
        }
    }

    #[test]
    fn every_numeric_option_takes_a_negative_number_to_its_range_check() {
        // Issue 31: `run --duration-s -10` said "unexpected argument '-1'".
        use std::any::TypeId;
        let numeric =
            [TypeId::of::<f64>(), TypeId::of::<u64>(), TypeId::of::<usize>(), TypeId::of::<u32>(), TypeId::of::<u16>()];
        let mut all = Vec::new();
        walk(&Cli::command(), &mut Vec::new(), &mut all);
        let mut checked = 0;
        for (path, arg) in all {
            let Some(long) = arg.get_long() else { continue };
            if !numeric.iter().any(|t| arg.get_value_parser().type_id() == *t) {
                continue;
            }
            assert!(arg.is_allow_negative_numbers_set(), "{path:?} --{long}: allow_negative_numbers");
            let values = arg.get_num_args().map_or(1, |r| r.min_values().max(1));
            let mut line = vec!["rinscope".to_owned()];
            line.extend(path.iter().cloned());
            line.push(format!("--{long}"));
            line.extend(std::iter::repeat_n("-1e300".to_owned(), values));
            let e = match Cli::try_parse_from(&line) {
                Ok(_) => panic!("{line:?}: -1e300 accepted"),
                Err(e) => e,
            };
            assert_eq!(e.kind(), clap::error::ErrorKind::ValueValidation, "{line:?}: {e}");
            let text = e.to_string();
            assert!(
                text.contains(&format!("--{long}")) && text.contains("-1e300") && text.len() < 400,
                "{line:?}: {text}"
            );
            checked += 1;
        }
        assert!(checked >= 25, "{checked} numeric options seen");
    }

    #[test]
    fn a_number_is_held_to_its_range_and_said_short() {
        assert_eq!(number("1e-3", &DURATION_S), Ok(1e-3));
        let e = number("1e308", &validity::IMU_RATE_HZ).expect_err("1e308 Hz");
        assert!(e.starts_with("1e308 Hz") && e.len() < 120, "{e}");
        assert!(
            number(&"9".repeat(400), &DURATION_S).expect_err("long").len() < 200,
            "1e400 parses as inf: said short"
        );
        assert!(number("abc", &DURATION_S).expect_err("text").contains("not a number"));
        assert_eq!(count("7", 1, 10, "runs"), Ok(7));
        assert!(
            count("-7", 1, 10, "runs")
                .expect_err("negative")
                .starts_with("-7: must be a whole number of runs, 1 ..= 10")
        );
        assert!(count("0", 1, 10, "runs").is_err() && count("1.5", 1, 10, "runs").is_err());
    }
}
