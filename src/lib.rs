//! # mbd
//!
//! Planar and spatial rigid multibody systems as differential-algebraic equations, with the
//! solvers of three papers and the analysis that measures them. This facade holds the front door
//! ([`Simulation`]) and the solver registry ([`registry`]) and re-exports the workspace's
//! crates; depend on a single crate (e.g. `mbd-model` + `mbd-rk4`) if you need only part of it.
//!
//! | crate | what |
//! |---|---|
//! | [`model`] | bodies, joints, forces, `System` (Phi, Phi_q, gamma, Hessians, energy), model files |
//! | [`solve`] | the `Integrator` trait, run loop, observers, Newton, index-1 solve, tableaus |
//! | [`rk4`] | RK4 baseline (optional Baumgarte / projection) |
//! | [`symplectic`] | paper A: (s,s) constrained Galerkin variational integrator, preadjusted gamma |
//! | [`tangent`] | paper B: tangent-space parameterisation with any explicit RK tableau |
//! | [`firefly`] | the firefly metaheuristic, generic over any objective |
//! | [`firefly_gauss`] | paper C: the firefly-Gauss DAE solver |
//! | [`analysis`] | energy/constraint errors, trajectory errors, convergence orders, CSV/JSON |
//!
//! The front door is [`Simulation`]: a model (built in code or read from a file), a solver
//! named by a spec string of the [`registry`] (`"rk4"`, `"symplectic:2"`, `"tangent:dopri5"`,
//! ...; `mbd solvers` lists them), and a run with fixed steps ([`solve::RunConfig`]) or
//! adaptive ones ([`solve::AdaptiveConfig`]), observed by any [`solve::Observer`]. The run
//! returns [`solve::RunStats`] with the reason it stopped.
//!
//! ```
//! use mbd::prelude::*;
//!
//! let sys = models::manipulator()?;
//! let mut sim = Simulation::new(sys, "rk4")?;
//! let mut obs = MeasureObserver::new(sim.system(), false);
//! let stats = sim.run_observed(RunConfig::new(2.0, 0.01), &mut obs)?;
//! assert_eq!((stats.steps, stats.stop), (200, StopReason::ReachedEnd));
//! assert!(obs.measures().e_phi > 1e-12); // plain RK4 drifts off the constraints
//! # Ok::<(), mbd::Error>(())
//! ```
#![warn(missing_docs)]

pub mod output;
mod registry;
mod simulation;

pub use registry::registry;
pub use simulation::{Plan, Simulation};

pub use mbd_analysis as analysis;
pub use mbd_firefly as firefly;
pub use mbd_firefly_gauss as firefly_gauss;
pub use mbd_model as model;
pub use mbd_rk4 as rk4;
pub use mbd_solve as solve;
pub use mbd_symplectic as symplectic;
pub use mbd_tangent as tangent;

/// Everything the workspace's crates can fail with, in one type: every crate's error converts
/// into it with `?` (`From`), so a program mixing solvers needs one error type.
///
/// ```
/// use mbd::prelude::*;
///
/// fn simulate() -> Result<f64, mbd::Error> {
///     let sys = models::pendulum(1.0, 1.0, 0.3, 9.81)?; // ModelError
///     let mut state = State::consistent(&sys, 0.0)?; // SolveError
///     let mut integ = TangentRk::new(&sys, ButcherTableau::dopri5(), TangentOptions::default())?;
///     let mut rec = Recorder::new();
///     run(&mut integ, &sys, &mut state, RunConfig::new(1.0, 0.01), &mut rec)?;
///     Ok(state.t)
/// }
/// assert!((simulate()? - 1.0).abs() < 1e-12);
/// // a bad step size is a typed error naming the parameter
/// let sys = models::pendulum(1.0, 1.0, 0.3, 9.81)?;
/// let mut state = State::consistent(&sys, 0.0)?;
/// let mut rk = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default())?;
/// let err: mbd::Error = run(&mut rk, &sys, &mut state, RunConfig::new(1.0, -0.1), &mut NoObserver)
///     .unwrap_err()
///     .into();
/// assert!(matches!(err, mbd::Error::Solve(SolveError::InvalidStep { .. })));
/// # Ok::<(), mbd::Error>(())
/// ```
#[derive(Debug)]
#[non_exhaustive]
pub enum Error {
    /// Building or reading a model ([`model::ModelError`]).
    Model(model::ModelError),
    /// The run loop, the index-1 solve, Newton, RK4 ([`solve::SolveError`]).
    Solve(solve::SolveError),
    /// The symplectic integrator and its calibration ([`symplectic::SymplecticError`]).
    Symplectic(symplectic::SymplecticError),
    /// The firefly optimiser ([`firefly::FireflyError`]).
    Firefly(firefly::FireflyError),
    /// The firefly-Gauss solver ([`firefly_gauss::FaDaeError`]).
    FaDae(firefly_gauss::FaDaeError),
    /// Measures, trajectories and output ([`analysis::AnalysisError`]).
    Analysis(analysis::AnalysisError),
}

