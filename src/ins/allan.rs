//! The Allan analysis of an IMU: the six channels (gyro and accelerometer x, y, z) of a static log
//! in the field's units, the fitted IEEE coefficients beside the configured ones, as a terminal
//! table, a markdown table and JSON (docs/allan.md). `app::allan` gathers the log (simulated or
//! read), `record::allan` draws it.

use serde_json::{Map, Value, json};

use super::noise::IeeeTerms;
use super::sensor::{AccelSpec, GyroSpec};
use crate::math::allan::edf::alpha_code;
use crate::math::allan::estimators::{DeviationCurve, Estimator, deviation_curve};
use crate::math::allan::{
    AllanError, AllanOptions, AllanReport, Estimate, MIN_SAMPLES, NoiseTerm, Phase, SlopeReading, TERMS, analyze,
    averaging_factors, gauss_markov_avar,
};
use crate::math::units::{
    MPS_PER_SQRT_S_PER_UG_PER_SQRT_HZ, MPS2_PER_SQRT_S_PER_UG_PER_SQRT_H, MPS2_PER_UG, MPS3_PER_UG_PER_H,
    RAD_PER_ARCSEC, RAD_PER_S_PER_DEG_PER_H, RAD_PER_S_PER_SQRT_S_PER_DEG_PER_H_PER_SQRT_H, RAD_PER_S2_PER_DEG_PER_H2,
    RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H,
};

/// The axis names, in channel order.
pub const AXES: [&str; 3] = ["x", "y", "z"];

/// What a channel measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sensor {
    /// Gyros: increments in rad, rates in rad/s.
    Gyro,
    /// Accelerometers: increments in m/s, rates in m/s².
    Accel,
    /// A clock or an oscillator (`allan --series` of a phase in s or a fractional frequency):
    /// increments in s, "rates" dimensionless. No IEEE 952 fit; the noise type per τ instead.
    Clock,
}

/// A conventional unit: its name in JSON keys and entity paths, as printed, and its SI value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unit {
    /// In keys and paths (`deg_per_h`).
    pub key: &'static str,
    /// As printed (`°/h`).
    pub text: &'static str,
    /// SI per unit (rad/s per °/h).
    pub si: f64,
}

impl Sensor {
    /// All, in channel order.
    pub const ALL: [Sensor; 3] = [Sensor::Gyro, Sensor::Accel, Sensor::Clock];

