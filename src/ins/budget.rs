//! The error budget: how much of the INS's and the table's errors each error source causes.
//!
//! Exact, by simulation: the run with one source alone (the same random draws as the full run:
//! [`ImuSources`]; the table's error with its own compensation) less the run with no source at all
//! (the algorithm's own error: the *baseline*) is that source's part. The baseline plus every part
//! against the full run leaves the non-linear remainder (a source's effect that depends on another:
//! a bias turned by a swinging shaft, a readout that quantizes the sum), which the budget states.

use nalgebra::Vector3;

use super::InsParams;
use super::pipeline::InsRun;
use super::sensor::{ImuErrorSpec, ImuSources, Spec, TriadSources};
use crate::math::timeline::Timeline;
use crate::math::units::ARCSEC_PER_RAD;
use crate::model::earth::Site;
use crate::model::gimbal::TableErrors;
use crate::sim::{DemodState, Model, TableParams};

/// The gyro or the accelerometer triad.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Triad {
    /// Gyros.
    Gyro,
    /// Accelerometers.
    Accel,
}

impl Triad {
    fn name(self) -> &'static str {
        match self {
            Self::Gyro => "gyro",
            Self::Accel => "accel",
        }
    }
}

/// One error term of the IMU.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImuTerm {
    /// Constant bias of one axis (0 = x).
    Bias(Triad, usize),
    /// Scale-factor error of one axis.
    Scale(Triad, usize),
    /// The triad's six misalignment angles.
    Misalignment(Triad),
    /// White noise N.
    White(Triad),
    /// The Gauss-Markov bias.
    Markov(Triad),
    /// IEEE's bias instability B.
    Instability(Triad),
    /// IEEE's rate random walk K.
    RandomWalk(Triad),
    /// IEEE's ramp R.
    Ramp(Triad),
    /// Quantization and saturation.
    Readout(Triad),
    /// The g-dependent gyro bias.
    GSensitivity,
    /// Ring-laser-gyro dither.
    Dither,
}

/// One error of the table (per axis where it has one).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableTerm {
    /// The shaft's swing cone (half-angle and phase).
    Swing(usize),
    /// The axis's tilt toward the previous one.
    NonOrthogonality(usize),
    /// The encoder's constant offset.
    EncoderOffset(usize),
    /// The encoder's scale-factor error.
    EncoderScale(usize),
    /// The encoder's latch delay.
    EncoderDelay(usize),
    /// The encoder's white noise.
    EncoderNoise(usize),
    /// The base's installation on the body.
    Installation,
    /// The IMU's mounting on the last gimbal.
    ImuMount,
}

/// What an error budget attributes the errors to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// An IMU error term.
    Imu(ImuTerm),
    /// A table error: its true value and what the compensated demodulation assumes of it.
    Table(TableTerm),
    /// The INS's initial alignment error.
    Alignment,
}

const AXES: [&str; 3] = ["x", "y", "z"];

impl Source {
    /// Its name, with the table's axis names (`axes`).
    #[must_use]
    pub fn name(&self, axes: &[String]) -> String {
        let axis = |k: usize| axes.get(k).map_or_else(|| format!("axis {k}"), Clone::clone);
        match *self {
            Self::Imu(t) => match t {
                ImuTerm::Bias(s, k) => format!("{} bias {}", s.name(), AXES[k]),
                ImuTerm::Scale(s, k) => format!("{} scale factor {}", s.name(), AXES[k]),
                ImuTerm::Misalignment(s) => format!("{} misalignment", s.name()),
                ImuTerm::White(s) => format!("{} white noise (N)", s.name()),
                ImuTerm::Markov(s) => format!("{} Gauss-Markov bias", s.name()),
                ImuTerm::Instability(s) => format!("{} bias instability (B)", s.name()),
                ImuTerm::RandomWalk(s) => format!("{} random walk (K)", s.name()),
                ImuTerm::Ramp(s) => format!("{} ramp (R)", s.name()),
                ImuTerm::Readout(s) => format!("{} quantization / saturation", s.name()),
                ImuTerm::GSensitivity => "gyro g-sensitivity".to_owned(),
                ImuTerm::Dither => "gyro dither".to_owned(),
            },
            Self::Table(t) => match t {
                TableTerm::Swing(k) => format!("{} swing cone", axis(k)),
                TableTerm::NonOrthogonality(k) => format!("{} non-orthogonality", axis(k)),
                TableTerm::EncoderOffset(k) => format!("{} encoder offset", axis(k)),
                TableTerm::EncoderScale(k) => format!("{} encoder scale", axis(k)),
                TableTerm::EncoderDelay(k) => format!("{} encoder delay", axis(k)),
                TableTerm::EncoderNoise(k) => format!("{} encoder noise", axis(k)),
                TableTerm::Installation => "table installation".to_owned(),
                TableTerm::ImuMount => "IMU mounting".to_owned(),
            },
            Self::Alignment => "initial alignment".to_owned(),
        }
    }

