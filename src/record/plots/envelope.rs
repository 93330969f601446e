//! What a plot can show of a long high-rate series: per time bucket, each line's first, smallest,
//! largest and last sample (an M4 envelope). A plot a few thousand pixels wide draws a bucket as
//! one column; drawn through these four rows, the column spans exactly what every sample in it
//! spans, so a peak of one sample is never lost, and a line enters and leaves each column where
//! the full-rate line does. Lines of one entity share their rows' times: the two middle rows stand
//! at the mean time of the lines' earlier and later extremes (exact for a single line; for several,
//! within the bucket, which the recording's bucket width makes a fraction of a pixel until zoomed
//! in by that much). A bucket of one, two or three samples, or whose extremes are its first and
//! last samples (a drift), gives only its samples; a stretch of repeated rows (a zero error, a
//! vehicle at rest) gives its first and last row: the same line, drawn flat.

use std::ops::Range;

use super::series::same_row;

/// The open bucket of every line of the plots sampled together (all of a recording's plots take
/// every row, on one grid): the bucket, its samples' count and times, and per line its first and
/// last sample and its extremes. One wide bucket, not one per plot: per plot and row, the
/// bookkeeping of a few lines cost more than the lines (a fifth of a pure coning run's recorder).
/// Each plot's [`Rows`] takes its lines when the bucket closes.
pub(crate) struct Bucket {
    bucket_s: f64,
    /// The open bucket's index on the grid (None before the first sample).
    bucket: Option<i64>,
    /// Samples in the open bucket.
    n: usize,
    t_first: f64,
    t_last: f64,
    first: Vec<f64>,
    last: Vec<f64>,
    /// Per line, the smallest and the largest finite sample so far and their times.
    lo: Vec<(f64, f64)>,
    hi: Vec<(f64, f64)>,
    /// The next sample's row, written in place by the caller ([`Self::row`]) and taken by
    /// [`Self::commit`], which swaps it with `last`: no copy of the row per sample (those copies
    /// were a sixth of a pure coning run's recorder).
    row: Vec<f64>,
}

/// A closed bucket's lines `first..last` of a [`Bucket`], for one plot's [`Rows::close`].
pub(crate) struct Lines<'a> {
    n: usize,
    t_first: f64,
    t_last: f64,
    first: &'a [f64],
    last: &'a [f64],
    lo: &'a [(f64, f64)],
    hi: &'a [(f64, f64)],
}

impl Bucket {
    /// A bucket of `width` lines over buckets of `bucket_s` s (0: every sample is a bucket).
    pub(crate) fn new(width: usize, bucket_s: f64) -> Self {
        Self {
            bucket_s,
            bucket: None,
            n: 0,
            t_first: 0.0,
            t_last: 0.0,
            first: vec![f64::NAN; width],
            last: vec![f64::NAN; width],
            lo: vec![(f64::INFINITY, 0.0); width],
            hi: vec![(f64::NEG_INFINITY, 0.0); width],
            row: Vec::with_capacity(width),
        }
    }

    /// The buckets' width, s.
    pub(crate) fn bucket_s(&self) -> f64 {
        self.bucket_s
    }

    /// The bucket of time `t_s` on a grid of `bucket_s` (0: every sample its own).
    #[inline]
    pub(crate) fn bucket_of(bucket_s: f64, t_s: f64) -> i64 {
        if bucket_s > 0.0 { (t_s / bucket_s + 1e-9).floor() as i64 } else { i64::MIN }
    }

    /// Whether a sample in the grid's bucket `bucket` closes the open bucket first (every sample
    /// does with buckets of 0 s): then each plot takes its lines ([`Self::lines`]) and
    /// [`Self::clear`] empties it, before [`Self::commit`].
    #[inline]
    pub(crate) fn leaves(&self, bucket: i64) -> bool {
        self.n > 0 && (self.bucket_s <= 0.0 || self.bucket != Some(bucket))
    }

    /// The next sample's row, empty, for the caller to write every line's value into; then
    /// [`Self::commit`].
    pub(crate) fn row(&mut self) -> &mut Vec<f64> {
        self.row.clear();
        &mut self.row
    }

    /// Takes the row written into [`Self::row`] as the sample at `t_s`, in the grid's bucket
    /// `bucket` ([`Self::bucket_of`] of `t_s`), the open one unless [`Self::leaves`] closed it.
    #[inline]
    pub(crate) fn commit(&mut self, bucket: i64, t_s: f64) {
        debug_assert_eq!(self.row.len(), self.lo.len());
        debug_assert_eq!(bucket, Self::bucket_of(self.bucket_s, t_s));
        debug_assert!(!self.leaves(bucket));
        self.bucket = Some(bucket);
        if self.n == 0 {
            self.t_first = t_s;
            self.first.copy_from_slice(&self.row);
        }
        self.n += 1;
        self.t_last = t_s;
        // Zipped slices: indexing reloaded the vectors' pointers and checked bounds at every value
        // (callgrind: the plots' instructions 13 % fewer on pure coning, the whole run's 2.8 %).
        for ((&v, lo), hi) in self.row.iter().zip(self.lo.iter_mut()).zip(self.hi.iter_mut()) {
            if v < lo.0 {
                *lo = (v, t_s);
            }
            if v > hi.0 {
                *hi = (v, t_s);
            }
        }
        std::mem::swap(&mut self.row, &mut self.last);
    }

