//! How the plots are framed on their data: each series' extent as it grows and the range a plot of
//! it shows ([`frame`]).

use std::collections::BTreeMap;

use rerun::RecordingStreamResult;

use super::Recorder;
use super::rows;

/// Every plot framed on its data: each series' extent as it grows. A run's layout, sent once its
/// data are in, and a saved live session's final layout take each plot's range from it ([`frame`],
/// on the 1-2-5 grid the saved recordings use). A viewer watching a live session gets no range: it
/// fits each plot's value axis to the data as they arrive (measured in Rerun 0.36's web viewer:
/// a plot sent before its data, with no range, shows them framed).
#[derive(Default)]
pub(super) struct Frames {
    /// Each series' value extent so far (entity path → min, max), finite values only.
    extents: BTreeMap<String, (f64, f64)>,
    /// A live viewer's plots: the range each was last held at by its frame points.
    held: BTreeMap<String, (f64, f64)>,
}

/// The child entity of a plot that holds its value axis in a live viewer: two points nobody sees
/// at the plot's range (the viewer fits the axis to everything plotted, these included).
const FRAME_SLUG: &str = "frame";

impl Frames {
    /// Takes `values` (any width, row-major) of the series at `path` into its extent.
    pub(super) fn observe(&mut self, path: &str, values: &[f64]) {
        let e = self.extents.entry(path.to_owned()).or_insert((f64::INFINITY, f64::NEG_INFINITY));
        for v in values.iter().filter(|v| v.is_finite()) {
            *e = (e.0.min(*v), e.1.max(*v));
        }
    }
}

/// Whether a plot of `what` is framed symmetrically about zero (an error).
fn symmetric(what: rows::Quantity) -> bool {
    use rows::Quantity as Q;
    matches!(
        what,
        Q::TableError(_) | Q::InsError(_) | Q::ClosedForm | Q::PositionError | Q::VelocityError | Q::Swing(_)
    )
}

/// The value range a plot of `what` shows for data in `[lo, hi]`: error plots symmetric about
/// zero (±1.25 h, h on the 1-2-3-10 grid of [`crate::math::units::nice_half_range`], as the saved
/// recordings are framed); others `[lo, hi]` widened to whole steps of a 1-2-5 × 10^k grid with
/// about eight steps over the data.
pub(crate) fn frame(what: rows::Quantity, lo: f64, hi: f64) -> (f64, f64) {
    use crate::math::units::{nice_at_least, nice_half_range};
    if symmetric(what) {
        let h = nice_half_range(lo.abs().max(hi.abs()));
        return (-1.25 * h, 1.25 * h);
    }
    let span = (hi - lo).max(1e-9 * lo.abs().max(hi.abs())).max(1e-12);
    let step = nice_at_least(span / 8.0);
    let (a, b) = ((lo / step).floor() * step, (hi / step).ceil() * step);
    if b > a { (a, b) } else { (a - step, b + step) }
}

impl Recorder {
    /// A live viewer's error plots framed as a saved recording's are (symmetric, ±1.25 h, with
    /// labelled ticks), without sending the layout again: the viewer fits each plot to what it
    /// plots, so each error plot whose data have left their range gets two invisible points at the
    /// new range's ends, at the newest time `t_s`. (A layout sent again re-activates every view —
    /// tabs jump back, the web viewer stalls; see docs/live.md. Other plots are left to the
    /// viewer's own fit, which labels them well.)
    pub(super) fn hold_live_frames(&mut self, t_s: f64) -> RecordingStreamResult<()> {
        let mut moved = Vec::new();
        for s in self.series.iter().filter(|s| symmetric(s.what)) {
            let Some(&(lo, hi)) = self.frames.extents.get(&s.path).filter(|e| e.0.is_finite()) else { continue };
            let range = frame(s.what, lo, hi);
            if self.frames.held.get(&s.path).is_none_or(|&(a, b)| lo < a || hi > b) {
                moved.push((s.path.clone(), range));
            }
        }
        for (path, (lo, hi)) in moved {
            let entity = format!("{path}/{FRAME_SLUG}");
            if !self.frames.held.contains_key(&path) {
                self.rec.log_static(
                    entity.as_str(),
                    &rerun::SeriesPoints::new()
                        .with_marker_sizes([0.0])
                        .with_colors([rerun::Color::from_unmultiplied_rgba(0, 0, 0, 0)]),
                )?;
            }
            self.rec.send_columns(
                entity,
                self.stream.time_columns(&[t_s, t_s]),
                rerun::Scalars::new([lo, hi]).columns_of_unit_batches()?,
            )?;
            self.frames.held.insert(path, (lo, hi));
        }
        Ok(())
    }

    /// The value range of the plot whose space origin is `origin` on its data so far (every
    /// series at or under it, [`frame`]), None before it has data.
    pub(crate) fn data_range(&self, origin: &str) -> Option<(f64, f64)> {
        let f = &self.frames;
        let under = |p: &str| p == origin || p.strip_prefix(origin).is_some_and(|r| r.starts_with('/'));
        let mut what = None;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for s in self.series.iter().filter(|s| under(&s.path)) {
            if let Some(&(a, b)) = f.extents.get(&s.path).filter(|e| e.0.is_finite()) {
                (lo, hi) = (lo.min(a), hi.max(b));
                what.get_or_insert(s.what);
            }
        }
        what.map(|w| frame(w, lo, hi))
    }
}