    /// "gyro", "accel" or "clock".
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Gyro => "gyro",
            Self::Accel => "accel",
            Self::Clock => "clock",
        }
    }

    /// The IEEE 952 / 1293 coefficients apply (inertial sensors).
    #[must_use]
    pub fn is_inertial(self) -> bool {
        self != Self::Clock
    }

    /// The unit of the Allan deviation of its rate: °/h for gyros, µg for accelerometers, a
    /// fractional frequency (dimensionless) for clocks.
    #[must_use]
    pub fn adev_unit(self) -> Unit {
        match self {
            Self::Gyro => Unit { key: "deg_per_h", text: "°/h", si: RAD_PER_S_PER_DEG_PER_H },
            Self::Accel => Unit { key: "ug", text: "µg", si: MPS2_PER_UG },
            Self::Clock => Unit { key: "frac", text: "", si: 1.0 },
        }
    }

    /// The unit of a deviation of the phase (TDEV): arcsec, m/s, ns.
    #[must_use]
    pub fn phase_unit(self) -> Unit {
        match self {
            Self::Clock => Unit { key: "ns", text: "ns", si: 1e-9 },
            _ => self.unit(NoiseTerm::Quantization),
        }
    }

    /// The unit of `estimator`'s deviation.
    #[must_use]
    pub fn deviation_unit(self, estimator: Estimator) -> Unit {
        if estimator.is_of_phase() { self.phase_unit() } else { self.adev_unit() }
    }

    /// The conventional unit of a coefficient (IEEE 952 for gyros, 1293 for accelerometers).
    #[must_use]
    pub fn unit(self, term: NoiseTerm) -> Unit {
        let (key, text, si) = match (self, term) {
            (Self::Gyro, NoiseTerm::Quantization) => ("arcsec", "″", RAD_PER_ARCSEC),
            (Self::Gyro, NoiseTerm::RandomWalk) => ("deg_per_sqrt_h", "°/√h", RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H),
            (Self::Gyro, NoiseTerm::BiasInstability) => ("deg_per_h", "°/h", RAD_PER_S_PER_DEG_PER_H),
            (Self::Gyro, NoiseTerm::RateRandomWalk) => {
                ("deg_per_h_per_sqrt_h", "°/h/√h", RAD_PER_S_PER_SQRT_S_PER_DEG_PER_H_PER_SQRT_H)
            }
            (Self::Gyro, NoiseTerm::RateRamp) => ("deg_per_h2", "°/h²", RAD_PER_S2_PER_DEG_PER_H2),
            (Self::Accel, NoiseTerm::Quantization) => ("mps", "m/s", 1.0),
            (Self::Accel, NoiseTerm::RandomWalk) => ("ug_per_sqrt_hz", "µg/√Hz", MPS_PER_SQRT_S_PER_UG_PER_SQRT_HZ),
            (Self::Accel, NoiseTerm::BiasInstability) => ("ug", "µg", MPS2_PER_UG),
            (Self::Accel, NoiseTerm::RateRandomWalk) => ("ug_per_sqrt_h", "µg/√h", MPS2_PER_SQRT_S_PER_UG_PER_SQRT_H),
            (Self::Accel, NoiseTerm::RateRamp) => ("ug_per_h", "µg/h", MPS3_PER_UG_PER_H),
            // A clock's coefficients of the same model, SI (σ_y² = 3Q²/τ² + N²/τ + ...).
            (Self::Clock, NoiseTerm::Quantization) => ("s", "s", 1.0),
            (Self::Clock, NoiseTerm::RandomWalk) => ("sqrt_s", "√s", 1.0),
            (Self::Clock, NoiseTerm::BiasInstability) => ("frac", "", 1.0),
            (Self::Clock, NoiseTerm::RateRandomWalk) => ("per_sqrt_s", "/√s", 1.0),
            (Self::Clock, NoiseTerm::RateRamp) => ("per_s", "/s", 1.0),
        };
        Unit { key, text, si }
    }

    /// The standard's name of a term for this sensor.
    #[must_use]
    pub fn term_name(self, term: NoiseTerm) -> &'static str {
        match (self, term) {
            (_, NoiseTerm::Quantization) => "quantization",
            (Self::Gyro, NoiseTerm::RandomWalk) => "angle random walk",
            (Self::Accel, NoiseTerm::RandomWalk) => "velocity random walk",
            (_, NoiseTerm::BiasInstability) => "bias instability",
            (Self::Gyro, NoiseTerm::RateRandomWalk) => "rate random walk",
            (Self::Accel, NoiseTerm::RateRandomWalk) => "acceleration random walk",
            (Self::Gyro, NoiseTerm::RateRamp) => "rate ramp",
            (Self::Accel, NoiseTerm::RateRamp) => "acceleration ramp",
            (Self::Clock, NoiseTerm::RandomWalk) => "white FM",
            (Self::Clock, NoiseTerm::RateRandomWalk) => "random-walk FM",
            (Self::Clock, NoiseTerm::RateRamp) => "frequency drift",
        }
    }

    /// The JSON key of a coefficient: `n_deg_per_sqrt_h`.
    #[must_use]
    pub fn key(self, term: NoiseTerm) -> String {
        format!("{}_{}", term.letter().to_lowercase(), self.unit(term).key)
    }
}

/// The stochastic errors a channel was configured with (a simulation's `[imu]`, or a log set's
/// `table.toml`), SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Truth {
    /// Q, N, B, K, R.
    pub terms: IeeeTerms,
    /// A first-order Gauss-Markov bias: its σ (rad/s | m/s²).
    pub markov_sigma_si: f64,
    /// Its correlation time, s.
    pub correlation_s: f64,
}