    /// The element of the table it belongs to, for the 3D scene: `Some(axis)` for an axis's error,
    /// `None` for the IMU, the base, the mounting and the alignment.
    #[must_use]
    pub fn table_axis(&self) -> Option<usize> {
        match *self {
            Self::Table(
                TableTerm::Swing(k)
                | TableTerm::NonOrthogonality(k)
                | TableTerm::EncoderOffset(k)
                | TableTerm::EncoderScale(k)
                | TableTerm::EncoderDelay(k)
                | TableTerm::EncoderNoise(k),
            ) => Some(k),
            _ => None,
        }
    }
}

/// Whether a value given as a spec is non-zero on axis `k`.
fn spec_on(s: Spec, k: usize) -> bool {
    match s {
        Spec::Sigma(x) => x != 0.0,
        Spec::Fixed(v) => v[k] != 0.0,
    }
}

/// The terms of one triad that are there, in a fixed order.
fn triad_terms(
    triad: Triad,
    bias: Spec,
    scale: Spec,
    misalignment: f64,
    noise: &super::noise::IeeeTerms,
    markov: f64,
) -> Vec<ImuTerm> {
    let mut out = Vec::new();
    out.extend((0..3).filter(|&k| spec_on(bias, k)).map(|k| ImuTerm::Bias(triad, k)));
    out.extend((0..3).filter(|&k| spec_on(scale, k)).map(|k| ImuTerm::Scale(triad, k)));
    let flags = [
        (misalignment != 0.0, ImuTerm::Misalignment(triad)),
        (noise.random_walk_si > 0.0, ImuTerm::White(triad)),
        (markov > 0.0, ImuTerm::Markov(triad)),
        (noise.bias_instability_si > 0.0, ImuTerm::Instability(triad)),
        (noise.rate_random_walk_si > 0.0, ImuTerm::RandomWalk(triad)),
        (noise.rate_ramp_si != 0.0, ImuTerm::Ramp(triad)),
        (noise.quantization_si > 0.0 || noise.saturation_si.is_some(), ImuTerm::Readout(triad)),
    ];
    out.extend(flags.into_iter().filter(|(on, _)| *on).map(|(_, t)| t));
    out
}

/// The IMU's error terms that are there.
fn imu_terms(e: &ImuErrorSpec) -> Vec<ImuTerm> {
    let g = &e.gyro;
    let a = &e.accel;
    let mut out = triad_terms(
        Triad::Gyro,
        g.bias_rad_per_s,
        g.scale,
        g.misalignment_rad,
        &g.noise,
        if g.correlation_s > 0.0 { g.markov_sigma_rad_per_s } else { 0.0 },
    );
    if e.g_sensitivity != 0.0 {
        out.push(ImuTerm::GSensitivity);
    }
    if e.dither.amplitudes_rad.iter().any(|x| *x != 0.0) {
        out.push(ImuTerm::Dither);
    }
    out.extend(triad_terms(
        Triad::Accel,
        a.bias_mps2,
        a.scale,
        a.misalignment_rad,
        &a.noise,
        if a.correlation_s > 0.0 { a.markov_sigma_mps2 } else { 0.0 },
    ));
    out
}

