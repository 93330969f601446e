//! What a calibration means: the physical angles with 1σ, the paper's state (Jiang et al. 2017 eq. 29, 34),
//! the observability analysis, the compensation before/after, as text and JSON.

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use serde::Serialize;

use super::{Calibration, ErrorSummary, Estimate, Param};
use crate::math::units::{ARCSEC_PER_RAD, DEG_PER_RAD};
use crate::model::gimbal::{Chain, TableErrors};

/// A function of the parameter vector.
type ParamFn = Box<dyn Fn(&[f64]) -> f64>;

/// A value with its 1σ, in the unit its field names.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct Value {
    /// Estimate.
    pub value: f64,
    /// 1σ.
    pub sigma: f64,
}

/// One row of a result table: a quantity, its true value, both estimators.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// Machine key.
    pub key: String,
    /// For people.
    pub label: String,
    /// Unit of every number in the row ("arcsec" or "deg").
    pub unit: &'static str,
    /// The simulation's true value.
    pub truth: f64,
    /// The static Kalman filter.
    pub kf: Value,
    /// Least squares on the exact model.
    pub nls: Value,
    /// Empty, or why the number must not be trusted.
    pub flag: String,
}

impl Row {
    /// Least-squares error (estimate − truth).
    #[must_use]
    pub fn nls_error(&self) -> f64 {
        self.nls.value - self.truth
    }

    /// Filter error (estimate − truth).
    #[must_use]
    pub fn kf_error(&self) -> f64 {
        self.kf.value - self.truth
    }
}

/// A direction of the parameter space the data do not determine.
#[derive(Debug, Clone, Serialize)]
pub struct Unobservable {
    /// (key, coefficient) of the unit direction.
    pub direction: Vec<(String, f64)>,
    /// 1σ the data alone give along it, arcsec (infinite: nothing).
    pub data_sigma_arcsec: f64,
    /// The prior's 1σ along it, arcsec.
    pub prior_sigma_arcsec: f64,
    /// The combination the data do determine, when the direction mixes two parameters.
    pub determined: Option<(String, Value)>,
    /// The prior pins the direction (e.g. η given by an independent measurement): every parameter
    /// in it is then known about as well as the observable ones.
    pub resolved_by_prior: bool,
}

/// Attitude error of the validation run for each demodulation (the summaries hold radians).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Compensation {
    /// Table model with the estimated parameters at zero.
    pub before: ErrorSummary,
    /// With the filter's estimates.
    pub after_kf: ErrorSummary,
    /// With the least-squares estimates.
    pub after_nls: ErrorSummary,
    /// With the true parameters: the floor set by the noise.
    pub with_truth: ErrorSummary,
}

/// Jiang et al. 2017 §6.2.2, laboratory: peak attitude error before → after compensation, arcsec
/// (pitch 1.6′ → 25.2″, roll 1.86′ → 30.24″, heading 2.5′ → 49.32″).
pub const PAPER_LAB: [(f64, f64); 3] = [(96.0, 25.2), (111.6, 30.24), (150.0, 49.32)];

