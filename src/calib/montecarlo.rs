//! The Monte Carlo of Jiang et al. 2017 §6.1 (Tables 2-3): many calibrations, each with its own true
//! parameters drawn from `[calibration.montecarlo]` and its own noise, run in parallel; the error
//! statistics of each estimator per quantity, the paper's beside.

use std::sync::atomic::{AtomicBool, Ordering};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::{CalibConfig, CalibError, Data, History, Param, ParamSet, calibrate};
use crate::math::units::{ARCSEC_PER_RAD, wrap_pi};
use crate::model::gimbal::{Chain, TableErrors};

/// Jiang et al. 2017 Table 3 (500 runs): (quantity, error mean ″, standard deviation ″).
pub const PAPER_TABLE3: [(&str, f64, f64); 5] =
    [("α1", 0.98, 0.0238), ("φ1", 1.14, 0.6103), ("α2", 0.78, 0.0078), ("φ2", 0.65, 0.0317), ("η", 1.05, 0.0091)];

/// One quantity's error statistics, arcsec.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ErrorSpread {
    /// Mean of the signed errors.
    pub mean: f64,
    /// Their standard deviation.
    pub std: f64,
    /// Mean of |error|.
    pub mean_abs: f64,
    /// Largest |error|.
    pub max_abs: f64,
}

impl ErrorSpread {
    fn of(errors: &[f64]) -> Self {
        let n = errors.len().max(1) as f64;
        let mean = errors.iter().sum::<f64>() / n;
        let var = errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
        Self {
            mean,
            std: var.sqrt(),
            mean_abs: errors.iter().map(|e| e.abs()).sum::<f64>() / n,
            max_abs: errors.iter().fold(0.0, |m, e| m.max(e.abs())),
        }
    }
}

/// One quantity's row.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QuantityRow {
    /// What.
    pub label: String,
    /// Static Kalman filter.
    pub kf: ErrorSpread,
    /// Exact least squares.
    pub nls: ErrorSpread,
    /// The mean of the least squares' reported 1σ over the runs, ″ (to set beside `nls.std`).
    #[serde(default)]
    pub nls_reported_sigma: Option<f64>,
    /// Jiang et al. 2017 Table 3's (mean, std), when it has the quantity.
    pub paper: Option<(f64, f64)>,
    /// Determined by the data (false: the prior / an independent measurement decides).
    pub identifiable: bool,
    /// Its accuracy is the independent η measurement's, returned (`--eta-measured-sigma-arcsec`).
    #[serde(default)]
    pub given_by_eta: bool,
}

/// The Monte Carlo's result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Scenario.
    pub scenario: String,
    /// Base seed of the draws and the noise.
    pub seed: u64,
    /// Runs completed.
    pub runs: usize,
    /// Runs asked for.
    pub runs_requested: usize,
    /// Wall time, s.
    pub wall_s: f64,
    /// Threads used.
    pub threads: usize,
    /// How the true values were drawn and what the filter was told about η.
    pub setup: String,
    /// One row per quantity.
    pub rows: Vec<QuantityRow>,
}

/// The quantities compared: for each axis from the IMU inward α and φ (φ in arcsec of phase, and as
/// the arc α·δφ), then η and the effective η of every axis that has one.
struct Quantities {
    /// (label, the paper's (mean, std), identifiable).
    labels: Vec<Quantity>,
}

/// (label, the paper's (mean, std), identifiable, given by an independent η measurement).
type Quantity = (String, Option<(f64, f64)>, bool, bool);

