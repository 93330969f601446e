//! The recording keeps what a viewer can show (issue 33): a long high-rate series is recorded as
//! per-bucket envelopes (first, smallest, largest, last sample of every line), the full-rate
//! numbers go to `--export`, and the summary's RMS and peak are taken on every sample. A spike of
//! one sample — an encoder reading off by 0.06° for one 5-ms sample of a log set — must survive
//! into the saved recording, at its value, where a decimated recording (every n-th sample) drops it.

mod common;
use common::{csv_table, rinscope, scratch, stderr};
use std::path::{Path, PathBuf};

fn ok(o: &std::process::Output) {
    assert!(o.status.success(), "exit {:?}: {}", o.status.code(), stderr(o));
}

/// `rinscope ARGS... --save r.rrd --summary-json r.json --export-format csv --export tables` in
/// `dir`: its summary, the recording's plots and the export folder.
fn recorded(dir: &Path, args: &[&std::ffi::OsStr]) -> (serde_json::Value, Vec<rinscope::record::read::Plot>, PathBuf) {
    let (rrd, json, tables) = (dir.join("r.rrd"), dir.join("r.json"), dir.join("tables"));
    ok(&rinscope()
        .args(args)
        .arg("--save")
        .arg(&rrd)
        .arg("--summary-json")
        .arg(&json)
        .args(["--export-format", "csv", "--export"])
        .arg(&tables)
        .output()
        .expect("rinscope"));
    let summary = serde_json::from_slice(&std::fs::read(&json).expect("json")).expect("json");
    (summary, rinscope::record::read::plots(&rrd).expect("recording"), tables)
}

