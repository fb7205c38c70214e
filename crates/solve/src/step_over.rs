//! Stepping over a grid time at which the mechanism is singular, in a fixed-step [`run`].
//!
//! A step that lands exactly on a singular configuration (a driven isosceles slider-crank at
//! its dead point, a driven parallelogram at its flat position: `Phi_q` loses rank there, and
//! a crank turning at a rational multiple of `pi` per second reaches it at a time on the
//! grid) leaves a state from which no step can start: the index-1 matrix, the chart's
//! Jacobian or the symplectic stage Jacobian is singular there to rounding. The motion itself
//! passes smoothly, and the solvers that keep the constraints follow their branch through the
//! configuration at any step that does not land on it. So when a step of such a solver fails
//! with [`SolveError::Singular`], [`run`] covers two grid intervals with three steps whose
//! ends and stages all miss the grid time between them (steps of `0.414 h`, `h` and `0.586 h`,
//! [`OFFSET`]):
//!
//! 1. the failing step and the next, from the failing step's start (`t_(k-1)` to `t_(k+1)`,
//!    stepping over `t_k`): where the failing step *ended* on the singular configuration (a
//!    step's equations or its end point's projection include it). The observer then has no
//!    state at `t_k`: the grid time at the singular configuration itself is skipped
//!    ([`RunStats::skipped_outputs`]);
//! 2. where that fails too (it starts from the failing step's start, which fails when that is
//!    the singular configuration), the interval before the failing step and the failing step
//!    itself, from the state before (`t_(k-2)` to `t_k`, stepping over `t_(k-1)`): where the
//!    failing step *started* on the singular configuration (the state there was reached and
//!    observed; only starting from it fails).
//!
//! In this order a window never ends on the singular configuration. Both need the window's
//! steps to have the nominal size. The integrator is reset before each attempt (its history
//! belongs to the steps being replaced), and an attempt's work counts in the run's statistics
//! only if it covers its window. Where neither does, the step's error is returned as it was.
//!
//! [`run`]: crate::run

use crate::guard::RunChecks;
use crate::{Integrator, OutputSolve, RunStats, SolveError, State};
use mbd_model::System;

/// The grid times around a step of a fixed-step run that failed as singular.
pub(crate) struct Window<'a> {
    /// The nominal step.
    pub(crate) h: f64,
    /// The failing step's start and its end time.
    pub(crate) start: &'a State,
    pub(crate) t_k: f64,
    /// The grid time after the failing step's end, where the window of case 1 ends (`None`
    /// where it is not one nominal step further within the run).
    pub(crate) after: Option<f64>,
    /// The state before the failing step's start, for case 2 (`None` where there is no such
    /// state or the failing step is not nominal).
    pub(crate) before: Option<&'a State>,
}

/// Which window covered the failure.
pub(crate) enum Covered {
    /// Case 1: the state is at [`Window::after`]; the grid time of the failing step's end
    /// was skipped.
    After,
    /// Case 2: the state is at the failing step's end.
    Before,
}

/// Covers the failure of a step from `window.start` ([`Covered`]), or `None` where neither
/// window could be covered (the state is then the failing step's start again). Counts the
/// step-over in `stats`.
pub(crate) fn step_over<I: Integrator + ?Sized>(
    integrator: &mut I,
    sys: &System,
    state: &mut State,
    window: &Window<'_>,
    checks: &mut RunChecks,
    stats: &mut RunStats,
) -> Option<Covered> {
    let attempt = |integrator: &mut I,
                   state: &mut State,
                   from: &State,
                   t_b: f64,
                   checks: &mut RunChecks,
                   stats: &mut RunStats| {
        copy_state(state, from);
        let mut trial = *stats;
        let ok = cover(integrator, sys, state, window.h, t_b, checks, &mut trial).is_ok();
        if ok {
            *stats = trial;
        }
        ok
    };
    let (covered, over) = if window
        .after
        .is_some_and(|t_b| attempt(integrator, state, window.start, t_b, checks, stats))
    {
        stats.skipped_outputs += 1;
        (Covered::After, window.t_k)
    } else if window
        .before
        .is_some_and(|from| attempt(integrator, state, from, window.t_k, checks, stats))
    {
        (Covered::Before, window.start.t)
    } else {
        copy_state(state, window.start);
        return None;
    };
    stats.stepped_over += 1;
    stats.first_stepped_over.get_or_insert(over);
    Some(covered)
}

