//! A replay's INS errors, table demodulations and statistics, on a thread of their own: the
//! replay's loop ([`super::replay`]) reads the log through the navigation computer and hands each
//! attitude update's outputs on (each algorithm's C_s^n with the instant it stands for, the encoder
//! readings and reference there), as a run's simulation hands them to its statistics' thread; the
//! rows for the recorder go on from here.

use std::sync::atomic::{AtomicBool, Ordering};

use super::super::feed::{Outbox, OutputRow};
use crate::ins::core::{NavError, SampleOut};
use crate::ins::nav::NavState;
use crate::ins::pipeline::{AlgorithmErrors, InsView};
use crate::math::attitude::{Attitude, AttitudeError};
use crate::math::frames::{N, Rot, S};
use crate::math::stats::RunningStat;
use crate::model::gimbal::{Chain, ChainMemo, ErrorRotations, TableErrors};
use crate::model::scheme::AxisValues;
use crate::record::Solution;
use crate::sim::{DemodState, StepOutput, demodulate};

use super::super::run::NavSummary;

/// One algorithm's output at an update: the instant it stands for, its C_s^n, the encoder readings
/// at that instant and the reference attitude at its truth instant (if the log has one there).
#[derive(Debug, Clone, Copy)]
pub(super) struct AlgorithmOutput {
    pub(super) t_repr_s: f64,
    pub(super) n_from_s: Rot<N, S>,
    pub(super) encoder_rad: AxisValues,
    pub(super) reference: Option<Attitude>,
}

/// An attitude update: its sample's time, the primary algorithm's truth instant, the navigation
/// errors, whether the plots and the scene take it; its outputs, one per algorithm, follow in the
/// batch's `algorithms`, and a plotted row's navigation state in its `nav_states` (when navigating).
#[derive(Debug, Clone, Copy)]
pub(super) struct Update {
    pub(super) t_s: f64,
    pub(super) t_ref_s: f64,
    pub(super) nav_error: Option<NavError>,
    pub(super) series_row: bool,
    pub(super) scene_row: bool,
}

/// What the loop hands on, in order.
pub(super) enum Item {
    /// A sample of the gyro signal's first seconds (recorded).
    Signal(SampleOut),
    /// An attitude update.
    Update(Update),
}

/// A batch of items, the updates' algorithm outputs one after the other, and the navigation states
/// of the updates the plots take (a state in every update was 56 of its 136 bytes, written by the
/// loop and read by the views' thread, for the few rows plotted).
pub(super) struct Batch {
    pub(super) items: Vec<Item>,
    pub(super) algorithms: Vec<AlgorithmOutput>,
    pub(super) nav_states: Vec<NavState>,
    /// Where the loop was when it sent the batch: what a replay that stops after it reached.
    pub(super) reached: Reached,
}

/// How far a replay got: the IMU samples replayed and the last one's time.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct Reached {
    pub(super) samples: u64,
    pub(super) t_s: f64,
}

impl Batch {
    /// An empty batch with room for `updates` updates of `algorithms` algorithms each.
    pub(super) fn with_capacity(updates: usize, algorithms: usize) -> Self {
        Self {
            items: Vec::with_capacity(updates),
            algorithms: Vec::with_capacity(updates * algorithms),
            nav_states: Vec::new(),
            reached: Reached::default(),
        }
    }
}

/// The statistics a replay reports: the table's (nominal, compensated), each algorithm's, the
/// navigation's and the updates compared.
pub(super) struct Tallies {
    pub(super) stats: [[RunningStat; 3]; 2],
    pub(super) ins_stats: Vec<[RunningStat; 3]>,
    pub(super) nav: Option<NavSummary>,
    pub(super) compared: u64,
    /// Where the replay stopped when a signal stopped it here (the loop may have read further).
    pub(super) stopped_at: Option<Reached>,
}

/// The table's demodulations and the INS's errors at each update, with their state.
pub(super) struct Views<'a> {
    pub(super) chain: &'a Chain,
    pub(super) compensation: &'a TableErrors,
    pub(super) nominal: TableErrors,
    pub(super) nominal_rot: ErrorRotations,
    pub(super) comp_rot: ErrorRotations,
    pub(super) has_reference: bool,
    pub(super) demod: Vec<DemodState>,
    pub(super) demod_nominal: DemodState,
    /// A table that stands (a dwell, a static test, no encoder file) costs one chain evaluation.
    pub(super) comp_cache: ChainMemo,
    pub(super) nominal_cache: ChainMemo,
}