/// The whole report.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// Scenario.
    pub scenario: String,
    /// Noise seed of the calibration data.
    pub seed: u64,
    /// "INS" or "exact IMU attitude".
    pub source: String,
    /// Measurements used.
    pub samples: usize,
    /// Test duration, s.
    pub duration_s: f64,
    /// R: 1σ per component, arcsec.
    pub measurement_sigma_arcsec: f64,
    /// The INS's angle random walk the 1σ allow for, °/√h (0: not modelled).
    pub ins_random_walk_deg_per_sqrt_h: f64,
    /// The INS's unknown gyro bias (1σ per axis) the 1σ allow for, °/h (0: not modelled).
    pub ins_bias_deg_per_h: f64,
    /// What the 1σ include, in words (the per-sample R, and the INS's error through the test or
    /// that it is not modelled).
    pub sigma_basis: String,
    /// Gauss–Newton iterations.
    pub nls_iterations: usize,
    /// Residual RMS (E, N, U) of the filter's and the least squares' solutions, arcsec.
    pub residual_rms_arcsec: [[f64; 3]; 2],
    /// The state vector (table parameters and nuisance), arcsec.
    pub state: Vec<Row>,
    /// The physical angles: α (arcsec), φ (deg), η (arcsec).
    pub angles: Vec<Row>,
    /// Jiang et al. 2017's state X (eq. 29), when the table has two axes, arcsec.
    pub paper_state: Vec<Row>,
    /// Directions the data do not determine.
    pub unobservable: Vec<Unobservable>,
    /// Everything a user must know before using the numbers.
    pub warnings: Vec<String>,
    /// Facts about the test that are not problems (a non-separable pair resolved by the prior).
    pub notes: Vec<String>,
    /// Attitude error of an independent run (other noise seed), demodulated four ways.
    pub compensation: Option<Compensation>,
    /// What 1″ of each error the calibration does not estimate would do to its estimates.
    pub aliases: Vec<super::alias::Alias>,
}

fn value(est: &Estimate, i: usize, scale: f64) -> Value {
    Value { value: est.theta[i] * scale, sigma: est.sigma(i) * scale }
}

/// A function of the parameters propagated to first order: value and 1σ from the gradient.
pub(crate) fn propagate(est: &Estimate, f: &dyn Fn(&[f64]) -> f64, scale: f64) -> Value {
    let x = &est.theta;
    let v = f(x);
    let mut grad = DVector::zeros(x.len());
    for i in 0..x.len() {
        let h = 1e-9_f64.max(x[i].abs() * 1e-6);
        let mut xp = x.clone();
        let mut xm = x.clone();
        xp[i] += h;
        xm[i] -= h;
        grad[i] = (f(&xp) - f(&xm)) / (2.0 * h);
    }
    let var = (grad.transpose() * &est.cov * &grad)[(0, 0)];
    Value { value: v * scale, sigma: var.max(0.0).sqrt() * scale }
}

/// Nuisance states marginalised out: the information the data hold on the table's parameters alone.
fn table_information(cal: &Calibration) -> DMatrix<f64> {
    let n = cal.set.n_table;
    let p = cal.set.len();
    let d = &cal.data_information;
    let tt = d.view((0, 0), (n, n)).into_owned();
    if p == n {
        return tt;
    }
    let tn = d.view((0, n), (n, p - n)).into_owned();
    let nn = d.view((n, n), (p - n, p - n)).into_owned();
    match nn.try_inverse() {
        Some(inv) => &tt - &tn * inv * tn.transpose(),
        None => tt,
    }
}

