//! The chord Newton iteration of the chart maps: the iteration matrix (centre, interpolated,
//! Broyden), the plain and Broyden iterations, and the travel bound.

use super::{ChartFailure, MapStats, NewtonSettings, TangentChart, ROUNDOFF_FACTOR, TRAVEL_FACTOR};

/// Factor on the largest contraction factor the chord iteration showed at the current and the
/// previous chart, for the estimate the stage maps stop on after their first correction: the
/// factor scales with the distance of the point from the centre, which changes little from one
/// step to the next at a fixed step size.
const THETA_PRIOR_SAFETY: f64 = 2.0;
use crate::kernels::{dot, gemv_cols, gemv_t_cols, rank_one_update, with_codim};
use mbd_model::System;
use mbd_solve::linalg::{max_abs, max_abs_diff, solve_rt};

impl TangentChart {
    /// Evaluates `Df` at a second point `x_e` (typically the Euler prediction `x_c + h F(x_c)` of
    /// the step's end point) and stores `E = (Df(x_e) - Df(x_c)) Q1`, so that
    /// [`TangentChart::select_iteration_matrix`] can interpolate the Newton matrix along the
    /// step; `t_e` is its time. A non-finite `Df(x_e)` leaves the chart with the centre matrix
    /// `R^T` only.
    pub fn set_secondary_point(&mut self, sys: &System, x_e: &[f64], t_e: f64) {
        let (n, m) = (self.n, self.m);
        let (nn, mm) = (2 * n, 2 * m);
        self.has_e = false;
        self.s = 0.0;
        if m == 0 || x_e.len() != nn || !self.centred {
            return;
        }
        self.form_p0();
        self.sel.jacobian(
            sys,
            &x_e[..n],
            None,
            &x_e[n..],
            t_e,
            &mut self.pq_e,
            &mut self.dphi_e,
            false,
        );
        // Delta Df = [[dP, 0], [dX, dP]] with dP = Phi_q(e) - Phi_q(c), dX likewise
        self.pq_e -= &self.phi_q;
        self.dphi_e -= &self.dphi;
        // the chart's velocity coordinates are tau v: dX enters weighted (as X at the centre)
        if self.vs != 1.0 {
            self.dphi_e *= self.vs;
        }
        // column k of E: (dP cq, dX cq + dP cv) for Q1_k = (cq, cv); dP, dX column-major m x n
        let (dp, dx) = (self.pq_e.as_slice(), self.dphi_e.as_slice());
        self.e.fill(0.0);
        for k in 0..mm {
            let col = &self.q[k * nn..(k + 1) * nn];
            let (cq, cv) = col.split_at(n);
            let (ep, ev) = self.e[k * mm..(k + 1) * mm].split_at_mut(m);
            gemv_cols(dp, cq, ep);
            gemv_cols(dx, cq, ev);
            gemv_cols(dp, cv, ev);
        }
        if !self.e.iter().all(|x| x.is_finite()) {
            return;
        }
        // K = E R^-T: column k = sum_{j >= k} (R^-1)_{kj} E_j
        self.k.fill(0.0);
        for k in 0..mm {
            for j in k..mm {
                self.u[j] = self.rinv[j * mm + k];
            }
            gemv_cols(
                &self.e[k * mm..],
                &self.u[k..mm],
                &mut self.k[k * mm..(k + 1) * mm],
            );
        }
        self.has_e = true;
    }

