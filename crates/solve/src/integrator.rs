//! The `Integrator` trait, the run loop and observers.

use crate::adaptive::AdaptiveIntegrator;
use crate::error::SolveError;
use crate::guard::RunChecks;
pub use crate::guard::{
    DriftGuard, BLOWUP_RATIO, BRANCH_ARM_CONDITION, BRANCH_JUMP_TOL, BRANCH_WATCH_CONDITION,
    GUARD_QUIET_RATIO, GUARD_STRIDE,
};
use crate::state::State;
use crate::step_over;
use mbd_model::System;

/// What one step did (for diagnostics and work counts).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepStats {
    /// Newton iterations (implicit solvers), 0 otherwise.
    pub newton_iterations: usize,
    /// Final Newton residual (implicit solvers).
    pub residual: f64,
    /// Evaluations of the equations of motion (right-hand side / acceleration solves).
    pub rhs_evals: usize,
    /// Objective evaluations (optimisation-based solvers).
    pub objective_evals: usize,
    /// Largest condition estimate of the index-1 matrix `Phi_q M^-1 Phi_q^T` met in the step
    /// (after diagonal equilibration; see [`crate::AccelerationSolver::condition_estimate`]);
    /// 0 when the solver does not estimate it. RK4 (`Index1Rk`), the tangent solver and FA-DAE
    /// report it; the symplectic scheme, which never forms the index-1 matrix (its stage system
    /// holds the constraints at the control points), reports 0.
    pub condition: f64,
    /// Stages whose accelerations [`crate::SingularBridge`] bridged through a singular
    /// configuration (RK4 and the tangent solver; 0 elsewhere).
    pub bridged_stages: usize,
}

/// A one-step method for the constrained equations of motion.
///
/// An integrator owns its workspace, sized for one [`System`] when it is created; `step`
/// advances `state` by `h` (setting `state.t += h`) and must allocate nothing.
pub trait Integrator {
    /// A short name for reports, e.g. `"RK4"` or `"symplectic (2,2)"`.
    fn name(&self) -> String;
    /// One step of size `h`.
    fn step(&mut self, sys: &System, state: &mut State, h: f64) -> Result<StepStats, SolveError>;
    /// Forgets any history (predictors, cached momenta) so the next step starts afresh. Called
    /// by [`run`] before the first step.
    fn reset(&mut self) {}
    /// Whether every step ends on the position constraints by the method's own means (a
    /// projection, constrained stage equations, a chart), so that it follows the branch it is
    /// on through a singular configuration. `false` (the default) for a method that
    /// integrates the index-1 equations as they are: past a singular configuration it may go
    /// on along another branch, so the run loops stop it with [`SolveError::Singular`] at the
    /// first step whose condition estimate exceeds the run's `condition_limit`.
    fn keeps_constraints(&self) -> bool {
        false
    }
    /// The method's convergence order in the step size, if known.
    fn order(&self) -> Option<u32> {
        None
    }
    /// This solver as an [`AdaptiveIntegrator`] (one with an embedded error estimate, driven by
    /// [`crate::run_adaptive`]), or `None` (the default) for a fixed-step method. Lets a caller
    /// holding a `Box<dyn Integrator>` (the solver registry's product) run it adaptively.
    fn as_adaptive(&mut self) -> Option<&mut dyn AdaptiveIntegrator> {
        None
    }
}

impl<I: Integrator + ?Sized> Integrator for Box<I> {
    fn name(&self) -> String {
        (**self).name()
    }
    fn step(&mut self, sys: &System, state: &mut State, h: f64) -> Result<StepStats, SolveError> {
        (**self).step(sys, state, h)
    }
    fn reset(&mut self) {
        (**self).reset()
    }
    fn keeps_constraints(&self) -> bool {
        (**self).keeps_constraints()
    }
    fn order(&self) -> Option<u32> {
        (**self).order()
    }
    fn as_adaptive(&mut self) -> Option<&mut dyn AdaptiveIntegrator> {
        (**self).as_adaptive()
    }
}

/// Whether a run should go on after an observation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flow {
    /// Keep stepping.
    Continue,
    /// Stop after this sample (the run ends successfully).
    Stop,
}