/// The directions along which the data add less than a factor 2 to the prior.
fn unobservable(cal: &Calibration, chain: &Chain) -> Vec<Unobservable> {
    let n = cal.set.n_table;
    let info = table_information(cal);
    let eig = SymmetricEigen::new(info);
    let mut out = Vec::new();
    for (k, mu) in eig.eigenvalues.iter().enumerate() {
        let v = eig.eigenvectors.column(k).into_owned();
        let prior_var: f64 = (0..n).map(|i| v[i] * v[i] * cal.prior.1[i].powi(2)).sum();
        let data_sigma = if *mu > 0.0 { 1.0 / mu.sqrt() } else { f64::INFINITY };
        if data_sigma < 0.5 * prior_var.sqrt() {
            continue;
        }
        // Sign convention: largest component positive.
        let sign = if v.iter().fold(0.0f64, |m, x| if x.abs() > m.abs() { *x } else { m }) < 0.0 { -1.0 } else { 1.0 };
        let comps: Vec<(usize, f64)> = (0..n).map(|i| (i, v[i] * sign)).filter(|(_, c)| c.abs() > 0.1).collect();
        let determined = if comps.len() == 2 {
            let ((i, ci), (j, cj)) = (comps[0], comps[1]);
            // Orthogonal to the direction within its plane, scaled so its larger coefficient is ±1:
            // w = (cj e_i − ci e_j)/max(|ci|, |cj|).
            let norm = ci.abs().max(cj.abs());
            let (wi, wj) = (cj / norm, -ci / norm);
            let est = &cal.nls;
            let val = wi * est.theta[i] + wj * est.theta[j];
            let var = wi * wi * est.cov[(i, i)] + wj * wj * est.cov[(j, j)] + 2.0 * wi * wj * est.cov[(i, j)];
            let term = |c: f64, label: String| {
                if (c.abs() - 1.0).abs() < 1e-3 {
                    format!("{} {label}", if c < 0.0 { "−" } else { "+" })
                } else {
                    format!("{c:+.3}·{label}")
                }
            };
            let name =
                format!("{} {}", term(wi, cal.set.params[i].label(chain)), term(wj, cal.set.params[j].label(chain)));
            let name = name.trim_start_matches("+ ").to_owned();
            Some((name, Value { value: val * ARCSEC_PER_RAD, sigma: var.max(0.0).sqrt() * ARCSEC_PER_RAD }))
        } else {
            None
        };
        // Resolved when the posterior 1σ of each parameter in the direction is within 3× the worst of
        // the table parameters outside it: the prior then pins it as well as the data pin the rest.
        let inside: Vec<usize> = comps.iter().map(|(i, _)| *i).collect();
        let outside_worst = (0..n).filter(|i| !inside.contains(i)).map(|i| cal.nls.sigma(i)).fold(0.0, f64::max);
        let resolved_by_prior = outside_worst > 0.0 && inside.iter().all(|&i| cal.nls.sigma(i) < 3.0 * outside_worst);
        out.push(Unobservable {
            resolved_by_prior,
            direction: comps
                .iter()
                .map(|(i, c)| (cal.set.params[*i].key(chain), (c * 1000.0).round() / 1000.0))
                .collect(),
            data_sigma_arcsec: data_sigma * ARCSEC_PER_RAD,
            prior_sigma_arcsec: prior_var.sqrt() * ARCSEC_PER_RAD,
            determined,
        });
    }
    out
}

/// The non-orthogonality the data see on axis k: η_k plus the previous rotor's swing component about
/// the same tilt axis u_k = a_k × a_{k−1} (both are rotor-fixed rotations of gimbal k−1, composed
/// side by side in the chain: only their sum acts; docs/calibration.md).
#[must_use]
pub fn effective_eta(chain: &Chain, set: &super::ParamSet, k: usize) -> Option<impl Fn(&[f64]) -> f64 + use<>> {
    let ie = set.index(Param::NonOrth(k))?;
    let (ic, is) = (set.index(Param::SwingCos(k - 1))?, set.index(Param::SwingSin(k - 1))?);
    let u = chain.non_orthogonality_axis(k);
    let prev = &chain.axes()[k - 1];
    let (cc, cs) = (prev.e1.dot(&u), prev.e2.dot(&u));
    Some(move |x: &[f64]| x[ie] + cc * x[ic] + cs * x[is])
}

