//! Gyro and accelerometer errors applied to the true increments, every random draw seeded: constant
//! bias, scale factor, misalignment, a first-order Gauss-Markov bias, g-dependent gyro bias,
//! ring-laser-gyro dither, and the stochastic terms of IEEE Std 952/1293 by their names (Q, N, B, K, R,
//! saturation; `noise`, docs/allan.md).

use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use super::noise::{IeeeTerms, TriadNoise};

/// A value given as a 1σ (each axis drawn from N(0, σ) with the seed) or as fixed per-axis values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spec {
    /// 1σ of a seeded draw per axis.
    Sigma(f64),
    /// Exact values per axis.
    Fixed([f64; 3]),
}

impl Default for Spec {
    fn default() -> Self {
        Self::Sigma(0.0)
    }
}

impl Spec {
    fn draw(&self, rng: &mut ChaCha8Rng) -> Vector3<f64> {
        match *self {
            Self::Fixed(v) => Vector3::from(v),
            Self::Sigma(s) => {
                let mut n = || -> f64 { StandardNormal.sample(rng) };
                Vector3::new(n(), n(), n()) * s
            }
        }
    }

    /// Multiplies every value (unit conversion).
    #[must_use]
    pub fn scaled(self, k: f64) -> Self {
        match self {
            Self::Sigma(s) => Self::Sigma(s * k),
            Self::Fixed(v) => Self::Fixed(v.map(|x| x * k)),
        }
    }
}

/// Which of one triad's error terms act (1 or 0 as factors: every draw is made whichever act, so a
/// term alone is exactly that term of the full run; an error budget runs them one at a time).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriadSources {
    /// The constant bias, per axis.
    pub bias: [bool; 3],
    /// The scale-factor error, per axis.
    pub scale: [bool; 3],
    /// The six misalignment angles.
    pub misalignment: bool,
    /// The white noise N (angle / velocity random walk).
    pub white: bool,
    /// The Gauss-Markov bias.
    pub markov: bool,
    /// IEEE's bias instability B.
    pub instability: bool,
    /// IEEE's rate (acceleration) random walk K.
    pub random_walk: bool,
    /// IEEE's ramp R.
    pub ramp: bool,
    /// The readout: quantization Q and saturation (applied to the total, not additive).
    pub readout: bool,
}

impl TriadSources {
    /// Every term.
    pub const ALL: Self = Self::every(true);
    /// None.
    pub const NONE: Self = Self::every(false);

    const fn every(on: bool) -> Self {
        Self {
            bias: [on; 3],
            scale: [on; 3],
            misalignment: on,
            white: on,
            markov: on,
            instability: on,
            random_walk: on,
            ramp: on,
            readout: on,
        }
    }
}

/// Which of the IMU's error terms act ([`TriadSources`] per triad, and the gyros' g-sensitivity and
/// dither).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuSources {
    /// The gyros'.
    pub gyro: TriadSources,
    /// The accelerometers'.
    pub accel: TriadSources,
    /// The g-dependent gyro bias.
    pub g_sensitivity: bool,
    /// The ring-laser-gyro dither.
    pub dither: bool,
}

impl ImuSources {
    /// Every term (what a run simulates).
    pub const ALL: Self = Self { gyro: TriadSources::ALL, accel: TriadSources::ALL, g_sensitivity: true, dither: true };
    /// None: an ideal IMU drawn from the same seed.
    pub const NONE: Self =
        Self { gyro: TriadSources::NONE, accel: TriadSources::NONE, g_sensitivity: false, dither: false };
}

impl Default for ImuSources {
    fn default() -> Self {
        Self::ALL
    }
}

/// 1 for a term that acts, 0 for one that does not (x · 1 is x to the bit: a full run is unchanged).
fn gain(on: bool) -> f64 {
    if on { 1.0 } else { 0.0 }
}

/// Errors of the gyro triad, SI.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GyroSpec {
    /// Constant bias, rad/s.
    pub bias_rad_per_s: Spec,
    /// Scale-factor error (dimensionless).
    pub scale: Spec,
    /// Misalignment: 1σ of each of the six small off-diagonal angles, rad.
    pub misalignment_rad: f64,
    /// IEEE 952's terms in rad, rad/s: Q (rad), N the angle random walk (rad/√s), B the bias
    /// instability (rad/s), K the rate random walk (rad/s/√s), R the rate ramp (rad/s²), saturation.
    pub noise: IeeeTerms,
    /// A first-order Gauss-Markov bias (not IEEE's B): its stationary σ, rad/s.
    pub markov_sigma_rad_per_s: f64,
    /// Its correlation time, s.
    pub correlation_s: f64,
}