/// Why a run ended (without an error: errors stay errors).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[non_exhaustive]
pub enum StopReason {
    /// The run reached its end time.
    #[default]
    ReachedEnd,
    /// An observer returned [`Flow::Stop`].
    Observer,
    /// A terminal event of a [`crate::DenseOutput`] fired.
    Event {
        /// The event's index (order of [`crate::DenseOutput::with_event`] calls).
        event: usize,
        /// The located time of the crossing.
        t: f64,
    },
}

/// Receives samples of a run: the initial state (step 0) and the state after steps.
pub trait Observer {
    /// Called with the step index (0 = initial state) and the state.
    fn observe(&mut self, sys: &System, state: &State, step: usize) -> Result<Flow, SolveError>;

    /// After this observer returned [`Flow::Stop`]: why, if more is known than "an observer
    /// stopped the run" (a terminal event). The run loops record it in [`RunStats::stop`].
    fn stop_reason(&self) -> Option<StopReason> {
        None
    }
}

impl<F> Observer for F
where
    F: FnMut(&System, &State, usize) -> Result<Flow, SolveError>,
{
    fn observe(&mut self, sys: &System, state: &State, step: usize) -> Result<Flow, SolveError> {
        self(sys, state, step)
    }
}

/// A pair of observers: both see every sample; the run stops if either asks to.
impl<A: Observer, B: Observer> Observer for (A, B) {
    fn observe(&mut self, sys: &System, state: &State, step: usize) -> Result<Flow, SolveError> {
        let a = self.0.observe(sys, state, step)?;
        let b = self.1.observe(sys, state, step)?;
        Ok(if a == Flow::Stop || b == Flow::Stop {
            Flow::Stop
        } else {
            Flow::Continue
        })
    }
    fn stop_reason(&self) -> Option<StopReason> {
        self.0.stop_reason().or_else(|| self.1.stop_reason())
    }
}

/// An observer from a closure over the state alone (see [`observe`]).
#[derive(Clone, Copy, Debug)]
pub struct StateFn<F>(pub F);

impl<F: FnMut(&State)> Observer for StateFn<F> {
    fn observe(&mut self, _: &System, state: &State, _: usize) -> Result<Flow, SolveError> {
        (self.0)(state);
        Ok(Flow::Continue)
    }
}

/// An observer from a closure `|state| ...` that sees every sample and never stops the run;
/// the closure's argument type is inferred.
///
/// ```
/// use mbd_model::models;
/// use mbd_solve::{observe, run, ButcherTableau, Index1Options, Index1Rk, RunConfig, SolveError, State};
///
/// let sys = models::pendulum(1.0, 1.0, 0.3, 9.81)?;
/// let mut state = State::consistent(&sys, 0.0)?;
/// let mut rk = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default())?;
/// let mut lowest = f64::INFINITY;
/// run(&mut rk, &sys, &mut state, RunConfig::new(1.0, 0.01), &mut observe(|s| {
///     lowest = lowest.min(s.q[1]);
/// }))?;
/// assert!(lowest < -0.49 && lowest > -0.51); // the rod's centre passes 0.5 m below the pivot
/// # Ok::<(), SolveError>(())
/// ```
pub fn observe<F: FnMut(&State)>(f: F) -> StateFn<F> {
    StateFn(f)
}

/// An observer from a closure `|sys, state, step| -> Result<Flow, SolveError>` with every
/// argument type inferred (a bare closure passed as `&mut O` needs them annotated).
///
/// ```
/// use mbd_model::models;
/// use mbd_solve::{observer, run, ButcherTableau, Flow, Index1Options, Index1Rk, RunConfig, SolveError, State};
///
/// let sys = models::pendulum(1.0, 1.0, 0.3, 9.81)?;
/// let mut state = State::consistent(&sys, 0.0)?;
/// let mut rk = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default())?;
/// // stop once the rod has swung past the vertical (x changes sign)
/// let stats = run(&mut rk, &sys, &mut state, RunConfig::new(5.0, 0.01), &mut observer(|_, s, _| {
///     Ok(if s.q[0] < 0.0 { Flow::Stop } else { Flow::Continue })
/// }))?;
/// assert!(stats.stopped_early && state.t < 1.0);
/// # Ok::<(), SolveError>(())
/// ```
pub fn observer<F>(f: F) -> FnObserver<F>
where
    F: FnMut(&System, &State, usize) -> Result<Flow, SolveError>,
{
    FnObserver(f)
}

