//! The table's errors a self-calibration can see through its encoders (docs/selfcal.md, "The table").
//!
//! The encoders and the nominal chain predict the IMU's attitude on the base; the IMU's own
//! navigation integrates it from the gyros. Their difference, `log(C̃_s^n · C_s^b(λ̂)ᵀ · C_refᵀ)`, is
//! a measurement of the navigation's attitude error φ, of a constant ψ (the base's attitude, which
//! nothing on the table can see: the installation and the first encoder's offset are in it), and of
//! the table's errors — but only of the combinations the shafts' motion separates. In the exact
//! chain `B·T_0·R_0·W_0·T_1·R_1·…·W_{N-1}·M` everything between shaft k and shaft k+1 is one
//! constant rotation C_k; its component along a_k commutes with R_k and joins C_{k−1} (or ψ for
//! k = 0), so each C_k shows only its two components across a_k. Those are exactly a rotor-fixed
//! tilt of shaft k — the swing cone's (α cos φ, α sin φ) — with the next axis's non-orthogonality,
//! the next encoder's offset and (last) the IMU's mounting folded into them. Per axis the filter
//! therefore estimates:
//!
//! | state | what it holds |
//! |---|---|
//! | `<axis>.swing_<e1>`, `<axis>.swing_<e2>` | the constant rotation after the shaft, across it (the swing with everything folded in) |
//! | `<axis>.encoder_scale` | the encoder's scale error s: λ̂ = (1 + s)·λ + … |
//! | `<axis>.encoder_delay` | the encoder's latch delay τ: λ̂ reads λ(t − τ) (seen only while the shaft turns) |
//!
//! The prediction uses the exact chain at the current estimate (an extended Kalman filter: no small
//! angle in the prediction, first order only in the Jacobian); [`TableStates::truth`] finds the
//! folded values of a true [`TableErrors`] by fitting the same exact chain to it, so that the
//! comparison is exact too.

use nalgebra::{DMatrix, DVector, Matrix3, SMatrix, UnitQuaternion, Vector3};

use crate::math::rotvec;
use crate::model::gimbal::{AxisErrors, Chain, TableErrors};
use crate::model::scheme::{AxisValues, MAX_AXES};

/// The most table states (four per axis).
pub const MAX_TABLE: usize = 4 * MAX_AXES;

/// The encoders at one instant: what the recording needs to draw where a table puts the IMU.
#[derive(Debug, Clone, Copy)]
pub struct ShaftSample {
    /// Time from the sequence's first sample, s.
    pub t_s: f64,
    /// The readings, rad.
    pub readings: AxisValues,
    /// Their rates (the difference with the sample before), rad/s.
    pub rates: AxisValues,
}

/// The table's part of the measurement Jacobian: Φ_b per state, body axes.
pub type TableJacobian = SMatrix<f64, 3, MAX_TABLE>;

/// What one table state is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableKind {
    /// A component of the constant rotation after a shaft, rad.
    Swing,
    /// An encoder scale error (dimensionless).
    EncoderScale,
    /// An encoder latch delay, s.
    EncoderDelay,
}

impl TableKind {
    /// The display unit and how many of it one SI unit is.
    #[must_use]
    pub fn unit(self) -> (&'static str, f64) {
        match self {
            Self::Swing => ("″", crate::math::units::ARCSEC_PER_RAD),
            Self::EncoderScale => ("ppm", 1e6),
            Self::EncoderDelay => ("ms", 1e3),
        }
    }

    /// The unit as an entity or column name suffix.
    #[must_use]
    pub fn unit_key(self) -> &'static str {
        match self {
            Self::Swing => "arcsec",
            Self::EncoderScale => "ppm",
            Self::EncoderDelay => "ms",
        }
    }
}

/// The self-calibration's table states on one chain.
#[derive(Debug, Clone)]
pub struct TableStates {
    chain: Chain,
}

impl TableStates {
    /// The states of `chain`; an error if two consecutive axes are not perpendicular (the folding
    /// above needs them so).
    ///
    /// # Errors
    /// Consecutive axes that are not perpendicular.
    pub fn new(chain: &Chain) -> Result<Self, String> {
        for w in chain.axes().windows(2) {
            if w[0].axis.dot(&w[1].axis).abs() > 1e-9 {
                return Err(format!(
                    "axes {} and {} are not perpendicular: the table's errors are not estimated (docs/selfcal.md)",
                    w[0].name, w[1].name
                ));
            }
        }
        Ok(Self { chain: chain.clone() })
    }

    /// Number of states (four per axis).
    #[must_use]
    pub fn len(&self) -> usize {
        4 * self.chain.axes().len()
    }