impl Truth {
    /// The gyros' configured noise.
    #[must_use]
    pub fn gyro(g: &GyroSpec) -> Self {
        Self { terms: g.noise, markov_sigma_si: g.markov_sigma_rad_per_s, correlation_s: g.correlation_s }
    }

    /// The accelerometers' configured noise.
    #[must_use]
    pub fn accel(a: &AccelSpec) -> Self {
        Self { terms: a.noise, markov_sigma_si: a.markov_sigma_mps2, correlation_s: a.correlation_s }
    }

    /// True if the Gauss-Markov bias is in the signal.
    #[must_use]
    pub fn has_markov(&self) -> bool {
        self.markov_sigma_si > 0.0 && self.correlation_s > 0.0
    }

    /// The Allan variance of what was configured at τ (s), SI rate units²: the terms' exact curves
    /// ([`IeeeTerms::model_avar`]) and the Gauss-Markov bias's.
    #[must_use]
    pub fn avar(&self, tau_s: f64) -> f64 {
        let markov =
            if self.has_markov() { gauss_markov_avar(self.markov_sigma_si, self.correlation_s, tau_s) } else { 0.0 };
        self.terms.model_avar(tau_s) + markov
    }
}

/// One channel's analysis.
#[derive(Debug, Clone)]
pub struct Channel {
    /// Gyro, accelerometer or clock.
    pub sensor: Sensor,
    /// The axis (x, y, z) or the series' column name.
    pub label: String,
    /// The overlapping Allan deviation, its confidence, the IEEE fit (inertial sensors with at
    /// least [`MIN_SAMPLES`] samples; IEEE 952 defines the coefficients on this estimator).
    pub report: Option<AllanReport>,
    /// The curves of the other estimators asked for (and OADEV's, where there is no `report`).
    pub curves: Vec<DeviationCurve>,
    /// What was configured, if known.
    pub truth: Option<Truth>,
}

impl Channel {
    /// "gyro x".
    #[must_use]
    pub fn name(&self) -> String {
        format!("{} {}", self.sensor.name(), self.label)
    }

    /// The fitted coefficient of `term` in its conventional unit (zero, not found, without a fit).
    #[must_use]
    pub fn fitted(&self, term: NoiseTerm) -> Estimate {
        self.report
            .as_ref()
            .map_or(Estimate { value: 0.0, sigma: 0.0, significant: false }, |r| r.fit.get(term))
            .scaled(1.0 / self.sensor.unit(term).si)
    }

    /// The configured coefficient of `term` in its conventional unit (None without a truth).
    #[must_use]
    pub fn configured(&self, term: NoiseTerm) -> Option<f64> {
        self.truth.map(|t| t.terms.coefficient(term) / self.sensor.unit(term).si)
    }
}

/// A channel that could not be analysed.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{channel}: {error}")]
pub struct ChannelError {
    /// "gyro x".
    pub channel: String,
    /// Why.
    pub error: AllanError,
}

/// Analyses the six channels (`phases` in the order gyro x, y, z, accel x, y, z) sampled every
/// `tau0_s`; `truth` holds the gyros' and the accelerometers' configured noise; `estimators` the
/// curves asked for beside the IEEE fit's OADEV. `parallel`: one channel per core (rayon), else
/// one after the other (the benchmark's single-core number).
///
/// # Errors
/// The first channel that cannot be analysed, named.
pub fn analyze_imu(
    phases: &[Phase],
    tau0_s: f64,
    opts: &AllanOptions,
    estimators: &[Estimator],
    truth: Option<[Truth; 2]>,
    parallel: bool,
) -> Result<Vec<Channel>, ChannelError> {
    use rayon::prelude::*;
    let one = |i: usize| {
        analyze_channel(Sensor::ALL[i / 3], AXES[i % 3], &phases[i], tau0_s, opts, estimators, truth.map(|t| t[i / 3]))
    };
    let n = phases.len().min(6);
    if parallel { (0..n).into_par_iter().map(one).collect() } else { (0..n).map(one).collect() }
}