    /// Chooses the matrix `J` of the chord iteration for the next maps: `R^T = Df(x_c) Q1` if
    /// `s` is 0 or no secondary point is set, else `J_s = R^T + s E`, the linear interpolation of
    /// `Df Q1` between the centre (`s = 0`) and the secondary point (`s = 1`); for a stage at
    /// `t_c + c h` pass `s = c`. With `K = E R^-T`, `J_s = (I + s K) R^T`, and the iteration
    /// applies `J_s^-1 = R^-T (I + s K)^-1` through the expansion
    /// `(I + s K)^-1 ~ I - s K + s^2 K^2` (`|s K| = O(h)`, so the neglected `O(h^3)` is below the
    /// `O(h^2)` interpolation error): `x <- x - P0 (f - s K f + s^2 K K f)` with `P0 = Q1 R^-T`
    /// formed once per chart and `K` once per step. Whatever the matrix, the iteration converges
    /// to the same point of the chart: the matrix only sets its speed.
    pub fn select_iteration_matrix(&mut self, s: f64) {
        self.s = if self.has_e && s.is_finite() { s } else { 0.0 };
    }

    /// Turns the quasi-Newton (good Broyden) chord iteration on or off (off by default). On,
    /// the iteration keeps an approximation `H` of `(Df(x) Q1)^-1`, starts each chart from the
    /// centre's `R^-T`, and after each correction `s = x_(k+1) - x_k` with residual change
    /// `y = f_(k+1) - f_k` applies the Sherman-Morrison rank-one update
    /// `H <- H + (s - H y) s^T H / (s^T H y)` (in the ambient space: on `P = Q1 H`, `O(n m)` per
    /// iteration). The updated matrix carries over from one map to the next until the chart is
    /// re-centred: the stage points of a step are close, so later maps start with a matrix that
    /// has already learnt how `Df` changed along the step. An update whose denominator is small
    /// (`|s^T H y| <= 0.1 |s|^2`) is skipped; an iteration that does not reduce the residual
    /// with an updated matrix is undone and restarted from `R^-T`. Only the speed changes: the
    /// limit is the same chart point. Ignored while an interpolated matrix
    /// ([`TangentChart::select_iteration_matrix`] with `s != 0`) is selected.
    pub fn set_broyden(&mut self, on: bool) {
        self.broyden = on;
        self.pb_active = false;
    }

    /// Broyden updates applied, and resets of the updated matrix to the centre's `R^-T` after
    /// an iteration without progress, since the chart was created (diagnostics).
    pub fn broyden_counts(&self) -> (usize, usize) {
        (self.broyden_updates, self.broyden_resets)
    }

    /// The chord iteration from `x`; on success `zeta = Q1^T (x - x_c)`.
    pub(super) fn run_chord(
        &mut self,
        sys: &System,
        t: f64,
        zeta: &mut [f64],
        x: &mut [f64],
        newton: &NewtonSettings,
        predicted: bool,
    ) -> Result<MapStats, ChartFailure> {
        if self.m == 0 {
            return Ok(MapStats::default());
        }
        let nn = 2 * self.n;
        let mut f = std::mem::take(&mut self.f);
        // sin/cos are rotated from the last evaluation (the previous iterate, or the last point
        // of the previous map: the stage points of a step lie close together), evaluated
        // exactly after a larger move or BodyAngles::MAX_ROTATIONS rotations
        self.x0.copy_from_slice(x);
        let res = self.residual_cached(sys, x, t, &mut f);
        let res_start = res;
        self.first_step = 0.0;
        // the plain chord iteration updates zeta along with x; the others leave it to the
        // projection below
        let mut zeta_done = false;
        let mut out = if self.broyden && self.s == 0.0 {
            self.chord_broyden(sys, t, x, newton, &mut f, res, predicted)
        } else if self.s == 0.0 {
            zeta_done = true;
            self.chord_centre(sys, t, x, zeta, newton, &mut f, res, predicted)
        } else {
            self.chord(sys, t, x, newton, &mut f, res, predicted)
        };
        if let Ok(ms) = out {
            // a chord iteration that converged far from where it started (relative to its
            // first correction) did not contract on the way: near a singular configuration it
            // can drift along the nearly singular direction onto another branch
            if !self.travel_ok(x, &self.x0, ms.iterations) {
                out = Err(ChartFailure {
                    t,
                    residual: ms.residual,
                    iterations: ms.iterations,
                });
            }
        }
        if let Err(failure) = out {
            zeta_done = false;
            // whatever the failure taught the matrix is suspect
            self.pb_active = false;
            if newton.fallback_change > 0.0 {
                let failure_iterations = failure.iterations;
                x.copy_from_slice(&self.x0);
                out = self.exact_newton(sys, t, x, newton, &mut f, failure, res_start);
                if let Ok(ms) = out {
                    // the same bound on the travel from the exact iteration's start
                    let exact_iterations = ms.iterations - failure_iterations;
                    if !self.travel_ok(x, &self.wx, exact_iterations) {
                        out = Err(ChartFailure {
                            t,
                            residual: ms.residual,
                            iterations: ms.iterations,
                        });
                    }
                }
            }
        }
        self.f = f;
        if out.is_ok() && !zeta_done {
            self.form_q();
            for ((d, xv), xc) in self.dx.iter_mut().zip(x.iter()).zip(&self.xc) {
                *d = xv - xc;
            }
            let mm = 2 * self.m;
            gemv_t_cols(&self.q[..mm * nn], &self.dx, &mut zeta[..mm]);
        }
        out
    }

