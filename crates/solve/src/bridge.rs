//! Continuation of the index-1 accelerations through a singular configuration
//! (docs/singular.md, "Bridging the acceleration").
//!
//! Near a configuration where `Phi_q` loses rank, the Schur complement
//! `S = Phi_q M^-1 Phi_q^T` has eigenvalues `mu_j` far below the others. In the eigenbasis
//! `u_j` of `S` the multipliers are `lambda_j = u_j^T r / mu_j` (`r = Phi_q M^-1 Q - gamma`),
//! and they move the accelerations along `g_j = M^-1 Phi_q^T u_j`, whose mass norm is
//! `sqrt(mu_j)`. A state that is off the constraints by `delta` (a Newton tolerance, a
//! projection's rounding, the offset of a Runge-Kutta stage) carries an error of about
//! `delta |v|` into `u_j^T r`, so the acceleration along `g_j` is wrong by about
//! `delta |v| / sqrt(mu_j)` per unit of `g_j`: by `0.07` in the measured case of a coupler's
//! angular acceleration that is exactly 0 along the motion. The error lies in the directions
//! in which the mechanism would leave its branch (the other branch's motion), and the
//! projection after the step turns part of it into a velocity error along the branch: a kick
//! that stops the run's error falling with `h`, since more stages land close to the singular
//! point as `h` falls.
//!
//! Along the motion the accelerations are a smooth function of time through the singular
//! configuration (only the algebraic description degenerates). [`SingularBridge`] keeps the
//! accelerations at the starts of the last [`BRIDGE_POINTS`] accepted steps; at a stage whose
//! solve has a condition estimate above [`BRIDGE_CONDITION`] it computes the eigenpairs of `S`
//! ([`mbd_linalg::symmetric_eigen`]) and replaces, for every `mu_j` below
//! `mu_max / BRIDGE_CONDITION`, the component of the solved acceleration along `g_j` (in the
//! mass inner product, in which the `g_j` are orthogonal) by that of the cubic extrapolation of
//! the recorded accelerations, and moves `lambda` along `u_j` by the same amount: the other
//! components, which the solve determines well, stay as solved. The replaced component of a
//! stage slope differs from the exact one by the extrapolation's `O(h^4)` and the stage's own
//! `O(h^2)` offset from the motion, so a bridged stage adds `O(h^3)` to its step's error, at
//! the few stages per passage that fall inside the window.

use crate::sparse::SparseAccelerationSolver;
use crate::AccelerationSolver;
use mbd_linalg::symmetric_eigen;
use mbd_model::System;

/// Accepted step starts the extrapolation runs through (a cubic).
pub const BRIDGE_POINTS: usize = 4;

/// How many times the condition estimate of `S` at a stage must exceed the smallest one of
/// the last [`BRIDGE_MEMORY`] accepted step starts (the mechanism's own conditioning, badly
/// scaled parts included) for the stage's near-null directions to be bridged: those whose
/// eigenvalue lies below the largest divided by this factor times that baseline.
pub const BRIDGE_CONDITION: f64 = 1e3;

/// How many times the extrapolation's own error estimate (the change from the quadratic
/// through the last three points to the cubic through all four) the solved component along a
/// near-null direction must be away from the extrapolation's for the extrapolation to replace
/// it.
pub const BRIDGE_DISAGREEMENT: f64 = 3.0;

/// Accepted step starts over which the baseline condition of [`BRIDGE_CONDITION`] is the
/// smallest: long enough to reach back before a passage's approach at small steps (64 steps
/// of 1e-4 s are 0.3 rad of the N-four-bar's crank at 6 rad/s), short enough to follow a
/// mechanism whose conditioning changes over its motion.
pub const BRIDGE_MEMORY: usize = 64;

/// The margin of [`SingularBridge::leaves_alone`]: the condition estimate of a solve near
/// the point in question must lie this factor below the bridge's threshold.
pub const BRIDGE_QUIET: f64 = 10.0;

/// Most constraints for which the bridge works (it forms `S` densely, `O(m^3)` per bridged
/// stage); larger models are solved as they are.
pub const BRIDGE_MAX_CONSTRAINTS: usize = 400;