/// The table's errors that are there: a true value or an assumed one (a compensation of an error
/// that is not there is a source too).
fn table_terms(table: &TableParams) -> Vec<TableTerm> {
    let (t, c) = (&table.truth, &table.compensation);
    let mut out = Vec::new();
    for k in 0..t.axes.len() {
        let (a, b) = (&t.axes[k], c.axes.get(k).copied().unwrap_or_default());
        let either = |f: fn(&crate::model::gimbal::AxisErrors) -> f64| f(a) != 0.0 || f(&b) != 0.0;
        let flags = [
            (either(|e| e.swing_half_angle_rad), TableTerm::Swing(k)),
            (either(|e| e.non_orthogonality_rad), TableTerm::NonOrthogonality(k)),
            (either(|e| e.encoder_offset_rad), TableTerm::EncoderOffset(k)),
            (either(|e| e.encoder_scale), TableTerm::EncoderScale(k)),
            (either(|e| e.encoder_delay_s), TableTerm::EncoderDelay(k)),
            (either(|e| e.encoder_noise_rad), TableTerm::EncoderNoise(k)),
        ];
        out.extend(flags.into_iter().filter(|(on, _)| *on).map(|(_, t)| t));
    }
    if t.installation_rad != Vector3::zeros() || c.installation_rad != Vector3::zeros() {
        out.push(TableTerm::Installation);
    }
    if t.imu_mount_rad != Vector3::zeros() || c.imu_mount_rad != Vector3::zeros() {
        out.push(TableTerm::ImuMount);
    }
    out
}

/// Every source there is in `table` and `ins`: the IMU's terms, the table's errors, the alignment.
#[must_use]
pub fn sources(table: &TableParams, ins: Option<&InsParams>) -> Vec<Source> {
    let mut out: Vec<Source> = Vec::new();
    if let Some(ins) = ins {
        out.extend(imu_terms(&ins.errors).into_iter().map(Source::Imu));
    }
    out.extend(table_terms(table).into_iter().map(Source::Table));
    if ins.is_some_and(|i| i.initial_error_rad != Vector3::zeros()) {
        out.push(Source::Alignment);
    }
    out
}

/// Only `term` of `from` (both the truth's and the compensation's use this), every other error 0.
fn table_only(from: &TableErrors, term: Option<TableTerm>) -> TableErrors {
    let mut out = TableErrors::zero(from.axes.len());
    let Some(term) = term else { return out };
    match term {
        TableTerm::Installation => out.installation_rad = from.installation_rad,
        TableTerm::ImuMount => out.imu_mount_rad = from.imu_mount_rad,
        TableTerm::Swing(k) => {
            out.axes[k].swing_half_angle_rad = from.axes[k].swing_half_angle_rad;
            out.axes[k].swing_phase_rad = from.axes[k].swing_phase_rad;
        }
        TableTerm::NonOrthogonality(k) => out.axes[k].non_orthogonality_rad = from.axes[k].non_orthogonality_rad,
        TableTerm::EncoderOffset(k) => out.axes[k].encoder_offset_rad = from.axes[k].encoder_offset_rad,
        TableTerm::EncoderScale(k) => out.axes[k].encoder_scale = from.axes[k].encoder_scale,
        TableTerm::EncoderDelay(k) => out.axes[k].encoder_delay_s = from.axes[k].encoder_delay_s,
        TableTerm::EncoderNoise(k) => out.axes[k].encoder_noise_rad = from.axes[k].encoder_noise_rad,
    }
    out
}

/// Only `term` of the IMU's error terms acting.
fn imu_only(term: Option<ImuTerm>) -> ImuSources {
    let mut on = ImuSources::NONE;
    let Some(term) = term else { return on };
    let pick = |on: &mut ImuSources, t: Triad, f: &dyn Fn(&mut TriadSources)| match t {
        Triad::Gyro => f(&mut on.gyro),
        Triad::Accel => f(&mut on.accel),
    };
    match term {
        ImuTerm::Bias(t, k) => pick(&mut on, t, &|s| s.bias[k] = true),
        ImuTerm::Scale(t, k) => pick(&mut on, t, &|s| s.scale[k] = true),
        ImuTerm::Misalignment(t) => pick(&mut on, t, &|s| s.misalignment = true),
        ImuTerm::White(t) => pick(&mut on, t, &|s| s.white = true),
        ImuTerm::Markov(t) => pick(&mut on, t, &|s| s.markov = true),
        ImuTerm::Instability(t) => pick(&mut on, t, &|s| s.instability = true),
        ImuTerm::RandomWalk(t) => pick(&mut on, t, &|s| s.random_walk = true),
        ImuTerm::Ramp(t) => pick(&mut on, t, &|s| s.ramp = true),
        ImuTerm::Readout(t) => pick(&mut on, t, &|s| s.readout = true),
        ImuTerm::GSensitivity => on.g_sensitivity = true,
        ImuTerm::Dither => on.dither = true,
    }
    on
}

