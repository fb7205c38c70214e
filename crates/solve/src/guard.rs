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
    /// The branch check: on a step whose condition estimate is above
    /// [`BRANCH_WATCH_CONDITION`] (near a singular configuration), the mismatch between the
    /// step's displacement and the mean of its end velocities, relative to the distance
    /// travelled, must stay below this (default [`BRANCH_JUMP_TOL`]); a step beyond it left
    /// the branch of the motion it was on and stops the run with [`SolveError::Singular`].
    /// `None` = not checked.
    pub branch_tol: Option<f64>,
}

impl Default for DriftGuard {
    fn default() -> Self {
        DriftGuard {
            position_tol: DriftGuard::DEFAULT_POSITION_TOL,
            velocity_tol: None,
            branch_tol: Some(BRANCH_JUMP_TOL),
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
        if let Some(b) = self.branch_tol {
            if !(b.is_finite() && b > 0.0) {
                return Err(SolveError::InvalidParameter {
                    parameter: "drift_guard.branch_tol",
                    value: b,
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
    /// The state before the step (time, positions, velocities) and the mass weights of the
    /// branch check.
    prev_t: f64,
    prev_q: Vec<f64>,
    prev_v: Vec<f64>,
    weight: Vec<f64>,
    /// The last step with a condition estimate above [`BRANCH_WATCH_CONDITION`] (its end time
    /// and condition): drift that appears later in the run of a solver that does not keep the
    /// constraints grew from there.
    passage: Option<(f64, f64)>,
    /// The condition estimate of the last accepted step (NaN before the first): the start of
    /// the next one.
    last_condition: f64,
    /// Accepted steps left before the next residual check (see [`GUARD_STRIDE`]).
    skip: usize,
}

impl GuardState {
    pub(crate) fn new(sys: &System, guard: DriftGuard, state: &State) -> Self {
        let m = sys.n_constraints();
        GuardState {
            guard,
            scale: sys.equation_scales(),
            buf: vec![0.0; m],
            prev_t: state.t,
            prev_q: state.q.as_slice().to_vec(),
            prev_v: state.v.as_slice().to_vec(),
            weight: sys.mass_diag().as_slice().to_vec(),
            passage: None,
            last_condition: f64::NAN,
            skip: 0,
        }
    }

    /// Whether a step that started with condition estimate `start` (the last accepted step's,
    /// NaN for the first step) started near a singular configuration: above
    /// [`BRANCH_ARM_CONDITION`]; for the first step, the initial state's unit-free condition
    /// (still in `prev_q`; an error path only), unknown counting as near.
    fn started_near(&self, sys: &System, start: f64) -> bool {
        if start.is_nan() {
            sys.dependence_condition(&self.prev_q, self.prev_t)
                .map_or(true, |c| c > BRANCH_ARM_CONDITION)
        } else {
            start > BRANCH_ARM_CONDITION
        }
    }

    /// The branch check after an accepted step of size `h` with condition estimate
    /// `condition`, started with estimate `start` (see [`DriftGuard::branch_tol`]); remembers
    /// the state for the next one.
    fn branch(
        &mut self,
        sys: &System,
        state: &State,
        h: f64,
        condition: f64,
        start: f64,
    ) -> Result<(), SolveError> {
        let Some(tol) = self.guard.branch_tol else {
            return Ok(());
        };
        // the state before this step is at hand only if the last step was remembered (its
        // condition estimate above BRANCH_ARM_CONDITION), or this is the first step
        let fresh = (state.t - h - self.prev_t).abs() <= 1e-12 * state.t.abs().max(h);
        if condition > BRANCH_WATCH_CONDITION && fresh {
            let dev = self.branch_deviation(state, h);
            // a step from a regular configuration passed no singular one: one that misses the
            // smooth relation from there is too long for the motion (what follows says so)
            if !(dev <= tol) && self.started_near(sys, start) {
                return Err(SolveError::Singular {
                    t: state.t,
                    what: "configuration passed onto another branch",
                    detail: format!(
                        "between t = {} and t = {} (condition estimate {condition:.1e}), the \
                         end velocity disagrees with the step's displacement by {dev:.2} of the \
                         distance travelled (a smooth step: about (omega h)^2 / 12): the solver \
                         went on along another branch of the motion; take a smaller h, or a \
                         solver that keeps the constraints",
                        self.prev_t, state.t
                    ),
                });
            }
        }
        // remembered only near a singular configuration (a well-conditioned step copies nothing)
        if condition > BRANCH_ARM_CONDITION {
            self.prev_t = state.t;
            self.prev_q.copy_from_slice(state.q.as_slice());
            self.prev_v.copy_from_slice(state.v.as_slice());
        } else {
            self.prev_t = f64::NAN;
        }
        Ok(())
    }

    /// Checks the residuals of the state after a step whose condition estimate is
    /// `condition`, or skips the check while the last one found them far below their limits
    /// (see [`GUARD_STRIDE`]).
    pub(crate) fn check(
        &mut self,
        sys: &System,
        state: &State,
        condition: f64,
    ) -> Result<(), SolveError> {
        if self.skip > 0 && condition <= BRANCH_ARM_CONDITION {
            self.skip -= 1;
            return Ok(());
        }
        let (q, v, t) = (state.q.as_slice(), state.v.as_slice(), state.t);
        sys.phi(q, t, &mut self.buf);
        let mut ratio = self.worst("position", self.guard.position_tol, true, sys, t)?;
        if let Some(tol) = self.guard.velocity_tol {
            sys.phi_dot(q, v, t, &mut self.buf);
            ratio = ratio.max(self.worst("velocity", tol, false, sys, t)?);
        }
        self.skip = if ratio <= GUARD_QUIET_RATIO && condition <= BRANCH_ARM_CONDITION {
            GUARD_STRIDE - 1
        } else {
            0
        };
        Ok(())
    }

    /// Errors with the equation whose residual is largest relative to its limit, if that one
    /// is over its limit (or NaN); else returns that largest ratio.
    fn worst(
        &self,
        level: &'static str,
        tol: f64,
        relative: bool,
        sys: &System,
        t: f64,
    ) -> Result<f64, SolveError> {
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
            return Ok(ratio);
        }
        let joint = sys.equation_element(row);
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

/// The drift guard checks the residuals after every step until one check finds them all below
/// [`GUARD_QUIET_RATIO`] of their limits on a well-conditioned step (condition estimate at
/// most [`BRANCH_ARM_CONDITION`]); it then skips the next `GUARD_STRIDE - 1` well-conditioned
/// steps. A skipped step cannot hide drift beyond the limit unless the residuals grew by
/// `1 / GUARD_QUIET_RATIO = 100` within `GUARD_STRIDE` steps, far faster than any drift seen
/// (plain RK4 leaving a singular passage grows its drift by about 10% a step, 2.1x in eight
/// steps), and every step near
/// a singular configuration, where a jump can happen, is checked; a non-finite state is caught
/// at every step regardless. The stride spares well-conditioned runs most `Phi` evaluations (a
/// tenth of a plain RK4 step on the manipulator); the run's states are the same either way.
pub const GUARD_STRIDE: usize = 8;

/// See [`GUARD_STRIDE`]: residuals below this fraction of their limits let the guard skip
/// steps.
pub const GUARD_QUIET_RATIO: f64 = 1e-2;

/// A drift residual above this multiple of the guard's tolerance (the mechanism's size with
/// the default `1e-2`) is a blow-up, not the drift of a singular passage (which the guard,
/// checking every step near one, meets just above its tolerance): see
/// [`SolveError::ConstraintDrift`].
pub const BLOWUP_RATIO: f64 = 100.0;

/// The default of [`DriftGuard::branch_tol`]: a step whose end velocity breaks the
/// trapezoidal relation with its displacement by more than this fraction of the distance
/// travelled jumped to another branch of the motion. A smooth step reaches it only at
/// `omega h` above about 1 rad (`omega`: the motion's angular rate).
pub const BRANCH_JUMP_TOL: f64 = 0.1;

/// Steps whose condition estimate is above this (constraint gradients within about 0.03 rad
/// of linear dependence) get the branch check of [`DriftGuard::branch_tol`]: a motion can
/// change branch only where `Phi_q` nearly loses rank, and away from there a large step on a
/// fast motion must not be taken for a jump.
pub const BRANCH_WATCH_CONDITION: f64 = 1e3;

/// A step with a condition estimate above this remembers its end state for the branch check of
/// the next step; below it nothing is copied (well-posed mechanisms stay below it), so the
/// check costs nothing away from singular configurations. A step that goes from below this
/// straight above [`BRANCH_WATCH_CONDITION`] is not checked.
pub const BRANCH_ARM_CONDITION: f64 = 1e2;

/// The checks of one run: opened before the first step, applied after every accepted one.
pub(crate) struct RunChecks {
    guard: Option<GuardState>,
    condition_limit: f64,
    /// Whether the integrator keeps the constraints itself (else a near-singular step stops
    /// the run).
    keeps_constraints: bool,
    /// Models with spatial bodies: the steps' condition estimates brought to the unit-free
    /// measure of the constraint geometry (see [`GeometryGate`]).
    geometry: Option<GeometryGate>,
}

/// How far the index-1 solve's condition estimate may move from the one at which the gate
/// last measured the geometry before it measures again: a factor of 4 up (the estimate grows
/// like the inverse square of the distance to a singular configuration: half the distance)
/// or of 64 down.
pub(crate) const GEOMETRY_REMEASURE: f64 = 4.0;

/// The condition estimate of the index-1 solves (`max_j S_jj / L_jj^2` of
/// `S = Phi_q M^-1 Phi_q^T`) measures how nearly the constraint gradients depend on each other
/// in the metric of the inverse mass. On a spatial body `M^-1` weighs the directors by the
/// inverse director masses `1 / E_i`, large on a slender or flat body (`E_i = (J_j + J_k -
/// J_i) / 2`: a 1 mm shaft's is 1e4 times below its `J_max`): its joints' gradients then look
/// nearly parallel in that metric at every configuration (the estimate of a flyball governor
/// with such a shaft is about 1e7 everywhere), while `Phi_q` is far from losing rank. The gate
/// scales the estimate by `min(1, g / c)`, `g` the unit-free condition
/// [`System::dependence_condition`] (directors weighed by `m / J_max`) and `c` the estimate, both
/// at the step where it last measured; it measures again when the estimate has moved by
/// [`GEOMETRY_REMEASURE`] from there (so an approach to a real singular configuration, where
/// both grow, is followed), and never below [`BRANCH_ARM_CONDITION`], where every decision
/// reads the step as regular anyway. Planar models (whose estimate has no director masses;
/// with bodies of equal masses `g` is the estimate itself) and models above
/// [`mbd_model::SPARSE_RANK_THRESHOLD`] equations go without it.
pub(crate) struct GeometryGate {
    /// `min(1, g / c)` at the last measurement (1 before the first).
    ratio: f64,
    /// The estimate `c` at the last measurement (0: none yet).
    at: f64,
}

impl GeometryGate {
    fn new(sys: &System) -> Option<Self> {
        (sys.has_spatial()
            && sys.n_constraints() > 0
            && sys.n_constraints() <= mbd_model::SPARSE_RANK_THRESHOLD)
            .then_some(GeometryGate {
                ratio: 1.0,
                at: 0.0,
            })
    }

    /// The estimate `c` of a step ending in `state`, in the unit-free measure.
    fn effective(&mut self, sys: &System, state: &State, c: f64) -> f64 {
        if !(c > BRANCH_ARM_CONDITION) {
            return c;
        }
        let moved = self.at == 0.0
            || c > GEOMETRY_REMEASURE * self.at
            || c * GEOMETRY_REMEASURE.powi(3) < self.at;
        if moved {
            if let Some(g) = sys.dependence_condition(state.q.as_slice(), state.t) {
                self.ratio = if g < c { g / c } else { 1.0 };
                self.at = c;
            }
        }
        c * self.ratio
    }
}

impl RunChecks {
    /// Checks the state against the model, the condition limit and the guard's settings, and
    /// allocates the guard's workspace.
    pub(crate) fn open(
        sys: &System,
        state: &State,
        drift_guard: Option<DriftGuard>,
        condition_limit: f64,
        keeps_constraints: bool,
    ) -> Result<Self, SolveError> {
        state.check(sys)?;
        validate_condition_limit(condition_limit)?;
        let guard = match drift_guard {
            Some(g) => {
                g.validate()?;
                Some(GuardState::new(sys, g, state))
            }
            None => None,
        };
        Ok(RunChecks {
            guard,
            condition_limit,
            keeps_constraints,
            geometry: GeometryGate::new(sys),
        })
    }
}

impl GuardState {
    /// The branch check of one step: on a smooth motion the displacement of a step and the
    /// mean of its end velocities agree to second order, `q1 - q0 - h (v0 + v1) / 2 =
    /// -h^3 q''' / 12 + ...`, a fraction `(omega h)^2 / 12` of the distance travelled
    /// `h |v|` (`omega`: the motion's angular rate; 3e-4 at 6 rad/s and h = 1e-2). A step
    /// that leaves its branch at a singular configuration ends with the velocity of the other
    /// branch (a four-bar's rocker turning the other way): the relation then fails by a
    /// fraction of order one. Mass-weighted norms (scale-free), with a floor at the
    /// positions' round-off for a mechanism at rest. Returns the fraction.
    fn branch_deviation(&self, state: &State, h: f64) -> f64 {
        let (q, v) = (state.q.as_slice(), state.v.as_slice());
        let (mut r2, mut v0, mut v1, mut q2) = (0.0, 0.0, 0.0, 0.0);
        for i in 0..q.len() {
            let w = self.weight[i];
            let r = q[i] - self.prev_q[i] - 0.5 * h * (self.prev_v[i] + v[i]);
            r2 += w * r * r;
            v0 += w * self.prev_v[i] * self.prev_v[i];
            v1 += w * v[i] * v[i];
            q2 += w * q[i] * q[i];
        }
        r2.sqrt() / (h * v0.max(v1).sqrt() + 1e3 * f64::EPSILON * q2.sqrt()).max(f64::MIN_POSITIVE)
    }
}

impl RunChecks {
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
        let condition = match self.geometry.as_mut() {
            Some(gate) => gate.effective(sys, state, s.condition),
            None => s.condition,
        };
        // the estimate at this step's start (the last step's; NaN before the first)
        let start = self.guard.as_ref().map_or(f64::NAN, |g| g.last_condition);
        if let Some(g) = self.guard.as_mut() {
            let passed_before = g.passage.is_some();
            g.last_condition = condition;
            if condition > BRANCH_WATCH_CONDITION {
                g.passage = Some((state.t, condition));
            }
            if let Err(e) = g.check(sys, state, condition) {
                // whether the run came near a singular configuration before this step, or
                // this step started near one
                let near_before = passed_before || g.started_near(sys, start);
                let passage = if self.keeps_constraints {
                    None
                } else {
                    g.passage
                };
                return Err(drift_error(
                    e,
                    state.t,
                    condition,
                    g.guard.branch_tol.is_some(),
                    passage,
                    near_before,
                ));
            }
        }
        if condition > self.condition_limit && !self.keeps_constraints {
            return Err(self.singular_stop(sys, state, condition));
        }
        if let Some(g) = self.guard.as_mut() {
            g.branch(sys, state, h, condition, start)?;
        }
        stats.steps += 1;
        stats.min_step = if stats.max_step == 0.0 {
            h
        } else {
            stats.min_step.min(h)
        };
        stats.max_step = stats.max_step.max(h);
        stats.max_residual = stats.max_residual.max(s.residual);
        stats.max_condition = stats.max_condition.max(condition);
        if condition > self.condition_limit {
            stats.near_singular_steps += 1;
            stats.first_near_singular.get_or_insert(state.t);
        }
        Ok(())
    }
}

impl RunChecks {
    /// The stop of an integrator that does not keep the constraints at a near-singular step:
    /// the equations nearest to dependence and their joints (allocates: an error path).
    #[cold]
    #[inline(never)]
    fn singular_stop(&self, sys: &System, state: &State, condition: f64) -> SolveError {
        // the condition estimate also carries the equations' scaling, which the dependence
        // test does not: the nearest equations are named at the first tolerance that finds
        // any (an angle of 1e-2 to 0.3 between a gradient and the others' span)
        let (tol, near) = NEAR_TOLS
            .iter()
            .map(|&tol| {
                (
                    tol,
                    sys.nearly_dependent_at(state.q.as_slice(), state.t, tol),
                )
            })
            .find(|(_, near)| !near.is_empty())
            .unwrap_or((NEAR_TOLS[0], Vec::new()));
        let named = if near.is_empty() {
            String::new()
        } else {
            let list: Vec<String> = near
                .iter()
                .map(|e| format!("{} (joints {})", e.equation, e.joints.join(", ")))
                .collect();
            format!(
                "; rank deficiency {} (equations within {tol:.0e} of dependence: {})",
                near.len(),
                list.join("; ")
            )
        };
        SolveError::Singular {
            t: state.t,
            what: "configuration (Phi_q near rank loss)",
            detail: format!(
                "condition estimate {condition:.2e} above the run's limit {:.0e}{named}; this \
                 solver integrates the index-1 equations without keeping the constraints, so past \
                 the singular configuration it may go on along another branch: use a solver that \
                 keeps them (a projection, symplectic or tangent: `mbd solvers`), or raise \
                 condition_limit to go on unchecked",
                self.condition_limit
            ),
        }
    }
}

/// The drift guard's error `e` after a step ending at `t` with condition estimate
/// `condition`, reported as a singular configuration while the branch check is on: drift
/// that appears on a step near a singular configuration means the solver left the branch
/// there (a solver on the constraints does not drift by 1%); drift of a solver that does not
/// keep the constraints, after it passed near one at `passage` (end time and condition of that
/// step), grew from the error of that passage (a well-posed mechanism never comes near).
///
/// A run that met no near-singular step before this one and whose step started at a regular
/// configuration (`near_before` false: the last step's condition estimate at most
/// [`BRANCH_ARM_CONDITION`]) gets the drift error itself: a step from there that ends off the
/// constraints did not pass a singular configuration (a motion approaching one shows a
/// growing estimate first). A residual beyond [`BLOWUP_RATIO`] times the guard's tolerance
/// there is a blow-up: the
/// state has left the constraints by more than the mechanism's size (with the default
/// tolerance) within the few steps since the last check, from regular configurations, the
/// growth of an unstable step (an explicit solver on stiff springs or dampers beyond its
/// stability), and the condition estimate at such a state says nothing about the mechanism.
#[cold]
#[inline(never)]
fn drift_error(
    e: SolveError,
    t: f64,
    condition: f64,
    branch_check: bool,
    passage: Option<(f64, f64)>,
    near_before: bool,
) -> SolveError {
    // a step from a regular configuration that ends off the constraints did not pass a
    // singular one: its end state's condition estimate says nothing about the mechanism
    if !near_before || !branch_check {
        return e;
    }
    // the drift itself, without the drift error's advice (the singular error gives its own)
    let drift = match &e {
        SolveError::ConstraintDrift {
            level,
            equation,
            residual,
            tolerance,
            ..
        } => format!(
            "{level} residual of {equation} is {residual:e}, beyond the drift guard's \
             {tolerance:e}"
        ),
        other => other.to_string(),
    };
    if condition > BRANCH_WATCH_CONDITION {
        SolveError::Singular {
            t,
            what: "configuration passed onto another branch",
            detail: format!(
                "the step ending at t = {t} (condition estimate {condition:.1e}) left the \
                 constraints: {drift}"
            ),
        }
    } else if let Some((tp, cp)) = passage {
        SolveError::Singular {
            t,
            what: "configuration passed with growing drift",
            detail: format!(
                "the run passed near a singular configuration at t = {tp} (condition estimate \
                 {cp:.1e}) and its constraints have drifted since: {drift}; this solver does \
                 not keep the constraints: use one that does (a projection, symplectic or \
                 tangent: `mbd solvers`)"
            ),
        }
    } else {
        e
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

/// Tolerances of the dependence test (`System::nearly_dependent_at`) tried in turn by the
/// singular stop's report, strictest first.
const NEAR_TOLS: [f64; 4] = [1e-2, 3e-2, 1e-1, 3e-1];
