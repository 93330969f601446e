//! The stochastic terms of IEEE Std 952-1997 (gyros) and 1293-1998 (accelerometers) that a sensor
//! triad adds on top of `sensor`'s constant errors and white noise: quantization with carry (pulse
//! counting), bias instability as flicker noise, rate random walk, rate ramp, and saturation.
//! Seeded and deterministic: one ChaCha8 stream per axis, none shared with `sensor`'s generator, so
//! a scenario without these terms draws exactly the numbers it drew before they existed.
//!
//! Per axis and sample k (interval τ0), the error increment is the exact integral over the sample of
//! the error rate:
//! * **N** (white rate noise of two-sided PSD N²): Normal(0, N²τ0) per sample, ADEV N/√τ. (In the
//!   simulation N is `sensor`'s `arw`/`vrw`; here for the generator used on its own.)
//! * **B** (flicker rate noise, S(f) = B²/(2πf)): a bank of first-order Gauss–Markov processes, one
//!   per decade of correlation time ([`flicker_bank`]), each discretised exactly together with its
//!   own integral and started in its stationary distribution; ADEV floor 0.664·B over the range.
//! * **K** (rate b(t) = K·W(t), b(0) = 0): with u = b_{k+1} − b_k ~ N(0, K²τ0) and v = ∫(b − b_k)dt,
//!   Var v = K²τ0³/3, Cov(u, v) = K²τ0²/2, the increment is b_k·τ0 + v (b_k·τ0 alone would make the
//!   ADEV at τ0 √1.5 too large); ADEV K√(τ/3).
//! * **R** (rate R·t from the first sample): increment R·τ0²(k + ½); ADEV Rτ/√2.
//!
//! [`TriadNoise::output`] clips the total rate at ±limit (saturation, counted) and outputs whole
//! pulses of weight q keeping the remainder (an RLG's pulse counting): Σ output = Σ input − carry,
//! |carry| ≤ q/2, so the angle never drifts. Quantization is white angle noise of variance q²/12
//! when the input decorrelates the remainder: Allan Q = q/√12, ADEV √3·Q/τ.

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use std::f64::consts::{LN_10, PI};

use crate::math::allan::{NoiseTerm, gauss_markov_avar};

#[cfg(test)]
mod tests;

/// The IEEE terms of one triad (every axis alike), SI in the triad's unit: gyro rad, rad/s;
/// accelerometer m/s, m/s².
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IeeeTerms {
    /// Q, the Allan quantization coefficient (rad | m/s); the pulse weight is √12·Q. 0: none.
    pub quantization_si: f64,
    /// N (rad/√s | m/s/√s).
    pub random_walk_si: f64,
    /// B (rad/s | m/s²).
    pub bias_instability_si: f64,
    /// τ range over which the bias-instability floor is flat, s.
    pub flicker_range_s: [f64; 2],
    /// K (rad/s/√s | m/s²/√s).
    pub rate_random_walk_si: f64,
    /// R (rad/s² | m/s³).
    pub rate_ramp_si: f64,
    /// |rate| limit (rad/s | m/s²); None: unlimited.
    pub saturation_si: Option<f64>,
}

/// The flat-floor range of the bias instability when a scenario does not give one, s.
pub const DEFAULT_FLICKER_RANGE_S: [f64; 2] = [1.0, 1e4];

impl Default for IeeeTerms {
    fn default() -> Self {
        Self {
            quantization_si: 0.0,
            random_walk_si: 0.0,
            bias_instability_si: 0.0,
            flicker_range_s: DEFAULT_FLICKER_RANGE_S,
            rate_random_walk_si: 0.0,
            rate_ramp_si: 0.0,
            saturation_si: None,
        }
    }
}

impl IeeeTerms {
    /// True if any term is set (else the simulation does not build a generator at all).
    #[must_use]
    pub fn is_active(&self) -> bool {
        self.quantization_si > 0.0
            || self.random_walk_si > 0.0
            || self.bias_instability_si > 0.0
            || self.rate_random_walk_si > 0.0
            || self.rate_ramp_si != 0.0
            || self.saturation_si.is_some()
    }