/// Below this a channel's size is rounding (1e-9 of its unit: arcsec, m, m/s): no remainder is
/// stated relative to it.
pub const ROUNDING: f64 = 1e-9;

/// What to simulate: every source (`All`), none (`Nothing`: the baseline), or one alone.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Selection {
    /// The full run.
    All,
    /// No error source: the algorithm's own error.
    Nothing,
    /// One source alone.
    Only(Source),
}

/// `table` and `ins` with only `selection`'s errors.
#[must_use]
pub fn select(table: &TableParams, ins: Option<&InsParams>, selection: Selection) -> (TableParams, Option<InsParams>) {
    let only = match selection {
        Selection::All => return (table.clone(), ins.cloned()),
        Selection::Nothing => None,
        Selection::Only(s) => Some(s),
    };
    let table_term = match only {
        Some(Source::Table(t)) => Some(t),
        _ => None,
    };
    let mut t = table.clone();
    t.truth = table_only(&table.truth, table_term);
    t.compensation = table_only(&table.compensation, table_term);
    let ins = ins.map(|i| {
        let mut i = i.clone();
        i.sources = imu_only(match only {
            Some(Source::Imu(term)) => Some(term),
            _ => None,
        });
        if only != Some(Source::Alignment) {
            i.initial_error_rad = Vector3::zeros();
        }
        i
    });
    (t, ins)
}

/// One quantity the budget attributes: its group, component and unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Channel {
    /// The group ("INS attitude", "velocity", ...).
    pub group: &'static str,
    /// The component ("heading", "east", ...).
    pub component: &'static str,
    /// The unit.
    pub unit: &'static str,
}

impl Channel {
    /// Its key in JSON, exports and entity paths: `ins_attitude_heading_arcsec`, `position_east_m`,
    /// `velocity_north_m_per_s`, `table_uncompensated_pitch_arcsec`.
    #[must_use]
    pub fn key(&self) -> String {
        let group: String =
            self.group.chars().map(|x| if x.is_ascii_alphanumeric() { x.to_ascii_lowercase() } else { '_' }).collect();
        format!("{}_{}_{}", group.replace("__", "_"), self.component, self.unit.replace("m/s", "m_per_s"))
    }
}

/// Every channel, in the order of [`Trace::values`]' rows.
pub const CHANNELS: [Channel; 13] = [
    Channel { group: "INS attitude", component: "pitch", unit: "arcsec" },
    Channel { group: "INS attitude", component: "roll", unit: "arcsec" },
    Channel { group: "INS attitude", component: "heading", unit: "arcsec" },
    Channel { group: "velocity", component: "east", unit: "m/s" },
    Channel { group: "velocity", component: "north", unit: "m/s" },
    Channel { group: "position", component: "east", unit: "m" },
    Channel { group: "position", component: "north", unit: "m" },
    Channel { group: "table, uncompensated", component: "pitch", unit: "arcsec" },
    Channel { group: "table, uncompensated", component: "roll", unit: "arcsec" },
    Channel { group: "table, uncompensated", component: "heading", unit: "arcsec" },
    Channel { group: "table, compensated", component: "pitch", unit: "arcsec" },
    Channel { group: "table, compensated", component: "roll", unit: "arcsec" },
    Channel { group: "table, compensated", component: "heading", unit: "arcsec" },
];

/// Index of the INS's heading error in [`CHANNELS`].
pub const INS_HEADING: usize = 2;
/// Indices of the east and north position errors.
pub const POSITION: [usize; 2] = [5, 6];
/// Index of the uncompensated table's heading error.
pub const TABLE_HEADING: usize = 9;

