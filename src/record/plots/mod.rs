//! The plots view: every time series of a recording (the table's errors, gimbals, swings, the
//! INS's errors and solution), buffered row by row, sent as columns, each plot fitted to its data.
//! It owns those entities and their styles; nothing else logs to them.

pub(crate) mod coning;
mod envelope;
mod extents;
pub mod series;
mod styles;

use std::time::{Duration, Instant};

use nalgebra::Vector3;
use rerun::RecordingStreamResult;

use super::{ReplayKind, Stream};
use crate::ins::core::NavError;
use crate::ins::pipeline::InsView;
use crate::math::units::{ARCSEC_PER_RAD, AngleUnit, DEG_PER_RAD};
use crate::model::gimbal::{Chain, TableErrors};
use crate::scenario::Params;
use crate::sim::StepOutput;
pub(crate) use extents::plot_range;
use extents::{Extents, FRAME_SLUG, symmetric};
pub use series::Solution;
pub(crate) use series::{InsSeries, Quantity};
use series::{Series, same_row};

/// Every plotted series of a recording and the rows buffered for them.
pub(crate) struct Plots {
    series: Vec<Series>,
    /// With `--export`: the buffered samples' times, s.
    t: Vec<f64>,
    /// The newest sample's time since the last flush, s.
    newest: Option<f64>,
    /// The table (its swing plots), its true errors and the unit of its error plots.
    chain: Chain,
    truth: TableErrors,
    unit: AngleUnit,
    /// With an IMU in the loop: its algorithms' plots.
    pub(crate) ins: Option<InsSeries>,
    /// Each series' extent (the plots fitted to their data).
    extents: Extents,
    /// Whether every sample's row is kept for the export tables (`--export`).
    exporting: bool,
    /// Every plot's open envelope bucket: their lines side by side, in the series' order.
    bucket: envelope::Bucket,
}

/// What a row without a navigation view shows.
const NO_NAV: NavError = NavError {
    east_m: f64::NAN,
    north_m: f64::NAN,
    radial_m: f64::NAN,
    velocity_enu_mps: Vector3::new(f64::NAN, f64::NAN, f64::NAN),
};

impl Plots {
    /// The plots of a run of `params` (`replay`: of a replayed log of that kind).
    /// Each plot draws the envelope of its samples over buckets of `1 / recording.series_hz`
    /// (`envelope.rs`); `exporting`: every sample's row also goes to the export tables.
    pub(crate) fn new(params: &Params, replay: Option<ReplayKind>, exporting: bool) -> Self {
        let chain = params.table.chain.clone();
        let unit = params.recording.error_unit;
        let mut series = series::table_series(&chain, replay, unit);
        let ins = series::ins_series(params, replay, &mut series);
        let truth = params.table.truth.clone();
        let mut me = Self {
            series,
            t: Vec::new(),
            newest: None,
            chain,
            truth,
            unit,
            ins,
            extents: Extents::default(),
            exporting,
            bucket: envelope::Bucket::new(0, 0.0),
        };
        me.set_series_hz(params.recording.series_hz);
        me
    }

    /// Buckets of `1 / series_hz` for every plot's envelope, before its first sample (a replay
    /// learns its length from its file after the recording has started).
    pub(crate) fn set_series_hz(&mut self, series_hz: f64) {
        debug_assert!(self.newest.is_none() && self.series.iter().all(|s| s.rows.t.is_empty()));
        let mut width = 0;
        for s in &mut self.series {
            s.rows = envelope::Rows::default();
            s.lines = width..width + s.width();
            width += s.width();
        }
        self.bucket = envelope::Bucket::new(width, 1.0 / series_hz);
    }

    /// The unit of the table's error plots.
    pub(crate) fn error_unit(&self) -> AngleUnit {
        self.unit
    }

    /// True if the recording has the entity `path`.
    pub(crate) fn has(&self, path: &str) -> bool {
        self.series.iter().any(|s| s.path == path)
    }

    /// Whether any series is of the kind `what` matches.
    pub(crate) fn any(&self, what: impl Fn(Quantity) -> bool) -> bool {
        self.series.iter().any(|s| what(s.what))
    }

    /// The line names of the series at `path` (its legend).
    pub(crate) fn names(&self, path: &str) -> Vec<String> {
        self.series.iter().find(|s| s.path == path).map(|s| s.names.clone()).unwrap_or_default()
    }

    /// Rows buffered: the samples kept for the export, else the envelope's rows ready to send
    /// (a chunk is sent per 8192 of them: a chunk per few thousand samples made tens of thousands
    /// of tiny chunks over a long run, and the file sink's index of them grew with the run).
    pub(crate) fn buffered(&self) -> usize {
        if self.exporting { self.t.len() } else { self.series.iter().map(|s| s.rows.t.len()).max().unwrap_or(0) }
    }

    /// The newest sample's time since the last flush, s.
    pub(crate) fn newest(&self) -> Option<f64> {
        self.newest
    }

    /// New true errors (a live reload): the swing plots follow them.
    pub(crate) fn set_truth(&mut self, truth: TableErrors) {
        self.truth = truth;
    }

