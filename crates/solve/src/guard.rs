//! What both run loops ([`crate::run`], [`crate::run_adaptive`]) check: the settings and the
//! state before the first step, and after every accepted step a finite state, the
//! constraint-drift guard and the near-singular count.

use crate::error::SolveError;
use crate::integrator::{RunStats, StepStats};
use crate::state::State;
use mbd_model::System;

/// The constraint-drift guard of [`crate::run`] and [`crate::run_adaptive`]: after every step the constraint residuals are
/// checked, and a run whose constraints have drifted stops with
/// [`SolveError::ConstraintDrift`] naming the time, the equation and its joint.
///
/// Position residuals are compared equation by equation with `position_tol` times the
/// equation's scale ([`System::equation_scale`]: the mechanism's length scale for equations in
/// lengths, 1 rad for angle equations). The default, `1e-2`, stops a run whose joints have come
/// apart by 1% of the mechanism's size (or whose angle constraints are off by 0.01 rad): a
/// violation visible in any plot or animation, far beyond every solver's tolerance, and reached
/// by unstabilised RK4 only when its step is too large for the run's length (plain RK4 at
/// h = 0.02 s on the two-link manipulator drifts by 1e-3 of its size in 1.2 s). It stops a solver
/// that has left the constraint manifold (plain RK4 past a singular configuration) before its
/// numbers become meaningless. Velocity residuals
/// `Phi_q v + Phi_t` are checked only if `velocity_tol` is set (absolute, in the equation's unit
/// per second). Turn the guard off ([`crate::RunConfig::without_drift_guard`]) to measure drift itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriftGuard {
    /// Largest accepted `|Phi_i|`, relative to the equation's scale (default `1e-2`).
    pub position_tol: f64,
    /// Largest accepted `|Phi_q v + Phi_t|_i` (absolute); `None` (default) = not checked.
    pub velocity_tol: Option<f64>,
}

impl Default for DriftGuard {
    fn default() -> Self {
        DriftGuard {
            position_tol: DriftGuard::DEFAULT_POSITION_TOL,
            velocity_tol: None,
        }
    }
}

impl DriftGuard {
    /// The default relative position tolerance.
    pub const DEFAULT_POSITION_TOL: f64 = 1e-2;

    pub(crate) fn validate(&self) -> Result<(), SolveError> {
        if !(self.position_tol.is_finite() && self.position_tol > 0.0) {
            return Err(SolveError::InvalidParameter {
                parameter: "drift_guard.position_tol",
                value: self.position_tol,
                reason: "must be positive and finite",
            });
        }
        if let Some(v) = self.velocity_tol {
            if !(v.is_finite() && v > 0.0) {
                return Err(SolveError::InvalidParameter {
                    parameter: "drift_guard.velocity_tol",
                    value: v,
                    reason: "must be positive and finite",
                });
            }
        }
        Ok(())
    }
}

/// The guard's workspace: one residual buffer, allocated once per run.
pub(crate) struct GuardState {
    guard: DriftGuard,
    scale: Vec<f64>,
    buf: Vec<f64>,
}

impl GuardState {
    pub(crate) fn new(sys: &System, guard: DriftGuard) -> Self {
        let m = sys.n_constraints();
        GuardState {
            guard,
            scale: sys.equation_scales(),
            buf: vec![0.0; m],
        }
    }

    pub(crate) fn check(&mut self, sys: &System, state: &State) -> Result<(), SolveError> {
        let (q, v, t) = (state.q.as_slice(), state.v.as_slice(), state.t);
        sys.phi(q, t, &mut self.buf);
        self.worst("position", self.guard.position_tol, true, sys, t)?;
        if let Some(tol) = self.guard.velocity_tol {
            sys.phi_dot(q, v, t, &mut self.buf);
            self.worst("velocity", tol, false, sys, t)?;
        }
        Ok(())
    }

    /// Errors with the equation whose residual is largest relative to its limit, if that one
    /// is over its limit (or NaN).
    fn worst(
        &self,
        level: &'static str,
        tol: f64,
        relative: bool,
        sys: &System,
        t: f64,
    ) -> Result<(), SolveError> {
        let limit = |r: usize| if relative { tol * self.scale[r] } else { tol };
        let mut worst = (0usize, 0.0f64);
        for (r, &x) in self.buf.iter().enumerate() {
            let ratio = x.abs() / limit(r);
            if ratio.is_nan() {
                worst = (r, f64::NAN);
                break;
            }
            if ratio > worst.1 {
                worst = (r, ratio);
            }
        }
        let (row, ratio) = worst;
        if ratio <= 1.0 {
            return Ok(());
        }
        let joint = sys
            .equation_joint(row)
            .map(|j| sys.joints()[j.index()].name.clone())
            .unwrap_or_default();
        Err(SolveError::ConstraintDrift {
            t,
            level,
            equation: sys.equation_name(row),
            joint,
            residual: self.buf[row].abs(),
            tolerance: limit(row),
        })
    }
}

/// The checks of one run: opened before the first step, applied after every accepted one.
pub(crate) struct RunChecks {
    guard: Option<GuardState>,
    condition_limit: f64,
}

impl RunChecks {
    /// Checks the state against the model, the condition limit and the guard's settings, and
    /// allocates the guard's workspace.
    pub(crate) fn open(
        sys: &System,
        state: &State,
        drift_guard: Option<DriftGuard>,
        condition_limit: f64,
    ) -> Result<Self, SolveError> {
        state.check(sys)?;
        validate_condition_limit(condition_limit)?;
        let guard = match drift_guard {
            Some(g) => {
                g.validate()?;
                Some(GuardState::new(sys, g))
            }
            None => None,
        };
        Ok(RunChecks {
            guard,
            condition_limit,
        })
    }

    /// After an accepted step of size `h` with work `s` (the state's time already advanced):
    /// a non-finite state and constraint drift are errors; the step is counted in `stats`.
    pub(crate) fn accepted(
        &mut self,
        sys: &System,
        state: &State,
        h: f64,
        s: &StepStats,
        stats: &mut RunStats,
    ) -> Result<(), SolveError> {
        if !state.is_finite() {
            return Err(SolveError::NonFinite {
                t: state.t,
                what: "state after step",
            });
        }
        if let Some(g) = self.guard.as_mut() {
            g.check(sys, state)?;
        }
        stats.steps += 1;
        stats.min_step = if stats.max_step == 0.0 {
            h
        } else {
            stats.min_step.min(h)
        };
        stats.max_step = stats.max_step.max(h);
        stats.max_residual = stats.max_residual.max(s.residual);
        stats.max_condition = stats.max_condition.max(s.condition);
        if s.condition > self.condition_limit {
            stats.near_singular_steps += 1;
            stats.first_near_singular.get_or_insert(state.t);
        }
        Ok(())
    }
}

/// The condition limit of both run configurations must be positive (infinity turns the
/// near-singular count off).
pub(crate) fn validate_condition_limit(limit: f64) -> Result<(), SolveError> {
    if limit > 0.0 {
        Ok(())
    } else {
        Err(SolveError::InvalidParameter {
            parameter: "condition_limit",
            value: limit,
            reason: "must be positive (infinity turns the count off)",
        })
    }
}
