//! Layer 2, the world model: the gimbal chain with its exact errors, the rotation schemes, the
//! vehicle's motion and the Earth. Pure functions of time and parameters; imports only `math`.

pub mod earth;
pub mod gimbal;
pub mod motion;
pub mod scheme;
pub mod turning;
