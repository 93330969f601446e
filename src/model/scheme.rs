//! Rotation schemes as data: gimbal angles and rates as pure functions of time.
//!
//! Continuous rotation at constant rates, or an indexed sequence of (axis, angle, rate, dwell)
//! moves with optional trapezoidal acceleration, repeated. Before t = 0 the table is at rest.

/// At most this many gimbal axes (single-, dual- and three-axis tables).
pub const MAX_AXES: usize = 3;

/// Gimbal angles (or rates) of up to [`MAX_AXES`] axes; unused entries are zero.
pub type AxisValues = [f64; MAX_AXES];

/// One move of an indexed sequence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IndexedStep {
    /// Index of the moving axis in the chain.
    pub axis: usize,
    /// Signed rotation of the move, rad.
    pub angle_rad: f64,
    /// Cruise rate magnitude, rad/s (> 0).
    pub rate_rad_per_s: f64,
    /// Dwell after the move, s.
    pub dwell_s: f64,
    /// Acceleration magnitude, rad/s^2; 0 means the rate steps instantly.
    pub accel_rad_per_s2: f64,
}

/// A move placed in time within one period.
#[derive(Debug, Clone, Copy)]
struct Move {
    /// Start, s from the start of the period.
    t0_s: f64,
    /// Duration, s.
    duration_s: f64,
    /// Angle at the start of the move relative to the axis angle at the start of the period, rad.
    from_rad: f64,
    /// Signed rotation, rad.
    delta_rad: f64,
    rate_rad_per_s: f64,
    accel_rad_per_s2: f64,
}

impl Move {
    /// Distance covered (unsigned) and rate magnitude `tau` seconds into the move.
    fn progress(&self, tau: f64) -> (f64, f64) {
        let d = self.delta_rad.abs();
        let (r, a) = (self.rate_rad_per_s, self.accel_rad_per_s2);
        if tau >= self.duration_s {
            return (d, 0.0);
        }
        if a <= 0.0 {
            return (r * tau, r);
        }
        let t_acc = (r / a).min(0.5 * self.duration_s);
        let peak = a * t_acc;
        if tau < t_acc {
            (0.5 * a * tau * tau, a * tau)
        } else if tau <= self.duration_s - t_acc {
            (0.5 * a * t_acc * t_acc + peak * (tau - t_acc), peak)
        } else {
            let rem = self.duration_s - tau;
            (d - 0.5 * a * rem * rem, a * rem)
        }
    }
}

impl Move {
    /// True when the rate is constant from `tau` on to the move's next bend (or its end).
    fn constant_rate_at(&self, tau: f64) -> bool {
        let a = self.accel_rad_per_s2;
        if a <= 0.0 || tau >= self.duration_s {
            return true;
        }
        let t_acc = (self.rate_rad_per_s / a).min(0.5 * self.duration_s);
        tau >= t_acc && tau < self.duration_s - t_acc
    }
}

fn move_duration(step: &IndexedStep) -> f64 {
    let d = step.angle_rad.abs();
    let (r, a) = (step.rate_rad_per_s, step.accel_rad_per_s2);
    if a <= 0.0 {
        d / r
    } else if d >= r * r / a {
        d / r + r / a
    } else {
        2.0 * (d / a).sqrt()
    }
}

#[derive(Debug, Clone)]
enum Kind {
    Continuous {
        rates: AxisValues,
    },
    Indexed {
        initial_dwell_s: f64,
        period_s: f64,
        repeat: bool,
        net_rad: AxisValues,
        moves: Vec<Vec<Move>>,
        breakpoints: Vec<f64>,
    },
}

/// Gimbal angles over time.
#[derive(Debug, Clone)]
pub struct Scheme {
    n_axes: usize,
    initial: AxisValues,
    kind: Kind,
    steps: Vec<IndexedStep>,
}

fn to_values(v: &[f64]) -> AxisValues {
    let mut out = [0.0; MAX_AXES];
    for (o, x) in out.iter_mut().zip(v) {
        *o = *x;
    }
    out
}

impl Scheme {
    /// Constant rates from `initial` angles (all rates zero: a static table).
    #[must_use]
    pub fn continuous(initial_rad: Vec<f64>, rates_rad_per_s: Vec<f64>) -> Self {
        assert!(initial_rad.len() <= MAX_AXES && initial_rad.len() == rates_rad_per_s.len());
        Self {
            n_axes: initial_rad.len(),
            initial: to_values(&initial_rad),
            kind: Kind::Continuous { rates: to_values(&rates_rad_per_s) },
            steps: Vec::new(),
        }
    }