fn quantities(chain: &Chain, set: &ParamSet, eta_known: bool) -> Quantities {
    let n = chain.axes().len();
    let mut labels = Vec::new();
    // The paper numbers its axes 1 (inner) and 2 (outer): the IMU-side axis first.
    let paper = |name: &str| PAPER_TABLE3.iter().find(|(q, _, _)| *q == name).map(|(_, m, s)| (*m, *s));
    let dual = n == 2;
    for (j, k) in (0..n).rev().enumerate() {
        let name = &chain.axes()[k].name;
        let num = j + 1;
        // Without an independent η, the swing of the axis before an η (its sin component) is seen
        // only in the combination η_eff.
        let needs_eta = set.index(Param::NonOrth(k + 1)).is_some();
        let swing_ok = eta_known || !needs_eta;
        // With a measured η, what depends on it is the measurement's accuracy returned, not the
        // calibration's: no paper comparison.
        let given = eta_known && needs_eta;
        let cmp = |q: &str| if dual && !given { paper(q) } else { None };
        labels.push((format!("{name} α"), cmp(&format!("α{num}")), swing_ok, given));
        labels.push((format!("{name} φ (″ of phase)"), cmp(&format!("φ{num}")), swing_ok, given));
        labels.push((format!("{name} α·δφ (arc, ″)"), None, swing_ok, given));
    }
    for k in (1..n).rev() {
        let name = &chain.axes()[k].name;
        labels.push((format!("{name} η"), if dual && !eta_known { paper("η") } else { None }, eta_known, eta_known));
        labels.push((format!("{name} η_eff"), None, true, false));
    }
    Quantities { labels }
}

/// Errors (″) of one estimate against `truth` and its reported 1σ (″, first-order propagation of
/// its covariance, as the report does), both in the order of [`quantities`].
fn errors_and_sigmas(chain: &Chain, set: &ParamSet, est: &super::Estimate, truth: &[f64]) -> (Vec<f64>, Vec<f64>) {
    use super::report::{effective_eta, propagate};
    let theta = &est.theta;
    let n = chain.axes().len();
    let (mut err, mut sig) = (Vec::new(), Vec::new());
    for k in (0..n).rev() {
        let (ic, is) = (set.index(Param::SwingCos(k)).unwrap_or(0), set.index(Param::SwingSin(k)).unwrap_or(0));
        let alpha = move |x: &[f64]| x[ic].hypot(x[is]);
        let phi = move |x: &[f64]| x[is].atan2(x[ic]);
        let (a, at) = (alpha(theta), alpha(truth));
        let dphi = wrap_pi(phi(theta) - phi(truth));
        let sigma_phi = propagate(est, &phi, ARCSEC_PER_RAD).sigma;
        err.extend([(a - at) * ARCSEC_PER_RAD, dphi * ARCSEC_PER_RAD, at * dphi * ARCSEC_PER_RAD]);
        sig.extend([propagate(est, &alpha, ARCSEC_PER_RAD).sigma, sigma_phi, a * sigma_phi]);
    }
    for k in (1..n).rev() {
        let ie = set.index(Param::NonOrth(k)).unwrap_or(0);
        err.push((theta[ie] - truth[ie]) * ARCSEC_PER_RAD);
        sig.push(est.sigma(ie) * ARCSEC_PER_RAD);
        let f = effective_eta(chain, set, k);
        err.push(f.as_ref().map_or(f64::NAN, |f| (f(theta) - f(truth)) * ARCSEC_PER_RAD));
        sig.push(f.map_or(f64::NAN, |f| propagate(est, &f, ARCSEC_PER_RAD).sigma));
    }
    (err, sig)
}

/// Draws run `i`'s true errors.
fn draw(base: &TableErrors, mc: &super::MonteCarloConfig, seed: u64, i: u64) -> (TableErrors, ChaCha8Rng) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x4D43_5F43_414C_4942);
    rng.set_stream(i);
    let mut t = base.clone();
    let u = |rng: &mut ChaCha8Rng, r: [f64; 2]| {
        if r[1] > r[0] { rng.random_range(r[0]..r[1]) } else { r[0] }
    };
    for (k, a) in t.axes.iter_mut().enumerate() {
        a.swing_half_angle_rad = u(&mut rng, mc.swing_half_angle_rad);
        a.swing_phase_rad = u(&mut rng, mc.swing_phase_rad);
        a.non_orthogonality_rad = if k > 0 { u(&mut rng, mc.non_orthogonality_rad) } else { 0.0 };
    }
    (t, rng)
}

/// What a Monte Carlo keeps fixed: the table (its truth is the base that each run's draw replaces),
/// what the demodulation knows, the calibration's configuration and the base seed.
#[derive(Debug, Clone, Copy)]
pub struct Setup<'a> {
    /// Scenario name, for the summary.
    pub scenario: &'a str,
    /// The nominal chain.
    pub chain: &'a Chain,
    /// The scenario's true errors (each run redraws the swing cones and non-orthogonalities).
    pub truth: &'a TableErrors,
    /// Every error not estimated, as known to the calibration.
    pub compensation: &'a TableErrors,
    /// The calibration's configuration (with `[calibration.montecarlo]`).
    pub cfg: &'a CalibConfig,
    /// Base seed of the draws and the noise.
    pub seed: u64,
}

