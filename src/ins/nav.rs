//! Strapdown navigation in the local-level frame (East-North-Up): velocity with rotation and
//! sculling compensation, Coriolis and transport rate, normal gravity, latitude/longitude/height;
//! the vertical channel held or free; optional horizontal velocity damping (seed 003 §4.1).

use nalgebra::Vector3;

use crate::math::frames::{Rot, N, S};

use crate::model::earth::{normal_gravity, omega_ie_n, Earth};

/// How the vertical channel is handled (it is unstable when free).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Vertical {
    /// Height and vertical velocity fixed at the start values (the usual choice for ships).
    Held,
    /// Integrated like the horizontal channels.
    Free,
}

/// Navigation options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavOptions {
    /// Vertical channel.
    pub vertical: Vertical,
    /// Horizontal velocity damping gain toward zero velocity, 1/s (0: off). A gain equal to the
    /// Schuler frequency gives a damping ratio of 0.5.
    pub damping_per_s: f64,
}

/// Position, velocity and the attitude used for the velocity update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavState {
    /// Latitude, rad.
    pub latitude_rad: f64,
    /// Longitude, rad.
    pub longitude_rad: f64,
    /// Height, m.
    pub height_m: f64,
    /// Velocity (East, North, Up), m/s.
    pub v_n: Vector3<f64>,
}

/// The navigator.
#[derive(Debug, Clone)]
pub struct Navigator {
    /// Current solution.
    pub state: NavState,
    options: NavOptions,
    height0: f64,
}

impl Navigator {
    /// Starts at rest at `earth`'s site.
    #[must_use]
    pub fn new(earth: &Earth, options: NavOptions) -> Self {
        let s = earth.site;
        Self { state: NavState { latitude_rad: s.latitude_rad, longitude_rad: s.longitude_rad, height_m: s.height_m, v_n: Vector3::zeros() }, options, height0: s.height_m }
    }

    /// ω_in^n = ω_ie^n + ω_en^n at the current state.
    #[must_use]
    pub fn omega_in_n(&self) -> Vector3<f64> {
        let st = &self.state;
        let (sl, cl) = st.latitude_rad.sin_cos();
        let (rm, rn) = Earth::radii(st.latitude_rad);
        let (rm, rn) = (rm + st.height_m, rn + st.height_m);
        let w_ie = omega_ie_n(st.latitude_rad);
        let w_en = Vector3::new(-st.v_n.y / rm, st.v_n.x / rn, st.v_n.x * sl / (cl * rn));
        w_ie + w_en
    }

    /// One velocity/position update over `h` seconds from the sensor increments of the update (one
    /// entry per gyro/accel sample), with the attitude C_s^n at the start of the update and the
    /// navigation-frame rotation `zeta_n` over it.
    pub fn update(&mut self, n_from_s_start: &Rot<N, S>, dtheta: &[Vector3<f64>], dv: &[Vector3<f64>], zeta_n: &Vector3<f64>, h: f64) {
        let theta: Vector3<f64> = dtheta.iter().sum();
        let vel: Vector3<f64> = dv.iter().sum();
        // Rotation compensation and sculling (Savage's two- and three-sample forms).
        let mut dv_s = vel + 0.5 * theta.cross(&vel);
        match dtheta.len() {
            2 => dv_s += (2.0 / 3.0) * (dtheta[0].cross(&dv[1]) + dv[0].cross(&dtheta[1])),
            3 => {
                dv_s += (33.0 / 80.0) * (dtheta[0].cross(&dv[2]) + dv[0].cross(&dtheta[2]))
                    + (57.0 / 80.0) * (dtheta[0].cross(&dv[1]) + dtheta[1].cross(&dv[2]) + dv[0].cross(&dtheta[1]) + dv[1].cross(&dtheta[2]));
            }
            _ => {}
        }
        let c = n_from_s_start.quaternion();
        let dv_sf_n = c * dv_s - 0.5 * zeta_n.cross(&(c * dv_s));

        let st = &mut self.state;
        let (sl, cl) = st.latitude_rad.sin_cos();
        let (rm, rn) = Earth::radii(st.latitude_rad);
        let (rm, rn) = (rm + st.height_m, rn + st.height_m);
        let w_ie = omega_ie_n(st.latitude_rad);
        let w_en = Vector3::new(-st.v_n.y / rm, st.v_n.x / rn, st.v_n.x * sl / (cl * rn));
        let g = Vector3::new(0.0, 0.0, -normal_gravity(st.latitude_rad, st.height_m));
        let v_old = st.v_n;
        let mut v_new = v_old + dv_sf_n + (g - (2.0 * w_ie + w_en).cross(&v_old)) * h;
        if self.options.damping_per_s > 0.0 {
            let k = (-self.options.damping_per_s * h).exp();
            v_new.x *= k;
            v_new.y *= k;
        }
        if self.options.vertical == Vertical::Held {
            v_new.z = 0.0;
        }
        let v_mid = 0.5 * (v_old + v_new);
        st.latitude_rad += v_mid.y / rm * h;
        st.longitude_rad += v_mid.x / (rn * cl) * h;
        st.height_m = if self.options.vertical == Vertical::Held { self.height0 } else { st.height_m + v_mid.z * h };
        st.v_n = v_new;
    }
}