    /// An indexed sequence: dwell `initial_dwell_s`, then the moves in order, each followed by its dwell.
    #[must_use]
    pub fn indexed(initial_rad: Vec<f64>, initial_dwell_s: f64, steps: Vec<IndexedStep>, repeat: bool) -> Self {
        let n_axes = initial_rad.len();
        assert!(n_axes <= MAX_AXES);
        let mut moves = vec![Vec::new(); n_axes];
        let mut rel = [0.0; MAX_AXES];
        let mut t = 0.0;
        let mut breakpoints = Vec::new();
        for s in &steps {
            let duration_s = move_duration(s);
            // Where the rate jumps or its slope changes: start, end of acceleration, start of braking, end.
            let t_acc = if s.accel_rad_per_s2 > 0.0 {
                (s.rate_rad_per_s / s.accel_rad_per_s2).min(0.5 * duration_s)
            } else {
                0.0
            };
            breakpoints.extend([t, t + t_acc, t + duration_s - t_acc, t + duration_s]);
            moves[s.axis].push(Move {
                t0_s: t,
                duration_s,
                from_rad: rel[s.axis],
                delta_rad: s.angle_rad,
                rate_rad_per_s: s.rate_rad_per_s,
                accel_rad_per_s2: s.accel_rad_per_s2,
            });
            rel[s.axis] += s.angle_rad;
            t += duration_s + s.dwell_s;
        }
        Self {
            n_axes,
            initial: to_values(&initial_rad),
            kind: Kind::Indexed {
                initial_dwell_s,
                period_s: t,
                repeat,
                net_rad: rel,
                moves,
                breakpoints: {
                    breakpoints.sort_by(f64::total_cmp);
                    breakpoints.dedup();
                    breakpoints
                },
            },
            steps,
        }
    }

    /// The same motion started from other initial angles (live mode: a new scheme starts where the
    /// gimbals are).
    #[must_use]
    pub fn with_initial(&self, initial_rad: &AxisValues) -> Self {
        Self { initial: *initial_rad, ..self.clone() }
    }

    /// Number of axes.
    #[must_use]
    pub fn n_axes(&self) -> usize {
        self.n_axes
    }

    /// Largest gimbal rate magnitude, rad/s (the frame rotation frequency it causes).
    #[must_use]
    pub fn max_rate(&self) -> f64 {
        match &self.kind {
            Kind::Continuous { rates } => rates.iter().fold(0.0, |m, r| m.max(r.abs())),
            Kind::Indexed { .. } => self.steps.iter().fold(0.0, |m, s| m.max(s.rate_rad_per_s)),
        }
    }

    /// Length of one indexed sequence, s (0 for continuous schemes).
    #[must_use]
    pub fn period_s(&self) -> f64 {
        match &self.kind {
            Kind::Continuous { .. } => 0.0,
            Kind::Indexed { period_s, .. } => *period_s,
        }
    }

    /// One period of a repeated indexed sequence as (start, length), s: it starts when the initial
    /// dwell ends. None for a continuous scheme or a sequence that runs once.
    #[must_use]
    pub fn period_window(&self) -> Option<(f64, f64)> {
        match &self.kind {
            Kind::Indexed { initial_dwell_s, period_s, repeat: true, .. } if *period_s > 0.0 => {
                Some((*initial_dwell_s, *period_s))
            }
            _ => None,
        }
    }

    /// The indexed moves as configured (empty for continuous schemes).
    #[must_use]
    pub fn steps(&self) -> &[IndexedStep] {
        &self.steps
    }

    /// The times the indexed moves start, s (scheme time), up to `until_s`, at most `limit` of
    /// them; empty for continuous schemes.
    #[must_use]
    pub fn move_starts_s(&self, until_s: f64, limit: usize) -> Vec<f64> {
        let Kind::Indexed { initial_dwell_s, period_s, repeat, moves, .. } = &self.kind else {
            return Vec::new();
        };
        let mut within: Vec<f64> = moves.iter().flatten().map(|m| m.t0_s).collect();
        within.sort_by(f64::total_cmp);
        within.dedup();
        let mut out = Vec::new();
        for cycle in 0.. {
            let start = initial_dwell_s + f64::from(cycle) * period_s;
            if start > until_s || (cycle > 0 && (!*repeat || *period_s <= 0.0)) {
                break;
            }
            for t in within.iter().map(|w| start + w).take_while(|t| *t <= until_s) {
                if out.len() == limit {
                    return out;
                }
                out.push(t);
            }
        }
        out
    }

