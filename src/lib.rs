//! rinscope: see the errors of a rotational inertial navigation system.
//!
//! The simulation (`frames`, `euler`, `gimbal`, `motion`, `scheme`, `sim`) is pure and knows nothing
//! of Rerun; `record` is the only module that talks to the viewer, `sink` opens its outputs.

pub mod bench;
pub mod calib;
pub mod config;
pub mod euler;
pub mod frames;
pub mod gimbal;
pub mod ins;
pub mod live;
pub mod modulation;
pub mod motion;
pub mod noise;
pub mod record;
pub mod reproduce;
pub mod run;
pub mod scenarios;
pub mod scheme;
pub mod sim;
pub mod sink;
pub mod tpr;
pub mod units;
