//! The one sampling rule of a run, used by every command.
//!
//! A run of `duration_s` at `rate_hz` has `n = round(duration_s · rate_hz)` intervals and the
//! instants `t_k = k / rate_hz`, `k = 0..=n`. Quantities that exist at an instant (the turntable's
//! truth, an encoder reading, the ideal-INS error) are evaluated at all `n + 1` instants; quantities
//! that belong to an interval (an IMU sample: the increments from `t_{k−1}` to `t_k`) exist for
//! `k = 1..=n`. Both end at `t_n`, the run's duration.

/// The instants of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timeline {
    rate_hz: f64,
    intervals: u64,
}

impl Timeline {
    /// `duration_s` at `rate_hz` (both positive; validated where they are read).
    #[must_use]
    pub fn new(duration_s: f64, rate_hz: f64) -> Self {
        // The scenario's validation bounds duration · rate to 2e9, so the cast cannot overflow.
        Self { rate_hz, intervals: (duration_s * rate_hz).round().max(0.0) as u64 }
    }

    /// Number of intervals `n` (= IMU samples, `k = 1..=n`).
    #[must_use]
    pub fn intervals(&self) -> u64 {
        self.intervals
    }

    /// Number of instants `n + 1` (`k = 0..=n`).
    #[must_use]
    pub fn instants(&self) -> u64 {
        self.intervals + 1
    }

    /// The instant `t_k`, s.
    #[must_use]
    pub fn t_s(&self, k: u64) -> f64 {
        k as f64 / self.rate_hz
    }

    /// The last instant `t_n`, s.
    #[must_use]
    pub fn end_s(&self) -> f64 {
        self.t_s(self.intervals)
    }

    /// The rate, Hz.
    #[must_use]
    pub fn rate_hz(&self) -> f64 {
        self.rate_hz
    }
}

/// Decimation of a step rate to an output rate: every `n`-th step (at least every step).
#[must_use]
pub fn decimation(step_hz: f64, output_hz: f64) -> u64 {
    let ratio = step_hz / output_hz;
    // A ratio beyond u64 (output_hz ~ 1e-300) means "once": the first step only.
    if !(ratio.is_finite() && ratio < 1e18) { u64::MAX } else { (ratio.round() as u64).max(1) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn instants_and_intervals_of_a_run() {
        // 360 s at 200 Hz: 72 000 intervals, 72 001 instants, ending at 360 s.
        let t = Timeline::new(360.0, 200.0);
        assert_eq!(t.intervals(), 72_000);
        assert_eq!(t.instants(), 72_001);
        assert_eq!(t.end_s(), 360.0);
        assert_eq!(t.t_s(1), 0.005);
    }

    #[test]
    fn decimation_rounds_to_whole_steps() {
        assert_eq!(decimation(200.0, 100.0), 2);
        assert_eq!(decimation(200.0, 25.0), 8);
        assert_eq!(decimation(200.0, 30.0), 7);
        assert_eq!(decimation(200.0, 500.0), 1);
        assert_eq!(decimation(200.0, 1e-300), u64::MAX);
    }
}
