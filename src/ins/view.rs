//! What the INS shows of the body at an output instant: each algorithm's attitude error against
//! the truth, computed from the computer's outputs ([`InsOutputs`], a value) by an [`InsViewer`]
//! that holds the table's demodulation state. A run's statistics take the outputs on their own
//! thread, beside the simulation's (`app::run`); [`super::pipeline::InsRun::view`] does both in one.

use super::coning::Algorithm;
use super::core::{InsCore, NavError};
use crate::math::attitude::{AttitudeError, EulerParts};
use crate::math::frames::{B, N, Rot, S};
use crate::model::gimbal::ChainMemo;
use crate::model::scheme::AxisValues;
use crate::sim::{DemodState, Model, demodulated, encoder_readings};

/// One attitude error per algorithm run, in integrator order: a fixed array (at most the five
/// algorithms), so a view at every update allocates nothing and copies as a value.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AlgorithmErrors {
    len: usize,
    values: [AttitudeError; Algorithm::ALL.len()],
}

impl AlgorithmErrors {
    /// Appends the next algorithm's error.
    ///
    /// # Panics
    /// Past the five algorithms (an INS runs each at most once).
    pub fn push(&mut self, e: AttitudeError) {
        self.values[self.len] = e;
        self.len += 1;
    }

    /// Empties it (for the next update).
    pub fn clear(&mut self) {
        self.len = 0;
    }
}

impl std::ops::Deref for AlgorithmErrors {
    type Target = [AttitudeError];
    fn deref(&self) -> &[AttitudeError] {
        &self.values[..self.len]
    }
}

impl std::ops::DerefMut for AlgorithmErrors {
    fn deref_mut(&mut self) -> &mut [AttitudeError] {
        &mut self.values[..self.len]
    }
}

impl<'a> IntoIterator for &'a AlgorithmErrors {
    type Item = &'a AttitudeError;
    type IntoIter = std::slice::Iter<'a, AttitudeError>;
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

/// The INS's view of the body at one output instant.
#[derive(Debug, Clone)]
pub struct InsView {
    /// Output time, s.
    pub t_s: f64,
    /// Truth reference time (output time minus the compensation Δt), s.
    pub t_ref_s: f64,
    /// Body attitude error of each algorithm (computed minus true), in integrator order.
    pub errors: AlgorithmErrors,
    /// True C_s^n at the instant the INS output represents (None from [`super::pipeline::InsRun::errors_view`]:
    /// what only the scene draws is not computed at every update).
    pub imu_true: Option<Rot<N, S>>,
    /// The primary algorithm's C_s^n.
    pub imu_ins: Rot<N, S>,
    /// Navigation errors, when navigating.
    pub nav: Option<NavError>,
}

/// An algorithm's latest error and the (instant, attitude) it was computed for.
type LastError = (f64, Rot<N, S>, AttitudeError);

/// What [`InsViewer::view`] computes once per output instant for the algorithms that share it.
#[derive(Clone)]
struct Shared {
    t_repr_s: f64,
    encoder_rad: AxisValues,
    /// The truth's instant, the true C_b^n there and its parts.
    t_ref_s: f64,
    n_from_b: Rot<N, B>,
    truth: EulerParts,
}

/// One algorithm's attitude output at an update: the instant it stands for, the truth instant it
/// is compared at, its C_s^n.
pub type AttitudeOutput = (f64, f64, Rot<N, S>);

/// What the computer outputs at an update, all a view needs: the navigation errors, the true C_s^n
/// when the scene draws it; and each algorithm's [`AttitudeOutput`], which [`Self::of`] appends to
/// a list the caller keeps. A value (a run sends it to its statistics' thread, the algorithms'
/// outputs of a batch of updates in one list: an update's share is as long as the algorithms run,
/// not the five there could be — a fixed array of five made each update 370 bytes, written and
/// read across threads, where one algorithm's is 130).
#[derive(Debug, Clone, Copy)]
pub struct InsOutputs {
    t_s: f64,
    t_ref_s: f64,
    imu_true: Option<Rot<N, S>>,
    nav: Option<NavError>,
}

impl InsOutputs {
    /// `core`'s outputs after a primary update at `t_s`, with the true C_s^n `imu_true` if drawn;
    /// each algorithm's appended to `attitudes`, in integrator order.
    #[must_use]
    pub fn of(core: &InsCore, t_s: f64, imu_true: Option<Rot<N, S>>, attitudes: &mut Vec<AttitudeOutput>) -> Self {
        for k in 0..core.algorithm_count() {
            let (t_repr, n_from_s) = core.output_attitude(k);
            attitudes.push((t_repr, core.reference_instant(t_repr), n_from_s));
        }
        let t_ref_s = t_s - core.config().output_compensation_s;
        Self { t_s, t_ref_s, imu_true, nav: core.nav_error() }
    }