/// The constraint-row products of an acceleration solver's last solve, through which
/// [`SingularBridge`] forms `S` and the directions `g_j`.
pub trait ConstraintRows {
    /// `out = Phi_q x` (`x`: n, `out`: m).
    fn rows_times(&self, x: &[f64], out: &mut [f64]);
    /// `out = M^-1 Phi_q^T y` (`y`: m, `out`: n); `false` when the solver does not hold
    /// `Phi_q` in rows (models with spatial bodies, whose internal constraints it eliminates).
    fn weighted_transpose(&self, sys: &System, y: &[f64], out: &mut [f64]) -> bool;
}

impl ConstraintRows for AccelerationSolver {
    fn rows_times(&self, x: &[f64], out: &mut [f64]) {
        self.schur_rows().times(x, out);
    }
    fn weighted_transpose(&self, _sys: &System, y: &[f64], out: &mut [f64]) -> bool {
        if self.has_body_blocks() {
            return false;
        }
        // the last solve factored S with W = M^-1: out = -(0 - M^-1 Phi_q^T y)
        out.fill(0.0);
        self.schur_rows().sub_weighted_transpose(y, out);
        for x in out.iter_mut() {
            *x = -*x;
        }
        true
    }
}

impl ConstraintRows for SparseAccelerationSolver {
    fn rows_times(&self, x: &[f64], out: &mut [f64]) {
        if let Some(s) = self.schur() {
            s.apply(x, out);
        }
    }
    fn weighted_transpose(&self, sys: &System, y: &[f64], out: &mut [f64]) -> bool {
        let Some(s) = self.schur() else {
            return false;
        };
        out.fill(0.0);
        s.add_weighted_transpose(1.0, sys.inv_mass_diag().as_slice(), y, out);
        true
    }
}

/// The accelerations and multipliers at the last accepted step starts of one solver, and the
/// bridge of its stage accelerations through singular configurations (see the module
/// documentation). Allocates when built; every method is allocation-free.
///
/// A solver calls [`SingularBridge::begin`] at the start of each step,
/// [`SingularBridge::correct`] after each stage's acceleration solve,
/// [`SingularBridge::hold`] with the (corrected) acceleration of the stage at the step's
/// start, and [`SingularBridge::accept`] once the step is accepted
/// ([`SingularBridge::retry_from`] after a rejected adaptive attempt).
#[derive(Clone, Debug)]
pub struct SingularBridge {
    n: usize,
    m: usize,
    /// Times and accelerations (`BRIDGE_POINTS x n`) of the recorded points, a ring: `len` of
    /// them valid, the next one goes to slot `head` (the oldest, once the ring is full).
    t: [f64; BRIDGE_POINTS],
    a: Vec<f64>,
    len: usize,
    head: usize,
    /// The start of the step in progress (its time, condition estimate and acceleration),
    /// recorded when the step is accepted: the step's own stages extrapolate from the points
    /// before it.
    pending: bool,
    pending_t: f64,
    pending_cond: f64,
    pending_a: Vec<f64>,
    /// The condition estimates of the last [`BRIDGE_MEMORY`] accepted step starts (a ring;
    /// `ring_len` of them valid).
    ring: [f64; BRIDGE_MEMORY],
    ring_len: usize,
    ring_pos: usize,
    /// The end time and positions of the last accepted step: the next step continues the
    /// recorded motion only if it starts there.
    end_t: f64,
    end_q: Vec<f64>,
    /// Scratch: the extrapolation (`n`), `S` and its eigenvectors (`m x m`, empty above
    /// [`BRIDGE_MAX_CONSTRAINTS`]), a direction `g` (`n`), a unit vector (`m`).
    ext: Vec<f64>,
    ext_err: Vec<f64>,
    s: Vec<f64>,
    vecs: Vec<f64>,
    g: Vec<f64>,
    e: Vec<f64>,
    /// Stages bridged since the bridge was built.
    bridged: usize,
}

impl SingularBridge {
    /// A bridge for `sys` (inactive above [`BRIDGE_MAX_CONSTRAINTS`] constraints).
    pub fn new(sys: &System) -> Self {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let mm = if m <= BRIDGE_MAX_CONSTRAINTS { m } else { 0 };
        SingularBridge {
            n,
            m,
            t: [f64::NAN; BRIDGE_POINTS],
            a: vec![0.0; BRIDGE_POINTS * n],
            len: 0,
            head: 0,
            pending: false,
            pending_t: f64::NAN,
            pending_cond: 1.0,
            pending_a: vec![0.0; n],
            ring: [1.0; BRIDGE_MEMORY],
            ring_len: 0,
            ring_pos: 0,
            end_t: f64::NAN,
            end_q: vec![0.0; n],
            ext: vec![0.0; n],
            ext_err: vec![0.0; n],
            s: vec![0.0; mm * mm],
            vecs: vec![0.0; mm * mm],
            g: vec![0.0; n],
            e: vec![0.0; mm],
            bridged: 0,
        }
    }