impl Views<'_> {
    /// Every batch from `rx` until the loop closes it, the recorder goes away or `stop` is raised
    /// (a signal: the batches still queued are left, and the replay ends where the last one handled
    /// did): the statistics, and the rows to `outbox`.
    pub(super) fn consume(
        mut self,
        rx: &crossbeam_channel::Receiver<Batch>,
        stop: &AtomicBool,
        mut outbox: Outbox<'_>,
    ) -> Tallies {
        let mut tallies = Tallies {
            stats: [[RunningStat::default(); 3]; 2],
            ins_stats: vec![[RunningStat::default(); 3]; self.demod.len()],
            nav: None,
            compared: 0,
            stopped_at: None,
        };
        let mut reached = Reached::default();
        'batches: for batch in rx {
            if stop.load(Ordering::Relaxed) {
                tallies.stopped_at = Some(reached);
                break;
            }
            reached = batch.reached;
            let mut algorithms = batch.algorithms.as_slice();
            let mut nav_states = batch.nav_states.iter();
            for item in &batch.items {
                let go_on = match item {
                    Item::Signal(s) => outbox.signal(*s),
                    Item::Update(u) => {
                        let (these, rest) = algorithms.split_at(self.demod.len());
                        algorithms = rest;
                        let nav_state = if u.series_row { nav_states.next().copied() } else { None };
                        self.update(u, these, nav_state, &mut tallies, &mut outbox)
                    }
                };
                if !go_on {
                    break 'batches;
                }
            }
        }
        outbox.close();
        tallies
    }

    /// One update: each algorithm at the instant its own output stands for, as the simulation
    /// compares them. The Euler angles are taken only where they are compared or drawn: without a
    /// reference the compensated demodulation is its own reference, an error of zero by
    /// definition. False when the recorder has gone away.
    fn update(
        &mut self,
        u: &Update,
        outputs: &[AlgorithmOutput],
        nav_state: Option<NavState>,
        tallies: &mut Tallies,
        outbox: &mut Outbox<'_>,
    ) -> bool {
        let nan = AttitudeError { pitch_rad: f64::NAN, roll_rad: f64::NAN, heading_rad: f64::NAN };
        let row = u.series_row || u.scene_row;
        let mut errors = AlgorithmErrors::default();
        let mut primary = None;
        for (k, (state, a)) in self.demod.iter_mut().zip(outputs).enumerate() {
            let corrected = state.correct(self.compensation, a.t_repr_s, &a.encoder_rad);
            let comp_b_from_s = self.comp_cache.get(self.chain, &self.comp_rot, &corrected);
            let body = (a.reference.is_some() || (k == 0 && row)).then(|| demodulate(a.n_from_s, comp_b_from_s));
            errors.push(match (body, a.reference) {
                (Some(b), Some(r)) => b.error_from(&r),
                _ => AttitudeError::default(),
            });
            if k == 0 {
                let raw = self.demod_nominal.correct(&self.nominal, a.t_repr_s, &a.encoder_rad);
                let nominal_b_from_s = self.nominal_cache.get(self.chain, &self.nominal_rot, &raw);
                // Nothing compensated (no table errors known): the same chain, the same attitude.
                let nominal = (nominal_b_from_s.quaternion() != comp_b_from_s.quaternion())
                    .then(|| demodulate(a.n_from_s, nominal_b_from_s));
                let body = body.or_else(|| nominal.map(|_| demodulate(a.n_from_s, comp_b_from_s)));
                primary = Some((corrected, comp_b_from_s, body, nominal));
            }
        }
        let (Some((corrected, comp_b_from_s, body, nominal)), Some(a)) = (primary, outputs.first()) else {
            return true;
        };
        // Outside the reference's span (it starts late or ends early) nothing is compared (the
        // errors recorded there are NaN); the INS's own solution is recorded all along.
        let compare = !(self.has_reference && a.reference.is_none());
        let truth = a.reference.or(body);
        let table_errors = if compare {
            // The compensated body against the reference (or itself); the nominal one against it.
            let compensated = errors[0];
            match (nominal, truth) {
                (Some(n), Some(truth)) => [n.error_from(&truth), compensated],
                _ => [compensated; 2],
            }
        } else {
            [nan; 2]
        };
        if compare {
            tallies.compared += 1;
            for (v, e) in table_errors.iter().enumerate() {
                for (axis, x) in e.as_array().into_iter().enumerate() {
                    tallies.stats[v][axis].add(x);
                }
            }
            for (k, e) in errors.iter().enumerate() {
                for (axis, x) in e.as_array().into_iter().enumerate() {
                    tallies.ins_stats[k][axis].add(x);
                }
            }
            if let Some(e) = u.nav_error {
                tallies.nav = Some(NavSummary::after(tallies.nav, &e));
            }
        } else {
            errors.iter_mut().for_each(|e| *e = nan);
        }
        if !row {
            return true;
        }
        // A recorded row: the rest of what the scene and plots show (the body was demodulated).
        let body = body.unwrap_or_else(|| demodulate(a.n_from_s, comp_b_from_s));
        let truth = truth.unwrap_or(body);
        let n_from_b = truth.n_from_b();
        let out = StepOutput {
            t_s: u.t_s,
            euler: Some(truth),
            n_from_b,
            gimbal_rad: corrected,
            encoder_rad: a.encoder_rad,
            errors: [table_errors[0], table_errors[1], nan],
        };
        // The best estimate of the true IMU attitude: the reference (the truth here) through the
        // compensated table, both at hand (not built a second time: three sines and the chain).
        let imu_true = Some(if a.reference.is_some() { n_from_b * comp_b_from_s } else { a.n_from_s });
        let view = InsView { t_s: u.t_s, t_ref_s: u.t_ref_s, errors, imu_true, imu_ins: a.n_from_s, nav: u.nav_error };
        if u.series_row {
            let solution = Some(Solution { body, nav: nav_state });
            if !outbox.series(OutputRow { core: out, ins: Some(view.clone()), solution }) {
                return false;
            }
        }
        !u.scene_row || outbox.scene(OutputRow { core: out, ins: Some(view), solution: None })
    }
}
