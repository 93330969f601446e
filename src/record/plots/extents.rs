//! Each plot fitted to its data: each series' extent as it grows and the range a plot of it shows
//! ([`plot_range`]).

use std::collections::BTreeMap;

use super::series as rows;

/// Every plot fitted to its data: each series' extent as it grows. A run's layout, sent once its
/// data are in, and a saved live session's final layout take each plot's range from it ([`plot_range`],
/// on the 1-2-5 grid the saved recordings use). A viewer watching a live session gets no range: it
/// fits each plot's value axis to the data as they arrive (measured in Rerun 0.36's web viewer:
/// a plot sent before its data, with no range, shows them framed).
#[derive(Default)]
pub(super) struct Extents {
    /// Each series' value extent so far (entity path → min, max), finite values only.
    pub(super) extents: BTreeMap<String, (f64, f64)>,
    /// A live viewer's plots: the range each was last held at by its frame points.
    pub(super) held: BTreeMap<String, (f64, f64)>,
}

/// The child entity of a plot that holds its value axis in a live viewer: two points nobody sees
/// at the plot's range (the viewer fits the axis to everything plotted, these included).
pub(super) const FRAME_SLUG: &str = "frame";

impl Extents {
    /// Takes `values` (any width, row-major) of the series at `path` into its extent.
    pub(super) fn observe(&mut self, path: &str, values: &[f64]) {
        let e = self.extents.entry(path.to_owned()).or_insert((f64::INFINITY, f64::NEG_INFINITY));
        for v in values.iter().filter(|v| v.is_finite()) {
            *e = (e.0.min(*v), e.1.max(*v));
        }
    }
}

/// Whether a plot of `what` is framed symmetrically about zero (an error).
pub(super) fn symmetric(what: rows::Quantity) -> bool {
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
pub(crate) fn plot_range(what: rows::Quantity, lo: f64, hi: f64) -> (f64, f64) {
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
