//! rinscope: see the errors of a rotational inertial navigation system.
//!
//! Layers, lowest first; a module imports only the layers above it in this list (enforced by
//! `tests/layers.rs`), and only `record` imports Rerun:
//!
//! 0. [`math`], [`io`] — frames and typed rotations, units, attitude, noise, statistics, the
//!    sampling rule; atomic output files and the one rule for opening inputs (`io::files`).
//! 1. [`model`] — the gimbal chain with its exact errors, rotation schemes, vehicle motion, Earth.
//! 2. [`sim`] — the turntable step: truth, encoders, three demodulations (pure).
//! 3. [`ins`], [`calib`] — the INS in the loop (IMU truth, sensors, algorithms, navigation,
//!    resets) and the calibration estimators; each takes the parameter struct it owns.
//! 4. [`scenario`] — the only code that knows the TOML: raw structs, validation, presets.
//! 5. [`record`] — the only door to Rerun: entity tree, series, layout, sinks; it never steps a model.
//! 6. [`app`] — the commands' orchestration: threads, channels, progress, files.
//! 7. [`cli`] — clap, the sink flags declared once, exit codes.

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
