//! Adaptive steps: [`AdaptiveSettings`], [`AdaptiveStats`] and
//! [`TangentRk::integrate_adaptive`] (PI control of the embedded error estimate).

use super::*;
use mbd_solve::{run_adaptive, AdaptiveConfig, RunConfig};

/// Settings of [`TangentRk::integrate_adaptive`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveSettings {
    /// Tolerances, safety factor, shrink/growth limits and the smallest step. The scaled error
    /// is `sqrt(sum_i (e_i / (atol + rtol max(|x_c,i|, |x_new,i|)))^2 / d)` with `e = U err_xi`
    /// the embedded estimate mapped to `x = (q, v)` and `d = 2 (n - m)` the dimension of the
    /// state equation.
    pub controller: StepController,
    /// First step size; `None` picks Hairer, Norsett and Wanner's estimate from `F(x0)` and
    /// one explicit Euler trial step (two acceleration solves).
    pub h0: Option<f64>,
    /// Largest step size.
    pub h_max: f64,
    /// Limit on accepted plus rejected steps.
    pub max_steps: usize,
    /// `beta` of the PI step-size controller (Hairer-Wanner form, `q` the embedded order):
    /// after an accepted step with error norm `err` (previous accepted step: `err_prev`),
    /// `h <- h safety err^-(1/(q+1) - 0.75 beta) err_prev^beta`. `None` (default) is
    /// Gustafsson's PI.3.4, `beta = 0.4 / (q+1)` (0.08 for DOPRI5: exponents 0.14 and 0.08);
    /// `Some(0.0)` the classical I controller; Hairer and Wanner's DOPRI5 code uses 0.04. Must
    /// lie in `[0, 1 / (1.75 (q+1)))`: at larger values a steady error never lets the step grow.
    pub pi_beta: Option<f64>,
    /// Factor applied to the step after a chart failure (the chart map did not converge) or a
    /// singular index-1 solve at a stage point; the error controller's memory is left alone.
    /// Default 0.25; must lie in (0, 1).
    pub chart_shrink: f64,
    /// Most chart failures in a row at one point before [`TangentError::Chart`]. Default 8
    /// (the step shrinks by `chart_shrink^8`, 1.5e-5 by default).
    pub max_chart_failures: usize,
}

impl Default for AdaptiveSettings {
    fn default() -> Self {
        AdaptiveSettings {
            controller: StepController::default(),
            h0: None,
            h_max: f64::INFINITY,
            max_steps: 10_000_000,
            pi_beta: None,
            chart_shrink: 0.25,
            max_chart_failures: 8,
        }
    }
}

impl AdaptiveSettings {
    /// Default settings with `atol = rtol = tol`.
    pub fn with_tolerance(tol: f64) -> Self {
        let mut s = Self::default();
        s.controller.atol = tol;
        s.controller.rtol = tol;
        s
    }

    /// The run loop's configuration for these settings: the same controller, step limits and
    /// `pi_beta`, no drift guard (the chart keeps the constraints), the default condition limit.
    fn config(&self, t_end: f64, h0: Option<f64>) -> AdaptiveConfig {
        AdaptiveConfig {
            t_end,
            controller: self.controller,
            h0,
            h_max: self.h_max,
            max_steps: self.max_steps,
            pi_beta: self.pi_beta,
            drift_guard: None,
            condition_limit: RunConfig::DEFAULT_CONDITION_LIMIT,
        }
    }

    /// Checks every setting: those shared with [`AdaptiveConfig`] by
    /// [`AdaptiveConfig::validate_settings`], then `pi_beta`, `chart_shrink` and
    /// `max_chart_failures`.
    pub fn validate(&self) -> Result<(), SolveError> {
        let bad = |parameter, value, reason| {
            Err(SolveError::InvalidParameter {
                parameter,
                value,
                reason,
            })
        };
        self.config(f64::NAN, self.h0).validate_settings()?;
        if let Some(b) = self.pi_beta {
            // the bound for the tableau's embedded order is checked when it is known
            if !(0.0..0.5).contains(&b) {
                return bad("pi_beta", b, "must lie in [0, 1 / (1.75 (q+1)))");
            }
        }
        if !(self.chart_shrink > 0.0 && self.chart_shrink < 1.0) {
            return bad("chart_shrink", self.chart_shrink, "must lie in (0, 1)");
        }
        if self.max_chart_failures == 0 {
            return bad("max_chart_failures", 0.0, "must be at least 1");
        }
        Ok(())
    }
}

