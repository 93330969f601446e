//! `rinscope export-log`: a simulated scenario written as a real system would log it — the IMU's
//! measured increments (pre-roll included), the encoder readings and the true body attitude at every
//! sample instant, the table description and the manifest (docs/logs.md). Every scenario is thereby
//! an example log set, and `replay` of it reproduces the in-loop run.
//!
//! The folder is written as `OUT.partial/` and renamed onto `OUT` when complete: a log set is never
//! half there, and an existing `OUT` is never touched.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use crate::ins::InsParams;
use crate::io::TableWriter;
use crate::math::timeline::Timeline;
use crate::scenario::Params;
use crate::scenario::logset::{
    MANIFEST, RawEncoderFile, RawFrame, RawImuFile, RawInitial, RawLogInfo, RawManifest, RawReference, RawTable,
};
use crate::sim::encoder_readings;

/// The file formats a log set can be written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LogFormat {
    /// CSV with a header (units in the column names).
    Csv,
    /// NumPy .npy (N × 7 `[t, dθ, dv]` for the IMU; columns in header order for the others).
    Npy,
    /// Parquet.
    Parquet,
}

impl LogFormat {
    /// Parses "csv", "npy" or "parquet".
    pub fn parse(text: &str) -> Result<Self, String> {
        match text {
            "csv" => Ok(Self::Csv),
            "npy" => Ok(Self::Npy),
            "parquet" => Ok(Self::Parquet),
            other => Err(format!("\"{other}\" is not a log format; use csv, npy or parquet")),
        }
    }

    fn extension(self) -> &'static str {
        match self {
            Self::Csv => "csv",
            Self::Npy => "npy",
            Self::Parquet => "parquet",
        }
    }
}

/// What was written.
#[derive(Debug, Clone)]
pub struct ExportedLog {
    /// The folder.
    pub dir: PathBuf,
    /// IMU samples (pre-roll included).
    pub samples: u64,
    /// Bytes of all files.
    pub bytes: u64,
}

/// Why a log set could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The target exists.
    #[error("{0} exists; export-log writes a new folder (choose another --out or remove it)")]
    Exists(String),
    /// The folder's partial cannot be used (another export is writing it, a symlink, a file).
    #[error("{0}")]
    Refused(String),
    /// A file could not be written.
    #[error("{0}")]
    Write(String),
    /// Stopped by the user.
    #[error("nothing was kept")]
    Interrupted,
}

fn write_err(e: impl std::fmt::Display) -> ExportError {
    ExportError::Write(e.to_string())
}

/// Writes the log set of `params` into the new folder `out`.
pub fn export_log(
    params: &Params,
    out: &Path,
    format: LogFormat,
    aligned: bool,
    stop: &AtomicBool,
) -> Result<ExportedLog, ExportError> {
    if out.exists() {
        return Err(ExportError::Exists(out.display().to_string()));
    }
    let partial = crate::io::files::partial_path(out);
    if let Some(parent) = partial.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).map_err(|e| ExportError::Write(format!("{}: {e}", parent.display())))?;
    }
    // Locked while written: a second export of the same folder is refused, one that a killed
    // export left is taken over.
    let _lock = crate::io::files::create_partial_dir(out).map_err(|e| match e {
        crate::io::files::OutputError::Io { .. } => ExportError::Write(e.to_string()),
        other => ExportError::Refused(other.to_string()),
    })?;
    crate::io::files::unfinished_dir(&partial);
    let result = write_files(params, &partial, format, aligned, stop);
    crate::io::files::finished_dir(&partial);
    match result {
        Ok(samples) => {
            std::fs::rename(&partial, out)
                .map_err(|e| ExportError::Write(format!("{} → {}: {e}", partial.display(), out.display())))?;
            let bytes = std::fs::read_dir(out)
                .map(|d| d.flatten().filter_map(|e| e.metadata().ok()).map(|m| m.len()).sum())
                .unwrap_or(0);
            Ok(ExportedLog { dir: out.to_path_buf(), samples, bytes })
        }
        Err(e) => {
            std::fs::remove_dir_all(&partial).ok();
            Err(e)
        }
    }
}

/// The IMU the log records: the scenario's `[imu]`, or an ideal one at the simulation rate.
fn logged_imu(params: &Params) -> InsParams {
    params.ins.clone().unwrap_or_else(|| InsParams::ideal(params.step_hz, crate::ins::coning::Algorithm::TwoSampleP1))
}