/// Errors of the accelerometer triad, SI.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AccelSpec {
    /// Constant bias, m/s².
    pub bias_mps2: Spec,
    /// Scale-factor error (dimensionless).
    pub scale: Spec,
    /// Misalignment: 1σ of each of the six small off-diagonal angles, rad.
    pub misalignment_rad: f64,
    /// IEEE 1293's terms in m/s, m/s²: Q (m/s), N the velocity random walk (m/s/√s), B the bias
    /// instability (m/s²), K the acceleration random walk (m/s²/√s), R the ramp (m/s³), saturation.
    pub noise: IeeeTerms,
    /// A first-order Gauss-Markov bias (not IEEE's B): its stationary σ, m/s².
    pub markov_sigma_mps2: f64,
    /// Its correlation time, s.
    pub correlation_s: f64,
}

/// One triad's errors in the common form (the unit is the triad's: rad/s or m/s²).
struct TriadErrors {
    bias: Spec,
    scale: Spec,
    misalignment_rad: f64,
    white_per_sqrt_s: f64,
    instability: f64,
    correlation_s: f64,
}

impl From<&GyroSpec> for TriadErrors {
    fn from(g: &GyroSpec) -> Self {
        Self {
            bias: g.bias_rad_per_s,
            scale: g.scale,
            misalignment_rad: g.misalignment_rad,
            white_per_sqrt_s: g.noise.random_walk_si,
            instability: g.markov_sigma_rad_per_s,
            correlation_s: g.correlation_s,
        }
    }
}

impl From<&AccelSpec> for TriadErrors {
    fn from(a: &AccelSpec) -> Self {
        Self {
            bias: a.bias_mps2,
            scale: a.scale,
            misalignment_rad: a.misalignment_rad,
            white_per_sqrt_s: a.noise.random_walk_si,
            instability: a.markov_sigma_mps2,
            correlation_s: a.correlation_s,
        }
    }
}

/// The generator of a triad's IEEE terms other than N (N is drawn with the constant errors, from
/// the scenario's own stream, as it always was), or None when there are none: a scenario without
/// them draws exactly the numbers it drew before they existed.
fn ieee_generator(terms: &IeeeTerms, h: f64, seed: u64, first_stream: u64) -> Option<TriadNoise> {
    let rest = IeeeTerms { random_walk_si: 0.0, ..*terms };
    rest.is_active().then(|| TriadNoise::new(&rest, h, seed, first_stream))
}

/// Ring-laser-gyro dither: each gyro block oscillates at its own frequency; the motion is sensed by
/// its gyro and, through the mount, by the other two (`coupling`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DitherSpec {
    /// Dither frequency of the x, y, z gyros, Hz.
    pub frequencies_hz: [f64; 3],
    /// Dither angle amplitude of each gyro, rad.
    pub amplitudes_rad: [f64; 3],
    /// Fraction of each gyro's dither sensed by each other gyro.
    pub coupling: f64,
}

/// Everything the IMU adds to the truth.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ImuErrorSpec {
    /// Gyros.
    pub gyro: GyroSpec,
    /// Accelerometers.
    pub accel: AccelSpec,
    /// g-dependent gyro bias: rad/s per m/s² of specific force along the gyro's axis.
    pub g_sensitivity: f64,
    /// Dither.
    pub dither: DitherSpec,
}

#[derive(Debug, Clone)]
struct Triad {
    bias: Vector3<f64>,
    gain: Matrix3<f64>,
    white_per_sample: f64,
    /// The white noise's factor (its draws are made whenever `white_per_sample` > 0).
    white_gain: f64,
    gm: Vector3<f64>,
    gm_decay: f64,
    gm_drive: f64,
    /// The Gauss-Markov bias's factor (it runs whatever it is).
    gm_gain: f64,
    /// `gain` is the identity (no scale factor or misalignment): the product is skipped (it would
    /// give the same numbers).
    unit_gain: bool,
    /// Nothing is added or drawn (unit gain, no bias, no noise): the triad measures the truth.
    exact: bool,
}

