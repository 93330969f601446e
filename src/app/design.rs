//! `design`'s one owner: a rotation-scheme designer. It draws indexing sequences under the user's
//! constraints (`model::sequences`), ranks them and the built-in schemes with the averaged error
//! model (`ins::averaged`: what each leaves of the IMU's biases, scale factors and misalignments,
//! through the INS's own position response), confirms the best few beside every built-in with the
//! exact simulation on the same seeds (`app::schemes`), and reports the winner as a `[scheme]`, how
//! far it beats the best built-in and which sources it cancels.

use std::collections::BTreeSet;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::failure::Failure;
use super::outputs::{RecordingRequest, check_output, write_json};
use super::schemes::{BUILT_IN, SchemeRow, SchemesReport, SchemesRequest, with_scheme};
use crate::ins::averaged::{self, Averages, Responses, Score};
use crate::ins::budget::{self, POSITION, Selection, Setup};
use crate::ins::sensor::{ImuErrorSpec, Spec};
use crate::io::files::write_atomically;
use crate::model::earth::Earth;
use crate::model::gimbal::TableErrors;
use crate::model::scheme::{IndexedStep, Scheme};
use crate::model::sequences::{self, Constraints};
use crate::record::sink::Saved;
use crate::scenario::{Params, indexed_scheme_toml};

/// The constraints as a user gives them (degrees, names).
#[derive(Debug, Clone, PartialEq)]
pub struct DesignSpace {
    /// The axes that may move, by name (empty: every axis).
    pub axes: Vec<String>,
    /// Moves per period.
    pub steps: Vec<usize>,
    /// Move sizes, deg.
    pub angles_deg: Vec<f64>,
    /// Cruise rates, deg/s (empty: the scenario's).
    pub rates_deg_per_s: Vec<f64>,
    /// Dwells, s (empty: the scenario's).
    pub dwells_s: Vec<f64>,
    /// The largest excursion of an axis from its start, deg.
    pub max_wrap_deg: f64,
}

impl Default for DesignSpace {
    fn default() -> Self {
        Self {
            axes: Vec::new(),
            steps: vec![8, 16, 32],
            angles_deg: vec![180.0],
            rates_deg_per_s: Vec::new(),
            dwells_s: Vec::new(),
            max_wrap_deg: 360.0,
        }
    }
}

/// `rinscope design` (and Python's `design`).
pub struct DesignRequest {
    /// The scenario: its IMU's error set, table, site, duration.
    pub params: Params,
    /// What the search may choose.
    pub space: DesignSpace,
    /// Sequences drawn (duplicates dropped).
    pub candidates: usize,
    /// Local moves tried from each of the model's best drawn sequences (0: none).
    pub refine: usize,
    /// How many of the model's best are confirmed by the exact simulation (beside every built-in).
    pub confirm: usize,
    /// Seeds per confirmed scheme.
    pub seeds: u64,
    /// Threads (default: every core).
    pub threads: Option<usize>,
    /// `--json`.
    pub json: Option<PathBuf>,
    /// `--save-scheme`: the winner's `[scheme]` as a file.
    pub save_scheme: Option<PathBuf>,
    /// The recording (the confirmed schemes side by side).
    pub recording: RecordingRequest,
}

/// A ranked scheme.
#[derive(Debug, Clone, Serialize)]
pub struct Ranked {
    /// Its label: a built-in's name or `found-<rank>`.
    pub label: String,
    /// Built in.
    pub built_in: bool,
    /// The model's RMS horizontal position error over the run from the biases, scale factors and
    /// misalignments it leaves, m.
    pub model_m: f64,
    /// That per source, m (largest first).
    pub model_terms: Vec<(String, f64)>,
    /// Moves per period.
    pub moves: usize,
    /// One period, s (None: not a repeated sequence).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub period_s: Option<f64>,
    /// The exact simulation's row, if confirmed (the drawn best and the built-ins the model puts
    /// within 5× of the best built-in).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exact: Option<SchemeRow>,
    /// Its `[scheme]` (TOML).
    pub scheme: String,
}