    /// The output pulse weight q = √12·Q (rad | m/s).
    #[must_use]
    pub fn pulse_weight_si(&self) -> f64 {
        12f64.sqrt() * self.quantization_si
    }

    /// The coefficient of one term in the standard's sense (the Allan Q, not the pulse weight).
    #[must_use]
    pub fn coefficient(&self, term: NoiseTerm) -> f64 {
        match term {
            NoiseTerm::Quantization => self.quantization_si,
            NoiseTerm::RandomWalk => self.random_walk_si,
            NoiseTerm::BiasInstability => self.bias_instability_si,
            NoiseTerm::RateRandomWalk => self.rate_random_walk_si,
            NoiseTerm::RateRamp => self.rate_ramp_si.abs(),
        }
    }

    /// The Allan variance at τ (s) of what this generator draws (SI rate units²): the power laws of
    /// Q, N, K, R and the exact curve of the flicker bank (flat at 0.664·B inside the range, falling
    /// off outside it). Saturation is not modelled.
    #[must_use]
    pub fn model_avar(&self, tau_s: f64) -> f64 {
        let laws: f64 =
            [NoiseTerm::Quantization, NoiseTerm::RandomWalk, NoiseTerm::RateRandomWalk, NoiseTerm::RateRamp]
                .iter()
                .map(|t| t.avar(self.coefficient(*t), tau_s))
                .sum();
        let flicker: f64 = flicker_bank(self.bias_instability_si, self.flicker_range_s)
            .iter()
            .map(|g| gauss_markov_avar(g.sigma_si, g.correlation_time_s, tau_s))
            .sum();
        laws + flicker
    }
}

/// One Gauss–Markov process of the flicker approximation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlickerTerm {
    /// Correlation time T, s.
    pub correlation_time_s: f64,
    /// Stationary standard deviation of the rate (rad/s | m/s²).
    pub sigma_si: f64,
}

/// The Gauss–Markov bank that approximates flicker rate noise of coefficient B (S(f) = B²/(2πf)
/// two-sided, IEEE 952 C.1.3) with a flat ADEV floor 0.664·B for τ in `range_s`.
///
/// Design: one process per decade, T_i = (τ_min/30)·10^i, i = 0..=I with I the least integer such
/// that T_I ≥ 3·τ_max; equal variances σ_i² = B²·ln10/π. (A log-uniform mixture of Lorentzians
/// 2σ²T/(1+(2πfT)²) with density 1/ln r per unit ln T sums to σ²/(2f ln r); equating it to
/// B²/(2πf) gives σ² = B² ln r / π.) Checked with [`gauss_markov_avar`]: the ADEV is within
/// −1.5 % / +1.2 % of 0.664·B over the whole range, for any range (the design is scale invariant);
/// below τ_min/3 it falls off as √τ, above 3·τ_max as 1/√τ. Example: 1 s..10⁴ s → 7 processes,
/// T = 0.033 s..3.3·10⁴ s. Empty for B = 0 or an invalid range (the scenario refuses those).
#[must_use]
pub fn flicker_bank(b_si: f64, range_s: [f64; 2]) -> Vec<FlickerTerm> {
    let [lo, hi] = range_s;
    if !(b_si > 0.0 && b_si.is_finite() && lo > 0.0 && hi > lo && hi.is_finite()) {
        return Vec::new();
    }
    let t0 = lo / 30.0;
    let last = (3.0 * hi / t0).log10().ceil().max(0.0) as i32;
    let sigma_si = b_si * (LN_10 / PI).sqrt();
    (0..=last).map(|i| FlickerTerm { correlation_time_s: t0 * 10f64.powi(i), sigma_si }).collect()
}