    /// Buffers one row of every series from the table's step `out`, the INS's view `ins` (errors,
    /// navigation) and, in a replay, its own `solution`.
    pub(crate) fn push(&mut self, out: &StepOutput, ins: Option<&InsView>, solution: Option<&Solution>) {
        // One bucket for the row's every plot (a division per plot and sample: 5 % of a pure
        // coning run's CPU).
        let bucket = envelope::Bucket::bucket_of(self.bucket.bucket_s(), out.t_s);
        if self.bucket.leaves(bucket) {
            self.close_buckets();
        }
        let Self { series, chain, truth, unit, ins: layout, t, exporting, bucket: open, .. } = self;
        if *exporting {
            t.push(out.t_s);
        }
        self.newest = Some(out.t_s);
        let per_rad = unit.per_rad();
        let lines = layout.as_ref().and_then(|l| l.coning.as_ref());
        let nav = ins.and_then(|v| v.nav).unwrap_or(NO_NAV);
        let state = solution.and_then(|s| s.nav);
        let v = open.row();
        for s in series.iter() {
            let width = s.width();
            match s.what {
                Quantity::TableError(a) => v.extend(out.errors[..width].iter().map(|e| e.as_array()[a] * per_rad)),
                Quantity::ClosedForm => {
                    let (exact, closed) = (out.errors[0].as_array(), out.errors[2].as_array());
                    v.extend((0..3).map(|a| (closed[a] - exact[a]) * ARCSEC_PER_RAD));
                }
                Quantity::GimbalAngles => v.extend(out.gimbal_rad[..width].iter().map(|x| x * DEG_PER_RAD)),
                Quantity::VehicleAttitude => {
                    let a = out.attitude();
                    v.extend([a.pitch_rad, a.roll_rad, a.heading_rad].map(|x| x * DEG_PER_RAD));
                }
                Quantity::Swing(k) => {
                    let g = &chain.axes()[k];
                    let sw = chain.swing_vector(k, &truth.axes[k], out.gimbal_rad[k]);
                    v.extend([sw.dot(&g.e1) * ARCSEC_PER_RAD, sw.dot(&g.e2) * ARCSEC_PER_RAD]);
                }
                Quantity::InsError(a) => match ins {
                    Some(view) => v.extend(view.errors.iter().map(|e| e.as_array()[a] * ARCSEC_PER_RAD)),
                    None => v.extend(std::iter::repeat_n(f64::NAN, width)),
                },
                // The values whose log10 the plot shows: the logarithm is monotonic, so the
                // envelope of the values is the envelope of their logarithms, taken at the flush
                // for the rows sent only (`log10_of_positive`).
                Quantity::ConingLog => {
                    let positive = |x: f64| if x > 0.0 && x.is_finite() { x } else { f64::NAN };
                    for j in 0..lines.map_or(0, |l| l.rates.len()) {
                        let measured =
                            ins.map_or(f64::NAN, |view| positive(view.errors[j].heading_rad.abs() * ARCSEC_PER_RAD));
                        v.extend([measured, positive(lines.map_or(f64::NAN, |l| l.at(j, out.t_s)))]);
                    }
                }
                Quantity::PositionError => v.extend([nav.east_m, nav.north_m, nav.radial_m]),
                Quantity::VelocityError => v.extend(nav.velocity_enu_mps.iter()),
                Quantity::BodyAttitude => match solution {
                    // Heading in (−180°, 180°]: a vehicle pointing North (most tests) does not jump by 360°.
                    Some(s) => {
                        v.extend([s.body.pitch_rad, s.body.roll_rad, s.body.heading_rad].map(|x| x * DEG_PER_RAD))
                    }
                    None => v.extend([f64::NAN; 3]),
                },
                Quantity::Velocity => {
                    v.extend(state.map_or([f64::NAN; 3], |n| [n.v_n.x, n.v_n.y, n.v_n.z])[..width].iter())
                }
                Quantity::PositionFromStart => v.extend([nav.east_m, nav.north_m]),
                Quantity::LatitudeLongitude => v.extend(
                    state.map_or([f64::NAN; 2], |n| [n.latitude_rad * DEG_PER_RAD, n.longitude_rad * DEG_PER_RAD]),
                ),
                Quantity::Height => v.push(state.map_or(f64::NAN, |n| n.height_m)),
            }
            debug_assert_eq!(v.len(), s.lines.end, "{}", s.path);
        }
        open.commit(bucket, out.t_s);
        if *exporting {
            for s in series.iter_mut() {
                s.values.extend_from_slice(&open.last_row()[s.lines.clone()]);
            }
        }
    }

    /// Closes every plot's open bucket (the end of the data): the next flush sends it.
    pub(crate) fn close_buckets(&mut self) {
        for s in &mut self.series {
            s.rows.close(&self.bucket.lines(s.lines.clone()));
        }
        self.bucket.clear();
    }

