//! Layer 8, one owner per command (each `execute(request, stop) -> report`): a recorded run (simulation thread → channel → recorder),
//! live mode, calibration and its Monte Carlo, the position-reset comparison, rotation modulation,
//! the paper reproductions and the benchmarks. Threads, channels, progress bars and files live
//! here, above the pure layers and the recorder.

pub mod allan;
pub mod bench;
pub mod budget;
pub mod calibrate;
pub mod design;
pub mod export_log;
pub mod failure;
pub(crate) mod feed;
pub mod inspect;
pub mod live;
pub mod modulation;
pub mod montecarlo;
pub mod outputs;
pub mod playback;
pub mod replay;
pub mod reproduce;
pub mod run;
pub mod schemes;
pub mod selfcal;
pub mod sweep;
pub mod terminate;
pub mod tpr;