    /// Never empty (a chain has an axis); for clippy's sake.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The chain.
    #[must_use]
    pub fn chain(&self) -> &Chain {
        &self.chain
    }

    /// What state `j` is.
    #[must_use]
    pub fn kind(j: usize) -> TableKind {
        match j % 4 {
            0 | 1 => TableKind::Swing,
            2 => TableKind::EncoderScale,
            _ => TableKind::EncoderDelay,
        }
    }

    /// The states' names, `<axis>.swing_<e1>` and so on.
    #[must_use]
    pub fn names(&self) -> Vec<String> {
        let letter = |v: &Vector3<f64>| match v.iamax() {
            0 => "x",
            1 => "y",
            _ => "z",
        };
        self.chain
            .axes()
            .iter()
            .flat_map(|g| {
                [
                    format!("{}.swing_{}", g.name, letter(&g.e1)),
                    format!("{}.swing_{}", g.name, letter(&g.e2)),
                    format!("{}.encoder_scale", g.name),
                    format!("{}.encoder_delay", g.name),
                ]
            })
            .collect()
    }

    /// The priors' 1σ, SI: 600″ for a folded rotation (Jiang et al. 2017's largest swing),
    /// 1000 ppm for a scale, 10 ms for a delay — wide for a navigation-grade table.
    #[must_use]
    pub fn priors(&self) -> Vec<f64> {
        (0..self.len())
            .map(|j| match Self::kind(j) {
                TableKind::Swing => 600.0 / crate::math::units::ARCSEC_PER_RAD,
                TableKind::EncoderScale => 1e-3,
                TableKind::EncoderDelay => 10e-3,
            })
            .collect()
    }

    /// The table of these states' values `p` as [`TableErrors`]: the swings, scales and delays,
    /// everything folded left at zero. With the same base it predicts the same IMU attitude as any
    /// table whose folded values are `p`.
    #[must_use]
    pub fn as_errors(&self, p: &[f64]) -> TableErrors {
        let mut e = TableErrors::zero(self.chain.axes().len());
        for (k, a) in e.axes.iter_mut().enumerate() {
            let (x, y) = (p[4 * k], p[4 * k + 1]);
            *a = AxisErrors {
                swing_half_angle_rad: x.hypot(y),
                swing_phase_rad: y.atan2(x),
                encoder_scale: p[4 * k + 2],
                encoder_delay_s: p[4 * k + 3],
                ..AxisErrors::default()
            };
        }
        e
    }

    /// The shaft angles a table with states `p` had at encoder readings `readings` turning at
    /// `rates` (the inverse of the encoder model with no offset: λ = λ̂/(1 + s) + λ̇τ).
    #[must_use]
    pub fn shaft_angles(&self, p: &[f64], readings: &AxisValues, rates: &AxisValues) -> AxisValues {
        let mut out = [0.0; MAX_AXES];
        for k in 0..self.chain.axes().len() {
            out[k] = readings[k] / (1.0 + p[4 * k + 2]) + rates[k] * p[4 * k + 3];
        }
        out
    }

    /// The IMU's attitude on the base, C_s^b, of a table with states `p` at encoder readings
    /// `readings` and shaft rates `rates`: the exact chain ([`Chain::b_from_s`]).
    #[must_use]
    pub fn b_from_s(&self, p: &[f64], readings: &AxisValues, rates: &AxisValues) -> UnitQuaternion<f64> {
        let rot = self.chain.error_rotations(&self.as_errors(p));
        *self.chain.b_from_s(&rot, &self.shaft_angles(p, readings, rates)).quaternion()
    }

    /// Where a table with states `p` puts the IMU, seen from where a table with states `reference`
    /// does, at the same encoder readings: `log(C_s^b(reference)ᵀ · C_s^b(p))`, sensor axes, rad.
    #[must_use]
    pub fn offset(&self, reference: &[f64], p: &[f64], at: &ShaftSample) -> Vector3<f64> {
        let from = self.b_from_s(reference, &at.readings, &at.rates).inverse();
        rotvec::log(&(from * self.b_from_s(p, &at.readings, &at.rates)))
    }

