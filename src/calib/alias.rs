//! Which errors the calibration does not estimate would go into which of its states: for each
//! unestimated error, 1″ of it is simulated in the measurement (exact chain) and passed through the
//! least squares' normal equations, Δθ = (Hᵀ R⁻¹ H + P₀⁻¹)⁻¹ Σ Hᵀ R⁻¹ Δz. A user whose table has such an
//! error (an IMU mounted 30″ off about z) reads here how much of it each estimate takes.

use std::sync::atomic::AtomicBool;

use nalgebra::{DVector, UnitQuaternion, Vector3};
use serde::Serialize;

use super::estimate::{SampleModel, exact_residual};
use super::{CalibConfig, CalibError, Calibration, Data};
use crate::math::units::RAD_PER_ARCSEC;
use crate::model::gimbal::{Chain, ShaftRotations, TableErrors};

/// How much of 1″ of an unestimated error each estimated state takes.
#[derive(Debug, Clone, Serialize)]
pub struct Alias {
    /// The unestimated error ("IMU mounting about z", "outer encoder offset").
    pub error: String,
    /// Per estimated state key: arcsec of the estimate per arcsec of the error (only |x| ≥ 0.05).
    pub into: Vec<(String, f64)>,
}

/// A small perturbation of what the measurement sees: table errors, or an encoder offset on axis k.
enum Perturbation {
    Errors(TableErrors),
    Encoder(usize),
}

/// The aliases of every unestimated error of the kinds a table has (installation, IMU mounting,
/// encoder offsets), for the calibration `cal` of `data` that assumed `known`.
///
/// # Errors
/// The data source's, or the stop.
pub fn aliases(
    chain: &Chain,
    known: &TableErrors,
    data: &Data,
    cal: &Calibration,
    cfg: &CalibConfig,
    stop: &AtomicBool,
) -> Result<Vec<Alias>, CalibError> {
    let set = &cal.set;
    let one = RAD_PER_ARCSEC;
    let mut cases: Vec<(String, Perturbation)> = Vec::new();
    for (i, axis) in ["x", "y", "z"].iter().enumerate() {
        let mut e = known.clone();
        e.installation_rad[i] += one;
        cases.push((format!("installation about {axis}"), Perturbation::Errors(e)));
        let mut e = known.clone();
        e.imu_mount_rad[i] += one;
        cases.push((format!("IMU mounting about {axis}"), Perturbation::Errors(e)));
    }
    for (k, g) in chain.axes().iter().enumerate() {
        cases.push((format!("{} encoder offset", g.name), Perturbation::Encoder(k)));
    }
    let base = chain.error_rotations(known);
    let n_from_b = data.n_from_b.matrix();
    let ref_inv = data.n_from_b.inverse();
    let cov = &cal.nls.cov;
    let nt = set.n_table;
    let mut out = Vec::new();
    for (name, case) in cases {
        let mut b = DVector::<f64>::zeros(set.len());
        let mut model = SampleModel::new();
        let perturbed = match &case {
            Perturbation::Errors(e) => Some(chain.error_rotations(e)),
            Perturbation::Encoder(_) => None,
        };
        data.samples.each(stop, &mut |s| {
            model.set(set, chain, &n_from_b, s, data.tau(s.t_s), cfg);
            let z0 = exact_residual(chain, &base, s, &ref_inv);
            let z1 = match (&case, &perturbed) {
                (_, Some(err)) => exact_residual(chain, err, s, &ref_inv),
                (Perturbation::Encoder(k), None) => {
                    // The encoder reads 1″ more than the shaft turned: the demodulation turns it back.
                    let mut shafts = ShaftRotations(s.shafts.0);
                    let axis = chain.axes()[*k].axis;
                    shafts.0[*k] *= UnitQuaternion::from_scaled_axis(axis * one);
                    let m = super::Measurement { t_s: s.t_s, n_from_s: s.n_from_s, shafts };
                    exact_residual(chain, &base, &m, &ref_inv)
                }
                _ => z0,
            };
            let dz: Vector3<f64> = z1 - z0;
            // Σ Hᵀ R⁻¹ Δz.
            let wdz = model.w * dz;
            for (j, bj) in b.iter_mut().enumerate() {
                *bj += (0..3).map(|r| model.h[r][j] * wdz[r]).sum::<f64>();
            }
        })?;
        let dtheta = cov * b;
        let into: Vec<(String, f64)> = set
            .params
            .iter()
            .enumerate()
            .take(nt)
            .map(|(j, p)| (p.key(chain), dtheta[j] / one))
            .filter(|(_, x)| x.abs() >= 0.05)
            .collect();
        out.push(Alias { error: name, into });
    }
    Ok(out)
}