/// Analyses one channel: for an inertial sensor with at least [`MIN_SAMPLES`] samples, the
/// OADEV and its IEEE fit ([`analyze`]) at the cluster sizes of `opts`; and the curves of
/// `estimators` (OADEV's too where there is no fit) at the same spacing, each as far as it is
/// defined and `opts.min_clusters` allows.
///
/// # Errors
/// A non-finite sample, too few samples for any estimator, a bad option; named by channel.
pub fn analyze_channel(
    sensor: Sensor,
    label: &str,
    phase: &Phase,
    tau0_s: f64,
    opts: &AllanOptions,
    estimators: &[Estimator],
    truth: Option<Truth>,
) -> Result<Channel, ChannelError> {
    let fail = |error| ChannelError { channel: format!("{} {label}", sensor.name()), error };
    if let Some((index, value)) = phase.first_bad() {
        return Err(fail(AllanError::NonFinite { index, value }));
    }
    let report = if sensor.is_inertial() && phase.len() >= MIN_SAMPLES.max(2 * opts.min_clusters) {
        Some(analyze(phase, tau0_s, opts).map_err(fail)?)
    } else {
        None
    };
    let x = phase.points();
    // Every curve at the spacing of the fit, up to N / min_clusters (each as far as it is defined).
    let m_max = phase.len() / opts.min_clusters.max(2);
    let ms = averaging_factors(m_max, &opts.spacing).map_err(fail)?;
    let curves: Vec<DeviationCurve> = estimators
        .iter()
        .filter(|e| report.is_none() || **e != Estimator::Oadev)
        .map(|e| deviation_curve(*e, x, tau0_s, &ms, opts.ci_sigma))
        .collect();
    if report.is_none() && curves.iter().all(|c| c.m.is_empty()) {
        return Err(fail(AllanError::TooFewSamples { got: phase.len(), min: 2 }));
    }
    Ok(Channel { sensor, label: label.to_owned(), report, curves, truth })
}

/// The analysis of an IMU log.
#[derive(Debug, Clone)]
pub struct ImuAllan {
    /// What was analysed ("scenario static-imu-10h (simulated)", "log set logs/static").
    pub source: String,
    /// The simulation's seed.
    pub seed: Option<u64>,
    /// The log's sample rate, Hz.
    pub rate_hz: f64,
    /// Samples summed into one before the analysis.
    pub decimate: usize,
    /// Samples per channel analysed (after decimation).
    pub samples: usize,
    /// Half-width of the confidence intervals, normal sigmas.
    pub ci_sigma: f64,
    /// The six channels.
    pub channels: Vec<Channel>,
    /// What a reader must know (gaps, motion, saturation...).
    pub notes: Vec<String>,
    /// Stopped by a signal before the end of the log.
    pub interrupted: bool,
    /// Wall time of reading or simulating, s.
    pub gather_s: f64,
    /// Wall time of the analysis, s.
    pub analysis_s: f64,
}

/// `x` with `digits` significant digits (scientific outside 1e-4..1e6).
#[must_use]
pub fn sig(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let e = x.abs().log10().floor() as i32;
    if !(-4..6).contains(&e) {
        return format!("{:.*e}", digits.saturating_sub(1), x);
    }
    format!("{:.*}", (digits as i32 - 1 - e).max(0) as usize, x)
}

/// A fitted value as the table shows it: "0.02000 ±0.03% (+0.1%)", or "— (<0.0011)" when the fit
/// did not find the term (with its 1σ detection limit).
fn cell(e: Estimate, truth: Option<f64>) -> String {
    if !e.significant || e.value <= 0.0 {
        return format!("— (<{})", sig(e.sigma, 2));
    }
    let mut s = format!("{} ±{}%", sig(e.value, 4), sig(100.0 * e.sigma / e.value, 2));
    if let Some(t) = truth.filter(|t| *t > 0.0) {
        s += &format!(" ({:+.1}%)", 100.0 * (e.value / t - 1.0));
    }
    s
}

