//! The commands on recorded data: `export-log` and `replay` (`calibrate --log` is `calibrate`'s).

use std::path::PathBuf;

use super::commands::print_saved;
use super::{ExportLogArgs, Failure, ReplayArgs};
use crate::app::export_log::{LogFormat, export_log as write_log_set};
use crate::app::outputs::read_small_file;
use crate::app::replay::{ReplayRequest, execute};
use crate::app::terminate::stop_flag;
use crate::scenario::logset::{self, RawImuFile, RawInitial, RawLogInfo, RawManifest, RawReference, RawTable};
use crate::scenario::presets;

/// `rinscope export-log`.
pub(super) fn export_log(args: &ExportLogArgs) -> Result<(), Failure> {
    let params = args.source.load(presets::DEFAULT_SCENARIO)?;
    let format = LogFormat::parse(&args.format).map_err(|e| Failure::input(format!("--format {e}")))?;
    let stop = stop_flag();
    let written = write_log_set(&params, &args.out, format, args.no_initial_attitude, &stop).map_err(|e| match e {
        crate::app::export_log::ExportError::Interrupted => Failure::interrupted(format!("export-log: {e}")),
        crate::app::export_log::ExportError::Write(_) => Failure::run(format!("export-log: {e}")),
        other => Failure::input(format!("export-log: {other}")),
    })?;
    outln!(
        "log set {}: {} IMU samples of {} ({:.1} s at {} Hz), encoders, reference attitude, table.toml, log.toml ({:.2} MB)",
        written.dir.display(),
        written.samples,
        params.meta.name,
        params.duration_s,
        params.step_hz,
        written.bytes as f64 / 1e6
    );
    outln!("replay it with:  rinscope replay {}", written.dir.display());
    Ok(())
}

fn triple(v: Option<&Vec<f64>>) -> Option<[f64; 3]> {
    match v {
        Some(v) if v.len() == 3 => Some([v[0], v[1], v[2]]),
        _ => None,
    }
}

/// The command line's start, span and reference over a manifest (they win over its keys).
fn apply_overrides(raw: &mut RawManifest, args: &ReplayArgs) {
    let i = &mut raw.initial;
    if let Some(a) = triple(args.attitude_deg.as_ref()) {
        *i = RawInitial { body_attitude_deg: Some(a), ..i.clone() };
        i.imu_quaternion_wxyz = None;
        i.alignment_s = None;
    }
    if let Some(s) = args.align_s {
        i.alignment_s = Some(s);
        i.imu_quaternion_wxyz = None;
        i.body_attitude_deg = None;
    }
    if let Some(v) = triple(args.velocity_enu_mps.as_ref()) {
        i.velocity_enu_mps = Some(v);
    }
    if let Some(p) = triple(args.position.as_ref()) {
        i.position = Some(p);
    }
    if let Some(a) = triple(args.reference_attitude_deg.as_ref()) {
        raw.reference =
            Some(RawReference { source: Some("--reference-attitude-deg".into()), file: None, attitude_deg: Some(a) });
    }
    if args.from.is_some() {
        raw.log.from_s = args.from;
    }
    if args.to.is_some() {
        raw.log.to_s = args.to;
    }
}

/// The log set of `args`: a folder with a manifest, or one IMU file described by the flags.
fn load_log(args: &ReplayArgs) -> Result<logset::LogSet, Failure> {
    if let Some(dir) = &args.dir {
        return Ok(logset::load_overridden(dir, |raw| apply_overrides(raw, args))?);
    }
    let Some(imu) = &args.imu else {
        return Err(Failure::input("replay: give a log set's folder, or --imu FILE"));
    };
    let file = std::path::absolute(imu).unwrap_or_else(|_| imu.clone());
    let layout = match &args.imu_layout {
        Some(l) => l.clone(),
        None => crate::io::guess_layout(&file).map_err(|e| Failure::input(format!("replay: {e}")))?.to_owned(),
    };
    let mut manifest = RawManifest {
        log: RawLogInfo {
            name: imu
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("replay")
                .chars()
                .map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' })
                .collect(),
            description: match &args.table {
                Some(t) => format!("`{}` replayed with the table {}", imu.display(), t.display()),
                None => format!("`{}` replayed as a strapdown IMU", imu.display()),
            },
            table: args.table.as_ref().map_or_else(|| "table.toml".into(), |t| t.display().to_string()),
            seed: None,
            from_s: None,
            to_s: None,
        },
        imu: RawImuFile {
            file: file.display().to_string(),
            layout,
            kind: args.imu_kind.clone(),
            rate_hz: args.rate_hz,
            frame: args.imu_frame.clone().map(logset::RawFrame::Named),
            time: None,
            topic: None,
            columns: None,
            gap_policy: "refuse".into(),
            gap_factor: 3.0,
        },
        encoders: args.encoders.as_ref().map(|e| logset::RawEncoderFile {
            file: std::path::absolute(e).unwrap_or_else(|_| e.clone()).display().to_string(),
            latch_delay_ms: 0.0,
            gap_policy: "interpolate".into(),
        }),
        reference: None,
        initial: RawInitial::default(),
    };
    apply_overrides(&mut manifest, args);
    let (raw_table, table_origin) = match &args.table {
        Some(t) => logset::read_table(t)?,
        None => (RawTable::strapdown(), "(no --table: a strapdown IMU)".to_owned()),
    };
    let cwd = PathBuf::from(".");
    Ok(logset::validate_manifest(&cwd, &manifest, "the command line (--imu ...)", &raw_table, &table_origin)?)
}

/// `rinscope replay`.
pub(super) fn replay(args: &ReplayArgs) -> Result<(), Failure> {
    let log = load_log(args)?;
    let compensation = match &args.compensation {
        None => None,
        Some(path) => Some((read_small_file(path, "--compensation")?, path.display().to_string())),
    };
    let request = ReplayRequest {
        log,
        compensation,
        recording: args.sinks.recording()?,
        summary_json: args.summary_json.clone(),
    };
    let bar = std::io::IsTerminal::is_terminal(&std::io::stderr()).then(|| {
        let bar = indicatif::ProgressBar::new_spinner();
        bar.enable_steady_tick(std::time::Duration::from_millis(200));
        bar.set_message("opening the log");
        bar
    });
    let report = execute(&request, &stop_flag(), bar.as_ref());
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let report = report?;
    out!("{}", report.summary.text());
    print_saved(&report.saved);
    if report.summary.interrupted {
        return Err(Failure::interrupted("the recording is complete up to that moment"));
    }
    Ok(())
}
