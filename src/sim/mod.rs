//! Layer 3, the turntable step: truth, encoders, and the body attitude error of three
//! demodulations.
//!
//! Pure: `step(&Model, &mut DemodState, t)` knows nothing of Rerun, files or threads.
//! The IMU attitude is exact here (an ideal INS), so every error is the turntable's.

use crate::math::attitude::{Attitude, AttitudeError, EulerParts};
use crate::math::frames::{B, N, Rot, S};
use crate::math::stats::RunningStat;
use crate::math::timeline::Timeline;
use crate::model::gimbal::{Chain, ErrorRotations, TableErrors};
use crate::model::motion::VehicleMotion;
use crate::model::scheme::{AxisValues, MAX_AXES, Scheme};

/// The three ways of computing the body attitude, in recording order.
pub const DEMODULATIONS: [&str; 3] = ["uncompensated", "compensated", "closed_form"];
/// The three attitude-error axes, in recording order.
pub const ERROR_AXES: [&str; 3] = ["pitch", "roll", "heading"];

/// What the turntable step is about: the nominal chain, the vehicle's motion, the gimbal scheme,
/// the table's true errors and the errors the compensated demodulation assumes.
#[derive(Debug, Clone)]
pub struct TableParams {
    /// Nominal gimbal geometry.
    pub chain: Chain,
    /// Vehicle attitude over time.
    pub vehicle: VehicleMotion,
    /// Gimbal angles over time.
    pub scheme: Scheme,
    /// True turntable errors.
    pub truth: TableErrors,
    /// Errors assumed by the compensated demodulation.
    pub compensation: TableErrors,
}

/// The next [`Model::id`].
static NEXT_MODEL_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// Everything a step needs, precomputed from [`TableParams`].
#[derive(Debug, Clone)]
pub struct Model {
    /// Nominal chain.
    pub chain: Chain,
    /// Vehicle motion.
    pub vehicle: VehicleMotion,
    /// Gimbal angles over time.
    pub scheme: Scheme,
    /// Simulated time at which the scheme's clock started, s (live mode re-anchors it on reload).
    pub scheme_t0_s: f64,
    /// True errors.
    pub truth: TableErrors,
    /// Errors assumed by the compensated demodulation.
    pub compensation: TableErrors,
    /// Seed of the encoder noise (the scenario's seed).
    pub noise_seed: u64,
    truth_rot: ErrorRotations,
    compensation_rot: ErrorRotations,
    /// The attitude of a vehicle at rest, computed once.
    fixed_attitude: Option<(Attitude, Rot<N, B>)>,
    /// Which [`Model::new`] made it (its clones share it): what a step's memo of the table's part
    /// is kept for (a live reload makes a new model).
    id: u64,
}

impl Model {
    /// Precomputes the constant rotations of a table; `noise_seed` seeds the encoder noise.
    #[must_use]
    pub fn new(table: &TableParams, noise_seed: u64) -> Self {
        let TableParams { chain, vehicle, scheme, truth, compensation } = table.clone();
        let truth_rot = chain.error_rotations(&truth);
        let compensation_rot = chain.error_rotations(&compensation);
        let fixed_attitude = vehicle.is_fixed().then(|| vehicle.state(0.0));
        Self {
            chain,
            vehicle,
            scheme,
            scheme_t0_s: 0.0,
            truth,
            compensation,
            noise_seed,
            truth_rot,
            compensation_rot,
            fixed_attitude,
            id: NEXT_MODEL_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
        }
    }

    /// Which [`Model::new`] made it: clones share it, a reload's model has another.
    #[must_use]
    pub fn id(&self) -> u64 {
        self.id
    }

    /// Number of gimbal axes.
    #[must_use]
    pub fn n_axes(&self) -> usize {
        self.chain.axes().len()
    }

    /// The vehicle's constant state when it never moves.
    #[must_use]
    pub fn fixed_state(&self) -> Option<(Attitude, Rot<N, B>)> {
        self.fixed_attitude
    }

