//! The front door: a [`Simulation`] holds a model, a solver chosen from the registry (or any
//! integrator), and the current state, and runs it with fixed steps or adaptive ones through
//! the one run loop of `mbd-solve`.

use crate::registry::registry;
use crate::Error;
use mbd_model::System;
use mbd_solve::registry::{BoxedIntegrator, SolverSpec};
use mbd_solve::{
    run, run_adaptive, AdaptiveConfig, Integrator, NoObserver, Observer, RunConfig, RunStats,
    SolveError, State,
};
use std::path::Path;

/// How a run steps: fixed steps ([`RunConfig`]: end time, `h`, drift guard) or adaptive ones
/// ([`AdaptiveConfig`]: end time, tolerances, step limits). Both convert into it, so
/// [`Simulation::run`] takes either.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum Plan {
    /// Fixed steps of `h` (the last one shortened to land on `t_end`).
    Fixed(RunConfig),
    /// Steps chosen by the solver's embedded error estimate.
    Adaptive(AdaptiveConfig),
}

impl From<RunConfig> for Plan {
    fn from(c: RunConfig) -> Self {
        Plan::Fixed(c)
    }
}

impl From<AdaptiveConfig> for Plan {
    fn from(c: AdaptiveConfig) -> Self {
        Plan::Adaptive(c)
    }
}

/// A model, a solver and the current state: the one way to run a simulation.
///
/// Build it from a [`System`] (code or a model file) and a solver spec string of the registry
/// ([`crate::registry`]: `"rk4"`, `"symplectic:2"`, `"tangent:dopri5"`, ...), or from any
/// [`Integrator`]. It starts from the consistent initial state at `t = 0`
/// ([`State::consistent`]); each [`Simulation::run`] continues from where the last one ended,
/// up to the plan's end time, and returns the run's [`RunStats`], whose
/// [`RunStats::stop`] says why it ended. Errors stay errors ([`Error`]).
///
/// ```
/// use mbd::prelude::*;
///
/// let mut sim = Simulation::new(models::manipulator()?, "symplectic:2")?;
/// let stats = sim.run(RunConfig::new(1.0, 1e-3))?;
/// assert_eq!(stats.steps, 1000);
/// assert_eq!(stats.stop, StopReason::ReachedEnd);
///
/// // adaptive steps with an observer, continuing to t = 2 s
/// let mut sim = Simulation::new(models::manipulator()?, "tangent:dopri5")?;
/// let mut rec = Recorder::new();
/// let stats = sim.run_observed(AdaptiveConfig::new(2.0, 1e-8), &mut rec)?;
/// assert_eq!(rec.len(), stats.steps + 1);
/// assert!((sim.state().t - 2.0).abs() < 1e-15);
///
/// // a fixed-step solver asked for adaptive steps says so
/// let mut sim = Simulation::new(models::manipulator()?, "rk4")?;
/// let e = sim.run(AdaptiveConfig::new(1.0, 1e-6)).unwrap_err();
/// assert!(e.to_string().contains("no embedded error estimate"));
/// # Ok::<(), mbd::Error>(())
/// ```
pub struct Simulation {
    system: System,
    solver: String,
    integrator: BoxedIntegrator,
    state: State,
    caveat: Option<String>,
}

impl std::fmt::Debug for Simulation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Simulation")
            .field("solver", &self.solver)
            .field("t", &self.state.t)
            .finish_non_exhaustive()
    }
}

impl Simulation {
    /// `system` with the registry's solver `solver` (a spec string such as `"symplectic:2"`),
    /// from its consistent initial state at `t = 0`.
    pub fn new(system: System, solver: &str) -> Result<Self, Error> {
        let spec = registry().parse(solver)?;
        Self::with_spec(system, &spec)
    }

    /// The model file at `path` (`.toml` or `.json`) with the registry's solver `solver`.
    pub fn from_path(path: impl AsRef<Path>, solver: &str) -> Result<Self, Error> {
        Self::new(System::from_path(path)?, solver)
    }

    /// `system` with a parsed solver spec.
    pub fn with_spec(system: System, spec: &SolverSpec) -> Result<Self, Error> {
        let integrator = spec
            .build(&system)
            .map_err(|e| registry().with_advice(&system, e))?;
        let state = State::consistent(&system, 0.0)?;
        Ok(Simulation {
            caveat: spec.caveat(&system),
            system,
            solver: spec.spec().to_string(),
            integrator,
            state,
        })
    }

    /// `system` with any integrator built for it (a solver outside the registry, or one with
    /// options no spec string offers).
    pub fn with_integrator(
        system: System,
        integrator: impl Integrator + Send + 'static,
    ) -> Result<Self, Error> {
        let state = State::consistent(&system, 0.0)?;
        Ok(Simulation {
            solver: integrator.name(),
            system,
            integrator: Box::new(integrator),
            state,
            caveat: None,
        })
    }

    /// `system` with an integrator built for it, named `solver`, from `state` (checked against
    /// the model's sizes): for callers that build the state themselves (from a restart file,
    /// or to report its errors apart from the solver's).
    pub fn from_parts(
        system: System,
        solver: impl Into<String>,
        integrator: BoxedIntegrator,
        state: State,
    ) -> Result<Self, Error> {
        state.check(&system)?;
        Ok(Simulation {
            system,
            solver: solver.into(),
            integrator,
            state,
            caveat: None,
        })
    }

    /// What the registry's solver does not deliver on this model of its nominal properties
    /// ([`SolverSpec::caveat`], e.g. the modified-Lagrangian schemes on a model with drivers
    /// keep the plain scheme's order), for a warning; `None` otherwise and for integrators
    /// built outside the registry.
    pub fn caveat(&self) -> Option<&str> {
        self.caveat.as_deref()
    }