    /// Whether an iteration that ended at `x` from `start` travelled at most [`TRAVEL_FACTOR`]
    /// times its first correction ([`TangentChart::first_step`]), up to rounding. A
    /// contracting iteration (factor `theta`) travels at most `1 / (1 - theta)` times its first
    /// correction and its limit is the solution nearest to the start; one that travelled
    /// further wandered, and near a singular configuration it may have reached another branch.
    pub(super) fn travel_ok(&self, x: &[f64], start: &[f64], iterations: usize) -> bool {
        if iterations <= 1 {
            // the travel is the first correction
            return true;
        }
        travel_within(x, start, self.first_step)
    }

    /// The chord iteration with the centre's matrix, `x <- x - Q1 R^-T f`, on `x` from its
    /// residual `f`: each correction solves `R^T u = f` (forward substitution, `1 / R_ii`
    /// stored) and moves `x` by `-Q1 u` and the normal coordinates `zeta` by `-u`, so that
    /// `zeta` stays `Q1^T (x - x_c)` without a projection at the end and `Q1 R^-T` need not be
    /// formed per chart.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn chord_centre(
        &mut self,
        sys: &System,
        t: f64,
        x: &mut [f64],
        zeta: &mut [f64],
        newton: &NewtonSettings,
        f: &mut [f64],
        res0: f64,
        predicted: bool,
    ) -> Result<MapStats, ChartFailure> {
        let (nn, mm) = (2 * self.n, 2 * self.m);
        let mut lp = ChordLoop::new(t, res0, newton, predicted);
        lp.theta_prior = self.theta_prior;
        let floor = self.floor;
        loop {
            if let Some(verdict) = lp.head() {
                return verdict;
            }
            if lp.it == 1 {
                // a second correction: the first one's size bounds the travel (`travel_ok`;
                // a map that stops after one needs no bound)
                self.first_step = max_abs_diff(x, &self.x0);
            }
            with_codim!(mm, solve_rt(&self.a, nn, &self.rdinv, f, &mut self.u));
            for (w, (z, u)) in self.w.iter_mut().zip(zeta.iter_mut().zip(&self.u)) {
                *w = -u;
                *z -= u;
            }
            self.add_q1_w(x);
            if let Some(ms) = lp.corrected() {
                return Ok(ms);
            }
            let res = self.residual_cached(sys, x, t, f);
            let stop = lp.evaluated(res, || self.roundoff.stall_cap(x, newton.tol, self.vinv));
            if let Some(theta) = lp.observed_theta(floor) {
                self.theta_seen = fast_max(self.theta_seen, theta);
            }
            if let Some(ms) = stop {
                return Ok(ms);
            }
            if let Some(e) = lp.diverged() {
                return Err(e);
            }
        }
    }

    /// Enables the predicted stop after the first correction of the stage maps (see
    /// [`TangentChart::map_predicted`]) with the contraction factors the chord iteration
    /// showed at this chart and the previous one, or disables it (`follows = false`: the last
    /// step had another size, or there was none, so its contraction says little).
    pub fn set_contraction_prior(&mut self, follows: bool) {
        let seen = fast_max(self.theta_seen, self.theta_seen_prev);
        self.theta_prior = if follows && seen > 0.0 {
            THETA_PRIOR_SAFETY * seen
        } else {
            f64::INFINITY
        };
    }

    /// The chord iteration on `x` from its residual `f`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn chord(
        &mut self,
        sys: &System,
        t: f64,
        x: &mut [f64],
        newton: &NewtonSettings,
        f: &mut [f64],
        res0: f64,
        predicted: bool,
    ) -> Result<MapStats, ChartFailure> {
        let s = self.s;
        let mut lp = ChordLoop::new(t, res0, newton, predicted);
        loop {
            if let Some(verdict) = lp.head() {
                return verdict;
            }
            // x <- x - Q1 J^-1 f = x - P0 (I + s K)^-1 f
            if s != 0.0 {
                // u = K f, f <- f - s u + s^2 K u
                self.u.fill(0.0);
                gemv_cols(&self.k, f, &mut self.u);
                let s2 = s * s;
                for ((fi, ui), wi) in f.iter_mut().zip(&self.u).zip(self.w.iter_mut()) {
                    *fi -= s * ui;
                    *wi = s2 * ui;
                }
                gemv_cols(&self.k, &self.w, f);
            }
            if lp.it == 1 {
                // as in `chord_centre`: the first correction's size, before a second
                self.first_step = max_abs_diff(x, &self.x0);
            }
            // f is overwritten by the next residual: negate it in place
            for fk in f.iter_mut() {
                *fk = -*fk;
            }
            gemv_cols(&self.p0, f, x);
            if let Some(ms) = lp.corrected() {
                return Ok(ms);
            }
            let res = self.residual_cached(sys, x, t, f);
            if let Some(ms) =
                lp.evaluated(res, || self.roundoff.stall_cap(x, newton.tol, self.vinv))
            {
                return Ok(ms);
            }
            if let Some(e) = lp.diverged() {
                return Err(e);
            }
        }
    }

    /// The chord iteration on `x` from its residual `f` with good Broyden updates of its matrix
    /// (see [`TangentChart::set_broyden`]); stopping rules as [`TangentChart::map`] and
    /// [`TangentChart::map_predicted`].
    #[allow(clippy::too_many_arguments)]
    pub(super) fn chord_broyden(
        &mut self,
        sys: &System,
        t: f64,
        x: &mut [f64],
        newton: &NewtonSettings,
        f: &mut [f64],
        res0: f64,
        predicted: bool,
    ) -> Result<MapStats, ChartFailure> {
        let tol = newton.tol;
        self.form_p0();
        let mut lp = ChordLoop::new(t, res0, newton, predicted);
        // whether `wx` holds `Q1 H f` for the current `f` and `H`
        let mut have_w = false;
        loop {
            if let Some(verdict) = lp.head() {
                return verdict;
            }
            if !have_w {
                let p = if self.pb_active { &self.pb } else { &self.p0 };
                self.wx.fill(0.0);
                gemv_cols(p, f, &mut self.wx);
            }
            // x <- x - Q1 H f
            for ((xi, si), wi) in x.iter_mut().zip(self.step.iter_mut()).zip(&self.wx) {
                *si = -wi;
                *xi -= wi;
            }
            if lp.it == 0 {
                self.first_step = max_abs(&self.wx);
            }
            if let Some(ms) = lp.corrected() {
                return Ok(ms);
            }
            self.fprev.copy_from_slice(f);
            let res = self.residual_cached(sys, x, t, f);
            if let Some(ms) =
                lp.evaluated(res, || self.roundoff.stall_cap(x, newton.tol, self.vinv))
            {
                return Ok(ms);
            }
            if self.pb_active && (lp.res.is_nan() || lp.res >= lp.prev) {
                // the updated matrix made no progress: undo the step, restart from R^-T
                for (xi, si) in x.iter_mut().zip(&self.step) {
                    *xi -= si;
                }
                f.copy_from_slice(&self.fprev);
                lp.res = lp.prev;
                lp.prev = f64::INFINITY;
                self.pb_active = false;
                self.broyden_resets += 1;
                have_w = false;
                continue;
            }
            if let Some(e) = lp.diverged() {
                return Err(e);
            }
            if lp.res <= tol {
                continue;
            }
            // w = Q1 H f_(k+1); with s = step: H y = w + s, so the good Broyden update is
            // H <- H - w (s^T H) / (s^T w + s^T s) and the next step is -w |s|^2 / den
            {
                let p = if self.pb_active { &self.pb } else { &self.p0 };
                self.wx.fill(0.0);
                gemv_cols(p, f, &mut self.wx);
            }
            have_w = true;
            let ss = dot(&self.step, &self.step);
            let den = dot(&self.step, &self.wx) + ss;
            if den.is_finite() && den.abs() > 0.1 * ss && ss > 0.0 {
                if !self.pb_active {
                    self.pb.copy_from_slice(&self.p0);
                    self.pb_active = true;
                }
                let inv = 1.0 / den;
                rank_one_update(&mut self.pb, &self.step, &self.wx, inv);
                let g = ss * inv;
                for w in self.wx.iter_mut() {
                    *w *= g;
                }
                self.broyden_updates += 1;
            }
        }
    }
}