impl ImuAllan {
    /// The shortest and the longest cluster time analysed, s.
    #[must_use]
    pub fn tau_range_s(&self) -> (f64, f64) {
        let taus = self.channels.iter().flat_map(|c| {
            c.report.iter().map(|r| r.taus_s.as_slice()).chain(c.curves.iter().map(|k| k.taus_s.as_slice()))
        });
        taus.fold((f64::INFINITY, 0.0), |(lo, hi), t| {
            (lo.min(t.first().copied().unwrap_or(lo)), hi.max(t.last().copied().unwrap_or(hi)))
        })
    }

    /// Number of cluster times of the longest curve.
    #[must_use]
    pub fn tau_count(&self) -> usize {
        self.channels
            .iter()
            .flat_map(|c| c.report.iter().map(|r| r.taus_s.len()).chain(c.curves.iter().map(|k| k.taus_s.len())))
            .max()
            .unwrap_or(0)
    }

    /// The one-line heading.
    #[must_use]
    pub fn heading(&self) -> String {
        let tau0 = self.decimate as f64 / self.rate_hz;
        let (lo, hi) = self.tau_range_s();
        let seed = self.seed.map(|s| format!(", seed {s}")).unwrap_or_default();
        format!(
            "Allan deviation of {}{seed}: {} samples per channel at {} Hz{} ({:.2} h), {} cluster times {} s .. {} s, ±{}σ intervals",
            self.source,
            self.samples,
            self.rate_hz,
            if self.decimate > 1 { format!(" summed by {}", self.decimate) } else { String::new() },
            self.samples as f64 * tau0 / 3600.0,
            self.tau_count(),
            sig(lo, 3),
            sig(hi, 4),
            self.ci_sigma
        )
    }

    /// The terminal table: per sensor, one row per coefficient, one column per axis and the configured value.
    #[must_use]
    pub fn text(&self) -> String {
        let mut s = String::new();
        if self.interrupted {
            s.push_str("INTERRUPTED: the analysis below is of the part of the log gathered before the stop\n");
        }
        s.push_str(&self.heading());
        s.push('\n');
        for sensor in Sensor::ALL {
            let chans: Vec<(&Channel, &AllanReport)> = self
                .channels
                .iter()
                .filter(|c| c.sensor == sensor)
                .filter_map(|c| c.report.as_ref().map(|r| (c, r)))
                .collect();
            if chans.is_empty() {
                continue;
            }
            let truth = chans[0].0.truth;
            let labels: Vec<String> = TERMS
                .iter()
                .map(|t| format!("{} {} ({})", t.letter(), sensor.term_name(*t), sensor.unit(*t).text))
                .collect();
            let w = labels.iter().map(|l| l.chars().count()).max().unwrap_or(0) + 2;
            let cells: Vec<Vec<String>> = TERMS
                .iter()
                .map(|t| chans.iter().map(|(c, _)| cell(c.fitted(*t), c.configured(*t))).collect())
                .collect();
            let cw = cells.iter().flatten().map(|c| c.chars().count()).max().unwrap_or(0).max(4) + 2;
            s += &format!("\n{:<w$}", format!("{} (fit ±1σ, error)", sensor.name()));
            for (c, _) in &chans {
                s += &format!("{:<cw$}", c.label);
            }
            if truth.is_some() {
                s += "configured";
            }
            s.push('\n');
            for (k, term) in TERMS.iter().enumerate() {
                s += &format!("{:<w$}", labels[k]);
                for c in &cells[k] {
                    s += &format!("{c:<cw$}");
                }
                if let Some(v) = chans[0].0.configured(*term) {
                    s += &sig(v, 4);
                }
                s = s.trim_end().to_owned();
                s.push('\n');
            }
            s += &format!("{:<w$}", "χ²/dof of the fit");
            for (_, r) in &chans {
                s += &format!("{:<cw$}", sig(r.fit_chi2_per_dof, 3));
            }
            s = s.trim_end().to_owned();
            s.push('\n');
            for (c, r) in &chans {
                for w in &r.fit_contradictions {
                    s += &format!("WARNING {}: {}\n", c.name(), w.text());
                }
            }
            if let Some(t) = truth.filter(Truth::has_markov) {
                s += &format!(
                    "also configured: a Gauss-Markov bias of σ {} {}, T {} s (not an IEEE term: its curve peaks at 0.62σ near τ = 1.9 T)\n",
                    sig(t.markov_sigma_si / sensor.adev_unit().si, 3),
                    sensor.adev_unit().text,
                    t.correlation_s
                );
            }
        }
        if self.channels.iter().any(|c| c.report.is_some()) {
            s.push_str("\n± the fit's 1σ (weighted NNLS of the IEEE 952/1293 model on the overlapping Allan variance, inflated by √(χ²/dof));\n(…) its error against the configured value; — not found, with its 1σ detection limit. Slope-line readings, the curves,\ntheir bounds and EDF are in --json and --export.\n");
        }
        for c in self.channels.iter().filter(|c| !c.curves.is_empty()) {
            // Three estimators per table: a terminal's width.
            for group in c.curves.chunks(3) {
                s += &curve_table(c, group, self.ci_sigma);
            }
            s += "noise: the power law the EDF assumed (WPM/FPM white/flicker phase, WFM/FFM/RWFM white/flicker/random-walk rate), by the lag-1\nautocorrelation; * carried from a shorter τ (under 30 points). EDF per τ in --json and --export.\n";
        }
        for n in &self.notes {
            s += &format!("note: {n}\n");
        }
        s
    }