    /// ∂Φ_b/∂p at `p`, body axes: each column the rotation a small change of one state makes in
    /// the exact chain, `log(C_s^b(p + δ) · C_s^b(p)ᵀ)/δ` (central differences; exact to ~1e-10,
    /// where the closed form's nominal prefixes are off by the errors themselves — 600″ is 3e-3,
    /// and an extended Kalman filter locks such Jacobian errors of its first updates in).
    #[must_use]
    pub fn jacobian(&self, p: &[f64], readings: &AxisValues, rates: &AxisValues) -> TableJacobian {
        let mut j = TableJacobian::zeros();
        let at = self.b_from_s(p, readings, rates);
        let mut q = p.to_vec();
        for c in 0..self.len() {
            let d = match Self::kind(c) {
                TableKind::Swing | TableKind::EncoderScale => 1e-6,
                TableKind::EncoderDelay => 1e-5,
            };
            q[c] = p[c] + d;
            let plus = rotvec::log(&(self.b_from_s(&q, readings, rates) * at.inverse()));
            q[c] = p[c] - d;
            let minus = rotvec::log(&(self.b_from_s(&q, readings, rates) * at.inverse()));
            q[c] = p[c];
            j.set_column(c, &((plus - minus) / (2.0 * d)));
        }
        j
    }

    /// The folded values of the true table `truth` whose IMU's frame is turned by `imu_rotation`
    /// from the one the chain ends in (the accelerometer triad's, rad): the states that make the
    /// exact chain reproduce the true one up to a constant base rotation, found by Gauss–Newton
    /// on the exact chains at every combination of quarter-turn shaft angles (scales and delays
    /// are the table's own).
    #[must_use]
    pub fn truth(&self, truth: &TableErrors, imu_rotation: &Vector3<f64>) -> Vec<f64> {
        let n = self.chain.axes().len();
        let mut p = vec![0.0; self.len()];
        for (k, a) in truth.axes.iter().enumerate() {
            p[4 * k + 2] = a.encoder_scale;
            p[4 * k + 3] = a.encoder_delay_s;
        }
        let true_rot = self.chain.error_rotations(truth);
        let turn = rotvec::exp(imu_rotation);
        let grid: Vec<AxisValues> = (0..4usize.pow(n as u32))
            .map(|i| {
                let mut a = [0.0; MAX_AXES];
                for (k, ak) in a.iter_mut().enumerate().take(n) {
                    // Quarter turns plus an odd angle, so that no two configurations coincide.
                    *ak = ((i / 4usize.pow(k as u32)) % 4) as f64 * std::f64::consts::FRAC_PI_2 + 0.3;
                }
                a
            })
            .collect();
        let geometric: Vec<usize> = (0..self.len()).filter(|&j| Self::kind(j) == TableKind::Swing).collect();
        for _ in 0..6 {
            let rep = self.chain.error_rotations(&self.as_errors(&p));
            let rows = 3 * grid.len();
            let mut a = DMatrix::zeros(rows, geometric.len() + 3);
            let mut r = DVector::zeros(rows);
            for (i, angles) in grid.iter().enumerate() {
                let mut readings = [0.0; MAX_AXES];
                for k in 0..n {
                    readings[k] = truth.axes[k].encoder_reading(angles[k]);
                }
                let c_true = self.chain.b_from_s(&true_rot, angles).quaternion() * turn;
                let c_rep =
                    *self.chain.b_from_s(&rep, &self.shaft_angles(&p, &readings, &[0.0; MAX_AXES])).quaternion();
                let res = rotvec::log(&(c_true * c_rep.inverse()));
                let jac = self.jacobian(&p, &readings, &[0.0; MAX_AXES]);
                for d in 0..3 {
                    r[3 * i + d] = res[d];
                    for (c, &g) in geometric.iter().enumerate() {
                        a[(3 * i + d, c)] = jac[(d, g)];
                    }
                    a[(3 * i + d, geometric.len() + d)] = 1.0;
                }
            }
            let Ok(step) = a.svd(true, true).solve(&r, 1e-12) else { break };
            for (c, &g) in geometric.iter().enumerate() {
                p[g] += step[c];
            }
            if step.rows(0, geometric.len()).amax() < 1e-13 {
                break;
            }
        }
        p
    }
}

