//! Bad PSINS SIMU files: each is one error naming the file, the line, the field and the value;
//! other layouts refuse a PSINS file and psins-imu refuses other files, saying what was expected.
//!
//! Every file is the valid text of `psins::imufile_text` (13 comment lines, a blank line, header
//! rows on lines 15-17, a blank line, data row k on line 18 + k) with one thing changed.

use crate::common::*;
use crate::psins::{imufile_text, input};
use rinscope::io::{
    Col, ColumnReader, ImuOptions, ImuReader, Layout, Location, LogError, ReadOptions, TimeUnit, read_psins_header,
};
use std::path::{Path, PathBuf};

/// The valid 6-column text (`seven`: with a dither, the 7-column form), as lines.
fn valid_lines(seven: bool) -> Vec<String> {
    let jitter = move |k: usize| if seven && k.is_multiple_of(3) { 2.5e-6 } else { 0.0 };
    imufile_text(&input(jitter)).lines().map(str::to_owned).collect()
}

/// Writes `lines` (each ended by '\n') to `dir/name`.
fn write_lines(dir: &Path, name: &str, lines: &[String]) -> PathBuf {
    write_text(dir, name, &(lines.join("\n") + "\n"))
}

/// Replaces field `k` (from 0) of line `line` (from 1).
fn with_field(lines: &[String], line: usize, k: usize, value: &str) -> Vec<String> {
    let mut out = lines.to_vec();
    let mut fields: Vec<&str> = lines[line - 1].split(' ').collect();
    fields[k] = value;
    out[line - 1] = fields.join(" ");
    out
}

/// The first error reading `path` as psins-imu; its message must start with the file and hold
/// every piece of `expected`.
fn error(path: &Path, expected: &[&str]) -> LogError {
    let e = match ImuReader::open(path, &ImuOptions::new(Layout::PsinsImu)) {
        Err(e) => e,
        Ok(reader) => reader.filter_map(Result::err).next().expect("an error"),
    };
    let msg = e.to_string();
    assert!(msg.starts_with(&path.display().to_string()), "{msg}");
    for piece in expected {
        assert!(msg.contains(piece), "{piece:?} not in: {msg}");
    }
    e
}

#[test]
fn counts_that_are_not_integers() {
    let dir = scratch("psins_bad_counts");
    let lines = valid_lines(false);
    // Data row 3 (line 21), field 3 (g_z).
    let path = write_lines(&dir, "frac.imu", &with_field(&lines, 21, 2, "12.5"));
    let e = error(&path, &["data row 3 (line 21)", "g_z (field 3)", "\"12.5\"", "not an integer"]);
    assert!(matches!(e, LogError::BadValue { at: Location { row: 3, line: Some(21) }, .. }), "{e:?}");
    let path = write_lines(&dir, "nan.imu", &with_field(&lines, 19, 5, "NaN"));
    let e = error(&path, &["data row 1 (line 19)", "a_z (field 6)", "NaN"]);
    assert!(matches!(e, LogError::NonFinite { .. }), "{e:?}");
    let path = write_lines(&dir, "word.imu", &with_field(&lines, 30, 0, "12x"));
    let e = error(&path, &["data row 12 (line 30)", "g_x (field 1)", "\"12x\"", "not a number"]);
    assert!(matches!(e, LogError::NonNumeric { .. }), "{e:?}");
    // The dither column is a count of µs too.
    let lines = valid_lines(true);
    let path = write_lines(&dir, "dt.imu", &with_field(&lines, 22, 6, "0.5"));
    error(&path, &["data row 4 (line 22)", "dt (field 7)", "\"0.5\""]);
    // An integral number is a count, as MATLAB's load reads it.
    let lines = valid_lines(false);
    let path = write_lines(
        &dir,
        "float.imu",
        &with_field(&lines, 19, 0, &format!("{}.0", lines[18].split(' ').next().unwrap())),
    );
    assert!(ImuReader::open(&path, &ImuOptions::new(Layout::PsinsImu)).unwrap().all(|e| e.is_ok()));
}

#[test]
fn rows_of_the_wrong_width() {
    let dir = scratch("psins_bad_width");
    let lines = valid_lines(false);
    let mut five = lines.clone();
    five[24] = five[24].rsplit_once(' ').unwrap().0.to_owned();
    let path = write_lines(&dir, "five.imu", &five);
    let e = error(&path, &["data row 7 (line 25)", "5 fields", "has 6"]);
    assert!(matches!(e, LogError::FieldCount { expected: 6, found: 5, truncated_last_line: false, .. }), "{e:?}");
    let lines = valid_lines(true);
    let mut eight = lines.clone();
    eight[19] += " 3";
    let path = write_lines(&dir, "eight.imu", &eight);
    let e = error(&path, &["data row 2 (line 20)", "8 fields", "has 7"]);
    assert!(matches!(e, LogError::FieldCount { expected: 7, found: 8, .. }), "{e:?}");
    // A 7-column data row under a 6-column header.
    let mut six = valid_lines(false);
    six[18] += " 0";
    error(&write_lines(&dir, "seven_under_six.imu", &six), &["data row 1 (line 19)", "7 fields", "has 6"]);
}