    /// Starts a step from `(t, q)`: the history is forgotten unless the step continues the
    /// last accepted one (same time to rounding, the same positions bit for bit).
    #[inline]
    pub fn begin(&mut self, t: f64, q: &[f64]) {
        self.pending = false;
        // (a run loop may set the time to its grid value, a few units in the last place off)
        let same_t = (t - self.end_t).abs() <= 64.0 * f64::EPSILON * t.abs().max(1.0);
        if !(same_t && q == self.end_q.as_slice()) {
            self.len = 0;
            self.ring_len = 0;
        }
    }

    /// Keeps the acceleration of the stage at the step's start (time `t`) and the condition
    /// estimate of its solve, to be recorded if the step is accepted.
    #[inline]
    pub fn hold(&mut self, t: f64, condition: f64, a: &[f64]) {
        self.pending_t = t;
        self.pending_cond = condition;
        self.pending_a.copy_from_slice(&a[..self.n]);
        self.pending = true;
    }

    /// Sets the condition estimate held with the step start's accelerations when their solve
    /// gave none (a solver that took them from another factorisation holds them with the
    /// condition of its next stage solve, at a nearby point).
    #[inline]
    pub fn hold_condition(&mut self, condition: f64) {
        self.pending_cond = condition;
    }

    /// Whether a stage solve with the condition estimate `condition` lies a factor
    /// [`BRIDGE_QUIET`] below the threshold at which [`SingularBridge::correct`] would replace
    /// a component of its accelerations (or the bridge has too few points to replace any): a
    /// solver may then take the accelerations of a nearby point from a factorisation that
    /// gives no estimate.
    pub fn leaves_alone(&self, condition: f64) -> bool {
        if self.len < BRIDGE_POINTS || condition * BRIDGE_QUIET <= BRIDGE_CONDITION {
            return true;
        }
        condition * BRIDGE_QUIET <= BRIDGE_CONDITION * self.baseline()
    }

    /// The mechanism's own conditioning: the smallest condition estimate of the recorded step
    /// starts (the last [`BRIDGE_MEMORY`]), at least 1.
    fn baseline(&self) -> f64 {
        self.ring[..self.ring_len]
            .iter()
            .fold(f64::INFINITY, |b, &c| b.min(c))
            .max(1.0)
    }

    /// Records the held point of a step accepted with end time `t_end` and positions `q_end`.
    #[inline]
    pub fn accept(&mut self, t_end: f64, q_end: &[f64]) {
        if self.pending {
            let (n, k) = (self.n, self.head);
            self.t[k] = self.pending_t;
            self.a[k * n..(k + 1) * n].copy_from_slice(&self.pending_a);
            self.head = (k + 1) % BRIDGE_POINTS;
            self.len = (self.len + 1).min(BRIDGE_POINTS);
            self.ring[self.ring_pos] = self.pending_cond;
            self.ring_pos = (self.ring_pos + 1) % BRIDGE_MEMORY;
            self.ring_len = (self.ring_len + 1).min(BRIDGE_MEMORY);
            self.pending = false;
        }
        self.end_t = t_end;
        self.end_q.copy_from_slice(&q_end[..self.n]);
    }

    /// After a rejected adaptive attempt from `(t, q)`: nothing is recorded, and the retry
    /// continues the history from there.
    #[inline]
    pub fn retry_from(&mut self, t: f64, q: &[f64]) {
        self.pending = false;
        self.end_t = t;
        self.end_q.copy_from_slice(&q[..self.n]);
    }

    /// Forgets the history.
    pub fn clear(&mut self) {
        self.len = 0;
        self.head = 0;
        self.ring_len = 0;
        self.pending = false;
        self.end_t = f64::NAN;
    }

    /// Stages bridged since the bridge was built.
    pub fn bridged(&self) -> usize {
        self.bridged
    }

