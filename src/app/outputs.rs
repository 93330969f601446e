//! What every command's owner does with its outputs, one way for all: the recording's name and
//! default file, opening the sinks (dropped unfinished, they are abandoned: the partial file is
//! removed), the up-front check of every output location, JSON documents written atomically.

use std::path::{Path, PathBuf};

use super::failure::Failure;
use crate::io::files::{check_output_path, open_input, write_atomically};
use crate::record::APPLICATION_ID;
use crate::record::sink::{self, OpenSinks, Saved, SinkRequest};

/// What a recording is of: its name (a scenario's or a log set's), the kind of work (`None` for
/// a plain run) and the seed when it was simulated. It names the recording in the viewer
/// (`jiang2017-calibration-calibration-seed7`) and its default file (`recordings/<name>[-<kind>].rrd`).
#[derive(Debug, Clone, Copy)]
pub struct RecordingName<'a> {
    /// The scenario's or the log set's name.
    pub name: &'a str,
    /// `calibration`, `selfcal`, `allan`, `replay`, `live`... or nothing for `run` and `tpr`.
    pub kind: Option<&'a str>,
    /// The simulation's seed (a log has none).
    pub seed: Option<u64>,
}

impl RecordingName<'_> {
    /// The recording id the viewer shows.
    #[must_use]
    pub fn id(&self) -> String {
        let mut id = self.name.to_owned();
        if let Some(k) = self.kind {
            id = format!("{id}-{k}");
        }
        if let Some(s) = self.seed {
            id = format!("{id}-seed{s}");
        }
        id
    }

    /// The file a command saves to when no viewer was asked for.
    #[must_use]
    pub fn default_file(&self) -> PathBuf {
        let stem = match self.kind {
            Some(k) => format!("{}-{k}", self.name),
            None => self.name.to_owned(),
        };
        PathBuf::from("recordings").join(format!("{stem}.rrd"))
    }
}

/// Where a command's recording goes: the sinks asked for and whether, with no file named, it is
/// saved under `recordings/` (the command line's rule when no viewer was asked for).
#[derive(Debug, Clone, Default)]
pub struct RecordingRequest {
    /// The sinks (`save` as given).
    pub sinks: SinkRequest,
    /// Save to [`RecordingName::default_file`] when `sinks.save` is `None`.
    pub save_by_default: bool,
}

impl RecordingRequest {
    /// Opens the sinks for the recording `name`, and says on stderr where the data goes.
    ///
    /// # Errors
    /// A sink could not be opened (a viewer not there, a file that cannot be written).
    pub fn open(&self, name: RecordingName<'_>) -> Result<OpenSinks, Failure> {
        let mut request = self.sinks.clone();
        if request.save.is_none() && self.save_by_default {
            request.save = Some(name.default_file());
        }
        let sinks = sink::open(&request, APPLICATION_ID, &name.id())?;
        for d in &sinks.description {
            errln!("rinscope: {d}");
        }
        Ok(sinks)
    }
}

/// Checks an output file's location before anything runs (see [`check_output_path`]): a typo
/// costs nothing.
///
/// # Errors
/// The path cannot be written, named with its `flag`.
pub fn check_output(flag: &str, path: Option<&Path>) -> Result<(), Failure> {
    match path {
        Some(p) => check_output_path(p).map_err(|e| Failure::input(format!("{flag} {e}"))),
        None => Ok(()),
    }
}

/// Writes `value` as pretty JSON to the file given with `flag`, atomically.
///
/// # Errors
/// The file could not be written.
pub fn write_json(flag: &str, path: &Path, value: &impl serde::Serialize) -> Result<(), Failure> {
    let json = serde_json::to_string_pretty(value).map_err(|e| Failure::run(e.to_string()))?;
    write_atomically(path, json.as_bytes()).map_err(|e| Failure::output(flag, &e))
}

/// Finishes a command's recording (see [`OpenSinks::finish`]); an error if a viewer failed and no
/// file kept the data.
///
/// # Errors
/// The recording could not be completed, or nothing kept this run's data.
pub fn finish(sinks: OpenSinks) -> Result<Saved, Failure> {
    let saved = sinks.finish()?;
    if saved.recording.is_none() && !saved.viewer_problems.is_empty() {
        return Err(Failure::run(format!(
            "nothing kept this run's data: {} (add --save FILE)",
            saved.viewer_problems.join("; ")
        )));
    }
    Ok(saved)
}

/// Logging into a recording that failed, as a failure of the run.
///
/// # Errors
/// `logged` was an error.
pub fn logged<E: std::fmt::Display>(logged: Result<(), E>) -> Result<(), Failure> {
    logged.map_err(|e| Failure::run(format!("rerun: {e}")))
}

/// A small input file (a calibration result, a shard file) read whole, at most 1 GB, opened by
/// the rule for every input (a FIFO or a device is refused at once).
///
/// # Errors
/// It cannot be opened or read, or is larger.
pub fn read_small_file(path: &Path, what: &str) -> Result<String, Failure> {
    use std::io::Read as _;
    let fail = |e: std::io::Error| Failure::input(format!("{what} {}: {e}", path.display()));
    let file = open_input(path).map_err(fail)?;
    let len = file.metadata().map_err(fail)?.len();
    if len > 1 << 30 {
        return Err(Failure::input(format!(
            "{what} {}: {len} bytes, more than the 1 GB such a file can be",
            path.display()
        )));
    }
    let mut text = String::new();
    file.take((1 << 30) + 1).read_to_string(&mut text).map_err(fail)?;
    Ok(text)
}