#[test]
fn header_rows_missing_or_of_the_wrong_width() {
    let dir = scratch("psins_bad_header");
    let lines = valid_lines(false);
    // Only two header rows.
    let path = write_lines(&dir, "two.imu", &lines[..16]);
    let e = error(&path, &["line 16", "after 2 of the 3 PSINS header rows"]);
    assert!(matches!(e, LogError::Corrupt { .. }), "{e:?}");
    // Header row 2 with 5 numbers; header row 1 with 5 (neither 6 nor 7) or 8.
    let mut short = lines.clone();
    short[15] = short[15].rsplit_once(' ').unwrap().0.to_owned();
    error(&write_lines(&dir, "row2.imu", &short), &["line 16", "5 fields where the first PSINS header row has 6"]);
    let mut short = lines.clone();
    short[14] = short[14].rsplit_once(' ').unwrap().0.to_owned();
    let e = error(&write_lines(&dir, "row1.imu", &short), &["line 15", "5 fields", "7 with the dither column"]);
    assert!(matches!(e, LogError::FieldCount { at: Location { row: 0, line: Some(15) }, .. }), "{e:?}");
    let mut long = lines.clone();
    long[14] += " 0 0";
    error(&write_lines(&dir, "row1_8.imu", &long), &["line 15", "8 fields"]);
    // read_psins_header says the same.
    assert!(read_psins_header(&path).unwrap_err().to_string().contains("after 2 of the 3"));
}

#[test]
fn header_values() {
    let dir = scratch("psins_bad_header_values");
    let lines = valid_lines(false);
    for (name, line, k, value, expected) in [
        ("ts0.imu", 16, 4, "0.00000000", ["sampling-interval(ms) (header row 2, field 5)", "at least 0.01 ms"]),
        ("ts_neg.imu", 16, 4, "-10.00000000", ["sampling-interval(ms)", "at least 0.01 ms"]),
        // Issue 31: every header number passes the samples' rule, said short (no 300 digits).
        (
            "pitch.imu",
            15,
            0,
            "1e300",
            ["pitch0(deg) (header row 1, field 1)", "1e300 deg is out of range for a pitch: it must be within ±90 deg"],
        ),
        ("ve.imu", 15, 3, "1e300", ["VE0(m/s) (header row 1, field 4)", "1e300 m/s is out of range for a velocity"]),
        ("h.imu", 16, 2, "-1e300", ["height0(m)", "-1e300 m is out of range for a height"]),
        ("t0.imu", 16, 3, "1e300", ["t0(s)", "a time on the file's clock"]),
        ("gf_big.imu", 17, 0, "1e300", ["gf_x", "1e300 arcsec is out of range"]),
        ("g.imu", 16, 5, "9.600000", ["g(m/s^2) (header row 2, field 6)", "9.7..9.9"]),
        ("g_mps2.imu", 16, 5, "98.066500", ["g(m/s^2)", "9.7..9.9"]),
        ("lat.imu", 16, 0, "134.24604800", ["latitude0(deg) (header row 2, field 1)", "±90 deg"]),
        ("gf.imu", 17, 1, "0.000000", ["gf_y (header row 3, field 2)", "zero scale factor"]),
        ("nan.imu", 15, 2, "NaN", ["yaw0(deg) (header row 1, field 3)", "NaN"]),
        ("word.imu", 17, 3, "one", ["af_x (header row 3, field 4)", "not a number"]),
    ] {
        let path = write_lines(&dir, name, &with_field(&lines, line, k, value));
        let line_text = format!("line {line}, column");
        // NaN is named bare ("the value is NaN"), the others quoted.
        let quoted = if value == "NaN" { value.to_owned() } else { format!("{value:?}") };
        let e = error(&path, &[&line_text, &quoted, expected[0], expected[1]]);
        assert!(e.to_string().len() < 400, "short: {e}");
        assert!(
            matches!(
                &e,
                LogError::BadValue { at: Location { row: 0, .. }, .. }
                    | LogError::NonFinite { .. }
                    | LogError::NonNumeric { .. }
            ),
            "{e:?}"
        );
        let header_error = read_psins_header(&path).unwrap_err().to_string();
        assert_eq!(header_error, e.to_string());
    }
}