/// The model's ranking as the recording's document shows it (before the exact simulation, whose
/// table follows it): each scheme's model score and largest term, which were confirmed.
fn model_ranking(ranked: &[Ranked], simulated: &dyn Fn(&Ranked) -> bool) -> String {
    let mut s = String::from(
        "# The designer's ranking\n\nThe averaged model's expected RMS horizontal position error of each scheme drawn \
         and built in (docs/schemes.md, \"A designer\"); those marked ✓ were simulated exactly, and their plots and \
         table follow. The chosen one and the `[scheme]` to run are in the terminal and `--json`.\n\n\
         | scheme | moves | period s | model m | largest model term | simulated |\n|---|---|---|---|---|---|\n",
    );
    for r in ranked {
        let [label, moves, period, model, top] = r.model_cells();
        s.push_str(&format!(
            "| {label} | {moves} | {period} | {model} | {top} | {} |\n",
            if simulated(r) { "✓" } else { "" }
        ));
    }
    s
}

impl Ranked {
    /// Its label, moves, period (s), model score (m) and largest model term, as the tables print them.
    fn model_cells(&self) -> [String; 5] {
        [
            self.label.clone(),
            self.moves.to_string(),
            self.period_s.map_or_else(|| "—".into(), |x| format!("{x:.0}")),
            num(self.model_m),
            self.model_terms.first().map_or_else(String::new, |(n, m)| format!("{n} {}", num(*m))),
        ]
    }
}

/// What `design` reports (and `--json` writes).
#[derive(Debug, Clone, Serialize)]
pub struct DesignReport {
    /// The scenario.
    pub scenario: String,
    /// Simulated time, s.
    pub duration_s: f64,
    /// Sequences drawn and, of them, distinct.
    pub drawn: usize,
    /// Distinct sequences the model ranked (drawn and refined).
    pub distinct: usize,
    /// Local moves tried from each of the best drawn sequences, and how many of those searches
    /// ended on a sequence not drawn.
    pub refine: (usize, usize),
    /// The confirmed and the built-in schemes, the model's order.
    pub ranked: Vec<Ranked>,
    /// The best drawn sequence by the exact median position error at the end (its `[scheme]` is
    /// the design).
    pub best: String,
    /// The best built-in one by the same.
    pub best_built_in: String,
    /// best built-in's median ÷ best's median (> 1: the designed scheme is better; < 1: a built-in
    /// is, and the report says so).
    pub ratio: f64,
    /// The same per seed (the same seeds): its median and range.
    pub ratio_per_seed: super::schemes::Spread,
    /// The sources the best cancels, by the model: (source, best built-in's m, best's m).
    pub cancels: Vec<(String, f64, f64)>,
    /// Seconds: the position responses, the model over every candidate, the exact simulations, all.
    pub wall_s: [f64; 4],
    /// Threads.
    pub threads: usize,
    /// Stopped early.
    pub interrupted: bool,
    /// The recording kept (not in the JSON).
    #[serde(skip)]
    pub saved: Option<Saved>,
}

/// The search's constraints in SI: the axes by index, the scenario's own move where none is given.
fn constraints(p: &Params, space: &DesignSpace) -> Result<Constraints, Failure> {
    let chain = &p.table.chain;
    let axes = if space.axes.is_empty() {
        (0..chain.axes().len()).collect()
    } else {
        space
            .axes
            .iter()
            .map(|a| {
                chain.index_of(a).ok_or_else(|| {
                    let names: Vec<&str> = chain.axes().iter().map(|x| x.name.as_str()).collect();
                    Failure::input(format!("design: --axes {a}: the table's axes are {}", names.join(", ")))
                })
            })
            .collect::<Result<Vec<_>, _>>()?
    };
    // The scenario's own move (its first step), else 10°/s, 10°/s², 60 s.
    let own = p.table.scheme.steps().first().copied();
    let rad = |v: &[f64]| v.iter().map(|x| x.to_radians()).collect::<Vec<_>>();
    let c = Constraints {
        axes,
        steps: space.steps.clone(),
        angles_rad: rad(&space.angles_deg),
        rates_rad_per_s: if space.rates_deg_per_s.is_empty() {
            vec![own.map_or(10f64.to_radians(), |s| s.rate_rad_per_s)]
        } else {
            rad(&space.rates_deg_per_s)
        },
        dwells_s: if space.dwells_s.is_empty() {
            vec![own.map_or(60.0, |s| s.dwell_s)]
        } else {
            space.dwells_s.clone()
        },
        accel_rad_per_s2: own.map_or(10f64.to_radians(), |s| s.accel_rad_per_s2),
        max_wrap_rad: space.max_wrap_deg.to_radians(),
    };
    match c.problem() {
        Some(why) => Err(Failure::input(format!("design: {why}"))),
        None => Ok(c),
    }
}

