//! Strapdown navigation in the local-level frame (East-North-Up): velocity with rotation and
//! sculling compensation, Coriolis and transport rate, normal gravity, latitude/longitude/height;
//! the vertical channel held or free; optional horizontal velocity damping (Zheng et al. 2016 §4.1).

use nalgebra::Vector3;

use crate::math::frames::{N, Rot, S};

use crate::model::earth::{Earth, normal_gravity, omega_ie_n};

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
    terms: LatitudeTerms,
}

/// The latitude- and height-dependent terms of the navigation equations, refreshed when the
/// position has moved by more than [`REFRESH_LATITUDE_RAD`] or [`REFRESH_HEIGHT_M`] (they change on
/// the scale of metres; recomputing them for every IMU sample was 43 % of the navigation's time).
///
/// Bound: with |δL| ≤ 1e-8 rad (6 cm) and |δh| ≤ 0.03 m the stale terms are off by at most
/// sin/cos: 1e-8; radii: |dR/dL|·δL + δh ≤ 4e4·1e-8 + 0.03 m of 6.4e6 m (6e-9 relative); gravity:
/// |dg/dL|·δL + 3.1e-6·δh ≤ 5e-10 + 9.3e-8 m/s² (9.5e-9 g); Coriolis Ω·δL = 7e-13 rad/s. Against a
/// navigation-grade error budget (accelerometer bias 1e-5 g, gyro bias 1e-3 °/h = 4.8e-9 rad/s)
/// that is at most 9.5e-4 (gravity's height term) and 1.5e-4 (Coriolis) of it, below the 1e-3
/// asked; a static INS moves less than 1 m in an hour, so the terms are refreshed a few times per
/// hour (a free vertical channel more often: every 3 cm of height).
#[derive(Debug, Clone, Copy)]
struct LatitudeTerms {
    latitude_rad: f64,
    height_m: f64,
    /// Meridian and transverse radii plus height, m, as reciprocals (1/m), and tan L/(R_N + h).
    inv_rm: f64,
    inv_rn: f64,
    tan_over_rn: f64,
    /// 1/((R_N + h) cos L), 1/m.
    inv_rn_cos: f64,
    omega_ie_n: Vector3<f64>,
    gravity_mps2: f64,
}

/// Latitude change that refreshes the cached terms, rad.
pub const REFRESH_LATITUDE_RAD: f64 = 1e-8;
/// Height change that refreshes the cached terms, m.
pub const REFRESH_HEIGHT_M: f64 = 0.03;

impl LatitudeTerms {
    fn at(latitude_rad: f64, height_m: f64) -> Self {
        let (sin_lat, cos_lat) = latitude_rad.sin_cos();
        let (rm, rn) = Earth::radii(latitude_rad);
        let (rm, rn) = (rm + height_m, rn + height_m);
        Self {
            latitude_rad,
            height_m,
            inv_rm: 1.0 / rm,
            inv_rn: 1.0 / rn,
            tan_over_rn: sin_lat / (cos_lat * rn),
            inv_rn_cos: 1.0 / (rn * cos_lat),
            omega_ie_n: omega_ie_n(latitude_rad),
            gravity_mps2: normal_gravity(latitude_rad, height_m),
        }
    }

    /// ω_en^n + ω_ie^n at velocity `v` (ENU, m/s).
    #[inline]
    fn omega_in_n(&self, v: &Vector3<f64>) -> Vector3<f64> {
        self.omega_ie_n + self.omega_en_n(v)
    }

    /// The transport rate ω_en^n at velocity `v`.
    #[inline]
    fn omega_en_n(&self, v: &Vector3<f64>) -> Vector3<f64> {
        Vector3::new(-v.y * self.inv_rm, v.x * self.inv_rn, v.x * self.tan_over_rn)
    }

    fn refresh(&mut self, latitude_rad: f64, height_m: f64) {
        if (latitude_rad - self.latitude_rad).abs() > REFRESH_LATITUDE_RAD
            || (height_m - self.height_m).abs() > REFRESH_HEIGHT_M
        {
            *self = Self::at(latitude_rad, height_m);
        }
    }
}

impl Navigator {
    /// Starts at rest at `earth`'s site.
    #[must_use]
    pub fn new(earth: &Earth, options: NavOptions) -> Self {
        let s = earth.site;
        Self {
            state: NavState {
                latitude_rad: s.latitude_rad,
                longitude_rad: s.longitude_rad,
                height_m: s.height_m,
                v_n: Vector3::zeros(),
            },
            options,
            height0: s.height_m,
            terms: LatitudeTerms::at(s.latitude_rad, s.height_m),
        }
    }

    /// ω_in^n = ω_ie^n + ω_en^n at the current state.
    #[must_use]
    pub fn omega_in_n(&self) -> Vector3<f64> {
        self.terms.omega_in_n(&self.state.v_n)
    }

    /// One velocity/position update over `h` seconds from the sensor increments of the update (one
    /// entry per gyro/accel sample), with the attitude C_s^n at the start of the update and the
    /// navigation-frame rotation `zeta_n` over it.
    pub fn update(
        &mut self,
        n_from_s_start: &Rot<N, S>,
        dtheta: &[Vector3<f64>],
        dv: &[Vector3<f64>],
        zeta_n: &Vector3<f64>,
        h: f64,
    ) {
        let theta: Vector3<f64> = dtheta.iter().sum();
        let vel: Vector3<f64> = dv.iter().sum();
        // Rotation compensation and sculling (Savage's two- and three-sample forms).
        let mut dv_s = vel + 0.5 * theta.cross(&vel);
        match dtheta.len() {
            2 => dv_s += (2.0 / 3.0) * (dtheta[0].cross(&dv[1]) + dv[0].cross(&dtheta[1])),
            3 => {
                dv_s += (33.0 / 80.0) * (dtheta[0].cross(&dv[2]) + dv[0].cross(&dtheta[2]))
                    + (57.0 / 80.0)
                        * (dtheta[0].cross(&dv[1])
                            + dtheta[1].cross(&dv[2])
                            + dv[0].cross(&dtheta[1])
                            + dv[1].cross(&dtheta[2]));
            }
            _ => {}
        }
        let dv_n = n_from_s_start.quaternion() * dv_s;
        let dv_sf_n = dv_n - 0.5 * zeta_n.cross(&dv_n);

        let st = &mut self.state;
        let t = self.terms;
        let w_ie = t.omega_ie_n;
        let w_en = t.omega_en_n(&st.v_n);
        let g = Vector3::new(0.0, 0.0, -t.gravity_mps2);
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
        st.latitude_rad += v_mid.y * t.inv_rm * h;
        st.longitude_rad += v_mid.x * t.inv_rn_cos * h;
        st.height_m = if self.options.vertical == Vertical::Held { self.height0 } else { st.height_m + v_mid.z * h };
        st.v_n = v_new;
        self.terms.refresh(st.latitude_rad, st.height_m);
    }

    /// A position fix: latitude and longitude set to `site`'s, velocity kept.
    pub fn fix_position(&mut self, site: &crate::model::earth::Site) {
        self.state.latitude_rad = site.latitude_rad;
        self.state.longitude_rad = site.longitude_rad;
        self.terms.refresh(self.state.latitude_rad, self.state.height_m);
    }
}
