//! Fit of the IEEE noise coefficients to an Allan variance curve: weighted
//! non-negative least squares with model selection (primary estimate) and the
//! classic slope-line readings (secondary estimate).

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::{AllanCurve, Estimate, NoiseCoefficients, NoiseTerm, TERMS, edf_overlapping};

/// Local-slope tolerance (in decades per decade) for [`SlopeReading::matched`].
pub const SLOPE_MATCH_TOLERANCE: f64 = 0.1;
/// z-score c²/σ(c²) a fitted term needs to be significant.
pub const SIGNIFICANCE_Z: f64 = 3.0;

/// Result of [`fit_noise_model`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoiseFit {
    /// The coefficients (SI).
    pub coefficients: NoiseCoefficients,
    /// EDF per curve point of the fitted noise mixture (see [`fit_noise_model`]).
    pub edf: Vec<f64>,
    /// Dominant fitted term per curve point.
    pub dominant: Vec<NoiseTerm>,
    /// Weighted residual sum of squares / (points − active terms).
    pub chi2_per_dof: f64,
    /// Where the data contradict a term or every IEEE combination (see [`check_claims`]).
    #[serde(default)]
    pub contradictions: Vec<Contradiction>,
}

/// A τ range where the measured curve contradicts a fitted term (its asymptote lies above the
/// curve's upper bound: a term can never exceed the total it is part of) or the fitted model as a
/// whole (the curve leaves the model's interval: not a stationary record of IEEE terms there).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Contradiction {
    /// The term, or None for the model as a whole.
    pub term: Option<NoiseTerm>,
    /// The first cluster time of the range, s.
    pub tau_from_s: f64,
    /// The last, s.
    pub tau_to_s: f64,
    /// The largest factor between the two deviations in the range (≥ 1).
    pub worst_factor: f64,
}

impl Contradiction {
    /// One sentence for people.
    #[must_use]
    pub fn text(&self) -> String {
        match self.term {
            Some(t) => format!(
                "{} would lie up to {:.1}× above the measured curve between τ = {:.4} s and {:.4} s (beyond its {:.0}σ bound): not reported as found",
                t.letter(),
                self.worst_factor,
                self.tau_from_s,
                self.tau_to_s,
                CLAIM_Z
            ),
            None if self.worst_factor.is_infinite() => format!(
                "between τ = {:.4} s and {:.4} s no IEEE term the data allow describes the curve: not a stationary record of IEEE noise there (a trend, a disturbance, a periodic signal?); the slope readings are still shown",
                self.tau_from_s, self.tau_to_s
            ),
            None => format!(
                "between τ = {:.4} s and {:.4} s the curve leaves every IEEE combination fitted (up to {:.1}× outside the model's {:.0}σ band): not a stationary record of these terms there (a trend, a disturbance, a periodic signal?)",
                self.tau_from_s, self.tau_to_s, self.worst_factor, CLAIM_Z
            ),
        }
    }
}

/// How far (in σ of the χ² interval) a term's asymptote or the model may lie from the measured
/// curve before the data are said to contradict it.
pub const CLAIM_Z: f64 = 3.0;

/// The runs of consecutive points where `factor(j)` exceeds 1, as contradictions of `term`.
fn runs(taus: &[f64], term: Option<NoiseTerm>, factor: impl Fn(usize) -> f64) -> Vec<Contradiction> {
    let mut out: Vec<Contradiction> = Vec::new();
    let mut open = false;
    for (j, tau) in taus.iter().enumerate() {
        let f = factor(j);
        if f > 1.0 {
            match out.last_mut().filter(|_| open) {
                Some(c) => {
                    c.tau_to_s = *tau;
                    c.worst_factor = c.worst_factor.max(f);
                }
                None => out.push(Contradiction { term, tau_from_s: *tau, tau_to_s: *tau, worst_factor: f }),
            }
            open = true;
        } else {
            open = false;
        }
    }
    out
}

