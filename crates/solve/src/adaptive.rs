//! Adaptive steps through the shared run loop: the [`AdaptiveIntegrator`] trait (attempt a
//! step, report its scaled error) and [`run_adaptive`], which drives it with a PI step-size
//! controller, the same observers, drift guard and [`RunStats`] as the fixed-step [`run`].
//!
//! [`run`]: crate::run

use crate::error::SolveError;
use crate::guard::{validate_condition_limit, DriftGuard, RunChecks};
use crate::integrator::{Flow, Integrator, Observer, RunConfig, RunStats, StepStats};
use crate::state::State;
use crate::tableau::StepController;
use mbd_model::System;

/// The outcome of [`AdaptiveIntegrator::attempt_step`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepAttempt {
    /// Whether the step was accepted (the state advanced).
    pub accepted: bool,
    /// The scaled error norm of the embedded estimate (accepted iff `<= 1`); infinite for a
    /// step that failed for another recoverable reason (e.g. a chart map that did not
    /// converge), which the controller treats as a large error.
    pub error_norm: f64,
    /// Work of the attempt.
    pub stats: StepStats,
    /// For a rejection that is not the error test's (infinite `error_norm`, e.g. a chart map
    /// that did not converge): the factor the next attempt's step is multiplied by, without
    /// touching the controller's memory; must lie in (0, 1) (otherwise, and for `None`, the
    /// default: the controller's `fac_min`).
    pub shrink: Option<f64>,
}

/// A one-step method with an embedded error estimate, driven by [`run_adaptive`].
pub trait AdaptiveIntegrator: Integrator {
    /// The order `q` of the embedded (lower-order) solution the controller's exponent uses
    /// (`1/(q+1)`); `None` if the method has no error estimate.
    fn embedded_order(&self) -> Option<u32>;

    /// Attempts one step of size `h` from `state`. If the scaled error norm (with `ctrl`'s
    /// `atol`, `rtol`) is at most 1 the step is accepted: `state` advances to `state.t + h`.
    /// Otherwise `state` is left unchanged. Errors are for unrecoverable failures only.
    fn attempt_step(
        &mut self,
        sys: &System,
        state: &mut State,
        h: f64,
        ctrl: &StepController,
    ) -> Result<StepAttempt, SolveError>;

    /// The first step of a run from `state` over `span` seconds when `cfg` gives none
    /// ([`AdaptiveConfig::h0`]), with the work it cost; `None` (the default) lets
    /// [`run_adaptive`] take `0.1 span tol^(1/(q+1))`. Called after [`Integrator::reset`], before
    /// the first attempt; the result is clamped to `[controller.h_min, min(h_max, span)]`.
    fn initial_step(
        &mut self,
        sys: &System,
        state: &State,
        span: f64,
        cfg: &AdaptiveConfig,
    ) -> Result<Option<(f64, StepStats)>, SolveError> {
        let _ = (sys, state, span, cfg);
        Ok(None)
    }
}

impl<I: AdaptiveIntegrator + ?Sized> AdaptiveIntegrator for Box<I> {
    fn embedded_order(&self) -> Option<u32> {
        (**self).embedded_order()
    }
    fn attempt_step(
        &mut self,
        sys: &System,
        state: &mut State,
        h: f64,
        ctrl: &StepController,
    ) -> Result<StepAttempt, SolveError> {
        (**self).attempt_step(sys, state, h, ctrl)
    }
    fn initial_step(
        &mut self,
        sys: &System,
        state: &State,
        span: f64,
        cfg: &AdaptiveConfig,
    ) -> Result<Option<(f64, StepStats)>, SolveError> {
        (**self).initial_step(sys, state, span, cfg)
    }
}