/// An observer from a closure over `(sys, state, step)` (see [`observer`]).
#[derive(Clone, Copy, Debug)]
pub struct FnObserver<F>(pub F);

impl<F> Observer for FnObserver<F>
where
    F: FnMut(&System, &State, usize) -> Result<Flow, SolveError>,
{
    fn observe(&mut self, sys: &System, state: &State, step: usize) -> Result<Flow, SolveError> {
        (self.0)(sys, state, step)
    }
}

/// Ignores every sample.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoObserver;

impl Observer for NoObserver {
    fn observe(&mut self, _: &System, _: &State, _: usize) -> Result<Flow, SolveError> {
        Ok(Flow::Continue)
    }
}

/// Passes every `k`-th sample (and the last one of the run) to an inner observer.
#[derive(Debug)]
pub struct Every<O> {
    /// Sampling interval in steps.
    pub k: usize,
    /// The observer sampled.
    pub inner: O,
    /// Total steps of the run (set by [`run`] through [`Observer`]-independent logic).
    last: usize,
}

impl<O> Every<O> {
    /// Samples every `k` steps (`k >= 1`; 0 is treated as 1).
    pub fn new(k: usize, inner: O) -> Self {
        Every {
            k: k.max(1),
            inner,
            last: usize::MAX,
        }
    }
    /// Sets the index of the final step so it is always sampled.
    pub fn with_last(mut self, last: usize) -> Self {
        self.last = last;
        self
    }
}

impl<O: Observer> Observer for Every<O> {
    fn observe(&mut self, sys: &System, state: &State, step: usize) -> Result<Flow, SolveError> {
        if step % self.k == 0 || step == self.last {
            self.inner.observe(sys, state, step)
        } else {
            Ok(Flow::Continue)
        }
    }
    fn stop_reason(&self) -> Option<StopReason> {
        self.inner.stop_reason()
    }
}

/// Keeps every sample it receives (times, positions, velocities).
#[derive(Clone, Debug, Default)]
pub struct Recorder {
    /// Sample times.
    pub t: Vec<f64>,
    /// Positions.
    pub q: Vec<Vec<f64>>,
    /// Velocities.
    pub v: Vec<Vec<f64>>,
    /// Step indices.
    pub step: Vec<usize>,
}

impl Recorder {
    /// An empty recorder.
    pub fn new() -> Self {
        Self::default()
    }
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }
    /// Whether no sample was kept.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
}

impl Observer for Recorder {
    fn observe(&mut self, _: &System, s: &State, step: usize) -> Result<Flow, SolveError> {
        self.t.push(s.t);
        self.q.push(s.q.as_slice().to_vec());
        self.v.push(s.v.as_slice().to_vec());
        self.step.push(step);
        Ok(Flow::Continue)
    }
}

/// Time span, step size and safety settings of a fixed-step run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunConfig {
    /// End time (the start is the state's time).
    pub t_end: f64,
    /// Step size.
    pub h: f64,
    /// The constraint-drift guard (default [`DriftGuard::default`]; `None` = off).
    pub drift_guard: Option<DriftGuard>,
    /// Steps whose index-1 condition estimate ([`StepStats::condition`]) exceeds this are
    /// counted in [`RunStats::near_singular_steps`] (default [`RunConfig::DEFAULT_CONDITION_LIMIT`]).
    pub condition_limit: f64,
}

impl RunConfig {
    /// The default of [`RunConfig::condition_limit`]: `1e6`, constraint gradients within about
    /// `1e-3` rad of linear dependence (six digits of the multipliers at risk). Well-posed
    /// mechanisms stay far below it (the manipulator and slider-crank below 100); a
    /// parallelogram four-bar swinging through its flat configuration reaches `5e7` with
    /// `h = 1e-4` (a step lands within `1e-4` of the singular point) and `2e5` with `h = 1e-3`.
    pub const DEFAULT_CONDITION_LIMIT: f64 = 1e6;

    /// A run to `t_end` with steps of `h` (validated by [`run`]), with the default drift guard
    /// and condition limit.
    pub fn new(t_end: f64, h: f64) -> Self {
        RunConfig {
            t_end,
            h,
            drift_guard: Some(DriftGuard::default()),
            condition_limit: Self::DEFAULT_CONDITION_LIMIT,
        }
    }

