//! # mbd-rk4
//!
//! The baseline of paper C's Table 2: the classic four-stage Runge-Kutta method on the index-1
//! form `q' = v`, `v' = a(q, v, t)`, where every stage solves
//! `[[M, Phi_q^T], [Phi_q, 0]] [a; lambda] = [Q; gamma]`. Nothing holds the position and velocity
//! constraints, so they drift (as in the paper); two stabilisations are available, both off by
//! default and named in [`Integrator::name`]:
//!
//! * Baumgarte: `Phi_q a = gamma - 2 alpha Phidot - beta^2 Phi`;
//! * post-step projection of `(q, v)` onto `Phi = 0`, `Phidot = 0` (minimum `M`-norm).
//!
//! ```
//! use mbd_model::models;
//! use mbd_rk4::{Rk4, Rk4Options};
//! use mbd_solve::{run, NoObserver, RunConfig, State};
//!
//! let sys = models::manipulator()?;
//! let mut state = State::consistent(&sys, 0.0)?;
//! let h0 = sys.energy(state.q.as_slice(), state.v.as_slice());
//! let mut rk4 = Rk4::new(&sys, Rk4Options::default())?;
//! run(&mut rk4, &sys, &mut state, RunConfig::new(1.0, 0.001), &mut NoObserver)?;
//! let h1 = sys.energy(state.q.as_slice(), state.v.as_slice());
//! assert!(((h1 - h0) / h0).abs() < 1e-6);
//! # Ok::<(), mbd_solve::SolveError>(())
//! ```
#![warn(missing_docs)]

mod registry;
pub use registry::SOLVERS;

use mbd_model::System;
use mbd_solve::{
    ButcherTableau, Index1Options, Index1Rk, Integrator, LinearSolver, ProjectionSettings,
    SolveError, State, StepStats,
};

/// Options of [`Rk4`]: both stabilisations off by default.
#[derive(Clone, Debug, PartialEq)]
pub struct Rk4Options {
    /// Baumgarte `(alpha, beta)`.
    pub baumgarte: Option<(f64, f64)>,
    /// Post-step projection.
    pub projection: Option<ProjectionSettings>,
    /// Dense or sparse index-1 solve (default: sparse for large systems).
    pub linear: LinearSolver,
    /// Bridge the stage accelerations through singular configurations (default on; see
    /// [`mbd_solve::SingularBridge`]).
    pub bridge: bool,
}

impl Default for Rk4Options {
    fn default() -> Self {
        Rk4Options {
            baumgarte: None,
            projection: None,
            linear: LinearSolver::default(),
            bridge: true,
        }
    }
}

impl Rk4Options {
    /// Plain RK4 (the paper's baseline).
    pub fn plain() -> Self {
        Self::default()
    }
    /// RK4 with Baumgarte stabilisation.
    pub fn baumgarte(alpha: f64, beta: f64) -> Self {
        Rk4Options {
            baumgarte: Some((alpha, beta)),
            ..Default::default()
        }
    }
    /// RK4 with post-step projection (default tolerance 1e-14).
    pub fn projected() -> Self {
        Rk4Options {
            projection: Some(ProjectionSettings::default()),
            ..Default::default()
        }
    }
}

/// Classic RK4 on the index-1 equations of motion.
#[derive(Debug)]
pub struct Rk4 {
    inner: Index1Rk,
}

impl Rk4 {
    /// An RK4 solver for `sys` (allocates its workspace once).
    pub fn new(sys: &System, options: Rk4Options) -> Result<Self, SolveError> {
        let inner = Index1Rk::new(
            sys,
            ButcherTableau::rk4(),
            Index1Options {
                baumgarte: options.baumgarte,
                projection: options.projection,
                linear: options.linear,
                bridge: options.bridge,
            },
        )?;
        Ok(Rk4 { inner })
    }
    /// Accelerations and multipliers of the last stage evaluated.
    pub fn last_acceleration(&self) -> (&[f64], &[f64]) {
        self.inner.last_acceleration()
    }
}

impl Integrator for Rk4 {
    fn name(&self) -> String {
        self.inner.name()
    }
    fn order(&self) -> Option<u32> {
        Some(4)
    }
    fn keeps_constraints(&self) -> bool {
        self.inner.keeps_constraints()
    }
    fn step(&mut self, sys: &System, state: &mut State, h: f64) -> Result<StepStats, SolveError> {
        self.inner.step(sys, state, h)
    }
}
