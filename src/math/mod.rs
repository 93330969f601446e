//! Layer 0, pure mathematics: typed frames and rotations, units, Euler attitude, rotation-vector
//! maps, counter-based noise, running statistics, the Allan deviation and its noise fit, and the
//! sampling rule of a run. Imports nothing of the crate.

pub mod allan;
pub mod attitude;
pub mod frames;
pub mod noise;
pub mod rotvec;
pub mod stats;
pub mod timeline;
pub mod units;