    /// The same run with the given drift guard.
    pub fn with_drift_guard(mut self, guard: DriftGuard) -> Self {
        self.drift_guard = Some(guard);
        self
    }

    /// The same run without the drift guard (to measure drift itself, as the papers' RK4 tables
    /// do).
    pub fn without_drift_guard(mut self) -> Self {
        self.drift_guard = None;
        self
    }

    /// The same run with another condition limit.
    pub fn with_condition_limit(mut self, limit: f64) -> Self {
        self.condition_limit = limit;
        self
    }
}

/// Summary of a run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RunStats {
    /// Steps taken (accepted steps of an adaptive run).
    pub steps: usize,
    /// Steps rejected by the error test of an adaptive run ([`crate::run_adaptive`]); 0 for
    /// fixed steps.
    pub rejected_steps: usize,
    /// Total Newton iterations.
    pub newton_iterations: usize,
    /// Total right-hand-side evaluations.
    pub rhs_evals: usize,
    /// Total objective evaluations.
    pub objective_evals: usize,
    /// Largest Newton residual of a step.
    pub max_residual: f64,
    /// Whether an observer stopped the run early (`stop != StopReason::ReachedEnd`).
    pub stopped_early: bool,
    /// Why the run ended.
    pub stop: StopReason,
    /// Steps whose index-1 condition estimate exceeded [`RunConfig::condition_limit`]: the run
    /// passed close to a singular configuration, where accelerations and multipliers lose
    /// digits (see [`RunStats::warning`]). On models with spatial bodies the estimate is taken
    /// in the unit-free measure of the constraint geometry (a slender or flat body's small
    /// director masses do not count as nearness to a singular configuration; see
    /// `docs/architecture.md`, "Slender bodies and the condition estimate").
    pub near_singular_steps: usize,
    /// Time at the end of the first such step.
    pub first_near_singular: Option<f64>,
    /// Largest condition estimate met, in the measure of
    /// [`RunStats::near_singular_steps`] (0 if the solver does not estimate it).
    pub max_condition: f64,
    /// Smallest step taken (accepted steps of an adaptive run; the shortened last step counts);
    /// 0 before the first step.
    pub min_step: f64,
    /// Largest step taken (accepted steps of an adaptive run); 0 before the first step.
    pub max_step: f64,
    /// Stages whose accelerations [`crate::SingularBridge`] bridged through a singular
    /// configuration (summed over steps and attempts).
    pub bridged_stages: usize,
    /// Grid times a fixed-step [`run`] stepped over because a step from or onto the
    /// configuration there failed as singular (three steps around it whose ends and stages
    /// miss it; only for solvers that keep the constraints, see
    /// `crates/solve/src/step_over.rs`).
    pub stepped_over: usize,
    /// The first such grid time.
    pub first_stepped_over: Option<f64>,
    /// Of those, the grid times the observer saw no state at (the step *onto* the grid time
    /// failed, as onto a singular configuration, so the run has no state there; otherwise
    /// the state there was reached and only a step from it failed).
    pub skipped_outputs: usize,
}

impl RunStats {
    /// Records that `observer` stopped the run.
    pub(crate) fn stopped_by<O: Observer + ?Sized>(&mut self, observer: &O) {
        self.stopped_early = true;
        self.stop = observer.stop_reason().unwrap_or(StopReason::Observer);
    }

    /// Adds the work of one step or attempt (Newton iterations, right-hand sides, objective
    /// evaluations).
    pub(crate) fn add_work(&mut self, s: &StepStats) {
        self.newton_iterations += s.newton_iterations;
        self.rhs_evals += s.rhs_evals;
        self.objective_evals += s.objective_evals;
        self.bridged_stages += s.bridged_stages;
    }