/// g(h) = h − 2(1 − e^{−h}) + (1 − e^{−2h})/2 = Σ_{n≥3} (−1)^{n+1}(2^{n−1} − 2)hⁿ/n!, a series for
/// small h (the closed form cancels catastrophically).
fn gm_integral_g(h: f64) -> f64 {
    if h > 0.5 {
        return h + 2.0 * (-h).exp_m1() - 0.5 * (-2.0 * h).exp_m1();
    }
    let (mut sum, mut pow, mut fact) = (0.0, h, 1.0);
    for n in 1..=30 {
        fact *= f64::from(n);
        if n >= 3 {
            let sign = if n % 2 == 1 { 1.0 } else { -1.0 };
            sum += sign * (2f64.powi(n - 1) - 2.0) * pow / fact;
        }
        pow *= h;
    }
    sum
}

/// An exactly discretised Gauss–Markov rate x (dx = −x/T dt + √(2σ²/T) dW) and its integral over
/// one sample: with φ = e^{−h}, h = τ0/T, x_{k+1} = φx_k + w1, I_k = T(1−φ)x_k + w2,
/// Var w1 = σ²(1−φ²), Var w2 = 2σ²T²·g(h), Cov(w1, w2) = σ²T(1−φ)²; (w1, w2) by a 2×2 Cholesky.
#[derive(Debug, Clone)]
pub(crate) struct GaussMarkov {
    phi: f64,
    gain: f64,
    l11: f64,
    l21: f64,
    l22: f64,
    x: f64,
}

impl GaussMarkov {
    /// The process `term` sampled every `tau0_s`, starting at `x0_normal` stationary sigmas.
    pub(crate) fn new(term: FlickerTerm, tau0_s: f64, x0_normal: f64) -> Self {
        let (s, t) = (term.sigma_si, term.correlation_time_s);
        let h = tau0_s / t;
        let one_minus_phi = -(-h).exp_m1();
        let var1 = -s * s * (-2.0 * h).exp_m1();
        let var2 = 2.0 * s * s * t * t * gm_integral_g(h);
        let cov = s * s * t * one_minus_phi * one_minus_phi;
        let l11 = var1.sqrt();
        let l21 = if l11 > 0.0 { cov / l11 } else { 0.0 };
        Self {
            phi: (-h).exp(),
            gain: t * one_minus_phi,
            l11,
            l21,
            l22: (var2 - l21 * l21).max(0.0).sqrt(),
            x: s * x0_normal,
        }
    }

    /// The integral of x over the next sample; advances x. `z1`, `z2` standard normal.
    #[inline]
    pub(crate) fn step(&mut self, z1: f64, z2: f64) -> f64 {
        let inc = self.gain * self.x + self.l21 * z1 + self.l22 * z2;
        self.x = self.phi * self.x + self.l11 * z1;
        inc
    }
}

#[derive(Debug, Clone)]
struct AxisState {
    rng: ChaCha8Rng,
    flicker: Vec<GaussMarkov>,
    rrw_rate: f64,
    carry: f64,
    pulses: i64,
    saturations: u64,
}

/// The seeded generator of one triad's IEEE terms.
#[derive(Debug, Clone)]
pub struct TriadNoise {
    terms: IeeeTerms,
    tau0_s: f64,
    k: u64,
    white_sigma: f64,
    pulse: f64,
    axes: [AxisState; 3],
    /// 1 or 0 per term (R, B, K): whether it reaches the output; every draw is made either way
    /// ([`Self::select`]).
    gains: [f64; 3],
}

