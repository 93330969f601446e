//! Running statistics of a signal: root mean square and peak of |x|, in constant memory; whether
//! numbers are all finite.

/// Whether every value is finite, checked without an early exit (`&`, not `all`): the compiler
/// vectorises it, where a short-circuit was a branch per number (~10 instructions a value). For
/// checks on hot paths: a log's columns, the INS's state after every update.
#[inline]
#[must_use]
pub fn all_finite(values: &[f64]) -> bool {
    values.iter().fold(true, |all, x| all & x.is_finite())
}

/// Running RMS and peak of one error component (in the unit of what is added).
#[derive(Debug, Clone, Copy, Default)]
pub struct RunningStat {
    sum_sq: f64,
    peak_abs: f64,
    count: u64,
}

impl RunningStat {
    /// Adds one sample.
    #[inline]
    pub fn add(&mut self, x: f64) {
        self.sum_sq += x * x;
        self.peak_abs = self.peak_abs.max(x.abs());
        self.count += 1;
    }

    /// Root mean square of the samples (0 for none).
    #[must_use]
    pub fn rms(&self) -> f64 {
        if self.count == 0 { 0.0 } else { (self.sum_sq / self.count as f64).sqrt() }
    }

    /// Largest absolute sample.
    #[must_use]
    pub fn peak(&self) -> f64 {
        self.peak_abs
    }

    /// Number of samples.
    #[must_use]
    pub fn count(&self) -> u64 {
        self.count
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rms_and_peak_of_a_known_sequence() {
        // 3, -4: RMS = √((9 + 16) / 2) = √12.5, peak 4.
        let mut s = RunningStat::default();
        s.add(3.0);
        s.add(-4.0);
        assert!((s.rms() - 12.5f64.sqrt()).abs() < 1e-15);
        assert_eq!(s.peak(), 4.0);
        assert_eq!(s.count(), 2);
        assert_eq!(RunningStat::default().rms(), 0.0);
    }
}