/// Builds the report of a calibration against the true errors.
#[must_use]
pub fn build(
    scenario: &str,
    chain: &Chain,
    truth: &TableErrors,
    cal: &Calibration,
    data: &super::Data,
    compensation: Option<Compensation>,
) -> Report {
    let set = &cal.set;
    let true_values = set.values(truth);
    let mut warnings = Vec::new();
    // Per state: is it the prior speaking, alone or through an unobservable combination?
    let unobs = unobservable(cal, chain);
    let prior_dominated: Vec<bool> = (0..set.len())
        .map(|i| {
            let key = set.params[i].key(chain);
            cal.nls.sigma(i) > 0.5 * cal.prior.1[i]
                || unobs.iter().any(|u| !u.resolved_by_prior && u.direction.iter().any(|(k, _)| *k == key))
        })
        .collect();
    let state: Vec<Row> = set
        .params
        .iter()
        .enumerate()
        .map(|(i, p)| Row {
            key: p.key(chain),
            label: p.label(chain),
            unit: "arcsec",
            truth: true_values[i] * ARCSEC_PER_RAD,
            kf: value(&cal.kf, i, ARCSEC_PER_RAD),
            nls: value(&cal.nls, i, ARCSEC_PER_RAD),
            flag: if prior_dominated[i] {
                "not determined by the data (see the unobservable combinations)".into()
            } else {
                String::new()
            },
        })
        .collect();

    // Physical angles.
    let mut angles = Vec::new();
    let n_axes = chain.axes().len();
    for k in (0..n_axes).rev() {
        let (Some(ic), Some(is)) = (set.index(Param::SwingCos(k)), set.index(Param::SwingSin(k))) else {
            continue;
        };
        let name = &chain.axes()[k].name;
        let alpha = move |x: &[f64]| x[ic].hypot(x[is]);
        let phi = move |x: &[f64]| x[is].atan2(x[ic]);
        let a_kf = propagate(&cal.kf, &alpha, ARCSEC_PER_RAD);
        let a_nls = propagate(&cal.nls, &alpha, ARCSEC_PER_RAD);
        let mut flag = String::new();
        if prior_dominated[ic] || prior_dominated[is] {
            flag = "not determined by the data (see the unobservable combinations)".into();
        }
        angles.push(Row {
            key: format!("{name}.swing_half_angle"),
            label: format!("{name} α"),
            unit: "arcsec",
            truth: truth.axes[k].swing_half_angle_rad * ARCSEC_PER_RAD,
            kf: a_kf,
            nls: a_nls,
            flag: flag.clone(),
        });
        let mut phase_flag = flag;
        if phase_flag.is_empty() && a_nls.value < 3.0 * a_nls.sigma {
            phase_flag = format!("α = {:.3}″ is within 3σ of 0: the phase is undefined", a_nls.value);
            warnings.push(format!("{name}: {phase_flag}"));
        }
        let wrap = |v: Value, t: f64| Value {
            value: t + crate::math::units::wrap_pi((v.value - t) / DEG_PER_RAD) * DEG_PER_RAD,
            sigma: v.sigma,
        };
        let t_phi = truth.axes[k].swing_phase_rad * DEG_PER_RAD;
        angles.push(Row {
            key: format!("{name}.swing_phase"),
            label: format!("{name} φ"),
            unit: "deg",
            truth: t_phi,
            kf: wrap(propagate(&cal.kf, &phi, DEG_PER_RAD), t_phi),
            nls: wrap(propagate(&cal.nls, &phi, DEG_PER_RAD), t_phi),
            flag: phase_flag,
        });
    }
    for k in (1..n_axes).rev() {
        let Some(i) = set.index(Param::NonOrth(k)) else {
            continue;
        };
        angles.push(Row {
            key: format!("{}.non_orthogonality", chain.axes()[k].name),
            label: format!("{} η", chain.axes()[k].name),
            unit: "arcsec",
            truth: true_values[i] * ARCSEC_PER_RAD,
            kf: value(&cal.kf, i, ARCSEC_PER_RAD),
            nls: value(&cal.nls, i, ARCSEC_PER_RAD),
            flag: state[i].flag.clone(),
        });
        if let Some(f) = effective_eta(chain, set, k) {
            angles.push(Row {
                key: format!("{}.effective_non_orthogonality", chain.axes()[k].name),
                label: format!("{} η_eff (η + {} swing)", chain.axes()[k].name, chain.axes()[k - 1].name),
                unit: "arcsec",
                truth: f(&true_values) * ARCSEC_PER_RAD,
                kf: propagate(&cal.kf, &f, ARCSEC_PER_RAD),
                nls: propagate(&cal.nls, &f, ARCSEC_PER_RAD),
                flag: String::new(),
            });
        }
    }

    // Jiang et al. 2017's state (eq. 29) for the dual-axis table: axis 1 = inner (index 1), axis 2 = outer (0).
    let mut paper_state = Vec::new();
    if n_axes == 2
        && let (Some(a1), Some(a2), Some(b1), Some(b2), Some(e)) = (
            set.index(Param::SwingCos(1)),
            set.index(Param::SwingSin(1)),
            set.index(Param::SwingCos(0)),
            set.index(Param::SwingSin(0)),
            set.index(Param::NonOrth(1)),
        )
    {
        let xs: [(&str, &str, ParamFn); 5] = [
            ("x1", "x1 = α1 cos φ1", Box::new(move |x: &[f64]| x[a1])),
            ("x2", "x2 = α1 sin φ1", Box::new(move |x: &[f64]| x[a2])),
            ("x3", "x3 = α2 cos φ2 sec η", Box::new(move |x: &[f64]| x[b1] / x[e].cos())),
            ("x4", "x4 = α1 cos φ1 tan η", Box::new(move |x: &[f64]| x[a1] * x[e].tan())),
            ("x5", "x5 = α2 sin φ2", Box::new(move |x: &[f64]| x[b2])),
        ];
        let t = &true_values;
        for (key, label, f) in &xs {
            let kf = propagate(&cal.kf, f.as_ref(), ARCSEC_PER_RAD);
            let nls = propagate(&cal.nls, f.as_ref(), ARCSEC_PER_RAD);
            let flag = if (*key == "x4" || *key == "x5") && (prior_dominated[b2] || prior_dominated[e]) {
                "not determined by the data (η and α2 sin φ2 are seen only as α2 sin φ2 − η)".into()
            } else {
                String::new()
            };
            paper_state.push(Row {
                key: (*key).into(),
                label: (*label).into(),
                unit: "arcsec",
                truth: f(t) * ARCSEC_PER_RAD,
                kf,
                nls,
                flag,
            });
        }
        // Eq. 34 recovers η = atan(x4/x1): meaningless when x1 = α1 cos φ1 is not clearly non-zero.
        let x1 = &paper_state[0].nls;
        if x1.value.abs() < 3.0 * x1.sigma {
            warnings.push(format!(
                    "Jiang et al. 2017 eq. 34 recovers η as atan(x4/x1), and x1 = α1 cos φ1 = {:.3}″ ± {:.3}″ is within 3σ of zero (cos φ1 ≈ 0): that route gives no η here. rinscope estimates η (and its one observable combination) directly, not through x4/x1.",
                    x1.value, x1.sigma
                ));
        }
    }

    let mut notes = Vec::new();
    for u in &unobs {
        let names: Vec<String> = u.direction.iter().map(|(k, c)| format!("{c:+.3}·{k}")).collect();
        if u.resolved_by_prior {
            notes.push(format!(
                "the data do not separate {}; the prior resolves it (e.g. η from an independent measurement: prior {:.3}″ ± {:.3}″)",
                names.join(" "),
                cal.prior.0.iter().zip(&set.params).find(|(_, p)| matches!(p, Param::NonOrth(_))).map_or(0.0, |(v, _)| v * ARCSEC_PER_RAD),
                cal.prior.1.iter().zip(&set.params).find(|(_, p)| matches!(p, Param::NonOrth(_))).map_or(0.0, |(v, _)| v * ARCSEC_PER_RAD),
            ));
            continue;
        }
        let mut w = format!(
            "not observable: {} — the data give σ = {} along it, the prior {:.1}″",
            names.join(" "),
            if u.data_sigma_arcsec.is_finite() { format!("{:.3e}″", u.data_sigma_arcsec) } else { "∞".into() },
            u.prior_sigma_arcsec
        );
        if let Some((name, v)) = &u.determined {
            w.push_str(&format!("; the data determine only {name} = {:.3}″ ± {:.3}″", v.value, v.sigma));
        }
        warnings.push(w);
    }
    // Residuals outside the encoders' directions are what the isotropic part of R must explain:
    // well above it, the INS errs more than assumed or the data hold an error the model lacks.
    let iso = cal.nls.isotropic_residual_rad;
    if iso.is_finite() && iso > 2.0 * cal.measurement_sigma_rad {
        warnings.push(format!(
            "the residuals outside the encoders' directions ({:.2}″ RMS) are {:.1}× the isotropic noise assumed ({:.2}″): the INS errs more than that, or the data hold an error the calibration does not model (see which errors alias into which states); the 1σ are optimistic by about that factor (set calibration.measurement_sigma_arcsec)",
            iso * ARCSEC_PER_RAD,
            iso / cal.measurement_sigma_rad,
            cal.measurement_sigma_rad * ARCSEC_PER_RAD
        ));
    }
    let (walk, bias) = (
        cal.ins_error.random_walk_rad_per_sqrt_s / crate::math::units::RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H,
        cal.ins_error.bias_sigma_rad_per_s / crate::math::units::RAD_PER_S_PER_DEG_PER_H,
    );
    let mut sigma_basis = format!(
        "R per sample: each encoder's noise about its axis + {:.2}″ isotropic",
        cal.measurement_sigma_rad * ARCSEC_PER_RAD
    );
    if cal.ins_error.is_some() {
        sigma_basis.push_str(&format!("; the 1σ also carry the INS's error through the whole test (correlated from sample to sample): angle random walk {walk}°/√h, unknown gyro bias {bias}°/h (1σ per axis)"));
    } else if data.source != super::AttitudeSource::Ideal {
        sigma_basis.push_str("; the INS's own error (random walk, bias) is not in the 1σ: state calibration.ins_random_walk_deg_per_sqrt_h and ins_bias_deg_per_h, or the 1σ of the states it reaches (the offsets, drifts, η_eff) are optimistic");
    }
    sigma_basis.push_str(".\nThe static KF's 1σ cover the noise, not the bias of the paper's linearised measurement model (first order in the swing angles): \
         at 5-10′ cones its error can exceed 3σ (x2 in the default scenario: about 6σ); the exact least squares has no such bias. \
         `rinscope montecarlo` measures both estimators' spread and bias against these 1σ");
    Report {
        scenario: scenario.to_owned(),
        seed: data.seed,
        source: match data.source {
            super::AttitudeSource::Ins => "INS in the loop ([imu])".into(),
            super::AttitudeSource::Ideal => "exact IMU attitude (no [imu])".into(),
            super::AttitudeSource::Log => "a log set's INS output (replayed)".into(),
        },
        samples: cal.samples,
        duration_s: data.samples.last_t_s(),
        measurement_sigma_arcsec: cal.measurement_sigma_rad * ARCSEC_PER_RAD,
        ins_random_walk_deg_per_sqrt_h: walk,
        ins_bias_deg_per_h: bias,
        sigma_basis,
        nls_iterations: cal.nls_iterations,
        residual_rms_arcsec: [
            cal.kf.residual_rms_rad.map(|v| v * ARCSEC_PER_RAD),
            cal.nls.residual_rms_rad.map(|v| v * ARCSEC_PER_RAD),
        ],
        state,
        angles,
        paper_state,
        unobservable: unobs,
        warnings,
        notes,
        compensation,
        aliases: Vec::new(),
    }
}

