//! The `Integrator` trait, the run loop and observers.

use crate::error::SolveError;
use crate::state::State;
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
    /// The method's convergence order in the step size, if known.
    fn order(&self) -> Option<u32> {
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
    fn order(&self) -> Option<u32> {
        (**self).order()
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

/// Receives samples of a run: the initial state (step 0) and the state after steps.
pub trait Observer {
    /// Called with the step index (0 = initial state) and the state.
    fn observe(&mut self, sys: &System, state: &State, step: usize) -> Result<Flow, SolveError>;
}

impl<F> Observer for F
where
    F: FnMut(&System, &State, usize) -> Result<Flow, SolveError>,
{
    fn observe(&mut self, sys: &System, state: &State, step: usize) -> Result<Flow, SolveError> {
        self(sys, state, step)
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

/// Time span and step size of a fixed-step run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunConfig {
    /// End time (the start is the state's time).
    pub t_end: f64,
    /// Step size.
    pub h: f64,
}

impl RunConfig {
    /// A run to `t_end` with steps of `h` (validated by [`run`]).
    pub fn new(t_end: f64, h: f64) -> Self {
        RunConfig { t_end, h }
    }
}

/// Summary of a run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RunStats {
    /// Steps taken.
    pub steps: usize,
    /// Total Newton iterations.
    pub newton_iterations: usize,
    /// Total right-hand-side evaluations.
    pub rhs_evals: usize,
    /// Total objective evaluations.
    pub objective_evals: usize,
    /// Largest Newton residual of a step.
    pub max_residual: f64,
    /// Whether an observer stopped the run early.
    pub stopped_early: bool,
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
    if !(1.0..=1e12).contains(&n) {
        return Err(SolveError::InvalidStep { h });
    }
    Ok(n as usize)
}

/// Integrates from `state.t` to `cfg.t_end` with steps of `cfg.h`, calling `observer` with the
/// initial state (step 0) and after every step. Times are set to `t0 + k h` after each step, so
/// they do not accumulate round-off; the last step is shortened if `h` does not divide the
/// interval. A non-finite state after a step is an error.
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
    state.check(sys)?;
    let t0 = state.t;
    let n = step_count(t0, cfg.t_end, cfg.h)?;
    integrator.reset();
    let mut stats = RunStats::default();
    if observer.observe(sys, state, 0)? == Flow::Stop {
        stats.stopped_early = true;
        return Ok(stats);
    }
    for k in 1..=n {
        let t_next = if k == n {
            cfg.t_end
        } else {
            t0 + k as f64 * cfg.h
        };
        let h = t_next - state.t;
        let s = integrator.step(sys, state, h)?;
        state.t = t_next;
        if !state.is_finite() {
            return Err(SolveError::NonFinite {
                t: state.t,
                what: "state after step",
            });
        }
        stats.steps = k;
        stats.newton_iterations += s.newton_iterations;
        stats.rhs_evals += s.rhs_evals;
        stats.objective_evals += s.objective_evals;
        stats.max_residual = stats.max_residual.max(s.residual);
        if observer.observe(sys, state, k)? == Flow::Stop {
            stats.stopped_early = true;
            break;
        }
    }
    Ok(stats)
}