/// One run's channels at the sampled instants (NaN where a channel is not computed: the INS's
/// without an `[imu]`, the navigation's without `[navigation]`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Trace {
    /// The instants, s.
    pub t_s: Vec<f64>,
    /// One row per instant, one value per channel (in the channel's unit).
    pub values: Vec<[f64; CHANNELS.len()]>,
}

/// What one budget run is on.
#[derive(Debug, Clone)]
pub struct Setup {
    /// The table.
    pub table: TableParams,
    /// The INS, if any.
    pub ins: Option<InsParams>,
    /// The site.
    pub site: Site,
    /// The seed (the IMU's draws and the encoders' noise).
    pub seed: u64,
    /// The simulated span and step.
    pub timeline: Timeline,
    /// The interval between sampled instants, s.
    pub sample_s: f64,
}

impl Setup {
    /// Every error source × `k` (sizes, noise densities, the encoders' delays, the alignment error;
    /// a swing cone's phase and a saturation limit stay): each part then scales by `k` where the INS
    /// is linear in it, the remainder by k² where it is second order — the budget's own check.
    #[must_use]
    pub fn scaled(&self, k: f64) -> Self {
        let mut out = self.clone();
        let table = |e: &mut TableErrors| {
            e.installation_rad *= k;
            e.imu_mount_rad *= k;
            for a in &mut e.axes {
                a.swing_half_angle_rad *= k;
                a.non_orthogonality_rad *= k;
                a.encoder_offset_rad *= k;
                a.encoder_scale *= k;
                a.encoder_delay_s *= k;
                a.encoder_noise_rad *= k;
            }
        };
        table(&mut out.table.truth);
        table(&mut out.table.compensation);
        if let Some(ins) = &mut out.ins {
            let e = &mut ins.errors;
            let noise = |n: &mut super::noise::IeeeTerms| {
                n.quantization_si *= k;
                n.random_walk_si *= k;
                n.bias_instability_si *= k;
                n.rate_random_walk_si *= k;
                n.rate_ramp_si *= k;
            };
            e.gyro.bias_rad_per_s = e.gyro.bias_rad_per_s.scaled(k);
            e.gyro.scale = e.gyro.scale.scaled(k);
            e.gyro.misalignment_rad *= k;
            e.gyro.markov_sigma_rad_per_s *= k;
            noise(&mut e.gyro.noise);
            e.accel.bias_mps2 = e.accel.bias_mps2.scaled(k);
            e.accel.scale = e.accel.scale.scaled(k);
            e.accel.misalignment_rad *= k;
            e.accel.markov_sigma_mps2 *= k;
            noise(&mut e.accel.noise);
            e.g_sensitivity *= k;
            e.dither.amplitudes_rad = e.dither.amplitudes_rad.map(|a| a * k);
            ins.initial_error_rad *= k;
        }
        out
    }
}

/// Simulates `setup` with only `selection`'s errors and samples every channel every `sample_s`
/// (at the first attitude update at or after each instant); `keep_going` is asked now and then
/// (false: the trace so far).
#[must_use]
pub fn simulate(setup: &Setup, selection: Selection, keep_going: &dyn Fn() -> bool) -> Trace {
    let (table, ins) = select(&setup.table, setup.ins.as_ref(), selection);
    let model = Model::new(&table, setup.seed);
    let mut trace = Trace::default();
    let mut demod = DemodState::default();
    let h = 1.0 / setup.timeline.rate_hz();
    let mut table_row = |row: &mut [f64; CHANNELS.len()], t_s: f64| {
        // The delay correction's rate from the reading just before (as when every step is computed).
        demod.observe(&model, t_s - h);
        let o = crate::sim::step(&model, &mut demod, t_s);
        for (v, e) in [(7, o.errors[0]), (10, o.errors[1])] {
            for (j, x) in e.as_array().into_iter().enumerate() {
                row[v + j] = x * ARCSEC_PER_RAD;
            }
        }
    };
    let mut next = 0.0;
    match ins {
        Some(ins) => {
            let mut run = InsRun::new(&ins, setup.site, setup.seed, model.clone());
            for i in 1..=setup.timeline.intervals() {
                if i % 65_536 == 0 && !keep_going() {
                    break;
                }
                let s = run.step();
                if !s.updated || s.t_s < next - 1e-9 {
                    continue;
                }
                next = (trace.t_s.len() + 1) as f64 * setup.sample_s;
                let v = run.errors_view(s.t_s);
                let mut row = [f64::NAN; CHANNELS.len()];
                if let Some(e) = v.errors.first() {
                    for (j, x) in e.as_array().into_iter().enumerate() {
                        row[j] = x * ARCSEC_PER_RAD;
                    }
                }
                if let Some(n) = v.nav {
                    row[3..7].copy_from_slice(&[n.velocity_enu_mps.x, n.velocity_enu_mps.y, n.east_m, n.north_m]);
                }
                table_row(&mut row, s.t_s);
                trace.t_s.push(s.t_s);
                trace.values.push(row);
            }
        }
        None => {
            let end = setup.timeline.end_s();
            while next <= end + 1e-9 {
                if trace.t_s.len() % 4096 == 4095 && !keep_going() {
                    break;
                }
                let mut row = [f64::NAN; CHANNELS.len()];
                table_row(&mut row, next);
                trace.t_s.push(next);
                trace.values.push(row);
                next = trace.t_s.len() as f64 * setup.sample_s;
            }
        }
    }
    trace
}