    /// A warning to show the user when the run passed near a singular configuration, `None`
    /// otherwise.
    pub fn warning(&self) -> Option<String> {
        let over = self.first_stepped_over.map(|t| {
            let skipped = if self.skipped_outputs > 0 {
                format!(
                    " ({} of them without an output: the step onto that time failed, as \
                     onto a singular configuration itself)",
                    self.skipped_outputs
                )
            } else {
                String::new()
            };
            format!(
                "{} grid time(s) at a singular configuration were stepped over by steps that \
                 straddle it (first at t = {t}){skipped}",
                self.stepped_over
            )
        });
        let Some(t) = self.first_near_singular else {
            return over;
        };
        let over = over.map(|o| format!("; {o}")).unwrap_or_default();
        let bridged = if self.bridged_stages > 0 {
            format!(
                "; {} stage(s) took the ill-determined part of their accelerations from the \
                 motion's extrapolation (SingularBridge)",
                self.bridged_stages
            )
        } else {
            String::new()
        };
        Some(format!(
            "{} step(s) passed near a singular configuration (index-1 condition estimate up to \
             {:.1e}, first at t = {t}): accelerations and multipliers there may have lost digits; \
             check the mechanism's geometry or take a smaller step{bridged}{over}",
            self.near_singular_steps, self.max_condition
        ))
    }
}

/// The number of steps and the size of each for a run from `t0` to `t_end` with nominal step
/// `h`: `n` steps of `h`, the last one shortened to land exactly on `t_end` when `h` does not
/// divide the interval (to 1e-9 relative). Errors for `h <= 0`, non-finite values, `t_end < t0`
/// and an empty interval (zero steps).
pub fn step_count(t0: f64, t_end: f64, h: f64) -> Result<usize, SolveError> {
    if !(h.is_finite() && h > 0.0) {
        return Err(SolveError::InvalidStep { h });
    }
    if !(t0.is_finite() && t_end.is_finite()) {
        return Err(SolveError::InvalidInterval {
            t0,
            t_end,
            reason: "times must be finite",
        });
    }
    if t_end < t0 {
        return Err(SolveError::InvalidInterval {
            t0,
            t_end,
            reason: "end time before start time",
        });
    }
    let span = t_end - t0;
    if span == 0.0 {
        return Err(SolveError::InvalidInterval {
            t0,
            t_end,
            reason: "zero steps: the interval is empty",
        });
    }
    let r = span / h;
    let n = if (r - r.round()).abs() <= 1e-9 * r.max(1.0) {
        r.round()
    } else {
        r.ceil()
    };
    // (a span far below h is one short step)
    let n = n.max(1.0);
    if !(n <= MAX_FIXED_STEPS) {
        return Err(SolveError::TooManySteps { steps: n, h, span });
    }
    Ok(n as usize)
}

/// The most steps a fixed-step run takes ([`step_count`]): beyond it a run is refused with
/// [`SolveError::TooManySteps`] rather than started (1e12 steps of the cheapest solver take
/// days).
pub const MAX_FIXED_STEPS: f64 = 1e12;

