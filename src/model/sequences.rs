//! Indexing sequences for a search: random balanced sequences of moves under a table's
//! constraints (which axes turn, the move sizes, rates and dwells, the cable's wrap).
//!
//! A candidate is a list of [`IndexedStep`]s whose moves sum to zero on every axis (the sequence
//! repeats without winding the cable) and never take an axis further than `max_wrap_rad` from its
//! start. Half the candidates are drawn free; half are a free half followed by its mirror (the
//! moves in reverse order, each reversed), the odd-symmetric form whose rate-excited errors cancel
//! in pairs — the search sees both families and lets the model choose.

use rand::Rng;

use super::scheme::IndexedStep;

/// What a search may choose from.
#[derive(Debug, Clone, PartialEq)]
pub struct Constraints {
    /// The axes that may move (indices into the chain).
    pub axes: Vec<usize>,
    /// Sequence lengths, moves per period (each even: every axis returns).
    pub steps: Vec<usize>,
    /// Move sizes, rad (> 0; the sign is the search's).
    pub angles_rad: Vec<f64>,
    /// Cruise rates, rad/s (> 0).
    pub rates_rad_per_s: Vec<f64>,
    /// Dwells after each move, s (≥ 0).
    pub dwells_s: Vec<f64>,
    /// The moves' acceleration, rad/s² (0: the rate steps instantly).
    pub accel_rad_per_s2: f64,
    /// The largest excursion of an axis from its start, rad (the cable's wrap).
    pub max_wrap_rad: f64,
}

impl Constraints {
    /// Why no sequence fits, if none does.
    #[must_use]
    pub fn problem(&self) -> Option<String> {
        let positive = |v: &[f64]| !v.is_empty() && v.iter().all(|x| x.is_finite() && *x > 0.0);
        if self.axes.is_empty() {
            return Some("no axis may move".into());
        }
        if self.steps.is_empty() || self.steps.iter().any(|n| *n < 2 || n % 2 == 1) {
            return Some(format!("moves per period {:?}: each an even number ≥ 2", self.steps));
        }
        if !positive(&self.angles_rad) || !positive(&self.rates_rad_per_s) {
            return Some("move angles and rates must be positive".into());
        }
        if self.dwells_s.is_empty() || self.dwells_s.iter().any(|d| !(d.is_finite() && *d >= 0.0)) {
            return Some("dwells must be ≥ 0 s".into());
        }
        if !(self.accel_rad_per_s2.is_finite() && self.accel_rad_per_s2 >= 0.0) {
            return Some("the acceleration must be ≥ 0".into());
        }
        let smallest = self.angles_rad.iter().copied().fold(f64::INFINITY, f64::min);
        if self.max_wrap_rad.is_nan() || self.max_wrap_rad < smallest * (1.0 - 1e-12) {
            return Some(format!(
                "a wrap of {:.1}° is less than the smallest move, {:.1}°",
                self.max_wrap_rad.to_degrees(),
                smallest.to_degrees()
            ));
        }
        None
    }
}

/// Picks one element.
fn pick<T: Copy>(v: &[T], rng: &mut impl Rng) -> T {
    v[rng.random_range(0..v.len())]
}

/// A direction (±1) that keeps an axis at `pos` (in moves of its size) within `wrap` and, when
/// `left` moves of this axis remain after it, able to return to 0.
fn direction(pos: i64, wrap: i64, left: Option<i64>, rng: &mut impl Rng) -> i64 {
    let ok = |d: i64| (pos + d).abs() <= wrap && left.is_none_or(|r| (pos + d).abs() <= r);
    match (ok(1), ok(-1)) {
        (true, true) if rng.random_bool(0.5) => 1,
        (true, false) => 1,
        // One always fits: |pos| ≤ min(wrap, left + 1) by construction.
        _ => -1,
    }
}

/// One random candidate (see the module doc). The constraints must have no [`Constraints::problem`].
#[must_use]
pub fn candidate(c: &Constraints, rng: &mut impl Rng) -> Vec<IndexedStep> {
    let n = pick(&c.steps, rng);
    let angle = pick(&c.angles_rad, rng);
    let rate = pick(&c.rates_rad_per_s, rng);
    let dwell = pick(&c.dwells_s, rng);
    // Moves of this size an axis may be away from its start.
    let wrap = ((c.max_wrap_rad / angle) * (1.0 + 1e-12)).floor() as i64;
    let step = |axis: usize, d: i64| IndexedStep {
        axis,
        angle_rad: angle * d as f64,
        rate_rad_per_s: rate,
        dwell_s: dwell,
        accel_rad_per_s2: c.accel_rad_per_s2,
    };
    let mut pos = vec![0i64; c.axes.iter().max().map_or(0, |m| m + 1)];
    if rng.random_bool(0.5) {
        // A free half, then its mirror.
        let mut half: Vec<IndexedStep> = (0..n / 2)
            .map(|_| {
                let axis = pick(&c.axes, rng);
                let d = direction(pos[axis], wrap, None, rng);
                pos[axis] += d;
                step(axis, d)
            })
            .collect();
        let mirror: Vec<IndexedStep> =
            half.iter().rev().map(|s| IndexedStep { angle_rad: -s.angle_rad, ..*s }).collect();
        half.extend(mirror);
        return half;
    }
    // Free: every axis an even number of moves (pairs of slots dealt to axes, shuffled), each axis
    // a walk that stays within the wrap and comes back.
    let mut order: Vec<usize> = (0..n / 2).flat_map(|_| [pick(&c.axes, rng); 2]).collect();
    for i in (1..order.len()).rev() {
        order.swap(i, rng.random_range(0..=i));
    }
    let mut left = vec![0i64; pos.len()];
    for a in &order {
        left[*a] += 1;
    }
    order
        .into_iter()
        .map(|axis| {
            left[axis] -= 1;
            let d = direction(pos[axis], wrap, Some(left[axis]), rng);
            pos[axis] += d;
            step(axis, d)
        })
        .collect()
}