/// A fit is a claim: every term reported as found must stay under the measured curve's upper
/// bound (at [`CLAIM_Z`]σ, with the point's EDF) at every τ — each term is a part of the total —,
/// and the model as a whole must pass through the curve's intervals; where not, say so.
/// Returns the terms' contradictions and the model's.
#[must_use]
pub fn check_claims(curve: &AllanCurve, fit: &NoiseFit) -> (Vec<Contradiction>, Vec<Contradiction>) {
    let np = curve.taus_s.len().min(fit.edf.len());
    let taus = &curve.taus_s[..np];
    let bounds: Vec<(f64, f64)> =
        (0..np).map(|j| super::adev_confidence(curve.avar_si[j].sqrt(), fit.edf[j], CLAIM_Z)).collect();
    let mut terms = Vec::new();
    for t in TERMS {
        let e = fit.coefficients.get(t);
        if !e.significant {
            continue;
        }
        // The coefficient at its own 2σ low end: a term contradicted only by its fit's scatter is not.
        let low = (e.value - 2.0 * e.sigma).max(0.0);
        terms.extend(runs(taus, Some(t), |j| t.avar(low, taus[j]).sqrt() / bounds[j].1.max(f64::MIN_POSITIVE)));
    }
    let model = runs(taus, None, |j| {
        let m = fit.coefficients.avar(taus[j]).sqrt();
        let (lo, hi) = bounds[j];
        // No term left at all: every point with signal is outside (a factor shown as the curve's
        // lower bound over the tiniest fitted level, i.e. "infinitely").
        if m > hi {
            m / hi.max(f64::MIN_POSITIVE)
        } else if m < lo {
            if m > 0.0 { lo / m } else { f64::INFINITY }
        } else {
            0.0
        }
    });
    // The model's band is two-sided at 3σ on ~40 correlated points per curve: a lone point just
    // outside is what chance gives about once per report; a contradiction is a run of points, or
    // one point well outside.
    let model = model
        .into_iter()
        .filter(|c| c.worst_factor >= 1.1 && (c.tau_to_s > c.tau_from_s || c.worst_factor >= 1.5))
        .collect();
    (terms, model)
}

/// Non-negative least squares min ‖Ax − b‖, x ≥ 0 (Lawson & Hanson 1974, ch. 23
/// active set), with unit-norm column scaling and SVD sub-solves.
fn nnls(a: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
    let (rows, n) = a.shape();
    let norms: Vec<f64> = (0..n).map(|k| a.column(k).norm()).collect();
    let an = DMatrix::from_fn(rows, n, |i, k| if norms[k] > 0.0 { a[(i, k)] / norms[k] } else { 0.0 });
    let solve = |passive: &[bool]| -> DVector<f64> {
        let idx: Vec<usize> = (0..n).filter(|&k| passive[k]).collect();
        let sub = DMatrix::from_fn(rows, idx.len(), |i, c| an[(i, idx[c])]);
        let mut z = DVector::zeros(n);
        if let Ok(s) = sub.svd(true, true).solve(b, 1e-15) {
            for (c, &k) in idx.iter().enumerate() {
                z[k] = s[c];
            }
        }
        z
    };
    let mut x = DVector::zeros(n);
    let mut passive = vec![false; n];
    let mut excluded = vec![false; n];
    let tol = 1e-12 * b.norm().max(f64::MIN_POSITIVE);
    for _ in 0..4 * n + 4 {
        let w = an.transpose() * (b - &an * &x);
        let cand = (0..n).filter(|&k| !passive[k] && !excluded[k] && norms[k] > 0.0 && w[k] > tol);
        let Some(t) = cand.max_by(|&i, &j| w[i].total_cmp(&w[j])) else {
            break;
        };
        passive[t] = true;
        for inner in 0..4 * n + 4 {
            let z = solve(&passive);
            if (0..n).all(|k| !passive[k] || z[k] > 0.0) {
                x = z;
                excluded.iter_mut().for_each(|e| *e = false);
                break;
            }
            if inner == 0 && z[t] <= 0.0 {
                passive[t] = false;
                excluded[t] = true;
                break;
            }
            let alpha =
                (0..n).filter(|&k| passive[k] && z[k] <= 0.0).map(|k| x[k] / (x[k] - z[k])).fold(1.0f64, f64::min);
            x += (z - &x) * alpha;
            for k in 0..n {
                if passive[k] && x[k] <= 1e-15 * x.amax() {
                    passive[k] = false;
                    x[k] = 0.0;
                }
            }
        }
    }
    DVector::from_fn(n, |k, _| if norms[k] > 0.0 { x[k].max(0.0) / norms[k] } else { 0.0 })
}