/// `max(a, b)` for non-NaN `b` (one `maxsd`; `f64::max`'s NaN handling costs several
/// instructions more in the short loops of the travel bound).
#[inline(always)]
pub(crate) fn fast_max(a: f64, b: f64) -> f64 {
    if b > a {
        b
    } else {
        a
    }
}

/// The state and stopping rules of one chord iteration, shared by the dense chart's plain and
/// Broyden loops and the sparse chart's loop: the iteration count, the last two residuals, the
/// tolerance and the round-off cap below which a stall is accepted.
pub(crate) struct ChordLoop {
    t: f64,
    tol: f64,
    max_iter: usize,
    divergence: f64,
    predicted: bool,
    /// The residual at the start.
    pub(crate) res0: f64,
    /// The current residual.
    pub(crate) res: f64,
    /// The residual before the last correction (infinite before the first).
    pub(crate) prev: f64,
    /// Corrections made.
    pub(crate) it: usize,
    /// An upper estimate of the contraction factor known before the iteration starts
    /// (infinite: none), for the predicted stop after the first correction.
    pub(crate) theta_prior: f64,
}

impl ChordLoop {
    /// An iteration at time `t` from `x` with residual `res0`; `predicted` for a stage map
    /// ([`TangentChart::map_predicted`]).
    pub(crate) fn new(t: f64, res0: f64, newton: &NewtonSettings, predicted: bool) -> Self {
        let tol = newton.tol;
        ChordLoop {
            t,
            tol,
            max_iter: newton.max_iter,
            divergence: newton.divergence,
            predicted,
            res0,
            res: res0,
            prev: f64::INFINITY,
            it: 0,
            theta_prior: f64::INFINITY,
        }
    }