/// Integrates from `state.t` to `cfg.t_end` with steps of `cfg.h`, calling `observer` with the
/// initial state (step 0) and after every step.
///
/// Every step is given exactly the nominal `cfg.h` (solvers that keep a history see one step
/// size), except the last where `h` does not divide the interval (to 1e-9 relative): it is
/// shortened to end at `cfg.t_end`. Times are set to `t0 + k h` after each step, so they do
/// not accumulate round-off, and to `(K + k) h` where `t0` is (to 1e-9 h) the multiple `K h`:
/// a run restarted from a state it saved at such a time steps through the same times and step
/// sizes as the run that went on, so it ends at the same state bit for bit. A non-finite
/// state after a step is an error; so is constraint drift beyond `cfg.drift_guard`
/// ([`SolveError::ConstraintDrift`]). Steps that pass near a singular configuration are
/// counted in [`RunStats::near_singular_steps`]. Where a step of an integrator that keeps the
/// constraints fails with [`SolveError::Singular`] because it starts or ends on a singular
/// configuration (not a Newton failure near one, [`SolveError::is_newton_near_rank_loss`]),
/// two grid intervals around it are covered by three steps that miss that grid time ([`RunStats::stepped_over`]; `docs/singular.md`, section 5): the observer is then
/// not called at a grid time where the run has no state ([`RunStats::skipped_outputs`]).
pub fn run<I, O>(
    integrator: &mut I,
    sys: &System,
    state: &mut State,
    cfg: RunConfig,
    observer: &mut O,
) -> Result<RunStats, SolveError>
where
    I: Integrator + ?Sized,
    O: Observer + ?Sized,
{
    let mut checks = RunChecks::open(
        sys,
        state,
        cfg.drift_guard,
        cfg.condition_limit,
        integrator.keeps_constraints(),
    )?;
    let t0 = state.t;
    let n = step_count(t0, cfg.t_end, cfg.h)?;
    integrator.reset();
    let mut stats = RunStats::default();
    if observer.observe(sys, state, 0)? == Flow::Stop {
        stats.stopped_by(observer);
        return Ok(stats);
    }
    // the step times lie on the grid of multiples of h when the run starts on it (to rounding):
    // a run restarted from a saved state at t = K h then steps through the same times as one
    // that went on from 0 (and so, for time-dependent models too, through the same states)
    let k0 = (t0 / cfg.h).round();
    let on_grid = (t0 - k0 * cfg.h).abs() <= 1e-9 * cfg.h && k0.abs() < MAX_FIXED_STEPS;
    // the time after step k and the step's size
    let grid = |k: usize| -> (f64, f64) {
        let at = |k: usize| {
            if on_grid {
                (k0 + k as f64) * cfg.h
            } else {
                t0 + k as f64 * cfg.h
            }
        };
        if k == n {
            // the last step: the nominal h where it divides the interval (to the rounding of
            // the times), shortened only where it does not
            let rest = cfg.t_end - if k == 1 { t0 } else { at(k - 1) };
            let h = if (rest - cfg.h).abs() <= 1e-9 * cfg.h {
                cfg.h
            } else {
                rest
            };
            (cfg.t_end, h)
        } else {
            (at(k), cfg.h)
        }
    };
    // the states before the current step and before the last one (`step_over`)
    let keeps = integrator.keeps_constraints();
    // (allocated once per run; copied into per step only for the solvers that keep the
    // constraints, whose failures at a singular configuration are stepped over)
    let (mut start, mut before) = (state.clone(), state.clone());
    let mut have_before = false;
    let mut landing = step_over::Landing::new(sys, keeps)?;
    let nominal = |k: usize| k <= n && grid(k).1 == cfg.h;
    let mut k = 1;
    while k <= n {
        let (t_next, h) = grid(k);
        if keeps {
            step_over::copy_state(&mut start, state);
        }
        let mut landed = false;
        let failure = match integrator.step(sys, state, h) {
            Ok(s) => {
                state.t = t_next;
                stats.add_work(&s);
                landed = landing.on_singular(sys, state);
                if landed {
                    Some(SolveError::Singular {
                        t: t_next,
                        what: step_over::LANDED_ON_SINGULAR,
                        detail: "the step's end".into(),
                    })
                } else {
                    checks.accepted(sys, state, h, &s, &mut stats)?;
                    if keeps {
                        std::mem::swap(&mut start, &mut before);
                        have_before = true;
                    }
                    None
                }
            }
            Err(e @ SolveError::Singular { .. }) if keeps && !e.is_newton_near_rank_loss() => {
                Some(e)
            }
            Err(e) => return Err(e),
        };
        if let Some(e) = failure {
            // a step from or onto a singular configuration: cover two grid intervals with
            // steps that straddle the grid time between them (`step_over`)
            // (a landing is left out only by the window after it: the one before ends on it)
            let window = step_over::Window {
                h: cfg.h,
                start: &start,
                t_k: t_next,
                after: (nominal(k) && nominal(k + 1)).then(|| grid(k + 1).0),
                before: (!landed && have_before && k >= 2 && nominal(k)).then_some(&before),
            };
            match step_over::step_over(integrator, sys, state, &window, &mut checks, &mut stats) {
                // grid time k, the singular configuration itself, has no state
                Some(step_over::Covered::After) => k += 1,
                // (the window before ends on grid time k: on the singular configuration if the
                // step failed landing there, which a run may not end on)
                Some(step_over::Covered::Before) => {
                    if landing.on_singular(sys, state) {
                        return Err(e);
                    }
                }
                None => return Err(e),
            }
            // the grid state before this one was stepped over
            have_before = false;
        }
        if observer.observe(sys, state, k)? == Flow::Stop {
            stats.stopped_by(observer);
            break;
        }
        k += 1;
    }
    Ok(stats)
}
