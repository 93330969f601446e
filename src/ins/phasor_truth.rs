//! The phasor truth: exact IMU increments, in closed form, over a piece of motion whose rotations
//! all turn at constant rates (a dwell, a continuous scheme, a cruise, a ramp, pure coning; `model::turning`).
//!
//! With `n_from_s(τ) = L_1(τ) ⋯ L_m(τ)` and `L_k = R(a_k, φ_k + ω_k τ)` or constant, the sensor
//! frame's rate and specific force at a fixed site are
//!
//! ```text
//! ω_is^s(τ) = C_n^s ω_ie^n + Σ_k ω_k (L_{k+1} ⋯ L_m)ᵀ a_k,     f^s(τ) = C_n^s (−g^n),
//! ```
//!
//! and `R(a, φ)ᵀ x = (a·x) a + ½ e^{iφ} (x⊥ + i a×x) + ½ e^{−iφ} (x⊥ − i a×x)` (Rodrigues with
//! cos φ, sin φ written as exponentials). Carrying the two constant vectors through the chain link by
//! link therefore gives both signals as finite trigonometric sums `Re Σ_ν c_ν e^{iντ}` whose
//! frequencies ν are sums of the link rates, and each sum integrates exactly:
//!
//! ```text
//! ∫_{τ_m − h/2}^{τ_m + h/2} Re(c e^{iντ}) dτ = Re(c e^{iν τ_m}) · 2 sin(νh/2)/ν.
//! ```
//!
//! Per IMU sample only the phasors `e^{iν τ_m}` change: they advance by the constant `e^{iνh}`
//! (renormalised, re-anchored from sin/cos every [`REANCHOR`] samples and whenever the interval
//! changes), so a sample costs a few multiplications per frequency and no trigonometry.

use nalgebra::Vector3;

use crate::model::turning::Link;

/// A complex 3-vector `re + i·im`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct CVec {
    re: Vector3<f64>,
    im: Vector3<f64>,
}

impl CVec {
    fn real(re: Vector3<f64>) -> Self {
        Self { re, im: Vector3::zeros() }
    }

    /// `self · (zr + i zi)`.
    fn times(&self, zr: f64, zi: f64) -> Self {
        Self { re: self.re * zr - self.im * zi, im: self.re * zi + self.im * zr }
    }

    fn add(&mut self, o: &Self) {
        self.re += o.re;
        self.im += o.im;
    }

    /// `R(a, φ)ᵀ` applied to `self · e^{iντ}` with φ = φ0 + ωτ: the terms at ν, ν + ω and ν − ω.
    fn turned_back(&self, axis: &Vector3<f64>, phase_rad: f64) -> [Self; 3] {
        let along = |v: &Vector3<f64>| axis * axis.dot(v);
        let (pr, pi) = (along(&self.re), along(&self.im));
        let perp = Self { re: self.re - pr, im: self.im - pi };
        // i·(a × x) for complex x = re + i im: −a × im + i a × re.
        let cross_i = Self { re: -axis.cross(&self.im), im: axis.cross(&self.re) };
        let (s, c) = phase_rad.sin_cos();
        let mut plus = perp;
        plus.add(&cross_i);
        let mut minus = perp;
        minus.add(&Self { re: -cross_i.re, im: -cross_i.im });
        [Self { re: pr, im: pi }, plus.times(0.5 * c, 0.5 * s), minus.times(0.5 * c, -0.5 * s)]
    }
}

/// One frequency of the two signals, and its phasor at the current sample.
#[derive(Debug, Clone, Copy)]
struct Term {
    /// ν, rad/s (> 0).
    nu: f64,
    /// Coefficient of ω_is^s.
    omega: CVec,
    /// Coefficient of f^s.
    f: CVec,
    /// e^{iν τ_m} at the current sample's midpoint.
    z: (f64, f64),
    /// e^{iν h}.
    step: (f64, f64),
    /// 2 sin(νh/2)/ν and its derivative in h, cos(νh/2).
    weight: f64,
    weight_dh: f64,
}