/// Summary of [`TangentRk::integrate_adaptive`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AdaptiveStats {
    /// Accepted steps.
    pub accepted: usize,
    /// Steps rejected by the error test.
    pub rejected: usize,
    /// Steps rejected because the chart map failed, or the index-1 solve at a stage point was
    /// singular (retried with [`AdaptiveSettings::chart_shrink`] times the step).
    pub chart_rejections: usize,
    /// Chart maps completed by the exact Newton fallback ([`NewtonSettings::fallback_change`]).
    pub exact_maps: usize,
    /// The first step chosen by the initial-step estimate (0 if [`AdaptiveSettings::h0`] was
    /// given).
    pub h_initial_estimate: f64,
    /// Acceleration solves.
    pub rhs_evals: usize,
    /// Chord Newton iterations.
    pub newton_iterations: usize,
    /// Smallest accepted step.
    pub h_min: f64,
    /// Largest accepted step.
    pub h_max: f64,
    /// Largest `||(Phi, Phidot)||_inf` at an accepted point.
    pub max_residual: f64,
    /// Whether the observer stopped the run early.
    pub stopped_early: bool,
}

impl TangentRk {
    /// Integrates from `state.t` to `t_end` with adaptive steps controlled by the tableau's
    /// embedded error estimate (e.g. DOPRI5 5(4), Bogacki-Shampine 3(2)), calling `observer`
    /// with the initial state (step 0) and after every accepted step.
    ///
    /// The steps are driven by [`mbd_solve::run_adaptive`] (the one step-control loop of the
    /// workspace) through this solver's [`AdaptiveIntegrator`] attempts, without its drift
    /// guard (the chart keeps the constraints). Step control (`docs/tangent.md` section 6):
    /// the first step from Hairer, Norsett and Wanner's estimate (`f(x0)` and one explicit
    /// Euler trial step) unless [`AdaptiveSettings::h0`] is given; after an accepted step a PI
    /// controller (`h <- h safety err^-(1/(q+1) - 0.75 beta) err_prev^beta`, clamped to
    /// `[fac_min, fac_max]`, no growth right after a rejection), after a rejected one
    /// `h <- h max(fac_min, safety err^-(1/(q+1) - 0.75 beta))`. A chart failure (the chart map
    /// did not converge) or a singular index-1 solve at a stage point multiplies the step by
    /// [`AdaptiveSettings::chart_shrink`] without touching the controller's memory; more than
    /// [`AdaptiveSettings::max_chart_failures`] of them in a row, or one whose shrunk step
    /// would fall below `controller.h_min`, is [`TangentError::Chart`]. An error-test step
    /// below `controller.h_min` is [`SolveError::StepSizeTooSmall`], more than
    /// [`AdaptiveSettings::max_steps`] attempts [`SolveError::TooManyAttempts`] (both inside
    /// [`TangentError::Solve`]). A singular configuration at an accepted point is
    /// [`SolveError::Singular`] at once (no retry with smaller steps).
    pub fn integrate_adaptive<O: Observer + ?Sized>(
        &mut self,
        sys: &System,
        state: &mut State,
        t_end: f64,
        settings: &AdaptiveSettings,
        observer: &mut O,
    ) -> Result<AdaptiveStats, TangentError> {
        settings.validate()?;
        self.check_sizes(sys, state)?;
        let t0 = state.t;
        if !(t_end.is_finite() && t_end > t0) {
            return Err(SolveError::InvalidInterval {
                t0,
                t_end,
                reason: "end time must be finite and after the start time",
            }
            .into());
        }
        if self.embedded_order().is_none() {
            return Err(SolveError::Unsupported(format!(
                "adaptive stepping needs a tableau with an embedded error estimate; '{}' has \
                 none (use DOPRI5 or Bogacki-Shampine)",
                self.rk.tableau.name
            ))
            .into());
        }
        self.load(sys, state)?;
        let mut st = AdaptiveStats::default();
        let h0 = match settings.h0 {
            Some(h0) => h0,
            None => {
                let h0 = self.initial_step(sys, t0, t_end - t0, settings)?;
                st.h_initial_estimate = h0;
                h0
            }
        };
        let cfg = settings.config(t_end, Some(h0));
        let exact_before = self.stats.exact_maps;
        let mut driver = Driver {
            rk: self,
            chart_shrink: settings.chart_shrink,
            max_chart_failures: settings.max_chart_failures,
            failures_here: 0,
            centred_at: f64::NAN,
            chart_error: None,
            chart_rejections: 0,
            h_min: f64::INFINITY,
            h_max: 0.0,
        };
        let run = run_adaptive(&mut driver, sys, state, cfg, observer);
        let Driver {
            chart_error,
            chart_rejections,
            h_min,
            h_max,
            ..
        } = driver;
        let rs = run.map_err(|source| match chart_error {
            Some((h, failures)) => TangentError::Chart {
                source,
                h,
                failures,
            },
            None => TangentError::Solve(source),
        })?;
        st.accepted = rs.steps;
        st.rejected = rs.rejected_steps - chart_rejections;
        st.chart_rejections = chart_rejections;
        st.exact_maps = self.stats.exact_maps - exact_before;
        st.rhs_evals = rs.rhs_evals + if settings.h0.is_none() { 2 } else { 0 };
        st.newton_iterations = rs.newton_iterations;
        st.h_min = if rs.steps == 0 { 0.0 } else { h_min };
        st.h_max = h_max;
        st.max_residual = rs.max_residual;
        st.stopped_early = rs.stopped_early;
        Ok(st)
    }