impl Error {
    fn inner(&self) -> &(dyn std::error::Error + 'static) {
        match self {
            Error::Model(e) => e,
            Error::Solve(e) => e,
            Error::Symplectic(e) => e,
            Error::Firefly(e) => e,
            Error::FaDae(e) => e,
            Error::Analysis(e) => e,
        }
    }
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Display::fmt(self.inner(), f)
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        // the wrapper is transparent: the inner error's message is ours, its source is ours
        self.inner().source()
    }
}

impl From<model::ModelError> for Error {
    fn from(e: model::ModelError) -> Self {
        Error::Model(e)
    }
}

/// A model error inside a solve error arrives as [`Error::Model`]: each kind of failure has one
/// variant, whichever crate passed it on.
impl From<solve::SolveError> for Error {
    fn from(e: solve::SolveError) -> Self {
        match e {
            solve::SolveError::Model(m) => Error::Model(m),
            e => Error::Solve(e),
        }
    }
}

/// A solve error inside a symplectic error arrives as [`Error::Solve`] (or [`Error::Model`]).
impl From<symplectic::SymplecticError> for Error {
    fn from(e: symplectic::SymplecticError) -> Self {
        match e {
            symplectic::SymplecticError::Solve(s) => s.into(),
            e => Error::Symplectic(e),
        }
    }
}

impl From<firefly::FireflyError> for Error {
    fn from(e: firefly::FireflyError) -> Self {
        Error::Firefly(e)
    }
}

/// A solve error inside an FA-DAE error arrives as [`Error::Solve`] (or [`Error::Model`]).
impl From<firefly_gauss::FaDaeError> for Error {
    fn from(e: firefly_gauss::FaDaeError) -> Self {
        match e {
            firefly_gauss::FaDaeError::Solve(s) => s.into(),
            e => Error::FaDae(e),
        }
    }
}

/// A solve error inside an analysis error arrives as [`Error::Solve`] (or [`Error::Model`]).
impl From<analysis::AnalysisError> for Error {
    fn from(e: analysis::AnalysisError) -> Self {
        match e {
            analysis::AnalysisError::Solve(s) => s.into(),
            e => Error::Analysis(e),
        }
    }
}

/// What a program needs for the common path: a model, a consistent state, a solver, the run
/// loop (fixed or adaptive steps), observers (with closures whose argument types are
/// inferred), dense output and events, and the one error type.
///
/// ```
/// use mbd::prelude::*;
///
/// let sys = models::pendulum(1.0, 1.0, 0.5, 9.81)?;
/// let mut state = State::consistent(&sys, 0.0)?;
/// let mut integ = TangentRk::new(&sys, ButcherTableau::dopri5(), TangentOptions::default())?;
/// let mut max_speed = 0.0f64;
/// let stats = run_adaptive(&mut integ, &sys, &mut state, AdaptiveConfig::new(2.0, 1e-9),
///     &mut observe(|s| max_speed = max_speed.max(s.v[0].hypot(s.v[1]))))?;
/// assert!(stats.steps > 0 && (state.t - 2.0).abs() < 1e-12);
/// assert!(max_speed > 0.5);
/// # Ok::<(), mbd::Error>(())
/// ```
pub mod prelude {
    pub use crate::{registry, Error, Plan, Simulation};
    pub use mbd_analysis::{CsvObserver, MeasureObserver};
    pub use mbd_firefly_gauss::{FaDaeOptions, FireflyGauss};
    pub use mbd_model::{models, System};
    pub use mbd_rk4::{Rk4, Rk4Options};
    pub use mbd_solve::{
        observe, observer, run, run_adaptive, AdaptiveConfig, AdaptiveIntegrator, ButcherTableau,
        Crossing, DenseOutput, Event, EventHit, Every, Flow, Index1Options, Index1Rk, Integrator,
        NoObserver, Observer, ProjectionSettings, Recorder, RunConfig, RunStats, SolveError, State,
        StopReason,
    };
    pub use mbd_symplectic::{Galerkin, PreadjustMode, SymplecticOptions};
    pub use mbd_tangent::{TangentOptions, TangentRk};
}

/// The README's usage example, compiled and run as a doctest.
#[doc = include_str!("../README.md")]
mod readme {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_failure_reaches_the_one_error_by_one_variant() {
        let m = model::ModelError::UnknownBody {
            element: "joint 'pin'".into(),
            body: "arm".into(),
        };
        assert!(matches!(Error::from(m.clone()), Error::Model(_)));
        let s = solve::SolveError::Model(m.clone());
        assert!(matches!(Error::from(s.clone()), Error::Model(_)));
        let sy = symplectic::SymplecticError::Solve(s.clone());
        assert!(matches!(Error::from(sy), Error::Model(_)));
        let fa = firefly_gauss::FaDaeError::Solve(s.clone());
        assert!(matches!(Error::from(fa), Error::Model(_)));
        let an = analysis::AnalysisError::Solve(s);
        assert!(matches!(Error::from(an), Error::Model(_)));
        let step = solve::SolveError::InvalidStep { h: -1.0 };
        assert!(matches!(
            Error::from(symplectic::SymplecticError::Solve(step)),
            Error::Solve(solve::SolveError::InvalidStep { .. })
        ));
    }
}