/// More frequencies than this and the quadrature is cheaper.
pub const MAX_TERMS: usize = 24;

/// Samples between re-anchorings of the phasors from sin/cos (the stepped phasors drift by ~1 ulp
/// per step in phase: at most ~3e-14 rad after this many).
pub const REANCHOR: u32 = 128;

/// The closed form of one piece of motion.
#[derive(Debug, Clone)]
pub struct PhasorTruth {
    /// The instant τ = 0, s.
    t_anchor_s: f64,
    /// The constant (ν = 0) parts of ω_is^s and f^s.
    omega0: Vector3<f64>,
    f0: Vector3<f64>,
    terms: Vec<Term>,
    /// Interval of the stepped phasors, s (NaN: not anchored).
    h_s: f64,
    /// Midpoint τ the next regular sample will have.
    tau_next: f64,
    since_anchor: u32,
}

/// Sorts by frequency and merges terms whose frequencies agree to rounding.
fn merge(terms: &mut Terms, tol: f64) {
    terms.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<(f64, CVec, CVec)> = Vec::with_capacity(terms.len());
    for t in terms.drain(..) {
        match out.last_mut() {
            Some(last) if (t.0 - last.0).abs() <= tol => {
                last.1.add(&t.1);
                last.2.add(&t.2);
            }
            _ => out.push(t),
        }
    }
    *terms = out;
}

type Terms = Vec<(f64, CVec, CVec)>;

/// Applies `R(axis, φ0 + ωτ)ᵀ` to every term; None when the sums grow past what pays.
fn turn_back(terms: &mut Terms, axis: &Vector3<f64>, phase_rad: f64, rate_rad_per_s: f64, tol: f64) -> Option<()> {
    let mut next = Vec::with_capacity(3 * terms.len() + 2);
    for (nu, w, f) in terms.iter() {
        let (w3, f3) = (w.turned_back(axis, phase_rad), f.turned_back(axis, phase_rad));
        for (j, d) in [0.0, rate_rad_per_s, -rate_rad_per_s].into_iter().enumerate() {
            next.push((nu + d, w3[j], f3[j]));
        }
    }
    merge(&mut next, tol);
    *terms = next;
    (terms.len() <= 2 * MAX_TERMS + 1).then_some(())
}

/// Applies the constant `qᵀ` to every term.
fn rotate_back(terms: &mut Terms, q: &nalgebra::UnitQuaternion<f64>) {
    let back = q.inverse();
    for (_, w, f) in terms.iter_mut() {
        *w = CVec { re: back * w.re, im: back * w.im };
        *f = CVec { re: back * f.re, im: back * f.im };
    }
}

