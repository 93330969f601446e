//! `selfcal --log`: the self-calibration of a sequence run on a real table, from its log set.

use std::sync::atomic::AtomicBool;

use anyhow::{Result, anyhow, bail};

use super::{Estimation, Reading, estimate, table_config};
use crate::app::playback::{ImuItem, ImuSamples};
use crate::calib::selfcal::{self, Config};
use crate::model::earth::Earth;

/// Self-calibrates the IMU of a logged sequence (a log set: its IMU file, site, rate and the
/// table description's [imu] as the datasheet), and with an encoder file the table's errors too
/// (the table description's encoder noise as their datasheet). The log must start with at least 60 s at rest
/// (the coarse alignment) and have no gaps; the vehicle must stand still throughout.
///
/// # Errors
/// An unreadable log, a gap, too short a log, interrupted.
pub fn run_log(log: &crate::scenario::logset::LogSet, stop: &AtomicBool) -> Result<Estimation> {
    let h = 1.0 / log.imu.rate_hz;
    let table = match &log.encoders {
        Some(_) if !log.table.strapdown => table_config(&log.table.chain, &log.table.stated).0,
        _ => None,
    };
    // How far the IMU turned after its rest (samples faster than the move threshold): a log with
    // no calibration sequence — a parked vehicle — separates none of the gains, and its biases only
    // in combinations; it is refused, not estimated.
    let turned = std::cell::Cell::new(0.0_f64);
    let open = || {
        turned.set(0.0);
        let (align, rest) = open_sequence(log)?;
        let rest = rest.inspect(|m| {
            if let Ok(((dtheta, _), _)) = m
                && dtheta.norm() / h > MOVE_RATE_RAD_PER_S
            {
                turned.set(turned.get() + dtheta.norm());
            }
        });
        Ok((align, rest))
    };
    let align = open_sequence(log)?.0.len();
    let config = Config::for_datasheet(&log.table.ins.errors, h, Earth::at(log.table.site), align);
    let result = estimate(config, table, open, stop)?;
    if turned.get() < MIN_TURN_RAD {
        bail!(
            "{}: no calibration sequence: after {:.1} s at rest the IMU turned {:.1}° in all (faster than {:.1}°/s); a self-calibration needs rotations about at least two axes (the built-in sequences turn 90° and 180° about each, docs/selfcal.md): nothing is estimated from a parked vehicle",
            log.imu.path.display(),
            align as f64 * h,
            turned.get().to_degrees(),
            MOVE_RATE_RAD_PER_S.to_degrees()
        );
    }
    Ok(result)
}

/// The log's samples (with the encoders' readings where it has an encoder file): those of the
/// rest at the start, and the rest.
///
/// # Errors
/// An unreadable log, or less than [`LOG_ALIGN_S`] at rest first.
fn open_sequence(
    log: &crate::scenario::logset::LogSet,
) -> Result<(Vec<Reading>, impl Iterator<Item = Result<Reading>> + use<'_>)> {
    let h = 1.0 / log.imu.rate_hz;
    let (mut imu, mut encoders, (from, to)) = ImuSamples::open_with_encoders(log).map_err(|e| anyhow!("{e}"))?;
    if log.table.strapdown {
        encoders = None;
    }
    let mut next = move || -> Option<Result<Reading>> {
        // The manifest's span (log.from_s, log.to_s): what is outside it is not calibrated.
        let mut item = imu.next_item();
        while let Ok(Some(ImuItem::Sample { t_s, .. })) = item
            && t_s < from
        {
            item = imu.next_item();
        }
        match item {
            Ok(Some(ImuItem::Sample { t_s, .. })) if t_s > to => None,
            Ok(None) => None,
            Ok(Some(ImuItem::Sample { t_s, dtheta, dv })) => {
                Some(match encoders.as_mut().map(|e| e.at(t_s)).transpose() {
                    Ok(readings) => Ok(((dtheta, dv), readings)),
                    Err(e) => Err(anyhow!("{e}")),
                })
            }
            Ok(Some(ImuItem::Gap { from_s, to_s })) => Some(Err(anyhow!(
                "{}: a gap in the IMU samples from {from_s:.3} s to {to_s:.3} s: selfcal needs an unbroken sequence",
                log.imu.path.display()
            ))),
            Err(e) => Some(Err(anyhow!("{e}"))),
        }
    };
    // The rest at the start: whole half-second blocks until the first whose mean rate exceeds
    // 0.5°/s (a move; the Earth turns at 0.004°/s), at most the built-in sequences' first dwell.
    let block = ((0.5 / h).round() as usize).max(1);
    let cap = (selfcal::INITIAL_DWELL_S / h).round() as usize;
    let mut align: Vec<Reading> = Vec::with_capacity(cap);
    let mut moving: Vec<Reading> = Vec::new();
    while align.len() < cap {
        let mut piece = Vec::with_capacity(block);
        for _ in 0..block {
            match next() {
                Some(m) => piece.push(m?),
                None => break,
            }
        }
        if piece.is_empty() {
            break;
        }
        let turned: nalgebra::Vector3<f64> = piece.iter().map(|m| m.0.0).sum();
        if turned.norm() / (piece.len() as f64 * h) > MOVE_RATE_RAD_PER_S {
            moving = piece;
            break;
        }
        align.extend(piece);
    }
    if (align.len() as f64) * h < LOG_ALIGN_S {
        bail!(
            "{}: {:.1} s at rest before the first move; selfcal needs at least {LOG_ALIGN_S} s at rest first, then the sequence",
            log.imu.path.display(),
            align.len() as f64 * h
        );
    }
    Ok((align, moving.into_iter().map(Ok).chain(std::iter::from_fn(next))))
}

/// A sample turning faster than this is part of a move (the Earth turns at 0.004°/s), rad/s.
const MOVE_RATE_RAD_PER_S: f64 = 0.5 * crate::math::units::RAD_PER_DEG;

/// The least total rotation after the rest for a log to hold a calibration sequence: one quarter
/// turn (every built-in sequence turns many), rad.
const MIN_TURN_RAD: f64 = 90.0 * crate::math::units::RAD_PER_DEG;

/// The least rest at the start of a logged sequence (the coarse alignment's data), s.
pub const LOG_ALIGN_S: f64 = 60.0;