#[test]
fn truncated_last_line() {
    let dir = scratch("psins_truncated");
    let text = valid_lines(false).join("\n");
    // Cut inside the 4th number of the last row: 4 fields, no line end.
    let last_start = text.rfind('\n').unwrap() + 1;
    let fourth = last_start + text[last_start..].match_indices(' ').nth(2).unwrap().0 + 2;
    let path = write_text(&dir, "cut.imu", &text[..fourth]);
    let e = error(&path, &["data row 500 (line 518)", "4 fields", "truncated"]);
    assert!(matches!(e, LogError::FieldCount { found: 4, truncated_last_line: true, .. }), "{e:?}");
    // Cut inside the 6th number: every field is there, but the line has no end (issue 20: a count
    // cut short is still a whole number, so only the missing line end tells).
    let sixth = text.len() - 1;
    let path = write_text(&dir, "cut6.imu", &text[..sixth]);
    let e = error(&path, &["data row 500 (line 518)", "no line end", "truncated"]);
    assert!(matches!(e, LogError::TruncatedLine { .. }), "{e:?}");
    // The same line with its end reads.
    let path = write_text(&dir, "whole.imu", &format!("{text}\n"));
    assert_eq!(samples(ImuReader::open(&path, &ImuOptions::new(Layout::PsinsImu)).unwrap()).len(), 500);
}

#[test]
fn other_layouts_refuse_a_psins_file_and_psins_imu_refuses_others() {
    let dir = scratch("psins_layouts");
    let psins = write_lines(&dir, "trj.imu", &valid_lines(false));
    for layout in [Layout::Rinscope, Layout::Psins, Layout::KfGins, Layout::Npy7 { time: TimeUnit::Seconds }] {
        let mut opts = ImuOptions::new(layout.clone());
        opts.frame = Some(rinscope::io::Frame::Named("rfu".into()));
        let e = ImuReader::open(&psins, &opts).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("PSINS .imu file") && msg.contains("layout = \"psins-imu\"") && msg.contains(layout.name()),
            "{msg}"
        );
    }
    // A .imu of whitespace-separated numbers (KF-GINS style) asked to be psins-imu.
    let kf = write_text(
        &dir,
        "kf.imu",
        "345600.00 1e-5 2e-5 3e-5 0.01 0.02 0.098\n345600.01 1e-5 2e-5 3e-5 0.01 0.02 0.098\n",
    );
    error(
        &kf,
        &["not a PSINS SIMU file", "line 1 is \"345600.00 1e-5", "% PSINS-format SIMU log file. (DO NOT MODIFY!)"],
    );
    // It stays a text table for the other layouts.
    assert!(ImuReader::open(&kf, &ImuOptions::new(Layout::KfGins)).is_ok());
    // A first line naming PSINS and SIMU that is not a % comment (MATLAB's load would refuse it).
    let mut lines = valid_lines(false);
    lines[0] = "PSINS-format SIMU log file".into();
    error(
        &write_lines(&dir, "nopercent.imu", &lines),
        &["not a PSINS SIMU file", "line 1 is \"PSINS-format SIMU log file\""],
    );
    lines[0] = "% PSINS log file".into();
    let path = write_lines(&dir, "nosimu.imu", &lines);
    error(&path, &["line 1 is \"% PSINS log file\""]);
    assert!(read_psins_header(&path).unwrap_err().to_string().contains("not a PSINS SIMU file"));
    let empty = write_text(&dir, "empty.imu", "");
    assert!(read_psins_header(&empty).unwrap_err().to_string().contains("the file is empty"));
    // A binary file.
    let npy = dir.join("a.npy");
    write_npy(&npy, &[vec![1.0; 7]], "<f8");
    error(&npy, &["layout psins-imu reads PSINS SIMU text files", "NumPy"]);
}

#[test]
fn bit_flips_never_panic() {
    let dir = scratch("psins_flips");
    let bytes = (valid_lines(true)[..40].join("\n") + "\n").into_bytes();
    let bad = dir.join("bad.imu");
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for _ in 0..300 {
        let mut g = bytes.clone();
        for _ in 0..1 + next() % 3 {
            let i = (next() % g.len() as u64) as usize;
            g[i] = next() as u8;
        }
        std::fs::write(&bad, &g).unwrap();
        let _ = ImuReader::open(&bad, &ImuOptions::new(Layout::PsinsImu)).map(|r| r.count());
        let _ = ColumnReader::open(&bad, &(0..7).map(Col::Index).collect::<Vec<_>>(), &ReadOptions::default()).map(
            |mut r| {
                let mut row = [0.0; 7];
                while let Ok(true) = r.next_row(&mut row) {}
            },
        );
    }
}