    /// The row of the latest sample committed.
    pub(crate) fn last_row(&self) -> &[f64] {
        &self.last
    }

    /// The open bucket's `lines`, as a plot's [`Rows::close`] takes them.
    pub(crate) fn lines(&self, lines: Range<usize>) -> Lines<'_> {
        Lines {
            n: self.n,
            t_first: self.t_first,
            t_last: self.t_last,
            first: &self.first[lines.clone()],
            last: &self.last[lines.clone()],
            lo: &self.lo[lines.clone()],
            hi: &self.hi[lines],
        }
    }

    /// Empties the open bucket (every plot took its lines).
    pub(crate) fn clear(&mut self) {
        self.n = 0;
        self.lo.fill((f64::INFINITY, 0.0));
        self.hi.fill((f64::NEG_INFINITY, 0.0));
    }
}

/// One plot's rows: what its lines' closed buckets gave, ready to send.
#[derive(Default)]
pub(crate) struct Rows {
    /// The rows ready to send: their times and values (row-major).
    pub(crate) t: Vec<f64>,
    pub(crate) values: Vec<f64>,
    /// The last row emitted (compared with the next).
    previous: Vec<f64>,
    /// The time of the newest row held back because it repeats `previous`.
    repeat_s: Option<f64>,
}

impl Rows {
    /// Emits the rows of a closed bucket's lines `b` (this plot's, always the same lines).
    pub(crate) fn close(&mut self, b: &Lines<'_>) {
        let width = b.first.len();
        let n = b.n;
        if n == 0 {
            return;
        }
        let (first, last) = (b.first, b.last);
        self.emit(b.t_first, first);
        if n >= 3 {
            // Per line, its extremes in the order they happened; the bucket adds rows only when
            // some line's extremes are not its first and last samples.
            let mut inner = false;
            let (mut early, mut late) = (vec![f64::NAN; width], vec![f64::NAN; width]);
            let (mut t_early, mut t_late, mut timed) = (0.0, 0.0, 0usize);
            for j in 0..width {
                let ((lo, t_lo), (hi, t_hi)) = (b.lo[j], b.hi[j]);
                if !lo.is_finite() && !hi.is_finite() {
                    continue;
                }
                let ends = [first[j], last[j]];
                let at_ends = |v: f64| ends.iter().any(|e| e.to_bits() == v.to_bits() || *e == v);
                inner |= !(at_ends(lo) && at_ends(hi));
                let ((a, ta), (b, tb)) = if t_lo <= t_hi { ((lo, t_lo), (hi, t_hi)) } else { ((hi, t_hi), (lo, t_lo)) };
                (early[j], late[j]) = (a, b);
                t_early += ta;
                t_late += tb;
                timed += 1;
            }
            if inner && timed > 0 {
                let k = timed as f64;
                let t1 = (t_early / k).clamp(b.t_first, b.t_last);
                let t2 = (t_late / k).clamp(t1, b.t_last);
                self.emit(t1, &early);
                self.emit(t2, &late);
            }
        }
        if n >= 2 {
            self.emit(b.t_last, last);
        }
    }

    /// Appends a row to the output, holding back one that repeats the last.
    fn emit(&mut self, t_s: f64, row: &[f64]) {
        if !self.previous.is_empty() && same_row(row, &self.previous) {
            self.repeat_s = Some(t_s);
            return;
        }
        self.release();
        self.t.push(t_s);
        self.values.extend_from_slice(row);
        self.previous.clear();
        self.previous.extend_from_slice(row);
    }

    /// The row held back as a repeat, out now (the line drawn flat up to it).
    pub(crate) fn release(&mut self) {
        if let Some(t) = self.repeat_s.take() {
            self.t.push(t);
            self.values.extend_from_slice(&self.previous);
        }
    }

    /// The rows ready to send, taken (with the repeat held back, if any).
    pub(crate) fn take(&mut self) -> (Vec<f64>, Vec<f64>) {
        self.release();
        (std::mem::take(&mut self.t), std::mem::take(&mut self.values))
    }
}

/// One plot's envelope on its own: a bucket of its lines and its rows.
#[cfg(test)]
pub(crate) struct Envelope {
    bucket: Bucket,
    rows: Rows,
}

#[cfg(test)]
impl Envelope {
    /// An envelope of `width` lines over buckets of `bucket_s` s (0: every sample is a bucket).
    pub(crate) fn new(width: usize, bucket_s: f64) -> Self {
        Self { bucket: Bucket::new(width, bucket_s), rows: Rows::default() }
    }

