//! Pure coning's analytic drift lines, drawn beside each algorithm's measured error on the log10
//! drift plot.

/// Pure coning's analytic drift lines: each algorithm's |heading error| grows at its rate
/// (`ins::coning::coning_drift_rate`, arcsec/s); in a live session whose cone or sample rate
/// changed, from what it had reached at the change (`base` at `since_s`) at the new rate.
#[derive(Debug, Clone)]
pub(crate) struct ConingLines {
    /// Each algorithm's analytic drift rate now, arcsec/s.
    pub(crate) rates: Vec<f64>,
    /// Since when, s.
    pub(crate) since_s: f64,
    /// Each line's value then, arcsec.
    pub(crate) base: Vec<f64>,
}

impl ConingLines {
    /// Lines from t = 0 at `rates`.
    pub(crate) fn new(rates: Vec<f64>) -> Self {
        let base = vec![0.0; rates.len()];
        Self { rates, since_s: 0.0, base }
    }

    /// Algorithm `j`'s analytic |heading error| at `t_s`, arcsec.
    pub(crate) fn at(&self, j: usize, t_s: f64) -> f64 {
        self.base[j] + self.rates[j] * (t_s - self.since_s)
    }

    /// From `t_s` on, the lines grow at `rates` from where they are.
    pub(crate) fn change(&mut self, t_s: f64, rates: Vec<f64>) {
        self.base = (0..self.rates.len()).map(|j| self.at(j, t_s)).collect();
        self.since_s = t_s;
        self.rates = rates;
    }
}

/// Each algorithm's analytic drift rate about the cone axis for the pure cone of `params` at its
/// step rate, arcsec/s (None without one).
pub(crate) fn coning_rates(
    params: &crate::scenario::Params,
    algorithms: &[crate::ins::coning::Algorithm],
) -> Option<Vec<f64>> {
    let cone = params.table.vehicle.pure_coning()?;
    let freq_hz = cone.omega_rad_per_s / std::f64::consts::TAU;
    Some(
        algorithms
            .iter()
            .map(|a| {
                crate::ins::coning::coning_drift_rate(*a, cone.half_angle_rad, freq_hz, 1.0 / params.step_hz).abs()
                    * crate::math::units::ARCSEC_PER_RAD
            })
            .collect(),
    )
}

/// The log10 plot of the coning drift: each algorithm's |heading error| beside its analytic rate × t.
pub(crate) const CONING_LOG_PATH: &str = "ins/coning_drift_log10_arcsec";
