//! One termination policy for every command: what went wrong, the exit code it deserves (the
//! policy in `cli`'s docs and docs/reliability.md) and the kind a binding turns it into (Python:
//! ValueError, OSError, RuntimeError, KeyboardInterrupt). Every command's owner in `app` returns
//! its failures through these constructors, never through a code of its own.

use crate::io::files::OutputError;
use crate::record::sink::SinkError;
use crate::scenario::ConfigError;

/// What kind of failure, for a binding that has no exit codes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FailureKind {
    /// Bad input: an argument, a configuration, a log's files or data, an output path.
    Input,
    /// An output could not be written (disk full, permission).
    Output,
    /// The run failed though its input was good (a viewer, a disagreement).
    Run,
    /// Stopped before the end by a signal or a stop request.
    Interrupted,
}

/// A failure with its exit code and its message (one line, naming what is wrong).
#[derive(Debug, Clone)]
pub struct Failure {
    /// The process's exit code: 2 bad input, 1 a failed run, 128 + the signal.
    pub code: u8,
    /// What kind, for bindings.
    pub kind: FailureKind,
    /// The message.
    pub message: String,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl Failure {
    /// Bad input (exit 2): arguments, configuration, a log set's files or data.
    pub fn input(message: impl Into<String>) -> Self {
        Self { code: 2, kind: FailureKind::Input, message: message.into() }
    }

    /// The run failed though its input was good (exit 1): a viewer, a disagreement.
    pub fn run(message: impl Into<String>) -> Self {
        Self { code: 1, kind: FailureKind::Run, message: message.into() }
    }

    /// Stopped before the end by a signal (exit 128 + the signal: 130, 143, 129).
    pub fn interrupted(message: impl Into<String>) -> Self {
        let by = super::terminate::stop_reason().unwrap_or("a stop request");
        Self {
            code: super::terminate::interrupted_exit_code(),
            kind: FailureKind::Interrupted,
            message: format!("interrupted by {by}: {}", message.into()),
        }
    }

    /// An output file `flag` names that could not be written: exit 1 when writing failed (disk
    /// full, permission), 2 when the path itself cannot be used (a directory, a symlinked partial,
    /// an input of the run, another run writing it).
    pub fn output(flag: &str, e: &OutputError) -> Self {
        let message = format!("{flag} {e}");
        match e {
            OutputError::Io { .. } => Self { code: 1, kind: FailureKind::Output, message },
            _ => Self { code: 2, kind: FailureKind::Output, message },
        }
    }

    /// A calibration that did not end (`calibrate`, `calibrate --log`, `montecarlo`): cut short by a
    /// signal, or refused because of its input — a table without axes, data the estimators cannot
    /// use (singular normal equations), a log set's unreadable or bad data.
    pub fn calibration(command: &str, e: crate::calib::CalibError, interrupted: &str) -> Self {
        match e {
            crate::calib::CalibError::Interrupted => Self::interrupted(interrupted),
            e => Self::input(format!("{command}: {e}")),
        }
    }
}

impl From<ConfigError> for Failure {
    fn from(e: ConfigError) -> Self {
        Self::input(format!("config error: {e}"))
    }
}

impl From<SinkError> for Failure {
    fn from(e: SinkError) -> Self {
        let message = e.to_string();
        match e {
            SinkError::Interrupted(m) => Self::interrupted(m),
            SinkError::Write(_) | SinkError::ExportWrite(_) | SinkError::FiguresWrite(_) => {
                Self { code: 1, kind: FailureKind::Output, message }
            }
            SinkError::File(_) => Self { code: 2, kind: FailureKind::Output, message },
            SinkError::Rerun(_) | SinkError::Spawn(_) => Self::run(message),
            _ => Self::input(message),
        }
    }
}

impl From<anyhow::Error> for Failure {
    fn from(e: anyhow::Error) -> Self {
        Self::run(format!("{e:#}"))
    }
}

impl From<super::allan::AllanRunError> for Failure {
    fn from(e: super::allan::AllanRunError) -> Self {
        use super::allan::AllanRunError;
        match e {
            // Every channel error is of the data: too few samples, a non-finite value, a bad rate.
            AllanRunError::Config(_) | AllanRunError::Data(_) | AllanRunError::Analysis(_) => {
                Self::input(format!("allan: {e}"))
            }
            AllanRunError::Interrupted(_) => Self::interrupted(format!("allan: {e}")),
        }
    }
}

impl From<super::playback::PlaybackError> for Failure {
    fn from(e: super::playback::PlaybackError) -> Self {
        match e {
            super::playback::PlaybackError::Record(_) => Self::run(format!("replay: {e}")),
            _ => Self::input(format!("replay: {e}")),
        }
    }
}