    /// Sends every finished bucket's rows to the plots, and every sample's rows to the export
    /// tables; returns the chunks sent. With `hold` (viewers watching live, a stream that exports
    /// nothing): a series whose rows all repeat the last row it sent (a table error that is zero,
    /// a vehicle at rest) sends nothing for up to `hold`, then its newest row only — the same line,
    /// drawn flat to the same end, with a chunk every `hold` instead of every flush (a web viewer
    /// ingests a few dozen chunks a second).
    pub(crate) fn flush(&mut self, stream: &Stream, hold: Option<Duration>) -> RecordingStreamResult<usize> {
        let samples = std::mem::take(&mut self.t);
        self.newest = None;
        let hold = hold.filter(|_| !stream.exports());
        let now = Instant::now();
        let mut sent = 0;
        for s in &mut self.series {
            let logarithmic = s.what == Quantity::ConingLog;
            let mut raw = std::mem::take(&mut s.values);
            if self.exporting && !samples.is_empty() {
                if logarithmic {
                    log10_of_positive(&mut raw);
                }
                stream.export_series(&s.path, &s.names, &samples, &raw);
            }
            let (times, mut values) = s.rows.take();
            if logarithmic {
                log10_of_positive(&mut values);
            }
            if times.is_empty() {
                continue;
            }
            let width = s.width();
            debug_assert_eq!(values.len(), width * times.len());
            self.extents.observe(&s.path, &values);
            let last_row = values.len().checked_sub(width).map(|i| values[i..].to_vec()).unwrap_or_default();
            let (t, v) = match (hold, &s.last_sent) {
                (Some(hold), Some((row, at))) if values.chunks(width).all(|r| same_row(r, row)) => {
                    if now.duration_since(*at) < hold {
                        s.held_until_s = times.last().copied();
                        continue;
                    }
                    (vec![times[times.len() - 1]], last_row.clone())
                }
                // After rows held back, the newest of them first: the line stays flat up to it
                // instead of sloping from the last row sent to the first new one.
                (_, Some((row, _))) if s.held_until_s.is_some() => {
                    let held = s.held_until_s.unwrap_or_default();
                    (
                        std::iter::once(held).chain(times.iter().copied()).collect(),
                        row.iter().copied().chain(values).collect(),
                    )
                }
                _ => (times, values),
            };
            s.held_until_s = None;
            stream.plot_series(&s.path, &t, v, width)?;
            s.last_sent = Some((last_row, now));
            sent += 1;
        }
        Ok(sent)
    }

    /// A live viewer's error plots framed as a saved recording's are (symmetric, ±1.25 h, with
    /// labelled ticks), without sending the layout again: the viewer fits each plot to what it
    /// plots, so each error plot whose data have left their range gets two invisible points at the
    /// new range's ends, at the newest time `t_s`. (A layout sent again re-activates every view —
    /// tabs jump back, the web viewer stalls; see docs/live.md. Other plots are left to the
    /// viewer's own fit, which labels them well.)
    pub(crate) fn hold_extents(&mut self, stream: &Stream, t_s: f64) -> RecordingStreamResult<()> {
        let mut moved = Vec::new();
        for s in self.series.iter().filter(|s| symmetric(s.what)) {
            let Some(&(lo, hi)) = self.extents.extents.get(&s.path).filter(|e| e.0.is_finite()) else { continue };
            let range = plot_range(s.what, lo, hi);
            if self.extents.held.get(&s.path).is_none_or(|&(a, b)| lo < a || hi > b) {
                moved.push((s.path.clone(), range));
            }
        }
        for (path, (lo, hi)) in moved {
            let entity = format!("{path}/{FRAME_SLUG}");
            if !self.extents.held.contains_key(&path) {
                stream.rec().log_static(
                    entity.as_str(),
                    &rerun::SeriesPoints::new()
                        .with_marker_sizes([0.0])
                        .with_colors([rerun::Color::from_unmultiplied_rgba(0, 0, 0, 0)]),
                )?;
            }
            stream.rec().send_columns(
                entity,
                stream.time_columns(&[t_s, t_s]),
                rerun::Scalars::new([lo, hi]).columns_of_unit_batches()?,
            )?;
            self.extents.held.insert(path, (lo, hi));
        }
        Ok(())
    }

    /// The value range of the plot whose space origin is `origin` on its data so far (every
    /// series at or under it, [`plot_range`]), None before it has data.
    pub(crate) fn data_range(&self, origin: &str) -> Option<(f64, f64)> {
        let f = &self.extents;
        let under = |p: &str| p == origin || p.strip_prefix(origin).is_some_and(|r| r.starts_with('/'));
        let mut what = None;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for s in self.series.iter().filter(|s| under(&s.path)) {
            if let Some(&(a, b)) = f.extents.get(&s.path).filter(|e| e.0.is_finite()) {
                (lo, hi) = (lo.min(a), hi.max(b));
                what.get_or_insert(s.what);
            }
        }
        what.map(|w| plot_range(w, lo, hi))
    }
}

/// The coning plot's values as it shows them: log10 of each (positive or NaN, [`Plots::push`]).
fn log10_of_positive(values: &mut [f64]) {
    values.iter_mut().for_each(|x| *x = x.log10());
}