impl PhasorTruth {
    /// The closed form of `n_from_s = L_1 ⋯ L_m` (`links`, τ counted from `t_anchor_s`) at a site with
    /// Earth rate `omega_ie_n` and specific force `f_n` (the reaction to gravity). None when the
    /// chain has more than [`MAX_TERMS`] frequencies.
    #[must_use]
    pub fn new(links: &[Link], omega_ie_n: Vector3<f64>, f_n: Vector3<f64>, t_anchor_s: f64) -> Option<Self> {
        // A cone turns its vectors through two links of rate ±Ω.
        let rate_sum: f64 = links
            .iter()
            .map(|l| l.rate_rad_per_s().abs() * if matches!(l, Link::Cone { .. }) { 2.0 } else { 1.0 })
            .sum();
        // Frequencies are sums of the rates in different orders: equal to a few ulps.
        let tol = 8.0 * f64::EPSILON * rate_sum;
        let mut terms = vec![(0.0, CVec::real(omega_ie_n), CVec::real(f_n))];
        for link in links {
            match *link {
                Link::Turning { axis, angle_rad, rate_rad_per_s } if rate_rad_per_s != 0.0 => {
                    turn_back(&mut terms, &axis, angle_rad, rate_rad_per_s, tol)?;
                    // The link's own rate, in its child frame (the axis is the same on both sides).
                    terms.push((0.0, CVec::real(axis * rate_rad_per_s), CVec::real(Vector3::zeros())));
                }
                Link::Cone { half_angle_rad, phase_rad, rate_rad_per_s } if rate_rad_per_s != 0.0 => {
                    // Kᵀ = Rz(φ)ᵀ... applied link by link: Rz(φ), Rx(α), Rz(−φ).
                    turn_back(&mut terms, &Vector3::z(), phase_rad, rate_rad_per_s, tol)?;
                    rotate_back(
                        &mut terms,
                        &nalgebra::UnitQuaternion::from_axis_angle(&Vector3::x_axis(), half_angle_rad),
                    );
                    turn_back(&mut terms, &Vector3::z(), -phase_rad, -rate_rad_per_s, tol)?;
                    // Its own rate, exact: Ω(−sin α sin φ, sin α cos φ, −2 sin²(α/2)) =
                    // Re(Ω sin α e^{iφ0} (i, 1, 0) e^{iΩτ}) + (0, 0, −2Ω sin²(α/2)).
                    let (w, (sa, sh)) = (rate_rad_per_s, (half_angle_rad.sin(), (0.5 * half_angle_rad).sin()));
                    let (s0, c0) = phase_rad.sin_cos();
                    let spin =
                        CVec { re: Vector3::new(-s0, c0, 0.0) * (w * sa), im: Vector3::new(c0, s0, 0.0) * (w * sa) };
                    terms.push((w, spin, CVec::real(Vector3::zeros())));
                    terms.push((
                        0.0,
                        CVec::real(Vector3::new(0.0, 0.0, -2.0 * w * sh * sh)),
                        CVec::real(Vector3::zeros()),
                    ));
                }
                _ => rotate_back(&mut terms, &link.rotation(0.0)),
            }
            merge(&mut terms, tol);
        }
        // Re(c e^{−iντ}) = Re(c̄ e^{iντ}): one term per |ν|.
        for (nu, w, f) in &mut terms {
            if *nu < 0.0 {
                *nu = -*nu;
                w.im = -w.im;
                f.im = -f.im;
            }
        }
        merge(&mut terms, tol);
        let (mut omega0, mut f0) = (Vector3::zeros(), Vector3::zeros());
        let mut out = Vec::new();
        for (nu, w, f) in terms {
            if nu <= tol {
                omega0 += w.re;
                f0 += f.re;
            } else {
                out.push(Term { nu, omega: w, f, z: (1.0, 0.0), step: (1.0, 0.0), weight: 0.0, weight_dh: 0.0 });
            }
        }
        (out.len() <= MAX_TERMS).then_some(Self {
            t_anchor_s,
            omega0,
            f0,
            terms: out,
            h_s: f64::NAN,
            tau_next: f64::NAN,
            since_anchor: 0,
        })
    }

    /// Number of frequencies (ν > 0).
    #[must_use]
    pub fn frequencies(&self) -> usize {
        self.terms.len()
    }

    /// ω_is^s and f^s at `t_s` (the sums evaluated directly).
    #[must_use]
    pub fn at(&self, t_s: f64) -> (Vector3<f64>, Vector3<f64>) {
        let tau = t_s - self.t_anchor_s;
        let (mut w, mut f) = (self.omega0, self.f0);
        for t in &self.terms {
            let (s, c) = (t.nu * tau).sin_cos();
            w += t.omega.re * c - t.omega.im * s;
            f += t.f.re * c - t.f.im * s;
        }
        (w, f)
    }