    /// One adaptive attempt of size `h` from `state` (loaded and checked): `Ok(Ok(attempt))`
    /// for an attempt the error test judged, `Ok(Err(failure))` for a recoverable failure (the
    /// chart map, or a stage point's index-1 solve), `Err` for a hard one. Centres the chart
    /// at `state` first if `recentre`.
    fn attempt_adaptive(
        &mut self,
        sys: &System,
        state: &mut State,
        h: f64,
        ctrl: &StepController,
        recentre: bool,
    ) -> Result<Result<StepAttempt, SolveError>, SolveError> {
        let t = state.t;
        if recentre {
            self.centre(sys, t)?;
        }
        match self.attempt(sys, t, h) {
            Ok(w) => {
                self.account(&w);
                // error estimate mapped to x: e = U err_xi
                self.path.to_ambient(&self.rk.err, &mut self.ex);
                for ((s, a), b) in self.scale.iter_mut().zip(&self.cur).zip(&self.xnew) {
                    *s = a.abs().max(b.abs());
                }
                let error_norm = self.error_norm(ctrl);
                let stats = StepStats {
                    newton_iterations: w.iterations,
                    residual: w.residual,
                    rhs_evals: w.rhs_evals,
                    condition: w.condition,
                    ..Default::default()
                };
                let accepted = error_norm <= 1.0;
                if accepted {
                    std::mem::swap(&mut self.cur, &mut self.xnew);
                    self.commit_history(h, t + h, w.end_initial_residual);
                    self.cur_t = t + h;
                    self.cur_ok = true;
                    self.stats.steps += 1;
                    self.stats.max_residual = self.stats.max_residual.max(w.residual);
                    self.store(state);
                    state.t = t + h;
                }
                Ok(Ok(StepAttempt {
                    accepted,
                    error_norm,
                    stats,
                    shrink: None,
                }))
            }
            Err(fail @ (Attempt::Chart(_) | Attempt::Stage(_) | Attempt::SingularEnd(_))) => {
                self.stats.chart_failures += 1;
                Ok(Err(match fail {
                    Attempt::Chart(f) => f.into_error(),
                    Attempt::Stage(e) | Attempt::SingularEnd(e) | Attempt::Hard(e) => e,
                }))
            }
            Err(Attempt::Hard(e)) => Err(e),
        }
    }