/// The navigation-frame position responses: six runs of the exact INS on the table at rest at its
/// start, each with one constant error along one navigation axis and nothing else.
fn responses(p: &Params, n_from_s: &Matrix3<f64>, sample_s: f64, stop: &AtomicBool) -> Responses {
    use rayon::prelude::*;
    const GYRO: f64 = 1e-8; // rad/s (0.002°/h)
    const ACCEL: f64 = 1e-4; // m/s² (10 µg)
    let setup = |gyro: bool, k: usize| {
        let mut table = p.table.clone();
        let n = table.chain.axes().len();
        table.truth = TableErrors::zero(n);
        table.compensation = TableErrors::zero(n);
        table.scheme = Scheme::continuous(table.scheme.state(0.0).0[..n].to_vec(), vec![0.0; n]);
        let mut ins = p.ins.clone().expect("checked: an INS");
        ins.errors = ImuErrorSpec::default();
        ins.imu_compensation = None;
        ins.initial_error_rad = Vector3::zeros();
        // FRAME: the IMU-axis error that is `unit` along navigation axis k.
        let along = |unit: f64| Spec::Fixed((n_from_s.transpose() * Vector3::ith(k, unit)).into());
        if gyro {
            ins.errors.gyro.bias_rad_per_s = along(GYRO);
        } else {
            ins.errors.accel.bias_mps2 = along(ACCEL);
        }
        Setup { table, ins: Some(ins), site: p.site, seed: p.meta.seed, timeline: p.timeline(), sample_s }
    };
    let keep_going = || !stop.load(Ordering::Relaxed);
    let traces: Vec<Vec<[f64; 2]>> = (0..6)
        .into_par_iter()
        .map(|r| {
            let t = budget::simulate(&setup(r < 3, r % 3), Selection::All, &keep_going);
            t.values.iter().map(|v| [v[POSITION[0]], v[POSITION[1]]]).collect()
        })
        .collect();
    Responses::from_runs(
        [&traces[0], &traces[1], &traces[2]],
        GYRO,
        [&traces[3], &traces[4], &traces[5]],
        ACCEL,
        sample_s,
    )
}

/// The model's RMS position error, m, and its share per source (named, largest first).
type Scored = (f64, Vec<(String, f64)>);

/// A scheme's model score and its terms named, largest first.
fn scored(avg: &Averages, errors: &ImuErrorSpec, r: &Responses, axes: &[String]) -> Scored {
    let Score { rms_m, mut terms } = averaged::score(avg, errors, r);
    terms.sort_by(|a, b| b.1.total_cmp(&a.1));
    (rms_m, terms.into_iter().map(|(s, m)| (s.name(axes), m)).collect())
}

/// How many of the model's best drawn sequences a local search starts from.
const REFINED: usize = 8;

