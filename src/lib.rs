//! rinscope: see the errors of a rotational inertial navigation system.
//!
//! The simulation (`frames`, `euler`, `gimbal`, `motion`, `scheme`, `sim`) is pure and knows nothing
//! of Rerun; `record` is the only module that talks to the viewer.

pub mod config;
pub mod euler;
pub mod frames;
pub mod gimbal;
pub mod motion;
pub mod scheme;
pub mod sim;
pub mod units;