    /// The exact increments (Δθ_s, Δv_s) over [`t0_s`, `t1_s`] (within the piece).
    pub fn increments(&mut self, t0_s: f64, t1_s: f64) -> (Vector3<f64>, Vector3<f64>) {
        let h = t1_s - t0_s;
        let tau = 0.5 * (t0_s + t1_s) - self.t_anchor_s;
        // The caller's times carry rounding of ~ulp(t) (t = i·h): intervals and midpoints that differ
        // from the stepped ones by that much are still regular.
        let slack = 1e-8 * self.h_s + 16.0 * f64::EPSILON * t1_s.abs();
        let regular =
            self.since_anchor < REANCHOR && (h - self.h_s).abs() <= slack && (tau - self.tau_next).abs() <= slack;
        let (mut dtheta, mut dv) = (self.omega0 * h, self.f0 * h);
        if regular {
            // The interval and the midpoint differ from the stepped ones by that rounding: the phasor
            // is turned on by ν·δτ (to second order: |νδτ| < 1e-8 leaves < 2e-25) and the weight
            // follows h to first order (the next term, (ν/4)·sin(νh/2)·δh², is below 1e-16·h).
            let (dtau, dh) = (tau - self.tau_next, h - self.h_s);
            for t in &mut self.terms {
                let (zr, zi) = (t.z.0 * t.step.0 - t.z.1 * t.step.1, t.z.0 * t.step.1 + t.z.1 * t.step.0);
                let x = t.nu * dtau;
                let (cr, ci) = (1.0 - 0.5 * x * x, x);
                let (zr, zi) = (zr * cr - zi * ci, zr * ci + zi * cr);
                let norm = 1.5 - 0.5 * (zr * zr + zi * zi);
                t.z = (zr * norm, zi * norm);
                let weight = t.weight + t.weight_dh * dh;
                dtheta += (t.omega.re * t.z.0 - t.omega.im * t.z.1) * weight;
                dv += (t.f.re * t.z.0 - t.f.im * t.z.1) * weight;
            }
            self.since_anchor += 1;
        } else {
            self.h_s = h;
            for t in &mut self.terms {
                let (s, c) = (t.nu * tau).sin_cos();
                t.z = (c, s);
                let (s, c) = (t.nu * h).sin_cos();
                t.step = (c, s);
                let (s, c) = (0.5 * t.nu * h).sin_cos();
                t.weight = 2.0 * s / t.nu;
                t.weight_dh = c;
                dtheta += (t.omega.re * t.z.0 - t.omega.im * t.z.1) * t.weight;
                dv += (t.f.re * t.z.0 - t.f.im * t.z.1) * t.weight;
            }
            self.since_anchor = 0;
        }
        self.tau_next = tau + self.h_s;
        (dtheta, dv)
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use crate::ins::truth::TruthImu;
    use crate::math::attitude::Attitude;
    use crate::model::earth::{Earth, Site};
    use crate::model::gimbal::{AxisGeometry, Chain, TableErrors};
    use crate::model::motion::{AngleKind, Coning, Ramp, VehicleMotion};
    use crate::model::scheme::Scheme;
    use crate::sim::{Model, TableParams};

    /// Gauss-Legendre nodes and weights on [−1, 1] (Newton on P_n from the Chebyshev guesses).
    fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
        (0..n)
            .map(|i| {
                let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
                let mut dp = 1.0;
                for _ in 0..100 {
                    let (mut p0, mut p1) = (1.0, x);
                    for k in 2..=n {
                        let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                        p0 = p1;
                        p1 = p2;
                    }
                    dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                    let dx = p1 / dp;
                    x -= dx;
                    if dx.abs() < 1e-17 {
                        break;
                    }
                }
                (x, 2.0 / ((1.0 - x * x) * dp * dp))
            })
            .collect()
    }