    /// First time after `t_s` where a gimbal rate jumps or bends (the IMU truth integrates piecewise
    /// between these so that a rate step does not spoil the quadrature).
    #[must_use]
    pub fn next_breakpoint_after(&self, t_s: f64) -> f64 {
        let Kind::Indexed { initial_dwell_s, period_s, repeat, breakpoints, .. } = &self.kind else {
            return if t_s < 0.0 { 0.0 } else { f64::INFINITY };
        };
        let tau = t_s - initial_dwell_s;
        let (cycle_start, within) = if tau < 0.0 {
            (*initial_dwell_s, -1.0)
        } else if *repeat {
            let c = (tau / period_s).floor();
            (initial_dwell_s + c * period_s, tau - c * period_s)
        } else {
            (*initial_dwell_s, tau)
        };
        let j = breakpoints.partition_point(|&b| b <= within);
        match breakpoints.get(j) {
            Some(b) => cycle_start + b,
            None if *repeat => cycle_start + period_s + breakpoints.first().copied().unwrap_or(0.0),
            None => f64::INFINITY,
        }
    }

    /// True when every gimbal turns at a constant rate (or rests) from `t_s` to the next breakpoint:
    /// no move is in its acceleration or braking phase (then the angles are linear in time and the
    /// IMU truth has closed-form increments).
    #[must_use]
    pub fn constant_rates_at(&self, t_s: f64) -> bool {
        let Kind::Indexed { initial_dwell_s, period_s, repeat, moves, .. } = &self.kind else {
            return true;
        };
        let tau = t_s - initial_dwell_s;
        if t_s < 0.0 || tau < 0.0 {
            return true;
        }
        let within = if *repeat {
            tau - (tau / period_s).floor() * period_s
        } else if tau >= *period_s {
            return true;
        } else {
            tau
        };
        moves.iter().take(self.n_axes).all(|list| {
            let j = list.partition_point(|m| m.t0_s <= within);
            j == 0 || list[j - 1].constant_rate_at(within - list[j - 1].t0_s)
        })
    }