/// Weighted least-squares fit of σ²(τ) = Σ a_i c_i² τ^{p_i}, p = −2..=2, with
/// c_i² ≥ 0 (NNLS) to the curve. Weights 1/sd²: a term μ_i estimated with
/// EDF_i has sd μ_i√(2/EDF_i) (χ²); for the mixture the sds are added,
/// sd = Σ μ_i√(2/EDF_i) (exact for fully correlated errors, and what the
/// cross terms give if EDF_ij ≈ √(EDF_i·EDF_j)), i.e. EDF = 2(Σμ_i)²/sd².
/// EDF_i per [`edf_overlapping`] with the term's noise type. Starts from the
/// data with white-rate EDF, then iterates with model-based weights until the
/// model settles (≤ 30 passes).
///
/// Uncertainty: covariance (AᵀWA)⁻¹ of the active terms, inflated by
/// √max(1, χ²/dof); σ(c) = σ(c²)/(2c). A zero coefficient gets √σ(c²) (its
/// column added to the active ones) as its 1σ detection limit.
/// Significant: c² ≥ [`SIGNIFICANCE_Z`]·σ(c²) and the term is the largest
/// contributor at ≥ 2 cluster times (a single-point upturn at the longest τ,
/// EDF ≈ 2, is not evidence of a term).
/// Model selection: insignificant terms are dropped and the fit repeated
/// until the set is stable; dropped terms are reported as 0 ± detection limit.
/// Caveat: overlapping-ADEV points at neighbouring τ are correlated, which the
/// covariance ignores: in Monte-Carlo runs (the tests' 40-seed study, docs/allan.md) the scatter
/// of K is ≈ 1.6× the reported σ, hence z = 3 for significance.
#[must_use]
pub fn fit_noise_model(curve: &AllanCurve) -> NoiseFit {
    let mut allowed = [true; 5];
    let mut fit = fit_pass(curve, allowed);
    let mut refuted: Vec<Contradiction> = Vec::new();
    for _ in 0..8 {
        let keep = TERMS.map(|t| fit.coefficients.get(t).significant);
        // A term the data contradict is dropped like an insignificant one, and said.
        let (against, _) = check_claims(curve, &fit);
        let keep: [bool; 5] = std::array::from_fn(|k| keep[k] && !against.iter().any(|c| c.term == Some(TERMS[k])));
        refuted.extend(against);
        if keep == allowed || !keep.contains(&true) {
            break;
        }
        allowed = keep;
        fit = fit_pass(curve, allowed);
    }
    for c in &refuted {
        if let Some(t) = c.term {
            let e = fit.coefficients.get(t);
            if e.significant {
                set_significant(&mut fit.coefficients, t, false);
            }
        }
    }
    let (_, model) = check_claims(curve, &fit);
    fit.contradictions = refuted.into_iter().chain(model).collect();
    fit
}

fn set_significant(c: &mut NoiseCoefficients, t: NoiseTerm, found: bool) {
    let e = match t {
        NoiseTerm::Quantization => &mut c.q_si,
        NoiseTerm::RandomWalk => &mut c.n_si,
        NoiseTerm::BiasInstability => &mut c.b_si,
        NoiseTerm::RateRandomWalk => &mut c.k_si,
        NoiseTerm::RateRamp => &mut c.r_si,
    };
    e.significant = found;
}