/// A channel's value at the end, its largest size and its RMS over the instants.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Metrics {
    /// The last value.
    pub end: f64,
    /// The largest absolute value.
    pub peak: f64,
    /// The root mean square.
    pub rms: f64,
}

impl Metrics {
    /// Of a series (NaN when it is empty or not computed).
    #[must_use]
    pub fn of(values: impl Iterator<Item = f64>) -> Self {
        let (mut n, mut sum_sq, mut peak, mut end) = (0usize, 0.0, 0.0f64, f64::NAN);
        for x in values {
            if x.is_nan() {
                return Self { end: f64::NAN, peak: f64::NAN, rms: f64::NAN };
            }
            n += 1;
            sum_sq += x * x;
            peak = peak.max(x.abs());
            end = x;
        }
        if n == 0 {
            return Self { end: f64::NAN, peak: f64::NAN, rms: f64::NAN };
        }
        Self { end, peak, rms: (sum_sq / n as f64).sqrt() }
    }
}

/// A part of the budget: a series per channel (its instants are the budget's).
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// One row per instant, one value per channel.
    pub values: Vec<[f64; CHANNELS.len()]>,
}

impl Part {
    /// `minuend − subtrahend`, instant by instant (a source's part: its run alone − the baseline).
    #[must_use]
    pub fn difference(minuend: &[[f64; CHANNELS.len()]], subtrahend: &[[f64; CHANNELS.len()]]) -> Self {
        Self { values: minuend.iter().zip(subtrahend).map(|(a, b)| std::array::from_fn(|c| a[c] - b[c])).collect() }
    }

    /// The metrics of channel `c`.
    #[must_use]
    pub fn metrics(&self, c: usize) -> Metrics {
        Metrics::of(self.values.iter().map(|r| r[c]))
    }

    /// The metrics of the horizontal position error's size (not additive: each part's own).
    #[must_use]
    pub fn radial_metrics(&self) -> Metrics {
        Metrics::of(self.values.iter().map(|r| r[POSITION[0]].hypot(r[POSITION[1]])))
    }
}

/// The budget: each source's part, the baseline, the full run, and what their sum leaves.
#[derive(Debug, Clone)]
pub struct Budget {
    /// The sampled instants, s.
    pub t_s: Vec<f64>,
    /// The sources and their parts (source alone − baseline), in [`sources`]' order.
    pub parts: Vec<(Source, Part)>,
    /// The run without any source: the algorithm's own error.
    pub baseline: Part,
    /// The run with every source.
    pub full: Part,
    /// Baseline + Σ parts.
    pub sum: Part,
    /// Full − (baseline + Σ parts): the non-linear remainder.
    pub remainder: Part,
}