    /// One sensor's coefficients as a markdown table, a row per axis (the recording's documents).
    #[must_use]
    pub fn markdown(&self, sensor: Sensor) -> String {
        let chans: Vec<&Channel> = self.channels.iter().filter(|c| c.sensor == sensor && c.report.is_some()).collect();
        let title = match sensor {
            Sensor::Gyro => "Gyros",
            Sensor::Accel => "Accelerometers",
            Sensor::Clock => "Clocks",
        };
        let mut s = format!("**{title}**: fit ±1σ (error vs configured); — not found (1σ detection limit)\n\n| |");
        for term in TERMS {
            s += &format!(" {} ({}) |", term.letter(), sensor.unit(term).text);
        }
        s += " χ²/dof |\n|---|";
        s += &"---|".repeat(TERMS.len() + 1);
        s.push('\n');
        for c in &chans {
            s += &format!("| **{}** |", c.label);
            for term in TERMS {
                s += &format!(" {} |", cell(c.fitted(term), c.configured(term)));
            }
            s += &format!(" {} |\n", c.report.as_ref().map_or_else(String::new, |r| sig(r.fit_chi2_per_dof, 3)));
        }
        if let Some(c) = chans.first().filter(|c| c.truth.is_some()) {
            s += "| configured |";
            for term in TERMS {
                s += &format!(" {} |", c.configured(term).map_or_else(String::new, |v| sig(v, 4)));
            }
            s += " |\n";
        }
        // A fit is a claim: where the data contradict it, said beside the coefficients.
        for c in &chans {
            for w in c.report.iter().flat_map(|r| &r.fit_contradictions) {
                s += &format!("\n**WARNING** {}: {}\n", c.name(), w.text());
            }
        }
        if let Some(t) = chans.first().and_then(|c| c.truth).filter(Truth::has_markov) {
            s += &format!(
                "\nAlso configured: a Gauss-Markov bias, σ {} {}, T {} s.\n",
                sig(t.markov_sigma_si / sensor.adev_unit().si, 3),
                sensor.adev_unit().text,
                t.correlation_s
            );
        }
        s
    }