/// Simulates one static test for true errors `truth` with noise seed `seed`.
pub type Collect<'a> = dyn Fn(&TableErrors, u64) -> Result<Data, CalibError> + Sync + 'a;

/// One slice of a Monte Carlo: the runs `i` with `i mod count == index`, seeded exactly as in the
/// whole run (`--shard index/count`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This slice, `0 ..count`.
    pub index: u64,
    /// Number of slices.
    pub count: u64,
}

impl Shard {
    /// The whole run.
    pub const WHOLE: Self = Self { index: 0, count: 1 };

    /// Parses `K/M` (0 ≤ K < M).
    pub fn parse(text: &str) -> Result<Self, String> {
        let (k, m) = text
            .split_once('/')
            .ok_or_else(|| format!("`{text}` is not K/M (e.g. 3/8: slice 3 of 8, counted from 0)"))?;
        let (k, m): (u64, u64) = (
            k.trim().parse().map_err(|_| format!("`{k}` in `{text}` is not a whole number"))?,
            m.trim().parse().map_err(|_| format!("`{m}` in `{text}` is not a whole number"))?,
        );
        if m == 0 || k >= m {
            return Err(format!("`{text}`: the slice K must be in 0 ..= M−1 and M ≥ 1"));
        }
        Ok(Self { index: k, count: m })
    }

    /// That `shards` (all of one count) are every slice once: the first given twice, else the first
    /// missing, is the error — what every merge of shards (`montecarlo`, `selfcal`, `sweep`) refuses.
    ///
    /// # Errors
    /// A slice of another count, "shard K/M is given twice", or "shard K/M is missing".
    pub fn check_cover(shards: impl IntoIterator<Item = Self>, count: u64) -> Result<(), String> {
        let mut seen = vec![false; count as usize];
        for s in shards {
            if s.count != count || s.index >= count {
                return Err(format!("shard {}/{} is not a slice of {count}", s.index, s.count));
            }
            if std::mem::replace(&mut seen[s.index as usize], true) {
                return Err(format!("shard {}/{count} is given twice", s.index));
            }
        }
        match seen.iter().position(|s| !s) {
            Some(k) => Err(format!("shard {k}/{count} is missing")),
            None => Ok(()),
        }
    }

    /// The run indices of this slice of `runs`.
    #[must_use]
    pub fn indices(&self, runs: u64) -> Vec<u64> {
        (self.index..runs).step_by(self.count as usize).collect()
    }
}

/// One run's errors (″), in the order of the summary's quantities: the filter's and the least
/// squares'. Kept so that shards can be merged into the statistics of the whole run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunErrors {
    /// The run's index (its seed and draw).
    pub index: u64,
    /// Static Kalman filter.
    pub kf: Vec<f64>,
    /// Exact least squares.
    pub nls: Vec<f64>,
    /// The least squares' reported 1σ (″), same order (absent in shard files of before).
    #[serde(default)]
    pub nls_sigma: Vec<f64>,
}