/// Settings of [`run_adaptive`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveConfig {
    /// End time (the start is the state's time).
    pub t_end: f64,
    /// Tolerances, safety factor, shrink/growth limits and the smallest step.
    pub controller: StepController,
    /// First step; `None` = the integrator's estimate
    /// ([`AdaptiveIntegrator::initial_step`]), or for integrators without one
    /// `0.1 (t_end - t0) tol^(1/(q+1))` with `tol = max(atol, rtol)` (the controller corrects it
    /// within a few steps).
    pub h0: Option<f64>,
    /// Largest step (default infinite).
    pub h_max: f64,
    /// Limit on accepted plus rejected steps (default `10^7`).
    pub max_steps: usize,
    /// `beta` of the PI controller (`None` = Gustafsson's `0.4/(q+1)`; `Some(0.0)` = I
    /// controller). After an accepted step with error norm `err` (previous accepted step:
    /// `err_prev`), `h <- h safety err^-(1/(q+1) - 0.75 beta) err_prev^beta`; Gustafsson's
    /// PI.3.4 is 0.08 for DOPRI5, Hairer and Wanner's DOPRI5 code uses 0.04. Must lie in
    /// `[0, 1 / (1.75 (q+1)))`: at larger values a steady error never lets the step grow.
    pub pi_beta: Option<f64>,
    /// The constraint-drift guard, checked after every accepted step (default on).
    pub drift_guard: Option<DriftGuard>,
    /// As [`RunConfig::condition_limit`].
    pub condition_limit: f64,
}

impl AdaptiveConfig {
    /// A run to `t_end` with `atol = rtol = tol` and default settings otherwise.
    pub fn new(t_end: f64, tol: f64) -> Self {
        AdaptiveConfig {
            t_end,
            controller: StepController {
                atol: tol,
                rtol: tol,
                ..Default::default()
            },
            h0: None,
            h_max: f64::INFINITY,
            max_steps: 10_000_000,
            pi_beta: None,
            drift_guard: Some(DriftGuard::default()),
            condition_limit: RunConfig::DEFAULT_CONDITION_LIMIT,
        }
    }

    /// The same run with the given first step.
    pub fn with_h0(mut self, h0: f64) -> Self {
        self.h0 = Some(h0);
        self
    }

    /// The same run with the given largest step.
    pub fn with_h_max(mut self, h_max: f64) -> Self {
        self.h_max = h_max;
        self
    }

    /// The same run without the drift guard.
    pub fn without_drift_guard(mut self) -> Self {
        self.drift_guard = None;
        self
    }

    fn validate(&self, t0: f64) -> Result<(), SolveError> {
        if !(self.t_end.is_finite() && t0.is_finite() && self.t_end > t0) {
            return Err(SolveError::InvalidInterval {
                t0,
                t_end: self.t_end,
                reason: "end time must be finite and after the start time",
            });
        }
        self.validate_settings()
    }

    /// Checks every setting but the interval (`t_end` is not read): the controller, `h0`,
    /// `h_max`, `max_steps` and `condition_limit`. `run_adaptive` checks these and the interval;
    /// the `pi_beta` bound depends on the integrator's embedded order and is checked there.
    pub fn validate_settings(&self) -> Result<(), SolveError> {
        let bad = |parameter, value, reason| {
            Err(SolveError::InvalidParameter {
                parameter,
                value,
                reason,
            })
        };
        self.controller.validate()?;
        if let Some(h0) = self.h0 {
            if !(h0.is_finite() && h0 > 0.0) {
                return bad("h0", h0, "must be positive and finite");
            }
        }
        if self.h_max.is_nan() || self.h_max <= 0.0 {
            return bad("h_max", self.h_max, "must be positive");
        }
        if self.max_steps == 0 {
            return bad("max_steps", 0.0, "must be at least 1");
        }
        validate_condition_limit(self.condition_limit)
    }
}