/// A row's numbers as text, in its unit: true, KF value, KF 1σ, KF error (″), LSQ value, LSQ 1σ,
/// LSQ error (″).
fn cells(r: &Row) -> [String; 7] {
    let d = if r.unit == "deg" { 5 } else { 3 };
    let u = if r.unit == "deg" { "°" } else { "″" };
    let err_scale = if r.unit == "deg" { 3600.0 } else { 1.0 };
    [
        format!("{:.d$}{u}", r.truth),
        format!("{:.d$}{u}", r.kf.value),
        format!("{:.d$}", r.kf.sigma),
        format!("{:+.3}″", r.kf_error() * err_scale),
        format!("{:.d$}{u}", r.nls.value),
        format!("{:.d$}", r.nls.sigma),
        format!("{:+.3}″", r.nls_error() * err_scale),
    ]
}

fn fmt_row(r: &Row) -> String {
    let [t, kv, ks, ke, nv, ns, ne] = cells(r);
    format!("  {:<26} {t:>13}  {kv:>13} ±{ks:>8}  ({ke:>9})  {nv:>13} ±{ns:>8}  ({ne:>9})  {}\n", r.label, r.flag)
}

/// A row as a markdown table row: quantity, true, KF ± 1σ (error), LSQ ± 1σ (error), flag.
fn md_row(r: &Row) -> String {
    let [t, kv, ks, ke, nv, ns, ne] = cells(r);
    format!("| {} | {t} | {kv} ± {ks} ({ke}) | {nv} ± {ns} ({ne}) | {} |\n", r.label, r.flag)
}