    /// The verdict before a correction ([`loop_head`]).
    pub(crate) fn head(&self) -> Option<Result<MapStats, ChartFailure>> {
        loop_head(
            self.t,
            self.res,
            self.res0,
            self.it,
            self.tol,
            self.max_iter,
        )
    }

    /// After a correction: counts it and, for a stage map, stops on the predicted residual
    /// ([`predicted_stop`]).
    pub(crate) fn corrected(&mut self) -> Option<MapStats> {
        self.it += 1;
        // before the first correction's result is evaluated, the prior estimate stands in
        // for the observed contraction
        let prev = if self.it == 1 && self.theta_prior.is_finite() {
            self.res / self.theta_prior
        } else {
            self.prev
        };
        predicted_stop(self.predicted, self.res, prev, self.tol, self.it, self.res0)
    }

    /// The contraction factor the last correction showed, `res / prev`, with `res` taken at
    /// least `floor` (a residual below the rounding of its own terms is chance, no evidence
    /// of faster contraction); `None` before the first evaluation after a correction.
    pub(crate) fn observed_theta(&self, floor: f64) -> Option<f64> {
        self.prev
            .is_finite()
            .then(|| fast_max(self.res, floor) / self.prev)
    }

    /// Records the residual `res` of the corrected point and accepts a stall at the round-off
    /// floor ([`stalled`]); `stall_cap` gives that floor (`f` cannot be evaluated more
    /// accurately, [`RoundoffFloor`]), evaluated only when the iteration stalled above the
    /// tolerance.
    pub(crate) fn evaluated(
        &mut self,
        res: f64,
        stall_cap: impl FnOnce() -> f64,
    ) -> Option<MapStats> {
        self.prev = self.res;
        self.res = res;
        stalled(self.res, self.prev, self.tol, stall_cap, self.it, self.res0)
    }

