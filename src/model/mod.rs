//! Layer 2, the world model: the gimbal chain with its exact errors, the rotation schemes (and the
//! indexing sequences a scheme search draws from), the vehicle's motion and the Earth. Pure functions of time and parameters; imports only `math`.

pub mod earth;
pub mod gimbal;
pub mod motion;
pub mod scheme;
pub mod sequences;
pub mod turning;