    /// Bridges a stage at time `t` whose solve by `rows` left the accelerations `a` (n) and
    /// multipliers `lambda` (m) with condition estimate `condition` (see the module
    /// documentation). Does nothing (returns `false`) unless `condition` exceeds
    /// [`BRIDGE_CONDITION`] times the smallest condition estimate of the last
    /// [`BRIDGE_MEMORY`] accepted step starts; nor before [`BRIDGE_POINTS`] accepted steps,
    /// above [`BRIDGE_MAX_CONSTRAINTS`] constraints, or when `rows` holds no rows. Returns
    /// whether it changed `a`.
    #[inline]
    pub fn correct(
        &mut self,
        rows: &dyn ConstraintRows,
        sys: &System,
        t: f64,
        condition: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> bool {
        if condition <= BRIDGE_CONDITION || self.len < BRIDGE_POINTS {
            return false;
        }
        self.correct_near_null(rows, sys, t, condition, a, lambda)
    }

    /// [`SingularBridge::correct`] past its cheap tests.
    #[inline(never)]
    fn correct_near_null(
        &mut self,
        rows: &dyn ConstraintRows,
        sys: &System,
        t: f64,
        condition: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> bool {
        let (n, m) = (self.n, self.m);
        let factor = BRIDGE_CONDITION * self.baseline();
        if condition <= factor || m == 0 || self.s.len() != m * m {
            return false;
        }
        // S = Phi_q M^-1 Phi_q^T, column by column
        for j in 0..m {
            self.e.fill(0.0);
            self.e[j] = 1.0;
            if !rows.weighted_transpose(sys, &self.e, &mut self.g) {
                return false;
            }
            rows.rows_times(&self.g, &mut self.s[j * m..(j + 1) * m]);
        }
        // (the two triangles agree to rounding; the mean keeps the matrix exactly symmetric)
        for c in 0..m {
            for r in c + 1..m {
                let x = 0.5 * (self.s[r + c * m] + self.s[c + r * m]);
                self.s[r + c * m] = x;
                self.s[c + r * m] = x;
            }
        }
        symmetric_eigen(&mut self.s, &mut self.vecs, m);
        let mu_max = (0..m).map(|j| self.s[j + j * m]).fold(0.0f64, f64::max);
        if !(mu_max > 0.0) {
            return false;
        }
        self.extrapolate(t);
        let mass = sys.mass_diag().as_slice();
        let mut changed = false;
        for j in 0..m {
            if !(self.s[j + j * m] < mu_max / factor) {
                continue;
            }
            let u = &self.vecs[j * m..(j + 1) * m];
            rows.weighted_transpose(sys, u, &mut self.g);
            // the component along g in the mass inner product
            let (mut num, mut den, mut est) = (0.0, 0.0, 0.0);
            for i in 0..n {
                let g = self.g[i];
                num += mass[i] * g * (a[i] - self.ext[i]);
                den += mass[i] * g * g;
                est += mass[i] * g * self.ext_err[i];
            }
            if !(den > 0.0) {
                continue;
            }
            let c = num / den;
            // kept as solved unless the solve is off the extrapolation by more than the
            // extrapolation's own error estimate allows (at large steps near a passage the
            // cubic is the worse of the two)
            if !(c.abs() > BRIDGE_DISAGREEMENT * (est / den).abs()) {
                continue;
            }
            // a = M^-1 (Q - Phi_q^T lambda): lambda + c u moves a by -c g
            for i in 0..n {
                a[i] -= c * self.g[i];
            }
            for (l, &ur) in lambda.iter_mut().zip(u) {
                *l += c * ur;
            }
            changed = true;
        }
        self.bridged += usize::from(changed);
        changed
    }

    /// The cubic through the recorded accelerations at `t`, into `ext`, and its change from
    /// the quadratic through the last three, into `ext_err` (the cubic's error estimate).
    fn extrapolate(&mut self, t: f64) {
        let n = self.n;
        // oldest first: the full ring starts at `head`
        let slot = |k: usize| (self.head + k) % BRIDGE_POINTS;
        let ts: [f64; BRIDGE_POINTS] = std::array::from_fn(|k| self.t[slot(k)]);
        self.ext.fill(0.0);
        self.ext_err.fill(0.0);
        for k in 0..BRIDGE_POINTS {
            let (mut w, mut w2) = (1.0, 1.0);
            for j in 0..BRIDGE_POINTS {
                if j != k {
                    w *= (t - ts[j]) / (ts[k] - ts[j]);
                    if j > 0 {
                        w2 *= (t - ts[j]) / (ts[k] - ts[j]);
                    }
                }
            }
            let w2 = if k == 0 { 0.0 } else { w2 };
            let sk = slot(k);
            for ((x, e), y) in self
                .ext
                .iter_mut()
                .zip(self.ext_err.iter_mut())
                .zip(&self.a[sk * n..(sk + 1) * n])
            {
                *x += w * y;
                *e += (w - w2) * y;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mbd_model::models;

    /// Two rows on a pendulum's three coordinates, nearly dependent: the second is the first
    /// turned by `eps` in the plane of its first two columns.
    struct Rows {
        phi_q: [[f64; 3]; 2],
    }

    impl Rows {
        fn new(eps: f64) -> Self {
            Rows {
                phi_q: [[1.0, 0.0, 0.5], [eps.cos(), eps.sin(), 0.5]],
            }
        }
    }

    impl ConstraintRows for Rows {
        fn rows_times(&self, x: &[f64], out: &mut [f64]) {
            for (o, r) in out.iter_mut().zip(&self.phi_q) {
                *o = r.iter().zip(x).map(|(a, b)| a * b).sum();
            }
        }
        fn weighted_transpose(&self, sys: &System, y: &[f64], out: &mut [f64]) -> bool {
            let minv = sys.inv_mass_diag();
            for (k, o) in out.iter_mut().enumerate() {
                *o = minv[k] * (self.phi_q[0][k] * y[0] + self.phi_q[1][k] * y[1]);
            }
            true
        }
    }

    /// Four accepted steps of size 0.1 whose start accelerations are `f(t)` (a cubic), at a
    /// condition of 10.
    fn filled(sys: &System, f: impl Fn(f64) -> [f64; 3]) -> SingularBridge {
        let mut b = SingularBridge::new(sys);
        let q = [0.0; 3];
        for k in 0..BRIDGE_POINTS {
            let t = 0.1 * k as f64;
            b.begin(t, &q);
            b.hold(t, 10.0, &f(t));
            b.accept(t + 0.1, &q);
        }
        b
    }

    fn cubic(t: f64) -> [f64; 3] {
        [1.0 + t - 2.0 * t * t, -3.0 * t * t * t, 0.5 + t]
    }

    #[test]
    fn only_the_near_null_component_is_replaced_and_the_multipliers_follow() {
        let sys = models::pendulum(1.0, 2.0, 0.1, 9.81).unwrap();
        let rows = Rows::new(1e-4);
        let mut b = filled(&sys, cubic);
        // a solved acceleration off the extrapolation along every direction
        let t = 0.45;
        let want = cubic(t);
        let mut a = [want[0] + 0.3, want[1] - 0.2, want[2] + 0.1];
        let mut lambda = [1.0, -1.0];
        let (a0, l0) = (a, lambda);
        assert!(b.correct(&rows, &sys, t, 1e9, &mut a, &mut lambda));
        assert_eq!(b.bridged(), 1);
        // the change is a constraint force: a - a0 = -M^-1 Phi_q^T (lambda - l0)
        let mut force = [0.0; 3];
        rows.weighted_transpose(&sys, &[lambda[0] - l0[0], lambda[1] - l0[1]], &mut force);
        for k in 0..3 {
            assert!((a[k] - a0[k] + force[k]).abs() < 1e-9, "coordinate {k}");
        }
        // the near-null direction g = M^-1 Phi_q^T u (u ~ (1, -1) / sqrt 2) now agrees with
        // the extrapolation; the well-determined one (u ~ (1, 1)) is as solved
        let m = sys.mass_diag();
        let along = |u: [f64; 2], x: &[f64; 3]| {
            let mut g = [0.0; 3];
            rows.weighted_transpose(&sys, &u, &mut g);
            let gg: f64 = (0..3).map(|k| m[k] * g[k] * g[k]).sum();
            (0..3).map(|k| m[k] * g[k] * x[k]).sum::<f64>() / gg
        };
        let diff = |x: &[f64; 3]| [x[0] - want[0], x[1] - want[1], x[2] - want[2]];
        let (null, well) = ([1.0, -1.0], [1.0, 1.0]);
        assert!(along(null, &diff(&a0)).abs() > 100.0);
        assert!(
            along(null, &diff(&a)).abs() < 1e-6,
            "{}",
            along(null, &diff(&a))
        );
        assert!((along(well, &diff(&a)) - along(well, &diff(&a0))).abs() < 1e-6);
    }

    #[test]
    fn it_acts_only_on_a_sharp_rise_of_the_condition_with_a_history() {
        let sys = models::pendulum(1.0, 2.0, 0.1, 9.81).unwrap();
        let rows = Rows::new(1e-4);
        let t = 0.45;
        let solved = |x: [f64; 3]| [x[0], x[1] + 0.3, x[2]];
        // below the baseline's thousandfold (baseline 10): kept
        let mut b = filled(&sys, cubic);
        let (mut a, mut l) = (solved(cubic(t)), [0.0; 2]);
        assert!(!b.correct(&rows, &sys, t, 9e3, &mut a, &mut l));
        assert_eq!(a, solved(cubic(t)));
        // a solve that agrees with the extrapolation: kept
        let (mut a, mut l) = (cubic(t), [0.0; 2]);
        assert!(!b.correct(&rows, &sys, t, 1e9, &mut a, &mut l));
        // three points only: kept
        let mut short = SingularBridge::new(&sys);
        for k in 0..BRIDGE_POINTS - 1 {
            let tk = 0.1 * k as f64;
            short.begin(tk, &[0.0; 3]);
            short.hold(tk, 10.0, &cubic(tk));
            short.accept(tk + 0.1, &[0.0; 3]);
        }
        let (mut a, mut l) = (solved(cubic(t)), [0.0; 2]);
        assert!(!short.correct(&rows, &sys, t, 1e9, &mut a, &mut l));
        // a step that does not continue the last one (other positions) clears the history;
        // a retried attempt keeps it
        let mut c = filled(&sys, cubic);
        c.retry_from(0.4, &[0.0; 3]);
        c.begin(0.4, &[0.0; 3]);
        let (mut a, mut l) = (solved(cubic(t)), [0.0; 2]);
        assert!(c.correct(&rows, &sys, t, 1e9, &mut a, &mut l));
        c.begin(0.4, &[1.0, 0.0, 0.0]);
        let (mut a, mut l) = (solved(cubic(t)), [0.0; 2]);
        assert!(!c.correct(&rows, &sys, t, 1e9, &mut a, &mut l));
    }

    #[test]
    fn a_badly_conditioned_baseline_raises_the_threshold() {
        let sys = models::pendulum(1.0, 2.0, 0.1, 9.81).unwrap();
        // (mu_min / mu_max about 1e-13: below the threshold of 1e-9 that the baseline sets)
        let rows = Rows::new(1e-6);
        let mut b = SingularBridge::new(&sys);
        for k in 0..BRIDGE_POINTS {
            let t = 0.1 * k as f64;
            b.begin(t, &[0.0; 3]);
            // a mechanism whose own condition estimate is 1e6 at every step
            b.hold(t, 1e6, &cubic(t));
            b.accept(t + 0.1, &[0.0; 3]);
        }
        let t = 0.45;
        let x = cubic(t);
        let (mut a, mut l) = ([x[0], x[1] + 0.3, x[2]], [0.0; 2]);
        assert!(!b.correct(&rows, &sys, t, 1e8, &mut a, &mut l));
        assert!(b.correct(&rows, &sys, t, 1e10, &mut a, &mut l));
    }

    /// `leaves_alone` says yes while the bridge has too few points, and after that exactly up to
    /// `BRIDGE_CONDITION * baseline / BRIDGE_QUIET` (the baseline at least 1); a start held
    /// without a condition estimate is recorded with the one `hold_condition` gives it.
    #[test]
    fn leaves_alone_follows_the_threshold_and_the_held_condition() {
        let sys = models::pendulum(1.0, 2.0, 0.1, 9.81).unwrap();
        let b = SingularBridge::new(&sys);
        assert!(b.leaves_alone(1e12), "no points yet");
        let b = filled(&sys, cubic);
        let limit = BRIDGE_CONDITION * 10.0 / BRIDGE_QUIET;
        assert!(b.leaves_alone(limit));
        assert!(!b.leaves_alone(limit * (1.0 + 1e-12)));
        // a baseline below 1 counts as 1
        let mut b = SingularBridge::new(&sys);
        let q = [0.0; 3];
        for k in 0..BRIDGE_POINTS {
            let t = 0.1 * k as f64;
            b.begin(t, &q);
            b.hold(t, f64::NAN, &cubic(t));
            b.hold_condition(if k == 2 { 0.5 } else { 10.0 });
            b.accept(t + 0.1, &q);
        }
        let limit = BRIDGE_CONDITION / BRIDGE_QUIET;
        assert!(b.leaves_alone(limit));
        assert!(!b.leaves_alone(2.0 * limit));
    }
}