    /// The precomputed true error rotations.
    #[must_use]
    pub fn truth_rotations(&self) -> &ErrorRotations {
        &self.truth_rot
    }

    /// The precomputed error rotations assumed by the compensation.
    #[must_use]
    pub fn compensation_rotations(&self) -> &ErrorRotations {
        &self.compensation_rot
    }
}

/// What the compensated demodulation remembers between steps (to estimate the gimbal rate for the
/// encoder-delay correction from its own readings, as a real system must).
#[derive(Debug, Clone, Default)]
pub struct DemodState {
    previous: Option<(f64, AxisValues)>,
    /// The table's part of the latest step, kept while the angles and rates repeat ([`step`]).
    table: Option<TableStep>,
}

/// What [`step`] computes from the gimbal angles, rates and encoder readings alone: the same at
/// every step of a dwell (a table at rest, an indexing scheme between its moves).
#[derive(Debug, Clone, Copy)]
struct TableStep {
    /// The model and the (true angles, rates, raw readings, corrected readings) it was computed for.
    key: (u64, [AxisValues; 4]),
    /// C_b^s through the true chain, the nominal chain at the raw readings and the compensated one.
    true_b_from_s: Rot<B, S>,
    nominal_b_from_s: Rot<B, S>,
    compensated_b_from_s: Rot<B, S>,
    /// The closed form's small rotation, in b.
    phi_b: crate::math::frames::V3<B>,
}

/// Encoder readings handed to the navigation computer with the IMU sample at `t_s`: latched
/// `delay` earlier, then offset and scale applied, plus white noise (docs/model.md, "Encoder").
/// The noise is a pure function of (seed, axis, `t_s`): asking twice gives the same reading.
#[must_use]
#[inline]
pub fn encoder_readings(model: &Model, t_s: f64) -> AxisValues {
    encoder_readings_of(model, t_s, &model.scheme.state(t_s - model.scheme_t0_s).0)
}

/// [`encoder_readings`] when the true angles at `t_s`, `now`, are known.
#[inline]
fn encoder_readings_of(model: &Model, t_s: f64, now: &AxisValues) -> AxisValues {
    let t_scheme = t_s - model.scheme_t0_s;
    let mut encoder_rad = [0.0; MAX_AXES];
    for (k, e) in model.truth.axes.iter().enumerate() {
        let latched =
            if e.encoder_delay_s == 0.0 { now[k] } else { model.scheme.state(t_scheme - e.encoder_delay_s).0[k] };
        encoder_rad[k] = e.encoder_reading(latched);
        if e.encoder_noise_rad > 0.0 {
            encoder_rad[k] += e.encoder_noise_rad * crate::math::noise::gaussian(model.noise_seed, k as u64, t_s);
        }
    }
    encoder_rad
}

impl DemodState {
    /// Encoder angles corrected with the assumed parameters `assumed`: offset and scale removed,
    /// then extrapolated over the assumed delay with the rate seen in successive corrected readings.
    #[inline]
    pub fn correct(&mut self, assumed: &TableErrors, t_s: f64, encoder_rad: &AxisValues) -> AxisValues {
        let n = assumed.axes.len();
        let mut corrected = [0.0; MAX_AXES];
        for k in 0..n {
            corrected[k] = assumed.axes[k].encoder_correct(encoder_rad[k]);
        }
        let raw_corrected = corrected;
        if let Some((t_prev, prev)) = self.previous {
            let dt = t_s - t_prev;
            if dt > 0.0 {
                for k in 0..n {
                    let delay = assumed.axes[k].encoder_delay_s;
                    if delay != 0.0 {
                        corrected[k] += (raw_corrected[k] - prev[k]) / dt * delay;
                    }
                }
            }
        }
        self.previous = Some((t_s, raw_corrected));
        corrected
    }

    /// Takes the encoder reading at `t_s` without demodulating: a loop that computes only some
    /// steps feeds it the instant before each, so that the delay correction's rate comes from
    /// successive readings exactly as when every step is computed (a reading is a pure function
    /// of the instant).
    pub fn observe(&mut self, model: &Model, t_s: f64) {
        self.correct(&model.compensation, t_s, &encoder_readings(model, t_s));
    }