/// Integrates from `state.t` to `cfg.t_end` with adaptive steps, calling `observer` with the
/// initial state (step 0) and after every accepted step (with the accepted-step index).
///
/// The first step is [`AdaptiveConfig::h0`], else the integrator's
/// [`AdaptiveIntegrator::initial_step`], else `0.1 span tol^(1/(q+1))`. After an accepted step
/// with error norm `err` (previous accepted: `err_prev`), `h <- h safety err^-(1/(q+1) -
/// 0.75 beta) err_prev^beta` clamped to `[fac_min, fac_max]` (no growth right after a
/// rejection); after a rejection `h <- h max(fac_min, safety err^-(1/(q+1) - 0.75 beta))`.
/// A rejection with an infinite error norm (an attempt that failed for another reason, e.g. a
/// chart map that did not converge) multiplies the step by the solver's
/// [`StepAttempt::shrink`] factor instead (`fac_min` without one), leaving the controller's
/// memory alone; the solver decides when such failures become an error. The last step lands exactly on `t_end`. Errors: a step below
/// `controller.h_min` ([`SolveError::StepSizeTooSmall`]), more than `max_steps` attempts
/// ([`SolveError::TooManyAttempts`]), a non-finite state or error estimate
/// ([`SolveError::NonFinite`]), constraint drift beyond the guard
/// ([`SolveError::ConstraintDrift`]). [`RunStats::steps`] counts accepted steps,
/// [`RunStats::rejected_steps`] rejections.
pub fn run_adaptive<I, O>(
    integrator: &mut I,
    sys: &System,
    state: &mut State,
    cfg: AdaptiveConfig,
    observer: &mut O,
) -> Result<RunStats, SolveError>
where
    I: AdaptiveIntegrator + ?Sized,
    O: Observer + ?Sized,
{
    let t0 = state.t;
    cfg.validate(t0)?;
    let mut checks = RunChecks::open(
        sys,
        state,
        cfg.drift_guard,
        cfg.condition_limit,
        integrator.keeps_constraints(),
    )?;
    let q = integrator.embedded_order().ok_or_else(|| {
        SolveError::Unsupported(format!(
            "adaptive stepping needs an embedded error estimate; '{}' has none \
             (use DOPRI5 or Bogacki-Shampine)",
            integrator.name()
        ))
    })?;
    let k = q as f64 + 1.0;
    let beta = cfg.pi_beta.unwrap_or(0.4 / k);
    if !(beta >= 0.0 && beta < 1.0 / (1.75 * k)) {
        return Err(SolveError::InvalidParameter {
            parameter: "pi_beta",
            value: beta,
            reason: "must lie in [0, 1 / (1.75 (q+1))) for the embedded order q",
        });
    }
    let ctrl = cfg.controller;
    let expo = 1.0 / k - 0.75 * beta;
    let span = cfg.t_end - t0;
    integrator.reset();
    let mut stats = RunStats::default();
    let h0 = match cfg.h0 {
        Some(h0) => h0,
        None => match integrator.initial_step(sys, state, span, &cfg)? {
            Some((h0, work)) => {
                stats.add_work(&work);
                h0
            }
            None => 0.1 * span * ctrl.atol.max(ctrl.rtol).powf(1.0 / k),
        },
    };
    if !(h0 > 0.0) {
        return Err(SolveError::NonFinite {
            t: t0,
            what: "initial step estimate",
        });
    }
    let mut h = h0.min(cfg.h_max).min(span).max(ctrl.h_min);
    if observer.observe(sys, state, 0)? == Flow::Stop {
        stats.stopped_by(observer);
        return Ok(stats);
    }
    let mut err_prev = 1e-4f64;
    let mut last_rejected = false;
    let mut attempts = 0usize;
    while state.t < cfg.t_end {
        attempts += 1;
        if attempts > cfg.max_steps {
            return Err(SolveError::TooManyAttempts {
                t: state.t,
                attempts: cfg.max_steps,
            });
        }
        let t = state.t;
        let remaining = cfg.t_end - t;
        let last = h >= remaining * (1.0 - 1e-12);
        let hs = if last { remaining } else { h };
        if hs < ctrl.h_min && !last {
            return Err(SolveError::StepSizeTooSmall {
                t,
                h: hs,
                h_min: ctrl.h_min,
            });
        }
        let a = integrator.attempt_step(sys, state, hs, &ctrl)?;
        stats.add_work(&a.stats);
        let en = a.error_norm;
        if en.is_nan() {
            return Err(SolveError::NonFinite {
                t,
                what: "embedded error estimate",
            });
        }
        let grow = if en == 0.0 {
            ctrl.fac_max
        } else {
            ctrl.safety * en.powf(-expo)
        };
        if !a.accepted {
            stats.rejected_steps += 1;
            last_rejected = true;
            h = match a.shrink {
                Some(f) if en == f64::INFINITY && f > 0.0 && f < 1.0 => hs * f,
                _ => hs * grow.clamp(ctrl.fac_min, 1.0),
            };
            continue;
        }
        state.t = if last { cfg.t_end } else { t + hs };
        checks.accepted(sys, state, hs, &a.stats, &mut stats)?;
        let mut fac = if en == 0.0 {
            ctrl.fac_max
        } else {
            (grow * err_prev.powf(beta)).clamp(ctrl.fac_min, ctrl.fac_max)
        };
        err_prev = en.max(1e-4);
        if last_rejected {
            fac = fac.min(1.0);
        }
        last_rejected = false;
        h = (hs * fac).min(cfg.h_max);
        if observer.observe(sys, state, stats.steps)? == Flow::Stop {
            stats.stopped_by(observer);
            break;
        }
    }
    Ok(stats)
}