    /// The model.
    pub fn system(&self) -> &System {
        &self.system
    }

    /// The solver's spec string (or the integrator's name for [`Simulation::with_integrator`]).
    pub fn solver(&self) -> &str {
        &self.solver
    }

    /// The integrator (its name, order; solver-specific statistics by downcasting your own).
    pub fn integrator(&self) -> &dyn Integrator {
        &*self.integrator
    }

    /// The current state.
    pub fn state(&self) -> &State {
        &self.state
    }

    /// Replaces the current state (checked against the model's sizes; the solvers check that
    /// it is consistent where they need it).
    pub fn set_state(&mut self, state: State) -> Result<(), Error> {
        state.check(&self.system)?;
        self.state = state;
        Ok(())
    }

    /// Runs from the current state to the plan's end time without observing it.
    pub fn run(&mut self, plan: impl Into<Plan>) -> Result<RunStats, Error> {
        self.run_observed(plan, &mut NoObserver)
    }

    /// Runs from the current state to the plan's end time, calling `observer` with the
    /// initial state and after every (accepted) step (a fixed-step run that steps over a grid
    /// time at a singular configuration has no state there: [`RunStats::skipped_outputs`]).
    /// On error the state is where the failing step started (or the last accepted point).
    pub fn run_observed<O: Observer + ?Sized>(
        &mut self,
        plan: impl Into<Plan>,
        observer: &mut O,
    ) -> Result<RunStats, Error> {
        let (sys, state) = (&self.system, &mut self.state);
        let stats = match plan.into() {
            Plan::Fixed(cfg) => run(&mut *self.integrator, sys, state, cfg, observer)?,
            Plan::Adaptive(cfg) => {
                let name = self.solver.clone();
                let adaptive = self.integrator.as_adaptive().ok_or_else(|| {
                    SolveError::Unsupported(format!(
                        "'{name}' has no embedded error estimate: run it with fixed steps \
                         (RunConfig), or choose an adaptive solver ({})",
                        adaptive_solvers()
                    ))
                })?;
                run_adaptive(adaptive, sys, state, cfg, observer)?
            }
        };
        Ok(stats)
    }
}

/// The registry's adaptive solvers, comma-separated.
fn adaptive_solvers() -> String {
    registry()
        .variants()
        .filter(|(_, v)| v.adaptive)
        .map(|(_, v)| v.spec)
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use mbd_model::models;
    use mbd_solve::{Event, StopReason};

    #[test]
    fn every_registered_solver_runs_the_pendulum() {
        for (_, v) in registry().variants() {
            let sys = models::pendulum(1.0, 1.0, 0.5, 9.81).expect("model");
            let mut sim = Simulation::new(sys, v.spec).expect(v.spec);
            let stats = sim
                .run(RunConfig::new(0.05, 0.01))
                .unwrap_or_else(|e| panic!("{}: {e}", v.spec));
            assert_eq!(stats.steps, 5, "{}", v.spec);
            if v.adaptive {
                let st = sim
                    .run(AdaptiveConfig::new(0.2, 1e-8))
                    .unwrap_or_else(|e| panic!("{} adaptive: {e}", v.spec));
                assert!(st.steps > 0 && sim.state().t == 0.2, "{}", v.spec);
            }
        }
    }

    #[test]
    fn a_terminal_event_is_the_stop_reason() {
        let sys = models::pendulum(1.0, 1.0, 0.5, 9.81).expect("model");
        let mut sim = Simulation::new(sys, "tangent:rk4").expect("sim");
        let mut dense = mbd_solve::DenseOutput::new(sim.system(), NoObserver)
            .with_event(Event::new("x = 0", |_, q, _| q[0]).terminal());
        let stats = sim
            .run_observed(RunConfig::new(5.0, 1e-3), &mut dense)
            .expect("run");
        match stats.stop {
            StopReason::Event { event: 0, t } => assert!(t > 0.1 && t < 1.0, "{t}"),
            other => panic!("{other:?}"),
        }
        assert!(stats.stopped_early);
    }

    #[test]
    fn a_solver_caveat_reaches_the_simulation() {
        let free = models::pendulum(1.0, 1.0, 0.5, 9.81).expect("model");
        let driven = models::ClosedLoop::n_four_bar(1, 1.0, 2.0)
            .and_then(|l| l.system(1.0, 1.0, true))
            .expect("model");
        for (_, v) in registry().variants() {
            let sim = Simulation::new(free.clone(), v.spec).expect(v.spec);
            assert_eq!(sim.caveat(), None, "{}", v.spec);
        }
        let sim = Simulation::new(driven.clone(), "symplectic:1:modified").expect("sim");
        let c = sim.caveat().expect("a caveat");
        assert!(c.contains("order 2 (not 4)"), "{c}");
        let sim = Simulation::new(driven, "symplectic:1").expect("sim");
        assert_eq!(sim.caveat(), None);
    }

    #[test]
    fn bad_specs_and_states_are_errors() {
        let sys = models::pendulum(1.0, 1.0, 0.5, 9.81).expect("model");
        let e = Simulation::new(sys.clone(), "rk5").unwrap_err().to_string();
        assert!(
            e.contains("unknown solver 'rk5'") && e.contains("tangent:rk4"),
            "{e}"
        );
        let e = Simulation::new(sys.clone(), "symplectic:2:gamma=1:gamma=2")
            .unwrap_err()
            .to_string();
        assert!(e.contains("given twice"), "{e}");
        let mut sim = Simulation::new(sys, "rk4").expect("sim");
        let other = models::manipulator().expect("model");
        let s = State::consistent(&other, 0.0).expect("state");
        assert!(sim.set_state(s).is_err());
    }
}