/// `design`'s one owner.
///
/// # Errors
/// A scenario without navigation or with a moving vehicle, constraints no sequence fits, an output
/// that cannot be written, a recording that fails.
pub fn execute(req: &DesignRequest, stop: &AtomicBool) -> Result<DesignReport, Failure> {
    use rayon::prelude::*;
    check_output("--json", req.json.as_deref())?;
    check_output("--save-scheme", req.save_scheme.as_deref())?;
    let p = &req.params;
    let Some(ins) = p.ins.as_ref().filter(|i| i.navigation.is_some()) else {
        return Err(Failure::input(format!(
            "design: {} has no [imu] with [navigation]: there is no position error to design for (try budget-dual-axis-16)",
            p.meta.name
        )));
    };
    if !p.table.vehicle.is_fixed() {
        return Err(Failure::input(format!(
            "design: {}'s vehicle moves: the averaged model assumes a base at rest (a ship's or car's motion is not in it)",
            p.meta.name
        )));
    }
    if req.candidates == 0 || req.seeds == 0 {
        return Err(Failure::input("design: at least one candidate and one seed"));
    }
    let c = constraints(p, &req.space)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(req.threads.unwrap_or(0))
        .build()
        .map_err(|e| Failure::run(format!("design: no thread pool ({e})")))?;
    let started = Instant::now();
    let axes: Vec<String> = p.table.chain.axes().iter().map(|a| a.name.clone()).collect();
    let chain = &p.table.chain;
    let nominal = chain.error_rotations(&TableErrors::zero(axes.len()));
    let n_from_b = p.table.vehicle.n_from_b(0.0).matrix();
    let initial = p.table.scheme.state(0.0).0;
    let n_from_s = n_from_b * chain.b_from_s(&nominal, &initial).matrix();
    let sample_s = (p.duration_s / 2000.0).max(1.0);
    errln!("rinscope: design: the INS's position responses (6 runs of {:.1} h)...", p.duration_s / 3600.0);
    let resp = pool.install(|| responses(p, &n_from_s, sample_s, stop));
    let t_responses = started.elapsed().as_secs_f64();
    // The candidates: drawn (distinct by their TOML) and the built-ins that fit the table.
    let mut rng = ChaCha8Rng::seed_from_u64(p.meta.seed);
    let mut seen = BTreeSet::new();
    let mut drawn_steps = Vec::new();
    let mut drawn = 0;
    while drawn_steps.len() < req.candidates && drawn < 20 * req.candidates {
        drawn += 1;
        let steps = sequences::candidate(&c, &mut rng);
        let text = indexed_scheme_toml(&axes, 0.0, &steps);
        if seen.insert(text.clone()) {
            drawn_steps.push((steps, text));
        }
    }
    let mut pool_of: Vec<(String, bool, Scheme, String)> = BUILT_IN
        .iter()
        .filter_map(|(name, text)| {
            let q = with_scheme(p, name, text).ok()?;
            Some(((*name).to_owned(), true, q.table.scheme.clone(), (*text).to_owned()))
        })
        .collect();
    for (steps, text) in drawn_steps {
        pool_of.push((String::new(), false, Scheme::indexed(initial[..axes.len()].to_vec(), 0.0, steps, true), text));
    }
    errln!("rinscope: design: the averaged model over {} schemes...", pool_of.len());
    let earth = Earth::at(p.site);
    let fallback_s = p.duration_s.min(86_400.0);
    let model = |scheme: &Scheme| {
        if stop.load(Ordering::Relaxed) {
            return (f64::NAN, Vec::new());
        }
        let avg = averaged::averages(chain, scheme, &n_from_b, &earth, fallback_s, 0.05);
        scored(&avg, &ins.errors, &resp, &axes)
    };
    let mut scores: Vec<Scored> = pool.install(|| pool_of.par_iter().map(|(_, _, scheme, _)| model(scheme)).collect());
    // A local search from the model's best drawn sequences: a neighbour (`sequences::neighbour`)
    // replaces the sequence when the model scores it lower.
    let sequence = |steps: Vec<IndexedStep>| Scheme::indexed(initial[..axes.len()].to_vec(), 0.0, steps, true);
    let mut starts: Vec<usize> = (0..pool_of.len()).filter(|k| !pool_of[*k].1).collect();
    starts.sort_by(|a, b| scores[*a].0.total_cmp(&scores[*b].0));
    starts.truncate(if req.refine > 0 { REFINED } else { 0 });
    if !starts.is_empty() {
        errln!("rinscope: design: {} local moves from each of the best {}...", req.refine, starts.len());
    }
    let refined: Vec<(Scheme, Scored)> = pool.install(|| {
        starts
            .par_iter()
            .enumerate()
            .map(|(r, &k)| {
                let mut rng = ChaCha8Rng::seed_from_u64(p.meta.seed.wrapping_add(1 + r as u64));
                let (mut best, mut score) = (pool_of[k].2.clone(), scores[k].clone());
                for _ in 0..req.refine {
                    let next = sequence(sequences::neighbour(best.steps(), &c, &mut rng));
                    let s = model(&next);
                    if s.0 < score.0 {
                        (best, score) = (next, s);
                    }
                }
                (best, score)
            })
            .collect()
    });
    let mut improved = 0;
    for (scheme, score) in refined {
        let text = indexed_scheme_toml(&axes, 0.0, scheme.steps());
        if seen.insert(text.clone()) {
            improved += 1;
            pool_of.push((String::new(), false, scheme, text));
            scores.push(score);
        }
    }
    let t_model = started.elapsed().as_secs_f64() - t_responses;
    let mut order: Vec<usize> = (0..pool_of.len()).collect();
    order.sort_by(|a, b| scores[*a].0.total_cmp(&scores[*b].0));
    let mut ranked = Vec::new();
    let mut found = 0;
    for k in order {
        let (name, built_in, scheme, text) = &pool_of[k];
        if !*built_in {
            if found == req.confirm {
                continue;
            }
            found += 1;
        }
        ranked.push(Ranked {
            label: if *built_in { name.clone() } else { format!("found-{found}") },
            built_in: *built_in,
            model_m: scores[k].0,
            model_terms: scores[k].1.clone(),
            moves: scheme.steps().len(),
            period_s: scheme.period_window().map(|w| w.1),
            exact: None,
            scheme: text.clone(),
        });
    }
    // The exact simulation on the same seeds: the drawn best and the built-ins the model puts within
    // HOPELESS of the best built-in (one further behind cannot be the best built-in: the model and the
    // simulation agree to well within that; its model row is still reported).
    const HOPELESS: f64 = 5.0;
    let t_exact = Instant::now();
    let floor = ranked.iter().filter(|r| r.built_in).map(|r| r.model_m).fold(f64::INFINITY, f64::min);
    let confirmed = |r: &Ranked| !r.built_in || r.model_m <= HOPELESS * floor || !floor.is_finite();
    let schemes = ranked.iter().filter(|r| confirmed(r)).map(|r| (r.label.clone(), r.scheme.clone())).collect();
    let request = SchemesRequest {
        params: p.clone(),
        schemes,
        seeds: req.seeds,
        threads: req.threads,
        json: None,
        budget: false,
        modulable_only: true,
        preface: Some(model_ranking(&ranked, &confirmed)),
        recording: req.recording.clone(),
    };
    let mut exact: SchemesReport = super::schemes::execute(&request, stop)?;
    let t_exact = t_exact.elapsed().as_secs_f64();
    for r in &mut ranked {
        r.exact = exact.rows.iter().find(|x| x.scheme == r.label).cloned();
    }
    let end = |r: &Ranked| r.exact.as_ref().map_or(f64::NAN, |x| x.position_end_m.median);
    let best_of = |built_in: bool| {
        ranked.iter().filter(|r| r.built_in == built_in).min_by(|a, b| end(a).total_cmp(&end(b))).cloned()
    };
    let (Some(best_found), Some(best_built_in)) = (best_of(false), best_of(true)) else {
        return Err(Failure::input("design: the constraints left no drawn sequence or no built-in fits the table"));
    };
    let best = &best_found;
    let per_seed = super::schemes::Spread::of(
        exact
            .per_seed_end_m(&best_built_in.label)
            .iter()
            .zip(exact.per_seed_end_m(&best.label))
            .map(|(b, f)| b / f)
            .collect(),
    );
    let term = |r: &Ranked, name: &str| r.model_terms.iter().find(|(n, _)| n == name).map_or(0.0, |x| x.1);
    let mut cancels: Vec<(String, f64, f64)> = best_built_in
        .model_terms
        .iter()
        .map(|(n, m)| (n.clone(), *m, term(best, n)))
        .filter(|(_, b, f)| *b > 1.05 * f)
        .collect();
    cancels.sort_by(|a, b| (b.1 - b.2).total_cmp(&(a.1 - a.2)));
    cancels.truncate(4);
    if let Some(path) = &req.save_scheme {
        write_atomically(
            path,
            format!("# rinscope design: {} on {}\n{}", best.label, p.meta.name, best.scheme).as_bytes(),
        )
        .map_err(|e| Failure::output("--save-scheme", &e))?;
    }
    let mut report = DesignReport {
        scenario: p.meta.name.clone(),
        duration_s: exact.duration_s,
        drawn,
        distinct: pool_of.len() - ranked.iter().filter(|r| r.built_in).count(),
        refine: (req.refine, improved),
        ratio: end(&best_built_in) / end(best),
        ratio_per_seed: per_seed,
        best: best.label.clone(),
        best_built_in: best_built_in.label.clone(),
        cancels,
        ranked,
        wall_s: [t_responses, t_model, t_exact, started.elapsed().as_secs_f64()],
        threads: pool.current_num_threads(),
        interrupted: exact.interrupted || stop.load(Ordering::SeqCst),
        saved: exact.saved.take(),
    };
    if report.interrupted {
        report.ratio = f64::NAN;
    }
    if let Some(path) = &req.json {
        write_json("--json", path, &report)?;
    }
    Ok(report)
}