    /// Divergence over the last correction ([`diverged`]).
    pub(crate) fn diverged(&self) -> Option<ChartFailure> {
        diverged(
            self.t,
            self.res,
            self.prev,
            self.tol,
            self.divergence,
            self.it,
        )
    }
}

/// The predicted stop of a stage map, decided after a correction and before `f` is evaluated
/// again: the residual after it is about `theta res` with `theta = res / prev` the contraction
/// just observed ([`TangentChart::map_predicted`]).
pub(crate) fn predicted_stop(
    predicted: bool,
    res: f64,
    prev: f64,
    tol: f64,
    it: usize,
    res0: f64,
) -> Option<MapStats> {
    let theta = res / prev;
    (predicted && prev.is_finite() && theta <= 0.5 && theta * res <= tol).then_some(MapStats {
        iterations: it,
        residual: theta * res,
        initial_residual: res0,
        exact: false,
    })
}

/// The round-off floor of evaluating `f(x) = (Phi, Phi_q v + Phi_t)` at a chart point: below
/// it a stall (no progress) is convergence as far as `f` can be evaluated, not a failure.
///
/// `f` carries the rounding of its terms, about `eps (|r| + |v|)`, and that of the bodies'
/// `sin`/`cos`: an angle `theta` is known to `eps |theta|`, so a body point `R(theta) p` is off
/// by `eps |theta| |p|` and its velocity `omega R'(theta) p` by `eps |theta| |omega| |p|`. On a
/// crank wound up to thousands of radians at thousands of rad/s (Andrews' squeezer at
/// `t = 0.8 s`: 4.1e3 rad, 1.05e4 rad/s) the last term dominates: the velocity rows stall at
/// 2e-11, where `eps (1 + |x|)` alone is 2.3e-12. So the floor is
/// `ROUNDOFF_FACTOR eps (1 + |x|_inf + L max_i (1 + |theta_i|) (1 + |omega_i|))`, `L` the
/// mechanism's length scale (`System::length_scale`) and `i` over the planar bodies (a spatial
/// body's directors do not wind up).
#[derive(Clone, Debug)]
pub(crate) struct RoundoffFloor {
    /// Index of each planar body's angle in `q` (its rate is `n` further on in `x`).
    angles: Vec<usize>,
    /// The number of coordinates `n`.
    n: usize,
    /// The mechanism's length scale.
    length: f64,
}

impl RoundoffFloor {
    /// The floor's terms for `sys` (allocates: at construction).
    pub(crate) fn new(sys: &System) -> Self {
        RoundoffFloor {
            angles: (0..sys.bodies().len()).map(|i| 3 * i + 2).collect(),
            n: sys.n_coords(),
            length: sys.length_scale(),
        }
    }