/// Runs calibrations `indices` in parallel, each on the data `collect` simulates for a drawn table
/// (`progress` ticks once per run; `stop` ends early: the runs not started are left out).
pub fn run_indices(
    setup: &Setup<'_>,
    indices: &[u64],
    collect: &Collect<'_>,
    progress: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Result<Vec<RunErrors>, CalibError> {
    let mc = &setup.cfg.montecarlo;
    let base_seed = setup.seed;
    let results: Vec<Result<Option<RunErrors>, CalibError>> = indices
        .par_iter()
        .map(|&i| {
            if stop.load(Ordering::Relaxed) {
                return Ok(None);
            }
            let (truth, mut rng) = draw(setup.truth, mc, base_seed, i);
            let mut cfg: CalibConfig = setup.cfg.clone();
            // What the calibration is told about η: an independent measurement, or only the range.
            let [lo, hi] = mc.non_orthogonality_rad;
            match mc.eta_measured_sigma_rad {
                Some(s) => {
                    let eta = truth.axes.get(1).map_or(0.0, |a| a.non_orthogonality_rad);
                    let noise: f64 = StandardNormal.sample(&mut rng);
                    cfg.prior_eta_rad = eta + s * noise;
                    cfg.prior_eta_sigma_rad = s;
                }
                None => {
                    cfg.prior_eta_rad = 0.5 * (lo + hi);
                    cfg.prior_eta_sigma_rad = ((hi - lo) / 12f64.sqrt()).max(1e-9);
                }
            }
            let data = collect(&truth, base_seed.wrapping_add(1000).wrapping_add(i))?;
            let cal = calibrate(setup.chain, setup.compensation, &data, &cfg, History::Lean, stop)?;
            let truth_v = cal.set.values(&truth);
            let (kf, _) = errors_and_sigmas(setup.chain, &cal.set, &cal.kf, &truth_v);
            let (nls, nls_sigma) = errors_and_sigmas(setup.chain, &cal.set, &cal.nls, &truth_v);
            let out = RunErrors { index: i, kf, nls, nls_sigma };
            progress();
            Ok(Some(out))
        })
        .collect();
    let mut done = Vec::new();
    for r in results {
        if let Some(x) = r? {
            done.push(x);
        }
    }
    Ok(done)
}

/// Runs `runs` calibrations in parallel (see [`run_indices`]) and summarises them.
pub fn run(
    setup: &Setup<'_>,
    runs: usize,
    collect: &Collect<'_>,
    progress: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Result<Summary, CalibError> {
    let started = std::time::Instant::now();
    let done = run_indices(setup, &Shard::WHOLE.indices(runs as u64), collect, progress, stop)?;
    Ok(summarize(setup, runs, &done, started.elapsed().as_secs_f64()))
}

/// The statistics of `done` (in index order, as a whole run or a merge of shards produces them)
/// out of `runs_requested`.
#[must_use]
pub fn summarize(setup: &Setup<'_>, runs_requested: usize, done: &[RunErrors], wall_s: f64) -> Summary {
    let mc = &setup.cfg.montecarlo;
    let eta_known = mc.eta_measured_sigma_rad.is_some();
    let set = ParamSet::new(setup.chain, setup.cfg.nuisance);
    let q = quantities(setup.chain, &set, eta_known);
    let rows = q
        .labels
        .iter()
        .enumerate()
        .map(|(j, (label, paper, identifiable, given_by_eta))| {
            let kf: Vec<f64> = done.iter().map(|r| r.kf[j]).collect();
            let nls: Vec<f64> = done.iter().map(|r| r.nls[j]).collect();
            let sig: Vec<f64> =
                done.iter().filter_map(|r| r.nls_sigma.get(j).copied()).filter(|v| v.is_finite()).collect();
            let nls_reported_sigma =
                (!sig.is_empty() && sig.len() == done.len()).then(|| sig.iter().sum::<f64>() / sig.len() as f64);
            QuantityRow {
                label: label.clone(),
                kf: ErrorSpread::of(&kf),
                nls: ErrorSpread::of(&nls),
                nls_reported_sigma,
                paper: *paper,
                identifiable: *identifiable,
                given_by_eta: *given_by_eta,
            }
        })
        .collect();
    let deg = |r: [f64; 2]| [r[0].to_degrees(), r[1].to_degrees()];
    let described = format!(
        "α ~ U({:.0}″, {:.0}″), φ ~ U({:.1}°, {:.1}°), η ~ U({:.0}″, {:.0}″); η prior: {}",
        mc.swing_half_angle_rad[0] * ARCSEC_PER_RAD,
        mc.swing_half_angle_rad[1] * ARCSEC_PER_RAD,
        deg(mc.swing_phase_rad)[0],
        deg(mc.swing_phase_rad)[1],
        mc.non_orthogonality_rad[0] * ARCSEC_PER_RAD,
        mc.non_orthogonality_rad[1] * ARCSEC_PER_RAD,
        match mc.eta_measured_sigma_rad {
            Some(s) => format!("an independent measurement with 1σ = {:.2}″", s * ARCSEC_PER_RAD),
            None => "the distribution only (no independent measurement)".into(),
        }
    );
    Summary {
        scenario: setup.scenario.to_owned(),
        seed: setup.seed,
        runs: done.len(),
        runs_requested,
        wall_s,
        threads: rayon::current_num_threads(),
        setup: described,
        rows,
    }
}

/// What a shard writes: its runs' errors (for the merge) and its own summary.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShardFile {
    /// Which slice.
    pub shard: Shard,
    /// The slice's summary (its own runs only).
    pub summary: Summary,
    /// Every run's errors, in index order.
    pub runs: Vec<RunErrors>,
}

/// Why shard files cannot be merged.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// Files of different Monte Carlos.
    #[error("{0}")]
    Mismatch(String),
}