/// True when no axis of `steps` goes further than `c.max_wrap_rad` from its start.
fn within_wrap(steps: &[IndexedStep], c: &Constraints) -> bool {
    let mut at = [0.0f64; super::scheme::MAX_AXES];
    steps.iter().all(|m| {
        at[m.axis] += m.angle_rad;
        at[m.axis].abs() <= c.max_wrap_rad * (1.0 + 1e-12)
    })
}

/// A neighbour of `steps` for a local search: two neighbouring moves of different axes exchanged
/// (each axis keeps its own walk), one axis's moves all reversed (its walk mirrored; the wrap is
/// symmetric), or two moves of one axis exchanged where its walk stays within the wrap. Whatever
/// `steps` satisfies of [`candidate`]'s rules, the neighbour does too.
#[must_use]
pub fn neighbour(steps: &[IndexedStep], c: &Constraints, rng: &mut impl Rng) -> Vec<IndexedStep> {
    let mut s = steps.to_vec();
    let n = s.len();
    if n < 2 {
        return s;
    }
    match rng.random_range(0..3) {
        0 => {
            let i = rng.random_range(0..n - 1);
            if s[i].axis != s[i + 1].axis {
                s.swap(i, i + 1);
            }
        }
        1 => {
            let axis = s[rng.random_range(0..n)].axis;
            for m in s.iter_mut().filter(|m| m.axis == axis) {
                m.angle_rad = -m.angle_rad;
            }
        }
        _ => {
            let (i, j) = (rng.random_range(0..n), rng.random_range(0..n));
            if s[i].axis == s[j].axis {
                s.swap(i, j);
                if !within_wrap(&s, c) {
                    s.swap(i, j);
                }
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::*;

    fn constraints(axes: Vec<usize>, steps: Vec<usize>, wrap_deg: f64) -> Constraints {
        Constraints {
            axes,
            steps,
            angles_rad: vec![90f64.to_radians(), 180f64.to_radians()],
            rates_rad_per_s: vec![0.1, 0.2],
            dwells_s: vec![10.0, 60.0],
            accel_rad_per_s2: 0.0,
            max_wrap_rad: wrap_deg.to_radians(),
        }
    }

    #[test]
    fn every_candidate_returns_and_stays_within_its_wrap() {
        // 2000 draws over two axes and lengths 2-32: every axis's moves sum to zero and its
        // cumulative angle never leaves ±wrap; both families (mirrored and free) appear.
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for wrap in [180.0, 360.0, 720.0] {
            let c = constraints(vec![0, 1], vec![2, 4, 8, 16, 32], wrap);
            assert_eq!(c.problem(), None);
            let mut mirrored = 0;
            for _ in 0..2000 {
                let s = candidate(&c, &mut rng);
                assert!(c.steps.contains(&s.len()));
                let mut at = [0.0f64; 2];
                for m in &s {
                    at[m.axis] += m.angle_rad;
                    assert!(at[m.axis].abs() <= c.max_wrap_rad + 1e-9, "{s:?}");
                }
                assert!(at.iter().all(|a| a.abs() < 1e-9), "{s:?}");
                let n = s.len();
                mirrored += usize::from(
                    (0..n / 2).all(|i| s[i].axis == s[n - 1 - i].axis && s[i].angle_rad == -s[n - 1 - i].angle_rad),
                );
            }
            assert!((600..=1400).contains(&mirrored), "{mirrored} of 2000 mirrored");
        }
    }

    #[test]
    fn a_neighbour_keeps_every_rule() {
        // 20 000 steps of a random walk through neighbours from drawn candidates: every axis still
        // returns and stays within its wrap; the walk moves (most neighbours differ).
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let c = constraints(vec![0, 1], vec![8, 16, 32], 360.0);
        let mut changed = 0;
        for _ in 0..200 {
            let mut s = candidate(&c, &mut rng);
            for _ in 0..100 {
                let next = neighbour(&s, &c, &mut rng);
                changed += usize::from(next != s);
                s = next;
                assert!(within_wrap(&s, &c), "{s:?}");
                for axis in 0..2 {
                    let net: f64 = s.iter().filter(|m| m.axis == axis).map(|m| m.angle_rad).sum();
                    assert!(net.abs() < 1e-9, "{s:?}");
                }
            }
        }
        assert!(changed > 10_000, "{changed} of 20000 neighbours differ");
    }

    #[test]
    fn a_wrap_below_the_move_or_an_odd_length_is_named() {
        assert!(constraints(vec![0], vec![4], 45.0).problem().unwrap().contains("45.0°"));
        assert!(constraints(vec![0], vec![3], 360.0).problem().unwrap().contains("even"));
        assert!(constraints(vec![], vec![4], 360.0).problem().is_some());
    }
}
