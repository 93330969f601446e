//! rinscope: see the errors of a rotational inertial navigation system.
//!
//! Layers, lowest first; a module imports only the layers above it in this list (enforced by
//! `tests/layers.rs`), and only `record` imports Rerun:
//!
//! 0. [`math`] — frames and typed rotations, units and the physical constants (each defined
//!    once), attitude, noise, statistics, the sampling rule.
//! 1. [`io`] — the file formats read and written, atomic output files and the one rule for
//!    opening inputs (`io::files`), the plausibility of a log's numbers.
//! 2. [`model`] — the gimbal chain with its exact errors, rotation schemes, vehicle motion, Earth.
//! 3. [`sim`] — the turntable step: truth, encoders, three demodulations (pure).
//! 4. [`ins`] — the INS in the loop: IMU truth, sensors and their error model, algorithms,
//!    navigation, alignment, resets; each takes the parameter struct it owns.
//! 5. [`calib`] — the estimators: the table's static calibration and the IMU's system-level
//!    self-calibration (on the INS's own error model).
//! 6. [`scenario`] — the only code that knows the TOML: raw structs, validation, presets, log sets.
//! 7. [`record`] — the only door to Rerun: the views (table, body, cone, INS, plots), documents,
//!    layout, sinks; it never steps a model.
//! 8. [`app`] — one owner per command: each command is one function taking a request and a stop
//!    flag and returning a report (`app::run::execute`, `app::calibrate::execute`, ...), with one
//!    termination policy (`app::failure`) and one way to open, check and write outputs
//!    (`app::outputs`); threads, channels and progress live here.
//! 9. [`cli`] — clap: arguments into requests, reports into text, failures into exit codes
//!    (`python/` does the same for Python).

/// `print!` for what a command outputs: stdout may be a pipe whose reader has gone
/// (`rinscope scenarios | head -5`); see [`app::terminate::write_stdout`].
macro_rules! out {
    ($($t:tt)*) => { $crate::app::terminate::write_stdout(format_args!($($t)*)) };
}

/// `println!` for what a command outputs (see [`out!`]).
macro_rules! outln {
    ($($t:tt)*) => { $crate::app::terminate::write_stdout(format_args!("{}\n", format_args!($($t)*))) };
}

/// `eprintln!` that never fails: a message to stderr is dropped when stderr cannot take it (a
/// pipe whose reader went away, a terminal that hung up: EPIPE, EIO), where `eprintln!` would
/// panic — in the signal thread, ending the only thread that answers SIGTERM and SIGINT; in the
/// main thread, turning a command's exit code into 101.
macro_rules! errln {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        std::io::stderr().lock().write_fmt(format_args!("{}\n", format_args!($($t)*))).ok();
    }};
}

pub mod app;
pub mod calib;
pub mod cli;
pub mod ins;
pub mod io;
pub mod math;
pub mod model;
pub mod record;
pub mod scenario;
pub mod sim;