    /// [`Self::observe`] at `t_s` if nothing has been read yet: the navigation computer reads the
    /// encoders with every IMU sample, so its first output already has the reading before it (without
    /// it the first demodulation would lack the delay correction: rate × delay).
    pub fn observe_if_first(&mut self, model: &Model, t_s: f64) {
        if self.previous.is_none() {
            self.observe(model, t_s);
        }
    }
}

/// Everything one step produces.
#[derive(Debug, Clone, Copy)]
pub struct StepOutput {
    /// Simulated time, s.
    pub t_s: f64,
    /// True vehicle attitude as the motion gives it (Euler angles), or None where it is read from
    /// `n_from_b` ([`StepOutput::attitude`]): a coned body's, computed by whoever plots it (the
    /// recorder's thread) rather than at every step.
    pub euler: Option<Attitude>,
    /// True C_b^n.
    pub n_from_b: Rot<N, B>,
    /// True gimbal angles, rad.
    pub gimbal_rad: AxisValues,
    /// Encoder readings, rad.
    pub encoder_rad: AxisValues,
    /// Attitude errors per demodulation (see [`DEMODULATIONS`]).
    pub errors: [AttitudeError; 3],
}

impl StepOutput {
    /// True vehicle attitude (Euler angles).
    #[must_use]
    pub fn attitude(&self) -> Attitude {
        self.euler.unwrap_or_else(|| Attitude::from_n_from_b(&self.n_from_b))
    }
}

/// The body attitude a RINS computes from the IMU attitude and a model of the table.
#[must_use]
#[inline]
pub fn demodulate(n_from_s: Rot<N, S>, b_from_s: Rot<B, S>) -> Attitude {
    Attitude::from_n_from_b(&(n_from_s * b_from_s.inverse()))
}

/// [`demodulate`]'s attitude as the parts an error is read from ([`AttitudeError::between`]): no
/// trigonometry, what the errors at every update take.
#[must_use]
#[inline]
pub fn demodulated(n_from_s: Rot<N, S>, b_from_s: Rot<B, S>) -> EulerParts {
    EulerParts::of(&(n_from_s * b_from_s.inverse()))
}

/// The table's part of a step at `key` = (true angles, rates, raw readings, corrected readings).
fn table_step(model: &Model, key: (u64, [AxisValues; 4])) -> TableStep {
    let [gimbal_rad, rate_rad_per_s, encoder_rad, corrected] = key.1;
    let chain = &model.chain;
    let true_shafts = chain.shaft_rotations(&gimbal_rad);
    // Shaft rotations of other angles; reuses the true ones when the angles are identical.
    let shafts_of =
        |angles: &AxisValues| if *angles == gimbal_rad { true_shafts } else { chain.shaft_rotations(angles) };
    TableStep {
        key,
        true_b_from_s: chain.b_from_s_with(&model.truth_rot, &true_shafts),
        nominal_b_from_s: chain.b_from_s_nominal_with(&shafts_of(&encoder_rad)),
        compensated_b_from_s: chain.b_from_s_with(&model.compensation_rot, &shafts_of(&corrected)),
        phi_b: chain.first_order_phi_b_with(&model.truth, &model.truth_rot, &gimbal_rad, &rate_rad_per_s, &true_shafts),
    }
}

/// Advances the simulation to `t_s` (steps must come in increasing time).
#[must_use]
pub fn step(model: &Model, state: &mut DemodState, t_s: f64) -> StepOutput {
    step_with(model, state, t_s, None)
}

