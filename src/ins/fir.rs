//! The anti-dither FIR filter of Li et al. 2014 §2.2, applied to each axis's increments, and its frequency
//! response. It is a low-pass filter (25 taps at 2 kHz, −4.4 dB at 100 Hz), not a notch filter: its
//! zeros on the unit circle sit at 343.5, 369.0 Hz and above 450 Hz, not at the three ring-laser-gyro
//! dither tones; at the tones (335.4, 375.5, 425.7 Hz) its stopband attenuates −91, −116, −106 dB.

use nalgebra::Vector3;

/// Li et al. 2014 §2.2, verbatim: 25 symmetric taps designed for 2 kHz data against the dither at 335.4,
/// 375.5 and 425.7 Hz, 100 Hz bandwidth (the paper calls them notches; see the module docs).
pub const SEED001_TAPS: [f64; 25] = [
    -3.6162e-4, -5.5582e-5, -4.6181e-4, 1.3181e-3, 4.3263e-3, 1.1456e-2, 2.3008e-2, 3.9629e-2, 6.0210e-2, 8.2250e-2,
    1.0213e-1, 1.1603e-1, 1.2103e-1, 1.1603e-1, 1.0213e-1, 8.2250e-2, 6.0210e-2, 3.9629e-2, 2.3008e-2, 1.1456e-2,
    4.3263e-3, 1.3181e-3, -4.6181e-4, -5.5582e-5, -3.6162e-4,
];

/// A FIR filter on 3-vectors. The taps are normalised to unit DC gain so that an increment stream
/// keeps its integral (the seed's printed taps sum to 0.99997).
#[derive(Debug, Clone)]
pub struct Fir {
    taps: Vec<f64>,
    history: Vec<Vector3<f64>>,
    head: usize,
}

impl Fir {
    /// A filter with these taps (empty or one tap: pass-through).
    #[must_use]
    pub fn new(taps: &[f64]) -> Self {
        let sum: f64 = taps.iter().sum();
        let taps: Vec<f64> =
            if taps.len() <= 1 || sum == 0.0 { vec![1.0] } else { taps.iter().map(|t| t / sum).collect() };
        let n = taps.len();
        Self { taps, history: vec![Vector3::zeros(); n], head: 0 }
    }

    /// Group delay, in samples: (taps − 1)/2 for the symmetric (linear-phase) filters used here.
    #[must_use]
    pub fn group_delay_samples(&self) -> f64 {
        (self.taps.len() as f64 - 1.0) / 2.0
    }

    /// Filters one sample.
    #[inline]
    pub fn push(&mut self, x: Vector3<f64>) -> Vector3<f64> {
        let n = self.taps.len();
        if n == 1 {
            return x;
        }
        self.history[self.head] = x;
        let mut y = Vector3::zeros();
        // taps[0] multiplies the newest sample.
        let mut idx = self.head;
        for t in &self.taps {
            y += self.history[idx] * *t;
            idx = if idx == 0 { n - 1 } else { idx - 1 };
        }
        self.head = (self.head + 1) % n;
        y
    }

    /// Pre-fills the history with `x` (a filter switched on long before t = 0).
    pub fn prime(&mut self, x: Vector3<f64>) {
        for h in &mut self.history {
            *h = x;
        }
    }

    /// |H(f)| for sampling at `fs_hz`.
    #[must_use]
    pub fn amplitude(&self, f_hz: f64, fs_hz: f64) -> f64 {
        let w = std::f64::consts::TAU * f_hz / fs_hz;
        let (mut re, mut im) = (0.0, 0.0);
        for (k, t) in self.taps.iter().enumerate() {
            re += t * (w * k as f64).cos();
            im -= t * (w * k as f64).sin();
        }
        re.hypot(im)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seed001_filter_suppresses_the_dither_tones() {
        // Li et al. 2014 §2.2: the three dither frequencies at 2 kHz fall in the stopband (the printed taps
        // were rounded to 5 digits); the attenuation there is deep (< -45 dB), not infinite. The passband keeps
        // low frequencies (0.5 Hz wobble: gain 1 to 1e-6).
        let f = Fir::new(&SEED001_TAPS);
        for tone in [335.4, 375.5, 425.7] {
            let db = 20.0 * f.amplitude(tone, 2000.0).log10();
            assert!(db < -90.0, "{tone} Hz: {db:.1} dB");
        }
        assert!((f.amplitude(0.5, 2000.0) - 1.0).abs() < 2e-5);
        assert!((20.0 * f.amplitude(100.0, 2000.0).log10() + 4.36).abs() < 0.05);
        // "extra attenuation at least 50 dB in the band 320-420 Hz" (Li et al. 2014 §2.2, about the new filter).
        let worst =
            (320..=420).map(|f_hz| 20.0 * f.amplitude(f64::from(f_hz), 2000.0).log10()).fold(f64::MIN, f64::max);
        assert!(worst < -70.0, "worst in band {worst:.1} dB");
    }

    #[test]
    fn group_delay_is_twelve_samples_six_ms_at_2khz() {
        // Li et al. 2014 §3.1(c): "Its group delay is 12. The time delay is 6 ms if the sampling frequency is 2 kHz."
        let mut f = Fir::new(&SEED001_TAPS);
        assert_eq!(f.group_delay_samples(), 12.0);
        // An impulse comes out centred 12 samples later (symmetric taps).
        let mut out = Vec::new();
        for i in 0..25 {
            out.push(f.push(if i == 0 { Vector3::new(1.0, 0.0, 0.0) } else { Vector3::zeros() }).x);
        }
        let peak = out.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)).map(|(i, _)| i);
        assert_eq!(peak, Some(12));
        // A ramp is delayed by exactly 12 samples.
        let mut f = Fir::new(&SEED001_TAPS);
        let mut last = 0.0;
        for i in 0..100 {
            last = f.push(Vector3::new(f64::from(i), 0.0, 0.0)).x;
        }
        assert!((last - (99.0 - 12.0)).abs() < 1e-9, "{last}");
    }
}