/// Where the steps that cover a window start relative to its grid time: the window
/// `[t_a, t_a + 2h]` is covered by steps of `OFFSET h`, `h` and `(1 - OFFSET) h`, so the middle
/// step straddles the grid time `t_a + h` and evaluates the model there only at a stage of
/// abscissa `c = 1 - OFFSET`. Not a simple fraction (`sqrt 2 - 1`): the stage abscissae of the
/// methods (`1/2` of RK4 and the (2,2) scheme's midpoint control point, `1/5 .. 8/9` of DOPRI5,
/// `2/3` of some third-order methods) then never fall on it.
pub(crate) const OFFSET: f64 = std::f64::consts::SQRT_2 - 1.0;

/// The window `[t_a, t_a + 2h]` covered from `state` (at `t_a`) by steps of `OFFSET h`, `h` and
/// `(1 - OFFSET) h` ([`OFFSET`]), ending at exactly `t_b` (the grid time `t_a + 2h`). Each step
/// is checked as an accepted step of the run; on an error the state is left where it failed.
#[allow(clippy::too_many_arguments)]
fn cover<I: Integrator + ?Sized>(
    integrator: &mut I,
    sys: &System,
    state: &mut State,
    h: f64,
    t_b: f64,
    checks: &mut RunChecks,
    stats: &mut RunStats,
) -> Result<(), SolveError> {
    integrator.reset();
    let t_a = state.t;
    for (size, t_end) in [
        (OFFSET * h, t_a + OFFSET * h),
        (h, t_a + (1.0 + OFFSET) * h),
        ((1.0 - OFFSET) * h, t_b),
    ] {
        let s = integrator.step(sys, state, size)?;
        state.t = t_end;
        stats.add_work(&s);
        checks.accepted(sys, state, size, &s, stats)?;
    }
    Ok(())
}

/// Detects a step that ended on a singular configuration although its factorisations
/// passed. On a mechanism that starts on a singular configuration the solvers may drop the
/// start's extra dependent equations at every factorisation ([`System::dependency_budget`]),
/// so a later step that lands exactly on a singular configuration does not fail; but its
/// end state is not the motion's (the velocities there may take a component along the other
/// branch, which the velocity constraints no longer exclude). The run treats it as a
/// failing step and steps over it (by the window after it only: the one before ends on it),
/// so a run that ends on a singular configuration stops there, as on any mechanism. Only for
/// such mechanisms: an index-1 solve at each step's end ([`OutputSolve::indeterminate`]), the
/// workspace allocated once per run.
pub(crate) struct Landing {
    solve: Option<OutputSolve>,
}

impl Landing {
    /// The check for a run of `sys` (nothing unless the integrator keeps the constraints and
    /// the mechanism starts on a singular configuration).
    pub(crate) fn new(sys: &System, keeps: bool) -> Result<Self, SolveError> {
        let solve = if keeps && sys.dependency_budget() > sys.n_redundant() {
            Some(OutputSolve::new(sys)?)
        } else {
            None
        };
        Ok(Landing { solve })
    }

    /// Whether `state` (a step's end) is a singular configuration: the index-1 solve there
    /// dropped more rows than the redundant equations, or found none of the rows it may drop
    /// enough (a velocity off every branch leaves the accelerations without a solution).
    pub(crate) fn on_singular(&mut self, sys: &System, state: &State) -> bool {
        match &mut self.solve {
            Some(s) => match s.at(sys, state) {
                Ok(_) => s.indeterminate(),
                Err(e) => matches!(e, SolveError::Singular { .. }),
            },
            None => false,
        }
    }
}

/// What a step that landed on a singular configuration fails with ([`Landing`]).
pub(crate) const LANDED_ON_SINGULAR: &str = "index-1 matrix at a step's end (a singular \
     configuration, passed only by the allowance of the singular start)";

/// Copies `from` into `to` (same sizes: no allocation).
#[inline]
pub(crate) fn copy_state(to: &mut State, from: &State) {
    to.t = from.t;
    to.q.copy_from(&from.q);
    to.v.copy_from(&from.v);
}