/// Merges shard files into the summary of the whole run: the same statistics, bit for bit, as the
/// unsharded run (the runs are put back in index order; only wall time and threads differ).
pub fn merge(setup: &Setup<'_>, files: &[ShardFile]) -> Result<Summary, MergeError> {
    let Some(first) = files.first() else {
        return Err(MergeError::Mismatch("no shard files given".into()));
    };
    let count = first.shard.count;
    let runs_requested = first.summary.runs_requested;
    let mut wall_s = 0.0f64;
    let mut done: Vec<RunErrors> = Vec::new();
    for f in files {
        let s = &f.summary;
        if f.shard.count != count
            || s.runs_requested != runs_requested
            || s.scenario != first.summary.scenario
            || s.seed != first.summary.seed
            || s.setup != first.summary.setup
        {
            return Err(MergeError::Mismatch(format!(
                "shard {}/{} of {} (seed {}, {} runs) does not belong with shard {}/{} of {} (seed {}, {} runs)",
                f.shard.index,
                f.shard.count,
                s.scenario,
                s.seed,
                s.runs_requested,
                first.shard.index,
                count,
                first.summary.scenario,
                first.summary.seed,
                runs_requested
            )));
        }
        if s.scenario != setup.scenario || s.seed != setup.seed {
            return Err(MergeError::Mismatch(format!(
                "the shards are of {} (seed {}), the scenario given is {} (seed {})",
                s.scenario, s.seed, setup.scenario, setup.seed
            )));
        }
        if f.runs.len() != f.shard.indices(runs_requested as u64).len() {
            return Err(MergeError::Mismatch(format!(
                "shard {}/{count} holds {} of its {} runs (interrupted?)",
                f.shard.index,
                f.runs.len(),
                f.shard.indices(runs_requested as u64).len()
            )));
        }
        wall_s = wall_s.max(s.wall_s);
        done.extend(f.runs.iter().cloned());
    }
    Shard::check_cover(files.iter().map(|f| f.shard), count).map_err(MergeError::Mismatch)?;
    done.sort_by_key(|r| r.index);
    Ok(summarize(setup, runs_requested, &done, wall_s))
}

impl Summary {
    /// The table printed by `rinscope montecarlo`.
    #[must_use]
    pub fn text(&self) -> String {
        let mut s = format!(
            "Monte Carlo: {} of {} runs of {} in {:.1} s on {} threads\n{}\nerrors in arcsec (mean ± std of the signed error, mean |error|; the least squares' reported 1σ, mean over the runs, beside its std)\n",
            self.runs, self.runs_requested, self.scenario, self.wall_s, self.threads, self.setup
        );
        s.push_str(&format!(
            "  {:<24} {:>30} {:>30} {:>12} {:>22}\n",
            "", "static KF", "exact least squares", "reported 1σ", "Jiang et al. 2017 Table 3"
        ));
        for r in &self.rows {
            let f = |st: &ErrorSpread| format!("{:>+9.4} ±{:>8.4} |{:>8.4}|", st.mean, st.std, st.mean_abs);
            let paper = r.paper.map_or(String::new(), |(m, sd)| format!("{m:>9.2} ±{sd:>8.4}"));
            let mark = if r.given_by_eta {
                "   given by the η measurement (its accuracy, returned)"
            } else if r.identifiable {
                ""
            } else {
                "   not identifiable: set by the η prior"
            };
            let reported = r.nls_reported_sigma.map_or(String::new(), |v| format!("{v:.4}"));
            s.push_str(&format!(
                "  {:<24} {} {} {:>12} {:>22}{}\n",
                r.label,
                f(&r.kf),
                f(&r.nls),
                reported,
                paper,
                mark
            ));
        }
        s
    }
}