impl Triad {
    fn new(spec: &TriadErrors, h: f64, rng: &mut ChaCha8Rng, on: &TriadSources) -> Self {
        let bias = spec.bias.draw(rng).component_mul(&Vector3::from(on.bias.map(gain)));
        let scale = spec.scale.draw(rng).component_mul(&Vector3::from(on.scale.map(gain)));
        let mut gain_matrix = Matrix3::identity() + Matrix3::from_diagonal(&scale);
        for i in 0..3 {
            for j in 0..3 {
                if i != j {
                    let a: f64 = StandardNormal.sample(rng);
                    gain_matrix[(i, j)] += a * spec.misalignment_rad * gain(on.misalignment);
                }
            }
        }
        let (gm_decay, gm_drive) = if spec.instability > 0.0 && spec.correlation_s > 0.0 {
            let d = (-h / spec.correlation_s).exp();
            (d, spec.instability * (1.0 - d * d).sqrt())
        } else {
            (0.0, 0.0)
        };
        let mut gm = Vector3::zeros();
        if gm_drive > 0.0 {
            // Start in the stationary distribution.
            gm = Spec::Sigma(spec.instability).draw(rng);
        }
        let white_per_sample = spec.white_per_sqrt_s * h.sqrt();
        let gm_gain = gain(on.markov);
        let unit_gain = gain_matrix == Matrix3::identity();
        let exact =
            unit_gain && white_per_sample <= 0.0 && gm_drive <= 0.0 && (bias + gm * gm_gain).iter().all(|x| *x == 0.0);
        Self {
            bias,
            gain: gain_matrix,
            white_per_sample,
            white_gain: gain(on.white),
            gm,
            gm_decay,
            gm_drive,
            gm_gain,
            unit_gain,
            exact,
        }
    }

    #[inline]
    fn apply(&mut self, x: &Vector3<f64>, extra_bias: Vector3<f64>, h: f64, rng: &mut ChaCha8Rng) -> Vector3<f64> {
        let mut y = if self.unit_gain { *x } else { self.gain * x };
        y += (self.bias + self.gm * self.gm_gain + extra_bias) * h;
        if self.white_per_sample > 0.0 {
            let n: [f64; 3] = [StandardNormal.sample(rng), StandardNormal.sample(rng), StandardNormal.sample(rng)];
            y += Vector3::from(n) * (self.white_per_sample * self.white_gain);
        }
        if self.gm_drive > 0.0 {
            let n: [f64; 3] = [StandardNormal.sample(rng), StandardNormal.sample(rng), StandardNormal.sample(rng)];
            self.gm = self.gm * self.gm_decay + Vector3::from(n) * self.gm_drive;
        }
        y
    }
}

/// The IMU's error model in action.
#[derive(Debug, Clone)]
pub struct Sensors {
    gyro: Triad,
    accel: Triad,
    gyro_ieee: Option<TriadNoise>,
    accel_ieee: Option<TriadNoise>,
    g_sensitivity: f64,
    dither: DitherSpec,
    dither_phase: [f64; 3],
    dither_last: [f64; 3],
    h: f64,
    rng: ChaCha8Rng,
    /// Whether the readouts (quantization, saturation) act: (gyros, accelerometers).
    readout: (bool, bool),
    /// The constant biases drawn (gyro rad/s, accel m/s²), for reports.
    pub drawn_bias: (Vector3<f64>, Vector3<f64>),
    /// Nothing acts (exact triads, no g-sensitivity, noise generators, dither or readout): each
    /// sample is the truth, returned as it is (a run on exact increments: the peer's workload).
    exact: bool,
}

impl Sensors {
    /// Draws the constant errors with `seed` for samples every `h` seconds starting at `t0`.
    #[must_use]
    pub fn new(spec: &ImuErrorSpec, h: f64, seed: u64, t0: f64) -> Self {
        Self::selected(spec, h, seed, t0, &ImuSources::ALL)
    }