    /// Everything as JSON, units in the key names.
    #[must_use]
    pub fn json(&self) -> Value {
        let mut out = Map::new();
        out.insert("source".into(), json!(self.source));
        out.insert("seed".into(), json!(self.seed));
        out.insert("rate_hz".into(), json!(self.rate_hz));
        out.insert("decimate".into(), json!(self.decimate));
        out.insert("tau0_s".into(), json!(self.decimate as f64 / self.rate_hz));
        out.insert("samples".into(), json!(self.samples));
        out.insert("confidence_sigma".into(), json!(self.ci_sigma));
        out.insert("interrupted".into(), json!(self.interrupted));
        out.insert("gather_s".into(), json!(self.gather_s));
        out.insert("analysis_s".into(), json!(self.analysis_s));
        out.insert("notes".into(), json!(self.notes));
        out.insert("estimator".into(), json!("overlapping Allan deviation of the rate; EDF by NIST SP 1065 Table 5 for the fitted noise mixture; chi-square interval (Wilson-Hilferty); coefficients by weighted NNLS of the IEEE 952/1293 model sigma^2 = 3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2"));
        out.insert("curves_method".into(), json!("each estimator by its NIST SP 1065 definition; noise type per tau by the lag-1 autocorrelation (Riley & Greenhall 2004); EDF by Greenhall & Riley (PTTI 2003), TOTDEV by SP 1065 Table 7; chi-square interval (Wilson-Hilferty)"));
        for sensor in Sensor::ALL {
            let list: Vec<Value> = self.channels.iter().filter(|c| c.sensor == sensor).map(channel_json).collect();
            if sensor.is_inertial() || !list.is_empty() {
                out.insert(sensor.name().into(), Value::Array(list));
            }
        }
        Value::Object(out)
    }
}

fn reading_json(r: Option<SlopeReading>, si: f64) -> Value {
    r.map_or(Value::Null, |r| json!({"value": r.value_si / si, "sigma": r.sigma_si / si, "tau_s": r.tau_s, "local_slope": r.local_slope, "nominal_slope": r.nominal_slope, "matched": r.matched}))
}

/// One estimator's curve as JSON, the deviation's unit in the keys.
fn curve_json(sensor: Sensor, k: &DeviationCurve) -> Value {
    let u = sensor.deviation_unit(k.estimator);
    let scale = |v: &[f64]| -> Vec<f64> { v.iter().map(|x| x / u.si).collect() };
    json!({
        "estimator": k.estimator.name(),
        "tau_s": k.taus_s,
        "m": k.m,
        format!("dev_{}", u.key): scale(&k.dev),
        format!("lower_{}", u.key): scale(&k.lower),
        format!("upper_{}", u.key): scale(&k.upper),
        "edf": k.edf,
        "alpha": k.alpha,
        "alpha_identified": k.alpha_identified,
        "terms": k.n_terms,
    })
}

/// A channel's curves as a terminal table: a row per τ, per estimator the deviation, its bounds
/// and the noise type the EDF assumed.
fn curve_table(c: &Channel, curves: &[DeviationCurve], ci_sigma: f64) -> String {
    let mut taus: Vec<(usize, f64)> =
        curves.iter().flat_map(|k| k.m.iter().copied().zip(k.taus_s.iter().copied())).collect();
    taus.sort_by_key(|(m, _)| *m);
    taus.dedup_by_key(|(m, _)| *m);
    let heads: Vec<String> = curves
        .iter()
        .map(|k| {
            let u = c.sensor.deviation_unit(k.estimator);
            format!(
                "{}{} [±{ci_sigma}σ] noise",
                k.estimator.name().to_uppercase(),
                if u.text.is_empty() { String::new() } else { format!(" ({})", u.text) }
            )
        })
        .collect();
    let rows: Vec<Vec<String>> = taus
        .iter()
        .map(|(m, _)| {
            curves
                .iter()
                .map(|k| {
                    let u = c.sensor.deviation_unit(k.estimator).si;
                    k.m.iter().position(|x| x == m).map_or_else(String::new, |j| {
                        format!(
                            "{} [{}, {}] {}{}",
                            sig(k.dev[j] / u, 4),
                            sig(k.lower[j] / u, 3),
                            sig(k.upper[j] / u, 3),
                            alpha_code(k.alpha[j]),
                            if k.alpha_identified[j] { "" } else { "*" }
                        )
                    })
                })
                .collect()
        })
        .collect();
    let widths: Vec<usize> = (0..heads.len())
        .map(|i| rows.iter().map(|r| r[i].chars().count()).chain([heads[i].chars().count()]).max().unwrap_or(0) + 2)
        .collect();
    let mut s = format!("\n{} — τ (s)", c.name());
    let tw = taus.iter().map(|(_, t)| sig(*t, 4).len()).max().unwrap_or(0).max(s.chars().count() - 1) + 2;
    s = format!("{:<tw$}", s);
    for (h, w) in heads.iter().zip(&widths) {
        s += &format!("{h:<w$}");
    }
    s = s.trim_end().to_owned() + "\n";
    for ((_, t), row) in taus.iter().zip(&rows) {
        s += &format!("{:<tw$}", sig(*t, 4));
        for (cell, w) in row.iter().zip(&widths) {
            s += &format!("{cell:<w$}");
        }
        s = s.trim_end().to_owned() + "\n";
    }
    s
}