impl Report {
    /// The report's tables in markdown (the recording's document: a panel wraps a fixed-width
    /// table mid-row, it lays out a markdown one); the rest of [`Self::text`] follows as text.
    #[must_use]
    pub fn markdown(&self) -> String {
        let head = "| | true | static KF ± 1σ (error) | exact LSQ ± 1σ (error) | |\n|---|---:|---:|---:|---|\n";
        let mut s = format!(
            "{} samples over {:.0} s, {} (seed {}). {}\n\n",
            self.samples, self.duration_s, self.source, self.seed, self.sigma_basis
        );
        let mut table = |title: &str, rows: &[Row]| {
            if !rows.is_empty() {
                s.push_str(&format!("**{title}**\n\n{head}"));
                for r in rows {
                    s.push_str(&md_row(r));
                }
                s.push('\n');
            }
        };
        table("Angles (phase errors in arcsec of phase)", &self.angles);
        table("Jiang et al. 2017's state X (eq. 29)", &self.paper_state);
        table("State vector (table and reference nuisance)", &self.state);
        if let Some(c) = &self.compensation {
            s.push_str("**Compensation**, on an independent run (other noise seed): attitude error RMS / peak, arcsec\n\n| | pitch | roll | heading |\n|---|---:|---:|---:|\n");
            for (name, e) in [
                ("before (no swing/η)", c.before),
                ("after, static KF", c.after_kf),
                ("after, exact LSQ", c.after_nls),
                ("with the true values", c.with_truth),
            ] {
                let cells: Vec<String> = (0..3)
                    .map(|i| format!("{:.2} / {:.2}", e.rms_rad[i] * ARCSEC_PER_RAD, e.peak_rad[i] * ARCSEC_PER_RAD))
                    .collect();
                s.push_str(&format!("| {name} | {} |\n", cells.join(" | ")));
            }
            let factors: Vec<String> =
                (0..3).map(|i| format!("{:.1}×", c.before.peak_rad[i] / c.after_nls.peak_rad[i].max(1e-300))).collect();
            s.push_str(&format!("| peak reduction (LSQ) | {} |\n", factors.join(" | ")));
            let paper: Vec<String> = PAPER_LAB.iter().map(|(b, a)| format!("{:.1}×", b / a)).collect();
            s.push_str(&format!("| Jiang et al. 2017 laboratory | {} |\n\n", paper.join(" | ")));
        }
        s
    }