    /// True gimbal angles and rates at `t_s`.
    #[must_use]
    #[inline]
    pub fn state(&self, t_s: f64) -> (AxisValues, AxisValues) {
        let mut angle = self.initial;
        let mut rate = [0.0; MAX_AXES];
        // At rest before t = 0; from t = 0 on the rates are the right-hand limits.
        if t_s < 0.0 {
            return (angle, rate);
        }
        match &self.kind {
            Kind::Continuous { rates } => {
                for ((a, r), w) in angle.iter_mut().zip(&mut rate).zip(rates).take(self.n_axes) {
                    *a += w * t_s;
                    *r = *w;
                }
            }
            Kind::Indexed { initial_dwell_s, period_s, repeat, net_rad, moves, .. } => {
                let tau = t_s - initial_dwell_s;
                if tau < 0.0 {
                    return (angle, rate);
                }
                let (cycles, within) = if *repeat {
                    let c = (tau / period_s).floor();
                    (c, tau - c * period_s)
                } else if tau >= *period_s {
                    (1.0, 0.0)
                } else {
                    (0.0, tau)
                };
                for k in 0..self.n_axes {
                    angle[k] += cycles * net_rad[k];
                    let list = &moves[k];
                    // Last move of this axis that started at or before `within`.
                    let j = list.partition_point(|m| m.t0_s <= within);
                    if j == 0 {
                        continue;
                    }
                    let m = &list[j - 1];
                    let (dist, speed) = m.progress(within - m.t0_s);
                    let sign = m.delta_rad.signum();
                    angle[k] += m.from_rad + sign * dist;
                    rate[k] = sign * speed;
                }
            }
        }
        (angle, rate)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::units::RAD_PER_DEG;

    /// The rotary-table paper section 5: 0/90/180/270 deg, 10 deg/s, 290 s dwell, back to 0 (docs/schemes.md).
    fn four_position() -> Scheme {
        let step = |deg: f64| IndexedStep {
            axis: 0,
            angle_rad: deg * RAD_PER_DEG,
            rate_rad_per_s: 10.0 * RAD_PER_DEG,
            dwell_s: 290.0,
            accel_rad_per_s2: 0.0,
        };
        Scheme::indexed(vec![0.0], 290.0, vec![step(90.0), step(90.0), step(90.0), step(-270.0)], true)
    }

    #[test]
    fn four_position_scheme_visits_its_positions() {
        let s = four_position();
        let deg = |t| s.state(t).0[0] / RAD_PER_DEG;
        // Period: 4 dwells of 290 s + (90+90+90+270) deg at 10 deg/s = 1160 + 54 = 1214 s.
        assert!((s.period_s() - 1214.0).abs() < 1e-9, "{}", s.period_s());
        assert!(deg(100.0).abs() < 1e-9);
        assert!((deg(294.5) - 45.0).abs() < 1e-9); // halfway through the first move
        assert!((deg(400.0) - 90.0).abs() < 1e-9);
        assert!((deg(700.0) - 180.0).abs() < 1e-9);
        assert!((deg(1000.0) - 270.0).abs() < 1e-9);
        // The return move starts at 290 + 3*(9+290) = 1187 s and lasts 27 s.
        assert!((deg(1187.0 + 13.5) - 135.0).abs() < 1e-9);
        assert!(deg(1300.0).abs() < 1e-9);
        // Next period: same positions shifted by 1214 s.
        assert!((deg(400.0 + 1214.0) - 90.0).abs() < 1e-9);
    }

    #[test]
    fn move_starts_are_where_the_table_starts_turning() {
        // The hand-computed starts of the four-position sequence (290 s dwell, then 9, 9, 9, 27 s
        // moves with 290 s dwells): 290, 589, 888, 1187, then + 1214 s.
        let s = four_position();
        let starts = s.move_starts_s(2500.0, 100);
        let expected = [290.0, 589.0, 888.0, 1187.0, 1504.0, 1803.0, 2102.0, 2401.0];
        assert_eq!(starts.len(), expected.len(), "{starts:?}");
        for (t, e) in starts.iter().zip(expected) {
            assert!((t - e).abs() < 1e-9, "{t} vs {e}");
            // At rest just before, turning just after.
            assert!(s.state(t - 1e-3).1[0].abs() < 1e-12 && s.state(t + 1e-3).1[0].abs() > 0.0, "{t}");
        }
        assert_eq!(s.move_starts_s(2500.0, 3).len(), 3, "the limit holds");
        assert!(Scheme::continuous(vec![0.0], vec![0.1]).move_starts_s(100.0, 10).is_empty());
    }

    #[test]
    fn breakpoints_are_the_move_boundaries() {
        let s = four_position();
        // Moves start at 290, 589, 888 and 1187 s; they last 9, 9, 9 and 27 s.
        assert!((s.next_breakpoint_after(0.0) - 290.0).abs() < 1e-9);
        assert!((s.next_breakpoint_after(290.0) - 299.0).abs() < 1e-9);
        assert!((s.next_breakpoint_after(300.0) - 589.0).abs() < 1e-9);
        assert!((s.next_breakpoint_after(1190.0) - 1214.0).abs() < 1e-9);
        // Next period: 290 + 1214.
        assert!((s.next_breakpoint_after(1214.5) - (290.0 + 1214.0)).abs() < 1e-9);
    }

    #[test]
    fn trapezoid_reaches_the_target_with_continuous_rate() {
        let step = IndexedStep { axis: 0, angle_rad: 1.0, rate_rad_per_s: 0.2, dwell_s: 1.0, accel_rad_per_s2: 0.1 };
        let s = Scheme::indexed(vec![0.0], 0.0, vec![step], false);
        // d = 1 rad >= r^2/a = 0.4: trapezoid of duration d/r + r/a = 5 + 2 = 7 s.
        assert!((s.period_s() - 8.0).abs() < 1e-12);
        let (a_end, r_end) = s.state(7.0 + 1e-9);
        assert!((a_end[0] - 1.0).abs() < 1e-9 && r_end[0].abs() < 1e-9);
        // Numerical derivative of the angle equals the reported rate everywhere.
        for t in [0.5, 1.9, 2.1, 4.0, 5.5, 6.9] {
            let h = 1e-6;
            let d = (s.state(t + h).0[0] - s.state(t - h).0[0]) / (2.0 * h);
            assert!((d - s.state(t).1[0]).abs() < 1e-6, "t={t}: {d} vs {}", s.state(t).1[0]);
        }
    }

    #[test]
    fn continuous_rotation_and_rest_before_start() {
        let s = Scheme::continuous(vec![0.1, 0.2], vec![0.5, -0.25]);
        let (a, r) = s.state(2.0);
        assert!((a[0] - 1.1).abs() < 1e-15 && (a[1] + 0.3).abs() < 1e-15);
        assert!((r[0] - 0.5).abs() < 1e-15);
        let (a, r) = s.state(-1.0);
        assert!((a[0] - 0.1).abs() < 1e-15 && r[0] == 0.0);
    }
}