    /// The output time, s.
    #[must_use]
    pub fn t_s(&self) -> f64 {
        self.t_s
    }
}

/// The INS's errors against the truth of a table `model`: the demodulation of each algorithm's
/// output through the compensated chain at its instant's encoder readings (the state of the
/// encoders' delay correction and the chain's memo kept between views).
#[derive(Clone)]
pub struct InsViewer {
    model: Model,
    /// The IMU's sample period, s (the delay correction's first reading is one sample earlier).
    h: f64,
    demod: Vec<DemodState>,
    /// Each algorithm's latest error and the (instant, attitude) it was computed for: an algorithm
    /// that has not updated since (more samples per update than the primary) is not recomputed.
    last_error: Vec<Option<LastError>>,
    /// The view's per-instant scratch, kept between views (no allocation per view).
    shared: Vec<Shared>,
    /// The compensated chain at the latest corrected angles, one per algorithm at most.
    chains: ChainMemo,
}

impl InsViewer {
    /// A viewer of `algorithms` algorithms sampled every `h` s on the table `model`.
    #[must_use]
    pub fn new(model: Model, h: f64, algorithms: usize) -> Self {
        Self {
            model,
            h,
            demod: vec![DemodState::default(); algorithms],
            last_error: vec![None; algorithms],
            shared: Vec::new(),
            chains: ChainMemo::new(algorithms),
        }
    }

    /// A live session's reload: the table is `model` from now on (the delay correction goes on).
    pub fn replace_model(&mut self, model: Model) {
        self.model = model;
        self.last_error.iter_mut().for_each(|e| *e = None);
        self.chains = ChainMemo::new(self.demod.len());
    }

    /// The true C_b^n of `model` at `t_s` and its parts, if the latest view computed them (an
    /// algorithm's truth instant is `t_s` and the model is this viewer's): what the table's step at
    /// the same instant takes instead of computing them again (`sim::step_with`).
    #[must_use]
    pub fn truth_at(&self, model: &Model, t_s: f64) -> Option<(Rot<N, B>, EulerParts)> {
        if model.id() != self.model.id() {
            return None;
        }
        self.shared.iter().find(|e| e.t_ref_s == t_s).map(|e| (e.n_from_b, e.truth))
    }

    /// The number of algorithms viewed: the attitude outputs each update has.
    #[must_use]
    pub fn algorithms(&self) -> usize {
        self.demod.len()
    }

    /// The INS body attitude errors of the outputs `o` (its algorithms' `attitudes`, one per
    /// [`Self::algorithms`]). Each algorithm is compared at the instant its own latest output stands
    /// for (algorithms with more samples per update update less often), against the truth
    /// `output_compensation` earlier.
    pub fn view(&mut self, o: &InsOutputs, attitudes: &[AttitudeOutput]) -> InsView {
        debug_assert_eq!(attitudes.len(), self.demod.len());
        let model = &self.model;
        let mut errors = AlgorithmErrors::default();
        // Algorithms that stand for the same instant share its encoder readings (a pure function of
        // the instant) and its true attitude; the same corrected angles, the compensated chain.
        let mut shared = std::mem::take(&mut self.shared);
        shared.clear();
        for (k, &(t_repr, t_ref, n_from_s)) in attitudes.iter().enumerate() {
            if let Some((t, q, e)) = self.last_error[k] {
                // The same output as last time: the same error (the demodulation's state is that of
                // having read this instant already).
                if t == t_repr && q.quaternion() == n_from_s.quaternion() {
                    errors.push(e);
                    continue;
                }
            }
            let known = shared.iter().position(|e| e.t_repr_s == t_repr);
            let (encoder, n_from_b, truth_att) = match known {
                Some(i) => (shared[i].encoder_rad, shared[i].n_from_b, shared[i].truth),
                None => {
                    // The encoders are read for the instant the IMU data represent (matched synchronisation).
                    let truth = model.fixed_state().map_or_else(|| model.vehicle.n_from_b(t_ref), |(_, r)| r);
                    (encoder_readings(model, t_repr), truth, EulerParts::of(&truth))
                }
            };
            self.demod[k].observe_if_first(model, t_repr - self.h);
            let corrected = self.demod[k].correct(&model.compensation, t_repr, &encoder);
            let b_from_s_comp = self.chains.get(&model.chain, model.compensation_rotations(), &corrected);
            if known.is_none() {
                shared.push(Shared {
                    t_repr_s: t_repr,
                    encoder_rad: encoder,
                    t_ref_s: t_ref,
                    n_from_b,
                    truth: truth_att,
                });
            }
            let error = AttitudeError::between(&demodulated(n_from_s, b_from_s_comp), &truth_att);
            self.last_error[k] = Some((t_repr, n_from_s, error));
            errors.push(error);
        }
        self.shared = shared;
        let imu_ins = attitudes[0].2;
        InsView { t_s: o.t_s, t_ref_s: o.t_ref_s, errors, imu_true: o.imu_true, imu_ins, nav: o.nav }
    }
}
