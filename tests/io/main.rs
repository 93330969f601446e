//! The log readers and table writers of `src/io`, in one test binary: every format reads the same data
//! to the same samples, every bad input is one error naming the file and where, writers never leave
//! a half-written file.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod bad_input;
mod common;
mod formats;
mod garbage;
mod large;
mod numpy_golden;
mod psins;
mod psins_bad;
mod psins_writer;
mod time_frames;
mod validity;
mod writers;