impl TableStates {
    /// The encoder noise one attitude measurement carries, rad², body axes: each reading's noise
    /// turns the IMU about its own shaft's axis (P_k a_k at `readings`), so the covariance is
    /// Σ σ_k² (P_k a_k)(P_k a_k)ᵀ — nothing about the third direction — with a floor of 0.05″ in
    /// every direction (the exact chain and the navigation are not better than that).
    #[must_use]
    pub fn measurement_variance(&self, encoder_sigma_rad: &[f64], readings: &AxisValues) -> Matrix3<f64> {
        let shafts = self.chain.shaft_rotations(readings);
        let mut prefix = UnitQuaternion::identity();
        let mut r = Matrix3::identity() * (0.05 / crate::math::units::ARCSEC_PER_RAD).powi(2);
        for (k, g) in self.chain.axes().iter().enumerate() {
            let a = prefix * g.axis;
            let s = encoder_sigma_rad.get(k).copied().unwrap_or(0.0);
            r += a * a.transpose() * (s * s);
            prefix *= shafts.0[k];
        }
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::units::ARCSEC_PER_RAD;
    use crate::model::gimbal::AxisGeometry;

    fn dual() -> Chain {
        Chain::new(vec![
            AxisGeometry::new("outer".into(), Vector3::y(), 0.0),
            AxisGeometry::new("inner".into(), Vector3::z(), 0.0),
        ])
    }

    fn table() -> TableErrors {
        let arcsec = 1.0 / ARCSEC_PER_RAD;
        let mut e = TableErrors::zero(2);
        e.installation_rad = Vector3::new(30.0, -20.0, 50.0) * arcsec;
        e.imu_mount_rad = Vector3::new(15.0, -25.0, 40.0) * arcsec;
        e.axes[0] = AxisErrors {
            swing_half_angle_rad: 600.0 * arcsec,
            swing_phase_rad: 0.4,
            encoder_offset_rad: 35.0 * arcsec,
            encoder_scale: 30e-6,
            ..AxisErrors::default()
        };
        e.axes[1] = AxisErrors {
            swing_half_angle_rad: 300.0 * arcsec,
            swing_phase_rad: -1.1,
            non_orthogonality_rad: 20.0 * arcsec,
            encoder_offset_rad: -45.0 * arcsec,
            encoder_scale: -20e-6,
            ..AxisErrors::default()
        };
        e
    }

    /// The folded table predicts the true chain's IMU attitude at any shaft angles (not only the
    /// fitting grid's), up to one constant base rotation: the exact chain is the referee.
    #[test]
    fn the_folded_table_reproduces_the_true_chain_up_to_a_constant() {
        let s = TableStates::new(&dual()).unwrap();
        let truth = table();
        let rho = Vector3::new(8.0, -5.0, 3.0) / ARCSEC_PER_RAD;
        let p = s.truth(&truth, &rho);
        let (tr, rep) = (s.chain.error_rotations(&truth), s.chain.error_rotations(&s.as_errors(&p)));
        let mut first = None;
        let mut worst: f64 = 0.0;
        for i in 0..50 {
            let angles = [0.37 * i as f64, 1.91 * i as f64 + 0.2, 0.0];
            let readings = [truth.axes[0].encoder_reading(angles[0]), truth.axes[1].encoder_reading(angles[1]), 0.0];
            let c_true = s.chain.b_from_s(&tr, &angles).quaternion() * rotvec::exp(&rho);
            let c_rep = *s.chain.b_from_s(&rep, &s.shaft_angles(&p, &readings, &[0.0; 3])).quaternion();
            let g = c_true * c_rep.inverse();
            let base = *first.get_or_insert(g);
            worst = worst.max(rotvec::log(&(g * base.inverse())).norm() * ARCSEC_PER_RAD);
        }
        assert!(worst < 1e-6, "the folded table misses the true chain by {worst:.2e}″");
        // And the folding is what the first-order analysis says (docs/selfcal.md), to second order
        // (600″² ≈ 0.9″): inner swing ≈ the true inner swing + the mount across z + ρ across z.
        let inner_x = (300.0 * (-1.1f64).cos() + 15.0 + 8.0) / ARCSEC_PER_RAD;
        assert!(
            (p[4] - inner_x).abs() * ARCSEC_PER_RAD < 2.0,
            "{} vs {}",
            p[4] * ARCSEC_PER_RAD,
            inner_x * ARCSEC_PER_RAD
        );
    }

    /// At a table without errors the Jacobian is the closed form's (`Chain::first_order_phi_b`),
    /// column by column.
    #[test]
    fn the_jacobian_is_the_closed_forms() {
        let s = TableStates::new(&dual()).unwrap();
        let (angles, rates) = ([0.7, -2.1, 0.0], [0.15, -0.05, 0.0]);
        let j = s.jacobian(&vec![0.0; s.len()], &angles, &rates);
        for c in 0..s.len() {
            let mut p = vec![0.0; s.len()];
            p[c] = 1.0;
            // The closed form's encoder error is b + sλ − λ̇τ; its swing is α(cos(λ+φ)e1 + …).
            let e = s.as_errors(&p);
            let phi = s.chain.first_order_phi_b(&e, &angles, &rates).v;
            assert!((phi - j.column(c)).norm() < 1e-8 * phi.norm().max(1.0), "state {c}: {phi:?} vs {:?}", j.column(c));
        }
    }

    #[test]
    fn tilted_consecutive_axes_are_refused() {
        let c = Chain::new(vec![
            AxisGeometry::new("a".into(), Vector3::z(), 0.0),
            AxisGeometry::new("b".into(), Vector3::z(), 0.0),
        ]);
        assert!(TableStates::new(&c).unwrap_err().contains("not perpendicular"));
    }
}