    /// Takes one sample `row` (`width` values) at `t_s` (not before the previous sample's).
    pub(crate) fn push(&mut self, t_s: f64, row: &[f64]) {
        let bucket = Bucket::bucket_of(self.bucket.bucket_s(), t_s);
        if self.bucket.leaves(bucket) {
            self.close();
        }
        self.bucket.row().extend_from_slice(row);
        self.bucket.commit(bucket, t_s);
    }

    /// Emits the open bucket's rows (the end of the data).
    pub(crate) fn close(&mut self) {
        self.rows.close(&self.bucket.lines(0..self.bucket.first.len()));
        self.bucket.clear();
    }

    /// The rows ready to send, taken.
    pub(crate) fn take(&mut self) -> (Vec<f64>, Vec<f64>) {
        self.rows.take()
    }
}

#[cfg(test)]
mod tests {
    use super::Envelope;

    /// Samples `f(t)` at `hz` for `secs` through an envelope of `bucket_s` buckets, closed at the end.
    fn through(bucket_s: f64, hz: f64, secs: f64, f: impl Fn(f64) -> [f64; 2]) -> (Vec<f64>, Vec<f64>, Vec<[f64; 2]>) {
        let mut e = Envelope::new(2, bucket_s);
        let mut all = Vec::new();
        let n = (secs * hz) as usize;
        for i in 0..n {
            let t = i as f64 / hz;
            let row = f(t);
            all.push(row);
            e.push(t, &row);
        }
        e.close();
        let (t, v) = e.take();
        (t, v, all)
    }

    #[test]
    fn a_spike_of_one_sample_survives_and_every_bucket_spans_its_samples() {
        // A noisy-looking deterministic signal at 100 Hz with a one-sample spike, 1-s buckets.
        let spike_at = 1234usize;
        let f = |t: f64| {
            let i = (t * 100.0).round() as usize;
            let s = if i == spike_at { 50.0 } else { 0.0 };
            [(t * 7.3).sin() + 0.1 * ((i * 7919) % 13) as f64 + s, -(t * 0.31).cos()]
        };
        let (t, v, all) = through(1.0, 100.0, 60.0, f);
        assert!(v.len() == 2 * t.len() && t.len() < all.len() / 10, "{} rows for {} samples", t.len(), all.len());
        // Times in order, and each bucket's extremes are the envelope's (computed independently).
        assert!(t.windows(2).all(|w| w[0] <= w[1]));
        for b in 0..60usize {
            let samples = &all[b * 100..(b + 1) * 100];
            for j in 0..2 {
                let (lo, hi) =
                    samples.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, z), r| (a.min(r[j]), z.max(r[j])));
                let rows: Vec<f64> = t
                    .iter()
                    .zip(v.chunks(2))
                    .filter(|(tt, _)| (**tt / 1.0 + 1e-9).floor() as usize == b)
                    .map(|(_, r)| r[j])
                    .collect();
                let (rlo, rhi) =
                    rows.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, z), x| (a.min(*x), z.max(*x)));
                assert_eq!((rlo, rhi), (lo, hi), "bucket {b} line {j}");
                assert_eq!(rows.first().copied(), Some(samples[0][j]), "bucket {b} line {j} starts where it starts");
                assert_eq!(rows.last().copied(), Some(samples[99][j]), "bucket {b} line {j} ends where it ends");
            }
        }
        // The spike: its value at its own time (a single line's extreme keeps its time).
        let k = v.chunks(2).position(|r| r[0] > 40.0).expect("the spike is in the envelope");
        assert!((t[k] - spike_at as f64 / 100.0).abs() < 1.0);
    }

    #[test]
    fn a_flat_stretch_is_two_rows_and_a_ramp_keeps_its_ends() {
        let (t, v, _) = through(1.0, 100.0, 30.0, |t| [0.0, if t < 10.0 { 1.0 } else { 2.0 }]);
        // Flat at (0, 1) until 9.99 s, then flat at (0, 2) until the end.
        assert_eq!(t, vec![0.0, 9.99, 10.0, 29.99]);
        assert_eq!(v, vec![0.0, 1.0, 0.0, 1.0, 0.0, 2.0, 0.0, 2.0]);
        // A ramp: each bucket's first and last sample only.
        let (t, _, _) = through(1.0, 100.0, 5.0, |t| [t, -t]);
        assert_eq!(t.len(), 10);
    }

    #[test]
    fn nan_rows_pass_as_rows_and_finite_extremes_are_kept() {
        let (t, v, _) = through(1.0, 10.0, 3.0, |t| if t < 1.0 { [f64::NAN; 2] } else { [t.sin(), 1.0] });
        assert!(v[0].is_nan() && t[0] == 0.0);
        assert!(v.iter().filter(|x| x.is_finite()).all(|x| x.abs() <= 1.0));
    }
}