    /// The report as a terminal table.
    #[must_use]
    pub fn text(&self) -> String {
        let mut s = format!(
            "calibration of {}: {} samples over {:.0} s, {} (seed {})\n{}\n",
            self.scenario, self.samples, self.duration_s, self.source, self.seed, self.sigma_basis
        );
        let header = format!(
            "  {:<26} {:>13}  {:>13} {:>9}  {:>11}  {:>13} {:>9}  {:>11}\n",
            "", "true", "static KF", "1σ", "(error)", "exact LSQ", "1σ", "(error)"
        );
        s.push_str("\nangles (phase errors in arcsec of phase):\n");
        s.push_str(&header);
        for r in &self.angles {
            s.push_str(&fmt_row(r));
        }
        if !self.paper_state.is_empty() {
            s.push_str("\nJiang et al. 2017's state X (eq. 29):\n");
            s.push_str(&header);
            for r in &self.paper_state {
                s.push_str(&fmt_row(r));
            }
        }
        s.push_str("\nstate vector (table and reference nuisance):\n");
        s.push_str(&header);
        for r in &self.state {
            s.push_str(&fmt_row(r));
        }
        s.push_str(&format!(
            "\nresidual RMS (E, N, U): filter {:.3}/{:.3}/{:.3}″, least squares {:.3}/{:.3}/{:.3}″ after {} Gauss–Newton iterations\n",
            self.residual_rms_arcsec[0][0],
            self.residual_rms_arcsec[0][1],
            self.residual_rms_arcsec[0][2],
            self.residual_rms_arcsec[1][0],
            self.residual_rms_arcsec[1][1],
            self.residual_rms_arcsec[1][2],
            self.nls_iterations
        ));
        if let Some(c) = &self.compensation {
            s.push_str("\ncompensation, on an independent run (other noise seed): attitude error RMS / peak, arcsec\n");
            s.push_str(&format!("  {:<22} {:>16} {:>16} {:>16}\n", "", "pitch", "roll", "heading"));
            for (name, e) in [
                ("before (no swing/η)", c.before),
                ("after, static KF", c.after_kf),
                ("after, exact LSQ", c.after_nls),
                ("with the true values", c.with_truth),
            ] {
                s.push_str(&format!("  {name:<22}"));
                for i in 0..3 {
                    s.push_str(&format!(
                        " {:>7.2} / {:>6.2}",
                        e.rms_rad[i] * ARCSEC_PER_RAD,
                        e.peak_rad[i] * ARCSEC_PER_RAD
                    ));
                }
                s.push('\n');
            }
            s.push_str(&format!("  {:<22}", "peak reduction (LSQ)"));
            for i in 0..3 {
                s.push_str(&format!(" {:>15.1}×", c.before.peak_rad[i] / c.after_nls.peak_rad[i].max(1e-300)));
            }
            s.push('\n');
            s.push_str(&format!("  {:<22}", "Jiang et al. 2017 laboratory"));
            for (b, a) in PAPER_LAB {
                s.push_str(&format!(" {:>15.1}×", b / a));
            }
            s.push_str("   (1.6′→25.2″, 1.86′→30.24″, 2.5′→49.32″)\n");
        }
        if !self.aliases.is_empty() {
            s.push_str("\nwhat the calibration assumes: each error it does not estimate is taken as `[compensation]` gives it (nominal, 0, where not given);\n1″ of each would go into the estimates as (″ per ″; |x| ≥ 0.05 shown):\n");
            for a in &self.aliases {
                let into = if a.into.is_empty() {
                    "nothing".to_owned()
                } else {
                    a.into.iter().map(|(k, x)| format!("{k} {x:+.2}")).collect::<Vec<_>>().join(", ")
                };
                s.push_str(&format!("  {:<28} → {into}\n", a.error));
            }
        }
        for n in &self.notes {
            s.push_str(&format!("\nnote: {n}\n"));
        }
        if !self.warnings.is_empty() {
            s.push_str("\nwarnings:\n");
            for w in &self.warnings {
                s.push_str(&format!("  - {w}\n"));
            }
        }
        s
    }
}
