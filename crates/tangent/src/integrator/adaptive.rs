//! Adaptive steps of paper B's method through the one run loop, [`mbd_solve::run_adaptive`]:
//! the [`AdaptiveIntegrator`] attempts with the embedded error estimate mapped to `x`, the
//! first-step estimate, and the rule for attempts that fail for another reason than the error
//! test (a chart map that did not converge, a singular stage point).

use super::*;
use mbd_solve::AdaptiveConfig;

impl TangentRk {
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
            self.centre(sys, t, h)?;
        }
        match self.attempt(sys, t, h) {
            Ok(w) => {
                self.account(&w);
                // error estimate mapped to x: e = U err_xi
                self.path.tangent_to_ambient(&self.rk.err, &mut self.ex);
                for ((s, a), b) in self.scale.iter_mut().zip(&self.cur).zip(&self.xnew) {
                    *s = a.abs().max(b.abs());
                }
                let error_norm = self.error_norm(ctrl);
                let stats = StepStats {
                    newton_iterations: w.iterations,
                    residual: w.residual,
                    rhs_evals: w.rhs_evals,
                    condition: w.condition,
                    bridged_stages: w.bridged,
                    ..Default::default()
                };
                let accepted = error_norm <= 1.0;
                if !accepted {
                    // the retry starts where this attempt did
                    self.bridge.retry_from(t, &self.cur[..self.n]);
                }
                if accepted {
                    std::mem::swap(&mut self.cur, &mut self.xnew);
                    self.bridge.accept(t + h, &self.cur[..self.n]);
                    self.commit_history(h, t + h, &w);
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
                    Attempt::Chart(f) => self.near_singular(sys, t, f.into_error()),
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
    fn estimate_initial_step(
        &mut self,
        sys: &System,
        t: f64,
        span: f64,
        ctrl: &StepController,
        h_max: f64,
    ) -> Result<f64, SolveError> {
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
                .accel(sys, q, v, t, &mut self.acc_a, &mut self.lambda)
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
        .min(h_max)
        .min(span);
        // explicit Euler trial step x1 = x0 + ha F(x0), F(x1) into proj
        for ((x1, x0), f) in self.x.iter_mut().zip(&self.cur).zip(&self.fx) {
            *x1 = x0 + ha * f;
        }
        {
            let (q, v) = self.x.split_at(n);
            self.path
                .accel(sys, q, v, t + ha, &mut self.acc_a, &mut self.lambda)?;
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
        let h0 = (100.0 * ha).min(hb).min(h_max).min(span);
        if !h0.is_finite() {
            return Err(SolveError::NonFinite {
                t,
                what: "initial step estimate",
            });
        }
        Ok(h0.max(ctrl.h_min))
    }
}

/// Adaptive steps (`docs/tangent.md` section 6). Each attempt centres the chart at the current
/// point unless it is still centred there (after a rejection) and takes one step; the error
/// norm is `sqrt(sum_i (e_i / (atol + rtol max(|x_c,i|, |x_new,i|)))^2 / d)` with `e = U err_xi`
/// the embedded estimate mapped to `x = (q, v)` and `d = 2 (n - m)` the dimension of the state
/// equation. The first step is Hairer, Norsett and Wanner's estimate unless the run gives one.
/// A chart failure or a singular index-1 solve at a stage point is a rejection with an
/// infinite error norm that shrinks the step by [`TangentOptions::chart_shrink`] (the
/// controller's memory is left alone); more than [`TangentOptions::max_chart_failures`] of
/// them in a row at one point, or one whose shrunk step would fall below `controller.h_min`,
/// is [`SolveError::RepeatedFailure`]. A singular configuration at an accepted point is
/// [`SolveError::Singular`] at once.
impl AdaptiveIntegrator for TangentRk {
    fn embedded_order(&self) -> Option<u32> {
        self.rk.tableau.error_estimate_order()
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
        let t = state.t;
        let recentre = self.centred_at != t;
        self.centred_at = t;
        let attempt = match self.attempt_adaptive(sys, state, h, ctrl, recentre) {
            Err(e) if recentre && mbd_solve::SingularStarter::refused_at_start(&e, t) => {
                self.centred_at = f64::NAN;
                let a = self.starter.attempt(sys, state, h, ctrl, e)?;
                if a.accepted {
                    self.after_starter();
                }
                return Ok(a);
            }
            r => r?,
        };
        match attempt {
            Ok(a) => {
                self.failures_here = 0;
                if a.accepted {
                    // the chart is centred at the old point
                    self.centred_at = f64::NAN;
                }
                Ok(a)
            }
            Err(source) => {
                self.failures_here += 1;
                let shrink = self.options.chart_shrink;
                if shrink * h < ctrl.h_min || self.failures_here > self.options.max_chart_failures {
                    return Err(SolveError::RepeatedFailure {
                        t,
                        h,
                        failures: self.failures_here,
                        source: Box::new(source),
                    });
                }
                Ok(StepAttempt {
                    accepted: false,
                    error_norm: f64::INFINITY,
                    stats: StepStats::default(),
                    shrink: Some(shrink),
                })
            }
        }
    }

    fn initial_step(
        &mut self,
        sys: &System,
        state: &State,
        span: f64,
        cfg: &AdaptiveConfig,
    ) -> Result<Option<(f64, StepStats)>, SolveError> {
        self.check_sizes(sys, state)?;
        self.load(sys, state)?;
        let h0 = match self.estimate_initial_step(sys, state.t, span, &cfg.controller, cfg.h_max) {
            Ok(h0) => h0,
            // a singular start: the run loop's own first step (the starter takes it)
            Err(e) if mbd_solve::SingularStarter::refused_at_start(&e, state.t) => return Ok(None),
            Err(e) => return Err(e),
        };
        let work = StepStats {
            rhs_evals: 2,
            ..Default::default()
        };
        Ok(Some((h0, work)))
    }
}