    /// [`Self::new`] with only the error terms `on` acting: the same draws, so each term is the one
    /// of the full IMU (an error budget's runs).
    #[must_use]
    pub fn selected(spec: &ImuErrorSpec, h: f64, seed: u64, t0: f64, on: &ImuSources) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let gyro = Triad::new(&TriadErrors::from(&spec.gyro), h, &mut rng, &on.gyro);
        let accel = Triad::new(&TriadErrors::from(&spec.accel), h, &mut rng, &on.accel);
        let mut dither_phase = [0.0; 3];
        for p in &mut dither_phase {
            *p = rand::Rng::random::<f64>(&mut rng) * std::f64::consts::TAU;
        }
        let drawn_bias = (gyro.bias, accel.bias);
        // Streams 1-3 (gyros) and 4-6 (accelerometers) of the seed: stream 0 is `rng`'s.
        let mut gyro_ieee = ieee_generator(&spec.gyro.noise, h, seed, 1);
        let mut accel_ieee = ieee_generator(&spec.accel.noise, h, seed, 4);
        for (n, t) in [(&mut gyro_ieee, &on.gyro), (&mut accel_ieee, &on.accel)] {
            if let Some(n) = n {
                n.select(t.ramp, t.instability, t.random_walk);
            }
        }
        let mut dither = spec.dither;
        if !on.dither {
            dither.amplitudes_rad = [0.0; 3];
        }
        let g_sensitivity = spec.g_sensitivity * gain(on.g_sensitivity);
        let exact = gyro.exact
            && accel.exact
            && g_sensitivity == 0.0
            && gyro_ieee.is_none()
            && accel_ieee.is_none()
            && dither.amplitudes_rad.iter().all(|x| *x == 0.0);
        let mut me = Self {
            exact,
            gyro,
            accel,
            gyro_ieee,
            accel_ieee,
            g_sensitivity,
            dither,
            dither_phase,
            dither_last: [0.0; 3],
            h,
            rng,
            readout: (on.gyro.readout, on.accel.readout),
            drawn_bias,
        };
        me.dither_last = me.dither_angles(t0);
        me
    }

    fn dither_angles(&self, t: f64) -> [f64; 3] {
        let mut a = [0.0; 3];
        for j in 0..3 {
            if self.dither.amplitudes_rad[j] != 0.0 {
                a[j] = self.dither.amplitudes_rad[j]
                    * (std::f64::consts::TAU * self.dither.frequencies_hz[j] * t + self.dither_phase[j]).sin();
            }
        }
        a
    }

    /// Measured (Δθ, Δv) for the true increments of the sample ending at `t1`.
    #[inline]
    pub fn measure(&mut self, dtheta: &Vector3<f64>, dv: &Vector3<f64>, t1: f64) -> (Vector3<f64>, Vector3<f64>) {
        if self.exact {
            // What the triads would give: x + 0·h, the same numbers (but for the sign of a zero).
            return (*dtheta, *dv);
        }
        let f = dv / self.h;
        let mut g = self.gyro.apply(dtheta, f * self.g_sensitivity, self.h, &mut self.rng);
        let mut a = self.accel.apply(dv, Vector3::zeros(), self.h, &mut self.rng);
        if let Some(n) = &mut self.gyro_ieee {
            g += n.next_error();
        }
        if let Some(n) = &mut self.accel_ieee {
            a += n.next_error();
        }
        if self.dither.amplitudes_rad.iter().any(|x| *x != 0.0) {
            let now = self.dither_angles(t1);
            let c = self.dither.coupling;
            let d = [now[0] - self.dither_last[0], now[1] - self.dither_last[1], now[2] - self.dither_last[2]];
            g += Vector3::new(d[0] + c * (d[1] + d[2]), d[1] + c * (d[0] + d[2]), d[2] + c * (d[0] + d[1]));
            self.dither_last = now;
        }
        // What the readout does last: saturation and pulse counting, of the dithered total.
        if let Some(n) = self.gyro_ieee.as_mut().filter(|_| self.readout.0) {
            g = n.output(g);
        }
        if let Some(n) = self.accel_ieee.as_mut().filter(|_| self.readout.1) {
            a = n.output(a);
        }
        (g, a)
    }

    /// The drawn gain errors K (measured = (I + K)·true + bias): (gyros, accelerometers), for the
    /// comparison of a calibration with the truth (no estimator reads them).
    #[must_use]
    pub fn drawn_gain_errors(&self) -> (Matrix3<f64>, Matrix3<f64>) {
        (self.gyro.gain - Matrix3::identity(), self.accel.gain - Matrix3::identity())
    }

    /// Samples clipped by saturation so far, per axis: (gyros, accelerometers).
    #[must_use]
    pub fn saturation_counts(&self) -> ([u64; 3], [u64; 3]) {
        let count = |n: &Option<TriadNoise>| n.as_ref().map_or([0; 3], TriadNoise::saturation_counts);
        (count(&self.gyro_ieee), count(&self.accel_ieee))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_noise_has_the_specified_density() {
        // ARW 1e-3 rad/√s at 100 Hz: per-sample σ = 1e-3·√0.01 = 1e-4 rad (sample std over 2e5 draws
        // within 1%: the standard error of a std estimate is σ/√(2n) = 0.16%).
        let spec = ImuErrorSpec {
            gyro: GyroSpec { noise: IeeeTerms { random_walk_si: 1e-3, ..IeeeTerms::default() }, ..Default::default() },
            ..Default::default()
        };
        let mut s = Sensors::new(&spec, 0.01, 7, 0.0);
        let n = 200_000;
        let mut sum_sq = 0.0;
        for i in 0..n {
            let (g, _) = s.measure(&Vector3::zeros(), &Vector3::zeros(), f64::from(i) * 0.01);
            sum_sq += g.x * g.x;
        }
        let std = (sum_sq / f64::from(n)).sqrt();
        assert!((std / 1e-4 - 1.0).abs() < 0.01, "{std}");
    }

    #[test]
    fn the_same_seed_gives_the_same_stream() {
        let spec = ImuErrorSpec {
            gyro: GyroSpec {
                bias_rad_per_s: Spec::Sigma(1e-6),
                noise: IeeeTerms {
                    random_walk_si: 1e-5,
                    bias_instability_si: 1e-7,
                    rate_random_walk_si: 1e-8,
                    ..IeeeTerms::default()
                },
                markov_sigma_rad_per_s: 1e-7,
                correlation_s: 100.0,
                ..Default::default()
            },
            ..Default::default()
        };
        let run = |seed| {
            let mut s = Sensors::new(&spec, 0.005, seed, 0.0);
            (0..100)
                .map(|i| s.measure(&Vector3::zeros(), &Vector3::zeros(), f64::from(i) * 0.005).0.x)
                .collect::<Vec<_>>()
        };
        assert_eq!(run(3), run(3));
        assert_ne!(run(3), run(4));
    }

    #[test]
    fn fixed_bias_and_scale_act_as_specified() {
        let spec = ImuErrorSpec {
            gyro: GyroSpec {
                bias_rad_per_s: Spec::Fixed([1e-5, 0.0, 0.0]),
                scale: Spec::Fixed([1e-3, 0.0, 0.0]),
                ..Default::default()
            },
            ..Default::default()
        };
        let mut s = Sensors::new(&spec, 0.01, 1, 0.0);
        let (g, _) = s.measure(&Vector3::new(0.1, 0.0, 0.0), &Vector3::zeros(), 0.01);
        assert!((g.x - (0.1 * 1.001 + 1e-7)).abs() < 1e-15);
    }

    #[test]
    fn dither_integrates_to_the_dither_angle() {
        // The sum of dither increments is the change of the dither angle: bounded, zero mean.
        let spec = ImuErrorSpec {
            dither: DitherSpec { frequencies_hz: [335.4, 375.5, 425.7], amplitudes_rad: [5e-4; 3], coupling: 0.2 },
            ..Default::default()
        };
        let mut s = Sensors::new(&spec, 0.0005, 1, 0.0);
        let mut total = Vector3::zeros();
        let mut peak = 0.0f64;
        for i in 1..=20_000 {
            total += s.measure(&Vector3::zeros(), &Vector3::zeros(), f64::from(i) * 0.0005).0;
            peak = peak.max(total.x.abs());
        }
        // |Σ| ≤ 2·A·(1 + 2·coupling) on each axis.
        assert!(peak <= 2.0 * 5e-4 * 1.4 + 1e-12, "{peak}");
    }

    #[test]
    fn the_ieee_terms_leave_every_other_draw_as_it_was() {
        // The presets' streams must not change when a scenario adds Q, B, K, R (they draw from their
        // own ChaCha8 streams 1-6): the measurement with them is the measurement without them plus
        // exactly the generator's own error increments, bit for bit.
        let base = GyroSpec {
            bias_rad_per_s: Spec::Sigma(1e-6),
            noise: IeeeTerms { random_walk_si: 1e-5, ..IeeeTerms::default() },
            markov_sigma_rad_per_s: 1e-7,
            correlation_s: 100.0,
            ..Default::default()
        };
        let extra = IeeeTerms {
            random_walk_si: 1e-5,
            bias_instability_si: 3e-6,
            rate_random_walk_si: 1e-7,
            rate_ramp_si: 1e-9,
            ..IeeeTerms::default()
        };
        let plain = ImuErrorSpec { gyro: base, ..Default::default() };
        let full = ImuErrorSpec { gyro: GyroSpec { noise: extra, ..base }, ..Default::default() };
        let (mut a, mut b) = (Sensors::new(&plain, 0.005, 9, 0.0), Sensors::new(&full, 0.005, 9, 0.0));
        let mut alone = TriadNoise::new(&IeeeTerms { random_walk_si: 0.0, ..extra }, 0.005, 9, 1);
        for i in 1..=1000 {
            let t = f64::from(i) * 0.005;
            let w = Vector3::new(1e-4, 2e-4, -3e-4);
            let (ga, aa) = a.measure(&w, &Vector3::new(0.0, 0.0, 0.049), t);
            let (gb, ab) = b.measure(&w, &Vector3::new(0.0, 0.0, 0.049), t);
            assert_eq!(gb, ga + alone.next_error(), "sample {i}");
            assert_eq!(ab, aa);
        }
    }
}