/// One weighted NNLS fit restricted to the `allowed` terms (see [`fit_noise_model`]).
fn fit_pass(curve: &AllanCurve, allowed: [bool; 5]) -> NoiseFit {
    let np = curve.taus_s.len().min(curve.avar_si.len()).min(curve.m.len());
    let y = &curve.avar_si;
    let ymax = y.iter().copied().fold(0.0f64, f64::max);
    let x = |j: usize, k: usize| TERMS[k].avar(1.0, curve.taus_s[j]);
    let edf_of = |j: usize, t: NoiseTerm| edf_overlapping(curve.n_samples, curve.m[j], t.noise_type());
    let floor = (ymax * 1e-12).max(f64::MIN_POSITIVE);
    let mut theta = DVector::<f64>::zeros(5);
    let mut model: Vec<f64> = y.clone();
    let mut dominant = vec![NoiseTerm::RandomWalk; np];
    let mut edf: Vec<f64> = (0..np).map(|j| edf_of(j, NoiseTerm::RandomWalk)).collect();
    let mut sd: Vec<f64> = (0..np).map(|j| y[j].max(floor) * (2.0 / edf[j]).sqrt()).collect();
    let mut a = DMatrix::<f64>::zeros(np, 5);
    let mut b = DVector::<f64>::zeros(np);
    for _ in 0..30 {
        for j in 0..np {
            b[j] = y[j] / sd[j];
            for k in 0..5 {
                a[(j, k)] = x(j, k) / sd[j];
            }
        }
        let masked = DMatrix::from_fn(np, 5, |j, k| if allowed[k] { a[(j, k)] } else { 0.0 });
        theta = if ymax > 0.0 { nnls(&masked, &b) } else { DVector::zeros(5) };
        let mut change = 0.0f64;
        for j in 0..np {
            let parts: Vec<f64> = (0..5).map(|k| x(j, k) * theta[k]).collect();
            let new: f64 = parts.iter().sum();
            change = change.max((new - model[j]).abs() / model[j].max(new).max(f64::MIN_POSITIVE));
            model[j] = new;
            if new > 0.0 {
                let best = (0..5).max_by(|&p, &q| parts[p].total_cmp(&parts[q])).unwrap_or(1);
                dominant[j] = TERMS[best];
                let s: f64 = (0..5).map(|k| parts[k] * (2.0 / edf_of(j, TERMS[k])).sqrt()).sum();
                edf[j] = (2.0 * new * new / (s * s)).max(1.0);
                sd[j] = s.max(floor);
            }
        }
        if change < 1e-9 {
            break;
        }
    }
    let r = &b - &a * &theta;
    let active: Vec<usize> = (0..5).filter(|&k| theta[k] > 0.0).collect();
    let dof = np.saturating_sub(active.len()).max(1);
    // A curve of zeros (a constant channel: a simulation's error-free sensor) is fitted exactly by
    // no term; its weights are 1/0, so its χ² is said, not computed.
    let chi2_per_dof = if ymax > 0.0 { r.norm_squared() / dof as f64 } else { 0.0 };
    let inflate = chi2_per_dof.max(1.0);
    let variance_of = |k: usize| -> f64 {
        let mut cols = active.clone();
        if !cols.contains(&k) {
            cols.push(k);
        }
        let norm = |c: usize| a.column(c).norm().max(f64::MIN_POSITIVE);
        let sub = DMatrix::from_fn(np, cols.len(), |i, c| a[(i, cols[c])] / norm(cols[c]));
        let pos = cols.iter().position(|&c| c == k).unwrap_or(0);
        let n = cols.len();
        let cov = (sub.transpose() * &sub).pseudo_inverse(1e-14).unwrap_or_else(|_| DMatrix::zeros(n, n));
        cov[(pos, pos)].max(0.0) * inflate / (norm(k) * norm(k))
    };
    let est = |k: usize| -> Estimate {
        let sd_t = variance_of(k).sqrt();
        let value = theta[k].sqrt();
        let sigma = if value > 0.0 { sd_t / (2.0 * value) } else { sd_t.sqrt() };
        let dominated = dominant.iter().filter(|&&d| d == TERMS[k]).count();
        let significant = theta[k] > 0.0 && theta[k] >= SIGNIFICANCE_Z * sd_t && dominated >= 2.min(np);
        Estimate { value, sigma, significant }
    };
    let coefficients = NoiseCoefficients { q_si: est(0), n_si: est(1), b_si: est(2), k_si: est(3), r_si: est(4) };
    NoiseFit { coefficients, edf, dominant, chi2_per_dof, contradictions: Vec::new() }
}