/// [`step`], given a coned body's true attitude at `t_s` when it is already known (`truth`:
/// C_b^n and its [`EulerParts`], as `model.vehicle.n_from_b(t_s)` gives them — an INS view at the
/// same instant computed it: `ins::view::InsViewer::truth_at`); otherwise computed.
pub fn step_with(
    model: &Model,
    state: &mut DemodState,
    t_s: f64,
    truth: Option<(Rot<N, B>, EulerParts)>,
) -> StepOutput {
    let (n_from_b, euler, truth) = match (model.fixed_attitude, truth) {
        (Some((a, r)), _) => (r, Some(a), EulerParts::of(&r)),
        // A coned body has no Euler angles of its own (the recorder reads them from C_b^n).
        (None, Some((r, parts))) if model.vehicle.is_coned() => (r, None, parts),
        (None, _) => {
            let (r, euler) = model.vehicle.n_from_b_and_euler(t_s);
            (r, euler, EulerParts::of(&r))
        }
    };
    let (gimbal_rad, rate_rad_per_s) = model.scheme.state(t_s - model.scheme_t0_s);
    let encoder_rad = encoder_readings_of(model, t_s, &gimbal_rad);
    let corrected = state.correct(&model.compensation, t_s, &encoder_rad);
    let key = (model.id, [gimbal_rad, rate_rad_per_s, encoder_rad, corrected]);
    let table = match state.table {
        Some(t) if t.key == key => t,
        _ => *state.table.insert(table_step(model, key)),
    };

    // Truth: the IMU attitude through the exact chain (an ideal INS reports it without error).
    let n_from_s = n_from_b * table.true_b_from_s;
    // 1. Uncompensated: the nominal table with the raw encoder angles.
    let uncompensated = demodulated(n_from_s, table.nominal_b_from_s);
    // 2. Compensated: the exact chain with the assumed errors and corrected encoder angles.
    let compensated = demodulated(n_from_s, table.compensated_b_from_s);
    // 3. Closed form: first-order error model (docs/closed-form.md).
    let closed_form = AttitudeError::first_order(&n_from_b, n_from_b.apply(table.phi_b));

    StepOutput {
        t_s,
        euler,
        n_from_b,
        gimbal_rad,
        encoder_rad,
        errors: [
            AttitudeError::between(&uncompensated, &truth),
            AttitudeError::between(&compensated, &truth),
            closed_form,
        ],
    }
}

/// RMS and peak of every variant and axis over a run.
#[derive(Debug, Clone, Copy, Default)]
pub struct ErrorStats {
    /// `[variant][axis]`, radians.
    pub stats: [[RunningStat; 3]; 3],
    /// Closed form minus exact (uncompensated), per axis, radians: where the small-angle theory holds.
    pub closed_form_deviation: [RunningStat; 3],
}

impl ErrorStats {
    /// Adds one step's errors.
    pub fn add(&mut self, out: &StepOutput) {
        for (v, e) in out.errors.iter().enumerate() {
            for (a, x) in e.as_array().into_iter().enumerate() {
                self.stats[v][a].add(x);
            }
        }
        let (exact, closed) = (out.errors[0].as_array(), out.errors[2].as_array());
        for a in 0..3 {
            self.closed_form_deviation[a].add(closed[a] - exact[a]);
        }
    }

    /// Largest peak over the three axes of one variant, radians.
    #[must_use]
    pub fn peak_over_axes(&self, variant: usize) -> f64 {
        self.stats[variant].iter().map(RunningStat::peak).fold(0.0, f64::max)
    }
}

