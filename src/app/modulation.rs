//! `rinscope modulation`: rotation modulation demonstrated. The same IMU (constant gyro and
//! accelerometer biases) on a static vehicle navigates 24 h with no rotation, with continuous azimuth
//! rotation and with the 16-position sequence — three simulations in parallel, one recording.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::app::failure::Failure;
use crate::app::outputs::{RecordingName, RecordingRequest, finish, logged};
use crate::ins::trace::{NavSample, NavTrace};
use crate::math::units::ARCSEC_PER_RAD;
use crate::record::sink::Saved;
use crate::scenario::{Params, presets};

/// The three variants: preset name and label.
pub const MODULATION_PRESETS: [(&str, &str); 3] = [
    ("rotation-modulation-none", "no rotation"),
    ("rotation-modulation-continuous", "continuous azimuth"),
    ("rotation-modulation-16-position", "16-position"),
];

/// `p`'s INS navigating its whole duration, sampled every `sample_s`; the IMU compensated with
/// `compensation` (a self-calibration's estimates) if given.
pub(crate) fn simulate(
    p: &Params,
    label: &str,
    sample_s: f64,
    stop: &AtomicBool,
    compensation: Option<crate::calib::selfcal::ImuErrors>,
) -> NavTrace {
    let mut trace = NavTrace { label: label.to_owned(), samples: Vec::new() };
    let Some(mut ins) = p.ins_run() else { return trace };
    ins.set_imu_compensation(compensation);
    let steps = p.timeline().intervals();
    let mut next = 0.0;
    for i in 0..steps {
        if i % 100_000 == 0 && stop.load(Ordering::Relaxed) {
            break;
        }
        let s = ins.step();
        if s.updated && s.t_s >= next {
            next += sample_s;
            let v = ins.view(s.t_s);
            let e = v.nav.unwrap_or_default();
            trace.samples.push(NavSample {
                t_s: s.t_s,
                position_m: [e.east_m, e.north_m, e.radial_m],
                heading_arcsec: v.errors[0].heading_rad * ARCSEC_PER_RAD,
            });
        }
    }
    trace
}

/// Runs the three variants for `hours` (in parallel) and returns their traces.
pub fn simulate_variants(hours: f64, stop: &AtomicBool) -> anyhow::Result<Vec<NavTrace>> {
    let mut params = Vec::new();
    for (name, label) in MODULATION_PRESETS {
        let mut p = presets::load(name)?;
        p.set_duration(hours * 3600.0);
        params.push((p, label));
    }
    let sample_s = (hours * 3600.0 / 2000.0).max(1.0);
    let traces = std::thread::scope(|scope| {
        let handles: Vec<_> =
            params.iter().map(|(p, label)| scope.spawn(move || simulate(p, label, sample_s, stop, None))).collect();
        handles
            .into_iter()
            .map(|h| h.join().map_err(|_| anyhow::anyhow!("a simulation thread panicked")))
            .collect::<anyhow::Result<Vec<_>>>()
    })?;
    Ok(traces)
}

/// The end-of-run table.
#[must_use]
pub fn table(traces: &[NavTrace], wall_s: f64) -> String {
    let mut s = format!(
        "rotation modulation, {wall_s:.1} s wall\n{:<22} {:>16} {:>16} {:>18}\n",
        "variant", "peak radial (m)", "final radial (m)", "peak heading (″)"
    );
    for t in traces {
        let last = t.samples.last().copied().unwrap_or_default();
        s.push_str(&format!(
            "{:<22} {:>16.1} {:>16.1} {:>18.1}\n",
            t.label,
            t.peak_radial_m(),
            last.position_m[2],
            t.peak_heading_arcsec()
        ));
    }
    s
}

/// `--hours`: > 0 and at most 30 days (`scenario::MAX_DURATION_S`, a scenario's longest).
pub const HOURS: crate::io::validity::Range =
    crate::io::validity::Range::positive(crate::scenario::MAX_DURATION_S / 3600.0, "h", "a simulated duration");

/// What `modulation` reports.
pub struct ModulationReport {
    /// The three variants side by side (with what a stop cut short said first).
    pub table: String,
    /// The recording kept.
    pub saved: Saved,
    /// Stopped early: the table and the recording cover the simulated part only.
    pub interrupted: bool,
}

/// `modulation`'s one owner: `hours` simulated three times in parallel, one recording.
///
/// # Errors
/// `hours` out of range, a sink that cannot be opened or written.
pub fn execute(hours: f64, recording: &RecordingRequest, stop: &AtomicBool) -> Result<ModulationReport, Failure> {
    crate::io::validity::check_number(hours, &HOURS).map_err(|e| Failure::input(format!("--hours {e}")))?;
    let sinks = recording.open(RecordingName { name: "rotation-modulation", kind: None, seed: None })?;
    let started = std::time::Instant::now();
    errln!("rinscope: simulating {hours} h three times in parallel (no rotation, continuous azimuth, 16-position)...");
    let traces = simulate_variants(hours, stop)?;
    let interrupted = stop.load(Ordering::SeqCst);
    let mut text = table(&traces, started.elapsed().as_secs_f64());
    if interrupted {
        let reached =
            traces.iter().filter_map(|t| t.samples.last()).map(|s| s.t_s / 3600.0).fold(f64::INFINITY, f64::min);
        text = format!(
            "INTERRUPTED after {reached:.2} of {hours} h: the numbers below are over that part only, not the run's\n{text}"
        );
    }
    logged(crate::record::modulation::log(&sinks.stream(), &traces, &text))?;
    Ok(ModulationReport { table: text, saved: finish(sinks)?, interrupted })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_averages_constant_biases_out() {
        // The principle (Zheng et al. 2016 §1, Levinson & Majure 1987): with constant biases, turning the IMU
        // modulates their effect. Over 6 h: the 16-position sequence keeps the position error two
        // orders of magnitude below the static INS; azimuth rotation alone leaves the vertical gyro's
        // bias, so its heading error stays of the static order.
        let traces = simulate_variants(6.0, &AtomicBool::new(false)).expect("runs");
        let (none, cont, sixteen) = (&traces[0], &traces[1], &traces[2]);
        assert!(none.peak_radial_m() > 1000.0, "static INS: {} m", none.peak_radial_m());
        assert!(
            sixteen.peak_radial_m() < none.peak_radial_m() / 50.0,
            "16-position {} m vs static {} m",
            sixteen.peak_radial_m(),
            none.peak_radial_m()
        );
        assert!(cont.peak_radial_m() < none.peak_radial_m(), "continuous {} m", cont.peak_radial_m());
        assert!(sixteen.peak_heading_arcsec() < none.peak_heading_arcsec() / 20.0);
        assert!(
            cont.peak_heading_arcsec() > none.peak_heading_arcsec() / 3.0,
            "the azimuth gyro is not modulated by azimuth rotation"
        );
    }
}