    /// The scaled error norm of the estimate `ex` (mapped to `x`) with the scale in `scale`
    /// (`max(|x_c,i|, |x_1,i|)`): `sqrt(sum_i (e_i / (atol + rtol scale_i))^2 / d)` with
    /// `d = 2 (n - m)` the dimension of the state equation. `e = U err_xi` has the Euclidean
    /// length of the estimate in chart coordinates, spread over the `2n` ambient components;
    /// dividing by `2n` instead of `d` would shrink the RMS of a `d`-dimensional error by
    /// `sqrt(d / 2n)` (1/sqrt(3) on the manipulator) and loosen every tolerance by that much.
    pub(super) fn error_norm(&self, ctrl: &StepController) -> f64 {
        let d = self.path.dim().max(1) as f64;
        let sum: f64 = self
            .ex
            .iter()
            .zip(&self.scale)
            .map(|(e, y)| (e / (ctrl.atol + ctrl.rtol * y.abs())).powi(2))
            .sum();
        (sum / d).sqrt()
    }

    /// Hairer, Norsett and Wanner's initial step (`HINIT` of DOPRI5, "Solving ODEs I",
    /// section II.4) in the controller's scaled RMS norm (`sk = atol + rtol |x0|`, normalised
    /// like [`TangentRk::error_norm`]): `d0 = ||x0||`, `d1 = ||F(x0)||`,
    /// `h_a = 0.01 d0 / d1` (1e-6 if either is below 1e-5), one explicit Euler trial step
    /// `x1 = x0 + h_a F(x0)` (off the manifold by `O(h_a^2)`; the index-1 solve does not need
    /// it on), `d2 = ||F(x1) - F(x0)|| / h_a`, `h_b = (0.01 / max(d1, d2))^(1/p)` with `p` the
    /// method's order (`max(1e-6, 1e-3 h_a)` if `max(d1, d2) <= 1e-15`), and
    /// `h0 = min(100 h_a, h_b, h_max, span)`, at least `h_min`. Two acceleration solves.
    pub(super) fn initial_step(
        &mut self,
        sys: &System,
        t: f64,
        span: f64,
        settings: &AdaptiveSettings,
    ) -> Result<f64, SolveError> {
        let ctrl = &settings.controller;
        let n = self.n;
        let d = self.path.dim().max(1) as f64;
        let norm = |x: &[f64], y: &[f64]| -> f64 {
            let sum: f64 = x
                .iter()
                .zip(y)
                .map(|(e, y)| (e / (ctrl.atol + ctrl.rtol * y.abs())).powi(2))
                .sum();
            (sum / d).sqrt()
        };
        {
            let (q, v) = self.cur.split_at(n);
            if let Err(e) = self
                .path
                .accel(sys, q, v, t, false, &mut self.acc_a, &mut self.lambda)
            {
                return Err(match e {
                    SolveError::Singular { .. } => self
                        .path
                        .singular_error_at(sys, q, t, SINGULAR_REPORT_TOL)
                        .unwrap_or(e),
                    e => e,
                });
            }
        }
        self.stats.rhs_evals += 1;
        self.fx[..n].copy_from_slice(&self.cur[n..]);
        self.fx[n..].copy_from_slice(&self.acc_a);
        let d0 = norm(&self.cur, &self.cur);
        let d1 = norm(&self.fx, &self.cur);
        let ha = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        }
        .min(settings.h_max)
        .min(span);
        // explicit Euler trial step x1 = x0 + ha F(x0), F(x1) into proj
        for ((x1, x0), f) in self.x.iter_mut().zip(&self.cur).zip(&self.fx) {
            *x1 = x0 + ha * f;
        }
        {
            let (q, v) = self.x.split_at(n);
            self.path
                .accel(sys, q, v, t + ha, false, &mut self.acc_a, &mut self.lambda)?;
        }
        self.stats.rhs_evals += 1;
        self.proj[..n].copy_from_slice(&self.x[n..]);
        self.proj[n..].copy_from_slice(&self.acc_a);
        for (df, f0) in self.ex.iter_mut().zip(self.proj.iter().zip(&self.fx)) {
            *df = (f0.0 - f0.1) / ha;
        }
        let d2 = norm(&self.ex, &self.cur);
        let d12 = d1.max(d2);
        let p = self.rk.tableau.order.max(1) as f64;
        let hb = if d12 <= 1e-15 {
            (1e-3 * ha).max(1e-6)
        } else {
            (0.01 / d12).powf(1.0 / p)
        };
        let h0 = (100.0 * ha).min(hb).min(settings.h_max).min(span);
        if !h0.is_finite() {
            return Err(SolveError::NonFinite {
                t,
                what: "initial step estimate",
            });
        }
        Ok(h0.max(ctrl.h_min))
    }
}