/// The RMS and the largest magnitude of `v`.
fn rms_peak(v: &[f64]) -> (f64, f64) {
    ((v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt(), v.iter().fold(0.0_f64, |m, x| m.max(x.abs())))
}

/// The export table of the table's attitude error about `axis` (its unit in its name).
fn error_table(dir: &Path, axis: &str) -> (PathBuf, String) {
    let file = std::fs::read_dir(dir)
        .expect("export dir")
        .map(|e| e.expect("entry").path())
        .find(|p| {
            let n = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            n.starts_with("attitude_error_") && n.ends_with(&format!("__{axis}.csv"))
        })
        .expect("the table's error export");
    let entity = file.file_stem().and_then(|s| s.to_str()).expect("name").replace("__", "/");
    (file, entity)
}

#[test]
fn a_one_sample_glitch_survives_in_the_recording_and_the_summary_counts_every_sample() {
    let dir = scratch("glitch");
    let log = dir.join("log");
    ok(&rinscope()
        .args(["export-log", "--scenario", "dual-axis-8-position", "--format", "csv", "--out"])
        .arg(&log)
        .output()
        .expect("export-log"));
    // One encoder sample at t = 10.000 s (the table dwells at its start: the readings are zero,
    // exact) reads 1e-3 rad (206″) too much on the inner axis.
    let path = log.join("encoders.csv");
    let text = std::fs::read_to_string(&path).expect("encoders");
    let mut glitched = 0;
    let edited: Vec<String> = text
        .lines()
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            if f[0].parse::<f64>().is_ok_and(|t| (t - 10.0).abs() < 1e-9) {
                glitched += 1;
                let inner: f64 = f[2].parse().expect("inner");
                format!("{},{},{}", f[0], f[1], inner + 1e-3)
            } else {
                l.to_owned()
            }
        })
        .collect();
    assert_eq!(glitched, 1, "one row at t = 10 s");
    std::fs::write(&path, edited.join("\n") + "\n").expect("write");

    let (summary, plots, tables) = recorded(&dir, &["replay".as_ref(), log.as_os_str()]);
    // The buckets a run of the log's length gets: 3000 over the log (`Bandwidth::series_hz`), the
    // length read from the export's time column (not from rinscope's estimate of it).
    let (_, clock) = csv_table(&error_table(&tables, "pitch").0);
    let length_s = clock.last().expect("rows")[0] - clock[0][0];
    let bucket_s = length_s / 3000.0;
    // Four rows a bucket at most (first, extremes, last) on every plot, whatever the log's length:
    // a recording sized for the viewer (a replay made 50 buckets a second before it knew its length).
    for line in plots.iter().flat_map(|p| p.series.iter()) {
        assert!(
            line.t.len() <= 4 * 3000 + 8,
            "{} ({}): {} rows over {length_s} s",
            line.entity,
            line.name,
            line.t.len()
        );
    }

    let mut spikes = 0;
    for axis in ["pitch", "roll", "heading"] {
        let (file, entity) = error_table(&tables, axis);
        let (header, rows) = csv_table(&file);
        let unit_per_arcsec = match entity.split('/').next().unwrap_or("") {
            "attitude_error_arcsec" => 1.0,
            "attitude_error_arcmin" => 1.0 / 60.0,
            "attitude_error_deg" => 1.0 / 3600.0,
            other => panic!("unit of {other}"),
        };
        let first = header.iter().position(|c| c != "t_s" && c != "t_file_s").expect("a line");
        let recorded: Vec<&rinscope::record::read::PlotSeries> =
            plots.iter().flat_map(|p| p.series.iter()).filter(|s| s.entity == entity).collect();
        assert_eq!(recorded.len(), header.len() - first, "{entity}: one recorded line per exported column");
        for (k, line) in recorded.iter().enumerate() {
            let column: Vec<(f64, f64)> = rows.iter().map(|r| (r[0], r[first + k])).collect();
            // The export is every attitude update: 100 Hz (two 200-Hz samples an update) over the log.
            let span = column.last().expect("rows").0 - column[0].0;
            assert!(column.len() as f64 > 0.99 * 100.0 * span && span > 600.0, "{} rows over {span} s", column.len());
            let finite = |v: &[f64]| v.iter().copied().filter(|x| x.is_finite()).collect::<Vec<f64>>();
            let all = finite(&column.iter().map(|c| c.1).collect::<Vec<_>>());
            let drawn = finite(&line.y);
            // Far fewer rows than samples; every drawn value is a sample's; the extremes are the same.
            assert!(line.t.len() * 10 < column.len(), "{entity}: {} rows for {} samples", line.t.len(), column.len());
            for v in &drawn {
                assert!(all.iter().any(|x| x.to_bits() == v.to_bits()), "{entity}: {v} is no sample's value");
            }
            let extremes =
                |v: &[f64]| v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(*x), b.max(*x)));
            // To 1e-9 of the plot's unit: rows closer than that are one row (a zero error's rounding
            // flicker, `same_row`; far under the smallest range a plot is framed at).
            let ((a, b), (c, d)) = (extremes(&drawn), extremes(&all));
            assert!(
                (a - c).abs() <= 1e-9 * c.abs().max(1.0) && (b - d).abs() <= 1e-9 * d.abs().max(1.0),
                "{entity} line {k} ({}): the envelope spans every sample: drawn [{a}, {b}], sampled [{c}, {d}]",
                line.name
            );
            // The glitch: one sample far off its neighbours, drawn at its value within one bucket
            // of its time (a single sample: every 20th would miss it 19 times in 20).
            let (i, peak) = column
                .iter()
                .enumerate()
                .max_by(|a, b| (a.1.1 - column[0].1).abs().total_cmp(&(b.1.1 - column[0].1).abs()))
                .map(|(i, c)| (i, c.1))
                .expect("samples");
            let near = (column[i - 1].1 - column[0].1).abs().max((column[i + 1].1 - column[0].1).abs());
            if (peak - column[0].1).abs() > 20.0 * near.max(1e-12) && (column[i].0 - 10.0).abs() < 0.05 {
                spikes += 1;
                let at = line.y.iter().position(|y| y.to_bits() == peak.to_bits()).expect("the spike is drawn");
                assert!(
                    (line.t[at] - column[i].0).abs() <= bucket_s,
                    "drawn at {} s, sampled at {} s",
                    line.t[at],
                    column[i].0
                );
            }
            // The summary's statistics are every sample's (its variants named as the lines are).
            let variant = if line.name.contains("nominal") { "nominal" } else { "compensated" };
            let stats = summary["attitude_error_arcsec"]
                .as_object()
                .and_then(|m| m.iter().find(|(name, _)| name.starts_with(variant)))
                .map(|(_, v)| &v[axis])
                .unwrap_or_else(|| panic!("summary of {variant}: {}", summary["attitude_error_arcsec"]));
            let (rms, peak_abs) = rms_peak(&all);
            let (rms, peak_abs) = (rms / unit_per_arcsec, peak_abs / unit_per_arcsec);
            let (s_rms, s_peak) =
                (stats["rms_arcsec"].as_f64().expect("rms"), stats["peak_arcsec"].as_f64().expect("peak"));
            assert!(
                (s_rms - rms).abs() <= 1e-9 * rms.max(1e-12),
                "{entity} {variant}: summary RMS {s_rms}, samples {rms}"
            );
            assert!(
                (s_peak - peak_abs).abs() <= 1e-9 * peak_abs.max(1e-12),
                "{entity} {variant}: peak {s_peak} vs {peak_abs}"
            );
        }
    }
    assert!(spikes >= 1, "the glitch shows as a one-sample spike on some line");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_run_exports_every_sample_its_summary_counts_and_records_their_extremes() {
    // jiang2017-calibration for 600 s (3000 buckets: 20 updates each): an INS with white sensor noise at 100 attitude updates a
    // second (two 200-Hz samples an update), the table's errors with white encoder noise. The
    // summary's INS statistics are every update's; the export must be every one of them, the
    // recording their envelope.
    let dir = scratch("run");
    let args = ["run", "--scenario", "jiang2017-calibration", "--duration-s", "600"].map(std::ffi::OsStr::new);
    let (summary, plots, tables) = recorded(&dir, &args);
    for axis in ["pitch", "roll", "heading"] {
        let entity = format!("ins/attitude_error_arcsec/{axis}");
        let (header, rows) = csv_table(&tables.join(format!("ins__attitude_error_arcsec__{axis}.csv")));
        assert!(rows.len() >= 100 * 600 - 2, "{entity}: {} exported rows, every update of 600 s at 100 Hz", rows.len());
        let k = header.iter().position(|c| c.starts_with("two_sample_p1")).expect("the algorithm's column");
        let all: Vec<f64> = rows.iter().map(|r| r[k]).filter(|x| x.is_finite()).collect();
        let stats = &summary["ins_attitude_error_arcsec"]["two-sample-p1"][axis];
        let (rms, peak) = rms_peak(&all);
        let (s_rms, s_peak) =
            (stats["rms_arcsec"].as_f64().expect("rms"), stats["peak_arcsec"].as_f64().expect("peak"));
        assert!((s_rms - rms).abs() <= 1e-9 * rms, "{entity}: summary RMS {s_rms}, every exported sample {rms}");
        assert!((s_peak - peak).abs() <= 1e-9 * peak, "{entity}: summary peak {s_peak}, every exported sample {peak}");
        let line = plots
            .iter()
            .flat_map(|p| p.series.iter())
            .find(|s| s.entity == entity && s.name.contains("p1"))
            .expect("the recorded line");
        let drawn = line.y.iter().fold(0.0_f64, |m, x| if x.is_finite() { m.max(x.abs()) } else { m });
        assert_eq!(drawn.to_bits(), peak.to_bits(), "{entity}: the recording draws the largest sample");
        assert!(line.t.len() * 4 < all.len(), "{entity}: {} rows drawn for {} samples", line.t.len(), all.len());
    }
    std::fs::remove_dir_all(&dir).ok();
}
