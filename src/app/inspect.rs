//! The commands that look without simulating: `events` (a recording's text log), `check-config`
//! (a scenario file validated), `scenarios` (the presets).

use std::path::Path;

use crate::app::failure::Failure;
use crate::record::read::Event;
use crate::scenario::{self, Params, presets};

/// `rinscope events`: the text log of the recording at `file`, in time order, and a note when the
/// file is not a finished recording (cut short: the events are those it holds).
///
/// # Errors
/// A file that is not a readable recording (damaged, or not an `.rrd`).
pub fn events(file: &Path) -> Result<(Vec<Event>, Option<String>), Failure> {
    crate::record::read::event_log(file).map_err(|e| Failure::input(format!("{e:#}")))
}

/// `rinscope check-config`: the scenario `file`, validated as a run would load it.
///
/// # Errors
/// The file's first error, naming the key, the value and the unit.
pub fn check_config(file: &Path) -> Result<Params, Failure> {
    Ok(scenario::load_file(file)?)
}

/// `rinscope scenarios`: each preset's name and its parameters (or why it does not load).
#[must_use]
pub fn scenarios() -> Vec<(&'static str, Result<Params, String>)> {
    presets::PRESETS.iter().map(|(name, _)| (*name, presets::load(name).map_err(|e| e.to_string()))).collect()
}