fn write_files(
    params: &Params,
    dir: &Path,
    format: LogFormat,
    aligned: bool,
    stop: &AtomicBool,
) -> Result<u64, ExportError> {
    let ext = format.extension();
    let ins_params = logged_imu(params);
    let mut ins = crate::ins::pipeline::InsRun::new(&ins_params, params.site, params.meta.seed, params.table_model());
    let model = params.table_model();
    let axis_names: Vec<String> = params.table.chain.axes().iter().map(|a| a.name.clone()).collect();

    let imu_path = dir.join(format!("imu.{ext}"));
    let mut imu = TableWriter::create(
        &imu_path,
        &["t_s", "dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad", "dv_x_mps", "dv_y_mps", "dv_z_mps"],
    )
    .map_err(write_err)?;
    let encoder_columns: Vec<String> =
        std::iter::once("t_s".to_owned()).chain(axis_names.iter().map(|n| format!("{n}_rad"))).collect();
    let encoder_refs: Vec<&str> = encoder_columns.iter().map(String::as_str).collect();
    let mut encoders = TableWriter::create(dir.join(format!("encoders.{ext}")), &encoder_refs).map_err(write_err)?;
    let mut reference =
        TableWriter::create(dir.join(format!("reference.{ext}")), &["t_s", "pitch_rad", "roll_rad", "heading_rad"])
            .map_err(write_err)?;

    let n_axes = axis_names.len();
    let mut row = |t: f64, g: nalgebra::Vector3<f64>, a: nalgebra::Vector3<f64>| -> Result<(), ExportError> {
        imu.write_row(&[t, g.x, g.y, g.z, a.x, a.y, a.z]).map_err(write_err)?;
        // The computer pairs each IMU sample with the encoders latched for the same instant.
        let enc = encoder_readings(&model, t);
        let mut e = Vec::with_capacity(1 + n_axes);
        e.push(t);
        e.extend_from_slice(&enc[..n_axes]);
        encoders.write_row(&e).map_err(write_err)?;
        let (att, _) = model.vehicle.state(t);
        reference.write_row(&[t, att.pitch_rad, att.roll_rad, att.heading_rad]).map_err(write_err)
    };
    let mut samples = 0u64;
    for (t, g, a) in ins.pre_roll().to_vec() {
        row(t, g, a)?;
        samples += 1;
    }
    let timeline = Timeline::new(params.duration_s, params.step_hz);
    for k in 1..=timeline.intervals() {
        if k % 65_536 == 0 && stop.load(Ordering::Relaxed) {
            return Err(ExportError::Interrupted);
        }
        let (t, g, a) = ins.next_measurement();
        row(t, g, a)?;
        samples += 1;
    }
    imu.finish().map_err(write_err)?;
    encoders.finish().map_err(write_err)?;
    reference.finish().map_err(write_err)?;

    let r = &params.resolved;
    let table = RawTable {
        recording: r.recording.clone(),
        site: r.site.clone(),
        turntable: Some(r.turntable.clone()),
        compensation: r.compensation.clone(),
        imu: Some(r.imu.clone().unwrap_or_default()),
        navigation: r.navigation.clone(),
        calibration: r.calibration.clone(),
    };
    let q = ins.start_attitude();
    let q = q.quaternion();
    let layout = if format == LogFormat::Npy { "npy7" } else { "rinscope" };
    let manifest = RawManifest {
        log: RawLogInfo {
            name: params.meta.name.clone(),
            description: format!(
                "Exported by `rinscope export-log` from the scenario `{}` (seed {}): the IMU's measured increments, the encoder readings and the true body attitude at every sample.\n\n{}",
                params.meta.name,
                params.meta.seed,
                params.meta.description.trim()
            ),
            table: "table.toml".into(),
            seed: Some(params.meta.seed),
            from_s: None,
            to_s: None,
        },
        imu: RawImuFile {
            file: format!("imu.{ext}"),
            layout: layout.into(),
            kind: Some("increments".into()),
            rate_hz: Some(params.step_hz),
            frame: Some(RawFrame::Named("rfu".into())),
            time: (format == LogFormat::Npy).then(|| "s".into()),
            topic: None,
            columns: None,
            gap_policy: "refuse".into(),
            gap_factor: 3.0,
        },
        encoders: Some(RawEncoderFile {
            file: format!("encoders.{ext}"),
            latch_delay_ms: 0.0,
            gap_policy: "refuse".into(),
        }),
        reference: Some(RawReference {
            source: Some("the simulation's truth".into()),
            file: Some(format!("reference.{ext}")),
            attitude_deg: None,
        }),
        // Exact: the INS starts from the truth. Aligned: the manifest says nothing and the replay
        // aligns on the data, as it would on a real log.
        initial: if aligned {
            RawInitial::default()
        } else {
            RawInitial { imu_quaternion_wxyz: Some([q.w, q.i, q.j, q.k]), ..RawInitial::default() }
        },
    };
    let table_text = format!(
        "# The table description of the log set (the [site], [turntable], [compensation], [imu], [navigation],\n# [calibration] and [recording] sections of the scenario `{}`, resolved). docs/logs.md.\n{}",
        params.meta.name,
        toml::to_string_pretty(&table).map_err(write_err)?
    );
    let manifest_text = format!(
        "# A rinscope log set (docs/logs.md), written by `rinscope export-log`.\n{}",
        toml::to_string_pretty(&manifest).map_err(write_err)?
    );
    crate::io::files::write_atomically(&dir.join("table.toml"), table_text.as_bytes()).map_err(write_err)?;
    crate::io::files::write_atomically(&dir.join(MANIFEST), manifest_text.as_bytes()).map_err(write_err)?;
    Ok(samples)
}
