//! How the plots are framed on their data: each series' extent as it grows, the range a plot of
//! it shows ([`frame`]), and in live mode the layout sent again when a series leaves its frame.

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use rerun::RecordingStreamResult;

use super::rows;
use super::Recorder;
use crate::scenario::Params;

/// Every plot framed on its data: each series' extent as it grows. The viewer fits a plot's value
/// axis once, when the plot first appears — before a live session has data — and keeps ±1 after;
/// so a live layout carries each plot's range itself, on the 1-2-5 grid the saved recordings use
/// ([`frame`]), and is sent again when a series leaves it (at most once every
/// [`REFRAME_MIN_INTERVAL`]). A run's layout, sent once its data are in, takes the same ranges.
pub(super) struct Frames {
    /// Each series' value extent so far (entity path → min, max), finite values only.
    extents: BTreeMap<String, (f64, f64)>,
    /// The range each series' extent gave when the layout was last sent (live mode).
    drawn: BTreeMap<String, (f64, f64)>,
    /// Live mode: the parameters the layout is rebuilt from, and when it was last sent.
    live: Option<(Box<Params>, Instant)>,
}

impl Frames {
    /// Framing for a recorder; `live_params` in live mode (the layout is then sent again as the
    /// data grow).
    pub(super) fn new(live_params: Option<&Params>) -> Self {
        Self { extents: BTreeMap::new(), drawn: BTreeMap::new(), live: live_params.map(|p| (Box::new(p.clone()), Instant::now())) }
    }

    /// Takes `values` (any width, row-major) of the series at `path` into its extent.
    pub(super) fn observe(&mut self, path: &str, values: &[f64]) {
        let e = self.extents.entry(path.to_owned()).or_insert((f64::INFINITY, f64::NEG_INFINITY));
        for v in values.iter().filter(|v| v.is_finite()) {
            *e = (e.0.min(*v), e.1.max(*v));
        }
    }
}

/// Least wall time between two live re-framings.
const REFRAME_MIN_INTERVAL: Duration = Duration::from_millis(500);

/// The value range a plot of `what` shows for data in `[lo, hi]`: error plots symmetric about
/// zero (±1.25 h, h on the 1-2-3-10 grid of [`crate::math::units::nice_half_range`], as the saved
/// recordings are framed); others `[lo, hi]` widened to whole steps of a 1-2-5 × 10^k grid with
/// about eight steps over the data.
pub(crate) fn frame(what: rows::Quantity, lo: f64, hi: f64) -> (f64, f64) {
    use crate::math::units::{nice_at_least, nice_half_range};
    use rows::Quantity as Q;
    if matches!(what, Q::TableError(_) | Q::InsError(_) | Q::ClosedForm | Q::PositionError | Q::VelocityError | Q::Swing(_)) {
        let h = nice_half_range(lo.abs().max(hi.abs()));
        return (-1.25 * h, 1.25 * h);
    }
    let span = (hi - lo).max(1e-9 * lo.abs().max(hi.abs())).max(1e-12);
    let step = nice_at_least(span / 8.0);
    let (a, b) = ((lo / step).floor() * step, (hi / step).ceil() * step);
    if b > a { (a, b) } else { (a - step, b + step) }
}

impl Recorder {
    /// Live mode: sends the layout again when a series has left the range it was framed at.
    pub(super) fn reframe_live(&mut self) -> RecordingStreamResult<()> {
        let f = &self.frames;
        let Some((params, sent)) = &f.live else { return Ok(()) };
        let outside = self.series.iter().any(|s| match (f.extents.get(&s.path), f.drawn.get(&s.path)) {
            (Some(&(lo, hi)), Some(&(a, b))) => lo.is_finite() && (lo < a || hi > b),
            (Some(&(lo, _)), None) => lo.is_finite(),
            _ => false,
        });
        if !outside || sent.elapsed() < REFRAME_MIN_INTERVAL {
            return Ok(());
        }
        self.send_blueprint(params, self.custom.clone())?;
        let drawn = self.series.iter().filter_map(|s| f.extents.get(&s.path).filter(|e| e.0.is_finite()).map(|&(lo, hi)| (s.path.clone(), frame(s.what, lo, hi)))).collect();
        self.frames.drawn = drawn;
        if let Some((_, sent)) = &mut self.frames.live {
            *sent = Instant::now();
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