impl TriadNoise {
    /// The generator of `terms` for samples every `tau0_s`; axis i draws from ChaCha8(`seed`)
    /// stream `first_stream + i` (stream 0 is `sensor`'s: give 1 for the gyros, 4 for the
    /// accelerometers). The parameters are the scenario's, validated there.
    #[must_use]
    pub fn new(terms: &IeeeTerms, tau0_s: f64, seed: u64, first_stream: u64) -> Self {
        let bank = flicker_bank(terms.bias_instability_si, terms.flicker_range_s);
        let axes = std::array::from_fn(|i| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            rng.set_stream(first_stream + i as u64);
            let flicker = bank.iter().map(|t| GaussMarkov::new(*t, tau0_s, rng.sample(StandardNormal))).collect();
            AxisState { rng, flicker, rrw_rate: 0.0, carry: 0.0, pulses: 0, saturations: 0 }
        });
        Self {
            terms: *terms,
            tau0_s,
            k: 0,
            white_sigma: terms.random_walk_si * tau0_s.sqrt(),
            pulse: terms.pulse_weight_si(),
            axes,
            gains: [1.0; 3],
        }
    }

    /// Which terms reach the output: the rate ramp R, the bias instability B, the rate random walk
    /// K (an error budget's one term alone). The same numbers are drawn whichever do, so a term
    /// alone is that term of the full run.
    pub fn select(&mut self, ramp: bool, instability: bool, random_walk: bool) {
        self.gains = [ramp, instability, random_walk].map(|on| if on { 1.0 } else { 0.0 });
    }

    /// The additive error increments (rad | m/s) of the next sample: N, B, K, R (no quantization,
    /// no saturation). Advances one sample.
    pub fn next_error(&mut self) -> Vector3<f64> {
        let (tau0, k) = (self.tau0_s, self.k);
        self.k += 1;
        // Each term times its gain (1 or 0: x · 1 is x to the bit, a full run is unchanged).
        let [g_ramp, g_flicker, g_rrw] = self.gains;
        let ramp = self.terms.rate_ramp_si * tau0 * tau0 * (k as f64 + 0.5) * g_ramp;
        let kk = self.terms.rate_random_walk_si;
        let mut out = Vector3::zeros();
        for (o, ax) in out.iter_mut().zip(self.axes.iter_mut()) {
            let mut inc = ramp;
            if self.white_sigma > 0.0 {
                inc += self.white_sigma * ax.rng.sample::<f64, _>(StandardNormal);
            }
            for gm in &mut ax.flicker {
                let (z1, z2) = (ax.rng.sample(StandardNormal), ax.rng.sample(StandardNormal));
                inc += gm.step(z1, z2) * g_flicker;
            }
            if kk > 0.0 {
                let (z1, z2): (f64, f64) = (ax.rng.sample(StandardNormal), ax.rng.sample(StandardNormal));
                let v = kk * tau0 * tau0.sqrt() * (0.5 * z1 + z2 / (2.0 * 3f64.sqrt()));
                inc += (ax.rrw_rate * tau0 + v) * g_rrw;
                ax.rrw_rate += kk * tau0.sqrt() * z1;
            }
            *o = inc;
        }
        out
    }

    /// What the sensor outputs for the increments `v` (truth plus every error): clipped at
    /// ±saturation·τ0, then whole pulses with the remainder carried. A non-finite component passes
    /// through and leaves the quantizer untouched.
    pub fn output(&mut self, v: Vector3<f64>) -> Vector3<f64> {
        let mut out = v;
        for (o, ax) in out.iter_mut().zip(self.axes.iter_mut()) {
            if !o.is_finite() {
                continue;
            }
            if let Some(limit) = self.terms.saturation_si {
                let max_inc = limit * self.tau0_s;
                if o.abs() > max_inc {
                    *o = max_inc.copysign(*o);
                    ax.saturations += 1;
                }
            }
            if self.pulse > 0.0 {
                ax.carry += *o;
                let n = (ax.carry / self.pulse).round();
                ax.carry -= n * self.pulse;
                ax.pulses += n as i64;
                *o = n * self.pulse;
            }
        }
        out
    }

    /// The sensor's output for the true increments: `output(truth + next_error())`.
    pub fn apply(&mut self, true_increment: Vector3<f64>) -> Vector3<f64> {
        let e = self.next_error();
        self.output(true_increment + e)
    }

    /// The quantizer's remainder per axis (rad | m/s): Σ input − Σ output, |·| ≤ q/2.
    #[must_use]
    pub fn carry_si(&self) -> Vector3<f64> {
        Vector3::from_fn(|i, _| self.axes[i].carry)
    }

    /// Pulses output per axis (Σ output = pulses·q).
    #[must_use]
    pub fn pulse_counts(&self) -> [i64; 3] {
        self.axes.each_ref().map(|a| a.pulses)
    }

    /// Samples clipped per axis so far.
    #[must_use]
    pub fn saturation_counts(&self) -> [u64; 3] {
        self.axes.each_ref().map(|a| a.saturations)
    }
}