/// Adaptive steps of paper B's method through [`mbd_solve::run_adaptive`] (the shared run loop
/// with its observers, drift guard and [`mbd_solve::RunStats`]). Each attempt centres the chart
/// at the current state and takes one step; the error norm is
/// [`AdaptiveSettings::controller`]'s as in [`TangentRk::integrate_adaptive`]. A chart failure
/// or a singular index-1 solve at a stage point is a rejection with an infinite error norm
/// (the run loop shrinks the step by `fac_min`).
impl AdaptiveIntegrator for TangentRk {
    fn embedded_order(&self) -> Option<u32> {
        match (&self.rk.tableau.b_hat, self.rk.tableau.embedded_order) {
            (Some(_), q) if q > 0 => Some(q),
            _ => None,
        }
    }

    fn attempt_step(
        &mut self,
        sys: &System,
        state: &mut State,
        h: f64,
        ctrl: &StepController,
    ) -> Result<StepAttempt, SolveError> {
        self.check_sizes(sys, state)?;
        if !(h.is_finite() && h > 0.0) {
            return Err(SolveError::InvalidStep { h });
        }
        if self.embedded_order().is_none() {
            return Err(SolveError::Unsupported(format!(
                "'{}' has no embedded error estimate",
                self.rk.tableau.name
            )));
        }
        self.load(sys, state)?;
        Ok(self
            .attempt_adaptive(sys, state, h, ctrl, true)?
            .unwrap_or(StepAttempt {
                accepted: false,
                error_norm: f64::INFINITY,
                stats: StepStats::default(),
                shrink: None,
            }))
    }
}

/// [`TangentRk::integrate_adaptive`]'s view of the solver for [`run_adaptive`]: the chart is
/// centred once per point (not again after a rejection), chart failures shrink the step by
/// [`AdaptiveSettings::chart_shrink`] up to [`AdaptiveSettings::max_chart_failures`] in a row,
/// and the statistics only the tangent solver knows are collected.
struct Driver<'a> {
    rk: &'a mut TangentRk,
    chart_shrink: f64,
    max_chart_failures: usize,
    /// Chart failures in a row at the current point.
    failures_here: usize,
    /// The time the chart was last centred at.
    centred_at: f64,
    /// The step and failure count of the chart failure that ended the run.
    chart_error: Option<(f64, usize)>,
    chart_rejections: usize,
    h_min: f64,
    h_max: f64,
}

impl Integrator for Driver<'_> {
    fn name(&self) -> String {
        self.rk.name()
    }
    fn step(&mut self, sys: &System, state: &mut State, h: f64) -> Result<StepStats, SolveError> {
        self.rk.step(sys, state, h)
    }
    /// Keeps the solver's history and statistics (`integrate_adaptive` never reset them).
    fn reset(&mut self) {}
    fn order(&self) -> Option<u32> {
        self.rk.order()
    }
}

impl AdaptiveIntegrator for Driver<'_> {
    fn embedded_order(&self) -> Option<u32> {
        self.rk.embedded_order()
    }

    fn attempt_step(
        &mut self,
        sys: &System,
        state: &mut State,
        h: f64,
        ctrl: &StepController,
    ) -> Result<StepAttempt, SolveError> {
        self.rk.load(sys, state)?;
        let recentre = self.centred_at != state.t;
        self.centred_at = state.t;
        match self.rk.attempt_adaptive(sys, state, h, ctrl, recentre)? {
            Ok(a) => {
                self.failures_here = 0;
                if a.accepted {
                    self.h_min = self.h_min.min(h);
                    self.h_max = self.h_max.max(h);
                }
                Ok(a)
            }
            Err(source) => {
                self.chart_rejections += 1;
                self.failures_here += 1;
                if self.chart_shrink * h < ctrl.h_min
                    || self.failures_here > self.max_chart_failures
                {
                    self.chart_error = Some((h, self.failures_here));
                    return Err(source);
                }
                Ok(StepAttempt {
                    accepted: false,
                    error_norm: f64::INFINITY,
                    stats: StepStats::default(),
                    shrink: Some(self.chart_shrink),
                })
            }
        }
    }
}