/// Classic slope-line reading of one coefficient.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SlopeReading {
    /// Coefficient in SI (same units as [`NoiseCoefficients`]).
    pub value_si: f64,
    /// 1σ from the CI half-width at the point read.
    pub sigma_si: f64,
    /// τ of the point read (s).
    pub tau_s: f64,
    /// Local log-log slope of the ADEV there.
    pub local_slope: f64,
    /// Nominal ADEV slope of the term (−1, −1/2, 0, 1/2, 1).
    pub nominal_slope: f64,
    /// |local − nominal| ≤ [`SLOPE_MATCH_TOLERANCE`]: the curve has that slope.
    pub matched: bool,
}

/// Slope readings of all five terms (`None` if the curve has < 2 positive points).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SlopeReadings {
    /// Q, read on the slope −1.
    pub q_si: Option<SlopeReading>,
    /// N, read on the slope −1/2 (the line at τ = 1 s).
    pub n_si: Option<SlopeReading>,
    /// B, read at the flattest point.
    pub b_si: Option<SlopeReading>,
    /// K, read on the slope +1/2 (the line at τ = 3 s).
    pub k_si: Option<SlopeReading>,
    /// R, read on the slope +1.
    pub r_si: Option<SlopeReading>,
}

impl SlopeReadings {
    /// The reading of one term.
    #[must_use]
    pub fn get(&self, term: NoiseTerm) -> Option<SlopeReading> {
        [self.q_si, self.n_si, self.b_si, self.k_si, self.r_si][term as usize]
    }
}

/// Slope-line readings: for each term, among the points whose local log-log
/// ADEV slope (central difference, one-sided at the ends) is within
/// [`SLOPE_MATCH_TOLERANCE`] of the nominal one, the one with the narrowest
/// relative CI (if none is, the point with the closest slope, `matched` false);
/// the coefficient is the term's line through that point, i.e. N = σ(τ)√τ
/// (the line read at τ = 1 s), K = σ√(3/τ) (read at τ = 3 s), Q = στ/√3,
/// B = σ/0.664, R = σ√2/τ. `adev_si`, `lower_si`, `upper_si` in rate units
/// (rad/s | m/s²), `taus_s` in s; slices of unequal length are cut to the shortest.
#[must_use]
pub fn slope_readings(taus_s: &[f64], adev_si: &[f64], lower_si: &[f64], upper_si: &[f64]) -> SlopeReadings {
    let n = taus_s.len().min(adev_si.len()).min(lower_si.len()).min(upper_si.len());
    let pts: Vec<usize> = (0..n).filter(|&j| adev_si[j] > 0.0 && taus_s[j] > 0.0).collect();
    let read = |term: NoiseTerm| -> Option<SlopeReading> {
        if pts.len() < 2 {
            return None;
        }
        let nominal = f64::from(term.exponent()) / 2.0;
        let slope = |i: usize| {
            let (p, q) = (pts[i.saturating_sub(1)], pts[(i + 1).min(pts.len() - 1)]);
            (adev_si[q] / adev_si[p]).ln() / (taus_s[q] / taus_s[p]).ln()
        };
        let miss = |i: usize| (slope(i) - nominal).abs();
        let rel_ci = |i: usize| (upper_si[pts[i]] - lower_si[pts[i]]) / adev_si[pts[i]];
        let within: Vec<usize> = (0..pts.len()).filter(|&i| miss(i) <= SLOPE_MATCH_TOLERANCE).collect();
        let i = if within.is_empty() {
            (0..pts.len()).min_by(|&a, &b| miss(a).total_cmp(&miss(b)))?
        } else {
            within.into_iter().min_by(|&a, &b| rel_ci(a).total_cmp(&rel_ci(b)))?
        };
        let j = pts[i];
        let value_si = adev_si[j] / term.avar(1.0, taus_s[j]).sqrt();
        Some(SlopeReading {
            value_si,
            sigma_si: value_si * (upper_si[j] - lower_si[j]) / (2.0 * adev_si[j]),
            tau_s: taus_s[j],
            local_slope: slope(i),
            nominal_slope: nominal,
            matched: (slope(i) - nominal).abs() <= SLOPE_MATCH_TOLERANCE,
        })
    };
    SlopeReadings {
        q_si: read(NoiseTerm::Quantization),
        n_si: read(NoiseTerm::RandomWalk),
        b_si: read(NoiseTerm::BiasInstability),
        k_si: read(NoiseTerm::RateRandomWalk),
        r_si: read(NoiseTerm::RateRamp),
    }
}