/// Runs a model over every instant of `timeline` without recording; returns the statistics.
#[must_use]
pub fn run_stats(model: &Model, timeline: &Timeline) -> ErrorStats {
    let mut state = DemodState::default();
    let mut stats = ErrorStats::default();
    for k in 0..timeline.instants() {
        let out = step(model, &mut state, timeline.t_s(k));
        stats.add(&out);
    }
    stats
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::math::units::{ARCSEC_PER_RAD, RAD_PER_ARCMIN, RAD_PER_ARCSEC, RAD_PER_DEG};
    use crate::model::gimbal::AxisGeometry;
    use crate::model::scheme::IndexedStep;

    fn table_model(
        chain: Chain,
        vehicle: VehicleMotion,
        scheme: Scheme,
        truth: TableErrors,
        compensation: TableErrors,
    ) -> Model {
        Model::new(&TableParams { chain, vehicle, scheme, truth, compensation }, 0)
    }

    fn dual_axis_chain() -> Chain {
        Chain::new(vec![
            AxisGeometry::new("outer".into(), Vector3::y(), 0.0),
            AxisGeometry::new("inner".into(), Vector3::z(), 0.0),
        ])
    }

    /// A 16-step dual-axis sequence (docs/schemes.md) at 10 deg/s with 20 s dwells.
    fn sixteen_position() -> Scheme {
        let s = |axis, deg: f64| IndexedStep {
            axis,
            angle_rad: deg * RAD_PER_DEG,
            rate_rad_per_s: 10.0 * RAD_PER_DEG,
            dwell_s: 20.0,
            accel_rad_per_s2: 0.0,
        };
        let first = [
            s(1, 180.0),
            s(0, 180.0),
            s(1, 180.0),
            s(0, 180.0),
            s(0, -180.0),
            s(1, -180.0),
            s(0, -180.0),
            s(1, -180.0),
        ];
        let second = [
            s(1, -180.0),
            s(0, -180.0),
            s(1, -180.0),
            s(0, -180.0),
            s(0, 180.0),
            s(1, 180.0),
            s(0, 180.0),
            s(1, 180.0),
        ];
        Scheme::indexed(vec![0.0, 0.0], 20.0, first.into_iter().chain(second).collect(), true)
    }

    fn moving_vehicle() -> VehicleMotion {
        use crate::model::motion::{AngleKind, Wobble};
        VehicleMotion::new(
            Attitude { pitch_rad: 10.0 * RAD_PER_DEG, roll_rad: -20.0 * RAD_PER_DEG, heading_rad: 40.0 * RAD_PER_DEG },
            vec![],
            vec![
                Wobble {
                    angle: AngleKind::Pitch,
                    amplitude_rad: 5.0 * RAD_PER_DEG,
                    omega_rad_per_s: 0.3,
                    phase_rad: 0.0,
                },
                Wobble {
                    angle: AngleKind::Heading,
                    amplitude_rad: 30.0 * RAD_PER_DEG,
                    omega_rad_per_s: 0.05,
                    phase_rad: 1.0,
                },
            ],
        )
        .expect("valid motion")
    }

    fn all_errors() -> TableErrors {
        let mut e = TableErrors::zero(2);
        e.installation_rad = Vector3::new(5.0, -5.0, 2.0) * RAD_PER_ARCMIN;
        e.imu_mount_rad = Vector3::new(1.0, 2.0, -3.0) * RAD_PER_ARCMIN;
        e.axes[0].swing_half_angle_rad = 10.0 * RAD_PER_ARCMIN;
        e.axes[0].swing_phase_rad = 1.0 * RAD_PER_DEG;
        e.axes[1].swing_half_angle_rad = 5.0 * RAD_PER_ARCMIN;
        e.axes[1].swing_phase_rad = 1.0 * RAD_PER_DEG;
        e.axes[1].non_orthogonality_rad = 20.0 * RAD_PER_ARCSEC;
        e.axes[0].encoder_offset_rad = 30.0 * RAD_PER_ARCSEC;
        e.axes[1].encoder_scale = 20e-6;
        e
    }

    fn peak_arcsec(stats: &ErrorStats, variant: usize) -> f64 {
        stats.stats[variant].iter().map(|s| s.peak()).fold(0.0, f64::max) * ARCSEC_PER_RAD
    }

    #[test]
    fn zero_errors_give_zero_error_over_a_full_scheme() {
        // Analytic anchor: with a perfect table the nominal demodulation is exact (issue: < 1e-6 arcsec).
        let scheme = sixteen_position();
        let duration = 20.0 + scheme.period_s();
        let model =
            table_model(dual_axis_chain(), moving_vehicle(), scheme, TableErrors::zero(2), TableErrors::zero(2));
        let stats = run_stats(&model, &Timeline::new(duration, 50.0));
        for v in 0..3 {
            assert!(peak_arcsec(&stats, v) < 1e-6, "variant {v}: {}", peak_arcsec(&stats, v));
        }
    }

    #[test]
    fn a_step_in_a_dwell_is_the_step_of_a_fresh_state_and_a_new_model_is_not_taken_for_the_old() {
        // The table's part of a step is kept while the angles repeat (a dwell): every step of a
        // 16-position period with one state must equal a step with no memory (a fresh state fed
        // the previous instant, as the delay correction needs); a new model at the same angles (a
        // live reload of the table's errors) must not reuse the old one's.
        let (scheme, truth) = (sixteen_position(), all_errors());
        let model = table_model(dual_axis_chain(), moving_vehicle(), scheme.clone(), truth.clone(), truth.scaled(0.5));
        let mut kept = DemodState::default();
        for i in 0..3400 {
            let t = f64::from(i) * 0.1;
            let out = step(&model, &mut kept, t);
            let mut fresh = DemodState::default();
            if i > 0 {
                fresh.observe(&model, t - 0.1);
            }
            let want = step(&model, &mut fresh, t);
            assert_eq!(out.errors, want.errors, "at {t} s");
        }
        // In the first dwell (the angles at rest): the old model's step, then the new one's, whose
        // outer swing cone is twice as wide (the encoders read the same).
        let mut wider = truth.clone();
        wider.axes[0].swing_half_angle_rad *= 2.0;
        let other = table_model(dual_axis_chain(), moving_vehicle(), scheme, wider, truth.scaled(0.5));
        let mut reloaded = DemodState::default();
        let _ = step(&model, &mut reloaded, 5.0);
        let after = step(&other, &mut reloaded, 5.1);
        let mut fresh = DemodState::default();
        fresh.observe(&other, 5.0);
        assert_eq!(after.errors, step(&other, &mut fresh, 5.1).errors);
        let old_model = step(&model, &mut DemodState::default(), 5.1);
        assert!(after.errors[0] != old_model.errors[0], "the wider cone shows");
    }

    #[test]
    fn compensation_with_true_parameters_leaves_no_residual() {
        // A smoke test, not evidence: the compensated demodulation is the exact inverse of the truth
        // chain by construction, so this only catches wiring mistakes (the errors' own signatures are
        // checked against analytic values in each_error_source_alone_has_its_analytic_signature).
        let scheme = sixteen_position();
        let truth = all_errors();
        let model = table_model(dual_axis_chain(), moving_vehicle(), scheme, truth.clone(), truth);
        let stats = run_stats(&model, &Timeline::new(400.0, 50.0));
        assert!(peak_arcsec(&stats, 0) > 60.0, "the uncompensated error is arcminutes");
        assert!(peak_arcsec(&stats, 1) < 1e-3, "compensated residual {}", peak_arcsec(&stats, 1));
    }

    #[test]
    fn closed_form_minus_exact_is_second_order() {
        // Halving all errors halves the error (first order) and quarters closed-form minus exact.
        let scheme = sixteen_position();
        let deviation = |f: f64| {
            let truth = all_errors().scaled(f);
            let model = table_model(dual_axis_chain(), moving_vehicle(), scheme.clone(), truth, TableErrors::zero(2));
            let mut st = DemodState::default();
            let (mut dev, mut mag) = (0.0f64, 0.0f64);
            for i in 0..4000 {
                let out = step(&model, &mut st, i as f64 * 0.1);
                for (a, b) in out.errors[0].as_array().iter().zip(out.errors[2].as_array()) {
                    dev = dev.max((a - b).abs());
                    mag = mag.max(a.abs());
                }
            }
            (dev, mag)
        };
        let (d1, m1) = deviation(1.0);
        let (d2, m2) = deviation(0.5);
        assert!((m1 / m2 - 2.0).abs() < 0.02, "error is first order: {m1} / {m2}");
        assert!((d1 / d2 - 4.0).abs() < 0.3, "closed form deviation is second order: {d1} / {d2}");
    }

    #[test]
    fn non_orthogonality_alone_turns_with_the_outer_gimbal_and_scales_linearly() {
        // η alone, level vehicle at heading 0, outer axis (body y) turning at ω, inner at rest.
        // Exact: E_b = R_y(ζ) T R_y(-ζ), T = exp(η (z × y)) = exp(-η x), so to first order
        // Φ_b = R_y(ζ)(-η x) = (-η cos ζ, 0, η sin ζ): pitch error -η cos ζ, heading error -η sin ζ
        // (docs/closed-form.md). Amplitude η, period one outer revolution (36 s at 10 deg/s).
        let omega = 10.0 * RAD_PER_DEG;
        let scheme = Scheme::continuous(vec![0.0, 0.0], vec![omega, 0.0]);
        let run = |eta_arcsec: f64| {
            let mut e = TableErrors::zero(2);
            e.axes[1].non_orthogonality_rad = eta_arcsec * RAD_PER_ARCSEC;
            let model = table_model(
                dual_axis_chain(),
                VehicleMotion::fixed(Attitude::default()),
                scheme.clone(),
                e,
                TableErrors::zero(2),
            );
            let mut st = DemodState::default();
            (0..=720).map(|i| step(&model, &mut st, i as f64 * 0.1).errors[0]).collect::<Vec<_>>()
        };
        let eta = 20.0;
        let small = run(eta);
        for (i, e) in small.iter().enumerate() {
            let zeta = omega * i as f64 * 0.1;
            // Second-order remainder ~ η² = (1e-4 rad)² ~ 0.002".
            assert!((e.pitch_rad * ARCSEC_PER_RAD + eta * zeta.cos()).abs() < 0.01, "pitch at {i}");
            assert!((e.heading_rad * ARCSEC_PER_RAD + eta * zeta.sin()).abs() < 0.01, "heading at {i}");
            assert!(e.roll_rad.abs() * ARCSEC_PER_RAD < 0.01, "roll at {i}");
        }
        // Linear while small: doubling η doubles the error.
        let double = run(2.0 * eta);
        for (a, b) in small.iter().zip(&double) {
            assert!((2.0 * a.pitch_rad - b.pitch_rad).abs() * ARCSEC_PER_RAD < 0.01);
        }
    }

    /// Runs one error source alone (level vehicle, heading 0, both gimbals turning at different
    /// rates so that every angle combination appears) and checks the exact error against the
    /// analytic first-order expectation at every sample, and linearity in the error angle.
    fn check_source_alone(set: impl Fn(&mut TableErrors, f64), expected: impl Fn(f64, f64, f64) -> [f64; 3]) {
        let (w_outer, w_inner) = (7.0 * RAD_PER_DEG, 11.0 * RAD_PER_DEG);
        let scheme = Scheme::continuous(vec![0.0, 0.0], vec![w_outer, w_inner]);
        let angle = 100.0 * RAD_PER_ARCSEC;
        let run = |a: f64| {
            let mut e = TableErrors::zero(2);
            set(&mut e, a);
            let model = table_model(
                dual_axis_chain(),
                VehicleMotion::fixed(Attitude::default()),
                scheme.clone(),
                e,
                TableErrors::zero(2),
            );
            let mut st = DemodState::default();
            (0..=600).map(|i| step(&model, &mut st, i as f64 * 0.1)).collect::<Vec<_>>()
        };
        let single = run(angle);
        let double = run(2.0 * angle);
        let mut peak = 0.0f64;
        for (o, o2) in single.iter().zip(&double) {
            let exp = expected(angle, w_outer * o.t_s, w_inner * o.t_s);
            for ((got, want), got2) in o.errors[0].as_array().iter().zip(exp).zip(o2.errors[0].as_array()) {
                // Second-order remainder: (100")^2 ~ 0.05".
                assert!(
                    (got - want).abs() * ARCSEC_PER_RAD < 0.1,
                    "t = {}: {} vs {}",
                    o.t_s,
                    got * ARCSEC_PER_RAD,
                    want * ARCSEC_PER_RAD
                );
                assert!((got2 - 2.0 * got).abs() * ARCSEC_PER_RAD < 0.2, "linear in the error angle");
                peak = peak.max(got.abs());
            }
        }
        // The amplitude is of the order of the error angle.
        assert!(peak > 0.5 * angle && peak < 2.1 * angle, "peak {}", peak * ARCSEC_PER_RAD);
    }

    #[test]
    fn each_error_source_alone_has_its_analytic_signature() {
        // Level vehicle at heading 0: pitch error = Φ_b.x, roll error = Φ_b.y, heading error = -Φ_b.z
        // (euler.rs). ζ = outer angle about body y, β = inner angle; R_y(ζ) x = (cos ζ, 0, -sin ζ).
        let ry = |zeta: f64, v: Vector3<f64>| nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), zeta) * v;
        let rz = |beta: f64, v: Vector3<f64>| nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), beta) * v;
        let to_euler = |phi: Vector3<f64>| [phi.x, phi.y, -phi.z];
        // Installation about body x: a constant pitch error, not modulated by the table.
        check_source_alone(|e, a| e.installation_rad.x = a, |a, _, _| [a, 0.0, 0.0]);
        // Inner swing (phase 0): Φ_b = R_y(ζ) α (cos β x + sin β y), turning with both gimbals.
        check_source_alone(
            |e, a| e.axes[1].swing_half_angle_rad = a,
            |a, z, b| to_euler(ry(z, Vector3::new(b.cos(), b.sin(), 0.0) * a)),
        );
        // Outer swing (phase 30°): Φ_b = α (cos(ζ+φ) z + sin(ζ+φ) x), once per outer revolution.
        check_source_alone(
            |e, a| {
                e.axes[0].swing_half_angle_rad = a;
                e.axes[0].swing_phase_rad = 30.0 * RAD_PER_DEG;
            },
            |a, z, _| {
                let p = z + 30.0 * RAD_PER_DEG;
                to_euler(Vector3::new(p.sin(), 0.0, p.cos()) * a)
            },
        );
        // Inner encoder offset b: the body is turned by -b about the inner axis R_y(ζ) z.
        check_source_alone(|e, a| e.axes[1].encoder_offset_rad = a, |a, z, _| to_euler(-ry(z, Vector3::z()) * a));
        // IMU mounting about its y: carried by both gimbals, Φ_b = R_y(ζ) R_z(β) y.
        check_source_alone(|e, a| e.imu_mount_rad.y = a, |a, z, b| to_euler(ry(z, rz(b, Vector3::y())) * a));
    }

    #[test]
    fn encoder_delay_is_compensated_from_the_observed_rate() {
        // A 1 ms latch delay at 10 deg/s is a 36" angle error; the compensator extrapolates it away
        // except at the single step where the rate changes.
        let chain = dual_axis_chain();
        let scheme = Scheme::continuous(vec![0.0, 0.0], vec![0.0, 10.0 * RAD_PER_DEG]);
        let mut e = TableErrors::zero(2);
        e.axes[1].encoder_delay_s = 1e-3;
        let model = table_model(chain, VehicleMotion::fixed(Attitude::default()), scheme, e.clone(), e);
        let mut st = DemodState::default();
        let outs: Vec<_> = (0..200).map(|i| step(&model, &mut st, i as f64 * 0.01)).collect();
        let heading = |o: &StepOutput, v: usize| o.errors[v].heading_rad * ARCSEC_PER_RAD;
        // The reading lags by ωτ, so the computed body is turned +ωτ about up: heading (clockwise)
        // error -ωτ = -36".
        assert!((heading(&outs[100], 0) + 36.0).abs() < 1e-6, "{}", heading(&outs[100], 0));
        // Closed form says the same.
        assert!((heading(&outs[100], 2) + 36.0).abs() < 1e-6);
        // Compensated: exact after the first step at constant rate.
        for o in &outs[2..] {
            assert!(heading(o, 1).abs() < 1e-6, "{}", heading(o, 1));
        }
    }
}