    /// The independent computation: 16-point Gauss-Legendre of the truth's own rates (`eval`: the
    /// model's rotations and their rates from trigonometry at each node) on panels over which the
    /// fastest frequency turns at most 0.1 rad (error ~0.1³²/…: nothing).
    fn quadrature(imu: &mut TruthImu, t0: f64, t1: f64, max_nu: f64) -> (Vector3<f64>, Vector3<f64>) {
        let gl = gauss_legendre(16);
        let panels = ((max_nu * (t1 - t0) / 0.1).ceil() as usize).max(1);
        let hp = (t1 - t0) / panels as f64;
        let (mut g, mut a) = (Vector3::zeros(), Vector3::zeros());
        for p in 0..panels {
            let mid = t0 + (p as f64 + 0.5) * hp;
            for (x, w) in &gl {
                let point = imu.eval(mid + 0.5 * hp * x);
                g += point.omega_is_s * (0.5 * hp * w);
                a += point.f_s * (0.5 * hp * w);
            }
        }
        (g, a)
    }

    /// A random table (1-3 axes, every error), scheme of constant rates, vehicle with Euler ramps in
    /// progress and a cone, at a random site; and the fastest frequency of the motion.
    fn random_case(rng: &mut ChaCha8Rng) -> (Model, Earth, f64) {
        let n_axes = rng.random_range(1..=3usize);
        let first = rng.random_range(0..3usize);
        let unit = [Vector3::x(), Vector3::y(), Vector3::z()];
        let axes = (0..n_axes).map(|k| AxisGeometry::new(format!("a{k}"), unit[(first + k) % 3], 0.0)).collect();
        let small = |rng: &mut ChaCha8Rng, s: f64| {
            Vector3::new(rng.random_range(-s..s), rng.random_range(-s..s), rng.random_range(-s..s))
        };
        let mut truth = TableErrors::zero(n_axes);
        truth.installation_rad = small(rng, 1e-3);
        truth.imu_mount_rad = small(rng, 1e-3);
        for (k, e) in truth.axes.iter_mut().enumerate() {
            e.swing_half_angle_rad = rng.random_range(0.0..1e-3);
            e.swing_phase_rad = rng.random_range(-3.0..3.0);
            e.non_orthogonality_rad = if k > 0 { rng.random_range(-1e-4..1e-4) } else { 0.0 };
        }
        let rates: Vec<f64> =
            (0..n_axes).map(|_| if rng.random_bool(0.3) { 0.0 } else { rng.random_range(-1.5..1.5) }).collect();
        let initial: Vec<f64> = (0..n_axes).map(|_| rng.random_range(-3.0..3.0)).collect();
        let base = Attitude {
            pitch_rad: rng.random_range(-1.0..1.0),
            roll_rad: rng.random_range(-3.0..3.0),
            heading_rad: rng.random_range(-3.0..3.0),
        };
        // Ramps from t = −1 s, far enough not to end before t = 14 s.
        let mut ramps = Vec::new();
        for angle in [AngleKind::Pitch, AngleKind::Roll, AngleKind::Heading] {
            if rng.random_bool(0.25) {
                // Pitch: at least 0.3 rad to go at up to 0.02 rad/s, the others 17 rad at 0.15 rad/s.
                let (target_rad, fastest) = if angle == AngleKind::Pitch { (1.3, 0.02) } else { (20.0, 0.15) };
                ramps.push(Ramp { angle, start_s: -1.0, target_rad, rate_rad_per_s: rng.random_range(0.005..fastest) });
            }
        }
        let mut vehicle = VehicleMotion::new(base, ramps, vec![]).expect("ramps of different angles");
        let mut max_nu = 4.0 * rates.iter().fold(0.0f64, |m, r| m.max(r.abs())) + 1.0;
        if rng.random_bool(0.7) {
            let coning =
                Coning { half_angle_rad: rng.random_range(1e-4..0.2), omega_rad_per_s: rng.random_range(-40.0..40.0) };
            max_nu += 2.0 * coning.omega_rad_per_s.abs();
            vehicle = vehicle.with_coning(coning);
        }
        let chain = Chain::new(axes);
        let table = TableParams {
            chain,
            vehicle,
            scheme: Scheme::continuous(initial, rates),
            truth,
            compensation: TableErrors::zero(n_axes),
        };
        let site = Site {
            latitude_rad: rng.random_range(-1.5..1.5),
            longitude_rad: 0.0,
            height_m: rng.random_range(0.0..3000.0),
        };
        (Model::new(&table, 0), Earth::at(site), max_nu)
    }

