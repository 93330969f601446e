//! The INS in the loop: IMU increments from the exact truth, sensor errors, dither and its FIR,
//! coning-compensated attitude algorithms and strapdown navigation.

pub mod coning;
pub mod strapdown;
pub mod truth;
pub mod fir;
pub mod sensor;