fn channel_json(c: &Channel) -> Value {
    let s = c.sensor;
    let u = s.adev_unit();
    let mut m = Map::new();
    m.insert("axis".into(), json!(c.label));
    m.insert("curves".into(), Value::Array(c.curves.iter().map(|k| curve_json(s, k)).collect()));
    let Some(r) = &c.report else {
        m.insert("fitted".into(), Value::Null);
        return Value::Object(m);
    };
    let scale = |v: &[f64]| -> Vec<f64> { v.iter().map(|x| x / u.si).collect() };
    m.insert("tau_s".into(), json!(r.taus_s));
    m.insert(format!("adev_{}", u.key), json!(scale(&r.adev_si)));
    m.insert(format!("adev_lower_{}", u.key), json!(scale(&r.adev_lower_si)));
    m.insert(format!("adev_upper_{}", u.key), json!(scale(&r.adev_upper_si)));
    m.insert("edf".into(), json!(r.edf));
    m.insert("second_differences".into(), json!(r.n_terms));
    m.insert("dominant".into(), json!(r.dominant.iter().map(|t| t.letter()).collect::<Vec<_>>()));
    m.insert("fit_chi2_per_dof".into(), json!(r.fit_chi2_per_dof));
    // A fit is a claim: where the data contradict a term or the whole model, said in words.
    m.insert(
        "fit_warnings".into(),
        json!(r.fit_contradictions.iter().map(crate::math::allan::Contradiction::text).collect::<Vec<_>>()),
    );
    let mut fitted = Map::new();
    let mut readings = Map::new();
    for term in TERMS {
        let e = c.fitted(term);
        fitted.insert(s.key(term), json!({"value": e.value, "sigma": e.sigma, "significant": e.significant}));
        readings.insert(s.key(term), reading_json(r.slope.get(term), s.unit(term).si));
    }
    m.insert("fitted".into(), Value::Object(fitted));
    m.insert("slope_readings".into(), Value::Object(readings));
    match c.truth {
        None => {
            m.insert("configured".into(), Value::Null);
        }
        Some(t) => {
            let mut cfg = Map::new();
            for term in TERMS {
                cfg.insert(s.key(term), json!(c.configured(term)));
            }
            cfg.insert("bias_instability_range_s".into(), json!(t.terms.flicker_range_s));
            cfg.insert(format!("markov_sigma_{}", u.key), json!(t.markov_sigma_si / u.si));
            cfg.insert("correlation_time_s".into(), json!(t.correlation_s));
            m.insert("configured".into(), Value::Object(cfg));
            m.insert(
                format!("configured_adev_{}", u.key),
                json!(r.taus_s.iter().map(|tau| t.avar(*tau).sqrt() / u.si).collect::<Vec<_>>()),
            );
        }
    }
    Value::Object(m)
}