    fn relative(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
        (a - b).norm() / b.norm()
    }

    #[test]
    fn the_closed_form_equals_a_high_order_quadrature_of_the_rates() {
        // 200 random motions, one interval each (anchored phasors) of 0.1-20 ms at 0-0.3 s (early: the
        // phases stay small, so that neither side loses digits to the rounding of ν·t).
        let mut rng = ChaCha8Rng::seed_from_u64(13);
        let (mut worst_g, mut worst_a) = (0.0f64, 0.0f64);
        let mut closed = 0;
        for _ in 0..200 {
            let (model, earth, max_nu) = random_case(&mut rng);
            let t0 = rng.random_range(0.0..0.3);
            let h = rng.random_range(1e-4..2e-2);
            let mut imu = TruthImu::new(model, earth, t0);
            if !imu.is_phasor_truth() {
                continue;
            }
            closed += 1;
            let (g, a) = imu.increments(t0 + h);
            let (g_ref, a_ref) = quadrature(&mut imu, t0, t0 + h, max_nu);
            worst_g = worst_g.max(relative(&g, &g_ref));
            worst_a = worst_a.max(relative(&a, &a_ref));
        }
        // The rest have too many frequencies (up to three shafts, three ramps and a cone) and use the
        // quadrature.
        assert!(closed > 100, "{closed} of 200 in closed form");
        assert!(worst_g < 3e-15 && worst_a < 3e-15, "relative differences: Δθ {worst_g:e}, Δv {worst_a:e}");
    }

    #[test]
    fn stepped_phasors_stay_exact_over_many_samples() {
        // 20 random motions, 600 consecutive samples at t = i·h from 1 s on (the rounding of i·h moves
        // each interval by an ulp; the phasors are re-anchored every 128 samples), against the same
        // closed form anchored at every sample (sin/cos of ν·τ each time) and against the quadrature
        // of the rates. The phases ν·τ reach ~500 rad here, and each side carries its own rounding of
        // them (ulp(500) = 1.1e-13): measured 1.5e-14 and 2.0e-14 relative.
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let (mut worst_anchored, mut worst_quadrature) = (0.0f64, 0.0f64);
        let mut closed = 0;
        for _ in 0..20 {
            let (model, earth, max_nu) = random_case(&mut rng);
            let h = 1.0 / [100.0, 200.0, 2000.0][rng.random_range(0..3usize)];
            let i0 = (1.0 / h) as u64;
            let mut imu = TruthImu::new(model, earth, i0 as f64 * h);
            let Some(anchored) = imu.phasor_truth(i0 as f64 * h, f64::INFINITY) else { continue };
            closed += 1;
            let mut reference = imu.clone();
            for i in i0 + 1..i0 + 600 {
                let (t0, t1) = ((i - 1) as f64 * h, i as f64 * h);
                let (g, a) = imu.increments(t1);
                let (g_anc, a_anc) = anchored.clone().increments(t0, t1);
                let (g_ref, a_ref) = quadrature(&mut reference, t0, t1, max_nu);
                worst_anchored = worst_anchored.max(relative(&g, &g_anc)).max(relative(&a, &a_anc));
                worst_quadrature = worst_quadrature.max(relative(&g, &g_ref)).max(relative(&a, &a_ref));
            }
        }
        assert!(closed > 10, "{closed} of 20 in closed form");
        assert!(worst_anchored < 4e-14, "stepped vs anchored: {worst_anchored:e} ({closed} motions)");
        assert!(worst_quadrature < 5e-14, "stepped vs quadrature: {worst_quadrature:e} ({closed} motions)");
    }
}