/// A number for a table.
fn num(x: f64) -> String {
    if !x.is_finite() {
        "—".into()
    } else if x.abs() >= 100.0 {
        format!("{x:.0}")
    } else {
        format!("{x:.3}")
    }
}

impl DesignReport {
    /// The best's `[scheme]`.
    #[must_use]
    pub fn scheme(&self) -> &str {
        self.ranked.iter().find(|r| r.label == self.best).map_or("", |r| r.scheme.as_str())
    }

    /// The table a terminal shows.
    #[must_use]
    pub fn text(&self) -> String {
        let mut s = format!(
            "{}: {} sequences drawn; {} local moves from each of the best {REFINED}, {} of which ended on a new sequence; \
             {} distinct, ranked by the averaged model with the built-ins; the best {} confirmed by \
             the exact simulation ({:.1} h, median [min, max] over the seeds) of the errors a scheme can modulate (biases, \
             scale factors, misalignments, the table's; the noise and the alignment, alike under every scheme, are \
             `budget`'s)\n\n",
            self.scenario,
            self.drawn,
            self.refine.0,
            self.refine.1,
            self.distinct,
            self.ranked.iter().filter(|r| !r.built_in).count(),
            self.duration_s / 3600.0
        );
        s.push_str(&format!(
            "{:<14} {:>6} {:>9} {:>11}  {:<32} {}\n",
            "scheme", "moves", "period s", "model m", "exact position at the end, m", "largest model term"
        ));
        for r in &self.ranked {
            let exact = r.exact.as_ref().map_or_else(
                || "—".into(),
                |x| {
                    format!(
                        "{} [{}, {}]",
                        num(x.position_end_m.median),
                        num(x.position_end_m.min),
                        num(x.position_end_m.max)
                    )
                },
            );
            let [label, moves, period, model, top] = r.model_cells();
            s.push_str(&format!("{label:<14} {moves:>6} {period:>9} {model:>11}  {exact:<32} {top}\n"));
        }
        let per_seed = format!(
            "per seed {:.2}× [{:.2}, {:.2}]",
            self.ratio_per_seed.median, self.ratio_per_seed.min, self.ratio_per_seed.max
        );
        if self.ratio >= 1.0 {
            s.push_str(&format!(
                "\ndesigned: {} — {:.2}× better than the best built-in, {} (median position error at the end; {per_seed})\n",
                self.best, self.ratio, self.best_built_in
            ));
        } else {
            s.push_str(&format!(
                "\ndesigned: {} — no drawn sequence beats the best built-in, {}: this one's position error at the end is \
                 {:.2}× its (median; the built-in's error ÷ this one's {per_seed}); widen the constraints or keep {}\n",
                self.best,
                self.best_built_in,
                1.0 / self.ratio,
                self.best_built_in
            ));
        }
        if !self.cancels.is_empty() {
            s.push_str(&format!("what it cancels that {} leaves (the model, m):\n", self.best_built_in));
            for (n, b, f) in &self.cancels {
                s.push_str(&format!("  {n:<22} {} → {}\n", num(*b), num(*f)));
            }
        }
        // The averaged model takes a period well inside the Schuler loop's 84 min: a longer one
        // resonates with it and is ranked on the simulation alone.
        let reach = 2.0 * std::f64::consts::PI / crate::model::earth::schuler_rate() / 3.0;
        if self.ranked.iter().any(|r| !r.built_in && r.period_s.is_some_and(|t| t > reach)) {
            s.push_str(&format!(
                "note: periods over {:.0} min (a third of the Schuler period) are beyond the averaged model's reach: \
                 its numbers for them rank loosely, the simulation decides (shorter dwells or fewer moves keep it in reach)\n",
                reach / 60.0
            ));
        }
        s.push_str(&format!(
            "time: responses {:.1} s, model {:.1} s, exact {:.1} s, all {:.1} s on {} threads\n\n{}",
            self.wall_s[0],
            self.wall_s[1],
            self.wall_s[2],
            self.wall_s[3],
            self.threads,
            self.scheme()
        ));
        s
    }
}