    /// `max(10 tol, ROUNDOFF_FACTOR eps (1 + |x|_inf + L max_i (1 + |theta_i|)(1 + |omega_i|)))`
    /// at `x = (q, v)` (a NaN entry is skipped, as by `f64::max`), for a chart point held as
    /// `(q, tau v)`: `vinv = 1 / tau` restores the velocities (1 for the model's own `x`).
    pub(crate) fn stall_cap(&self, x: &[f64], tol: f64, vinv: f64) -> f64 {
        let n = self.n;
        let xmax = if x.len() == 2 * n && vinv != 1.0 {
            let (q, v) = x.split_at(n);
            let qm = q.iter().fold(0.0f64, |m, v| fast_max(m, v.abs()));
            v.iter().fold(qm, |m, v| fast_max(m, (v * vinv).abs()))
        } else {
            x.iter().fold(0.0f64, |m, v| fast_max(m, v.abs()))
        };
        let wound = if x.len() == 2 * n {
            self.angles.iter().fold(0.0f64, |m, &i| {
                fast_max(m, (1.0 + x[i].abs()) * (1.0 + (x[n + i] * vinv).abs()))
            })
        } else {
            0.0
        };
        (10.0 * tol).max(ROUNDOFF_FACTOR * f64::EPSILON * (1.0 + xmax + self.length * wound))
    }
}

/// A stall at the round-off floor (no progress below `stall_cap`, not slow convergence): the
/// map is accepted with the residual it reached.
pub(crate) fn stalled(
    res: f64,
    prev: f64,
    tol: f64,
    stall_cap: impl FnOnce() -> f64,
    it: usize,
    res0: f64,
) -> Option<MapStats> {
    (res > tol && res >= 0.9 * prev && res <= stall_cap()).then_some(MapStats {
        iterations: it,
        residual: res,
        initial_residual: res0,
        exact: false,
    })
}

/// Divergence: the residual grew by more than `divergence` over the last iteration.
pub(crate) fn diverged(
    t: f64,
    res: f64,
    prev: f64,
    tol: f64,
    divergence: f64,
    it: usize,
) -> Option<ChartFailure> {
    (res > divergence * prev && res > tol).then_some(ChartFailure {
        t,
        residual: res,
        iterations: it,
    })
}

/// Whether an iteration that ended at `x` from `start` travelled at most [`TRAVEL_FACTOR`]
/// times its first step (plus a rounding floor relative to the size of `start`).
pub(crate) fn travel_within(x: &[f64], start: &[f64], first_step: f64) -> bool {
    // one pass: the travel and the size of the start (for the rounding floor); a NaN in
    // `x` cannot reach here (its residual would not be finite)
    let (mut travel, mut size) = (0.0f64, 0.0f64);
    for (a, b) in x.iter().zip(start) {
        travel = fast_max(travel, (a - b).abs());
        size = fast_max(size, b.abs());
    }
    travel <= TRAVEL_FACTOR * first_step + 16.0 * f64::EPSILON * (1.0 + size)
}

/// The verdict at the head of a chord iteration: failed (residual not finite, or `max_iter`
/// iterations used), converged (`res <= tol`), or `None` to go on.
pub(crate) fn loop_head(
    t: f64,
    res: f64,
    res0: f64,
    it: usize,
    tol: f64,
    max_iter: usize,
) -> Option<Result<MapStats, ChartFailure>> {
    let failure = || ChartFailure {
        t,
        residual: res,
        iterations: it,
    };
    if !res.is_finite() {
        Some(Err(failure()))
    } else if res <= tol {
        Some(Ok(MapStats {
            iterations: it,
            residual: res,
            initial_residual: res0,
            exact: false,
        }))
    } else if it >= max_iter {
        Some(Err(failure()))
    } else {
        None
    }
}