/// Assembles the budget from the runs: `full`, `baseline` and one trace per source, all sampled at
/// the same instants (the shortest sets the length: a stopped run).
#[must_use]
pub fn assemble(full: Trace, baseline: Trace, alone: Vec<(Source, Trace)>) -> Budget {
    let n =
        alone.iter().map(|(_, t)| t.values.len()).chain([full.values.len(), baseline.values.len()]).min().unwrap_or(0);
    let base = &baseline.values[..n];
    let parts: Vec<(Source, Part)> =
        alone.into_iter().map(|(s, t)| (s, Part::difference(&t.values[..n], base))).collect();
    let sum: Vec<[f64; CHANNELS.len()]> = (0..n)
        .map(|i| std::array::from_fn(|c| base[i][c] + parts.iter().map(|(_, p)| p.values[i][c]).sum::<f64>()))
        .collect();
    let remainder = Part::difference(&full.values[..n], &sum);
    Budget {
        t_s: full.t_s[..n].to_vec(),
        parts,
        baseline: Part { values: base.to_vec() },
        full: Part { values: full.values[..n].to_vec() },
        sum: Part { values: sum },
        remainder,
    }
}

impl Budget {
    /// The remainder's size relative to the full run's, per channel: peak |remainder| / peak |full|
    /// (NaN for a channel not computed or identically zero).
    #[must_use]
    pub fn relative_remainder(&self, c: usize) -> f64 {
        let (r, f) = (self.remainder.metrics(c).peak, self.full.metrics(c).peak);
        if f > ROUNDING { r / f } else { f64::NAN }
    }

    /// The channels worth drawing: computed and above rounding in the full run.
    #[must_use]
    pub fn moving_channels(&self) -> Vec<usize> {
        (0..CHANNELS.len()).filter(|&c| self.full.metrics(c).peak >= ROUNDING).collect()
    }

    /// The channel a user looks at first among `channels`: the position when navigating (its
    /// size), else the INS's heading, else the table's.
    #[must_use]
    pub fn headline(channels: &[usize]) -> Option<usize> {
        [POSITION[0], INS_HEADING, TABLE_HEADING].into_iter().find(|c| channels.contains(c))
    }

    /// The size of part `k` on the headline `h` (the horizontal position's size for the position).
    fn headline_peak(&self, k: usize, h: usize) -> f64 {
        let part = &self.parts[k].1;
        if h == POSITION[0] { part.radial_metrics().peak } else { part.metrics(h).peak }
    }

    /// The parts' indices, largest first on headline `h`.
    #[must_use]
    pub fn ranked(&self, h: usize) -> Vec<usize> {
        let mut order: Vec<usize> = (0..self.parts.len()).collect();
        order.sort_by(|x, y| self.headline_peak(*y, h).total_cmp(&self.headline_peak(*x, h)));
        order
    }

    /// The size of part `k` on headline `h` at instant `i` (the horizontal position's size for the position).
    #[must_use]
    pub fn size(&self, k: usize, h: usize, i: usize) -> f64 {
        let v = &self.parts[k].1.values[i];
        if h == POSITION[0] { v[POSITION[0]].hypot(v[POSITION[1]]) } else { v[h].abs() }
    }

    /// The part largest in size on headline `h` at instant `i` (None: no finite part).
    #[must_use]
    pub fn dominant(&self, h: usize, i: usize) -> Option<usize> {
        let sizes = (0..self.parts.len()).map(|k| (k, self.size(k, h, i))).filter(|(_, s)| s.is_finite());
        sizes.max_by(|a, b| a.1.total_cmp(&b.1)).map(|(k, _)| k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_of_a_known_series() {
        // 3, -4: end -4, peak 4, RMS √12.5.
        let m = Metrics::of([3.0, -4.0].into_iter());
        assert_eq!((m.end, m.peak), (-4.0, 4.0));
        assert!((m.rms - 12.5f64.sqrt()).abs() < 1e-15);
        assert!(Metrics::of([1.0, f64::NAN].into_iter()).peak.is_nan());
    }

    #[test]
    fn a_term_alone_selects_that_term_only() {
        let on = imu_only(Some(ImuTerm::Bias(Triad::Accel, 2)));
        assert_eq!(on.accel.bias, [false, false, true]);
        assert_eq!(on.gyro, TriadSources::NONE);
        assert!(!on.accel.white && !on.g_sensitivity);
        assert_eq!(imu_only(None), ImuSources::NONE);
    }
}
